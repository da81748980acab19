//! `quadrille`: the command-line batch mode of the pipeline.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "quadrille",
    version,
    about = "Quad-dominant remeshing and Catmull-Clark control meshes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Read a mesh, validate and repair it, and print the import report as JSON.
    Info {
        /// Mesh file (.obj, .ply, .stl, .off, .gltf, .glb).
        input: PathBuf,
        /// Print the JSON on one line.
        #[arg(long)]
        compact: bool,
    },
    /// Read a mesh and write it as OBJ or PLY (by the output's extension),
    /// polygons kept, after the import repairs.
    Convert {
        input: PathBuf,
        #[arg(short, long)]
        output: PathBuf,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("quadrille: {message}");
            ExitCode::FAILURE
        }
    }
}

fn import(path: &Path) -> Result<quadrille::io::Imported, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    quadrille::io::import(&bytes, &path.display().to_string()).map_err(|e| e.to_string())
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Info { input, compact } => {
            let imported = import(&input)?;
            let json = if compact {
                serde_json::to_string(&imported.report)
            } else {
                serde_json::to_string_pretty(&imported.report)
            };
            println!("{}", json.map_err(|e| e.to_string())?);
            Ok(())
        }
        Command::Convert { input, output } => {
            let imported = import(&input)?;
            let world: Vec<_> = imported
                .mesh
                .positions
                .iter()
                .map(|&p| imported.frame.to_world(p))
                .collect();
            let name = output.display().to_string();
            let bytes = quadrille::io::write_by_extension(&name, &world, &imported.polygons)
                .map_err(|e| e.to_string())?;
            std::fs::write(&output, bytes).map_err(|e| format!("{name}: {e}"))
        }
    }
}

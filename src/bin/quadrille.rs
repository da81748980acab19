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
    /// Print the quality metrics (JSON) of a polygon mesh against a reference
    /// surface, both read as stored (e.g. to compare another remesher).
    Metrics {
        mesh: PathBuf,
        #[arg(long)]
        reference: PathBuf,
    },
    /// Run the whole pipeline and write the quad mesh (OBJ, PLY or OFF by
    /// the output's extension, polygons kept): quad-dominant in the local
    /// mode, pure quads in the global mode (`--mode global`).
    Remesh(RemeshArgs),
    /// Fit a Catmull–Clark control mesh to a reference surface, starting
    /// from any polygon mesh (a retopology, another remesher's output):
    /// one subdivision step, then Kloiber §3.8's normal-offset iterations and a least-squares finish.
    /// Both meshes are read in the same (file) coordinates.
    Fit(FitArgs),
    /// Compute the integer-grid map (Ebke et al. 2014 / Campen et al. 2016,
    /// Bommes et al. 2009's MIQ) and write the input mesh with it as
    /// per-corner texture coordinates (`vt`, split at the seams; one unit
    /// is one target edge).
    Param(ParamArgs),
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

/// Writes a report to standard output; a reader that closed the pipe
/// early (`quadrille info x.obj | head`) is not an error.
fn print_stdout(text: &str) -> Result<(), String> {
    use std::io::Write;
    match writeln!(std::io::stdout().lock(), "{text}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(format!("stdout: {e}")),
        _ => Ok(()),
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
            print_stdout(&json.map_err(|e| e.to_string())?)
        }
        Command::Convert { input, output } => {
            let imported = import(&input)?;
            let world: Vec<_> = imported.frame.points_to_world(&imported.mesh.positions);
            let name = output.display().to_string();
            let bytes = quadrille::io::write_by_extension(&name, &world, &imported.polygons)
                .map_err(|e| e.to_string())?;
            std::fs::write(&output, bytes).map_err(|e| format!("{name}: {e}"))
        }
        Command::Metrics { mesh, reference } => metrics_of(&mesh, &reference),
        Command::Fit(args) => fit(args),
        Command::Remesh(args) => remesh(args),
        Command::Param(args) => param(args),
    }
}

#[derive(clap::Args)]
struct RemeshArgs {
    input: PathBuf,
    #[arg(short, long)]
    output: PathBuf,
    /// Target vertex count (default: input vertices / 16).
    #[arg(long, conflicts_with = "edge_length")]
    vertices: Option<usize>,
    /// Global target edge length in the file's units (overrides the count).
    #[arg(long)]
    edge_length: Option<f64>,
    /// Seed of the random initialisation.
    #[arg(long)]
    seed: Option<u64>,
    /// Remeshing mode (overrides `remesh.mode` of --params): local
    /// (Instant Meshes' fields as in the thesis, quad-dominant; the
    /// default) or global (integer-grid map and QEx extraction, pure quads).
    #[arg(long, value_parser = ["local", "global"])]
    mode: Option<String>,
    /// Pipeline parameters as JSON (every field optional).
    #[arg(long)]
    params: Option<PathBuf>,
    /// Write the quality metrics and per-stage timings as JSON here.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Also fit a Catmull–Clark control mesh to the input (Kloiber §3.8)
    /// and write it here.
    #[arg(long)]
    control: Option<PathBuf>,
    /// Also write the fitted control mesh's limit surface here.
    #[arg(long)]
    limit: Option<PathBuf>,
    /// Subdivision levels of the written limit surface.
    #[arg(long, default_value_t = 2)]
    limit_levels: u32,
    /// Print progress to stderr.
    #[arg(short, long)]
    verbose: bool,
}

fn remesh(args: RemeshArgs) -> Result<(), String> {
    use quadrille::pipeline::{Params, Pipeline, target_vertex_count};
    let name = args.output.display().to_string();
    if quadrille::io::Format::from_extension(&name).is_none_or(|f| {
        !matches!(
            f,
            quadrille::io::Format::Obj | quadrille::io::Format::Ply | quadrille::io::Format::Off
        )
    }) {
        return Err(format!("{name}: can only write .obj, .ply and .off files"));
    }
    let mut params: Params = match &args.params {
        None => Params::default(),
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))?
        }
    };
    let start = std::time::Instant::now();
    let imported = import(&args.input)?;
    let import_ms = start.elapsed().as_secs_f64() * 1e3;
    command_line_params(&args, &mut params, imported.frame.scale)?;
    let input_vertices = imported.mesh.vertex_count();
    quadrille::pipeline::check_target(input_vertices, &params.sizing)
        .map_err(|e| format!("{}: {e}", args.input.display()))?;
    let target = target_vertex_count(input_vertices, &params.sizing);
    let mut pipeline = Pipeline::new(imported, params);
    // The control mesh (and, for the stats, its limit error before and
    // after fitting) is the pipeline's last stage.
    pipeline.fit_enabled = args.control.is_some() || args.limit.is_some() || args.stats.is_some();
    let clock = move || start.elapsed().as_secs_f64() * 1e3;
    let verbose = args.verbose;
    let mut last = String::new();
    let mut sink = |stage: &str, fraction: f32, message: &str| {
        if verbose {
            let line = format!("{stage}: {message}");
            if line != last {
                eprintln!("[{:>5.1}%] {line}", 100.0 * fraction);
                last = line;
            }
        }
        true
    };
    pipeline
        .run(&mut sink, &mut |_, _| {}, &clock)
        .map_err(|e| format!("{}: {e}", args.input.display()))?;
    let surface = pipeline.surface();
    let post = pipeline
        .postprocess
        .as_ref()
        .ok_or("the pipeline produced no mesh")?;
    let mesh = post.mesh();
    if mesh.face_count() == 0 {
        return Err(
            "extraction produced an empty mesh (is the target vertex count too small?)".into(),
        );
    }
    let frame = pipeline.input.frame;
    let world: Vec<_> = frame.points_to_world(&mesh.positions);
    let bytes = quadrille::io::write_by_extension(&name, &world, &mesh.to_face_list())
        .map_err(|e| e.to_string())?;
    std::fs::write(&args.output, bytes).map_err(|e| format!("{name}: {e}"))?;

    let fitted = pipeline.fit.as_ref().map(|f| &f.result);
    if let Some(result) = fitted {
        use quadrille::subdivision;
        let fit_params = pipeline.params.fit;
        let write = |path: &Path, m: &quadrille::mesh::PolyMesh| -> Result<(), String> {
            let name = path.display().to_string();
            let world: Vec<_> = frame.points_to_world(&m.positions);
            let bytes = quadrille::io::write_by_extension(&name, &world, &m.to_face_list())
                .map_err(|e| e.to_string())?;
            std::fs::write(path, bytes).map_err(|e| format!("{name}: {e}"))
        };
        if let Some(path) = &args.control {
            write_control(path, result, &frame)?;
        }
        if let Some(path) = &args.limit {
            if args.limit_levels == fit_params.error_levels {
                write(path, &result.limit)?;
            } else {
                write(
                    path,
                    &subdivision::limit_mesh_creased(
                        &result.control,
                        &result.sharp,
                        args.limit_levels,
                        fit_params.boundary,
                    ),
                )?;
            }
        }
    }
    // What of the input's boundaries and parts the output lost is said on
    // every run, not only in the stats.
    let t0 = std::time::Instant::now();
    let metrics = match (&args.stats, &surface) {
        (Some(_), Some(surface)) => Some(quadrille::metrics::metrics(
            mesh,
            &pipeline.input.mesh,
            surface,
        )),
        _ => None,
    };
    let metrics_ms = t0.elapsed().as_secs_f64() * 1e3;
    let preservation = metrics.as_ref().map_or_else(
        || quadrille::metrics::preservation_metrics(mesh, &pipeline.input.mesh),
        |m| m.preservation.clone(),
    );
    if let Some(warning) = preservation.warning() {
        eprintln!("warning: {}: {warning}", args.input.display());
    }
    if let Some(stats) = &args.stats {
        let metrics = metrics.ok_or("the input has no triangles")?;
        let mut timings = serde_json::Map::new();
        timings.insert("import".into(), serde_json::json!(import_ms));
        for (stage, ms) in &pipeline.timings {
            timings.insert(stage.name().into(), serde_json::json!(ms));
        }
        timings.insert("metrics".into(), serde_json::json!(metrics_ms));
        let extracted = pipeline.extraction.as_ref().map(|e| &e.extracted);
        let extraction = extracted.and_then(|e| e.local()).map(|e| &e.report);
        let qex = extracted.and_then(|e| e.qex());
        let parametrization = pipeline.parametrization.as_ref().map(|s| {
            serde_json::json!({
                "cones": s.run.map.cones.len(),
                "measures": s.run.measures,
                "integer_conflicts": s.run.map.conflicts,
                "timings": s.run.timings,
            })
        });
        let json = serde_json::json!({
            "input": args.input.display().to_string(),
            "output": name,
            "mode": pipeline.params.remesh.mode,
            "target_vertices": target,
            "achieved_vertices": mesh.vertex_count(),
            "vertex_count_error_percent": target.map(|t| 100.0 * (mesh.vertex_count() as f64 - t as f64) / t as f64),
            "length_unit": "largest bounding-box axis of the input (multiply by frame_scale for file units)",
            "frame_scale": frame.scale,
            "metrics": metrics,
            "extraction": extraction,
            "parametrization": parametrization,
            "qex": qex,
            "postprocess": post.result.report,
            "postprocess_repair": post.result.repair,
            "limit_surface": fitted.map(|r| &r.summary),
            "timings_ms": timings,
        });
        let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
        std::fs::write(stats, text).map_err(|e| format!("{}: {e}", stats.display()))?;
    }
    Ok(())
}

/// The command line's options over the parameter file's values (the
/// explicit edge length from file units to the normalised frame, whose
/// largest axis is `frame_scale` file units).
fn command_line_params(
    args: &RemeshArgs,
    params: &mut quadrille::pipeline::Params,
    frame_scale: f64,
) -> Result<(), String> {
    target_overrides(
        args.vertices,
        args.edge_length,
        &mut params.sizing,
        frame_scale,
    )?;
    if let Some(s) = args.seed {
        params.field.seed = s;
    }
    if let Some(mode) = &args.mode {
        params.remesh.mode = mode.parse()?;
    }
    Ok(())
}

/// `--vertices` and `--edge-length` (in file units; the mesh's largest
/// axis is `frame_scale` file units) over the sizing parameters.
fn target_overrides(
    vertices: Option<usize>,
    edge_length: Option<f64>,
    sizing: &mut quadrille::sizing::SizingParams,
    frame_scale: f64,
) -> Result<(), String> {
    if let Some(v) = vertices {
        if v < 4 {
            return Err("--vertices must be at least 4".into());
        }
        sizing.target_vertex_count = Some(v);
        sizing.edge_length = None;
    }
    if let Some(l) = edge_length {
        if !(l.is_finite() && l > 0.0) {
            return Err("--edge-length must be a positive number".into());
        }
        sizing.edge_length = Some(l / frame_scale);
    }
    Ok(())
}

/// Writes the fitted control mesh by `path`'s extension; OBJ files carry
/// its sharp creases as OpenSubdiv's `t crease` tags, and the other
/// formats, which cannot, say so on stderr.
fn write_control(
    path: &Path,
    result: &quadrille::subdivision::FitResult,
    frame: &quadrille::mesh::Frame,
) -> Result<(), String> {
    let name = path.display().to_string();
    let m = &result.control;
    let world: Vec<_> = frame.points_to_world(&m.positions);
    let creases = result.crease_vertex_pairs();
    let bytes = if quadrille::io::Format::from_extension(&name) == Some(quadrille::io::Format::Obj)
    {
        quadrille::io::write_obj_with_creases(&world, &m.to_face_list(), &creases).into_bytes()
    } else {
        if !creases.is_empty() {
            eprintln!(
                "warning: {name}: this format cannot store the control mesh's {} sharp crease edges; \
                 write .obj to keep them",
                creases.len()
            );
        }
        quadrille::io::write_by_extension(&name, &world, &m.to_face_list())
            .map_err(|e| e.to_string())?
    };
    std::fs::write(path, bytes).map_err(|e| format!("{name}: {e}"))
}

fn metrics_of(mesh: &Path, reference: &Path) -> Result<(), String> {
    use quadrille::mesh::{FaceList, PolyMesh, TriMesh};
    let reference = import(reference)?;
    let bytes = std::fs::read(mesh).map_err(|e| format!("{}: {e}", mesh.display()))?;
    let (_, raw) =
        quadrille::io::read_raw(&bytes, &mesh.display().to_string()).map_err(|e| e.to_string())?;
    // Both in the reference's frame; unreferenced vertices dropped.
    let mut index = vec![u32::MAX; raw.positions.len()];
    let mut positions = Vec::new();
    let mut faces = FaceList::new();
    for f in raw.faces.iter() {
        let g: Vec<u32> = f
            .iter()
            .map(|&v| {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = positions.len() as u32;
                    positions.push(reference.frame.to_local(raw.positions[v as usize]));
                }
                index[v as usize]
            })
            .collect();
        faces.push(&g);
    }
    let surface = quadrille::spatial::SurfaceIndex::new(&reference.mesh)
        .ok_or("the reference has no triangles")?;
    let json = match PolyMesh::from_faces(positions.clone(), &faces) {
        Ok(poly) => serde_json::json!({
            "manifold": true,
            "metrics": quadrille::metrics::metrics(&poly, &reference.mesh, &surface),
        }),
        Err(e) => {
            let topology = quadrille::mesh::Topology::of(positions.len(), &faces);
            let tris = faces.triangulate(&positions);
            let tri = TriMesh::new(positions.clone(), tris).map_err(|e| e.to_string())?;
            let hist = faces.degree_histogram();
            let nonquad = faces.len() - hist.get(4).copied().unwrap_or(0);
            let out = quadrille::spatial::SurfaceIndex::new(&tri);
            let there = positions
                .iter()
                .map(|&p| surface.distance(p))
                .fold(0.0, f64::max);
            let back = out.map_or(f64::NAN, |o| {
                reference
                    .mesh
                    .positions
                    .iter()
                    .map(|&p| o.distance(p))
                    .fold(0.0, f64::max)
            });
            serde_json::json!({
                "manifold": false,
                "why": e.to_string(),
                "topology": topology,
                "vertices": positions.len(),
                "non_quad_percent": 100.0 * nonquad as f64 / faces.len().max(1) as f64,
                "extraordinary_vertex_percent":
                    quadrille::metrics::extraordinary_vertex_percent(positions.len(), &faces),
                "quads": quadrille::metrics::quad_metrics(&positions, &faces),
                "face_degrees": hist,
                "hausdorff": there.max(back),
            })
        }
    };
    print_stdout(&serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?)
}

#[derive(clap::Args)]
struct FitArgs {
    /// The reference surface (.obj, .ply, .stl, .off, .gltf, .glb).
    #[arg(long)]
    reference: PathBuf,
    /// The polygon mesh to fit (any face degrees; manifold edges).
    #[arg(long)]
    mesh: PathBuf,
    /// Where to write the fitted control mesh (OBJ, PLY or OFF by extension).
    #[arg(short, long)]
    output: PathBuf,
    /// Also write the limit surface (the control mesh subdivided
    /// `--limit-levels` times, vertices on the limit surface).
    #[arg(long)]
    limit: Option<PathBuf>,
    /// Subdivision levels of the written limit mesh.
    #[arg(long, default_value_t = 2)]
    limit_levels: u32,
    /// Fitting parameters as JSON (every field optional; see FitParams).
    #[arg(long)]
    params: Option<PathBuf>,
    /// Write the fitting statistics and limit-surface errors as JSON here.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Print progress to stderr.
    #[arg(short, long)]
    verbose: bool,
}

fn fit(args: FitArgs) -> Result<(), String> {
    use quadrille::subdivision::{self, FitParams};
    let started = std::time::Instant::now();
    let params: FitParams = match &args.params {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?
        }
        None => FitParams::default(),
    };
    let reference = import(&args.reference)?;
    let mesh_name = args.mesh.display().to_string();
    let bytes = std::fs::read(&args.mesh).map_err(|e| format!("{mesh_name}: {e}"))?;
    let (_, raw) = quadrille::io::read_raw(&bytes, &mesh_name).map_err(|e| e.to_string())?;
    let (quads, split) = subdivision::poly_mesh_in_frame(&raw, &reference.frame)
        .map_err(|e| format!("{mesh_name}: {e}"))?;
    let load_ms = started.elapsed().as_secs_f64() * 1e3;

    let fitting = std::time::Instant::now();
    let verbose = args.verbose;
    let mut sink = |stage: &str, fraction: f32, message: &str| {
        if verbose {
            eprintln!("[{stage} {:3.0}%] {message}", 100.0 * fraction);
        }
        true
    };
    let mut progress = quadrille::progress::Progress::new(&mut sink, "fit");
    let result = subdivision::fit_control_mesh(&quads, &reference.mesh, &params, &mut progress)
        .map_err(|e| e.to_string())?;
    let fit_ms = fitting.elapsed().as_secs_f64() * 1e3;

    let frame = reference.frame;
    let write = |path: &Path, mesh: &quadrille::mesh::PolyMesh| -> Result<(), String> {
        let name = path.display().to_string();
        let world: Vec<_> = frame.points_to_world(&mesh.positions);
        let bytes = quadrille::io::write_by_extension(&name, &world, &mesh.to_face_list())
            .map_err(|e| e.to_string())?;
        std::fs::write(path, bytes).map_err(|e| format!("{name}: {e}"))
    };
    write_control(&args.output, &result, &frame)?;
    if let Some(path) = &args.limit {
        if args.limit_levels == params.error_levels {
            write(path, &result.limit)?;
        } else {
            let limit = subdivision::limit_mesh_creased(
                &result.control,
                &result.sharp,
                args.limit_levels,
                params.boundary,
            );
            write(path, &limit)?;
        }
    }
    let s = &result.summary;
    eprintln!(
        "fit: {} faces -> {} control faces; limit mean {:.3e} -> {:.3e}, Hausdorff {:.3e} -> {:.3e} \
         (× largest axis); {} iterations{}, {} least-squares steps; {}/{} rays missed; {:.0} ms",
        quads.face_count(),
        s.control_faces,
        s.before.stats.mean,
        s.after.stats.mean,
        s.before.hausdorff,
        s.after.hausdorff,
        s.iterations,
        if s.converged { ", converged" } else { "" },
        s.lspia_iterations,
        s.rays_missed,
        s.rays_cast,
        fit_ms
    );
    if let Some(path) = &args.stats {
        let json = serde_json::json!({
            "reference": args.reference.display().to_string(),
            "mesh": mesh_name,
            "input_faces": quads.face_count(),
            "input_vertices": quads.vertex_count(),
            "split_nonmanifold_vertices": split,
            "params": params,
            "distance_units": "fraction of the reference's largest bounding-box axis",
            "reference_scale": frame.scale,
            "fit": s,
            "time_ms": { "load": load_ms, "fit": fit_ms },
        });
        let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

#[derive(clap::Args)]
struct ParamArgs {
    input: PathBuf,
    /// Output OBJ with `vt` per corner.
    #[arg(short, long)]
    output: PathBuf,
    /// Target vertex count of the quad mesh (default: input vertices / 16).
    #[arg(long, conflicts_with = "edge_length")]
    vertices: Option<usize>,
    /// Target edge length in the file's units (overrides the count).
    #[arg(long)]
    edge_length: Option<f64>,
    /// Parameters (`quadrille::param::Params`) as JSON, every field optional.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Write cones, flips, Campen §5's measures and timings as JSON here.
    #[arg(long)]
    stats: Option<PathBuf>,
}

fn param(args: ParamArgs) -> Result<(), String> {
    use quadrille::param::{Params, run};
    let name = args.output.display().to_string();
    if !name.to_ascii_lowercase().ends_with(".obj") {
        return Err(format!("{name}: param writes .obj files"));
    }
    let mut params: Params = match &args.params {
        None => Params::default(),
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", p.display()))?
        }
    };
    let start = std::time::Instant::now();
    let imported = import(&args.input)?;
    target_overrides(
        args.vertices,
        args.edge_length,
        &mut params.sizing,
        imported.frame.scale,
    )?;
    let clock = move || start.elapsed().as_secs_f64() * 1e3;
    let import_ms = clock();
    let mesh = &imported.mesh;
    let result =
        run(mesh, &params, &clock).map_err(|e| format!("{}: {e}", args.input.display()))?;
    // The map's mesh: the input, with its holes below the target scale
    // closed (`Params::close_small_holes`).
    let map_mesh = result.map_mesh(mesh);
    let world: Vec<_> = imported.frame.points_to_world(&map_mesh.positions);
    let text = quadrille::param::export::obj_with_uv(&world, &map_mesh.triangles, &result.map);
    std::fs::write(&args.output, text).map_err(|e| format!("{name}: {e}"))?;
    if let Some(path) = &args.stats {
        let stats = serde_json::json!({
            "input": args.input.display().to_string(),
            "vertices": mesh.vertex_count(),
            "measures": result.measures,
            "cones": result.map.cones,
            "e_smooth": result.field.energy,
            "e_orient": result.map.energy,
            "rounding_steps": result.map.rounding_steps,
            "symbolic_analyses": result.map.symbolic_analyses,
            "integer_conflicts": result.map.conflicts,
            "cyclic_loops": quadrille::param::cyclic_loops(&result.prepared, &params).len(),
            "closed_loops": result.map.closed_loops,
            "widened_loops": result.map.widened_loops,
            "import_ms": import_ms,
            "timings": result.timings,
            "total_ms": clock(),
        });
        let text = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

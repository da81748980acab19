//! Times the surface analysis stage by stage, single threaded:
//! `cargo run --release --example bench_analysis [mesh-file]`
//! (default: `../shared/meshes/stanford-bunny.obj`).

use std::time::Instant;

use quadrille::analysis::{
    self, AnalysisParams, CurvatureEstimator, CurvatureParams, FilteredNormalsMode, Sigma,
};
use quadrille::mesh::{FaceAdjacency, VertexAdjacency};
use quadrille::sizing::{self, SizingContext, SizingParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        format!(
            "{}/../shared/meshes/stanford-bunny.obj",
            env!("CARGO_MANIFEST_DIR")
        )
    });
    let bytes = std::fs::read(&path)?;
    let name = path.rsplit('/').next().unwrap_or(&path);
    let imported = quadrille::io::import(&bytes, name)?;
    let mesh = &imported.mesh;
    println!(
        "{name}: {} vertices, {} faces",
        mesh.vertex_count(),
        mesh.face_count()
    );

    let params = AnalysisParams::default();
    let sizing_params = SizingParams::default();
    let mut timer = Timer::default();
    macro_rules! timed {
        ($label:expr, $e:expr) => {
            timer.run($label, || $e)
        };
    }

    let adjacency = timed!("adjacency (vertex + face CSR)", {
        (VertexAdjacency::new(mesh), FaceAdjacency::new(mesh))
    });
    let (adjacency, face_adjacency) = adjacency;
    let (face_normals, vertex_normals, _areas) = timed!("normals + cell areas", {
        (
            analysis::face_normals(mesh),
            analysis::vertex_normals(mesh, params.normal_weighting),
            analysis::barycentric_cell_areas(mesh),
        )
    });
    let curvature = timed!(
        "curvature (cubic fit, 2-ring)",
        analysis::principal_curvatures(
            &mesh.positions,
            &vertex_normals,
            &adjacency,
            &params.curvature
        )
    );
    let averaged = timed!("selection + averaging", {
        let selected = analysis::select_curvature(&curvature, params.selection);
        analysis::average_curvature(&selected, &adjacency, &params.averaging)
    });
    let (context, edge_length) = timed!("sizing field", {
        let context = SizingContext::for_mesh(mesh, &averaged, &sizing_params);
        let lengths = sizing::sizing_field(&averaged, &context, &sizing_params);
        (context, lengths)
    });
    let features = timed!(
        "feature vertices",
        analysis::feature_vertices(&curvature, &adjacency, &params.features)
    );
    let _filtered = timed!(
        "filtered normals (σ = s/2)",
        analysis::filtered_normals(
            mesh,
            &face_adjacency,
            &face_normals,
            Sigma::Uniform(0.5 * context.global_edge_length),
            2.0
        )
    );
    println!("{:<34} {:>9.1} ms", "total (defaults)", timer.total * 1e3);
    println!();
    // Alternatives, not part of the total above.
    let regions = timed!(
        "smooth regions + significance",
        analysis::smooth_regions::smooth_regions(
            mesh,
            &curvature,
            &analysis::smooth_regions::SmoothRegionParams::default()
        )
    );
    println!(
        "  {} regions, {} kept at 70°, {} cyclic",
        regions.region_count(),
        regions.filtered.iter().filter(|&&f| f).count(),
        regions.cyclic.iter().filter(|&&c| c).count()
    );
    let _ = timed!(
        "curvature (discrete sums, 1-ring)",
        analysis::principal_curvatures(
            &mesh.positions,
            &vertex_normals,
            &adjacency,
            &CurvatureParams {
                estimator: CurvatureEstimator::DiscreteSums,
                rings: 1
            }
        )
    );
    let _ = timed!(
        "curvature (cubic fit, 1-ring)",
        analysis::principal_curvatures(
            &mesh.positions,
            &vertex_normals,
            &adjacency,
            &CurvatureParams {
                estimator: CurvatureEstimator::CubicFit,
                rings: 1
            }
        )
    );
    let _ = timed!(
        "filtered normals (sizing-aware)",
        analysis::filtered_normals(
            mesh,
            &face_adjacency,
            &face_normals,
            Sigma::PerFace(&analysis::filtered_normals::face_sigma_from_sizing(
                mesh,
                &edge_length,
                0.5
            )),
            2.0
        )
    );
    let _ = timed!(
        "analyze() with sizing-aware normals",
        analysis::analyze(
            mesh,
            &AnalysisParams {
                filtered_normals: analysis::FilteredNormalsParams {
                    mode: FilteredNormalsMode::SizingAware,
                    ..Default::default()
                },
                ..params
            },
            &sizing_params
        )
    );

    let lengths = &edge_length;
    let (lo, hi) = lengths
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
    println!();
    println!(
        "global edge length s = {:.5}; per-vertex {:.5} … {:.5}; {} feature vertices ({} candidates)",
        context.global_edge_length,
        lo,
        hi,
        features.indices().len(),
        features.candidate.iter().filter(|&&c| c).count()
    );
    Ok(())
}

#[derive(Default)]
struct Timer {
    total: f64,
}

impl Timer {
    fn run<T>(&mut self, label: &str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let value = f();
        let seconds = start.elapsed().as_secs_f64();
        self.total += seconds;
        println!("{label:<34} {:>9.1} ms", seconds * 1e3);
        value
    }
}

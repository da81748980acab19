//! The command line end to end: `quadrille remesh` with a fitted control
//! mesh, its limit surface and the stats file.

mod common;

use std::path::PathBuf;
use std::process::Command;

#[test]
fn remesh_writes_quads_control_mesh_limit_surface_and_stats() {
    let dir = std::env::temp_dir().join(format!("quadrille-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (out, control, limit, stats) = (
        dir.join("spot.obj"),
        dir.join("control.ply"),
        dir.join("limit.obj"),
        dir.join("stats.json"),
    );
    let status = Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .arg("remesh")
        .arg(common::path("spot.obj"))
        .arg("-o")
        .arg(&out)
        .arg("--control")
        .arg(&control)
        .arg("--limit")
        .arg(&limit)
        .args(["--limit-levels", "1"])
        .arg("--stats")
        .arg(&stats)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );

    let read = |p: &PathBuf| {
        quadrille::io::import(&std::fs::read(p).unwrap(), &p.display().to_string()).unwrap()
    };
    let quads = read(&out);
    let cage = read(&control);
    let surface = read(&limit);
    // The control mesh is one Catmull–Clark step of the quad-dominant mesh:
    // pure quads, closed like the input.
    assert!(
        cage.report.face_degrees.iter().all(|&[d, _]| d == 4),
        "{:?}",
        cage.report.face_degrees
    );
    assert_eq!(cage.report.boundary_edges, 0);
    assert_eq!(surface.report.faces, 4 * cage.report.faces);
    assert!(quads.report.vertices > 100);

    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(json["achieved_vertices"], quads.report.vertices);
    let fit = &json["limit_surface"];
    let (before, after) = (
        fit["before"]["stats"]["mean"].as_f64().unwrap(),
        fit["after"]["stats"]["mean"].as_f64().unwrap(),
    );
    assert!(
        after < 0.5 * before,
        "limit mean distance {before} -> {after}"
    );
    assert!(json["timings_ms"]["fit"].as_f64().unwrap() > 0.0);
    for key in [
        "analysis",
        "hierarchy",
        "orientation",
        "position",
        "extraction",
        "postprocess",
    ] {
        assert!(json["timings_ms"][key].is_number(), "timing of {key}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn info_into_a_closed_pipe_is_not_a_panic() {
    // `quadrille info x.obj | head -1`: the reader goes away before the
    // report is written.
    let mut child = Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .arg("info")
        .arg(common::path("stanford-bunny.obj"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

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
    // Spot is closed and one piece: nothing to lose, nothing said.
    assert!(
        !String::from_utf8_lossy(&status.stderr).contains("warning"),
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

#[test]
fn remesh_says_which_input_parts_it_lost() {
    // A 20 × 20 plane and, apart from it, a triangle far smaller than an
    // output edge, which no quad can hold: the run says it was lost, on
    // stderr and in the stats.
    let dir = std::env::temp_dir().join(format!("quadrille-cli-speck-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n = 20;
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            obj += &format!("v {} {} 0\n", i as f64 / n as f64, j as f64 / n as f64);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    let m = (n + 1) * (n + 1);
    obj += &format!(
        "v 0.5 0.5 0.5\nv 0.51 0.5 0.5\nv 0.5 0.51 0.5\nf {} {} {}\n",
        m + 1,
        m + 2,
        m + 3
    );
    let (input, out, stats) = (
        dir.join("speck.obj"),
        dir.join("out.obj"),
        dir.join("stats.json"),
    );
    std::fs::write(&input, obj).unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .arg("remesh")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .arg("--stats")
        .arg(&stats)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning")
            && stderr.contains("1 of the input's 2 parts was lost (1 triangle"),
        "{stderr}"
    );
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    let kept = &json["metrics"]["preservation"];
    assert_eq!(kept["components_lost"], serde_json::json!([1]), "{kept}");
    assert_eq!(kept["loops_kept"], 1, "{kept}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `--mode`: accepted and written to the stats (`mode`), overriding the
/// parameter file's `remesh.mode`; an unknown mode is refused with the
/// modes there are.
#[test]
fn remesh_mode_is_chosen_on_the_command_line_and_reported() {
    let dir = std::env::temp_dir().join(format!("quadrille-cli-mode-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (params, out, stats) = (
        dir.join("params.json"),
        dir.join("out.obj"),
        dir.join("stats.json"),
    );
    std::fs::write(&params, r#"{ "remesh": { "mode": "global" } }"#).unwrap();
    let remesh = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_quadrille"))
            .arg("remesh")
            .arg(common::path("spot.obj"))
            .arg("-o")
            .arg(&out)
            .arg("--stats")
            .arg(&stats)
            .arg("--params")
            .arg(&params)
            .args(extra)
            .output()
            .unwrap()
    };
    let run = remesh(&["--mode", "local"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(json["mode"], "local", "--mode overrides the parameter file");
    assert!(json["qex"].is_null() && json["parametrization"].is_null());
    assert!(
        json["extraction"]["attempts"].is_number(),
        "{}",
        json["extraction"]
    );

    let run = remesh(&["--mode", "sideways"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("'sideways'") && stderr.contains("local") && stderr.contains("global"),
        "{stderr}"
    );
    let help = Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .args(["remesh", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(
        help.contains("--mode <MODE>") && help.contains("global"),
        "{help}"
    );
    // A parameter file's unknown mode is refused too, naming the file.
    std::fs::write(&params, r#"{ "remesh": { "mode": "sideways" } }"#).unwrap();
    let run = remesh(&[]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("params.json") && stderr.contains("sideways"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The global mode end to end on spot (closed, genus 0): a closed,
/// manifold, pure-quad mesh near the target, the stats say `global` with
/// the QEx report and the map's cones, and the control mesh is the quad
/// mesh itself (no Catmull–Clark split: as many control vertices as quad
/// vertices).
#[test]
fn remesh_global_mode_gives_a_closed_pure_quad_mesh_fitted_without_a_split() {
    let dir = std::env::temp_dir().join(format!("quadrille-cli-global-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (out, control, stats) = (
        dir.join("spot.obj"),
        dir.join("control.obj"),
        dir.join("stats.json"),
    );
    let run = Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .arg("remesh")
        .arg(common::path("spot.obj"))
        .arg("-o")
        .arg(&out)
        .arg("--control")
        .arg(&control)
        .arg("--stats")
        .arg(&stats)
        .args(["--mode", "global"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let read = |p: &PathBuf| {
        quadrille::io::import(&std::fs::read(p).unwrap(), &p.display().to_string()).unwrap()
    };
    let quads = read(&out);
    let r = &quads.report;
    assert!(
        r.face_degrees.iter().all(|&[d, _]| d == 4),
        "{:?}",
        r.face_degrees
    );
    assert_eq!(r.boundary_edges, 0);
    assert_eq!((r.nonmanifold_edges, r.nonmanifold_vertices), (0, 0));
    assert_eq!(r.inconsistent_edges, 0);
    assert_eq!(r.genus, Some(0));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(json["mode"], "global");
    assert!(json["extraction"].is_null());
    assert_eq!(json["qex"]["faces"], r.faces, "{}", json["qex"]);
    assert!(json["parametrization"]["cones"].as_u64().unwrap() >= 8);
    assert_eq!(json["metrics"]["topology"]["non_quad_percent"], 0.0);
    let target = json["target_vertices"].as_f64().unwrap();
    let achieved = json["achieved_vertices"].as_f64().unwrap();
    assert!(
        (achieved - target).abs() <= 0.1 * target,
        "{achieved} vertices for a target of {target}"
    );
    let fit = &json["limit_surface"];
    assert_eq!(fit["split"], false);
    assert_eq!(fit["control_vertices"], r.vertices);
    assert_eq!(read(&control).report.vertices, r.vertices);
    for key in [
        "analysis",
        "parametrization",
        "extraction",
        "postprocess",
        "fit",
    ] {
        assert!(json["timings_ms"][key].is_number(), "timing of {key}");
    }
    assert!(json["timings_ms"]["hierarchy"].is_null());
    // A target edge longer than the whole mesh: no integer point, said as
    // the local mode says a too-small target.
    let run = Command::new(env!("CARGO_BIN_EXE_quadrille"))
        .arg("remesh")
        .arg(common::path("spot.obj"))
        .arg("-o")
        .arg(&out)
        .args(["--mode", "global", "--edge-length", "20"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("spot.obj: extraction: no quads")
            && stderr.contains("target vertex count too small"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

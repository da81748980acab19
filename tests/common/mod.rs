//! The shared test meshes (`../shared/meshes`, or `QUADRILLE_MESHES`), one
//! loader for every integration test. A missing mesh fails the test with
//! the path it looked at: no test skips silently because a mesh is absent.
//!
//! Each test crate compiles this module on its own and uses part of it.
#![allow(dead_code)]

use std::path::PathBuf;

use quadrille::io::Imported;
use quadrille::mesh::TriMesh;

/// Every mesh in the shared directory, by file name.
pub const ALL: [&str; 8] = [
    "beetle.obj",
    "cow.obj",
    "fandisk.obj",
    "rocker-arm.obj",
    "spot.obj",
    "stanford-bunny.obj",
    "suzanne.obj",
    "teapot.obj",
];

/// The shared mesh directory: `QUADRILLE_MESHES` when set, else
/// `../shared/meshes` next to the crate (as the Makefile's default).
pub fn meshes_dir() -> PathBuf {
    std::env::var_os("QUADRILLE_MESHES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes"))
}

/// The path of shared mesh `name` (a file name such as `spot.obj`); panics
/// when the file is not there.
pub fn path(name: &str) -> PathBuf {
    let path = meshes_dir().join(name);
    assert!(
        path.is_file(),
        "shared mesh {} is missing (set QUADRILLE_MESHES to the directory holding it)",
        path.display()
    );
    path
}

/// The bytes of shared mesh `name`; panics when it cannot be read.
pub fn bytes(name: &str) -> Vec<u8> {
    let path = path(name);
    std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "shared mesh {}: {e} (set QUADRILLE_MESHES to the directory holding it)",
            path.display()
        )
    })
}

/// Shared mesh `name`, imported (validated, repaired, normalised); panics
/// when it is missing or does not import.
pub fn import(name: &str) -> Imported {
    quadrille::io::import(&bytes(name), name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The triangle mesh of shared mesh `name`.
pub fn mesh(name: &str) -> TriMesh {
    import(name).mesh
}

/// The triangles of `mesh` that `keep` accepts, unreferenced vertices
/// dropped (numbered in order of first use).
pub fn kept_triangles(mesh: &TriMesh, keep: impl Fn(&[u32; 3]) -> bool) -> TriMesh {
    let mut id = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let triangles = mesh
        .triangles
        .iter()
        .filter(|t| keep(t))
        .map(|t| {
            t.map(|v| {
                if id[v as usize] == u32::MAX {
                    id[v as usize] = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                id[v as usize]
            })
        })
        .collect();
    TriMesh::new(positions, triangles).unwrap()
}

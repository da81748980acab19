//! The viewer: a wgpu renderer of plain data (a surface with an optional
//! scalar quantity, line sets, point sets) seen through an orbit camera,
//! with layers that can be shown and hidden. Polyscope's vocabulary:
//! structures (surface, curves, points) and quantities on them (a scalar
//! with a colormap and range; the legend is drawn by the page from
//! [`Viewer::legend`]).
//!
//! The camera, colormaps, scene data and picking are plain Rust and tested
//! natively; only [`gpu`] and the `Viewer` binding need a browser.

pub mod camera;
pub mod colormap;
pub mod scene;
pub mod shaders;

#[cfg(target_arch = "wasm32")]
mod api;
#[cfg(target_arch = "wasm32")]
pub mod gpu;
#[cfg(target_arch = "wasm32")]
pub use api::Viewer;

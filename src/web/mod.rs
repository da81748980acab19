//! The browser side of Quadrille.
//!
//! - [`worker_api`] (wasm32): the `Session` that lives in the Web Worker and
//!   runs the pipeline stage by stage, returning big arrays as typed arrays.
//! - [`viewer`]: the wgpu renderer used on the page's main thread. Its plain
//!   parts (camera, colormaps, scene data, picking, WGSL shaders) build and
//!   test natively; the GPU part and the `Viewer` binding are wasm32 only.
//! - [`mesh_arrays`]: the flat arrays a mesh is drawn from.
//!
//! Every error crosses the boundary as a JS `Error` with its message; a
//! panic is logged, its message kept for `takePanicMessage`, and surfaces
//! in JS as a `RuntimeError` the caller turns into a visible error.

pub mod layout_glue;
pub mod mesh_arrays;
pub mod viewer;

#[cfg(target_arch = "wasm32")]
pub mod worker_api;

#[cfg(target_arch = "wasm32")]
pub mod layout_api;

#[cfg(target_arch = "wasm32")]
pub mod analysis_api;

#[cfg(target_arch = "wasm32")]
mod panic {
    use std::cell::RefCell;
    use wasm_bindgen::prelude::*;

    thread_local! {
        static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
    }

    /// Installs a panic hook that logs the panic (with its location) and
    /// keeps the message so the page can show it.
    #[wasm_bindgen(start)]
    pub fn start() {
        std::panic::set_hook(Box::new(|info| {
            console_error_panic_hook::hook(info);
            let message = info.to_string();
            LAST_PANIC.with(|p| *p.borrow_mut() = Some(message));
        }));
    }

    /// The message of the last panic since the previous call, if any. After
    /// a panic the module's state is not trusted: callers start a new worker.
    #[wasm_bindgen(js_name = takePanicMessage)]
    pub fn take_panic_message() -> Option<String> {
        LAST_PANIC.with(|p| p.borrow_mut().take())
    }

    /// Panics on purpose, so the browser tests can check that a panic in the
    /// worker reaches the page and the app recovers.
    #[wasm_bindgen(js_name = panicForTesting)]
    pub fn panic_for_testing() {
        panic!("deliberate panic for testing");
    }
}

//! The wasm-bindgen boundary for the browser (compiled for wasm32 only).

use wasm_bindgen::prelude::*;

/// Installs the panic hook so a panic shows its message in the console and
/// reaches the page as an error instead of an opaque trap.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// Reads a mesh file and returns its import report as a JS object (what
/// `quadrille info` prints), or throws an `Error` naming the file and place.
#[wasm_bindgen(js_name = importReport)]
pub fn import_report(bytes: &[u8], name: &str) -> Result<JsValue, JsError> {
    let imported = crate::io::import(bytes, name).map_err(|e| JsError::new(&e.to_string()))?;
    let json = serde_json::to_string(&imported.report).map_err(|e| JsError::new(&e.to_string()))?;
    js_sys::JSON::parse(&json).map_err(|_| JsError::new("could not encode the report"))
}

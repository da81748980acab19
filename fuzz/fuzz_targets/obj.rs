//! Fuzzes the OBJ reader: any bytes must give a mesh or an error naming
//! the file, never a panic, a hang or a huge allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let name = "fuzz.obj";
    if let Err(e) = quadrille::io::read_raw(data, name) {
        assert!(e.to_string().starts_with(name));
    }
    if let Err(e) = quadrille::io::import(data, name) {
        assert!(e.to_string().starts_with(name));
    }
});

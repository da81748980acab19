//! The viewer's WGSL shaders, compiled into the library as text. They live
//! outside the wasm-only code so a native test can parse and validate every
//! one with naga (no GPU needed), as rerun does.

/// The input surface: normals, per-vertex colours, headlight.
pub const SURFACE: &str = include_str!("shaders/surface.wgsl");
/// Line layers: one instance per segment, expanded to a screen-space quad.
pub const LINES: &str = include_str!("shaders/lines.wgsl");
/// Point layers: one instance per marker, a round screen-space sprite.
pub const POINTS: &str = include_str!("shaders/points.wgsl");

/// Every shader with its file name, for tests and error messages.
pub const ALL: [(&str, &str); 3] = [
    ("surface.wgsl", SURFACE),
    ("lines.wgsl", LINES),
    ("points.wgsl", POINTS),
];

#[cfg(test)]
mod tests {
    use super::ALL;

    #[test]
    fn every_shader_parses_and_validates() {
        for (name, source) in ALL {
            let module = naga::front::wgsl::parse_str(source)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::empty(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
            for entry in ["vs_main", "fs_main"] {
                assert!(
                    module.entry_points.iter().any(|ep| ep.name == entry),
                    "{name} lacks {entry}"
                );
            }
        }
    }

    #[test]
    fn every_shader_file_is_listed() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/web/viewer/shaders");
        let mut files: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".wgsl"))
            .collect();
        files.sort();
        let mut listed: Vec<String> = ALL.iter().map(|(n, _)| n.to_string()).collect();
        listed.sort();
        assert_eq!(files, listed);
    }
}

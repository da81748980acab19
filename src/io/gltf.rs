//! glTF reader (placeholder until the glTF work lands).
use super::{IoError, RawMesh};

pub fn read(_bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    Err(IoError::in_file(file, "glTF reading is not available yet"))
}

//! STL reader (placeholder until the STL work lands).
use super::{IoError, RawMesh};

/// A binary STL's size is 84 + 50 × (its declared triangle count).
pub fn looks_binary(bytes: &[u8]) -> bool {
    bytes.len() >= 84
        && u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64 * 50 + 84
            == bytes.len() as u64
}

pub fn read(_bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    Err(IoError::in_file(file, "STL reading is not available yet"))
}

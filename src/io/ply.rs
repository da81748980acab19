//! PLY reader and writer (placeholder until the PLY work lands).
use super::{IoError, RawMesh};
use crate::mesh::FaceList;
use glam::DVec3;

/// How a PLY file stores its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

pub fn read(_bytes: &[u8], file: &str) -> Result<RawMesh, IoError> {
    Err(IoError::in_file(file, "PLY reading is not available yet"))
}

pub fn write(_positions: &[DVec3], _faces: &FaceList, _encoding: PlyEncoding) -> Vec<u8> {
    Vec::new()
}

//! stub
use super::{IoError, LoadedMesh, MeshAttributes, WriteOptions};
use crate::mesh::TriMesh;
use std::io::Write;
pub(super) fn read(_bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    Err(IoError::Unsupported {
        path: path.to_string(),
        format: "ply",
        what: "not yet".into(),
    })
}
pub(super) fn write(
    _w: &mut dyn Write,
    _m: &TriMesh,
    _a: &MeshAttributes,
    _o: &WriteOptions,
) -> std::io::Result<()> {
    Err(std::io::Error::other("not yet"))
}

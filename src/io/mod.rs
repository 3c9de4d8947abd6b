//! Mesh file formats: OBJ, OFF, PLY, STL, Medit `.mesh` (one file per format, reader and
//! writer). Writers are atomic: a failure leaves no partial output file.

use thiserror::Error;

/// Errors of reading and writing mesh files.
#[derive(Debug, Error)]
pub enum IoError {
    /// Operating-system error on a path.
    #[error("{path}: {source}")]
    Os {
        /// the file
        path: String,
        /// the OS error
        source: std::io::Error,
    },
}

//! Algorithm 1: the loop over patches.

use thiserror::Error;

/// Errors of Algorithm 1.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// A stage failed on a patch.
    #[error("patch {patch}: {message}")]
    Stage {
        /// which patch
        patch: crate::ids::PatchId,
        /// what failed
        message: String,
    },
}

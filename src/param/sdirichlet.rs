//! Symmetric Dirichlet optimisation (in progress).
use super::*;
/// Options.
#[derive(Clone, Debug, Default)]
pub struct SdOptions {}
/// Log.
#[derive(Clone, Debug, Default)]
pub struct SdLog {}
/// SD.
#[derive(Clone, Debug, Default)]
pub struct SymmetricDirichlet {
    /// options
    pub options: SdOptions,
}
/// optimise.
pub fn optimize_with_log() {}

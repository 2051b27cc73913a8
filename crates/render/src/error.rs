/// Why a render could not be made or a mesh read, split by who is at fault. Messages are lower
/// case and name the problem; the caller adds what it was reading or rendering.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Error {
    /// Inputs that do not make sense: a damaged OBJ file, an index out of range, NaN, settings
    /// that contradict each other (an `spp` that does not divide the samples per vector, ...).
    #[error("{0}")]
    Invalid(String),
    /// Valid inputs beyond what the renderer accepts (image size, triangle count, file size);
    /// checked before anything is allocated from them.
    #[error("limit exceeded: {0}")]
    LimitExceeded(String),
}

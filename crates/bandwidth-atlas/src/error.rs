/// Why an atlas or a PCA model could not be made. Messages are lower case and name the problem;
/// callers add the file name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A configuration value is out of its range.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// An atlas or a model whose fields disagree with each other, or hold a non-finite value.
    #[error("{0}")]
    Invalid(String),
}

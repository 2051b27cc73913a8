/// Why a table could not be read. Messages are lower case and name the problem; the caller adds
/// the file name.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The bytes are not a valid MERL table (short, wrong dimensions, NaN, ...).
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// Why a computation was refused. Messages are lower case; the caller adds context.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The caller asked for something this crate does not compute: no exponents, exponents out
    /// of order or range, a layer size that is not 2:1, images of inconsistent sizes.
    #[error("{0}")]
    InvalidConfig(String),
    /// A result does not fit its number format (`f32` layers; half floats even after scaling).
    #[error("{0}")]
    Overflow(String),
}

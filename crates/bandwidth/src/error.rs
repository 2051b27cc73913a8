/// Why an estimate was refused. Messages are lower case and name the problem.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The wavelet transform refused the (possibly padded) image: NaN or infinite values, or a
    /// size that does not divide by `2^levels`.
    #[error(transparent)]
    Wavelet(#[from] dwt::Error),
    /// The image is too small or has a side that does not allow enough levels (see the crate
    /// documentation, "Sizes").
    #[error("{0}")]
    Size(String),
    /// A configuration value is out of its range.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// Pixel data does not fit the stated size.
    #[error("{what} holds {len} values, expected {width}x{height} = {}", width * height)]
    DataLength { what: &'static str, width: usize, height: usize, len: usize },
    /// An input value is NaN or infinite. `index` is the row-major pixel index.
    #[error("{what} holds a non-finite value at pixel {index}")]
    NonFinite { what: &'static str, index: usize },
    /// Two maps handed to a comparison differ in length.
    #[error("maps differ in length: {0} and {1} values")]
    LengthMismatch(usize, usize),
}

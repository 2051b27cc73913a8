/// Why a transform was refused. Messages are lower case and name the problem.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Error {
    /// The signal or image has no samples.
    #[error("{what} is empty")]
    Empty { what: &'static str },
    /// A decomposition of zero levels was requested (or handed to a reconstruction).
    #[error("zero levels requested: at least one level is needed")]
    ZeroLevels,
    /// `levels` levels do not fit: `dim` (`"length"`, `"width"` or `"height"`) must be divisible by
    /// `2^levels`, and `len` allows at most `max` levels ([`crate::max_levels`]).
    #[error("{dim} {len} is not divisible by 2^{levels}, needed for {levels} level(s); it allows at most {max}")]
    TooManyLevels { dim: &'static str, len: usize, levels: usize, max: usize },
    /// An input value is NaN or infinite. `index` is row-major for images.
    #[error("{what} holds a non-finite value at index {index}")]
    NonFinite { what: String, index: usize },
    /// Coefficient arrays handed to an inverse transform do not fit together.
    #[error("coefficient shapes do not match: {0}")]
    ShapeMismatch(String),
    /// [`crate::Image::new`] got a data vector of the wrong length.
    #[error("image data holds {len} values, expected {width}x{height} = {}", width * height)]
    DataLength { width: usize, height: usize, len: usize },
}

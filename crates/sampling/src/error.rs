/// Why a distribution could not be built. Messages are lower case, name the problem and carry no
/// trailing period; the caller adds which table it was building.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A 1D function with no values.
    #[error("function has no values, need at least one")]
    Empty,
    /// A 2D grid with no rows or no columns.
    #[error("grid is {nu} x {nv}, need nu >= 1 and nv >= 1")]
    EmptyGrid { nu: usize, nv: usize },
    /// A 2D function whose length is not `nu * nv`.
    #[error("function has {len} values, expected nu * nv = {nu} * {nv}")]
    WrongSize { len: usize, nu: usize, nv: usize },
    /// A value that is NaN, infinite or negative. For a 2D function `index` is the row-major
    /// index `iv * nu + iu`.
    #[error("func[{index}] is {value}, expected a finite value >= 0")]
    InvalidValue { index: usize, value: f64 },
    /// A CDF table entry out of place: not 0 first, not 1 last, not finite, or below the entry
    /// before it.
    #[error("cdf[{index}] is {value}, expected a finite table from 0 to 1 that never decreases")]
    InvalidCdf { index: usize, value: f64 },
}

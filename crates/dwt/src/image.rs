use crate::Error;

/// A 2D array of `f64`, row-major: `data[y * width + x]`. Rows (`y`, `0..height`) are numpy's
/// axis 0 and columns (`x`, `0..width`) its axis 1, so an `Image` and a numpy array of shape
/// `(height, width)` hold the same values in the same order.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: usize,
    height: usize,
    data: Vec<f64>,
}

impl Image {
    /// An image from row-major data; fails with [`Error::DataLength`] unless
    /// `data.len() == width * height`.
    pub fn new(width: usize, height: usize, data: Vec<f64>) -> Result<Self, Error> {
        if width.checked_mul(height) != Some(data.len()) {
            return Err(Error::DataLength { width, height, len: data.len() });
        }
        Ok(Self { width, height, data })
    }

    /// An image of zeros.
    pub fn zeros(width: usize, height: usize) -> Self {
        Self { width, height, data: vec![0.0; width * height] }
    }

    /// The image given row by row by `rows`, stored.
    pub fn from_rows(rows: &dyn crate::Rows) -> Self {
        let (width, height) = (rows.width(), rows.height());
        let (mut data, mut buffer) = (Vec::with_capacity(width * height), vec![0.0; width]);
        for r in 0..height {
            data.extend_from_slice(rows.row(r, &mut buffer));
        }
        Self { width, height, data }
    }

    /// An image with `f(x, y)` at column `x`, row `y`.
    pub fn from_fn(width: usize, height: usize, mut f: impl FnMut(usize, usize) -> f64) -> Self {
        let mut data = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Self { width, height, data }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The row-major samples.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    pub fn data_mut(&mut self) -> &mut [f64] {
        &mut self.data
    }

    pub fn into_data(self) -> Vec<f64> {
        self.data
    }

    /// The value at column `x`, row `y`. Panics when outside the image.
    pub fn get(&self, x: usize, y: usize) -> f64 {
        assert!(x < self.width && y < self.height, "({x}, {y}) is outside a {}x{} image", self.width, self.height);
        self.data[y * self.width + x]
    }

    /// Row `y`. Panics when `y >= height`.
    pub fn row(&self, y: usize) -> &[f64] {
        &self.data[y * self.width..(y + 1) * self.width]
    }

    /// Iterates over the rows, top (`y = 0`) first.
    pub fn rows(&self) -> impl Iterator<Item = &[f64]> {
        self.data.chunks_exact(self.width.max(1))
    }

    /// Sum of squares of all samples (the energy an orthogonal transform preserves).
    pub fn energy(&self) -> f64 {
        self.data.iter().map(|v| v * v).sum()
    }
}

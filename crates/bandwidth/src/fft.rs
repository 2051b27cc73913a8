//! The papers' validation reference: a windowed Fourier transform (32 x 32 Hann windows) and the
//! radius holding 95% of the DC-removed energy, per window centre. A diagnostic: it measures
//! something else than the wavelet estimate on real images (crate docs, "Windowed FFT").

use std::f64::consts::TAU;
use std::sync::Arc;

use dwt::Image;
use rayon::prelude::*;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use crate::Error;
use crate::estimate::check_finite;

/// How [`windowed_fft_bandwidth`] reads an image. [`WindowedFftConfig::default`] is the papers'
/// 32 x 32 window with the 95% energy radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowedFftConfig {
    /// Window side in pixels (even, at least 4): 32.
    pub window: usize,
    /// Distance between window centres in pixels: 8.
    pub stride: usize,
    /// Fraction of the window's DC-removed energy inside the reported radius: 0.95.
    pub energy_fraction: f64,
    /// The FFT is `zero_pad` times the window (zero padded), for a finer grid of radii: 2.
    pub zero_pad: usize,
    /// Subtract [`window_spread`] from the radius, so a pure sinusoid reads its own frequency:
    /// on by default.
    pub subtract_window_spread: bool,
    /// Windows whose DC-removed RMS amplitude (Hann-weighted, image units) is below this read 0:
    /// 1e-6, as [`crate::Config::noise_floor`].
    pub noise_floor: f64,
}

impl Default for WindowedFftConfig {
    fn default() -> Self {
        Self {
            window: 32,
            stride: 8,
            energy_fraction: 0.95,
            zero_pad: 2,
            subtract_window_spread: true,
            noise_floor: 1e-6,
        }
    }
}

impl WindowedFftConfig {
    fn check(&self) -> Result<(), Error> {
        if self.window < 4 || !self.window.is_multiple_of(2) || self.window > 4096 {
            return Err(Error::Config(format!("window {} is not an even size in 4..=4096", self.window)));
        }
        if self.stride == 0 {
            return Err(Error::Config("stride 0: windows need a positive stride".to_owned()));
        }
        if !(self.energy_fraction > 0.0 && self.energy_fraction < 1.0) {
            return Err(Error::Config(format!("energy fraction {} is not in (0, 1)", self.energy_fraction)));
        }
        if !(1..=8).contains(&self.zero_pad) {
            return Err(Error::Config(format!("zero pad {} is not in 1..=8", self.zero_pad)));
        }
        if !(self.noise_floor >= 0.0 && self.noise_floor.is_finite()) {
            return Err(Error::Config(format!("noise floor {} is negative or not finite", self.noise_floor)));
        }
        Ok(())
    }
}

/// Windowed-FFT bandwidth at a grid of window centres: centre `(i, j)` is pixel
/// `(window / 2 + i stride, window / 2 + j stride)`; its window covers the pixels
/// `centre - window / 2 .. centre + window / 2` on both axes, all inside the image.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowedFftMap {
    window: usize,
    stride: usize,
    columns: usize,
    rows: usize,
    frequency: Vec<f64>,
}

impl WindowedFftMap {
    /// Number of window centres along a row.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Number of window centres down a column.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Window side in pixels.
    pub fn window(&self) -> usize {
        self.window
    }

    /// The pixel window `(i, j)` is centred on: `(window / 2 + i stride, window / 2 + j stride)`.
    pub fn centre(&self, i: usize, j: usize) -> (usize, usize) {
        assert!(i < self.columns && j < self.rows, "window ({i}, {j}) is outside {}x{}", self.columns, self.rows);
        (self.window / 2 + i * self.stride, self.window / 2 + j * self.stride)
    }

    /// Frequencies in cycles per pixel, one per window, row-major (`j * columns + i`).
    pub fn frequency(&self) -> &[f64] {
        &self.frequency
    }

    /// The frequency of window `(i, j)` in cycles per pixel.
    pub fn frequency_at(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.columns && j < self.rows, "window ({i}, {j}) is outside {}x{}", self.columns, self.rows);
        self.frequency[j * self.columns + i]
    }
}

/// The periodic Hann window of `n` samples, `(1 - cos(2 pi i / n)) / 2`: its peak is sample `n / 2`.
fn hann(n: usize) -> Vec<f64> {
    (0..n).map(|i| 0.5 - 0.5 * (TAU * i as f64 / n as f64).cos()).collect()
}

/// How far, in cycles per pixel, the `window`-sample Hann window widens a spectral line at the
/// energy fraction `fraction`: the frequency `q` below which `fraction` of the window's own
/// energy spectrum `|W(nu)|^2` lies (a one-sided quantile, from a 64-fold zero-padded DFT). A line
/// at `f0` measured through the window puts `fraction` of its energy within radius `f0 + q`, so
/// `q` is what [`windowed_fft_bandwidth`] subtracts. 0.0293 (0.94 bins) for 32 samples at 0.95.
pub fn window_spread(window: usize, fraction: f64) -> f64 {
    let len = 64 * window;
    let fft = FftPlanner::new().plan_fft_forward(len);
    let mut buffer: Vec<Complex<f64>> = hann(window).into_iter().map(|v| Complex::new(v, 0.0)).collect();
    buffer.resize(len, Complex::new(0.0, 0.0));
    fft.process(&mut buffer);
    // Bins in increasing signed frequency: -len/2 .. len/2.
    let power: Vec<f64> = (0..len).map(|i| buffer[(i + len / 2) % len].norm_sqr()).collect();
    let total: f64 = power.iter().sum();
    let mut sum = 0.0;
    for (i, p) in power.iter().enumerate() {
        sum += p;
        if sum >= fraction * total {
            return (i as f64 - (len / 2) as f64) / len as f64;
        }
    }
    0.5
}

/// The papers' reference bandwidth: for every window (see [`WindowedFftMap`]), subtract the
/// Hann-weighted mean, apply the separable Hann window, take the zero-padded 2D FFT, drop the DC
/// bin and report the smallest radius `sqrt(fx^2 + fy^2)` (cycles per pixel) whose disc holds
/// `energy_fraction` of the energy, less [`window_spread`] when configured (clamped at 0).
/// Windows below the noise floor read 0.
pub fn windowed_fft_bandwidth(image: &Image, config: &WindowedFftConfig) -> Result<WindowedFftMap, Error> {
    config.check()?;
    let (w, h, n) = (image.width(), image.height(), config.window);
    if w < n || h < n {
        return Err(Error::Size(format!("image is {w}x{h}, smaller than the {n}x{n} window")));
    }
    check_finite("image", image.data())?;
    let (columns, rows) = ((w - n) / config.stride + 1, (h - n) / config.stride + 1);
    let size = n * config.zero_pad;
    let fft: Arc<dyn Fft<f64>> = FftPlanner::new().plan_fft_forward(size);
    let taper = hann(n);
    let weight_sum: f64 = taper.iter().sum::<f64>().powi(2);
    let weight_sq_sum: f64 = taper.iter().map(|v| v * v).sum::<f64>().powi(2);
    // Every bin of the padded spectrum, by increasing radius (cycles per pixel).
    let signed = |i: usize| if i < size / 2 { i as f64 } else { i as f64 - size as f64 };
    let radius: Vec<f64> = (0..size * size).map(|b| signed(b / size).hypot(signed(b % size)) / size as f64).collect();
    let mut order: Vec<u32> = (0..(size * size) as u32).collect();
    order.sort_by(|&a, &b| radius[a as usize].total_cmp(&radius[b as usize]));
    let spread = if config.subtract_window_spread { window_spread(n, config.energy_fraction) } else { 0.0 };
    let floor_energy = config.noise_floor * config.noise_floor * weight_sq_sum;

    let mut frequency = vec![0.0; columns * rows];
    let scratch_len = fft.get_inplace_scratch_len();
    frequency.par_iter_mut().enumerate().for_each_init(
        || {
            let zero = Complex::new(0.0, 0.0);
            (vec![zero; size * size], vec![zero; size * size], vec![zero; scratch_len])
        },
        |(buffer, transposed, scratch), (index, out)| {
            let (x0, y0) = ((index % columns) * config.stride, (index / columns) * config.stride);
            let patch = |dx: usize, dy: usize| image.get(x0 + dx, y0 + dy);
            let mut mean = 0.0;
            for (dy, wy) in taper.iter().enumerate() {
                for (dx, wx) in taper.iter().enumerate() {
                    mean += wy * wx * patch(dx, dy);
                }
            }
            mean /= weight_sum;
            buffer.fill(Complex::new(0.0, 0.0));
            let mut energy = 0.0;
            for (dy, wy) in taper.iter().enumerate() {
                for (dx, wx) in taper.iter().enumerate() {
                    let v = wy * wx * (patch(dx, dy) - mean);
                    energy += v * v;
                    buffer[dy * size + dx] = Complex::new(v, 0.0);
                }
            }
            if energy <= floor_energy {
                *out = 0.0;
                return;
            }
            // Rows (only the first n hold data), then columns through a transpose; the radius is
            // symmetric in the two axes, so the spectrum can stay transposed.
            fft.process_with_scratch(&mut buffer[..n * size], scratch);
            for r in 0..size {
                for c in 0..size {
                    transposed[c * size + r] = buffer[r * size + c];
                }
            }
            fft.process_with_scratch(transposed, scratch);
            transposed[0] = Complex::new(0.0, 0.0);
            let total: f64 = transposed.iter().map(Complex::norm_sqr).sum();
            let target = config.energy_fraction * total;
            let mut sum = 0.0;
            let mut r = 0.0;
            for &b in &order {
                sum += transposed[b as usize].norm_sqr();
                if sum >= target {
                    r = radius[b as usize];
                    break;
                }
            }
            *out = (r - spread).max(0.0);
        },
    );
    Ok(WindowedFftMap { window: n, stride: config.stride, columns, rows, frequency })
}

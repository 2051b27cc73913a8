//! Convolution in spherical harmonics: the wide lobes.
//!
//! The reference sum `f(r) = sum_j L_j omega_j K(w_j . r)` over the source texel centres `w_j`
//! becomes, with the addition theorem `(2l + 1) / (4 pi) P_l(w . r) = sum_m Y_lm(r) Y_lm*(w)`,
//! `f(r) = sum_lm k_l a_lm Y_lm(r)` where `a_lm = sum_j L_j omega_j Y_lm*(w_j)` and `k_l` are the
//! lobe's Legendre coefficients. Nothing is projected or assumed band-limited: `a_lm` is the same
//! discrete sum over texel centres as the reference, so the only error is the truncation of the
//! lobe's Legendre series at degree `L`.
//!
//! `Y_lm(theta, phi) = P_lm(cos theta) e^{i m phi}` with `P_lm` the orthonormalized associated
//! Legendre functions (no Condon-Shortley sign: it cancels). Per map row the sums over `phi` are
//! one FFT; per column `m` the sums over rows run the three-term recurrence in `l`, for the rows
//! north and south of the equator at once (`P_lm(-x) = (-1)^{l+m} P_lm(x)`). The cost is
//! `O(L^2 (H_source + H_layer) + W H log W)`, independent of the lobe's width beyond `L`.

use std::f64::consts::PI;
use std::sync::Arc;

use envmap::EnvMap;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};

/// `ln` of the smallest starting value `P_mm` worth running the recurrence from (about
/// `1e-200`). From `P_mm` to `P_lm` the functions grow at most by about `(l / m)^m <= e^{l / e}`
/// (near a pole `P_lm(cos theta) ~ J_m((l + 1/2) theta)`, and below its turning point
/// `J_m(z) ~ (z / 2)^m / m!`), so a row whose `P_mm` starts below `e^-460` adds less than
/// `e^{-460 + L / e} < e^-90` to any coefficient up to degree `L <= MAX_DEGREE`: it is skipped
/// (and never runs on slow subnormal numbers).
const LN_TINY: f64 = -460.0;

/// The largest degree this module accepts (see [`LN_TINY`]).
pub(crate) const MAX_DEGREE: usize = 1000;

/// The recurrence steps (one degree, one row pair) of a convolution to degree `l_max` of a map of
/// `source_height` rows into a layer of `height` rows: the cost of [`analyse`] and [`synthesize`].
pub(crate) fn steps(l_max: usize, source_height: usize, height: usize) -> f64 {
    let terms = ((l_max + 1) * (l_max + 2) / 2) as f64;
    terms * (source_height.div_ceil(2) + height.div_ceil(2)) as f64
}

/// Three complex channels as `re, im` pairs: `[re_r, im_r, re_g, im_g, re_b, im_b]`.
type Rgb = [f64; 6];

/// Row pairs are processed this many at a time: the recurrences of different rows are
/// independent, so interleaving them hides the latency of each one's chain.
const LANES: usize = 4;

/// The coefficients `a_lm` of a map up to degree `l_max`, `m >= 0` (those of `-m` are the complex
/// conjugates: the map is real).
pub(crate) struct Coefficients {
    l_max: usize,
    /// Column `m` holds `l = m ..= l_max`, columns one after another.
    values: Vec<Rgb>,
}

impl Coefficients {
    fn column(&self, m: usize) -> &[Rgb] {
        let start = column_offset(m, self.l_max);
        &self.values[start..start + self.l_max - m + 1]
    }
}

fn column_offset(m: usize, l_max: usize) -> usize {
    m * (l_max + 1) - m * m.saturating_sub(1) / 2
}

/// The recurrence of column `m`: `P_mm = c_m sin^m theta`, `P_{m+1,m} = sqrt(2m + 3) x P_mm`,
/// `P_lm = a_l (x P_{l-1,m} - b_l P_{l-2,m})`.
struct Recurrence {
    m: usize,
    ln_c_m: f64,
    /// `a_l`, `b_l` for `l = m + 2 ..= l_max`, at index `l - m - 2`.
    a: Vec<f64>,
    b: Vec<f64>,
}

impl Recurrence {
    fn new(m: usize, l_max: usize, ln_c: &[f64]) -> Recurrence {
        let mf = m as f64;
        let (a, b) = (m + 2..=l_max)
            .map(|l| {
                let lf = l as f64;
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let b = (((lf - 1.0).powi(2) - mf * mf) / (4.0 * (lf - 1.0).powi(2) - 1.0)).sqrt();
                (a, b)
            })
            .unzip();
        Recurrence { m, ln_c_m: ln_c[m], a, b }
    }

    /// `P_mm` at a row of `ln(sin theta) = ln_sin`, or 0 when negligible.
    fn start(&self, ln_sin: f64) -> f64 {
        let ln_p = self.ln_c_m + self.m as f64 * ln_sin;
        if ln_p >= LN_TINY { ln_p.exp() } else { 0.0 }
    }

    /// Calls `visit(l - m, [P_lm(x_j)])` for `l = m ..= m + len - 1` and the lanes' `x`, starting
    /// from their `P_mm`.
    #[inline]
    fn run(&self, x: [f64; LANES], p_mm: [f64; LANES], len: usize, mut visit: impl FnMut(usize, &[f64; LANES])) {
        if len == 0 {
            return;
        }
        visit(0, &p_mm);
        if len == 1 {
            return;
        }
        let c = (2.0 * self.m as f64 + 3.0).sqrt();
        let mut p0 = p_mm;
        let mut p1: [f64; LANES] = std::array::from_fn(|j| c * x[j] * p_mm[j]);
        visit(1, &p1);
        for i in 2..len {
            let (a, b) = (self.a[i - 2], self.b[i - 2]);
            let p2: [f64; LANES] = std::array::from_fn(|j| a * (x[j] * p1[j] - b * p0[j]));
            visit(i, &p2);
            p0 = p1;
            p1 = p2;
        }
    }
}

/// `ln c_m`, `c_m = sqrt((2m + 1)!! / (2m)!! / (4 pi))`, for `m = 0 ..= l_max`.
fn ln_c(l_max: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(l_max + 1);
    let mut acc = -0.5 * (4.0 * PI).ln();
    out.push(acc);
    for m in 1..=l_max {
        let k = m as f64;
        acc += 0.5 * ((2.0 * k + 1.0) / (2.0 * k)).ln();
        out.push(acc);
    }
    out
}

/// Up to [`LANES`] row pairs symmetric about the equator: `x = cos theta` and `ln sin theta` of
/// each northern row (unused lanes have `x = 0` and start at 0), and per `m` the rows' spectra
/// combined as `north + south` (even `l + m`) and `north - south` (odd).
struct Block {
    x: [f64; LANES],
    ln_sin: [f64; LANES],
    used: usize,
    /// `[m][lane]`.
    even: Vec<[Rgb; LANES]>,
    odd: Vec<[Rgb; LANES]>,
}

impl Block {
    fn starts(&self, recurrence: &Recurrence) -> Option<[f64; LANES]> {
        let starts: [f64; LANES] =
            std::array::from_fn(|j| if j < self.used { recurrence.start(self.ln_sin[j]) } else { 0.0 });
        starts.iter().any(|&p| p != 0.0).then_some(starts)
    }
}

/// A row and its mirror image across the equator (none for the middle row of an odd height).
type RowPair = (usize, Option<usize>);

/// The rows of a `height`-row lat-long grid in pairs `(y, height - 1 - y)`.
fn row_pairs(height: usize) -> Vec<RowPair> {
    (0..height.div_ceil(2))
        .map(|y| {
            let south = height - 1 - y;
            (y, (south != y).then_some(south))
        })
        .collect()
}

fn row_cos_ln_sin(y: usize, height: usize) -> (f64, f64) {
    let theta = PI * (y as f64 + 0.5) / height as f64;
    (theta.cos(), theta.sin().ln())
}

/// The coefficients `a_lm`, `l <= l_max`, of the map's texels as point masses `L_j omega_j` at
/// their centres. Calls `tick` once per column `m` done.
pub(crate) fn analyse(map: &EnvMap, l_max: usize, tick: &(dyn Fn() + Sync)) -> Coefficients {
    assert!(l_max <= MAX_DEGREE, "degree {l_max} above {MAX_DEGREE}");
    let (w, h) = (map.width(), map.height());
    let fft = FftPlanner::new().plan_fft_forward(w);
    let phases: Vec<Complex64> = (0..=l_max).map(|m| Complex64::from_polar(1.0, -PI * m as f64 / w as f64)).collect();
    // Row spectra, weighted by the rows' texel solid angle, for m = 0 ..= l_max.
    let spectra: Vec<Vec<Rgb>> = (0..h)
        .into_par_iter()
        .map_init(
            || (vec![Complex64::default(); w], vec![Complex64::default(); fft.get_inplace_scratch_len()]),
            |(buffer, scratch), y| row_spectrum(map, y, &phases, &*fft, buffer, scratch),
        )
        .collect();
    let zero = [0.0; 6];
    let blocks: Vec<Block> = row_pairs(h)
        .chunks(LANES)
        .map(|chunk| {
            let mut block = Block {
                x: [0.0; LANES],
                ln_sin: [0.0; LANES],
                used: chunk.len(),
                even: vec![[zero; LANES]; l_max + 1],
                odd: vec![[zero; LANES]; l_max + 1],
            };
            for (j, &(north, south)) in chunk.iter().enumerate() {
                (block.x[j], block.ln_sin[j]) = row_cos_ln_sin(north, h);
                for (m, n) in spectra[north].iter().enumerate() {
                    let s = south.map_or(&zero, |s| &spectra[s][m]);
                    block.even[m][j] = std::array::from_fn(|k| n[k] + s[k]);
                    block.odd[m][j] = std::array::from_fn(|k| n[k] - s[k]);
                }
            }
            block
        })
        .collect();
    drop(spectra);

    let ln_c = ln_c(l_max);
    let columns: Vec<Vec<Rgb>> = (0..=l_max)
        .into_par_iter()
        .map(|m| {
            let recurrence = Recurrence::new(m, l_max, &ln_c);
            let mut column = vec![zero; l_max - m + 1];
            for block in &blocks {
                let Some(starts) = block.starts(&recurrence) else { continue };
                let (even, odd) = (&block.even[m], &block.odd[m]);
                recurrence.run(block.x, starts, column.len(), |i, p| {
                    let spectrum = if i % 2 == 0 { even } else { odd };
                    let acc = &mut column[i];
                    for (j, s) in spectrum.iter().enumerate() {
                        for k in 0..6 {
                            acc[k] += p[j] * s[k];
                        }
                    }
                });
            }
            tick();
            column
        })
        .collect();
    Coefficients { l_max, values: columns.concat() }
}

/// `omega_y sum_x L(x, y) e^{-i m phi_x}` for `m = 0 ..= l_max`, `phi_x = 2 pi (x + 1/2) / W`: the
/// FFT's bin `m mod W` times `phases[m] = e^{-i pi m / W}`, the phase of the half-texel offset.
fn row_spectrum(
    map: &EnvMap,
    y: usize,
    phases: &[Complex64],
    fft: &dyn Fft<f64>,
    buffer: &mut [Complex64],
    scratch: &mut [Complex64],
) -> Vec<Rgb> {
    let w = map.width();
    let omega = map.texel_solid_angle(y);
    let row = &map.texels()[y * w..(y + 1) * w];
    let mut out = vec![[0.0; 6]; phases.len()];
    for c in 0..3 {
        for (b, texel) in buffer.iter_mut().zip(row) {
            *b = Complex64::new(f64::from(texel[c]) * omega, 0.0);
        }
        fft.process_with_scratch(buffer, scratch);
        for (m, (value, phase)) in out.iter_mut().zip(phases).enumerate() {
            let v = buffer[m % w] * phase;
            value[2 * c] = v.re;
            value[2 * c + 1] = v.im;
        }
    }
    out
}

/// One layer to synthesize: the lobe's Legendre coefficients `k_0 ..= k_L`, `L <= l_max` of the
/// coefficients.
pub(crate) struct LayerSpec {
    pub k: Vec<f64>,
}

/// The convolutions `f(r) = sum_lm k_l a_lm Y_lm(r)` at the texel centres of a `width x height`
/// lat-long grid, one per layer, as interleaved RGB rows. Negative values (truncation ringing
/// where the true value is near 0) are clamped to 0: the true convolution of non-negative
/// radiance is never negative. Calls `tick` once per column `m` and once per layer row.
pub(crate) fn synthesize(
    coeffs: &Coefficients,
    layers: &[LayerSpec],
    width: usize,
    height: usize,
    tick: &(dyn Fn() + Sync),
) -> Vec<Vec<f32>> {
    let l_max = coeffs.l_max;
    assert!(layers.iter().all(|layer| layer.k.len() <= l_max + 1));
    let ln_c = ln_c(l_max);
    let zero = [0.0; 6];
    let pairs = row_pairs(height);
    let blocks: Vec<(&[RowPair], Block)> = pairs
        .chunks(LANES)
        .map(|chunk| {
            let mut block =
                Block { x: [0.0; LANES], ln_sin: [0.0; LANES], used: chunk.len(), even: Vec::new(), odd: Vec::new() };
            for (j, &(north, _)) in chunk.iter().enumerate() {
                (block.x[j], block.ln_sin[j]) = row_cos_ln_sin(north, height);
            }
            (chunk, block)
        })
        .collect();
    // g[m][layer][row]: sum_l k_l a_lm P_lm(x_row).
    let g: Vec<Vec<Vec<Rgb>>> = (0..=l_max)
        .into_par_iter()
        .map(|m| {
            let recurrence = Recurrence::new(m, l_max, &ln_c);
            let a = coeffs.column(m);
            let mut out = vec![vec![zero; height]; layers.len()];
            // Per layer, the products k_l a_lm for l = m ..= L_layer.
            let weighted: Vec<Vec<Rgb>> = layers
                .iter()
                .map(|layer| {
                    let len = layer.k.len().saturating_sub(m);
                    (0..len).map(|i| a[i].map(|v| v * layer.k[m + i])).collect()
                })
                .collect();
            let len = weighted.iter().map(Vec::len).max().unwrap_or(0);
            let mut even = vec![[zero; LANES]; layers.len()];
            let mut odd = vec![[zero; LANES]; layers.len()];
            for (chunk, block) in &blocks {
                if len == 0 {
                    break;
                }
                let Some(starts) = block.starts(&recurrence) else { continue };
                even.iter_mut().chain(odd.iter_mut()).for_each(|s| *s = [zero; LANES]);
                recurrence.run(block.x, starts, len, |i, p| {
                    let sums = if i % 2 == 0 { &mut even } else { &mut odd };
                    for (sum, w) in sums.iter_mut().zip(&weighted) {
                        if let Some(w) = w.get(i) {
                            for (j, s) in sum.iter_mut().enumerate() {
                                for k in 0..6 {
                                    s[k] += p[j] * w[k];
                                }
                            }
                        }
                    }
                });
                for (layer, (e, o)) in out.iter_mut().zip(even.iter().zip(&odd)) {
                    for (j, &(north, south)) in chunk.iter().enumerate() {
                        layer[north] = std::array::from_fn(|k| e[j][k] + o[j][k]);
                        if let Some(south) = south {
                            layer[south] = std::array::from_fn(|k| e[j][k] - o[j][k]);
                        }
                    }
                }
            }
            tick();
            out
        })
        .collect();

    let ifft: Arc<dyn Fft<f64>> = FftPlanner::new().plan_fft_inverse(width);
    let phases: Vec<Complex64> = (0..=l_max)
        .map(|m| Complex64::from_polar(if m == 0 { 1.0 } else { 2.0 }, PI * m as f64 / width as f64))
        .collect();
    layers
        .iter()
        .enumerate()
        .map(|(index, layer)| {
            let degree = layer.k.len().saturating_sub(1);
            let mut rgb = vec![0.0f32; 3 * width * height];
            rgb.par_chunks_mut(3 * width).enumerate().for_each_init(
                || (vec![Complex64::default(); width], vec![Complex64::default(); ifft.get_inplace_scratch_len()]),
                |(buffer, scratch), (y, row)| {
                    for c in 0..3 {
                        buffer.fill(Complex64::default());
                        // f(phi_i) = Re sum_{m >= 0} w_m G_m e^{i m phi_i}, w_0 = 1, w_m = 2, with
                        // phi_i = 2 pi (i + 1/2) / width: fold m into bin m mod width.
                        for (m, (column, phase)) in g.iter().zip(&phases).enumerate().take(degree + 1) {
                            let v = column[index][y];
                            buffer[m % width] += Complex64::new(v[2 * c], v[2 * c + 1]) * phase;
                        }
                        ifft.process_with_scratch(buffer, scratch);
                        for (texel, value) in row.chunks_exact_mut(3).zip(buffer.iter()) {
                            texel[c] = value.re.max(0.0) as f32;
                        }
                    }
                    tick();
                },
            );
            rgb
        })
        .collect()
}

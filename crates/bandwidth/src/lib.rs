//! Local bandwidth of 2D signals (environment maps, BRDF slices, textures, area lights): for
//! every pixel, the highest frequency that carries significant energy around it, estimated from
//! a 2D wavelet decomposition as in the papers (`000` section 2.4 and Appendix A; `001` section
//! 2.3 and Fig. 6), in cycles per pixel or, for lat-long maps, in cycles per radian. A windowed
//! FFT, the papers' validation reference, is included as a diagnostic, with a comparison of two
//! maps. No IO: every function works on memory.
//!
//! # The estimator
//!
//! The image is decomposed with [`dwt::wavedec2`] (D4, PyWavelets' `db2`, periodization)
//! into levels `j = 1` (finest, half the image size) to `J` (coarsest), each holding the
//! orientations `cH`, `cV`, `cD`. The coefficients are the transform's orthonormal ones, not
//! rescaled per level.
//!
//! 1. **`lambda_j(p)`** is the largest `|coefficient|` over the three orientations and over the
//!    level-`j` coefficients whose synthesis support covers pixel `p`. The support of coefficient
//!    `(kx, ky)` is the product of [`Wavelet::support`]`(j, kx)` and `(j, ky)` (`3 2^j - 2`
//!    pixels per axis for D4), wrapped into the image periodically: `p` is covered when
//!    `start <= p + t n < end` for some integer `t`, `n` the image side. Per axis a pixel is
//!    covered by 2 or 3 consecutive coefficients (modulo the grid); a coefficient of a level
//!    whose grid has fewer coefficients than that covers every pixel, more than once. The maximum
//!    is separable: first along `x` over every coefficient row, then along `y`, so each level
//!    costs a few comparisons per pixel.
//! 2. **Eq. 7, finest level first.** With `M = max_j lambda_j(p)`, `j*` is the first level `j`
//!    (going from 1 up) at which `lambda_1 + ... + lambda_j >= eps M` (`eps = 0.01`): the levels
//!    finer than `j*` are negligible together, level `j*` and the finer ones are not. The papers'
//!    "sum over `k = i .. n`" is read as "band `i` and every finer band".
//! 3. **Frequency** `f = c 2^-j*` cycles per pixel, one constant `c` for the mother wavelet's
//!    bandwidth ([`DEFAULT_C`], below).
//!
//! A pixel where every `lambda_j` is zero (after the noise floor) has no significant level:
//! [`BandwidthMap::level_at`] is `None` and its frequency is 0. A flat region near structure is
//! not zero: the coarse coefficients that reach the structure cover it, so it reads a low
//! frequency, lower the farther the structure is. A pixel whose finest level is significant
//! (`j* = 1`) is at the grid's Nyquist limit ([`BandwidthMap::at_nyquist`]): its true bandwidth
//! may be anything from `c / 2` up, which a later tool must say.
//!
//! # Calibration of `c`
//!
//! `c = 2^-2.5 = 0.177`. With `c = 1` (level `j` read as its band's upper edge, `2^-j`), pure
//! sinusoids of periods 8 to 64 pixels (8, 11, 16, 23, 32, 45, 64, including non-dyadic ones) at
//! 0, 30 and 45 degrees on 256 x 256 images read between 2.0 and 3.0 octaves above their
//! frequency on every pixel 24 pixels or more from the border, median 2.49: D4 has two vanishing
//! moments, so a sinusoid of level `j0` leaks into level `j0 - m` at about `8^-m` of its peak
//! (orthonormal 2D coefficients), and `eps = 0.01` makes about two finer levels significant.
//! `c = 2^-2.5` centres that range: sinusoids read within half an octave, 0.8 octave at worst
//! (periods 8 to 64, angles 0 to 90 degrees, three phases). The test
//! `sinusoids::c_is_the_calibrated_constant` redoes the calibration.
//!
//! # Noise floor
//!
//! A level-`j` coefficient whose magnitude is below `noise_floor 2^j` counts as zero: `2^j` is
//! the size of the coefficient a pattern of unit amplitude produces at level `j`, so the floor
//! is an amplitude in the units of the image. Default `1e-6`, for images of O(1) values (the
//! log-luminance below): far above the rounding noise of f64 transforms of values up to about
//! `1e6` (a constant image gives details of order `1e-16` times its value) and far below any
//! visible detail. Without a floor, the eps test is relative per pixel, so a flat image would
//! read its rounding noise as signal.
//!
//! # Sizes and boundaries
//!
//! - [`local_bandwidth`]: the image is one period of a periodic image (the transform's own
//!   boundary), so its right edge meets its left edge. Both sides must divide by `2^J`. By
//!   default `J` is the most the size allows ([`dwt::max_levels2`]), and the size is refused
//!   when that leaves more than 3 coefficients on the shorter side: then the coarsest support
//!   (`3 2^J - 2` pixels) still does not span the image and frequencies down to the image size
//!   would be invisible (1000 x 500 allows only 2 levels). Callers pad or resample such images,
//!   or set [`Config::levels`] knowingly. Levels beyond the image do not exist: `J` never
//!   exceeds the factors of 2 of the sides.
//! - [`local_bandwidth_zero_padded`] (`001` section 2.3): an image of finite extent, zero
//!   outside (an area light, a texture on a finite patch). It is padded with zeros on the right
//!   and bottom to at least twice its size, rounded up to a multiple of `2^J` (any size works),
//!   estimated, and cropped back. Its borders then meet zeros, as the real source does, instead
//!   of the opposite border: a light's true edge reads high, and a dark border does not read
//!   the far side's content through the wrap-around. `J` defaults to the deepest level with at
//!   most 2 coefficients on the shorter padded side; more levels than twice the longer side
//!   allows are refused (they would only analyse zeros).
//! - [`latlong_bandwidth`]: lat-long maps, periodic in `phi` and continued across the poles
//!   (next section). The width must be even, and the extended `width x 2 height` image must
//!   satisfy the periodic rule (1024 x 512 gives 10 levels).
//!
//! # HDR input
//!
//! HDR images are analysed as `ln(1 + Y)`, `Y` the Rec. 709 luminance ([`log1p_luminance`]).
//! On linear values a sun of luminance `1e5` dominates every `lambda_j` it reaches, and the eps
//! test is relative to the largest one, so hundreds of pixels around it would read only the
//! sun's bandwidth. The logarithm compresses highlights to a few units while keeping contrast
//! between dark values, and `ln(1 + Y)` stays finite and smooth at `Y = 0`.
//!
//! # Lat-long maps and angular units
//!
//! Convention, shared with the environment-map loader: a `W x H` map (`W = 2 H`) has pixel
//! `(x, y)` at `u = (x + 1/2) / W`, `v = (y + 1/2) / H`, `phi = 2 pi u`, `theta = pi v`, `theta`
//! measured from `+z` (row 0 touches the `+z` pole) and direction `(sin theta cos phi,
//! sin theta sin phi, cos theta)` ([`latlong_angles`], [`latlong_direction`]).
//!
//! Across a pole the sphere continues in the same column turned by half a turn: the row above
//! row 0 is row 0 shifted by `W / 2`, and likewise below row `H - 1`. The estimator analyses the
//! `W x 2H` image made of the map and, below it, the map flipped upside down and shifted by
//! `W / 2`; that image is periodic in both axes and continuous across both poles, so neither
//! the poles nor the seam at `phi = 0` read as edges. The estimate is cropped to the map.
//!
//! The mapping from the image to the sphere has, at row `y`, singular values `2 pi sin(theta)
//! / W` radians per pixel along a row and `pi / H` down a column
//! ([`latlong_radians_per_pixel`]). A pattern of `f` cycles per pixel in the image direction
//! `d` has `f / s_d` cycles per radian on the sphere, `s_d` the radians per pixel along `d`. The
//! estimator does not know `d`, so the conversion divides by the smaller singular value,
//! `nu = f / min(2 pi sin(theta) / W, pi / H)`, i.e. multiplies by the largest singular value of
//! the mapping from the sphere onto the image, in pixels per radian
//! ([`latlong_pixels_per_radian`], the papers' `lambda_max`). For `W = 2 H` that is
//! `W / (2 pi sin theta)` on every row. This is the conservative direction: the result is never
//! below the angular frequency of the content, whichever way it runs; content that runs along a
//! meridian is overstated by `1 / sin(theta)`: half an octave at 45 degrees of latitude; on
//! `cos(k alpha)` patterns, 2.3 to 3.1 octaves on average within 15 degrees of a pole, where
//! fewer than 10% of the pixels read within an octave. Dividing by the larger one would instead
//! understate content that runs along a parallel near the poles, and a sampling rate must not be
//! understated.
//!
//! Units: [`AngularBandwidthMap::cycles_per_radian`] is in cycles per radian of arc. A pattern
//! `cos(k alpha)`, `alpha` an angle on the sphere, has `k / (2 pi)` cycles per radian; the
//! papers' `nu_a = 2 pi / (2^h lambda_max)`, with `lambda_max` in radians per pixel, is the
//! angular wavenumber in radians of phase per radian, `2 pi` times ours.
//!
//! # Windowed FFT (diagnostic)
//!
//! [`windowed_fft_bandwidth`] is the papers' reference (`001` section 4.1): 32 x 32 windows on a
//! grid of centres (stride 8 by default, windows wholly inside the image, one value per centre,
//! not per pixel), the Hann-weighted mean removed, a separable periodic Hann window, a 2D FFT
//! zero padded to 64 x 64 (radii on a grid of 1/64 cycle per pixel), the DC bin dropped, and the
//! smallest radius whose disc holds 95% of the energy. The window widens every spectral line by
//! its own spread, [`window_spread`] (0.94 bins, 0.029 cycles per pixel, computed from the
//! window alone), which is subtracted; then a sinusoid of period 3 to 16 pixels reads within 5%
//! of its frequency. Longer periods are beyond the window's resolution: 23 pixels reads 11 to
//! 15% high, 32 pixels (one cycle in the window) 10 to 30%. Windows whose Hann-weighted RMS is
//! below the noise floor read 0.
//!
//! The two measure different things on real images: the FFT spreads a step edge's energy over
//! all radii and reads every noisy window near its noise's bandwidth, whatever its amplitude,
//! while the wavelet estimate is relative to the largest level at the pixel (see "Known
//! behaviour": on faint noise beside a strong step the wavelet reads 3 to 7 octaves lower). So
//! it is reported ([`compare_maps`]: percentiles of `log2` ratios and Spearman's rank
//! correlation; [`wavelet_at_windows`] samples the wavelet map at the windows), not gated.
//!
//! # Known behaviour
//!
//! The test is relative to the largest `lambda_j` of the pixel, and the orthonormal coefficients
//! of a pattern or an edge grow as `2^j` with the level, so the coarse levels usually hold `M`:
//!
//! - **Masking by coarser content.** Near a boundary between sinusoids of periods 11 and 45,
//!   the finer side reads the coarser side's large coefficients and its own finer levels fall
//!   below `eps`, so it reads lower; measured, the zone reaches 62 pixels.
//! - **Masking by strong large-scale structure, everywhere the coarsest levels reach** (which is
//!   the whole image). On a 1024 x 512 image with a unit step across the middle, white noise of
//!   amplitude 0.2, 128 rows from the step, reads 0.0014 cycles per pixel (level 7) instead of
//!   the limit; it needs an amplitude of about 1 to read within an octave of the limit (on 256 x
//!   256: 0.5). On real maps a horizon or a bright window may lower the estimate of fine texture
//!   across the whole map. Scaling `lambda_j` by `2^-j` (the pattern's amplitude) removes the
//!   masking (noise of amplitude 0.01 reads at the limit) but makes the finest level significant
//!   for every sinusoid of period below about 23 pixels (D4 then leaks at `4^-m`), so sinusoids
//!   no longer read within an octave; `2^-j/2` is in between and breaks the `1 / sigma` law of
//!   blurred noise (slope -0.67). The orthonormal reading is the one the papers' description and
//!   the calibration support; the choice should be checked on real maps.
//! - A long straight step reads `j* = 1` on images up to 256 pixels (`J <= 8`) and `j* = 2` or 3
//!   at 512 and 1024, for the same reason.
//! - Frequencies above `c / 2 = 0.088` cycles per pixel all read `c / 2` and are flagged.
//!
//! # Readings
//!
//! [`Config::reading`] chooses how eq. 7 compares the levels. [`Reading::Paper`] is Appendix A
//! as printed, with the masking above. [`Reading::LevelNormalized`] scales `lambda_j` by `2^-j`
//! first, so each level counts in units of the amplitude of the pattern it answers: its eq. 7
//! ratio is at least the paper's at every level (the sums gain at least `2^-j`, the largest
//! `lambda` loses at least as much), so it never reads a coarser level, and faint noise beside a
//! strong step reads at the limit instead of 3 octaves below (test `readings`). Its cost is the
//! finest level's leakage on sinusoids of periods below about 23 pixels. Which one serves a
//! renderer is measured end to end, by shading with each (`render::adaptive`, the previewer's
//! adaptive benchmark).
//!
//! # Performance
//!
//! The transform is `dwt`'s (parallel over rows; the details only of the coefficient rows that
//! cover an output row). Per level, the maximum over orientations and the sliding maximum along
//! `x` run on those rows, one row at a time (parallel over levels); the sliding maximum along `y`
//! and eq. 7 run per output row, in bands of 16 rows (parallel over bands), a level's maximum
//! kept while the coefficient rows covering the output row stay the same, in one scratch buffer
//! of `(J + 2) x width` values per rayon job; eq. 7 adds the levels of a whole row at once, each
//! pixel's sum in its own order. The loops are compiled for AVX-512 or AVX2 where the processor
//! has them (the same bits). Nothing is allocated per pixel. [`Workspace`] keeps every buffer
//! between estimates of images of one size, and [`Workspace::levels_top_left`] estimates only a
//! corner of an image given row by row ([`dwt::Rows`]: the bandwidth atlas's continued lobe images,
//! whose rows below the lobe are made as they are read), each pixel as in the whole map.
//! `cargo bench -p bandwidth --bench bandwidth` times a real 1024 x 512 map against one D4
//! decomposition of it (its last report is in `docs/benchmarks.md`).

mod compare;
mod error;
mod estimate;
mod fft;
mod hdr;
mod latlong;

pub use compare::{Comparison, PERCENTILES, compare_maps, spearman, wavelet_at_windows};
pub use dwt::{Image, Wavelet};
pub use error::Error;
pub use estimate::{
    BandwidthMap, Config, DEFAULT_C, Reading, Workspace, level_frequency, local_bandwidth, local_bandwidth_zero_padded,
};
pub use fft::{WindowedFftConfig, WindowedFftMap, window_spread, windowed_fft_bandwidth};
pub use hdr::log1p_luminance;
pub use latlong::{
    AngularBandwidthMap, latlong_angles, latlong_bandwidth, latlong_direction, latlong_pixels_per_radian,
    latlong_radians_per_pixel,
};

//! The angular bandwidth of a measured BRDF's outgoing lobes, precomputed for rendering (`000`
//! section 2.4 and Fig. 8, `001` section 2.3): for each incident direction of a grid, the lobe
//! `f(wi, .)` as an image, its local bandwidth from the `bandwidth` crate's wavelet estimate in
//! cycles per radian, reduced conservatively to a small tile; the tiles packed into one atlas;
//! and the atlas compressed by PCA. No IO: the tools read and write the files.
//!
//! # Pipeline
//!
//! 1. The MERL table becomes one Rec. 709 luminance per cell ([`LuminanceTable`]), read by
//!    `merl`'s trilinear interpolation (equal to `color::luminance` of the RGB lookup to 1e-12
//!    wherever the table holds data; the cells below the horizon continued, "Lobe images").
//! 2. For each row of the incident grid (one `theta_i`), the lobe image: `n x n` pixels
//!    (`Config::analysis_size`, default 1024) of the hemisphere of `wo` ([`LobeMap`]).
//! 3. The image is continued to a periodic `2n x 2n` image by mirroring ([`extend_periodic`])
//!    and handed to [`bandwidth::local_bandwidth`]: D4, `eps = 0.01`, `c = 2^-2.5`, the noise
//!    floor scaled to the lobe's peak, [`analysis_levels`] levels. The estimate of the image's
//!    own pixels, in cycles per pixel, times the map's pixels per radian, is cycles per radian.
//! 4. Each texel of the `t x t` tile (`Config::tile`, default 16) takes the largest value of the
//!    pixels of the hemisphere it covers ([`TileReduction`]).
//! 5. The tiles go into the atlas row-major ([`Atlas`]); [`fit`] makes the PCA model.
//!
//! # Incident directions
//!
//! [`IncidentGrid`]: `lobes x lobes` cells (default 64 x 64, the paper's `n_b = 4096`). Row `j`
//! is `cos(theta_i) = 1 - (j + 1/2) / lobes`, column `i` is `phi_i = 2 pi (i + 1/2) / lobes`.
//!
//! - **Rows in equal steps of `cos(theta_i)`**: every row covers the same solid angle of incident
//!   directions, so a renderer's uniformly distributed samples meet every row equally often; the
//!   steps are finest at grazing incidence (0.9 degrees for the last of 64 rows), where lobes
//!   change fastest (Fresnel, the horizon cutting the lobe, off-specular peaks), and coarsest
//!   near the normal (the first row is at 7.2 degrees), where a lobe is even in `theta_i` and
//!   barely changes.
//! - **Columns in `phi_i`, lobes in their own frame.** Each lobe image is drawn in the frame of
//!   its plane of incidence ([`to_incidence_frame`]), and a MERL table is isotropic (it has no
//!   `phi_h` axis), so every lobe of a row is the same image and the builder analyses each row
//!   once ([`build_atlas`]). The second axis is kept for the paper's layout (64 x 64 lobes of
//!   16 x 16 in a 1024 x 1024 texture), so that a renderer indexes the atlas by `wi` directly,
//!   and so that an anisotropic source fits the same format. In files the repeats are dropped:
//!   an isotropic atlas ([`Atlas::is_isotropic`]) is stored as its rows ([`Atlas::rows`], one
//!   tile per row, 1/64 of the texels) and expanded on reading ([`Atlas::expand_rows`]), and its
//!   PCA is fitted on the rows: `lobes_x` copies of each tile have the same mean and components
//!   as the tiles alone, so the model loses nothing. Drawing the lobes in the tangent frame
//!   instead (with a concentric-disk grid of `wi`) makes the tiles of a ring rotated copies of
//!   each other, which PCA cannot compress: on the 20 shared materials 2% relative RMSE then
//!   needed 186 to 212 of 256 components (a model of 77 to 88% of the atlas's size); in the
//!   frame of the plane of incidence it needs 28 to 52 (4.6 to 8.6 times smaller than the full
//!   grid with one set of coefficients per lobe; fitted on the 64 rows, such a model is 0.56 to
//!   1.03 times the size of the rows themselves: at 2%, PCA saves little over storing each
//!   distinct tile once, and for pink-fabric, K = 52, nothing).
//!
//! # Lobe images
//!
//! [`LobeMap`]: `n x n` pixels over the square `[-1, 1]^2` (column `x` along `a`, row `y` along
//! `-b`), an azimuthal equidistant projection of `wo` in the frame of the plane of incidence:
//! the point `(a, b) = r (cos phi, sin phi)` is `theta_o = (pi / 2) r`, `phi_o - phi_i = phi`.
//! `wi` lies towards `+a`, its mirror direction (a glossy lobe's peak) on the left half. The
//! projection is smooth everywhere, the normal included, and distorts little: along the radius
//! a pixel spans `pi / n` radians everywhere, across it `(2 / n) sin(theta_o) / r`, from
//! `pi / n` at the centre to `2 / n` on the horizon ([`LobeMap::radians_per_pixel`]).
//!
//! The values are the luminance of `f` in 1/sr, linear. The `bandwidth` crate reads HDR
//! environment maps as `ln(1 + Y)` so that a sun does not mask the rest of the map; a BRDF lobe
//! multiplies radiance linearly, and the bandwidth of that product is the one a renderer needs,
//! so the lobe is read as it is. Eq. 7 is relative to each pixel's largest coefficient and the
//! noise floor ([`Config::relative_noise_floor`], 1e-6 of the lobe's peak) scales with the
//! lobe, so the estimate does not depend on the BRDF's scale. On a logarithm, a Phong lobe
//! (a parabola in `ln f`) would read the same bandwidth for every exponent.
//!
//! The corners of the square (`r > 1`, 21% of the pixels, up to `theta_o = 127` degrees) are
//! below the horizon, where the BRDF does not exist. They hold the lobe continued along the
//! radius ([`Sample`]): at depth `t` below the horizon, `6 f(-t) - 8 f(-2t) + 3 f(-3t)` of the
//! values at heights `t`, `2t`, `3t` above it on the same great circle, exact for every
//! quadratic, so the image meets the horizon with its value, slope and curvature and the
//! wavelets (D4 has two vanishing moments) see no edge there. Three pixels down
//! ([`param::CONTINUATION_REACH`]) it has blended into the odd reflection `2 f(0) - f(-t)`,
//! which stays within the lobe's range and reads no further than `t` above the horizon (the
//! three-point rule reads `3t` in, where a narrow lobe is no longer a quadratic, and, 37
//! degrees deep, past the zenith). Lesser continuations leave an edge: an even reflection a kink
//! where the lobe is steep at the horizon (at 64 x 64, broad Phong lobes (n = 2) read the
//! grid's limit on the rim), the odd reflection alone a jump in curvature, which reads the
//! limit where a narrow lobe straddles the horizon (Phong n = 1000 at 512 x 512: 320 of 4096
//! lobes, the last five rows; with the three-point rule, none).
//!
//! Pixels with no table data around them (all eight trilinear corners in columns of the table
//! that hold no data at all, which a damaged or hand-made table may have) are filled with the
//! mean of their neighbours ([`lobe_image`]); on the 20 shared materials none is.
//!
//! The table has an edge of its own at the horizon: MERL tables hold no data for
//! configurations below it, and `merl`'s trilinear lookup leaves those corners out and
//! renormalizes, which holds the lobe flat across the last cell before the horizon. Where a
//! narrow lobe meets the horizon nearly opposite `wi` (grazing incidence, where the half vector
//! swings fast with `wo` and a cell is small in `wo`), the lobe read that way reaches the
//! limit on the horizon's last pixel at any analysis size (`merl-synth phong -n 1000`: rows at
//! theta_i 86.9 and 89.6 degrees at 512, 86.9 at 1024), while the same lobe analytically, or
//! tabulated with values beyond the horizon, reads it in none (test
//! `phong_1000_across_the_horizon_is_resolved_at_the_default_size`). The analysis therefore
//! reads the table with its cells below the horizon continued linearly along `theta_d`
//! ([`LuminanceTable`]); a table of Phong n = 1000 then reads the limit nowhere at the default
//! size. The table's other edge, its cells linear in `sqrt(theta_h)`, a cusp at the mirror
//! direction, is read as it is: reading the first cells linearly in `theta_h` instead changes no
//! count at 512 or 1024.
//!
//! # Boundaries
//!
//! The periodic transform would wrap the square's left edge onto its right edge, i.e. one side
//! of the horizon onto the other. [`extend_periodic`] analyses instead a `2n x 2n` image, the
//! lobe image in its top-left quarter, continued across each of its borders the way the
//! corners continue it below the horizon: the three-point rule for the first pixels, blended
//! into the odd reflection about the border, which carries the slope across; half way to the
//! next border that has blended into the plain mirror image, so that the continuations of
//! opposite borders never meet. Periodic and smooth everywhere. This matters where the
//! square's edge touches the horizon (`phi = 0, 90, 180, 270` degrees): a plain mirror there
//! leaves a kink wherever the lobe is steep, as at grazing
//! incidence, where the mirror direction lies on the `-a` edge. Only the estimate of the
//! top-left `n x n` pixels is kept. (The layer selection's energy shares read the plain mirror
//! tiling instead, [`mirror_tiling`]: there the continuation's ramps would count as the lobe's
//! energy.)
//!
//! # Levels
//!
//! [`analysis_levels`]`(n) = log2(n) - 1` (5 for 64): from the finest level to the one whose
//! wavelets have the scale of the hemisphere's radius (`n / 2` pixels); coarser levels of the
//! `2n` image would only describe the mirror tiling. The `bandwidth` crate's default would take
//! all 7 levels of a 128-pixel image; measured on Phong and real lobes, 5 and 7 give the same
//! staircase, 5 is 13% faster and slightly less dependent on the lobe's orientation.
//!
//! # Units and the grid's limit
//!
//! Cycles per pixel become cycles per radian through the Jacobian: a pattern of `f` cycles per
//! pixel along a direction where a pixel spans `s` radians has `f / s` cycles per radian, and
//! the estimator does not know the direction, so the conversion divides by the smaller span,
//! the tangential one ([`LobeMap::pixels_per_radian`]: `n / pi` at the centre, `n / 2` on the
//! horizon), as the `bandwidth` crate does for lat-long maps. It never understates; content
//! running along the radius is overstated by `theta_o / sin(theta_o)`, at most `pi / 2` (0.65
//! octave) on the horizon. `cos(k alpha)` has `k / (2 pi)` cycles per radian; the papers'
//! `nu_a` is `2 pi` times ours.
//!
//! The finest level reads `c / 2` cycles per pixel, i.e. `0.088 n / pi` cycles per radian at the
//! centre (1.80 for 64) up to `0.088 n / 2` on the horizon (2.83): a pixel whose finest level is
//! significant is at the grid's limit and its true bandwidth may be higher
//! ([`BuildStats::nyquist_pixels`]; the tool reports the lobes). Measured on Phong lobes (tests
//! `phong`): the estimate at the lobe's centre grows like `sqrt(n)` (log-log slope 0.49 over
//! `n` = 2 to 256 at 256 x 256) while the lobe's full width at half maximum is at least 12
//! pixels, and sits at the limit once it is below about 10 (n >= 23 at 64 x 64, n >= 362 at
//! 256 x 256).
//!
//! # Tiles
//!
//! [`TileReduction`]: texel `(tx, ty)` of a `t x t` tile covers the `m x m` pixels
//! `[tx m, (tx + 1) m) x [ty m, (ty + 1) m)` of the analysis grid (`m = n / t`, 4 by default)
//! and holds the largest bandwidth of those of its pixels that lie on the hemisphere (the
//! paper's "reduce it to 16 x 16", made conservative). Texels that cover no pixel of the
//! hemisphere (the tile's corners) copy the nearest texel that does, so that bilinear filtering
//! across the horizon reads the rim's value.
//!
//! # Known behaviour
//!
//! - The estimate comes in octaves (one wavelet level each), times the smooth Jacobian factor.
//! - D4 is not symmetric: the same lobe turned by a quarter turn reads the same level on 70 to
//!   99% of its pixels, and up to 0.3 octave apart on average on the others (measured on Phong
//!   and gold-paint lobes).
//! - The 20 shared materials are rebuilt from neural fits whose input is `sqrt(theta_h)`: their
//!   lobes have a cusp at the mirror direction (gold-paint: 0.2498 at `theta_h = 0`, 0.2583 at
//!   0.75 degrees), which has no finite bandwidth, and every lobe reaches the grid's limit
//!   there.
//!
//! # PCA
//!
//! [`fit`]: every tile is a vector of `t^2` values; the model ([`PcaModel`]) is their mean, the
//! first `K` eigenvectors of the covariance of the centred tiles (by decreasing eigenvalue, from
//! `nalgebra`'s symmetric eigensolver in `f64`), and each lobe's `K` coefficients, stored as
//! `f32`. [`PcaModel::reconstruct`] is `mean + sum_k coefficient_k component_k`. All components
//! reproduce the atlas to 1e-6 of its largest texel; [`Components::MaxRelativeRmse`] keeps the
//! fewest components whose relative RMSE (`|reconstruction - atlas| / |atlas|`, Frobenius norms
//! over all texels) is within the bound. The reconstruction is not conservative: it may read
//! below the atlas.
//!
//! # Performance
//!
//! One analysis per row: 64 lobe images of `n^2` pixels (one trilinear lookup each on the
//! hemisphere, two to four below the horizon) and 64 estimates of the `2n x 2n` continuation,
//! in parallel over rows. The lobe map's samples are computed once, in parallel, for its top
//! half alone: row `n - 1 - y` holds the mirror images of row `y`'s directions
//! ([`LobeMap`]). A lobe image's two mirrored rows are looked up together: for `wi` in the
//! plane of incidence, a direction and its mirror image have the same `theta_h` and `theta_d`
//! and opposite `phi_d`, exactly, so the second row's angles cost a negation. A row in progress
//! holds one set of buffers (the lobe image, the continuation's rows that hold the image, the
//! transform's and the estimator's workspaces, [`bandwidth::Workspace`]), taken from and given
//! back to a pool, so that no row faults in fresh memory. The continuation's rows below the
//! image are made as the transform reads them ([`dwt::Rows`]), each once, as are the band
//! energies' mirror tiling's, never stored; and only the continuation's top-left `n x n`
//! pixels, the image's own, are estimated ([`bandwidth::Workspace::levels_top_left`], whose
//! transform computes the details of the coefficient rows it reads alone). Every step computes
//! what the straightforward version computes, bit for bit, except the band energies' order of
//! summation and the lookups' angles ("Angles": the tests compare them; `cargo bench -p bake
//! --bench stages` times the atlas, row `bandwidth atlas`).
//!
//! The band energies' details are summed as they are made, never stored. The loops (the
//! lookups, with their reads of the table's cells as gathers, the transform's rows, eq. 7, the
//! band energies' sums) are compiled for the best instruction set the processor has, AVX-512 or
//! AVX2 where present, chosen at run time (`pulp`); the compiler never fuses a multiply and an
//! add unasked, so every processor computes the same bits. Of the build's CPU time at the
//! default size, the lookups take about two fifths, the two D4 transforms per row (the
//! continuation's and the band energies' mirror tiling, with their rows made on demand) a
//! little less, eq. 7 with its per-level maxima about a tenth (`perf record
//! target/release/brdf-bandwidth target/merl/gold-paint.binary --out-dir DIR`). `cargo bench -p
//! bandwidth-atlas --bench atlas` times the build (`make bench BENCH=atlas` writes its report into
//! `docs/benchmarks.md`).
//!
//! # Angles
//!
//! The lookups ([`LuminanceTable::lookup`]) take the half and difference angles from
//! `s = wi + wo` by arithmetic alone: `theta_h` is the polar angle of `s`, `theta_d` the angle
//! between `wi` and `s` (`atan2(|wi x s|, wi . s)`), `phi_d` the azimuth of `d` from its
//! components times `rho |s|` (no normalization, no rotation), each by a branch-free `atan2` of
//! this crate's own (a polynomial after reducing the octant and `pi / 4`, within 2 ulp of the
//! system's libm; its tests hold it there on 3 million arguments), so that a block of pairs is
//! one loop the compiler vectorizes (measured with libm's `atan2`, a call per angle and three
//! per lookup: half of the build's time).
//!
//! That moves the last bits of the lobe images. The reference is [`LuminanceTable::lookup_libm`]
//! (libm's `atan2` of the normalized half vector and of `wi` rotated into its frame, as
//! `merl::half_diff`): the grid coordinates are within `1e-13` of its own times their
//! conditioning (`1 / |s|`; `1 / sqrt(theta_h)` for `theta_h`'s square-root spacing,
//! `1 / sin(theta_d)` for `phi_d` near the pole) and the luminance within `1e-13` of the largest
//! of the eight corners (test `fast_angles_equal_libms_to_rounding`, a million random pairs).
//! The band energies ([`view::band_energy`]) are summed as the transform makes each row of
//! coefficients ([`dwt::Workspace2::detail_energy`]: eight partial sums per row and orientation,
//! which vectorize, the rows in order), rather than stored and added one after another, which is
//! bound by the addition's latency: the two orders are each within `m u` of the exact sum of
//! their `m` terms (`u = 2^-53`).
//!
//! On the 20 shared materials at the default settings, against libm's lookups and one sum after
//! another (`cargo run --release -p bandwidth-atlas --example analysis-difference --
//! target/merl/*.binary`, after `make test-data`): every pixel of every row's lobe image within
//! 5e-14 of the lobe's peak, every band energy within 2e-13 and every view bandwidth within
//! 5e-14 (relative); **no texel of any atlas differs** (a pixel's level moves only where a
//! coefficient sits within such a difference of an eq. 7 threshold: none does) and **no row's
//! layer**: `brdf-bandwidth` writes the same files, byte for byte, as it would with libm's lookups
//! and one sum after another, on all 20.

mod analysis;
mod atan;
mod atlas;
mod error;
mod lobe;
pub mod param;
pub mod pca;
pub mod view;

pub use analysis::{Analyser, LobeBandwidth, TileReduction, analysis_levels, extend_periodic, mirror_tiling};
pub use atlas::{Atlas, AtlasBuild, BuildStats, Config, MAX_TEXELS, Parameterization, build_atlas, build_atlas_with};
pub use error::Error;
pub use lobe::{LuminanceTable, lobe_image, lobe_image_from_fn};
pub use param::{IncidentGrid, LobeMap, Sample, to_incidence_frame};
pub use pca::{Components, PcaFit, PcaModel, PcaReport, evaluate, fit};

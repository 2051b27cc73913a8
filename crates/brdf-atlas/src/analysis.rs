//! The bandwidth of one lobe image: the image continued into a periodic image, the `bandwidth`
//! crate's wavelet estimate on it, the conversion to cycles per radian through the lobe map's
//! Jacobian, and the conservative reduction to a tile.

use crate::atlas::Config;
use crate::lobe::{LuminanceTable, fill_holes, render};
use crate::param::{LobeMap, Sample};

/// The per-pixel bandwidth of one lobe at the analysis resolution.
#[derive(Clone, Debug, PartialEq)]
pub struct LobeBandwidth {
    /// Pixels per side of the analysis grid.
    pub size: usize,
    /// The lobe image that was analysed: luminance in 1/sr, row-major, holes filled.
    pub image: Vec<f64>,
    /// Angular bandwidth in cycles per radian, row-major; 0 where the lobe is flat.
    pub cycles_per_radian: Vec<f64>,
    /// The finest significant wavelet level `j*` per pixel: 0 flat, 1 at the grid's Nyquist
    /// limit (the true bandwidth may be higher; see [`Analyser::nyquist_cycles_per_radian`]).
    pub level: Vec<u8>,
}

impl LobeBandwidth {
    /// Number of pixels on the hemisphere ([`LobeMap::inside`]) at the grid's limit
    /// (`level == 1`).
    pub fn nyquist_count(&self) -> usize {
        let map = LobeMap::new(self.size);
        (0..self.level.len()).filter(|&k| self.level[k] == 1 && map.inside(k % self.size, k / self.size)).count()
    }

    /// The tile of this lobe ([`TileReduction`]): `tile x tile` texels, row-major.
    pub fn tile(&self, tile: usize) -> Vec<f32> {
        let mut out = vec![0.0f32; tile * tile];
        TileReduction::new(self.size, tile).reduce(&self.cycles_per_radian, &self.level, &mut out);
        out
    }
}

/// The conservative reduction of a lobe's `size x size` bandwidth to a `tile x tile` tile.
/// Texel `(tx, ty)` covers the `m x m` pixels `[tx m, (tx + 1) m) x [ty m, (ty + 1) m)`
/// (`m = size / tile`). A texel that covers pixels of the hemisphere ([`LobeMap::inside`])
/// holds the largest bandwidth among them; the pixels below the horizon, which only continue
/// the image, never count. A texel that covers none (in the corners of the tile) holds the
/// value of the nearest texel that does, so that filtering across the horizon reads the rim's
/// value.
#[derive(Clone, Debug, PartialEq)]
pub struct TileReduction {
    size: usize,
    tile: usize,
    inside: Vec<bool>,
    /// Per texel: the texel whose value it holds (itself when it covers the hemisphere).
    source: Vec<u32>,
}

impl TileReduction {
    /// The reduction from `size` to `tile` per side; `tile` must divide `size`.
    pub fn new(size: usize, tile: usize) -> Self {
        assert!(tile > 0 && size.is_multiple_of(tile), "tile {tile} does not divide the analysis size {size}");
        let map = LobeMap::new(size);
        let inside: Vec<bool> = (0..size * size).map(|k| map.inside(k % size, k / size)).collect();
        let m = size / tile;
        let covers = |t: usize| {
            let (tx, ty) = (t % tile, t / tile);
            (ty * m..(ty + 1) * m).any(|y| (tx * m..(tx + 1) * m).any(|x| inside[y * size + x]))
        };
        let covering: Vec<usize> = (0..tile * tile).filter(|&t| covers(t)).collect();
        let distance2 = |a: usize, b: usize| {
            let (dx, dy) = ((a % tile) as i64 - (b % tile) as i64, (a / tile) as i64 - (b / tile) as i64);
            dx * dx + dy * dy
        };
        let source = (0..tile * tile)
            .map(|t| {
                // Ties go to the first in row-major order: deterministic.
                let nearest = covering.iter().copied().min_by_key(|&c| (distance2(t, c), c));
                nearest.expect("the centre texel covers the hemisphere") as u32
            })
            .collect();
        Self { size, tile, inside, source }
    }

    /// The texel whose value texel `(tx, ty)` holds.
    pub fn source(&self, tx: usize, ty: usize) -> (usize, usize) {
        let s = self.source[ty * self.tile + tx] as usize;
        (s % self.tile, s / self.tile)
    }

    /// Reduces one lobe (`cycles_per_radian` and `level` per pixel, row-major) into `out`
    /// (`tile^2` texels). Returns the number of texels that cover a pixel of the hemisphere at
    /// the grid's limit (`level == 1`).
    pub fn reduce(&self, cycles_per_radian: &[f64], level: &[u8], out: &mut [f32]) -> usize {
        let (n, t) = (self.size, self.tile);
        let m = n / t;
        let mut nyquist_texels = 0;
        for ty in 0..t {
            for tx in 0..t {
                let (mut best, mut nyquist) = (0.0f64, false);
                for y in ty * m..(ty + 1) * m {
                    for x in tx * m..(tx + 1) * m {
                        let k = y * n + x;
                        if self.inside[k] {
                            best = best.max(cycles_per_radian[k]);
                            nyquist |= level[k] == 1;
                        }
                    }
                }
                out[ty * t + tx] = best as f32;
                nyquist_texels += usize::from(nyquist);
            }
        }
        for (k, &s) in self.source.iter().enumerate() {
            if s as usize != k {
                out[k] = out[s as usize];
            }
        }
        nyquist_texels
    }
}

/// Reusable buffers for one thread: a lobe image, its periodic continuation, hole filling, the
/// per-pixel results.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    pub image: Vec<f64>,
    extended: Vec<f64>,
    holes: Vec<(usize, f64)>,
    pub cycles_per_radian: Vec<f64>,
    pub level: Vec<u8>,
}

/// Everything about the analysis grid that does not depend on the lobe: what its pixels hold,
/// their Jacobian factors, the reduction to a tile.
#[derive(Debug)]
pub struct Analyser {
    config: Config,
    map: LobeMap,
    samples: Vec<Sample>,
    pixels_per_radian: Vec<f64>,
    inside: Vec<bool>,
    reduction: TileReduction,
}

impl Analyser {
    /// The analyser of `config`'s analysis grid. The configuration must be valid
    /// ([`Config::check`]).
    pub fn new(config: &Config) -> Self {
        let n = config.analysis_size;
        let map = LobeMap::new(n);
        let pixels = || (0..n * n).map(move |k| (k % n, k / n));
        let samples = pixels().map(|(x, y)| map.sample(x, y)).collect();
        let pixels_per_radian = pixels().map(|(x, y)| map.pixels_per_radian(x, y)).collect();
        let inside = pixels().map(|(x, y)| map.inside(x, y)).collect();
        Self { config: *config, map, samples, pixels_per_radian, inside, reduction: TileReduction::new(n, config.tile) }
    }

    pub fn map(&self) -> LobeMap {
        self.map
    }

    pub fn reduction(&self) -> &TileReduction {
        &self.reduction
    }

    /// The conversion factor of pixel `(x, y)`, in pixels per radian
    /// ([`LobeMap::pixels_per_radian`]).
    pub fn pixels_per_radian(&self, x: usize, y: usize) -> f64 {
        self.pixels_per_radian[y * self.map.size + x]
    }

    /// The highest bandwidth the grid can report at pixel `(x, y)`, in cycles per radian: the
    /// finest level's `c / 2` cycles per pixel, converted.
    pub fn nyquist_cycles_per_radian(&self, x: usize, y: usize) -> f64 {
        self.config.c / 2.0 * self.pixels_per_radian(x, y)
    }

    /// The bandwidth of the lobe of incidence `theta_i` with its image, in the frame of the
    /// plane of incidence (a convenience that allocates; the atlas builder reuses its buffers).
    /// The table is isotropic, so this is the lobe of every `wi` of polar angle `theta_i`.
    pub fn analyse(&self, table: &LuminanceTable, theta_i: f64) -> LobeBandwidth {
        let mut scratch = Scratch::default();
        self.render(table, theta_i, &mut scratch);
        self.analyse_scratch(&mut scratch);
        self.finish(scratch)
    }

    /// The bandwidth of a lobe image given directly (`size^2` finite luminances, row-major), e.g.
    /// of an analytic BRDF from [`crate::lobe_image_from_fn`].
    pub fn analyse_image(&self, image: Vec<f64>) -> LobeBandwidth {
        assert_eq!(image.len(), self.samples.len(), "a lobe image has size^2 pixels");
        let mut scratch = Scratch { image, ..Scratch::default() };
        self.analyse_scratch(&mut scratch);
        self.finish(scratch)
    }

    fn finish(&self, scratch: Scratch) -> LobeBandwidth {
        LobeBandwidth {
            size: self.map.size,
            image: scratch.image,
            cycles_per_radian: scratch.cycles_per_radian,
            level: scratch.level,
        }
    }

    /// Renders the lobe of incidence `theta_i` (in the frame of the plane of incidence: `wi` at
    /// azimuth 0) into `scratch.image` and fills its holes; returns how many pixels were filled.
    pub(crate) fn render(&self, table: &LuminanceTable, theta_i: f64, scratch: &mut Scratch) -> usize {
        scratch.image.resize(self.samples.len(), 0.0);
        render(table, merl::spherical_dir(theta_i, 0.0), &self.samples, &mut scratch.image);
        fill_holes(self.map.size, &mut scratch.image, &mut scratch.holes)
    }

    /// Analyses `scratch.image` into `scratch.cycles_per_radian` and `scratch.level`: the
    /// periodic continuation
    /// ([`extend_periodic`]), the estimate with [`analysis_levels`] levels and the noise floor
    /// scaled to the lobe's peak, the estimate of the image's own pixels converted to cycles per
    /// radian.
    pub(crate) fn analyse_scratch(&self, scratch: &mut Scratch) {
        let n = self.map.size;
        let e = 2 * n;
        let image = &scratch.image;
        let peak = image.iter().fold(0.0f64, |m, v| m.max(v.abs()));

        let ext = &mut scratch.extended;
        ext.clear();
        ext.resize(e * e, 0.0);
        let (top, bottom) = ext.split_at_mut(e * n);
        for (y, row) in top.chunks_exact_mut(e).enumerate() {
            for (x, &v) in image[y * n..(y + 1) * n].iter().enumerate() {
                row[x] = v;
                row[e - 1 - x] = v;
            }
        }
        for (y, row) in bottom.chunks_exact_mut(e).enumerate() {
            row.copy_from_slice(&top[e * (n - 1 - y)..e * (n - y)]);
        }

        let config = bandwidth::Config {
            eps: self.config.eps,
            c: self.config.c,
            noise_floor: self.config.relative_noise_floor * peak,
            levels: Some(analysis_levels(n)),
            ..bandwidth::Config::default()
        };
        let extended = wavelet::Image::new(e, e, std::mem::take(ext)).expect("sizes match");
        let map = bandwidth::local_bandwidth(&extended, &config).expect("the configuration was checked");
        *ext = extended.into_data();

        scratch.cycles_per_radian.resize(n * n, 0.0);
        scratch.level.resize(n * n, 0);
        for y in 0..n {
            let frequency = &map.frequency()[e * y..][..n];
            let level = &map.level()[e * y..][..n];
            let factors = &self.pixels_per_radian[n * y..][..n];
            let out = &mut scratch.cycles_per_radian[n * y..][..n];
            for ((out, f), s) in out.iter_mut().zip(frequency).zip(factors) {
                *out = f * s;
            }
            scratch.level[n * y..][..n].copy_from_slice(level);
        }
    }

    /// Pixels of the hemisphere at the grid's limit in `scratch.level`.
    pub(crate) fn nyquist_pixels(&self, scratch: &Scratch) -> usize {
        scratch.level.iter().zip(&self.inside).filter(|&(&l, &inside)| l == 1 && inside).count()
    }
}

/// The number of wavelet levels a lobe image of side `n` is analysed with: `log2(n) - 1`, the
/// finest (level 1, half a pixel's period... up to the level whose wavelets have the scale of
/// the hemisphere's radius, `n / 2` pixels (crate docs, "Levels").
pub fn analysis_levels(n: usize) -> usize {
    n.trailing_zeros() as usize - 1
}

/// The periodic continuation of an `n x n` lobe image (row-major) that the analysis reads: the
/// `2n x 2n` image made of the image, its mirror image in `x` to the right, and both mirrored
/// in `y` below. It is periodic and continuous across every border (crate docs, "Boundaries").
pub fn extend_periodic(image: &[f64], n: usize) -> wavelet::Image {
    let e = 2 * n;
    wavelet::Image::from_fn(e, e, |x, y| {
        let (sx, sy) = (if x < n { x } else { e - 1 - x }, if y < n { y } else { e - 1 - y });
        image[sy * n + sx]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_analyser_reads_the_mirrored_continuation() {
        // The analyser's own continuation equals extend_periodic, so the documented function is
        // the one that runs.
        let config = Config { analysis_size: 16, tile: 4, ..Config::default() };
        let analyser = Analyser::new(&config);
        let image: Vec<f64> = (0..256).map(|k| ((k * 37 % 101) as f64).sin()).collect();
        let mut scratch = Scratch { image: image.clone(), ..Scratch::default() };
        analyser.analyse_scratch(&mut scratch);
        let direct = bandwidth::local_bandwidth(
            &extend_periodic(&image, 16),
            &bandwidth::Config { levels: Some(3), noise_floor: 1e-6, ..bandwidth::Config::default() },
        )
        .unwrap();
        for y in 0..16 {
            for x in 0..16 {
                assert_eq!(scratch.level[y * 16 + x], direct.level()[y * 32 + x]);
            }
        }
        let ext = extend_periodic(&image, 16);
        assert!(
            (0..32)
                .all(|y| (0..32).all(|x| ext.get(x, y) == ext.get(31 - x, y) && ext.get(x, y) == ext.get(x, 31 - y)))
        );
    }

    #[test]
    fn corner_texels_copy_the_nearest_hemisphere_texel() {
        let r = TileReduction::new(64, 16);
        // The tile's corner texel lies wholly below the horizon; the centre ones do not.
        assert_ne!(r.source(0, 0), (0, 0));
        assert_eq!(r.source(8, 8), (8, 8));
        assert_eq!(r.source(0, 8), (0, 8));
        let (sx, sy) = r.source(0, 0);
        assert_eq!(r.source(sx, sy), (sx, sy));
        // One pixel per texel: every texel whose pixel is on the hemisphere is its own source.
        let map = LobeMap::new(16);
        let r = TileReduction::new(16, 16);
        for y in 0..16 {
            for x in 0..16 {
                assert_eq!(r.source(x, y) == (x, y), map.inside(x, y));
            }
        }
    }
}

//! The brute-force reference: for one direction `r`, the double-precision sum over every source
//! texel centre `w_j` of `L_j (n + 1) / (2 pi) max(0, w_j . r)^n omega_j`. It costs the whole map
//! per layer texel (half a million terms for a 1024 x 512 map), which is why it is the reference
//! and not the method; the tests and the benchmark use it on a subset of texels.
//!
//! The directions are `envmap`'s own texel directions and solid angles; nothing is shared with the
//! methods but the lobe's definition.

use envmap::EnvMap;
use glam::DVec3;

use crate::lobe::normalization;

const LANES: usize = 4;

/// A map's texels as point masses: the direction of each texel centre and its radiance times its
/// solid angle, as separate arrays.
#[derive(Clone, Debug)]
pub struct Reference {
    direction: [Vec<f64>; 3],
    power: [Vec<f64>; 3],
}

impl Reference {
    pub fn new(map: &EnvMap) -> Reference {
        let (w, h) = (map.width(), map.height());
        let mut direction: [Vec<f64>; 3] = Default::default();
        let mut power: [Vec<f64>; 3] = Default::default();
        for y in 0..h {
            let omega = map.texel_solid_angle(y);
            for x in 0..w {
                let d = map.texel_direction(x, y);
                let rgb = map.texel(x, y);
                for c in 0..3 {
                    direction[c].push(d[c]);
                    power[c].push(f64::from(rgb[c]) * omega);
                }
            }
        }
        Reference { direction, power }
    }

    /// The convolution with the lobe of each exponent at the unit direction `r`, RGB. The
    /// exponents must be increasing (as in [`crate::Config`]); panics otherwise.
    ///
    /// `t^n` is built up along the exponents: `t^{n_k} = (t^{n_{k-1}})^q t^s` with
    /// `n_k = q n_{k-1} + s`, each power by squaring (two squarings per layer for exponents a
    /// factor 4 apart). Its relative rounding error is a few `n` ulps, below `1e-12`. Texels
    /// behind `r` are skipped (their terms are 0), and so are the higher powers of a texel once a
    /// power has underflowed to 0.
    pub fn at(&self, r: DVec3, exponents: &[u32]) -> Vec<[f64; 3]> {
        assert!(exponents.windows(2).all(|w| w[0] < w[1]), "exponents must increase: {exponents:?}");
        let steps: Vec<(u32, u32)> = exponents
            .iter()
            .scan(0u32, |previous, &n| {
                let step = n.checked_div(*previous).map_or((0, n), |q| (q, n % *previous));
                *previous = n;
                Some(step)
            })
            .collect();
        // Four texels at a time in arrays, so that the arithmetic vectorizes; sums per lane.
        let mut sums = vec![[[0.0f64; LANES]; 3]; exponents.len()];
        let [dx, dy, dz] = &self.direction;
        let total = dx.len();
        for start in (0..total).step_by(LANES) {
            let lane = |v: &[f64], j: usize| v.get(start + j).copied().unwrap_or(0.0);
            let t: [f64; LANES] =
                std::array::from_fn(|j| (lane(dx, j) * r.x + lane(dy, j) * r.y + lane(dz, j) * r.z).max(0.0));
            if t.iter().all(|&t| t == 0.0) {
                continue;
            }
            let power: [[f64; LANES]; 3] = std::array::from_fn(|c| std::array::from_fn(|j| lane(&self.power[c], j)));
            let mut p = [1.0; LANES];
            for (sum, &(q, s)) in sums.iter_mut().zip(&steps) {
                let ts = pow_lanes(t, s);
                p = if q == 0 {
                    ts
                } else {
                    let pq = pow_lanes(p, q);
                    std::array::from_fn(|j| pq[j] * ts[j])
                };
                if p.iter().all(|&p| p == 0.0) {
                    break;
                }
                for (sum, power) in sum.iter_mut().zip(&power) {
                    for j in 0..LANES {
                        sum[j] += p[j] * power[j];
                    }
                }
            }
        }
        let sums: Vec<[f64; 3]> = sums.iter().map(|sum| sum.map(|lanes| lanes.iter().sum())).collect();
        sums.iter().zip(exponents).map(|(sum, &n)| sum.map(|s| s * normalization(n))).collect()
    }

    /// The convolution with any zonal lobe at the unit direction `r`, RGB: the same sum with
    /// `lobe.eval(w_j . r)` as the weight (one lobe at a time; the Phong exponents have the faster
    /// [`Reference::at`]).
    pub fn at_lobe(&self, r: DVec3, lobe: &crate::Lobe) -> [f64; 3] {
        let [dx, dy, dz] = &self.direction;
        let mut sum = [0.0f64; 3];
        for j in 0..dx.len() {
            let t = dx[j] * r.x + dy[j] * r.y + dz[j] * r.z;
            if t <= 0.0 {
                continue;
            }
            let weight = lobe.eval(t);
            for (c, s) in sum.iter_mut().enumerate() {
                *s += weight * self.power[c][j];
            }
        }
        sum
    }

    /// [`Reference::at`] at the centre of texel `(x, y)` of a `width x height` lat-long grid.
    pub fn at_texel(&self, x: usize, y: usize, width: usize, height: usize, exponents: &[u32]) -> Vec<[f64; 3]> {
        let (u, v) = envmap::geometry::texel_center_uv(x, y, width, height);
        self.at(envmap::direction(u, v), exponents)
    }
}

/// `t^n` by squaring in every lane.
#[inline]
fn pow_lanes(t: [f64; LANES], n: u32) -> [f64; LANES] {
    let (mut result, mut base, mut e) = ([1.0; LANES], t, n);
    while e > 0 {
        if e & 1 == 1 {
            for j in 0..LANES {
                result[j] *= base[j];
            }
        }
        e >>= 1;
        if e > 0 {
            for b in base.iter_mut() {
                *b *= *b;
            }
        }
    }
    result
}

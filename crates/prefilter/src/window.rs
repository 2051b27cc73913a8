//! Direct summation over the lobe's extent: the narrow lobes.
//!
//! The lobe falls below `WINDOW_EPSILON` of its peak at the angle `a` where `cos^n a = eps`; for
//! every layer texel `r` only the source texels whose centres lie in that cap contribute. Per
//! source row the cap is an interval of `phi` (`cos(phi - phi_r) >= (cos a - cos theta_r cos
//! theta) / (sin theta_r sin theta)`), computed once per layer row, so no texel outside the cap is
//! visited. The cost per layer texel is the number of source texels in the cap: about `(2 pi (1 -
//! cos a)) W H / (4 pi) ~ 1.6 W H / n` at `eps = 1e-9`, more near the poles where texels are
//! small.

use std::f64::consts::PI;

use envmap::EnvMap;
use rayon::prelude::*;

use crate::lobe::{Lobe, normalization};

/// The fraction of its peak below which the lobe is cut off. A source texel of power `P`
/// (radiance times solid angle) just outside the cap would have added at most
/// `eps (n + 1) / (2 pi) P` to a layer texel: with the quarry sun (`P ~ 2.7`) and `n = 4096`,
/// `2e-6`, far below the darkest texels of a real map's layers.
pub(crate) const WINDOW_EPSILON: f64 = 1e-9;

/// The cosine of the cap's angular radius: `eps^(1/n)` for the Phong lobe of exponent `n`, found
/// by bisection for GGX.
pub(crate) fn cap_cos(lobe: &Lobe) -> f64 {
    match lobe {
        Lobe::Phong(n) => (WINDOW_EPSILON.ln() / f64::from(*n)).exp(),
        Lobe::Ggx(g) => g.cap_cos(WINDOW_EPSILON),
    }
}

/// How many source texels [`convolve`] visits for `lobe`, a `source_width x source_height` map and
/// a `width x height` layer (the spans' lengths, averaged over `phi_r`): its cost.
pub(crate) fn visits(lobe: &Lobe, source_width: usize, source_height: usize, width: usize, height: usize) -> f64 {
    let cos_a = cap_cos(lobe);
    let a = cos_a.acos();
    let (sw, sh) = (source_width as f64, source_height as f64);
    let mut total = 0.0;
    for j in 0..height {
        let theta_r = PI * (j as f64 + 0.5) / height as f64;
        let (sin_r, cos_r) = theta_r.sin_cos();
        let y_lo = ((theta_r - a) / PI * sh - 0.5).ceil().max(0.0) as usize;
        let y_end = (((theta_r + a) / PI * sh - 0.5).floor().min(sh - 1.0) + 1.0).max(0.0) as usize;
        for y in y_lo..y_end {
            let (sin_y, cos_y) = (PI * (y as f64 + 0.5) / sh).sin_cos();
            let c = (cos_a - cos_r * cos_y) / (sin_r * sin_y);
            if c <= 1.0 {
                let span = if c > -1.0 { (c.acos() / PI * sw + 1.0).min(sw) } else { sw };
                total += span * width as f64;
            }
        }
    }
    total
}

/// The convolution of `map` with `lobe` at the texel centres of a `width x height` lat-long grid,
/// as interleaved RGB. Calls `tick` once per row done.
pub(crate) fn convolve(map: &EnvMap, lobe: &Lobe, width: usize, height: usize, tick: &(dyn Fn() + Sync)) -> Vec<f32> {
    let (sw, sh) = (map.width(), map.height());
    let cos_a = cap_cos(lobe);
    let a = cos_a.acos();
    let texels = map.texels();
    let phi: Vec<(f64, f64)> = (0..sw).map(|x| (2.0 * PI * (x as f64 + 0.5) / sw as f64).sin_cos()).collect();
    let rows: Vec<(f64, f64, f64)> = (0..sh)
        .map(|y| {
            let (sin, cos) = (PI * (y as f64 + 0.5) / sh as f64).sin_cos();
            (cos, sin, map.texel_solid_angle(y))
        })
        .collect();
    // The Phong lobe's weights are `norm t^n`, built by squaring; GGX's are the lobe itself.
    let norm = match lobe {
        Lobe::Phong(n) => normalization(*n),
        Lobe::Ggx(_) => 1.0,
    };

    let mut rgb = vec![0.0f32; 3 * width * height];
    rgb.par_chunks_mut(3 * width).enumerate().for_each(|(j, out_row)| {
        let theta_r = PI * (j as f64 + 0.5) / height as f64;
        let (sin_r, cos_r) = theta_r.sin_cos();
        // The source rows whose centres lie within `a` of theta_r, and the half-width of the
        // cap's phi interval on each (None: the whole row).
        let y_lo = ((theta_r - a) / PI * sh as f64 - 0.5).ceil().max(0.0) as usize;
        let y_end = ((theta_r + a) / PI * sh as f64 - 0.5).floor().min(sh as f64 - 1.0) + 1.0;
        let mut spans: Vec<(usize, Option<f64>)> = Vec::new();
        let y_end = (y_end.max(0.0) as usize).max(y_lo);
        for (y, &(cos_y, sin_y, _)) in rows.iter().enumerate().take(y_end).skip(y_lo) {
            let (aa, bb) = (cos_r * cos_y, sin_r * sin_y);
            let c = (cos_a - aa) / bb;
            if c > 1.0 {
                continue;
            }
            spans.push((y, (c > -1.0).then(|| c.acos())));
        }
        let mut ts = Vec::new();
        let mut base = Vec::new();
        for (i, out) in out_row.chunks_exact_mut(3).enumerate() {
            let phi_r = 2.0 * PI * (i as f64 + 0.5) / width as f64;
            let (sin_pr, cos_pr) = phi_r.sin_cos();
            let mut sum = [0.0f64; 3];
            for &(y, half_width) in &spans {
                let (cos_y, sin_y, omega) = rows[y];
                let (aa, bb) = (cos_r * cos_y, sin_r * sin_y);
                let (bc, bs) = (bb * cos_pr, bb * sin_pr);
                let (x_lo, count) = match half_width {
                    Some(d) => {
                        let lo = ((phi_r - d) / (2.0 * PI) * sw as f64 - 0.5).ceil() as i64;
                        let hi = ((phi_r + d) / (2.0 * PI) * sw as f64 - 0.5).floor() as i64;
                        if hi < lo {
                            continue;
                        }
                        (lo, ((hi - lo + 1) as usize).min(sw))
                    }
                    None => (0, sw),
                };
                let start = x_lo.rem_euclid(sw as i64) as usize;
                let row = &texels[y * sw..(y + 1) * sw];
                // The span wraps around phi = 0 at most once: two contiguous segments.
                let first = count.min(sw - start);
                let mut row_sum = [0.0f64; 3];
                for (from, len) in [(start, first), (0, count - first)] {
                    if len == 0 {
                        continue;
                    }
                    let segment = from..from + len;
                    ts.clear();
                    ts.extend(phi[segment.clone()].iter().map(|&(s, c)| aa + bc * c + bs * s));
                    match lobe {
                        Lobe::Phong(n) => pow_n_in_place(&mut ts, &mut base, *n, cos_a),
                        Lobe::Ggx(g) => ts.iter_mut().for_each(|t| *t = if *t >= cos_a { g.eval(*t) } else { 0.0 }),
                    }
                    for (&weight, texel) in ts.iter().zip(&row[segment]) {
                        for (s, &v) in row_sum.iter_mut().zip(texel) {
                            *s += weight * f64::from(v);
                        }
                    }
                }
                for (s, r) in sum.iter_mut().zip(row_sum) {
                    *s += omega * r;
                }
            }
            for (o, s) in out.iter_mut().zip(sum) {
                *o = (norm * s) as f32;
            }
        }
        tick();
    });
    rgb
}

/// `t <- t^n` for every `t >= cut`, 0 below, by squaring: the loop over the bits of `n` outside,
/// the loops over the values inside, so that they vectorize. The same products as
/// [`crate::lobe::pow_n`], so the result is identical.
fn pow_n_in_place(ts: &mut [f64], base: &mut Vec<f64>, n: u32, cut: f64) {
    base.clear();
    base.extend(ts.iter().map(|&t| if t >= cut { t } else { 0.0 }));
    ts.fill(1.0);
    let mut e = n;
    while e > 0 {
        if e & 1 == 1 {
            for (r, &b) in ts.iter_mut().zip(base.iter()) {
                *r *= b;
            }
        }
        e >>= 1;
        if e > 0 {
            for b in base.iter_mut() {
                *b *= *b;
            }
        }
    }
}

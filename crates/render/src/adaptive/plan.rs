//! The pyramids and the plan: which blocks are shaded and how the others are up-sampled (module
//! docs, "The pyramid" and "Coarse to fine").

use glam::DVec3;
use rayon::prelude::*;

use crate::error::Error;

use super::*;

/// One level of the pyramid: `width x height` blocks of `2^level` pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub level: usize,
    pub width: usize,
    pub height: usize,
    /// The min pyramid: the least level of the block's pixels, -1 when one is not shadeable.
    pub min_level: Vec<i32>,
    /// The max pyramid of the predicted variance.
    pub max_variance: Vec<f64>,
}

impl Level {
    /// Whether block `b` may be shaded at this level or coarser (module docs).
    pub fn valid(&self, b: usize) -> bool {
        self.min_level[b] >= self.level as i32
    }

    /// The render pixel block `(bx, by)` is shaded with: `b 2^k + floor(2^k / 2)` per axis,
    /// clamped to the image.
    pub fn pixel(&self, bx: usize, by: usize, width: usize, height: usize) -> (usize, usize) {
        block_pixel(self.level, bx, by, width, height)
    }
}

/// The render pixel block `(bx, by)` of level `level` stands for: `b 2^k + floor(2^k / 2)` per
/// axis, clamped to the `width x height` image.
pub(super) fn block_pixel(level: usize, bx: usize, by: usize, width: usize, height: usize) -> (usize, usize) {
    let (size, half) = (1usize << level, (1usize << level) / 2);
    ((bx * size + half).min(width - 1), (by * size + half).min(height - 1))
}

/// The render pixels around a pixel whose levels bound its own ([`grade_levels`]): a square of
/// `2 GRADE_RADIUS + 1` on a side, a prediction block's width at the default
/// [`Settings::predict_level`] (module docs, "The pyramid").
pub const GRADE_RADIUS: usize = 4;

/// How many levels coarser than the finest shadeable pixel within [`GRADE_RADIUS`] a pixel may be.
pub const GRADE_SLACK: i32 = 1;

/// Grades the predicted levels (module docs, "The pyramid"): each shadeable pixel's level is at
/// most [`GRADE_SLACK`] more than the least level of the shadeable pixels within
/// [`GRADE_RADIUS`] (Chebyshev distance, clamped to the image); pixels that are not shadeable
/// (level -1) stay so and bound nothing. A separable minimum, rows then columns.
pub fn grade_levels(predictions: &mut [Prediction], width: usize, height: usize) {
    let level: Vec<i32> = predictions.iter().map(|p| p.level).collect();
    let least = |values: &mut dyn Iterator<Item = i32>| values.filter(|&l| l >= 0).min().unwrap_or(i32::MAX);
    let rows: Vec<i32> = (0..height * width)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let span = x.saturating_sub(GRADE_RADIUS)..=(x + GRADE_RADIUS).min(width - 1);
            least(&mut span.map(|q| level[y * width + q]))
        })
        .collect();
    for (i, p) in predictions.iter_mut().enumerate() {
        if p.level < 0 {
            continue;
        }
        let (x, y) = (i % width, i / width);
        let span = y.saturating_sub(GRADE_RADIUS)..=(y + GRADE_RADIUS).min(height - 1);
        let m = span.map(|q| rows[q * width + x]).min().unwrap_or(i32::MAX);
        p.level = p.level.min(m.saturating_add(GRADE_SLACK));
    }
}

/// The min and max pyramids of a bandwidth buffer of `width x height` pixels, levels `0..=top`.
pub fn pyramid(predictions: &[Prediction], width: usize, height: usize, top: usize) -> Vec<Level> {
    let mut levels = vec![Level {
        level: 0,
        width,
        height,
        min_level: predictions.iter().map(|p| p.level).collect(),
        max_variance: predictions.iter().map(|p| p.variance).collect(),
    }];
    for k in 1..=top {
        let child = &levels[k - 1];
        let (w, h) = (child.width.div_ceil(2), child.height.div_ceil(2));
        let mut min_level = vec![i32::MAX; w * h];
        let mut max_variance = vec![0.0f64; w * h];
        for cy in 0..child.height {
            for cx in 0..child.width {
                let (c, b) = (cy * child.width + cx, (cy / 2) * w + cx / 2);
                min_level[b] = min_level[b].min(child.min_level[c]);
                max_variance[b] = max_variance[b].max(child.max_variance[c]);
            }
        }
        levels.push(Level { level: k, width: w, height: h, min_level, max_variance });
    }
    levels
}

/// What happens to a block (module docs, "Coarse to fine").
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Not computed at this level (not valid).
    Skip,
    /// Shaded with this many samples; `rescued` when it could have been up-sampled but its
    /// parents do not represent it (a bilinear parent not valid, or the weights vanish).
    Shade { samples: u32, rescued: bool },
    /// The weighted mean of `count` blocks of the next coarser level: `(index, weight)`, the
    /// weights summing to 1.
    Upsample { parents: [(u32, f32); 4], count: u8 },
}

/// The plan of a frame: every level's actions, fixed by the G-buffer before any shading.
#[derive(Clone, Debug)]
pub struct Plan {
    pub levels: Vec<Level>,
    pub actions: Vec<Vec<Action>>,
    /// The frame's budget of samples.
    pub budget: u64,
}

impl Plan {
    /// The blocks shaded at each level.
    pub fn shaded_per_level(&self) -> Vec<usize> {
        self.actions.iter().map(|a| a.iter().filter(|a| matches!(a, Action::Shade { .. })).count()).collect()
    }

    /// Checks that `other` is this plan to `f32` rounding: the same pyramid, every block the same
    /// action with the same parents and samples, the weights within `tolerance` of each other
    /// (`gpu::preview` plans in `f32`). Returns the largest weight difference, or the first
    /// difference in words.
    pub fn compare(&self, other: &Plan, tolerance: f32) -> Result<f32, String> {
        if self.levels != other.levels {
            return Err("the pyramids differ".into());
        }
        let mut worst = 0.0f32;
        for (k, (a, b)) in self.actions.iter().zip(&other.actions).enumerate() {
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                let same = match (x, y) {
                    (Action::Upsample { parents: p, count: m }, Action::Upsample { parents: q, count: n }) => {
                        worst = p.iter().zip(q).fold(worst, |w, (u, v)| w.max((u.1 - v.1).abs()));
                        m == n && p.iter().zip(q).all(|(u, v)| u.0 == v.0)
                    }
                    _ => x == y,
                };
                if !same {
                    return Err(format!("level {k} block {i}: {x:?} against {y:?}"));
                }
            }
        }
        if worst > tolerance {
            return Err(format!("up-sampling weights differ by {worst:e}"));
        }
        Ok(worst)
    }

    /// The samples the plan spends.
    pub fn samples(&self) -> u64 {
        self.actions
            .iter()
            .flatten()
            .map(|a| match a {
                Action::Shade { samples, .. } => u64::from(*samples),
                _ => 0,
            })
            .sum()
    }
}

/// The least weight a parent counts with (module docs, "Coarse to fine"): `2^-100`, far above
/// the underflow of `f32` (`2^-126`), so that a renderer weighting in `f32` counts the same
/// parents as this one in `f64`.
pub const MIN_WEIGHT: f64 = 7.888609052210118e-31;

/// The up-sampling weights of block `(bx, by)` of `child` from its bilinear parents in `parent`
/// (module docs, "Coarse to fine"); `None` (shade it) when one of them is not valid, or their
/// weights vanish or sum to at most the rescue threshold.
pub(super) fn upsample_weights(
    child: &Level,
    parent: &Level,
    (bx, by): (usize, usize),
    pixels: &[Option<Pixel>],
    (width, height): (usize, usize),
    settings: &Settings,
    sharpness: Option<&[f64]>,
) -> Option<([(u32, f32); 4], u8)> {
    let (depth_sigma, rescue_below) = (settings.depth_sigma, settings.rescue_below);
    let (cx, cy) = child.pixel(bx, by, width, height);
    let me = pixels[cy * width + cx].as_ref()?;
    let spacing = (1usize << parent.level) as f64;
    let centre = |b: usize, level: usize| (b * (1 << level) + (1 << level) / 2) as f64 + 0.5;
    // Bilinear neighbours along one axis: (first parent, fraction towards the second).
    let axis = |b: usize, n: usize| -> (usize, f64) {
        if n == 1 {
            return (0, 0.0);
        }
        let offset = centre(0, parent.level);
        let t = ((centre(b, child.level) - offset) / spacing).clamp(0.0, (n - 1) as f64);
        let first = (t.floor() as usize).min(n - 2);
        (first, t - first as f64)
    };
    let (x0, fx) = axis(bx, parent.width);
    let (y0, fy) = axis(by, parent.height);
    let cos_x = me.cos_o.max(0.1);
    let mut out = [(0u32, 0f32); 4];
    let (mut count, mut total) = (0u8, 0.0f64);
    let mut weights = [0.0f64; 4];
    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let alpha = (if dx == 0 { 1.0 - fx } else { fx }) * (if dy == 0 { 1.0 - fy } else { fy });
        let (px, py) = ((x0 + dx).min(parent.width - 1), (y0 + dy).min(parent.height - 1));
        let b = py * parent.width + px;
        if alpha <= 0.0 || out[..count as usize].iter().any(|(i, _)| *i as usize == b) {
            continue;
        }
        // A parent that is not valid lies where the image needs a finer level (or holds a
        // silhouette): the others would extrapolate across it.
        if !parent.valid(b) {
            return None;
        }
        let (rx, ry) = parent.pixel(px, py, width, height);
        let them = pixels[ry * width + rx].as_ref()?;
        let dz = (me.depth - them.depth) / (depth_sigma * me.depth);
        let g_z = (-0.5 * dz * dz).exp();
        let v = [
            (centre(px, parent.level) - centre(bx, child.level)) / spacing,
            (centre(py, parent.level) - centre(by, child.level)) / spacing,
        ];
        // A normal facing the eye has no screen direction: M is then the identity.
        let [nx, ny] = if me.screen_normal == [0.0; 2] { [1.0, 0.0] } else { me.screen_normal };
        let along = v[0] * nx + v[1] * ny;
        let across = -v[0] * ny + v[1] * nx;
        let g_a = (-(along * along / (cos_x * cos_x) + across * across)).exp();
        let g_lobe = sharpness.map_or(1.0, |rows| {
            let lambda = |p: &Pixel| rows[(((1.0 - p.cos_o) * rows.len() as f64) as usize).min(rows.len() - 1)];
            lobe_similarity(me.mirror, lambda(me), them.mirror, lambda(them))
        });
        let w = g_z * g_a * alpha * g_lobe;
        if w >= MIN_WEIGHT {
            out[count as usize] = (b as u32, 0.0);
            weights[count as usize] = w;
            total += w;
            count += 1;
        }
    }
    if count == 0 || total.is_nan() || total <= rescue_below {
        return None;
    }
    for j in 0..count as usize {
        out[j].1 = (weights[j] / total) as f32;
    }
    Some((out, count))
}

/// The plan of a frame (module docs): which blocks are shaded, with how many samples, and the
/// up-sampling weights of the others. `budget` samples in all.
pub(crate) fn plan(
    levels: Vec<Level>,
    pixels: &[Option<Pixel>],
    (width, height): (usize, usize),
    budget: u64,
    settings: &Settings,
    sharpness: Option<&[f64]>,
) -> Result<Plan, Error> {
    let top = levels.len() - 1;
    let mut actions: Vec<Vec<Action>> = Vec::with_capacity(levels.len());
    for k in (0..=top).rev() {
        let level = &levels[k];
        let row: Vec<Action> = (0..level.width * level.height)
            .into_par_iter()
            .map(|b| {
                if !level.valid(b) {
                    return Action::Skip;
                }
                let (bx, by) = (b % level.width, b / level.width);
                if k < top && levels[k + 1].valid((by / 2) * levels[k + 1].width + bx / 2) {
                    match upsample_weights(
                        level,
                        &levels[k + 1],
                        (bx, by),
                        pixels,
                        (width, height),
                        settings,
                        sharpness,
                    ) {
                        Some((parents, count)) => Action::Upsample { parents, count },
                        None => Action::Shade { samples: 0, rescued: true },
                    }
                } else {
                    Action::Shade { samples: 0, rescued: false }
                }
            })
            .collect();
        actions.push(row);
    }
    actions.reverse();
    allocate(&levels, &mut actions, budget, settings)?;
    Ok(Plan { levels, actions, budget })
}

/// The inner product of two normalized spherical Gaussians `exp(lambda (xi . w - 1))` (`003`
/// eq. 4): 1 for equal lobes, towards 0 as their axes part relative to their widths.
/// `4 sqrt(a_i a_j) sinh(d) / (exp(lambda_i + lambda_j) d)`, `d = |lambda_i xi_i + lambda_j
/// xi_j|`, `a = lambda / (1 - exp(-4 lambda))`, evaluated as `exp(d - l_i - l_j)` terms so
/// that sharp lobes do not overflow.
pub fn lobe_similarity(xi_i: DVec3, lambda_i: f64, xi_j: DVec3, lambda_j: f64) -> f64 {
    let alpha = |l: f64| if l < 1e-9 { 0.25 } else { l / -(-4.0 * l).exp_m1() };
    let sum = lambda_i + lambda_j;
    let d = (lambda_i * xi_i + lambda_j * xi_j).length();
    let sinh_over = if d < 1e-9 { (-sum).exp() } else { ((d - sum).exp() - (-d - sum).exp()) / (2.0 * d) };
    4.0 * (alpha(lambda_i) * alpha(lambda_j)).sqrt() * sinh_over
}

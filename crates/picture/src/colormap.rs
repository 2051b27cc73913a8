//! False colour: matplotlib's perceptually uniform colour maps (inferno for maps over an image,
//! viridis for atlases and error maps), linear and logarithmic [`Scale`]s that turn values into
//! positions on them, and colour ranges chosen by (weighted) percentiles, so that a few outliers
//! do not spend the whole scale.

/// matplotlib's inferno at 0, 0.1, ..., 1 (viridisLite's `inferno(11)`), interpolated linearly
/// in sRGB: close enough to the 256-entry table for a preview, and still monotone in lightness.
const INFERNO: [[u8; 3]; 11] = [
    [0x00, 0x00, 0x04],
    [0x16, 0x0b, 0x39],
    [0x42, 0x0a, 0x68],
    [0x6a, 0x17, 0x6e],
    [0x93, 0x26, 0x67],
    [0xbc, 0x37, 0x54],
    [0xdd, 0x51, 0x3a],
    [0xf3, 0x78, 0x19],
    [0xfc, 0xa5, 0x0a],
    [0xf6, 0xd7, 0x46],
    [0xfc, 0xff, 0xa4],
];

/// The colour of position `t` in `0..=1`.
pub fn inferno(t: f64) -> [u8; 3] {
    let s = t.clamp(0.0, 1.0) * (INFERNO.len() - 1) as f64;
    let i = (s.floor() as usize).min(INFERNO.len() - 2);
    let f = s - i as f64;
    std::array::from_fn(|c| (f64::from(INFERNO[i][c]) * (1.0 - f) + f64::from(INFERNO[i + 1][c]) * f).round() as u8)
}

/// Viridis at 0, 1/8, ..., 1 (sRGB bytes); linear in between.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// The colour of `t` in `[0, 1]` (clamped).
pub fn viridis(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x as usize).min(7);
    let f = x - i as f64;
    std::array::from_fn(|c| (VIRIDIS[i][c] * (1.0 - f) + VIRIDIS[i + 1][c] * f).round() as u8)
}

/// The range of a logarithmic scale for `values`: from the smallest positive value, but no
/// more than `decades` decades below the largest, to the largest. `None` when no value is
/// positive.
pub fn log_range(values: &[f32], decades: f64) -> Option<(f64, f64)> {
    let hi = values.iter().fold(0.0f64, |m, v| m.max(f64::from(*v)));
    if hi <= 0.0 {
        return None;
    }
    let lo = values.iter().filter(|v| **v > 0.0).fold(hi, |m, v| m.min(f64::from(*v)));
    Some((lo.max(hi * 10f64.powf(-decades)), hi))
}

/// Interleaved RGB bytes for `values`: `log(v)` mapped linearly from `range.0` (dark violet) to
/// `range.1` (yellow), clamped; zero, negative and NaN values are black.
pub fn false_colour_log(values: &[f32], range: (f64, f64)) -> Vec<u8> {
    let (lo, hi) = (range.0.ln(), range.1.ln());
    let span = if hi > lo { hi - lo } else { 1.0 };
    values
        .iter()
        .flat_map(|&v| {
            let v = f64::from(v);
            if v > 0.0 { viridis((v.ln() - lo) / span) } else { [0, 0, 0] }
        })
        .collect()
}

/// How values map onto a colour map's `0..=1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScaleKind {
    /// `t = (v - lo) / (hi - lo)`.
    Linear,
    /// `t = log(v / lo) / log(hi / lo)`.
    Log,
}

/// A colour scale from `lo` (position 0) to `hi` (position 1). Always valid: `lo < hi`, both
/// finite, and `lo > 0` on a log scale (the constructors repair anything else).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    kind: ScaleKind,
    lo: f64,
    hi: f64,
}

impl Scale {
    /// A linear scale. Swapped ends are put in order; equal ends are widened to `lo +- |lo| / 2`
    /// (`-1 ..= 1` around zero); non-finite ends give `0 ..= 1`.
    pub fn linear(lo: f64, hi: f64) -> Self {
        let (lo, hi) = if lo.is_finite() && hi.is_finite() { (lo.min(hi), lo.max(hi)) } else { (0.0, 1.0) };
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            let half = if lo == 0.0 { 1.0 } else { lo.abs() / 2.0 };
            (lo - half, lo + half)
        };
        Scale { kind: ScaleKind::Linear, lo, hi }
    }

    /// A logarithmic scale. Swapped ends are put in order; a non-positive `lo` becomes
    /// `hi / 1000` (three decades); equal ends are widened by half a decade each way; without a
    /// positive finite end, `0.001 ..= 1`.
    pub fn log(lo: f64, hi: f64) -> Self {
        let (lo, hi) = (lo.min(hi), lo.max(hi));
        let (lo, hi) = match (lo > 0.0 && lo.is_finite(), hi > 0.0 && hi.is_finite()) {
            (true, true) => (lo, hi),
            (false, true) => (hi / 1e3, hi),
            _ => (1e-3, 1.0),
        };
        let (lo, hi) = if hi > lo { (lo, hi) } else { (lo / 10f64.sqrt(), lo * 10f64.sqrt()) };
        Scale { kind: ScaleKind::Log, lo, hi }
    }

    pub fn kind(&self) -> ScaleKind {
        self.kind
    }

    pub fn lo(&self) -> f64 {
        self.lo
    }

    pub fn hi(&self) -> f64 {
        self.hi
    }

    /// The position of `v` on the scale, clamped to `0..=1`. NaN, and on a log scale zero and
    /// negative values, are at 0: give them a special colour where they mean something.
    pub fn position(&self, v: f64) -> f64 {
        let t = match self.kind {
            ScaleKind::Linear => (v - self.lo) / (self.hi - self.lo),
            ScaleKind::Log => (v / self.lo).ln() / (self.hi / self.lo).ln(),
        };
        if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
    }

    /// The value at position `t` (the inverse of [`Scale::position`] inside `0..=1`).
    pub fn value(&self, t: f64) -> f64 {
        match self.kind {
            ScaleKind::Linear => self.lo + t * (self.hi - self.lo),
            ScaleKind::Log => self.lo * (self.hi / self.lo).powf(t),
        }
    }

    /// The scale widened to round ends, so that the bar's ends are labelled: on a log scale the
    /// nearest 1, 2 or 5 times a power of ten outside `lo` and `hi`; on a linear scale the
    /// nearest multiples outside of the tick step (1, 2 or 5 times a power of ten, for at most 5
    /// intervals).
    pub fn nice(&self) -> Self {
        match self.kind {
            ScaleKind::Log => Scale::log(nice_at_most(self.lo), nice_at_least(self.hi)),
            ScaleKind::Linear => {
                let step = Step::for_span(self.hi - self.lo, LEGEND_INTERVALS);
                let lo = step.value((self.lo / step.size() + 1e-9).floor() as i64);
                let hi = step.value((self.hi / step.size() - 1e-9).ceil() as i64);
                Scale::linear(lo, hi)
            }
        }
    }

    /// Whether some finite value lies below `lo` and whether some lies above `hi`: where the
    /// legend draws its clipping arrows. On a log scale zero and negative values do not count as
    /// below (they have no place on it; callers colour them specially).
    pub fn clipping(&self, values: &[f64]) -> (bool, bool) {
        let on_scale = |v: &&f64| v.is_finite() && (self.kind == ScaleKind::Linear || **v > 0.0);
        let below = values.iter().filter(on_scale).any(|v| *v < self.lo);
        let above = values.iter().filter(on_scale).any(|v| *v > self.hi);
        (below, above)
    }
}

/// The number of tick intervals a linear legend aims at (at most).
pub(crate) const LEGEND_INTERVALS: usize = 5;

/// The mantissas of round numbers.
const NICE: [i64; 3] = [1, 2, 5];

/// The largest `m 10^e <= v`, `m` in [`NICE`]. Compared with a relative tolerance, so that a
/// value that is a round number up to rounding is its own end.
fn nice_at_most(v: f64) -> f64 {
    let e = v.log10().floor() as i32;
    let candidates = (e - 1..=e + 1).flat_map(|e| NICE.map(|m| decimal(m, e)));
    candidates.filter(|n| *n <= v * (1.0 + 1e-9)).fold(0.0, f64::max)
}

/// The smallest `m 10^e >= v`, `m` in [`NICE`].
fn nice_at_least(v: f64) -> f64 {
    let e = v.log10().floor() as i32;
    let candidates = (e - 1..=e + 1).flat_map(|e| NICE.map(|m| decimal(m, e)));
    candidates.filter(|n| *n >= v * (1.0 - 1e-9)).fold(f64::INFINITY, f64::min)
}

/// `mantissa 10^exponent` as the nearest double: dividing by an exact power of ten, so that
/// `3 x 0.1` comes out as `0.3`, not `0.30000000000000004`.
pub(crate) fn decimal(mantissa: i64, exponent: i32) -> f64 {
    if exponent >= 0 { mantissa as f64 * 10f64.powi(exponent) } else { mantissa as f64 / 10f64.powi(-exponent) }
}

/// A tick step `m 10^e`, `m` in 1, 2, 5.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Step {
    m: i64,
    pub(crate) e: i32,
}

impl Step {
    /// The smallest step that cuts `span` into at most `intervals` intervals.
    pub(crate) fn for_span(span: f64, intervals: usize) -> Self {
        let raw = span / intervals.max(1) as f64;
        if !(raw > 0.0 && raw.is_finite()) {
            return Step { m: 1, e: 0 };
        }
        // Within the range of doubles: no power of ten overflows.
        let e = (raw.log10().floor() as i32).clamp(-300, 300);
        [1, 2, 5, 10]
            .into_iter()
            .find(|&m| decimal(m, e) >= raw * (1.0 - 1e-9))
            .map_or(Step { m: 1, e: e + 1 }, |m| if m == 10 { Step { m: 1, e: e + 1 } } else { Step { m, e } })
    }

    pub(crate) fn size(&self) -> f64 {
        decimal(self.m, self.e)
    }

    /// The `k`-th multiple of the step.
    pub(crate) fn value(&self, k: i64) -> f64 {
        decimal(k * self.m, self.e)
    }
}

/// The round values from `lo` to `hi` (either order) at a 1-2-5 step chosen for at most
/// `intervals` intervals, with the step's exponent (for the labels' decimals). Empty for an
/// empty or non-finite range.
pub(crate) fn linear_ticks(lo: f64, hi: f64, intervals: usize) -> (Vec<f64>, Step) {
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    let step = Step::for_span(hi - lo, intervals);
    if !(hi > lo && hi.is_finite() && lo.is_finite()) {
        return (Vec::new(), step);
    }
    let first = (lo / step.size() - 1e-9).ceil() as i64;
    let last = (hi / step.size() + 1e-9).floor() as i64;
    // Only a range at the limits of doubles (where the step rounds away) gets here.
    if last.saturating_sub(first) > 10 * intervals as i64 + 10 {
        return (Vec::new(), step);
    }
    ((first..=last).map(|k| step.value(k)).collect(), step)
}

/// The `lo` and `hi` quantiles (fractions in `0..=1`; swapped if out of order) of `values`,
/// each value counting with its weight (e.g. a texel's solid angle, so that the many tiny texels
/// of a lat-long map's pole rows count for what they cover), to choose a colour range that
/// ignores outliers. The `p` quantile is the smallest value whose cumulative weight reaches `p`
/// times the total. Non-finite values and values of zero, negative or non-finite weight are
/// ignored; `None` when nothing is left. For a log scale pass only the positive values (and
/// their weights).
///
/// # Panics
/// When `weights` is not as long as `values`.
pub fn range_by_percentiles(values: &[f64], weights: Option<&[f64]>, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if let Some(weights) = weights {
        assert_eq!(weights.len(), values.len(), "one weight per value");
    }
    let weight = |i: usize| weights.map_or(1.0, |w| w[i]);
    let mut sorted: Vec<(f64, f64)> = (0..values.len())
        .map(|i| (values[i], weight(i)))
        .filter(|(v, w)| v.is_finite() && w.is_finite() && *w > 0.0)
        .collect();
    let last = sorted.iter().map(|(v, _)| *v).reduce(f64::max)?;
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = sorted.iter().map(|(_, w)| w).sum();
    let quantile = |p: f64| {
        let target = p.clamp(0.0, 1.0) * total;
        let mut cumulative = 0.0;
        for (v, w) in &sorted {
            cumulative += w;
            if cumulative >= target {
                return *v;
            }
        }
        // Rounding in the sum can leave the last cumulative weight a hair below the total.
        last
    };
    Some((quantile(lo.min(hi)), quantile(lo.max(hi))))
}

//! The inner loops. Everything here works on slices whose lengths the callers have checked: a
//! signal of even length `n >= 2` against coefficient arrays of length `n / 2`.

use crate::wavelet::Bank;

/// `i mod n` for an index that may have run off either end of a periodic signal.
fn wrap(i: isize, n: usize) -> usize {
    i.rem_euclid(n as isize) as usize
}

/// One analysis step of a contiguous signal: `a[k] = sum_j lo[j] x[(2k - SHIFT + j) mod n]`, and
/// `d[k]` the same with `hi`.
pub(crate) fn analyze<const F: usize>(bank: &Bank<F>, x: &[f64], a: &mut [f64], d: &mut [f64]) {
    let n = x.len();
    debug_assert!(n >= 2 && n.is_multiple_of(2) && a.len() == n / 2 && d.len() == n / 2);
    let shift = Bank::<F>::SHIFT;
    // Coefficients `interior` read x[2k - shift .. 2k - shift + F] without wrapping.
    let first = shift.div_ceil(2);
    let end = if n + shift >= F { ((n + shift - F) / 2 + 1).max(first) } else { first };
    let interior = first.min(a.len())..end.min(a.len());
    let dot = |w: &[f64; F]| {
        let (mut sa, mut sd) = (0.0, 0.0);
        for ((lo, hi), v) in bank.lo.iter().zip(&bank.hi).zip(w) {
            sa += lo * v;
            sd += hi * v;
        }
        (sa, sd)
    };
    for k in (0..interior.start).chain(interior.end..a.len()) {
        let start = (2 * k) as isize - shift as isize;
        let w: [f64; F] = std::array::from_fn(|j| x[wrap(start + j as isize, n)]);
        (a[k], d[k]) = dot(&w);
    }
    let base = 2 * interior.start - shift;
    for (i, (ak, dk)) in a[interior.clone()].iter_mut().zip(&mut d[interior]).enumerate() {
        let w: &[f64; F] = x[base + 2 * i..base + 2 * i + F].try_into().expect("interior window");
        (*ak, *dk) = dot(w);
    }
}

/// One synthesis step, the transpose of [`analyze`]: `x[(2k - SHIFT + j) mod n]` receives
/// `lo[j] a[k] + hi[j] d[k]` for every `k` and `j`, gathered per output sample.
pub(crate) fn synthesize<const F: usize>(bank: &Bank<F>, a: &[f64], d: &[f64], x: &mut [f64]) {
    let h = a.len();
    debug_assert!(h >= 1 && d.len() == h && x.len() == 2 * h);
    let shift = Bank::<F>::SHIFT;
    // Output 2m + q takes the taps j = parity(q) + 2t from k = m + lift(q) - t, t = 0..F/2.
    let parity = |q: usize| (q + shift) % 2;
    let lift = |q: usize| (q + shift - parity(q)) / 2;
    // Interior m read a[m - back ..= m + ahead] without wrapping.
    let back = (F / 2 - 1).saturating_sub(lift(0).min(lift(1)));
    let ahead = lift(0).max(lift(1));
    let interior = back.min(h)..h.saturating_sub(ahead).max(back.min(h));
    for m in (0..interior.start).chain(interior.end..h) {
        for q in 0..2 {
            let mut acc = 0.0;
            for t in 0..F / 2 {
                let j = parity(q) + 2 * t;
                let k = wrap((m + lift(q)) as isize - t as isize, h);
                acc += bank.lo[j] * a[k] + bank.hi[j] * d[k];
            }
            x[2 * m + q] = acc;
        }
    }
    for m in interior {
        let (aw, dw) = (&a[m - back..=m + ahead], &d[m - back..=m + ahead]);
        for q in 0..2 {
            let mut acc = 0.0;
            for t in 0..F / 2 {
                let (j, i) = (parity(q) + 2 * t, lift(q) + back - t);
                acc += bank.lo[j] * aw[i] + bank.hi[j] * dw[i];
            }
            x[2 * m + q] = acc;
        }
    }
}

/// The rows of a periodic column signal of `n` rows that output row `k` of an analysis step reads:
/// `(2k - SHIFT + j) mod n` for `j = 0..F`.
pub(crate) fn analysis_rows<const F: usize>(k: usize, n: usize) -> [usize; F] {
    let start = (2 * k) as isize - Bank::<F>::SHIFT as isize;
    std::array::from_fn(|j| wrap(start + j as isize, n))
}

/// [`analyze`] across rows: output row `a = sum_j lo[j] rows[j]`, `d` likewise with `hi`. Each
/// row is contiguous, so the loops run over columns and vectorize.
pub(crate) fn analyze_across<const F: usize>(bank: &Bank<F>, rows: &[&[f64]; F], a: &mut [f64], d: &mut [f64]) {
    for (j, row) in rows.iter().enumerate() {
        let (lo, hi, row) = (bank.lo[j], bank.hi[j], &row[..a.len()]);
        if j == 0 {
            for ((ac, dc), v) in a.iter_mut().zip(d.iter_mut()).zip(row) {
                *ac = lo * v;
                *dc = hi * v;
            }
        } else {
            for ((ac, dc), v) in a.iter_mut().zip(d.iter_mut()).zip(row) {
                *ac += lo * v;
                *dc += hi * v;
            }
        }
    }
}

/// [`synthesize`] across rows: output row `n` of a column signal of `2 h` rows, from the `h` rows
/// of `a` and `d` (row-major, `width` columns each).
pub(crate) fn synthesize_across<const F: usize>(
    bank: &Bank<F>,
    n: usize,
    a: &[f64],
    d: &[f64],
    width: usize,
    out: &mut [f64],
) {
    let h = a.len() / width;
    let shift = Bank::<F>::SHIFT;
    let parity = (n + shift) % 2;
    let top = (n + shift - parity) / 2;
    for t in 0..F / 2 {
        let (j, k) = (parity + 2 * t, wrap(top as isize - t as isize, h));
        let (lo, hi) = (bank.lo[j], bank.hi[j]);
        let (ar, dr) = (&a[k * width..(k + 1) * width], &d[k * width..(k + 1) * width]);
        if t == 0 {
            for ((o, av), dv) in out.iter_mut().zip(ar).zip(dr) {
                *o = lo * av + hi * dv;
            }
        } else {
            for ((o, av), dv) in out.iter_mut().zip(ar).zip(dr) {
                *o += lo * av + hi * dv;
            }
        }
    }
}

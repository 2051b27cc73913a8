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

/// [`analyze`] of a signal given deinterleaved: `even[i] = x[2 i]`, `odd[i] = x[2 i + 1]`. The same
/// sums in the same order (`a[k] = 0 + lo[0] x[..] + lo[1] x[..] + ...`, bit for bit), but away
/// from the wrap-around every tap reads a contiguous slice, so the loops run over `k` and
/// vectorize where [`analyze`]'s stride-2 windows do not. Without `d`, the approximation alone.
#[inline(always)]
pub(crate) fn analyze_split<const F: usize>(
    bank: &Bank<F>,
    even: &[f64],
    odd: &[f64],
    a: &mut [f64],
    mut d: Option<&mut [f64]>,
) {
    let half = even.len();
    let n = 2 * half;
    debug_assert!(half >= 1 && odd.len() == half && a.len() == half && d.as_ref().is_none_or(|d| d.len() == half));
    let shift = Bank::<F>::SHIFT;
    let x = |i: usize| if i.is_multiple_of(2) { even[i / 2] } else { odd[i / 2] };
    let first = shift.div_ceil(2);
    let end = if n + shift >= F { ((n + shift - F) / 2 + 1).max(first) } else { first };
    let interior = first.min(half)..end.min(half);
    for k in (0..interior.start).chain(interior.end..half) {
        let start = (2 * k) as isize - shift as isize;
        let (mut sa, mut sd) = (0.0, 0.0);
        for j in 0..F {
            let v = x(wrap(start + j as isize, n));
            sa += bank.lo[j] * v;
            sd += bank.hi[j] * v;
        }
        a[k] = sa;
        if let Some(d) = d.as_deref_mut() {
            d[k] = sd;
        }
    }
    if interior.is_empty() {
        return;
    }
    let a = &mut a[interior.clone()];
    let mut d = d.map(|d| &mut d[interior.clone()]);
    for j in 0..F {
        // Tap j of output k reads x[2 k + t], t = j - SHIFT: even[k + t / 2] or odd[k + (t - 1) / 2].
        let t = j as isize - shift as isize;
        let (src, offset) = if t.rem_euclid(2) == 0 { (even, t.div_euclid(2)) } else { (odd, (t - 1).div_euclid(2)) };
        let src = &src[(interior.start as isize + offset) as usize..][..a.len()];
        let (lo, hi) = (bank.lo[j], bank.hi[j]);
        // The sums start from 0.0, as the boundary coefficients' do (0.0 + x, not x: the same
        // bits, the sign of a zero included), without a pass to clear them first.
        match (j, d.as_deref_mut()) {
            (0, Some(d)) => {
                for ((ak, dk), v) in a.iter_mut().zip(d.iter_mut()).zip(src) {
                    *ak = 0.0 + lo * v;
                    *dk = 0.0 + hi * v;
                }
            }
            (_, Some(d)) => {
                for ((ak, dk), v) in a.iter_mut().zip(d.iter_mut()).zip(src) {
                    *ak += lo * v;
                    *dk += hi * v;
                }
            }
            (0, None) => {
                for (ak, v) in a.iter_mut().zip(src) {
                    *ak = 0.0 + lo * v;
                }
            }
            (_, None) => {
                for (ak, v) in a.iter_mut().zip(src) {
                    *ak += lo * v;
                }
            }
        }
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

/// [`analyze`] across rows: output row `a = sum_j lo[j] rows[j]`, `d` likewise with `hi`: the
/// definition [`analyze_across_split`] is held to.
#[cfg(test)]
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

/// [`analyze_across`] with its outputs deinterleaved for [`analyze_split`]: column `2 i` of the
/// low-pass row goes to `lo[0][i]`, column `2 i + 1` to `lo[1][i]`, likewise the high-pass row.
/// Without `hi`, the low-pass row alone.
#[inline(always)]
pub(crate) fn analyze_across_split<const F: usize>(
    bank: &Bank<F>,
    rows: &[&[f64]; F],
    lo: [&mut [f64]; 2],
    hi: Option<[&mut [f64]; 2]>,
) {
    let [lo_even, lo_odd] = lo;
    let half = lo_even.len();
    let Some([hi_even, hi_odd]) = hi else {
        for (j, row) in rows.iter().enumerate() {
            let (l, row) = (bank.lo[j], &row[..2 * half]);
            let outputs = lo_even.iter_mut().zip(lo_odd.iter_mut()).zip(row.chunks_exact(2));
            if j == 0 {
                for ((le, lo), pair) in outputs {
                    (*le, *lo) = (l * pair[0], l * pair[1]);
                }
            } else {
                for ((le, lo), pair) in outputs {
                    *le += l * pair[0];
                    *lo += l * pair[1];
                }
            }
        }
        return;
    };
    for (j, row) in rows.iter().enumerate() {
        let (l, h, row) = (bank.lo[j], bank.hi[j], &row[..2 * half]);
        let outputs = lo_even.iter_mut().zip(lo_odd.iter_mut()).zip(hi_even.iter_mut().zip(hi_odd.iter_mut()));
        if j == 0 {
            for (((le, lo), (he, ho)), pair) in outputs.zip(row.chunks_exact(2)) {
                (*le, *lo) = (l * pair[0], l * pair[1]);
                (*he, *ho) = (h * pair[0], h * pair[1]);
            }
        } else {
            for (((le, lo), (he, ho)), pair) in outputs.zip(row.chunks_exact(2)) {
                *le += l * pair[0];
                *lo += l * pair[1];
                *he += h * pair[0];
                *ho += h * pair[1];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wavelet::{D4, HAAR};

    /// The split kernels of the 2D transform give the plain kernels' values bit for bit: the
    /// column filter, deinterleaved, then the row filter on the two halves.
    fn check_split<const F: usize>(bank: &Bank<F>) {
        for w in [2, 4, 6, 8, 16, 34, 64] {
            let rows: Vec<Vec<f64>> =
                (0..F).map(|r| (0..w).map(|c| ((r * 131 + c * 71) as f64 * 0.37).sin() * 1e3).collect()).collect();
            let rows: [&[f64]; F] = std::array::from_fn(|r| &rows[r][..]);
            let (mut lo, mut hi) = (vec![0.0; w], vec![0.0; w]);
            analyze_across(bank, &rows, &mut lo, &mut hi);
            let half = w / 2;
            let mut split = vec![0.0; 2 * w];
            let (l, h) = split.split_at_mut(w);
            let ((le, lo_), (he, ho)) = (l.split_at_mut(half), h.split_at_mut(half));
            analyze_across_split(bank, &rows, [&mut *le, &mut *lo_], Some([&mut *he, &mut *ho]));
            let same = |p: &[f64], q: &[f64]| p.iter().zip(q).all(|(u, v)| u.to_bits() == v.to_bits());
            // The low-pass alone is the same low-pass.
            let (mut le_alone, mut lo_alone) = (vec![0.0; half], vec![0.0; half]);
            analyze_across_split(bank, &rows, [&mut le_alone, &mut lo_alone], None);
            assert!(same(le, &le_alone) && same(lo_, &lo_alone), "w {w}");
            for (x, (line, (even, odd))) in [(&lo, (&*le, &*lo_)), (&hi, (&*he, &*ho))].into_iter().enumerate() {
                let interleaved: Vec<f64> = even.iter().zip(odd.iter()).flat_map(|(e, o)| [*e, *o]).collect();
                assert!(same(line, &interleaved), "w {w}, row {x}");
                let (mut a, mut d) = (vec![0.0; half], vec![0.0; half]);
                analyze(bank, line, &mut a, &mut d);
                let (mut a2, mut d2) = (vec![0.0; half], vec![0.0; half]);
                analyze_split(bank, even, odd, &mut a2, Some(&mut d2));
                assert!(same(&a, &a2) && same(&d, &d2), "w {w}, row {x}");
                let mut a3 = vec![0.0; half];
                analyze_split(bank, even, odd, &mut a3, None);
                assert!(same(&a, &a3), "w {w}, row {x}: the approximation alone");
            }
        }
    }

    #[test]
    fn the_split_kernels_equal_the_plain_ones_bit_for_bit() {
        check_split(&D4);
        check_split(&HAAR);
    }
}

//! `atan2` for the lookups' half and difference angles, branch-free so that a loop over many
//! direction pairs vectorizes (the system's libm `atan2` is a call per angle, three per lookup).
//!
//! The octant is reduced to `atan(t)`, `t = small / large` in `[0, 1]` (the smaller and the
//! larger of `|x|` and `|y|`), and `t >= 1/2` further to `atan(t) = pi / 4 + atan(u)`,
//! `u = (small - large) / (small + large)` in `[-1/3, 0]` (a difference that is exact there), so
//! that `|u| <= 1/2` and one division makes `u`. There `atan(u) = u + u s P(s)`, `s = u^2`, with
//! `P` of degree 13 in `s` ([`ATAN_P`]: the Chebyshev fit of `(atan(sqrt s) - sqrt s) / (s sqrt s)`
//! on `[0, 1/4]`, whose own error, 2e-19 times `|u|^3`, is far below an ulp of the result),
//! evaluated as its even and its odd half, two independent chains. What remains is the
//! rounding of the steps, within 2 ulp of libm's `atan2` (the tests, on random and edge
//! arguments). The sign of a zero `x` is not looked at: `atan2(+-0, -0)` is `+-0`, libm's `+-pi`.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Coefficients of `P` (module docs), highest degree first. Made by mpmath 1.3
/// (`mpmath.chebyfit(f, [0, 1/4], 14)` at 50 digits, `f(0) = -1/3`), each rounded to `f64`.
pub(crate) const ATAN_P: [f64; 14] = [
    0.007656295362176976,
    -0.021682234961125823,
    0.03398634344047341,
    -0.041833386159884724,
    0.04729953834332562,
    -0.05258718904277028,
    0.05881913328517996,
    -0.06666636087824868,
    0.07692306240562284,
    -0.0909090904607358,
    0.11111111110278944,
    -0.14285714285706202,
    0.19999999999999968,
    -0.3333333333333333,
];

/// `pi / 4 - FRAC_PI_4`, `pi / 2 - FRAC_PI_2`, `pi - PI`: the constants' rounding errors, added
/// back after the sums with them.
const FRAC_PI_4_LO: f64 = 3.061616997868383e-17;
const FRAC_PI_2_LO: f64 = 6.123233995736766e-17;
const PI_LO: f64 = 1.2246467991473532e-16;

/// `atan(u)` for `|u| <= 1/2`.
#[inline(always)]
fn atan_half(u: f64) -> f64 {
    let s = u * u;
    let s2 = s * s;
    // P(s) = even(s^2) + s odd(s^2); ATAN_P[0] is the coefficient of s^13 (odd).
    let (mut odd, mut even) = (ATAN_P[0], ATAN_P[1]);
    for pair in ATAN_P[2..].chunks_exact(2) {
        odd = odd * s2 + pair[0];
        even = even * s2 + pair[1];
    }
    u + u * s * (even + s * odd)
}

/// The angle of `(x, y)` in `[-pi, pi]`, like `f64::atan2` to 2 ulp (module docs), for finite
/// arguments below `1e300`. Only comparisons, arithmetic and one division: no branch, no call.
#[inline(always)]
pub(crate) fn atan2(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    let (small, large) = if steep { (ax, ay) } else { (ay, ax) };
    let reduce = small + small >= large && large > 0.0;
    let (num, den) = if reduce { (small - large, small + large) } else { (small, large) };
    // Both zero: the angle 0 (the division is 0 / 0, replaced).
    let u = num / den;
    let u = if large > 0.0 { u } else { 0.0 };
    let r = atan_half(u);
    let r = if reduce { FRAC_PI_4 + (r + FRAC_PI_4_LO) } else { r };
    let r = if steep { (FRAC_PI_2 - r) + FRAC_PI_2_LO } else { r };
    let r = if x < 0.0 { (PI - r) + PI_LO } else { r };
    r.copysign(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng, rngs::StdRng};

    /// Units in the last place of `expect` between `got` and `expect`.
    fn ulps(got: f64, expect: f64) -> f64 {
        let ulp = f64::from_bits(expect.abs().to_bits() + 1) - expect.abs();
        (got - expect).abs() / ulp
    }

    fn check(y: f64, x: f64, bound: f64) -> f64 {
        let (got, expect) = (atan2(y, x), y.atan2(x));
        let e = ulps(got, expect);
        assert!(e <= bound, "atan2({y:e}, {x:e}) = {got:e}, libm {expect:e}: {e} ulp");
        e
    }

    #[test]
    fn within_two_ulp_of_libm_on_random_arguments() {
        let mut rng = StdRng::seed_from_u64(33);
        let mut worst = 0.0f64;
        for _ in 0..2_000_000 {
            let angle = rng.random_range(-PI..PI);
            let scale = 10f64.powf(rng.random_range(-8.0..8.0));
            let (y, x) = (scale * angle.sin(), scale * angle.cos());
            worst = worst.max(check(y, x, 2.0));
        }
        // The arguments of the lookups: components of unit vectors and sums of them.
        for _ in 0..1_000_000 {
            let (y, x) = (rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            worst = worst.max(check(y, x, 2.0));
        }
        println!("largest difference from libm: {worst} ulp");
    }

    #[test]
    fn within_one_and_a_half_ulp_of_libm_in_the_first_octant() {
        let mut rng = StdRng::seed_from_u64(34);
        let mut worst = 0.0f64;
        for _ in 0..1_000_000 {
            worst = worst.max(check(rng.random_range(0.0..1.0), 1.0, 1.5));
        }
        println!("largest difference from libm on [0, 1]: {worst} ulp");
    }

    #[test]
    fn edges_and_signs() {
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 1.0),
            (-1.0, -1.0),
            (1e-300, 1.0),
            (1.0, 1e-300),
            (1e-300, -1.0),
            (f64::MIN_POSITIVE, f64::MIN_POSITIVE),
            (1.0, -1.0 + 1e-16),
        ] {
            check(y, x, 2.0);
            assert_eq!(atan2(y, x).is_sign_negative(), y.is_sign_negative(), "atan2({y}, {x})");
        }
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert_eq!(atan2(0.0, -1.0), PI);
        assert_eq!(atan2(-0.0, -1.0), -PI);
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
    }
}

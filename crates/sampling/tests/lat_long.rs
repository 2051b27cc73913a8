//! `LatLong`: the lat-long distribution over the sphere, held to its own density per unit solid
//! angle by quadrature and by chi-square over bins of the sphere that the texel grid does not
//! share.

use std::f64::consts::PI;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use sampling::{Distribution2D, LatLong};

use crate::chi2::{assert_accepts, assert_rejects, chi2_test};

/// A 64 x 32 map: a dim gradient, a bright one-texel "sun" and a band of zeros.
fn weights() -> (Vec<f64>, usize, usize) {
    let (w, h) = (64, 32);
    let mut weights: Vec<f64> = (0..w * h).map(|k| 0.2 + ((k % w) as f64 / w as f64) + (k / w) as f64 * 0.05).collect();
    weights[7 * w + 40] = 4000.0;
    for x in 0..w {
        weights[20 * w + x] = 0.0;
    }
    (weights, w, h)
}

/// The `(u, v)` of a unit direction, `theta` from `+z` and `phi` from `+x` towards `+y`.
fn uv_of(d: [f64; 3]) -> [f64; 2] {
    let phi = d[1].atan2(d[0]).rem_euclid(2.0 * PI);
    [(phi / (2.0 * PI)).min(sampling::ONE_MINUS_EPSILON), d[2].clamp(-1.0, 1.0).acos() / PI]
}

/// Bins equal in solid angle: `BANDS` bands of `z` times `SECTORS` sectors of `phi`, unrelated to
/// the texels.
const BANDS: usize = 23;
const SECTORS: usize = 29;

fn bin_of(uv: [f64; 2]) -> usize {
    let z = (PI * uv[1]).cos();
    let band = (((1.0 - z) / 2.0 * BANDS as f64) as usize).min(BANDS - 1);
    band * SECTORS + ((uv[0] * SECTORS as f64) as usize).min(SECTORS - 1)
}

/// The length of the overlap of `[a0, a1)` and `[b0, b1)`.
fn overlap(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.1.min(b.1) - a.0.max(b.0)).max(0.0)
}

/// The probability of every bin, exactly: a bin is a rectangle in `(u, v)` too (band edges at
/// `v = acos(z) / pi`), and the density over `(u, v)` is constant per texel, so a bin's mass is
/// the sum of each texel's density times its overlap with the bin.
fn expected(d: &LatLong, w: usize, h: usize) -> Vec<f64> {
    let dist = d.distribution();
    let band_edge = |b: usize| (1.0 - 2.0 * b as f64 / BANDS as f64).clamp(-1.0, 1.0).acos() / PI;
    let mut mass = vec![0.0; BANDS * SECTORS];
    for band in 0..BANDS {
        for sector in 0..SECTORS {
            let bu = (sector as f64 / SECTORS as f64, (sector + 1) as f64 / SECTORS as f64);
            let bv = (band_edge(band), band_edge(band + 1));
            for y in 0..h {
                let ov = overlap(bv, (y as f64 / h as f64, (y + 1) as f64 / h as f64));
                if ov == 0.0 {
                    continue;
                }
                for x in 0..w {
                    let ou = overlap(bu, (x as f64 / w as f64, (x + 1) as f64 / w as f64));
                    let centre = [(x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64];
                    mass[band * SECTORS + sector] += dist.pdf(centre) * ou * ov;
                }
            }
        }
    }
    mass
}

fn histogram(mut sample: impl FnMut([f64; 2]) -> [f64; 2], n: usize, seed: u64) -> Vec<u64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut observed = vec![0u64; BANDS * SECTORS];
    for _ in 0..n {
        observed[bin_of(sample([rng.random(), rng.random()]))] += 1;
    }
    observed
}

#[test]
fn density_integrates_to_one_over_the_sphere() {
    let (weights, w, h) = weights();
    let d = LatLong::new(&weights, w, h).unwrap();
    // Over solid angle, by a midpoint rule in (z, phi) (each point carries the same solid angle)
    // that steps over texel edges: its error is the share of points near an edge times the
    // density's jump there, largest at the one-texel sun (0.4% at this resolution).
    let (nz, nphi) = (4096, 8192);
    let mut total = 0.0;
    for i in 0..nz {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / nz as f64;
        let s = (1.0 - z * z).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * PI * (j as f64 + 0.5) / nphi as f64;
            total += d.pdf(uv_of([s * phi.cos(), s * phi.sin(), z]));
        }
    }
    total *= 4.0 * PI / (nz * nphi) as f64;
    assert!((total - 1.0).abs() < 5e-3, "the density integrates to {total} over the sphere");
    // Over (u, v), exactly, from the bins' masses.
    let exact: f64 = expected(&d, w, h).iter().sum();
    assert!((exact - 1.0).abs() < 1e-12, "the bins' masses sum to {exact}");
}

#[test]
fn pdf_agrees_with_sample_and_invert_undoes_it() {
    let (weights, w, h) = weights();
    let d = LatLong::new(&weights, w, h).unwrap();
    let mut rng = StdRng::seed_from_u64(40);
    for _ in 0..100_000 {
        let u: [f64; 2] = [rng.random(), rng.random()];
        let s = d.sample(u);
        assert_eq!(d.pdf(s.uv), s.pdf, "{u:?} -> {s:?}");
        assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{u:?} -> {s:?}");
        let back = d.invert(s.uv);
        assert!((back[0] - u[0]).abs() < 1e-9 && (back[1] - u[1]).abs() < 1e-9, "{u:?} -> {s:?} -> {back:?}");
        // The zero band is never drawn.
        assert_ne!(((s.uv[1] * h as f64) as usize), 20, "{u:?} -> {s:?}");
    }
}

/// The chi-square test of `n = 10^6` points `sample` draws (from independent uniform `u`, seeded)
/// against the test map's distribution.
fn chi2_against_the_distribution(sample: impl FnMut([f64; 2]) -> [f64; 2], seed: u64) -> sampling::chi2::Chi2 {
    let (weights, w, h) = weights();
    let d = LatLong::new(&weights, w, h).unwrap();
    let n = 1_000_000;
    let expected: Vec<f64> = expected(&d, w, h).iter().map(|p| p * n as f64).collect();
    chi2_test(&histogram(sample, n, seed), &expected)
}

#[test]
fn chi2_accepts_the_sampler_in_solid_angle() {
    let (weights, w, h) = weights();
    let d = LatLong::new(&weights, w, h).unwrap();
    assert_accepts(chi2_against_the_distribution(|u| d.sample(u).uv, 41), "lat-long sampler");
}

#[test]
fn chi2_rejects_a_sampler_that_forgets_sin_theta() {
    // The texels drawn by their weights alone: the poles' small texels drawn as often as the
    // equator's, which the solid-angle density does not do.
    let (weights, w, h) = weights();
    let wrong = Distribution2D::new(&weights, w, h).unwrap();
    assert_rejects(chi2_against_the_distribution(|u| wrong.sample(u).p, 42), "sampler without sin theta");
}

#[test]
fn refuses_weights_that_are_not_a_grid_of_finite_non_negative_values() {
    assert!(LatLong::new(&[1.0; 6], 4, 2).is_err());
    assert!(LatLong::new(&[1.0, -1.0], 2, 1).is_err());
    assert!(LatLong::new(&[1.0, f64::INFINITY], 2, 1).is_err());
    assert!(LatLong::new(&[], 0, 0).is_err());
}

//! The split-sum BRDF table that goes with a GGX chain (Karis 2013, "DFG" in Filament): for a view
//! at `mu = n . v` and perceptual roughness `rho`, the scale `A` and bias `B` of `F0` in the
//! directional albedo of the GGX microfacet BRDF with Schlick's Fresnel,
//!
//! ```text
//! int f(l, v) (n . l) dl = F0 A + B,
//! f = D(h) G2(l, v) F(v . h) / (4 (n . l) (n . v)),  F = F0 + (1 - F0) (1 - v . h)^5,
//! ```
//!
//! `D` the GGX distribution of width `alpha = rho^2`, `G2` Smith's height-correlated
//! masking-shadowing `1 / (1 + Lambda(v) + Lambda(l))` (the `merl` crate's GGX). A shader
//! computes `prefiltered(r, rho) (F0 A + B)`.
//!
//! # Computation
//!
//! By Monte Carlo over a 2D Hammersley set of [`DFG_SAMPLES`] points, with half vectors drawn from
//! GGX's distribution of normals visible from `v` (Heitz 2018): `l` then has the density
//! `G1(v) D / (4 n . v)` and the estimator of the integral is `G2 F / G1(v)`, at most `F`, over
//! the samples with `n . l > 0`. `A` takes `1 - Fc`, `B` takes `Fc`, `Fc = (1 - v . h)^5`. (Drawing
//! `h` from `D (n . h)`, as Karis and most engines do, weighs samples by `(v . h) / ((n . v) (n .
//! h))`, unbounded at grazing views: 4096 of them miss `A` by 1e-2 at `n . v = 0.03`.) The tests
//! hold it to two deterministic quadratures.
//!
//! # Layout
//!
//! `size x size` texels, texel `(i, j)` at `mu = (i + 1/2) / size` (columns) and `rho = (j + 1/2)
//! / size` (rows, row 0 the smoothest): the layout of Filament's and glTF-IBL-Sampler's tables up
//! to their row order. In `dfg.ktx2` (RGBA16F, half floats are plenty for values in `[0, 1]`)
//! red is `A`, green `B`, blue 0, alpha 1.
//!
//! # Embedded table
//!
//! The table depends on nothing a bake reads (neither the map nor the material), so the
//! default size is computed once per version of this crate and embedded in the build
//! (`src/dfg-128.bin`): [`table`] at [`DFG_SIZE`] costs a copy instead of the samples. After a
//! change to the computation, `cargo run --release -p prefilter --example dfg-table >
//! crates/prefilter/src/dfg-128.bin` writes it again; a test holds the embedded table to
//! [`compute_table`] on a spread of texels.

use std::f64::consts::PI;

use glam::DVec3;
use merl::analytic::smith_lambda;
use rayon::prelude::*;

/// Samples per texel: with visible-normal sampling the estimate is within `1e-4` of the
/// quadratures at this count (measured: 3.9e-4 at worst over a 16 x 16 table; 3.2e-4 with 4096).
pub const DFG_SAMPLES: usize = 2048;

/// The default table side (Filament's).
pub const DFG_SIZE: usize = 128;

/// `(A, B)` at `mu = n . v` (in `(0, 1]`) and width `alpha`, by [`DFG_SAMPLES`] Hammersley samples.
pub fn dfg(mu: f64, alpha: f64) -> [f64; 2] {
    dfg_with(mu, alpha, DFG_SAMPLES)
}

/// [`dfg`] with `n` samples.
pub fn dfg_with(mu: f64, alpha: f64, n: usize) -> [f64; 2] {
    let v = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let g1_v = 1.0 / (1.0 + smith_lambda(alpha, mu));
    let (mut a, mut b) = (0.0, 0.0);
    for k in 0..n {
        let h = visible_normal(v, alpha, (k as f64 + 0.5) / n as f64, radical_inverse(k as u32));
        let vh = v.dot(h);
        let l = 2.0 * vh * h - v;
        if l.z <= 0.0 || vh <= 0.0 {
            continue;
        }
        let weight = 1.0 / (1.0 + smith_lambda(alpha, mu) + smith_lambda(alpha, l.z)) / g1_v;
        let fc = (1.0 - vh).powi(5);
        a += (1.0 - fc) * weight;
        b += fc * weight;
    }
    [a / n as f64, b / n as f64]
}

/// A half vector drawn from GGX's distribution of normals visible from `v` (Heitz 2018,
/// "Sampling the GGX Distribution of Visible Normals", isotropic), for `(u1, u2)` in `[0, 1)^2`.
fn visible_normal(v: DVec3, alpha: f64, u1: f64, u2: f64) -> DVec3 {
    let vh = DVec3::new(alpha * v.x, alpha * v.y, v.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 { DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt() } else { DVec3::X };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    DVec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// The table at [`DFG_SIZE`], as [`compute_table`] made it, embedded in the build (module docs,
/// "Embedded table"): `DFG_SIZE^2` pairs of little-endian `f32`, `A` then `B`, row-major.
const EMBEDDED: &[u8] = include_bytes!("dfg-128.bin");

/// The table (module docs): `size^2` texels `(A, B)`, row-major, row 0 at the smallest roughness.
/// At [`DFG_SIZE`] the embedded table, else [`compute_table`].
pub fn table(size: usize) -> Vec<[f32; 2]> {
    if size == DFG_SIZE && EMBEDDED.len() == size * size * 8 {
        let value = |bytes: &[u8]| f32::from_le_bytes(bytes.try_into().expect("4 bytes"));
        return EMBEDDED.chunks_exact(8).map(|t| [value(&t[..4]), value(&t[4..])]).collect();
    }
    compute_table(size)
}

/// The table computed: [`dfg`] at every texel (about 34 million samples at [`DFG_SIZE`]).
pub fn compute_table(size: usize) -> Vec<[f32; 2]> {
    (0..size * size)
        .into_par_iter()
        .map(|k| {
            let mu = (k % size) as f64 + 0.5;
            let rho = (k / size) as f64 + 0.5;
            let alpha = crate::ggx::alpha(rho / size as f64).max(crate::ggx::MIN_ALPHA);
            dfg(mu / size as f64, alpha).map(|x| x as f32)
        })
        .collect()
}

/// The van der Corput radical inverse in base 2 (the second coordinate of a Hammersley set).
fn radical_inverse(bits: u32) -> f64 {
    f64::from(bits.reverse_bits()) / 4_294_967_296.0
}

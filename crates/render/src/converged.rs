//! The converged estimate: the same integral as [`crate::Estimator::Reference`],
//! `L_o = int f(wi, wo) L(wi) cos theta_i dwi` with `f` the table's nearest lookup and `L` level
//! 0 of the environment, bilinear, over the same G-buffer and shading frame, estimated without
//! any baked table by multiple importance sampling of three strategies with the balance
//! heuristic. Each round draws one direction from each strategy; a direction `x_s` contributes
//! `g(x_s) / (p_env + p_cos + p_h)(x_s)`, so the estimate is unbiased wherever one density is
//! positive, and the cosine density is positive on the whole upper hemisphere.
//!
//! - **Environment** (`p_env`): the lighting's own importance sampling of level 0
//!   ([`crate::Lighting::environment`]: texels weighted by the luminance of the bilinear
//!   reconstruction averaged over each texel, times `sin theta`; uniform in `(u, v)` within a
//!   texel), the one the reference mode draws from too. Its density is evaluated exactly for
//!   every direction and is positive wherever the bilinear lookup is, so reading `L` bilinearly
//!   costs no bias, and a sun does not throw fireflies.
//! - **Cosine** (`p_cos = cos theta_i / pi`): Malley's method, `wi = (sqrt(u0) cos 2 pi u1,
//!   sqrt(u0) sin 2 pi u1, sqrt(1 - u0))`.
//! - **MERL-grid half vector** (`p_h`): `x_h = u0`, `theta_h = (pi / 2) x_h^2` (MERL's
//!   square-root spacing: uniform over its `theta_h` cells), `phi_h = 2 pi u1`,
//!   `wi = 2 (wo . h) h - wo`; `wo . h <= 0` draws nothing. Over the solid angle of `h`,
//!   `dw_h = sin theta_h (pi x_h) dx_h dphi_h`, so `p(h) = 1 / (2 pi^2 x_h sin theta_h)`, and over
//!   `wi`, `p_h(wi) = p(h) / (4 (wo . h))` at `h = normalize(wi + wo)` (0 where `h.z <= 0`).
//!
//! The points are Owen-scrambled Sobol' sequences (`sampling::OwenSobol2D`), one per pixel and
//! strategy, drawn from `seed`: every point is uniform (no bias) and the rounds are stratified.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;
use sampling::OwenSobol2D;

use crate::error::Error;
use crate::shade::{ShadingFrame, brdf, shade_rows, visibility};
use crate::{Image, Lighting, Material, Scene};

/// The converged estimate of every covered pixel with `samples_per_strategy` rounds (see the
/// module documentation); uncovered pixels show the environment as in [`crate::render`].
/// Deterministic for a `seed`, whatever the number of threads.
pub fn converged(
    scene: &Scene,
    material: &Material,
    lighting: &Lighting,
    samples_per_strategy: u32,
    seed: u64,
) -> Result<Image, Error> {
    converged_with_progress(scene, material, lighting, samples_per_strategy, seed, &|_, _| {})
}

/// [`converged`], calling `progress(rows done, rows)` as rows finish (a progress bar's hook).
pub fn converged_with_progress(
    scene: &Scene,
    material: &Material,
    lighting: &Lighting,
    samples_per_strategy: u32,
    seed: u64,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<Image, Error> {
    if samples_per_strategy == 0 {
        return Err(Error::Invalid("the converged estimate needs at least one sample per strategy".into()));
    }
    let gbuffer = visibility(scene)?;
    let width = scene.width;
    Ok(shade_rows(scene, &gbuffer, lighting.mips.level(0), progress, |frame, x, y| {
        estimate(frame, material, lighting, samples_per_strategy, seed, (y * width + x) as u64)
    }))
}

/// The cosine strategy, in the shading frame (density [`pdf_cosine`]).
fn sample_cosine(u: [f64; 2]) -> DVec3 {
    let r = u[0].sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
    DVec3::new(r * cos_phi, r * sin_phi, (1.0 - u[0]).max(0.0).sqrt())
}

fn pdf_cosine(wi_local: DVec3) -> f64 {
    wi_local.z.max(0.0) / PI
}

/// The density over the solid angle of `h` of the MERL-grid half-vector strategy.
fn half_vector_density(theta_h: f64) -> f64 {
    let x_h = (theta_h / FRAC_PI_2).sqrt();
    let jacobian = 2.0 * PI * PI * x_h * theta_h.sin();
    if jacobian > 0.0 { 1.0 / jacobian } else { 0.0 }
}

/// The MERL-grid half-vector strategy, in the shading frame (density [`pdf_half_vector`]);
/// `None` when `wo . h <= 0`.
fn sample_half_vector(u: [f64; 2], wo: DVec3) -> Option<DVec3> {
    let h = merl::spherical_dir(FRAC_PI_2 * u[0] * u[0], 2.0 * PI * u[1]);
    let wo_h = wo.dot(h);
    (wo_h > 0.0).then(|| 2.0 * wo_h * h - wo)
}

fn pdf_half_vector(wi_local: DVec3, wo: DVec3) -> f64 {
    let sum = wi_local + wo;
    if sum.length_squared() == 0.0 {
        return 0.0;
    }
    let h = sum.normalize();
    let wo_h = wo.dot(h);
    if !(h.z > 0.0 && wo_h > 0.0) {
        return 0.0;
    }
    half_vector_density(merl::coords::theta_of(h)) / (4.0 * wo_h)
}

/// One pixel's estimate.
fn estimate(
    frame: &ShadingFrame,
    material: &Material,
    lighting: &Lighting,
    rounds: u32,
    seed: u64,
    pixel: u64,
) -> [f64; 3] {
    let wo = frame.wo_local;
    let (level0, env) = (lighting.mips.level(0), &lighting.environment);
    let sequences = [0, 1, 2].map(|s| OwenSobol2D::for_vector(seed, 3 * pixel + s));
    // `g / (p_env + p_cos + p_h)` of one direction, given in both frames.
    let contribution = |wi_local: DVec3, wi: DVec3, sum: &mut [f64; 3], env_pdf: Option<f64>| {
        if wi_local.z.is_nan() || wi_local.z <= 0.0 {
            return;
        }
        let f = brdf(material, wi_local, wo);
        if f == [0.0; 3] {
            return;
        }
        let p = env_pdf.unwrap_or_else(|| env.pdf(envmap::uv(wi).into()))
            + pdf_cosine(wi_local)
            + pdf_half_vector(wi_local, wo);
        if !(p > 0.0 && p.is_finite()) {
            return;
        }
        let radiance = level0.lookup(wi);
        for c in 0..3 {
            sum[c] += f[c] * f64::from(radiance[c]) * wi_local.z / p;
        }
    };
    let mut sum = [0.0f64; 3];
    for round in 0..rounds {
        let light = env.sample(sequences[0].point(round));
        if light.pdf > 0.0 {
            let wi = envmap::direction(light.uv[0], light.uv[1]);
            contribution(frame.to_local(wi), wi, &mut sum, Some(light.pdf));
        }
        let wi_local = sample_cosine(sequences[1].point(round));
        contribution(wi_local, frame.to_world(wi_local), &mut sum, None);
        if let Some(wi_local) = sample_half_vector(sequences[2].point(round), wo) {
            contribution(wi_local, frame.to_world(wi_local), &mut sum, None);
        }
    }
    sum.map(|s| s / f64::from(rounds))
}

//! Analytic BRDFs with known answers, and MERL tables made from them. They are the fixtures of
//! this project: a table of any of them can be generated in a test instead of being committed.

use std::f64::consts::PI;

use glam::DVec3;

use crate::table::{Dims, MerlTable};

/// Configurations whose sample directions lie this close to the horizon, or below, hold no data
/// in generated tables, as in MERL's own files (and `nbrdf2merl.py`).
pub const HORIZON_EPS: f64 = 1e-12;

/// An analytic, isotropic BRDF. Values are in 1/sr, per RGB channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Analytic {
    /// `f = albedo / pi`: directional albedo `albedo` at every angle.
    Lambertian { albedo: [f64; 3] },
    /// Energy-normalized Phong with a Lambertian term (Lewis 1994):
    /// `f = kd / pi + ks (n + 2) / (2 pi) max(0, wi . r)^n`, `r` the mirror of `wo` about the
    /// normal. Its directional albedo is exactly `kd + ks` at normal incidence and less elsewhere
    /// (part of the lobe falls below the horizon).
    Phong { n: f64, ks: [f64; 3], kd: [f64; 3] },
    /// Blinn-Phong with the usual approximate normalization
    /// `f = ks (n + 8) / (8 pi) cos^n theta_h`.
    BlinnPhong { n: f64, ks: [f64; 3] },
    /// GGX (Trowbridge-Reitz) microfacets, height-correlated Smith masking-shadowing and
    /// Schlick's Fresnel: `f = F(wi . h) D(h) G2(wi, wo) / (4 cos theta_i cos theta_o)`.
    Ggx { alpha: f64, f0: [f64; 3] },
}

impl Analytic {
    /// The largest Phong and Blinn-Phong exponent: a lobe about 1e-3 radians wide, finer than
    /// MERL's finest cells resolve.
    pub const MAX_EXPONENT: f64 = 1e6;
    /// The narrowest GGX width: a lobe about 1e-3 radians wide, the sharpest Phong exponent's.
    /// Narrower is a mirror a table cannot hold: its one cell at `theta_h = 0` grows as
    /// `1 / alpha^2` while every other goes to 0, and below about 1e-8 that cell is infinite
    /// (`alpha^2 - 1` rounds to `-1` in `D`).
    pub const MIN_ALPHA: f64 = 1e-3;
    /// The largest GGX width: far past the roughest material (1 is already very rough).
    pub const MAX_ALPHA: f64 = 100.0;

    /// The BRDF for directions above the horizon (`wi.z > 0`, `wo.z > 0`); zero otherwise.
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> [f64; 3] {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return [0.0; 3];
        }
        match *self {
            Analytic::Lambertian { albedo } => albedo.map(|a| a / PI),
            Analytic::Phong { n, ks, kd } => {
                let r = DVec3::new(-wo.x, -wo.y, wo.z);
                let lobe = (n + 2.0) / (2.0 * PI) * wi.dot(r).max(0.0).powf(n);
                [0, 1, 2].map(|c| kd[c] / PI + ks[c] * lobe)
            }
            Analytic::BlinnPhong { n, ks } => {
                let h = (wi + wo).normalize();
                let lobe = (n + 8.0) / (8.0 * PI) * h.z.max(0.0).powf(n);
                ks.map(|k| k * lobe)
            }
            Analytic::Ggx { alpha, f0 } => {
                let h = (wi + wo).normalize();
                let d = ggx_d(alpha, h.z);
                let g2 = 1.0 / (1.0 + smith_lambda(alpha, wi.z) + smith_lambda(alpha, wo.z));
                let schlick = (1.0 - wi.dot(h).clamp(0.0, 1.0)).powi(5);
                let common = d * g2 / (4.0 * wi.z * wo.z);
                f0.map(|f| (f + (1.0 - f) * schlick) * common)
            }
        }
    }

    /// A MERL table of this BRDF, sampled at the lower edge of every cell. Cells whose sample
    /// directions are within [`HORIZON_EPS`] of the horizon or below it hold no data.
    ///
    /// Every value is finite for exponents in `(0, MAX_EXPONENT]`, widths in
    /// `[MIN_ALPHA, MAX_ALPHA]` and reflectances in `[0, 1]`; outside them the table may not be,
    /// and this panics (the callers check their arguments against these ranges first).
    pub fn table(&self, dims: Dims) -> MerlTable {
        MerlTable::from_fn(dims, |hd| {
            let (wi, wo) = hd.to_dirs();
            (wi.z > HORIZON_EPS && wo.z > HORIZON_EPS).then(|| self.eval(wi, wo))
        })
    }
}

/// For people: `ggx alpha 0.2, f0 0.95 0.64 0.54`.
impl std::fmt::Display for Analytic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let rgb = |c: [f64; 3]| format!("{} {} {}", c[0], c[1], c[2]);
        match *self {
            Analytic::Lambertian { albedo } => write!(f, "lambertian albedo {}", rgb(albedo)),
            Analytic::Phong { n, ks, kd } if kd == [0.0; 3] => write!(f, "normalized phong n {n}, ks {}", rgb(ks)),
            Analytic::Phong { n, ks, kd } => write!(f, "normalized phong n {n}, ks {}, kd {}", rgb(ks), rgb(kd)),
            Analytic::BlinnPhong { n, ks } => write!(f, "blinn-phong n {n}, ks {}", rgb(ks)),
            Analytic::Ggx { alpha, f0 } => write!(f, "ggx alpha {alpha}, f0 {}", rgb(f0)),
        }
    }
}

/// GGX normal distribution, normalized so that `integral D(h) cos theta_h dh = 1`.
pub fn ggx_d(alpha: f64, cos_theta_h: f64) -> f64 {
    if cos_theta_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = cos_theta_h * cos_theta_h * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// Smith's Lambda for GGX: `(-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2`.
pub fn smith_lambda(alpha: f64, cos_theta: f64) -> f64 {
    let c2 = cos_theta * cos_theta;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * (-1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// Integral over the hemisphere of g(theta) sin(theta) dtheta dphi for an isotropic g,
    /// by a fine midpoint rule.
    fn hemisphere(g: impl Fn(f64) -> f64) -> f64 {
        let n = 200_000;
        let dt = FRAC_PI_2 / n as f64;
        (0..n).map(|i| (i as f64 + 0.5) * dt).map(|t| g(t) * t.sin() * dt).sum::<f64>() * 2.0 * PI
    }

    #[test]
    fn display_is_plain() {
        assert_eq!(
            Analytic::Ggx { alpha: 0.2, f0: [0.95, 0.64, 0.54] }.to_string(),
            "ggx alpha 0.2, f0 0.95 0.64 0.54"
        );
        assert_eq!(
            Analytic::Phong { n: 1000.0, ks: [1.0; 3], kd: [0.0; 3] }.to_string(),
            "normalized phong n 1000, ks 1 1 1"
        );
    }

    /// The ranges `table` documents give finite tables at their ends (a width of 1e-10 was
    /// accepted by `merl-synth` and panicked on an infinite cell).
    #[test]
    fn tables_at_the_ends_of_the_ranges_are_finite() {
        let (one, zero) = ([1.0; 3], [0.0; 3]);
        let ends = [
            Analytic::Ggx { alpha: Analytic::MIN_ALPHA, f0: one },
            Analytic::Ggx { alpha: Analytic::MIN_ALPHA, f0: zero },
            Analytic::Ggx { alpha: Analytic::MAX_ALPHA, f0: one },
            Analytic::Phong { n: Analytic::MAX_EXPONENT, ks: one, kd: one },
            Analytic::Phong { n: f64::MIN_POSITIVE, ks: one, kd: zero },
            Analytic::BlinnPhong { n: Analytic::MAX_EXPONENT, ks: one },
            Analytic::BlinnPhong { n: f64::MIN_POSITIVE, ks: one },
        ];
        for brdf in ends {
            let table = brdf.table(Dims::MERL);
            assert!(table.raw().iter().all(|v| v.is_finite()), "{brdf}");
        }
        // What the lower bound excludes: a narrower lobe's cells at theta_h = 0 are infinite.
        assert!(ggx_d(Analytic::MIN_ALPHA, 1.0).is_finite());
        assert!(!ggx_d(1e-10, 1.0).is_finite());
    }

    #[test]
    fn ggx_ndf_is_normalized() {
        // A property of D alone, independent of the BRDF code: the projected microfacet area is 1.
        for alpha in [0.05, 0.2, 0.5, 1.0] {
            let total = hemisphere(|t| ggx_d(alpha, t.cos()) * t.cos());
            assert!((total - 1.0).abs() < 1e-4, "alpha {alpha}: {total}");
        }
    }

    #[test]
    fn phong_albedo_at_normal_incidence_is_kd_plus_ks() {
        for (n, kd) in [(1.0, 0.0), (10.0, 0.0), (100.0, 0.0), (10.0, 0.15)] {
            let wo = DVec3::Z;
            let phong = Analytic::Phong { n, ks: [0.8, 0.5, 0.2], kd: [kd; 3] };
            let a = hemisphere(|t| phong.eval(crate::spherical_dir(t, 0.0), wo)[0] * t.cos());
            assert!((a - 0.8 - kd).abs() < 1e-4, "n {n}, kd {kd}: {a}");
        }
    }

    #[test]
    fn reciprocity() {
        let brdfs = [
            Analytic::Phong { n: 20.0, ks: [0.2; 3], kd: [0.8, 0.5, 0.1] },
            Analytic::BlinnPhong { n: 20.0, ks: [1.0; 3] },
            Analytic::Ggx { alpha: 0.3, f0: [0.04, 0.5, 0.9] },
        ];
        let (a, b) = (crate::spherical_dir(0.3, 0.5), crate::spherical_dir(1.1, 2.9));
        for brdf in brdfs {
            let (x, y) = (brdf.eval(a, b), brdf.eval(b, a));
            for c in 0..3 {
                assert!((x[c] - y[c]).abs() <= 1e-12 * x[c].abs(), "{brdf:?}: {x:?} {y:?}");
            }
        }
    }

    #[test]
    fn generated_table_marks_the_horizon_like_merl() {
        // nbrdf2merl.py reports 346 570 below-horizon cells per channel for 90 x 90 x 180.
        let t = Analytic::Lambertian { albedo: [0.5; 3] }.table(Dims::MERL);
        assert_eq!(t.no_data_cells(), 346_570);
    }
}

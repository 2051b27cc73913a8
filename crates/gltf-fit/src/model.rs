//! The BRDF of glTF 2.0's metallic-roughness material (the specification's Appendix B) with
//! `KHR_materials_specular` and `KHR_materials_clearcoat`, as one function: [`brdf`].

use std::f64::consts::PI;

use glam::DVec3;

/// The factors of a glTF material that the BRDF reads (no textures: one value per material).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// `pbrMetallicRoughness.baseColorFactor`'s RGB, linear, each in `[0, 1]`.
    pub base_color: [f64; 3],
    /// `metallicFactor`, in `[0, 1]`.
    pub metallic: f64,
    /// `roughnessFactor`, in `[0, 1]`; the GGX width is `alpha = roughness^2`.
    pub roughness: f64,
    /// `KHR_materials_specular.specularFactor`, in `[0, 1]` (1 without the extension).
    pub specular: f64,
    /// `KHR_materials_specular.specularColorFactor`, each `>= 0` (1 without the extension).
    pub specular_color: [f64; 3],
    /// `KHR_materials_clearcoat.clearcoatFactor`, in `[0, 1]` (0 without the extension: no coat).
    pub clearcoat: f64,
    /// `KHR_materials_clearcoat.clearcoatRoughnessFactor`, in `[0, 1]`; the coat's GGX width is
    /// its square. Read only where `clearcoat > 0`.
    pub clearcoat_roughness: f64,
}

impl Material {
    /// The core material: `KHR_materials_specular` at its defaults, which leave the BRDF as the
    /// core specification defines it.
    pub fn core(base_color: [f64; 3], metallic: f64, roughness: f64) -> Material {
        Material {
            base_color,
            metallic,
            roughness,
            specular: 1.0,
            specular_color: [1.0; 3],
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
        }
    }

    /// Whether the material needs `KHR_materials_specular` (its factors are not the defaults).
    pub fn uses_specular_extension(&self) -> bool {
        self.specular != 1.0 || self.specular_color != [1.0; 3]
    }

    /// Whether the material needs `KHR_materials_clearcoat` (it has a coat).
    pub fn uses_clearcoat_extension(&self) -> bool {
        self.clearcoat != 0.0
    }

    /// The glTF extensions the material needs, in the order `fit.json` and the glTF list them.
    pub fn extensions(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self.uses_specular_extension() {
            out.push("KHR_materials_specular");
        }
        if self.uses_clearcoat_extension() {
            out.push("KHR_materials_clearcoat");
        }
        out
    }

    /// The GGX width `alpha = roughness^2`.
    pub fn alpha(&self) -> f64 {
        self.roughness * self.roughness
    }

    /// The dielectric Fresnel term at `v.h = 1` per channel (`KHR_materials_specular`'s
    /// `dielectric_f0`, see [`brdf`]): `min(0.04 specularColor, 1) specular`.
    pub fn dielectric_f0(&self) -> [f64; 3] {
        self.specular_color.map(|c| (DIELECTRIC_F0 * c).min(1.0) * self.specular)
    }

    /// The albedo of the diffuse lobe where the Fresnel term is its `v.h = 1` value, per channel:
    /// `(1 - metallic) (1 - max_value(dielectric_f0)) baseColor`, what [`brdf`] weighs
    /// `baseColor / pi` by there (the weight grows smaller towards grazing `v.h`).
    pub fn diffuse_albedo(&self) -> [f64; 3] {
        let f0_max = self.dielectric_f0().into_iter().fold(f64::MIN, f64::max);
        self.base_color.map(|b| (1.0 - self.metallic) * (1.0 - f0_max) * b)
    }
}

/// The masking-shadowing term of the specular BRDF. The specification's Appendix B sample
/// implementation (B.3.2, non-normative) writes the separable form of Smith's function; the
/// Khronos sample renderer, three.js and Filament evaluate the height-correlated form (Heitz
/// 2014), which is also `merl::analytic::Analytic::Ggx`'s. The fit uses the height-correlated
/// form by default (what conformant viewers draw) and records which it used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Masking {
    /// `G2 = 1 / (1 + Lambda(wi) + Lambda(wo))`.
    #[default]
    HeightCorrelated,
    /// `G2 = G1(wi) G1(wo)`, `G1 = 1 / (1 + Lambda)`: Appendix B.3.2's formula.
    Separable,
}

impl Masking {
    /// The name `fit.json` records.
    pub fn name(self) -> &'static str {
        match self {
            Masking::HeightCorrelated => "height-correlated",
            Masking::Separable => "separable",
        }
    }
}

/// glTF's dielectric F0 for its fixed index of refraction 1.5: `((1 - ior) / (1 + ior))^2`.
pub const DIELECTRIC_F0: f64 = 0.04;

/// The visibility term `V = G2 / (4 |n.l| |n.v|)` of the specification (B.3.2), in the
/// algebraically simplified forms that never divide by a cosine:
///
/// - separable: `V = 1 / (|n.l| + sqrt(a2 + (1 - a2) (n.l)^2)) * 1 / (|n.v| + sqrt(a2 + (1 - a2) (n.v)^2))`
/// - height-correlated: `V = 0.5 / (|n.l| sqrt(a2 + (1 - a2) (n.v)^2) + |n.v| sqrt(a2 + (1 - a2) (n.l)^2))`
///
/// `a2 = alpha^2`.
pub fn visibility(masking: Masking, alpha: f64, n_l: f64, n_v: f64) -> f64 {
    let a2 = alpha * alpha;
    let root = |c: f64| (a2 + (1.0 - a2) * c * c).sqrt();
    match masking {
        Masking::Separable => 1.0 / ((n_l + root(n_l)) * (n_v + root(n_v))),
        Masking::HeightCorrelated => 0.5 / (n_l * root(n_v) + n_v * root(n_l)),
    }
}

/// The Trowbridge-Reitz (GGX) distribution of B.3.2:
/// `D = alpha^2 chi+(n.h) / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)`.
pub fn ggx_d(alpha: f64, n_h: f64) -> f64 {
    merl::analytic::ggx_d(alpha, n_h)
}

/// The cosines a BRDF of a microfacet model reads, computed once per direction pair (the fit
/// evaluates many materials at the same pairs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    pub n_l: f64,
    pub n_v: f64,
    pub n_h: f64,
    pub v_h: f64,
}

impl Geometry {
    /// `wi` (the light, `l`) and `wo` (the viewer, `v`) in the shading frame (`z` the normal).
    pub fn new(wi: DVec3, wo: DVec3) -> Geometry {
        let h = (wi + wo).normalize();
        Geometry { n_l: wi.z, n_v: wo.z, n_h: h.z, v_h: wo.dot(h) }
    }

    /// The pair the other way round: the light at `wo`, the viewer at `wi` (`v.h = l.h`).
    pub fn swapped(&self) -> Geometry {
        Geometry { n_l: self.n_v, n_v: self.n_l, ..*self }
    }
}

/// The BRDF of glTF 2.0's metallic-roughness material (Appendix B.2 and B.3) with
/// `KHR_materials_specular`, in 1/sr per linear RGB channel, for directions above the surface
/// (zero otherwise):
///
/// ```text
/// material        = mix(dielectric_brdf, metal_brdf, metallic)
///                 = (1 - metallic) dielectric_brdf + metallic metal_brdf
/// metal_brdf      = conductor_fresnel(f0 = baseColor, bsdf = specular_brdf(alpha))
///                 = (baseColor + (1 - baseColor) (1 - |v.h|)^5) specular_brdf(alpha)
/// dielectric_brdf = fresnel_mix(ior = 1.5, base = diffuse_brdf(baseColor), layer = specular_brdf(alpha))
/// specular_brdf   = V D                  (B.3.2, V from [`visibility`], D from [`ggx_d`])
/// diffuse_brdf    = baseColor / pi       (B.3.3)
/// alpha           = roughness^2
/// ```
///
/// `KHR_materials_specular` (its Implementation section) gives `fresnel_mix` a colour and a
/// weight:
///
/// ```text
/// dielectric_f0      = min(0.04 specularColor, 1) specular
/// dielectric_f90     = specular
/// dielectric_fresnel = dielectric_f0 + (dielectric_f90 - dielectric_f0) (1 - |v.h|)^5
/// dielectric_brdf    = dielectric_fresnel specular_brdf + (1 - max_value(dielectric_fresnel)) diffuse_brdf
/// ```
///
/// With the extension's defaults (`specular = 1`, `specularColor = 1`) this is the core
/// specification's `mix(diffuse, specular, 0.04 + 0.96 (1 - |v.h|)^5)`.
///
/// `KHR_materials_clearcoat` (its Layering section) lays a colourless GGX lobe over the result,
/// weighted by a Fresnel term of the viewing angle:
///
/// ```text
/// coated = mix(material, specular_brdf(clearcoatRoughness^2), clearcoat fr)
/// fr     = 0.04 + 0.96 (1 - |v.n|)^5
/// ```
///
/// `fr` reads the viewer's direction alone, so a coated material is not reciprocal: `g` is the
/// light `l` and the viewer `v` in that order ([`Geometry::swapped`] gives the other reading).
pub fn brdf(m: &Material, masking: Masking, g: &Geometry) -> [f64; 3] {
    if g.n_l <= 0.0 || g.n_v <= 0.0 {
        return [0.0; 3];
    }
    let alpha = m.alpha();
    let specular_brdf = visibility(masking, alpha, g.n_l, g.n_v) * ggx_d(alpha, g.n_h);
    let fresnel_w = (1.0 - g.v_h.abs()).powi(5);
    let dielectric_fresnel = m.dielectric_f0().map(|f0| f0 + (m.specular - f0) * fresnel_w);
    let fresnel_max = dielectric_fresnel.iter().copied().fold(f64::MIN, f64::max);
    let mut out = [0.0; 3];
    for c in 0..3 {
        let diffuse_brdf = m.base_color[c] / PI;
        let dielectric = dielectric_fresnel[c] * specular_brdf + (1.0 - fresnel_max) * diffuse_brdf;
        let metal = (m.base_color[c] + (1.0 - m.base_color[c]) * fresnel_w) * specular_brdf;
        out[c] = (1.0 - m.metallic) * dielectric + m.metallic * metal;
    }
    if m.clearcoat > 0.0 {
        let alpha_c = m.clearcoat_roughness * m.clearcoat_roughness;
        let coat = visibility(masking, alpha_c, g.n_l, g.n_v) * ggx_d(alpha_c, g.n_h);
        let weight = m.clearcoat * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * (1.0 - g.n_v.abs()).powi(5));
        out = out.map(|base| base * (1.0 - weight) + coat * weight);
    }
    out
}

/// [`brdf`] for a direction pair.
pub fn eval(m: &Material, masking: Masking, wi: DVec3, wo: DVec3) -> [f64; 3] {
    brdf(m, masking, &Geometry::new(wi, wo))
}

#[cfg(test)]
mod tests {
    use super::*;
    use merl::albedo::{Quadrature, directional_albedo};
    use merl::analytic::Analytic;
    use merl::spherical_dir;

    /// Directions spread over the upper hemisphere (no randomness needed: a fixed grid of
    /// elevations and azimuths, grazing ones included).
    fn pairs() -> Vec<(DVec3, DVec3)> {
        let thetas = [0.0, 0.2, 0.5, 0.9, 1.2, 1.45, 1.55];
        let phis = [0.0, 0.7, 2.0, 3.1];
        let mut out = Vec::new();
        for &ti in &thetas {
            for &to in &thetas {
                for &p in &phis {
                    out.push((spherical_dir(ti, p), spherical_dir(to, 0.3)));
                }
            }
        }
        out
    }

    /// An independent evaluation of the height-correlated GGX microfacet BRDF with Schlick
    /// Fresnel: `merl::analytic`'s `F D G2 / (4 cos_i cos_o)`, written from Lambda rather than
    /// from the visibility's simplified form. A metal (metallic 1) is exactly that with
    /// `F0 = baseColor`; the two agree to rounding (1e-12 relative).
    #[test]
    fn a_metal_is_merl_analytic_ggx() {
        for (roughness, base) in [(0.2, [0.95, 0.64, 0.54]), (0.6, [0.5, 0.5, 0.5]), (1.0, [1.0, 0.1, 0.0])] {
            let m = Material::core(base, 1.0, roughness);
            let ggx = Analytic::Ggx { alpha: m.alpha(), f0: base };
            for (wi, wo) in pairs() {
                let (a, b) = (eval(&m, Masking::HeightCorrelated, wi, wo), ggx.eval(wi, wo));
                for c in 0..3 {
                    assert!((a[c] - b[c]).abs() <= 1e-12 * b[c].abs().max(1e-3), "{m:?} {wi} {wo}: {a:?} {b:?}");
                }
            }
        }
    }

    /// The diffuse lobe's albedo is what [`brdf`] adds per unit of `baseColor / pi` where
    /// `v.h = 1` (light and viewer along the normal): two dielectrics that differ only in their
    /// base colour differ there by `diffuse_albedo`'s difference over pi (their specular lobes,
    /// which do not read the base colour, cancel), for the extension's factors, including a
    /// specular colour whose `0.04 specularColor` passes 1 and is clamped; a metal has none.
    #[test]
    fn the_diffuse_albedo_is_the_weight_brdf_gives_the_base_colour_at_the_normal() {
        let n = DVec3::Z;
        for (specular, specular_color) in [(1.0, [1.0; 3]), (0.3, [2.0, 9.0, 40.0]), (0.0, [1.0; 3])] {
            let with = |base: [f64; 3]| Material { specular, specular_color, ..Material::core(base, 0.0, 0.4) };
            let (a, b) = (with([0.8, 0.5, 0.2]), with([0.1, 0.1, 0.1]));
            let (fa, fb) = (eval(&a, Masking::HeightCorrelated, n, n), eval(&b, Masking::HeightCorrelated, n, n));
            let (da, db) = (a.diffuse_albedo(), b.diffuse_albedo());
            for c in 0..3 {
                let expected = (da[c] - db[c]) / PI;
                assert!((fa[c] - fb[c] - expected).abs() <= 1e-12, "{specular} {specular_color:?}: {fa:?} {fb:?}");
            }
        }
        // The clamped colour: min(0.04 x 40, 1) x 0.3 = 0.3 is the largest f0, so 0.7 of the base.
        let clamped =
            Material { specular: 0.3, specular_color: [2.0, 9.0, 40.0], ..Material::core([1.0; 3], 0.0, 0.4) };
        assert!((clamped.diffuse_albedo()[0] - 0.7).abs() < 1e-15);
        assert_eq!(Material::core([0.9; 3], 1.0, 0.4).diffuse_albedo(), [0.0; 3]);
    }

    /// The separable form is `F D G1(wi) G1(wo) / (4 cos_i cos_o)` with `G1 = 1 / (1 + Lambda)`
    /// (the specification's G), here from `merl::analytic::smith_lambda`.
    #[test]
    fn separable_visibility_is_the_product_of_g1() {
        for alpha in [0.01, 0.3, 1.0] {
            for (wi, wo) in pairs() {
                let g1 = |c: f64| 1.0 / (1.0 + merl::analytic::smith_lambda(alpha, c));
                let expected = g1(wi.z) * g1(wo.z) / (4.0 * wi.z * wo.z);
                let v = visibility(Masking::Separable, alpha, wi.z, wo.z);
                assert!((v - expected).abs() <= 1e-12 * expected, "alpha {alpha}: {v} {expected}");
            }
        }
    }

    /// A dielectric with `KHR_materials_specular`'s `specular = 0` is a Lambertian of albedo
    /// `baseColor` exactly (the extension's "pure diffuse material").
    #[test]
    fn specular_zero_is_lambertian() {
        let m = Material {
            base_color: [0.8, 0.4, 0.1],
            metallic: 0.0,
            roughness: 0.3,
            specular: 0.0,
            specular_color: [1.0; 3],
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
        };
        for (wi, wo) in pairs() {
            let f = eval(&m, Masking::HeightCorrelated, wi, wo);
            let expected = Analytic::Lambertian { albedo: m.base_color }.eval(wi, wo);
            assert_eq!(f, expected, "{wi} {wo}");
        }
    }

    /// The extension's defaults are the core BRDF: `mix(diffuse, specular, F)` with
    /// `F = 0.04 + 0.96 (1 - v.h)^5`, written here as the core specification writes it.
    #[test]
    fn extension_defaults_are_the_core_dielectric() {
        let m = Material::core([0.3, 0.6, 0.9], 0.0, 0.5);
        for (wi, wo) in pairs() {
            let g = Geometry::new(wi, wo);
            let f = brdf(&m, Masking::HeightCorrelated, &g);
            let fr = 0.04 + 0.96 * (1.0 - g.v_h).powi(5);
            let spec = visibility(Masking::HeightCorrelated, 0.25, g.n_l, g.n_v) * ggx_d(0.25, g.n_h);
            for c in 0..3 {
                let expected = (1.0 - fr) * m.base_color[c] / PI + fr * spec;
                assert!((f[c] - expected).abs() <= 1e-14 * expected.max(1.0), "{f:?} {expected}");
            }
        }
    }

    /// White furnace bounds: a white metal's directional albedo is at most 1 (single scattering
    /// loses energy, never gains it) and, for a smooth one, close to 1 (within 2% at roughness
    /// 0.1: the masking loss of a narrow lobe is about alpha^2). A white dielectric is not bounded
    /// by 1 exactly: the specification's `fresnel_mix` weighs the diffuse by `1 - F(v.h)` of each
    /// `wi`, not by what the specular lobe reflects, and gains energy towards grazing (measured at
    /// roughness 0.5: 1.011 at 60 degrees, 1.082 at 80), hence its bound 1.1. The quadrature is `merl`'s, accurate to
    /// 5e-4 on a Lambertian.
    #[test]
    fn white_furnace() {
        let q = Quadrature::default();
        for theta_deg in [0.0_f64, 30.0, 60.0, 80.0] {
            for (m, low, high) in [
                (Material::core([1.0; 3], 1.0, 0.1), 0.98, 1.001),
                (Material::core([1.0; 3], 1.0, 0.7), 0.6, 1.001),
                (Material::core([1.0; 3], 0.0, 0.5), 0.8, 1.1),
            ] {
                for masking in [Masking::HeightCorrelated, Masking::Separable] {
                    let a = directional_albedo(|wi, wo| Some(eval(&m, masking, wi, wo)), theta_deg.to_radians(), q);
                    let a = a.rgb[0];
                    assert!(a <= high && a >= low, "{m:?} {masking:?} theta_o {theta_deg}: albedo {a}");
                }
            }
        }
    }

    #[test]
    fn reciprocity() {
        let m = Material {
            base_color: [0.3, 0.6, 0.9],
            metallic: 0.4,
            roughness: 0.35,
            specular: 0.7,
            specular_color: [1.5, 0.5, 3.0],
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
        };
        for masking in [Masking::HeightCorrelated, Masking::Separable] {
            for (wi, wo) in pairs() {
                let (a, b) = (eval(&m, masking, wi, wo), eval(&m, masking, wo, wi));
                for c in 0..3 {
                    assert!((a[c] - b[c]).abs() <= 1e-12 * a[c].abs().max(1e-6), "{a:?} {b:?}");
                }
            }
        }
    }

    /// `KHR_materials_clearcoat` over a Lambertian base (`specular = 0`): the base weighed by
    /// `1 - clearcoat fr` plus the coat, a GGX lobe with `F = 1` (`merl::analytic`'s, from Lambda)
    /// weighed by `clearcoat fr`, `fr = 0.04 + 0.96 (1 - cos theta_o)^5` of the viewer's angle.
    /// Not reciprocal: the two readings of a pair differ where the two angles do.
    #[test]
    fn clearcoat_is_a_colourless_lobe_weighed_by_the_viewing_fresnel() {
        let base = [0.5, 0.25, 0.125];
        let m = Material { specular: 0.0, clearcoat: 0.8, clearcoat_roughness: 0.3, ..Material::core(base, 0.0, 0.6) };
        let coat = Analytic::Ggx { alpha: 0.09, f0: [1.0; 3] };
        let mut asymmetric = 0;
        for (wi, wo) in pairs() {
            let weight = 0.8 * (0.04 + 0.96 * (1.0 - wo.z).powi(5));
            let lobe = coat.eval(wi, wo)[0];
            let f = eval(&m, Masking::HeightCorrelated, wi, wo);
            for c in 0..3 {
                let expected = base[c] / PI * (1.0 - weight) + lobe * weight;
                assert!((f[c] - expected).abs() <= 1e-12 * expected, "{wi} {wo}: {f:?} {expected}");
            }
            let back = eval(&m, Masking::HeightCorrelated, wo, wi);
            if (back[0] - f[0]).abs() > 1e-6 * f[0] {
                asymmetric += 1;
                assert!((wi.z - wo.z).abs() > 1e-9, "{wi} {wo}");
            }
        }
        assert!(asymmetric > 0, "a coat's readings never differed");
        assert_eq!(m.extensions(), ["KHR_materials_specular", "KHR_materials_clearcoat"]);
    }
}

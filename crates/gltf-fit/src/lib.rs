//! The glTF material closest to a measured BRDF: fits the BRDF of glTF 2.0's metallic-roughness
//! material, with `KHR_materials_specular` or `KHR_materials_clearcoat`, to a MERL table (`brdf-fit`), and writes the result
//! as a glTF asset and as a MERL table of its own. No IO: tables in, materials and bytes out.
//!
//! # The model ([`model`])
//!
//! Exactly the BRDF of the specification's Appendix B, written once in [`model::brdf`] with its
//! equations: `mix(dielectric_brdf, metal_brdf, metallic)`, GGX `D` with `alpha = roughness^2`,
//! Smith masking-shadowing, Schlick's Fresnel, a Lambertian `baseColor / pi` under the
//! dielectric's Fresnel, `KHR_materials_specular`'s weight and colour of the dielectric F0, and
//! `KHR_materials_clearcoat`'s colourless second lobe, weighed by a Fresnel term of the viewing
//! angle (which makes a coated material non-reciprocal: the fit compares each reading of a
//! pair with the table's cell, and a coated material's table holds the mean of the two).
//! The masking term is a choice ([`Masking`]): Appendix B.3.2's sample implementation
//! writes the separable Smith function, while the Khronos sample renderer, three.js and Filament
//! draw the height-correlated one; the default is height-correlated, what conformant viewers
//! show, and the fit records which it used.
//!
//! # The initial estimate ([`estimate`])
//!
//! Dupuy et al. 2015's power iteration recovers the microfacet distribution `D(theta)` from the
//! table's backscattering `f(k, k)`, the cells at `theta_d = 0`; the GGX width is the one whose
//! `D` is closest to it in the projected-area measure, and `roughness = sqrt(alpha)`. For a
//! roughness, `baseColor` follows by linear least squares (the BRDF is linear in it), for a
//! dielectric and for a metal, and the one of lower objective starts the refinement.
//!
//! # The refinement ([`mod@fit`])
//!
//! Levenberg-Marquardt over the table's cells, each weighted by its measure in `dwi dwo`, on the
//! error of `ln(1 + f cos theta)` per channel, taken with `cos theta_i` and with `cos theta_o`
//! (the table holds both readings of a pair in one cell). Why the logarithm: the reflected
//! radiance of a light is `f cos theta_i`, and the logarithm compresses the specular peak, whose
//! few cells hold values thousands of times the diffuse body's, so that the body, which covers
//! most of a picture, is not traded for the peak's last percent; where `f cos` is small it is
//! the linear error. Measured in pictures (`cargo bench -p brdf-preview --bench fits`: each of the
//! 20 real-derived tables fitted under both objectives, the kept material's exact render against
//! the table's under a sunlit and an indoor map), this objective draws the better picture for 17
//! and 18 of the 20 materials, by 3.2 and 3.0 dB at the median (from -3.5 to +10.6 and -4.2 to
//! +12.3 dB; the metals gain most: chrome +10.6 / +12.3, steel +9.6 / +6.1); the linear objective
//! is kept ([`Objective::LinearCosine`], `brdf-fit --objective`) so that the
//! two can be compared on every table, and `fit.json` reports the kept material under both
//! (`objective.by_kind`). Three variants are refined: the core material (`baseColor`,
//! `metallic`, `roughness`); a dielectric with `KHR_materials_specular` (`baseColor`,
//! `roughness`, `specular`, `specularColor`), which covers coloured and weak specular reflection
//! and a Fresnel whose grazing value (`specular`) is below 1, which the core material cannot; and
//! the core material under `KHR_materials_clearcoat` (`clearcoat`, `clearcoatRoughness`), a
//! second lobe for a sharp peak over a broad body, refined from two starts (the core's lobe as
//! the coat over a rougher base, and a rougher coat over the core). A variant with an extension is
//! kept only when its objective is lower than the core's by [`Settings::margin`], the lower of
//! two that are. `cargo bench -p brdf-preview --bench fits` renders every variant of the 20
//! real-derived materials against the measured tables and reports how often the least objective
//! draws the best picture.
//!
//! The result is reported with the directional albedo of both tables at 0, 30, 60 and 80
//! degrees ([`fit::albedo_rows`]) and written as a glTF sphere ([`gltf`]) and as a MERL table
//! ([`fit::fitted_table`]) that every estimator of the project renders exactly.

pub mod estimate;
pub mod fit;
pub mod gltf;
pub mod model;

pub use fit::{
    AlbedoRow, Fit, Objective, Settings, Stage, Variant, VariantFit, albedo_rows, fit, fit_reporting, fitted_table,
    objective,
};
pub use model::{Masking, Material};

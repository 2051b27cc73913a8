//! Values behind valid checksums: each field a reader takes is held to the
//! range its meaning allows, and a value outside it is refused with the field and the value,
//! whatever its sizes say. One table: the kind, the edit, what the message says.

use asset::{
    Asset, BandwidthAnalysis, BandwidthAtlas, BandwidthPca, BandwidthRows, ImportanceSamples, LayerSelection,
    LinkedFile, MaterialInfo, Payload, PrefilteredEnvmap,
};

fn importance() -> ImportanceSamples {
    let wi = [0.6f32, 0.0, 0.8];
    ImportanceSamples {
        theta_o: vec![0.0],
        n_vectors: 1,
        n_samples: 2,
        theta_h_edges: vec![0.0, std::f64::consts::FRAC_PI_2],
        n_phi_h: 2,
        samples: vec![[wi[0], wi[1], wi[2], 1.5], [wi[0], wi[1], wi[2], 0.0]],
        marginal_cdf: vec![0.0, 1.0],
        conditional_cdf: vec![0.0, 0.5, 1.0],
        h_density: vec![0.25, 0.0],
    }
}

fn prefiltered() -> PrefilteredEnvmap {
    let file = |name: &str| LinkedFile { name: name.into(), sha256: [7; 32] };
    PrefilteredEnvmap {
        source_size: [64, 32],
        source_mean_radiance: [0.5, 0.25, 0.0],
        layer_size: [16, 8],
        mip_levels: 7,
        layers_radiance_scale: 1.0,
        mips_radiance_scale: 1.0,
        exponents: vec![1, 4],
        lobe_bandwidth: vec![0.27, 0.39],
        bandwidth_thresholds: vec![0.32],
        layer_mean_radiance: vec![[0.5, 0.25, 0.0]; 2],
        layers_ktx2: file("layers.ktx2"),
        layer_exrs: vec![file("layer-n1.exr"), file("layer-n4.exr")],
        mips_ktx2: file("mips.ktx2"),
        contact_sheet_png: file("layers.png"),
    }
}

fn analysis() -> BandwidthAnalysis {
    BandwidthAnalysis { parameterization: "incidence-plane-equidistant".into(), analysis_size: 128, eps: 0.01, c: 0.18 }
}

fn rows() -> BandwidthRows {
    BandwidthRows { lobes_x: 4, lobes_y: 2, tile: 1, analysis: analysis(), data: vec![3.0, 0.0] }
}

fn selection() -> LayerSelection {
    LayerSelection {
        analysis: analysis(),
        rows: 2,
        reduction: "band-0.99".into(),
        exponents: vec![1, 4],
        layer_bandwidth: vec![0.27, 0.39],
        view_bandwidth: vec![0.3, 0.0],
        view_layer: vec![0, 1],
    }
}

fn atlas() -> BandwidthAtlas {
    BandwidthAtlas { lobes_x: 1, lobes_y: 2, tile: 1, analysis: analysis(), data: vec![3.0, 0.0] }
}

/// Two lobes of 2 x 2 texels and one component.
fn pca() -> BandwidthPca {
    BandwidthPca {
        lobes_x: 2,
        lobes_y: 1,
        tile: 2,
        analysis: analysis(),
        n_components: 1,
        mean: vec![3.0, 1.0, 0.0, 2.0],
        components: vec![0.5, 0.5, -0.5, -0.5],
        coefficients: vec![1.5, -2.0],
    }
}

fn material_info() -> MaterialInfo {
    MaterialInfo {
        dims: [90, 90, 180],
        no_data_cells: 0,
        channel_min: [0.1; 3],
        channel_max: [2.0; 3],
        channel_mean: [0.3; 3],
        peak_rgb: [2.0; 3],
        peak_cell: [0, 0, 0],
        albedo_theta_o: vec![0.0, 1.0],
        albedo_rgb: vec![[0.5; 3]; 2],
        albedo_no_data_fraction: vec![0.0, 0.01],
    }
}

/// The message decoding `payload` gives, or `None` when it reads.
fn refusal(payload: Payload) -> Option<String> {
    let asset = Asset { provenance: crate::small_asset().provenance, payload };
    asset::decode(&asset::encode(&asset)).err().map(|e| e.to_string())
}

#[test]
fn the_untouched_payloads_read() {
    for payload in [
        importance().into(),
        prefiltered().into(),
        rows().into(),
        atlas().into(),
        selection().into(),
        pca().into(),
        material_info().into(),
    ] {
        let payload: Payload = payload;
        assert_eq!(refusal(payload.clone()), None, "{payload:?}");
    }
}

#[test]
fn values_outside_their_ranges_are_refused_with_the_field_and_the_value() {
    type Edit<T> = fn(&mut T);
    let importance_cases: [(Edit<ImportanceSamples>, &str); 10] = [
        (
            |p| p.samples[1] = [1e30; 4],
            "sample 1 (slice 0, vector 0, sample 1): wi (1e30, 1e30, 1e30) is not a unit direction",
        ),
        (|p| p.samples[0] = [-1.0; 4], "sample 0 (slice 0, vector 0, sample 0): wi (-1e0, -1e0, -1e0) is not a unit"),
        (|p| p.samples[0] = [-0.0; 4], "wi (-0e0, -0e0, -0e0) is not a unit direction"),
        (|p| p.samples[0] = [1e-40; 4], "is not a unit direction"),
        (|p| p.samples[0][3] = f32::NAN, "sample 0 (slice 0, vector 0, sample 0): pdf NaN is not a finite density"),
        (|p| p.samples[1][3] = -1.0, "pdf -1e0 is not a finite density of 0 or more"),
        (|p| p.h_density[1] = f32::INFINITY, "h density 1 is inf, not a finite density of 0 or more"),
        (|p| p.h_density[0] = -0.5, "h density 0 is -5e-1"),
        (|p| p.marginal_cdf[1] = 1.5, "marginal cdf value 1 is 1.5e0, outside [0, 1]"),
        (|p| p.conditional_cdf[0] = f32::NAN, "conditional cdf value 0 is NaN, outside [0, 1]"),
    ];
    for (edit, needle) in importance_cases {
        let mut p = importance();
        edit(&mut p);
        let e = refusal(p.into()).expect("refused");
        assert_eq!(e.strip_prefix("invalid payload: importance samples: ").map(|_| ()), Some(()), "{e}");
        assert!(e.contains(needle), "{e}\nshould say {needle:?}");
    }
    let prefiltered_cases: [(Edit<PrefilteredEnvmap>, &str); 5] = [
        (|p| p.source_mean_radiance[1] = f64::NAN, "the source's mean radiance [0.5, NaN, 0.0] is not finite"),
        (|p| p.layer_mean_radiance[1][0] = f64::INFINITY, "layer 1's mean radiance [inf, 0.25, 0.0]"),
        (|p| p.layer_mean_radiance[0][2] = -1.0, "layer 0's mean radiance [0.5, 0.25, -1.0]"),
        (|p| p.layer_size = [1 << 31, 1 << 30], "layers of 2147483648 x 1073741824, taller than the 8192 rows"),
        (|p| p.mip_levels = u32::MAX, "4294967295 mip levels of a 64 x 32 source, which has at most 7"),
    ];
    for (edit, needle) in prefiltered_cases {
        let mut p = prefiltered();
        edit(&mut p);
        let e = refusal(p.into()).expect("refused");
        assert!(
            e.starts_with("invalid payload: prefiltered envmap: ") && e.contains(needle),
            "{e}\nshould say {needle:?}"
        );
    }
    // Bandwidths: within twice the analysis grid's limit, c n / 4 (here 128 and 0.18: 11.52).
    for (value, shown) in [(1e30f32, "1e30"), (f32::NAN, "NaN"), (-1.0, "-1e0"), (11.6, "1.16e1")] {
        let outside = format!("is {shown}, outside [0, 11.52] cycles per radian (twice the limit of a 128 grid)");
        let mut p = rows();
        p.data[1] = value;
        assert_eq!(refusal(p.into()).expect("refused"), format!("invalid payload: bandwidth rows: texel 1 {outside}"));
        let mut p = atlas();
        p.data[0] = value;
        assert_eq!(refusal(p.into()).expect("refused"), format!("invalid payload: bandwidth atlas: texel 0 {outside}"));
        let mut p = selection();
        p.view_bandwidth[1] = value.into();
        let e = refusal(p.into()).expect("refused");
        assert!(e.starts_with("invalid payload: layer selection: view bandwidth 1 is "), "{e}");
    }
    let mut p = selection();
    p.view_bandwidth[0] = 1e300;
    let e = refusal(p.into()).expect("refused");
    assert!(
        e.ends_with("view bandwidth 0 is 1e300, outside [0, 11.52] cycles per radian (twice the limit of a 128 grid)"),
        "{e}"
    );
    let mut p = selection();
    p.layer_bandwidth[0] = f64::INFINITY;
    assert!(refusal(p.into()).expect("refused").contains("layer bandwidth 0 is inf, outside"));
}

#[test]
fn pca_and_material_info_values_outside_their_ranges_are_refused() {
    type Edit<T> = fn(&mut T);
    // The bound: 11.52 cycles per radian (see above); coefficients within sqrt(4) x 11.52 = 23.04.
    let pca_cases: [(Edit<BandwidthPca>, &str); 5] = [
        (|p| p.mean[1] = 1e30, "bandwidth pca: mean value 1 is 1e30, outside [0, 11.52] cycles per radian"),
        (|p| p.mean[0] = -1.0, "mean value 0 is -1e0, outside"),
        (|p| p.components[0] = 2.0, "bandwidth pca: component 0 has length 2.179449471770337e0, not 1"),
        (|p| p.coefficients[1] = f32::NAN, "bandwidth pca: coefficient 0 of lobe 1 is NaN, outside [-23.04, 23.04]"),
        (|p| p.coefficients[0] = 24.0, "coefficient 0 of lobe 0 is 2.4e1, outside"),
    ];
    for (edit, needle) in pca_cases {
        let mut p = pca();
        edit(&mut p);
        let e = refusal(p.into()).expect("refused");
        assert!(e.starts_with("invalid payload: bandwidth pca: ") && e.contains(needle), "{e}\nshould say {needle:?}");
    }
    let info_cases: [(Edit<MaterialInfo>, &str); 4] = [
        (|p| p.channel_max[1] = f64::INFINITY, "material info: a statistic or an albedo is inf, not finite"),
        (|p| p.albedo_rgb[1][2] = f64::NAN, "a statistic or an albedo is NaN"),
        (|p| p.albedo_no_data_fraction[0] = 2.0, "material info: a no-data fraction is 2e0, outside [0, 1]"),
        (|p| p.albedo_theta_o[1] = 4.0, "material info: an albedo angle is 4e0 radians, outside [0, pi / 2]"),
    ];
    for (edit, needle) in info_cases {
        let mut p = material_info();
        edit(&mut p);
        let e = refusal(p.into()).expect("refused");
        assert!(e.contains(needle), "{e}\nshould say {needle:?}");
    }
}

/// The check across fields that decoding leaves to the renderers' reader: each pdf is the density
/// `h_density[cell of h] / (4 wo . h)` of its direction. A sample `wi = (0, 0.6, 0.8)` seen from
/// the pole has `h = (0, 0.6, 1.8) / |.|` in the middle of sector 0 of the one row (`phi_h = pi /
/// 2`; on an edge, at `phi_h = 0`, sector 1's density of 0 would be as near), `wo . h = 1.8 /
/// sqrt(3.6)`.
#[test]
fn pdfs_that_are_not_their_tables_densities_are_found() {
    let wo_h = 1.8 / 3.6f64.sqrt();
    let density = 0.25 / (4.0 * wo_h);
    let with_pdf = |pdf: f64| {
        let mut p = importance();
        p.samples[0] = [0.0, 0.6, 0.8, pdf as f32];
        p
    };
    assert_eq!(with_pdf(density).check_densities(), Ok(()));
    // Within the stated tolerance, 1e-3 + 1e-6 / (wo . h) relatively, and just past it.
    assert_eq!(with_pdf(density * (1.0 + 0.9e-3)).check_densities(), Ok(()));
    for (pdf, needle) in [
        (density * 1.002, "is not the density the tables give its direction (6.588"),
        (0.0, "pdf 0e0 is not the density"),
        (1.5, "sample 0 (slice 0, vector 0, sample 0): pdf 1.5e0 is not the density"),
    ] {
        let e = with_pdf(pdf).check_densities().expect_err("a pdf off its tables");
        assert!(e.contains(needle), "{pdf}: {e}");
        // Decoding takes it: its values are within their ranges.
        assert_eq!(refusal(with_pdf(pdf).into()), None);
    }
    // Sector 1 has no density: a direction there may only have pdf 0, and a pdf for a direction
    // whose half vector is below the horizon is refused.
    let mut p = with_pdf(density);
    p.samples[1] = [0.0, -0.6, 0.8, 0.0];
    assert_eq!(p.check_densities(), Ok(()));
    p.samples[1][3] = 0.1;
    assert!(p.check_densities().unwrap_err().contains("sample 1 "), "{p:?}");
    p.samples[1] = [0.0, 0.0, -1.0, 0.1];
    assert!(p.check_densities().unwrap_err().contains("no half vector above the surface reflects"));

    // The golden file of version 1 decodes (the format's promise) and its pdfs are twice its
    // tables' densities: asset-info reports it, the previewer would refuse it.
    let golden = asset::read_file(&crate::fixtures_dir().join("assets/golden-v1-importance-samples.asset")).unwrap();
    let Payload::ImportanceSamples(golden) = golden.payload else { panic!("importance samples") };
    assert!(golden.check_densities().unwrap_err().contains("is not the density"));
}

//! A Lambertian material has a flat atlas: every lobe is a constant, so no texel may report a
//! frequency, and in particular none may read the rounding noise of the lookups and the
//! transform as signal. The noise floor (relative to each lobe's peak) is what makes it so.

use bandwidth_atlas::{Config, build_atlas};
use merl::Dims;
use merl::analytic::Analytic;

fn lambertian() -> merl::MerlTable {
    Analytic::Lambertian { albedo: [0.8, 0.5, 0.2] }.table(Dims::MERL)
}

#[test]
fn a_lambertian_atlas_is_flat() {
    // Every lobe of a 16 x 16 grid, grazing ones included (the table has no data below the
    // horizon, so those lobes exercise the hole filling and the renormalized lookups).
    let config = Config { lobes: 16, analysis_size: 64, ..Config::default() };
    let build = build_atlas(&lambertian(), &config, &|_| {}).unwrap();
    let nonzero = build.atlas.data.iter().filter(|v| **v != 0.0).count();
    println!(
        "lambertian: {nonzero} of {} texels nonzero, {} lobes at the limit, {} pixels filled",
        build.atlas.data.len(),
        build.stats.nyquist_lobes(),
        build.stats.filled_pixels
    );
    assert_eq!(nonzero, 0, "largest texel {}", build.atlas.data.iter().fold(0.0f32, |m, v| m.max(*v)));
    assert_eq!(build.stats.nyquist_lobes(), 0);
}

#[test]
fn without_the_noise_floor_rounding_noise_reads_as_signal() {
    // The same material with the floor at zero: the lookups' rounding (1e-16 relative) is all
    // the detail there is, and the relative test of eq. 7 reads it. This is why the test above
    // can fail.
    let config = Config { lobes: 4, analysis_size: 64, relative_noise_floor: 0.0, ..Config::default() };
    let build = build_atlas(&lambertian(), &config, &|_| {}).unwrap();
    let nonzero = build.atlas.data.iter().filter(|v| **v != 0.0).count();
    println!("lambertian without a noise floor: {nonzero} of {} texels nonzero", build.atlas.data.len());
    assert!(nonzero > 0);
}

//! Refusals: every bad input is an `Error` naming the problem, never a panic.

use bandwidth::{
    Config, Error, Image, WindowedFftConfig, latlong_bandwidth, local_bandwidth, local_bandwidth_zero_padded,
    log1p_luminance, windowed_fft_bandwidth,
};

fn message(e: Error) -> String {
    e.to_string()
}

#[test]
fn sizes_that_leave_too_few_levels_are_refused() {
    let e = local_bandwidth(&Image::zeros(1000, 500), &Config::default()).unwrap_err();
    assert!(matches!(e, Error::Size(_)), "{e:?}");
    assert_eq!(
        message(e),
        "image is 1000x500: the height 500 allows 2 level(s) only, which leave 125 coefficients on the shorter \
         side at the coarsest level (at most 3 allowed); pad or resample it, or set the levels"
    );
    assert!(matches!(local_bandwidth(&Image::zeros(1, 8), &Config::default()), Err(Error::Size(_))));
    assert!(matches!(latlong_bandwidth(&Image::zeros(33, 16), &Config::default()), Err(Error::Size(_))));
    assert!(matches!(local_bandwidth_zero_padded(&Image::zeros(0, 0), &Config::default()), Err(Error::Size(_))));
    // Padded, levels beyond twice the image would only analyse (and allocate) zeros.
    let deep = Config { levels: Some(9), ..Config::default() };
    assert!(matches!(local_bandwidth_zero_padded(&Image::zeros(100, 20), &deep), Err(Error::Config(_))));
    let deepest = Config { levels: Some(8), ..Config::default() };
    assert_eq!(local_bandwidth_zero_padded(&Image::zeros(100, 20), &deepest).unwrap().levels(), 8);
    // Levels set by hand must divide the size: the transform says so.
    let e = local_bandwidth(&Image::zeros(24, 24), &Config { levels: Some(4), ..Config::default() }).unwrap_err();
    assert!(matches!(e, Error::Wavelet(dwt::Error::TooManyLevels { .. })), "{e:?}");
    // 24 allows 3 levels, leaving 3 coefficients: accepted.
    assert_eq!(local_bandwidth(&Image::zeros(24, 24), &Config::default()).unwrap().levels(), 3);
}

#[test]
fn non_finite_values_are_refused() {
    let mut image = Image::zeros(16, 16);
    image.data_mut()[17] = f64::NAN;
    assert!(matches!(local_bandwidth(&image, &Config::default()), Err(Error::Wavelet(_))));
    assert!(matches!(
        local_bandwidth_zero_padded(&image, &Config::default()),
        Err(Error::NonFinite { what: "image", index: 17 })
    ));
    let image = Image::from_fn(32, 32, |x, _| if x == 3 { f64::INFINITY } else { 0.0 });
    assert!(matches!(windowed_fft_bandwidth(&image, &WindowedFftConfig::default()), Err(Error::NonFinite { .. })));
}

#[test]
fn bad_configurations_are_refused() {
    let image = Image::zeros(16, 16);
    for config in [
        Config { eps: 0.0, ..Config::default() },
        Config { eps: f64::NAN, ..Config::default() },
        Config { noise_floor: -1.0, ..Config::default() },
        Config { c: 0.0, ..Config::default() },
        Config { levels: Some(0), ..Config::default() },
    ] {
        // Every entry point refuses it, not just the plain one.
        assert!(matches!(local_bandwidth(&image, &config), Err(Error::Config(_))), "{config:?}");
        assert!(matches!(local_bandwidth_zero_padded(&image, &config), Err(Error::Config(_))), "{config:?}");
        let latlong = Image::zeros(32, 16);
        assert!(matches!(latlong_bandwidth(&latlong, &config), Err(Error::Config(_))), "{config:?}");
    }
    let image = Image::zeros(64, 64);
    for config in [
        WindowedFftConfig { window: 31, ..WindowedFftConfig::default() },
        WindowedFftConfig { stride: 0, ..WindowedFftConfig::default() },
        WindowedFftConfig { energy_fraction: 1.0, ..WindowedFftConfig::default() },
        WindowedFftConfig { zero_pad: 0, ..WindowedFftConfig::default() },
    ] {
        assert!(matches!(windowed_fft_bandwidth(&image, &config), Err(Error::Config(_))), "{config:?}");
    }
    let small = WindowedFftConfig::default();
    assert!(matches!(windowed_fft_bandwidth(&Image::zeros(31, 64), &small), Err(Error::Size(_))));
}

/// `ln(1 + Y)` with Rec. 709 weights; negative luminance clamps to 0; bad data is refused.
#[test]
fn log1p_luminance_known_answers() {
    let rgb: [[f32; 3]; 4] = [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, -1.0, -1.0]];
    let image = log1p_luminance(2, 2, &rgb).unwrap();
    let want = [2f64.ln(), 0.0, (1.0f64 + 0.2126).ln(), 0.0];
    for (got, want) in image.data().iter().zip(want) {
        assert!((got - want).abs() < 1e-7, "{got} vs {want}");
    }
    assert!(matches!(log1p_luminance(3, 2, &rgb), Err(Error::DataLength { .. })));
    let bad: [[f64; 3]; 1] = [[f64::NAN, 0.0, 0.0]];
    assert!(matches!(log1p_luminance(1, 1, &bad), Err(Error::NonFinite { index: 0, .. })));
}

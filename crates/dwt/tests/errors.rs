//! Each documented error, with its message.

use dwt::{
    Decomposition, Decomposition2, Error, Image, Wavelet, dwt, dwt2, idwt, idwt2, wavedec, wavedec2, waverec, waverec2,
};

fn check<T: std::fmt::Debug>(result: Result<T, Error>, want: Error, message: &str) {
    let got = result.expect_err("an error");
    assert_eq!(got, want);
    assert_eq!(got.to_string(), message);
}

const W: Wavelet = Wavelet::D4;

#[test]
fn sizes_that_do_not_fit_the_rule() {
    check(
        dwt(&[1.0; 7], W),
        Error::TooManyLevels { dim: "length", len: 7, levels: 1, max: 0 },
        "length 7 is not divisible by 2^1, needed for 1 level(s); it allows at most 0",
    );
    check(
        wavedec(&[1.0; 24], W, 4),
        Error::TooManyLevels { dim: "length", len: 24, levels: 4, max: 3 },
        "length 24 is not divisible by 2^4, needed for 4 level(s); it allows at most 3",
    );
    check(
        wavedec(&[1.0; 16], W, 5),
        Error::TooManyLevels { dim: "length", len: 16, levels: 5, max: 4 },
        "length 16 is not divisible by 2^5, needed for 5 level(s); it allows at most 4",
    );
    check(
        wavedec2(&Image::zeros(64, 24), W, 4),
        Error::TooManyLevels { dim: "height", len: 24, levels: 4, max: 3 },
        "height 24 is not divisible by 2^4, needed for 4 level(s); it allows at most 3",
    );
    check(
        dwt2(&Image::zeros(5, 4), W),
        Error::TooManyLevels { dim: "width", len: 5, levels: 1, max: 0 },
        "width 5 is not divisible by 2^1, needed for 1 level(s); it allows at most 0",
    );
}

#[test]
fn zero_levels_and_empty_inputs() {
    check(wavedec(&[1.0; 8], W, 0), Error::ZeroLevels, "zero levels requested: at least one level is needed");
    check(
        wavedec2(&Image::zeros(8, 8), W, 0),
        Error::ZeroLevels,
        "zero levels requested: at least one level is needed",
    );
    let dec = Decomposition { wavelet: W, approx: vec![1.0; 4], details: vec![] };
    check(waverec(&dec), Error::ZeroLevels, "zero levels requested: at least one level is needed");
    check(wavedec(&[], W, 1), Error::Empty { what: "signal" }, "signal is empty");
    check(dwt2(&Image::zeros(0, 4), W), Error::Empty { what: "image" }, "image is empty");
    check(idwt(&[], &[], W), Error::Empty { what: "approximation" }, "approximation is empty");
}

#[test]
fn non_finite_values() {
    let mut x = vec![0.5; 16];
    x[5] = f64::NAN;
    check(
        wavedec(&x, W, 2),
        Error::NonFinite { what: "signal".into(), index: 5 },
        "signal holds a non-finite value at index 5",
    );
    let mut image = Image::zeros(8, 8);
    image.data_mut()[8 * 3 + 1] = f64::NEG_INFINITY;
    check(
        wavedec2(&image, W, 1),
        Error::NonFinite { what: "image".into(), index: 25 },
        "image holds a non-finite value at index 25",
    );
    // The first level's pass checks each row as it reads it: a value anywhere, in every row,
    // with both wavelets, one level or several, and the first of two is the one named.
    for wavelet in [Wavelet::Haar, W] {
        for index in (0..256).step_by(7) {
            let mut image = Image::zeros(16, 16);
            image.data_mut()[index] = f64::NAN;
            image.data_mut()[255] = f64::INFINITY;
            let want = || Error::NonFinite { what: "image".into(), index };
            assert_eq!(wavedec2(&image, wavelet, 3).unwrap_err(), want(), "{wavelet:?} at {index}");
            assert_eq!(dwt2(&image, wavelet).unwrap_err(), want(), "{wavelet:?} at {index}");
        }
    }
    // Finite values whose coefficients overflow are not the image's fault: no error.
    let huge = Image::new(8, 8, vec![f64::MAX; 64]).unwrap();
    assert!(wavedec2(&huge, W, 2).is_ok());
    // Past the first block of the scan too.
    let mut long = vec![0.0; 4096];
    long[3001] = f64::INFINITY;
    check(
        dwt(&long, W),
        Error::NonFinite { what: "signal".into(), index: 3001 },
        "signal holds a non-finite value at index 3001",
    );
    let mut dec = wavedec2(&Image::zeros(8, 8), W, 2).unwrap();
    dec.detail_mut(1, dwt::Orientation::Diagonal).data_mut()[2] = f64::NAN;
    check(
        waverec2(&dec),
        Error::NonFinite { what: "level 1 diagonal detail".into(), index: 2 },
        "level 1 diagonal detail holds a non-finite value at index 2",
    );
}

#[test]
fn coefficients_that_do_not_fit_together() {
    check(
        idwt(&[1.0; 4], &[1.0; 3], W),
        Error::ShapeMismatch("approximation has 4 coefficients, detail has 3".into()),
        "coefficient shapes do not match: approximation has 4 coefficients, detail has 3",
    );
    let mut dec = wavedec(&[1.0; 32], W, 3).unwrap();
    dec.details[1].pop();
    check(
        waverec(&dec),
        Error::ShapeMismatch("level 2 detail has 7 coefficients, expected 8".into()),
        "coefficient shapes do not match: level 2 detail has 7 coefficients, expected 8",
    );
    let mut dec = wavedec2(&Image::zeros(16, 8), W, 2).unwrap();
    dec.details[0][1] = Image::zeros(8, 3);
    check(
        waverec2(&dec),
        Error::ShapeMismatch("level 1 vertical detail is 8x3, expected 8x4".into()),
        "coefficient shapes do not match: level 1 vertical detail is 8x3, expected 8x4",
    );
    let details = [Image::zeros(4, 4), Image::zeros(4, 4), Image::zeros(4, 2)];
    check(
        idwt2(&Image::zeros(4, 4), &details, W),
        Error::ShapeMismatch("level 1 diagonal detail is 4x2, expected 4x4".into()),
        "coefficient shapes do not match: level 1 diagonal detail is 4x2, expected 4x4",
    );
    let dec = Decomposition2 { wavelet: W, approx: Image::zeros(2, 2), details: vec![] };
    check(waverec2(&dec), Error::ZeroLevels, "zero levels requested: at least one level is needed");
}

#[test]
fn image_data_of_the_wrong_length() {
    check(
        Image::new(4, 3, vec![0.0; 11]),
        Error::DataLength { width: 4, height: 3, len: 11 },
        "image data holds 11 values, expected 4x3 = 12",
    );
}

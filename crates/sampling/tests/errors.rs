use sampling::{Distribution1D, Distribution2D, Error};

/// `result` is `expected`, and its message reads `message`: lower case, no trailing period.
#[track_caller]
fn check<T: std::fmt::Debug>(result: Result<T, Error>, expected: Error, message: &str) {
    let error = result.unwrap_err();
    assert_eq!(error.to_string(), message);
    assert_eq!(error, expected);
    assert!(message.starts_with(|c: char| !c.is_uppercase()) && !message.ends_with('.'), "{message}");
}

#[test]
fn empty_1d() {
    check(Distribution1D::new(&[]), Error::Empty, "function has no values, need at least one");
}

#[test]
fn nan_1d_names_the_first_bad_index() {
    let result = Distribution1D::new(&[1.0, 2.0, f64::NAN, -1.0]);
    assert!(matches!(result, Err(Error::InvalidValue { index: 2, value }) if value.is_nan()), "{result:?}");
    assert_eq!(result.unwrap_err().to_string(), "func[2] is NaN, expected a finite value >= 0");
}

#[test]
fn infinity_1d() {
    let expected = Error::InvalidValue { index: 0, value: f64::INFINITY };
    check(Distribution1D::new(&[f64::INFINITY]), expected, "func[0] is inf, expected a finite value >= 0");
}

#[test]
fn negative_1d() {
    let expected = Error::InvalidValue { index: 1, value: -0.5 };
    check(Distribution1D::new(&[1.0, -0.5]), expected, "func[1] is -0.5, expected a finite value >= 0");
}

#[test]
fn negative_zero_is_zero() {
    let d = Distribution1D::new(&[-0.0, 1.0]).unwrap();
    assert_eq!(d.sample(0.0).index, 1);
}

#[test]
fn wrong_size_2d() {
    let expected = Error::WrongSize { len: 5, nu: 2, nv: 3 };
    check(Distribution2D::new(&[1.0; 5], 2, 3), expected, "function has 5 values, expected nu * nv = 2 * 3");
}

#[test]
fn overflowing_size_2d() {
    let expected = Error::WrongSize { len: 4, nu: usize::MAX, nv: 2 };
    let message = format!("function has 4 values, expected nu * nv = {} * 2", usize::MAX);
    check(Distribution2D::new(&[1.0; 4], usize::MAX, 2), expected, &message);
}

#[test]
fn empty_grid_2d() {
    check(Distribution2D::new(&[], 0, 3), Error::EmptyGrid { nu: 0, nv: 3 }, "grid is 0 x 3, need nu >= 1 and nv >= 1");
    check(Distribution2D::new(&[], 2, 0), Error::EmptyGrid { nu: 2, nv: 0 }, "grid is 2 x 0, need nu >= 1 and nv >= 1");
}

#[test]
fn negative_2d_names_the_row_major_index() {
    // Row 1, column 2 of a 3-wide grid.
    let mut func = vec![1.0; 6];
    func[5] = -2.0;
    let expected = Error::InvalidValue { index: 5, value: -2.0 };
    check(Distribution2D::new(&func, 3, 2), expected, "func[5] is -2, expected a finite value >= 0");
}

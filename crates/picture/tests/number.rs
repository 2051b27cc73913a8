use picture::format_number;

/// The examples the labels need: 4 significant digits, integers from 1000 on, no exponent in
/// 1e-3 ..= 1e5, no trailing zeros, no float noise.
#[test]
fn examples() {
    let cases = [
        (0.0, "0"),
        (0.001, "0.001"),
        (0.00123456, "0.001235"),
        (4.56789, "4.568"),
        (123.456, "123.5"),
        (1234.6, "1235"),
        (99999.0, "99999"),
        (1e5, "100000"),
        (2.0, "2"),
        (0.1 + 0.2, "0.3"),
        (-12.5, "-12.5"),
        (9.99996, "10"),
        (2.5e-4, "2.5e-4"),
        (1.2e6, "1.2e6"),
        (-3.0e-7, "-3e-7"),
        (123456.0, "1.235e5"),
    ];
    for (v, text) in cases {
        assert_eq!(format_number(v), text, "{v}");
    }
}

/// Read back, a label is within half a unit of its 4th significant digit of the value: a
/// relative error below 5e-4 (values from a fixed pseudo-random sequence over 16 decades).
#[test]
fn round_trip() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    for _ in 0..2000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let u = (state >> 11) as f64 / (1u64 << 53) as f64;
        let v = 10f64.powf(16.0 * u - 8.0) * if state & 1 == 1 { -1.0 } else { 1.0 };
        let text = format_number(v);
        let back: f64 = text.parse().unwrap();
        assert!(((back - v) / v).abs() <= 5e-4, "{v} -> {text}");
        assert!(text.len() <= 9, "{v} -> {text} is long");
    }
}

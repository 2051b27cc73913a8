//! Numbers as labels: short, without exponents where a reader does not need one.

/// `v` with 4 significant digits (fewer for numbers of 1000 and more, which are rounded to an
/// integer), trailing zeros dropped: `0.001`, `3.142`, `123.5`, `12346`. Outside
/// `1e-3 ..= 1e5` in magnitude, an exponent: `2.5e-4`, `1.2e6`. Zero is `0`.
pub fn format_number(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    if !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs();
    if (1e-3..=1e5).contains(&magnitude) {
        let decimals = (3 - magnitude.log10().floor() as i32).max(0) as usize;
        trim_zeros(format!("{v:.decimals$}"))
    } else {
        let text = format!("{v:.3e}");
        match text.split_once('e') {
            Some((mantissa, exponent)) => format!("{}e{exponent}", trim_zeros(mantissa.to_string())),
            None => text,
        }
    }
}

/// `1.500` -> `1.5`, `2.000` -> `2`; a number without a decimal point is left alone.
fn trim_zeros(text: String) -> String {
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

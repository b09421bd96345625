//! Plugin parameters written as RON text (the form `PluginCall::params` takes).

/// A finite number (Rust's shortest round-trip form, which RON reads back exactly).
pub(super) fn float(x: f64) -> String {
    format!("{x:?}")
}

pub(super) fn vec2(v: [f64; 2]) -> String {
    format!("({}, {})", float(v[0]), float(v[1]))
}

pub(super) fn vec3(v: [f64; 3]) -> String {
    format!("({}, {}, {})", float(v[0]), float(v[1]), float(v[2]))
}

/// A RON string literal.
pub(super) fn string(s: &str) -> String {
    ron::to_string(s).unwrap_or_else(|_| format!("{s:?}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_strings_read_back() {
        for x in [0.1, -2.0, 1e-7, 3e300, 1.0 / 3.0] {
            let back: f64 = ::ron::from_str(&float(x)).unwrap();
            assert_eq!(back, x);
        }
        let s = "dir/a \"b\"\\c.ppm";
        let back: String = ::ron::from_str(&string(s)).unwrap();
        assert_eq!(back, s);
    }
}

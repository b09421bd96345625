//! Parameter helpers shared by every texture: checked colours and numbers, defaults, and
//! `Factors`, a parameter that is either one number or one per axis.

use luxon_plugin::{finite, invalid, Error};
use serde::de::{self, Deserialize, Deserializer, IgnoredAny, SeqAccess, Visitor};

/// A colour parameter: finite and non-negative; alpha 1.
pub fn color(name: &str, c: [f64; 3]) -> Result<[f32; 4], Error> {
    let c = finite(name, c)?;
    if c.iter().any(|&x| x < 0.0) {
        return Err(invalid(format!(
            "parameter `{name}` must not be negative, got {c:?}"
        )));
    }
    Ok([c[0] as f32, c[1] as f32, c[2] as f32, 1.0])
}

/// A finite number greater than 0.
pub fn positive(name: &str, v: f64) -> Result<f64, Error> {
    let [v] = finite(name, [v])?;
    if v <= 0.0 {
        return Err(invalid(format!(
            "parameter `{name}` must be greater than 0, got {v}"
        )));
    }
    Ok(v)
}

/// A finite number that is not negative.
pub fn non_negative(name: &str, v: f64) -> Result<f64, Error> {
    let [v] = finite(name, [v])?;
    if v < 0.0 {
        return Err(invalid(format!(
            "parameter `{name}` must not be negative, got {v}"
        )));
    }
    Ok(v)
}

/// A finite, non-zero direction, normalised.
pub fn direction(name: &str, v: [f64; 3]) -> Result<[f64; 3], Error> {
    let v = finite(name, v)?;
    let len = v.iter().map(|a| a * a).sum::<f64>().sqrt();
    if len == 0.0 || !len.is_finite() {
        return Err(invalid(format!(
            "parameter `{name}` must be a non-zero finite direction, got {v:?}"
        )));
    }
    Ok(v.map(|a| a / len))
}

/// Fractal octaves: 1 to 16.
pub fn octaves(name: &str, n: u32) -> Result<u32, Error> {
    if !(1..=16).contains(&n) {
        return Err(invalid(format!(
            "parameter `{name}` must be between 1 and 16, got {n}"
        )));
    }
    Ok(n)
}

pub fn one() -> f64 {
    1.0
}

pub fn white() -> [f64; 3] {
    [1.0; 3]
}

pub fn up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

pub fn yes() -> bool {
    true
}

/// `N` per-axis factors, written as one number (the same on every axis) or as an `N`-tuple.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors<const N: usize>(pub [f64; N]);

impl<const N: usize> Default for Factors<N> {
    fn default() -> Self {
        Factors([1.0; N])
    }
}

impl<const N: usize> Factors<N> {
    /// Every factor finite and greater than 0.
    pub fn positive(self, name: &str) -> Result<[f64; N], Error> {
        let v = finite(name, self.0)?;
        if v.iter().any(|&x| x <= 0.0) {
            return Err(invalid(format!(
                "parameter `{name}` must be greater than 0, got {v:?}"
            )));
        }
        Ok(v)
    }

    /// Every factor finite and not 0 (a negative factor mirrors).
    pub fn nonzero(self, name: &str) -> Result<[f64; N], Error> {
        let v = finite(name, self.0)?;
        if v.contains(&0.0) {
            return Err(invalid(format!(
                "parameter `{name}` must not be 0, got {v:?}"
            )));
        }
        Ok(v)
    }
}

impl<'de, const N: usize> Deserialize<'de> for Factors<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for V<N> {
            type Value = Factors<N>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "a number or a tuple of {N} numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Factors<N>, E> {
                Ok(Factors([v; N]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Factors<N>, E> {
                Ok(Factors([v as f64; N]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Factors<N>, E> {
                Ok(Factors([v as f64; N]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Factors<N>, A::Error> {
                let mut out = [0.0; N];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element::<f64>()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(N + 1, &self));
                }
                Ok(Factors(out))
            }
        }
        d.deserialize_any(V::<N>)
    }
}

/// Rewrites RON/serde messages about nested texture specs (which reach the host as plain text)
/// into the host's wording: `unknown parameter `x`, did you mean `y`?`, `missing parameter`.
pub fn explain(message: &str) -> String {
    let quoted: Vec<&str> = message.split('`').skip(1).step_by(2).collect();
    let with_suggestion = |what: &str| {
        let found = quoted[0];
        let expected = &quoted[1..];
        let mut m = format!("unknown {what} `{found}`");
        if let Some(s) = luxon_plugin::suggest(found, expected.iter().copied()) {
            m.push_str(&format!(", did you mean `{s}`?"));
        }
        if !expected.is_empty() {
            m.push_str(&format!(" (expected one of: {})", expected.join(", ")));
        }
        m
    };
    if message.starts_with("Unexpected field named") && !quoted.is_empty() {
        with_suggestion("parameter")
    } else if (message.starts_with("Unexpected enum variant named")
        || message.starts_with("Unexpected variant named")
        || message.starts_with("unknown variant"))
        && !quoted.is_empty()
    {
        with_suggestion("variant")
    } else if message.starts_with("Unexpected missing field named") && !quoted.is_empty() {
        format!("missing parameter `{}`", quoted[0])
    } else {
        message.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_plugin::parse_params;

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    struct P {
        #[serde(default)]
        s3: Factors<3>,
        #[serde(default)]
        s2: Factors<2>,
    }

    #[test]
    fn factors_accept_a_number_or_a_tuple() {
        let p: P = parse_params("(s3: 2, s2: (0.5, 4))").unwrap();
        assert_eq!(p.s3.0, [2.0; 3]);
        assert_eq!(p.s2.0, [0.5, 4.0]);
        let p: P = parse_params("(s3: (1, 2.5, 3))").unwrap();
        assert_eq!(p.s3.0, [1.0, 2.5, 3.0]);
        assert_eq!(p.s2.0, [1.0, 1.0]);
        let e = parse_params::<P>("(s3: (1, 2))").unwrap_err();
        assert!(e.message.contains("3 numbers"), "{}", e.message);
        let e = parse_params::<P>("(s2: (1, 2, 3))").unwrap_err();
        assert!(e.message.contains("2 numbers"), "{}", e.message);
        assert!(Factors([1.0, 0.0]).positive("scale").is_err());
        assert!(Factors([1.0, f64::NAN]).positive("scale").is_err());
    }

    #[test]
    fn explain_rewrites_nested_messages() {
        assert_eq!(
            explain("Unexpected field named `scael`, expected one of `scale`, `rotate`, or `seed` instead"),
            "unknown parameter `scael`, did you mean `scale`? (expected one of: scale, rotate, seed)"
        );
        assert_eq!(
            explain("Unexpected missing field named `file`"),
            "missing parameter `file`"
        );
        assert_eq!(explain("something else"), "something else");
    }
}

//! File names with a frame number in them: `frame%04d.png`, `frame%d.png` or `frame####.png`
//! (four `#`: four digits). `%%` is a percent sign; any other `%` stays as it is.

/// A name with one place for the frame number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    prefix: String,
    /// Zero-padded to this many digits; `None`: as many as the number needs (`%d`).
    digits: Option<usize>,
    suffix: String,
}

/// The widest padding accepted (u32 frame numbers have at most 10 digits).
const MAX_DIGITS: usize = 10;

impl FramePattern {
    /// The pattern in `text`, or `None` when it has no frame number.
    pub fn parse(text: &str) -> Result<Option<FramePattern>, String> {
        let mut prefix = String::new();
        let mut found: Option<(Option<usize>, String)> = None;
        let chars: Vec<char> = text.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let (marker, len) = match chars[i] {
                '#' => {
                    let n = chars[i..].iter().take_while(|&&c| c == '#').count();
                    (Some(Some(n)), n)
                }
                '%' => match percent(&chars[i + 1..]) {
                    Percent::Literal(len) => {
                        out(&mut prefix, &mut found).push('%');
                        i += 1 + len;
                        continue;
                    }
                    Percent::Number(digits, len) => (Some(digits), 1 + len),
                    Percent::Bad(len) => {
                        let written: String = chars[i..i + 1 + len].iter().collect();
                        return Err(format!(
                            "`{written}` in `{text}` is not a frame number; expected %d or %0Nd \
                             (N digits, zero-padded)"
                        ));
                    }
                },
                c => {
                    out(&mut prefix, &mut found).push(c);
                    i += 1;
                    continue;
                }
            };
            if let Some(digits) = marker {
                if digits.is_some_and(|d| d > MAX_DIGITS) {
                    return Err(format!(
                        "`{text}` pads frame numbers to more than {MAX_DIGITS} digits; expected \
                         at most {MAX_DIGITS}"
                    ));
                }
                if found.is_some() {
                    return Err(format!(
                        "`{text}` has two frame numbers; expected one %d, %0Nd or #### where \
                         the frame number goes"
                    ));
                }
                found = Some((digits, String::new()));
            }
            i += len;
        }
        Ok(found.map(|(digits, suffix)| FramePattern {
            prefix,
            digits,
            suffix,
        }))
    }

    /// The name for frame `k`.
    pub fn name(&self, k: u32) -> String {
        let number = match self.digits {
            Some(d) => format!("{k:0d$}"),
            None => k.to_string(),
        };
        format!("{}{number}{}", self.prefix, self.suffix)
    }
}

/// Where the next character goes: the prefix until the marker is found, its suffix after.
fn out<'a>(
    prefix: &'a mut String,
    found: &'a mut Option<(Option<usize>, String)>,
) -> &'a mut String {
    match found {
        Some((_, suffix)) => suffix,
        None => prefix,
    }
}

enum Percent {
    /// A literal `%`, and how many characters after it belong to it.
    Literal(usize),
    /// `%d` (`None`) or `%0Nd`, and its length after the `%`.
    Number(Option<usize>, usize),
    /// `%Nd` and the like: meant as a number, but not one we read.
    Bad(usize),
}

/// What follows a `%`.
fn percent(rest: &[char]) -> Percent {
    match rest.first() {
        Some('%') => return Percent::Literal(1),
        Some('d') => return Percent::Number(None, 1),
        _ => {}
    }
    let digits = rest.iter().take_while(|c| c.is_ascii_digit()).count();
    if digits == 0 || rest.get(digits) != Some(&'d') {
        return Percent::Literal(0);
    }
    let text: String = rest[..digits].iter().collect();
    match (text.starts_with('0'), text.parse::<usize>()) {
        (true, Ok(n)) if n > 0 => Percent::Number(Some(n), digits + 1),
        _ => Percent::Bad(digits + 1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(p: &str, k: u32) -> String {
        FramePattern::parse(p).unwrap().expect("a pattern").name(k)
    }

    #[test]
    fn markers_pad_as_written() {
        assert_eq!(name("out/frame%04d.png", 7), "out/frame0007.png");
        assert_eq!(name("out/frame%04d.png", 123456), "out/frame123456.png");
        assert_eq!(name("f%d.exr", 42), "f42.exr");
        assert_eq!(name("f####.tga", 3), "f0003.tga");
        assert_eq!(name("#.ppm", 12), "12.ppm");
        assert_eq!(name("100%%-%03d.png", 5), "100%-005.png");
        assert_eq!(name("a%b%d", 5), "a%b5");
    }

    #[test]
    fn names_without_a_marker_are_not_patterns() {
        assert_eq!(FramePattern::parse("out.png"), Ok(None));
        assert_eq!(FramePattern::parse("50%.png"), Ok(None));
        assert_eq!(FramePattern::parse("100%%.png"), Ok(None));
    }

    #[test]
    fn bad_markers_are_errors() {
        let e = FramePattern::parse("f%04d_%d.png").unwrap_err();
        assert!(e.contains("has two frame numbers"), "{e}");
        let e = FramePattern::parse("f##_%d.png").unwrap_err();
        assert!(e.contains("has two frame numbers"), "{e}");
        let e = FramePattern::parse("f%5d.png").unwrap_err();
        assert!(
            e.contains("`%5d` in `f%5d.png` is not a frame number"),
            "{e}"
        );
        let e = FramePattern::parse("f%011d.png").unwrap_err();
        assert!(e.contains("more than 10 digits"), "{e}");
        let e = FramePattern::parse("f###########.png").unwrap_err();
        assert!(e.contains("more than 10 digits"), "{e}");
    }
}

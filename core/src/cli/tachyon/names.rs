//! The file names Tachyon writes. One image: `-o NAME` verbatim, else `outfile.<ext>`. A
//! sequence (the frames of `-camfile`, or several scene files): `cam.%04d.<ext>` or
//! `outfile.%04d.<ext>`, and with `-o NAME` Tachyon passes NAME to `sprintf` with the frame
//! number, so `-o frame%03d.tga` numbers the frames. A NAME without such a pattern would
//! make every frame overwrite the same file; Luxon numbers them instead (`movie.tga` →
//! `movie.0000.tga`, ...) and says so.

use super::args::usage;
use luxon::Error;
use std::ffi::OsStr;
use std::path::PathBuf;

/// A printf-like name with one `%d` conversion: `prefix`, the number (at least `width`
/// digits, zero-padded if `zero`), `suffix`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pattern {
    prefix: String,
    width: usize,
    zero: bool,
    suffix: String,
}

impl Pattern {
    /// The name of frame `n`.
    pub fn name(&self, n: usize) -> PathBuf {
        let number = if self.zero {
            format!("{n:0w$}", w = self.width)
        } else {
            format!("{n:w$}", w = self.width)
        };
        PathBuf::from(format!("{}{number}{}", self.prefix, self.suffix))
    }

    /// Reads `text` as printf would with one integer: `%d`, `%i`, `%Nd`, `%0Nd` and `%%`.
    /// `None` when it has no conversion; an error for any other conversion or a second one.
    fn parse(text: &str) -> Result<Option<Pattern>, String> {
        let mut prefix = String::new();
        let mut found: Option<(usize, bool)> = None;
        let mut suffix = String::new();
        let mut chars = text.chars().peekable();
        while let Some(c) = chars.next() {
            let out = if found.is_some() {
                &mut suffix
            } else {
                &mut prefix
            };
            if c != '%' {
                out.push(c);
                continue;
            }
            if chars.peek() == Some(&'%') {
                chars.next();
                out.push('%');
                continue;
            }
            let mut spec = String::new();
            while let Some(&d) = chars.peek().filter(|d| d.is_ascii_digit()) {
                spec.push(d);
                chars.next();
            }
            match chars.next() {
                Some('d' | 'i') if found.is_none() => {
                    let width = spec.parse().unwrap_or(0);
                    if width > 64 {
                        return Err(format!("the number width {width} is too large"));
                    }
                    found = Some((width, spec.starts_with('0')));
                }
                Some('d' | 'i') => {
                    return Err("it has two frame-number conversions; expected one".into())
                }
                other => {
                    let what = other.map_or("%".to_string(), |c| format!("%{spec}{c}"));
                    return Err(format!(
                        "`{what}` is not a frame-number conversion; expected %d or %04d (and \
                         %% for a percent sign)"
                    ));
                }
            }
        }
        Ok(found.map(|(width, zero)| Pattern {
            prefix,
            width,
            zero,
            suffix,
        }))
    }
}

/// The name of a single image: `-o NAME` as given, else `outfile.<ext>`.
pub fn single(output: Option<&OsStr>, extension: &str) -> PathBuf {
    match output {
        Some(name) => PathBuf::from(name),
        None => PathBuf::from(format!("outfile.{extension}")),
    }
}

/// The names of a sequence, and a warning when `-o NAME` had no frame-number pattern.
/// `default_stem`: `cam` for camera files, `outfile` for several scenes.
pub fn sequence(
    output: Option<&OsStr>,
    default_stem: &str,
    extension: &str,
) -> Result<(Pattern, Option<String>), Error> {
    let Some(name) = output else {
        let p = Pattern {
            prefix: format!("{default_stem}."),
            width: 4,
            zero: true,
            suffix: format!(".{extension}"),
        };
        return Ok((p, None));
    };
    let text = name.to_str().ok_or_else(|| {
        usage(format!(
            "-o {}: a name for numbered frames must be UTF-8 text",
            name.to_string_lossy()
        ))
    })?;
    match Pattern::parse(text) {
        Err(why) => Err(usage(format!("-o {}: {why}", luxon_formats::shown(text)))),
        Ok(Some(p)) => Ok((p, None)),
        Ok(None) => {
            // The number goes before the file name's extension, as in `cam.0000.tga`.
            let file_start = text.rfind('/').map_or(0, |i| i + 1);
            let (stem, ext) = match text[file_start..].rfind('.') {
                Some(i) if i > 0 => text.split_at(file_start + i),
                _ => (text, ""),
            };
            let p = Pattern {
                prefix: format!("{stem}."),
                width: 4,
                zero: true,
                suffix: ext.to_string(),
            };
            let warning = format!(
                "-o {text} has no frame-number pattern (Tachyon would write every frame over \
                 it); writing {}, {}, ... instead (put %04d in the name to choose where the \
                 number goes)",
                p.name(0).display(),
                p.name(1).display()
            );
            Ok((p, Some(warning)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(o: Option<&str>, stem: &str, ext: &str) -> (Vec<String>, Option<String>) {
        let (p, w) = sequence(o.map(OsStr::new), stem, ext).unwrap();
        let n = [0, 1, 12, 12345]
            .iter()
            .map(|&k| p.name(k).display().to_string())
            .collect();
        (n, w)
    }

    #[test]
    fn single_images_are_named_as_tachyon_names_them() {
        assert_eq!(single(None, "tga"), PathBuf::from("outfile.tga"));
        assert_eq!(single(None, "jpg"), PathBuf::from("outfile.jpg"));
        // Verbatim, whatever the format or a `%` in it.
        assert_eq!(
            single(Some(OsStr::new("x.png")), "tga"),
            PathBuf::from("x.png")
        );
        assert_eq!(single(Some(OsStr::new("a%d")), "tga"), PathBuf::from("a%d"));
    }

    #[test]
    fn sequences_use_tachyons_default_names() {
        let (n, w) = names(None, "cam", "tga");
        assert_eq!(
            n,
            [
                "cam.0000.tga",
                "cam.0001.tga",
                "cam.0012.tga",
                "cam.12345.tga"
            ]
        );
        assert!(w.is_none());
        assert_eq!(names(None, "outfile", "ppm").0[1], "outfile.0001.ppm");
    }

    #[test]
    fn printf_patterns_number_the_frames() {
        assert_eq!(
            names(Some("f%03d.png"), "cam", "tga").0,
            ["f000.png", "f001.png", "f012.png", "f12345.png"]
        );
        assert_eq!(names(Some("f%d.tga"), "cam", "tga").0[2], "f12.tga");
        assert_eq!(names(Some("f%4i.tga"), "cam", "tga").0[1], "f   1.tga");
        assert_eq!(names(Some("100%%-%02d"), "cam", "tga").0[1], "100%-01");
        assert!(names(Some("dir.d/f%04d.tga"), "cam", "tga").1.is_none());
    }

    #[test]
    fn a_name_without_a_pattern_gets_the_number_before_its_extension() {
        let (n, w) = names(Some("movie.tga"), "cam", "tga");
        assert_eq!(n[..2], ["movie.0000.tga", "movie.0001.tga"]);
        assert!(w
            .unwrap()
            .contains("writing movie.0000.tga, movie.0001.tga, ..."));
        assert_eq!(
            names(Some("out/movie"), "cam", "tga").0[1],
            "out/movie.0001"
        );
        assert_eq!(
            names(Some("a.b/movie"), "cam", "tga").0[1],
            "a.b/movie.0001"
        );
        assert_eq!(names(Some(".hidden"), "cam", "tga").0[1], ".hidden.0001");
    }

    #[test]
    fn other_conversions_are_errors() {
        for (o, fragment) in [
            ("f%s.tga", "`%s` is not a frame-number conversion"),
            ("f%d%d.tga", "two frame-number conversions"),
            ("f%", "`%` is not a frame-number conversion"),
            ("f%5.2f", "`%5.` is not a frame-number conversion"),
            ("f%99d", "the number width 99 is too large"),
        ] {
            let e = sequence(Some(OsStr::new(o)), "cam", "tga")
                .unwrap_err()
                .to_string();
            assert!(e.contains(fragment), "{o}: {e}");
        }
    }
}

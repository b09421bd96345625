//! Tachyon camera files (`-camfile`): a stream of numbers, nine per frame — VIEWDIR (3),
//! UPDIR (3), CENTER (3) — separated by any whitespace (line breaks mean nothing).
//!
//! Tachyon's end-of-file quirk is reproduced: it tests for the end of the file before reading
//! a frame, not after, so when anything (a newline) follows the last number it reads nothing,
//! keeps the last frame and renders it a second time. Every camera file VMD writes, and all of
//! Debian's examples, end with a newline: with the quirk, Luxon renders as many frames as
//! Tachyon, with the same names, and the last two images are the same.

use luxon::Error;
use luxon_formats::Origin;
use std::path::Path;
use std::sync::Arc;

/// One frame: Tachyon's VIEWDIR, UPDIR and CENTER, and where its first number is.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub viewdir: [f64; 3],
    pub updir: [f64; 3],
    pub center: [f64; 3],
    pub at: Origin,
}

/// The largest camera file read (VMD's are kilobytes; the cap keeps a wrong path such as a
/// device from being read without end).
const MAX_BYTES: u64 = 256 << 20;

/// Reads the camera file at `path`.
pub fn read(path: &Path) -> Result<Vec<Frame>, Error> {
    let text = luxon_plugin::files::read_text(path, MAX_BYTES).map_err(|e| {
        Error::Usage(format!(
            "-camfile {}: cannot read the camera file: it {e}",
            path.display()
        ))
    })?;
    parse(&text, path)
}

/// The frames of camera-file `text` (named `path` in errors, which give `file:line:col`).
pub fn parse(text: &str, path: &Path) -> Result<Vec<Frame>, Error> {
    let file = Arc::new(path.to_path_buf());
    let origin = |line: usize, col: usize| Origin {
        file: file.clone(),
        line: line as u32,
        col: col as u32,
    };
    let mut numbers: Vec<(f64, Origin)> = Vec::new();
    for (l, line) in text.lines().enumerate() {
        let mut col = 1;
        for word in line.split_inclusive(char::is_whitespace) {
            let token = word.trim_end_matches(char::is_whitespace);
            if !token.is_empty() {
                let at = origin(l + 1, col);
                match token.parse::<f64>() {
                    Ok(x) if x.is_finite() => numbers.push((x, at)),
                    _ => {
                        return Err(Error::at(
                            &at,
                            format!(
                                "expected a number of a camera frame (VIEWDIR, UPDIR, CENTER: 9 \
                                 numbers per frame), found `{}`",
                                luxon_formats::shown(token)
                            ),
                        ))
                    }
                }
            }
            col += word.chars().count();
        }
    }
    if numbers.is_empty() {
        return Err(Error::at(
            &origin(1, 1),
            "the camera file has no frames; expected 9 numbers per frame (VIEWDIR, UPDIR, CENTER)",
        ));
    }
    let whole = numbers.len() / 9;
    if !numbers.len().is_multiple_of(9) {
        let (_, at) = &numbers[whole * 9];
        return Err(Error::at(
            at,
            format!(
                "frame {} is incomplete: the file ends after {} of its 9 numbers (VIEWDIR, \
                 UPDIR, CENTER)",
                whole + 1,
                numbers.len() % 9
            ),
        ));
    }
    let mut frames: Vec<Frame> = numbers
        .chunks_exact(9)
        .map(|c| {
            let v = |k: usize| [c[k].0, c[k + 1].0, c[k + 2].0];
            Frame {
                viewdir: v(0),
                updir: v(3),
                center: v(6),
                at: c[0].1.clone(),
            }
        })
        .collect();
    // Tachyon's quirk: anything after the last number renders the last frame again.
    if text.ends_with(char::is_whitespace) {
        if let Some(last) = frames.last().cloned() {
            frames.push(last);
        }
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(text: &str) -> Result<Vec<Frame>, String> {
        parse(text, Path::new("a.cam")).map_err(|e| e.to_string())
    }

    #[test]
    fn nine_numbers_per_frame_whatever_the_line_breaks() {
        let f = frames("0 0 1  0 1 0  1 2 3").unwrap();
        assert_eq!(f.len(), 1);
        assert_eq!(
            (f[0].viewdir, f[0].updir, f[0].center),
            ([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 2.0, 3.0])
        );
        let f = frames("0 0 1\n0 1 0\n1 2 3 0 0 -1 0 1\n0 -1e1 2.5 .5").unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[1].viewdir, [0.0, 0.0, -1.0]);
        assert_eq!(f[1].center, [-10.0, 2.5, 0.5]);
        assert_eq!((f[1].at.line, f[1].at.col), (3, 7));
    }

    #[test]
    fn a_trailing_newline_renders_the_last_frame_twice_as_tachyon_does() {
        // Measured with tachyon-nox: 2 lines of 18 numbers ending with a newline: 5 frames.
        let two = "0 0 1 0 1 0 0 0 0  0 0 1 0 1 0 0 0 1\n";
        assert_eq!(frames(&format!("{two}{two}")).unwrap().len(), 5);
        assert_eq!(frames("0 0 1 0 1 0 0 0 0").unwrap().len(), 1);
        let f = frames("0 0 1 0 1 0 0 0 0\n0 0 1 0 1 0 0 0 7\n").unwrap();
        assert_eq!(f.len(), 3);
        assert_eq!(f[2], f[1]);
        assert_eq!(frames("0 0 1 0 1 0 0 0 0 \t").unwrap().len(), 2);
    }

    #[test]
    fn errors_name_the_line_and_column() {
        assert_eq!(
            frames("0 0 1 0 1 0 0 0 0\n0 0 1 0 x 0").unwrap_err(),
            "a.cam:2:9: expected a number of a camera frame (VIEWDIR, UPDIR, CENTER: 9 numbers \
             per frame), found `x`"
        );
        assert_eq!(
            frames("0 0 1 0 1 0 0 0 0\n  1 2 3\n").unwrap_err(),
            "a.cam:2:3: frame 2 is incomplete: the file ends after 3 of its 9 numbers (VIEWDIR, \
             UPDIR, CENTER)"
        );
        assert!(frames(" \n\n")
            .unwrap_err()
            .starts_with("a.cam:1:1: the camera file has no frames"));
        assert!(frames("0 0 1 0 1 0 0 0 nan")
            .unwrap_err()
            .contains("found `nan`"));
        assert!(frames("0 0 1 0 1 0 0 0 1e999")
            .unwrap_err()
            .contains("a.cam:1:17"));
    }

    #[test]
    fn a_missing_file_is_an_error_naming_it() {
        let e = read(Path::new("/nonexistent/a.cam"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("-camfile /nonexistent/a.cam: cannot read the camera file"),
            "{e}"
        );
    }
}

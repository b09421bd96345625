//! The output names of each frame of a sequence. A name with a frame number in it
//! (`frame%04d.png`, `frame%d.png`, `frame####.png`, see [`FramePattern`]) gets the frame's
//! number there; a name without one gets the number appended before its extension
//! (`anim.png` → `anim007.png`), zero-padded to the digits of the scene's last frame (or of the
//! last frame asked for, if later), so every run over any part of the scene's range names a
//! frame alike. A single frame rendered from a name without a number keeps the name as given.

use crate::error::Error;
use luxon_formats::{FramePattern, OutputDesc};
use std::ffi::OsString;
use std::path::PathBuf;

/// How one output is named per frame.
#[derive(Clone, Debug)]
enum Naming {
    Pattern(FramePattern),
    /// The number appended to the file stem, zero-padded to `digits`.
    Append {
        digits: usize,
    },
    /// The name as given (one frame only).
    Literal,
}

/// The outputs of a sequence, named for any frame.
#[derive(Clone, Debug)]
pub struct FrameNames {
    outputs: Vec<(OutputDesc, Naming)>,
}

impl FrameNames {
    /// Names for `outputs`; `last` is the highest frame number a name must hold (for the
    /// padding of appended numbers); `single`: only one frame is rendered.
    pub fn new(outputs: &[OutputDesc], last: u32, single: bool) -> Result<FrameNames, Error> {
        let digits = last.to_string().len();
        let outputs = outputs
            .iter()
            .map(|o| {
                let pattern = match o.path.to_str() {
                    Some(text) => {
                        FramePattern::parse(text).map_err(|m| Error::at(&o.params_at, m))?
                    }
                    None => None,
                };
                let naming = match pattern {
                    Some(p) => Naming::Pattern(p),
                    None if single => Naming::Literal,
                    None => Naming::Append { digits },
                };
                Ok((o.clone(), naming))
            })
            .collect::<Result<_, Error>>()?;
        Ok(FrameNames { outputs })
    }

    /// The first output's name as given (pattern or plain), which the frame records sit beside.
    pub fn first(&self) -> Option<&std::path::Path> {
        self.outputs.first().map(|(o, _)| o.path.as_path())
    }

    /// The outputs of frame `k`.
    pub fn outputs_for(&self, k: u32) -> Vec<OutputDesc> {
        self.outputs
            .iter()
            .map(|(o, naming)| {
                let path = match naming {
                    Naming::Pattern(p) => PathBuf::from(p.name(k)),
                    Naming::Append { digits } => appended(&o.path, k, *digits),
                    Naming::Literal => o.path.clone(),
                };
                OutputDesc { path, ..o.clone() }
            })
            .collect()
    }
}

/// `dir/name.ext` → `dir/name{k:0digits}.ext` (also without an extension).
fn appended(path: &std::path::Path, k: u32, digits: usize) -> PathBuf {
    let mut name: OsString = path.file_stem().unwrap_or_default().to_owned();
    name.push(format!("{k:0digits$}"));
    if let Some(ext) = path.extension() {
        name.push(".");
        name.push(ext);
    }
    path.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_formats::Origin;
    use std::sync::Arc;

    fn outputs(paths: &[&str]) -> Vec<OutputDesc> {
        paths
            .iter()
            .map(|p| OutputDesc {
                path: PathBuf::from(p),
                plugin: None,
                params: "()".into(),
                params_at: Origin {
                    file: Arc::new(PathBuf::from("s.ron")),
                    line: 3,
                    col: 9,
                },
            })
            .collect()
    }

    fn names(n: &FrameNames, k: u32) -> Vec<String> {
        n.outputs_for(k)
            .iter()
            .map(|o| o.path.display().to_string())
            .collect()
    }

    #[test]
    fn patterns_and_appended_numbers() {
        let n = FrameNames::new(
            &outputs(&["out/f%04d.png", "out/anim.exr", "out/g##", "plain"]),
            239,
            false,
        )
        .unwrap();
        assert_eq!(
            names(&n, 7),
            ["out/f0007.png", "out/anim007.exr", "out/g07", "plain007"]
        );
        assert_eq!(
            names(&n, 239),
            ["out/f0239.png", "out/anim239.exr", "out/g239", "plain239"]
        );
    }

    #[test]
    fn one_frame_keeps_a_plain_name() {
        let n = FrameNames::new(&outputs(&["still.png", "f%d.png"]), 9, true).unwrap();
        assert_eq!(names(&n, 9), ["still.png", "f9.png"]);
    }

    #[test]
    fn a_bad_pattern_is_an_error_at_the_output() {
        let e = FrameNames::new(&outputs(&["f%3d.png"]), 9, false).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("s.ron:3:9: `%3d` in `f%3d.png` is not a frame number"),
            "{e}"
        );
    }
}

//! The files of a `series:` (see `series`), read one data frame at a time: `.xyz` trajectories
//! (line 1 the atom count, line 2 a comment, then one `element x y z [radius]` line per atom)
//! and one `.obj` mesh per data frame (through the OBJ reader; its materials are not used, the
//! series' `material` is). Every error names the series and the movie frame, at the line and
//! column of the data file (or, for a missing file, at the series' `files` pattern).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use luxon_plugin::files::{read_text, FileError};

use crate::desc::{Origin, SeriesDesc, SeriesKind};
use crate::error::{quoted_list, shown, SceneError};
use crate::geometry::InlineGeometry;
use crate::input::LoadOptions;
use crate::obj::load_obj_with;

/// One data frame of a series, as read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesFrame {
    /// `.xyz`: each atom's style (an index in the series' `atoms`; `atoms.len()` for
    /// `default_atom`) and its sphere (x, y, z, radius), in file order.
    pub spheres: Vec<(u32, [f64; 4])>,
    /// `.obj`: the file's meshes (their materials not set: the series' applies).
    pub meshes: Vec<InlineGeometry>,
    /// The file read.
    pub file: PathBuf,
}

impl SeriesFrame {
    /// Bytes held (capacities), roughly what a cache of frames keeps.
    pub fn bytes(&self) -> u64 {
        let spheres = self.spheres.capacity() * std::mem::size_of::<(u32, [f64; 4])>();
        spheres as u64 + self.meshes.iter().map(InlineGeometry::bytes).sum::<u64>()
    }
}

/// Reads data frame `data_frame` of `s`, shown at movie frame `frame` (for messages).
pub fn load_frame(
    s: &SeriesDesc,
    data_frame: u32,
    frame: u32,
    options: &LoadOptions,
) -> Result<SeriesFrame, SceneError> {
    let file = s.path(data_frame);
    let prefix = format!("series `{}`, frame {frame}", shown(&s.name.value));
    match std::fs::metadata(&file) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(missing(s, &file, data_frame, &prefix));
        }
        _ => {}
    }
    match &s.kind {
        SeriesKind::Atoms { atoms, default } => {
            let text = read_text(&file, options.max_scene_bytes).map_err(|e| match e {
                FileError::Missing => missing(s, &file, data_frame, &prefix),
                e => prefixed(crate::input::file_error(e, &file, "an .xyz file"), &prefix),
            })?;
            let names: Vec<&str> = atoms.iter().map(|(n, _)| n.as_str()).collect();
            let spheres = read_xyz(&text, &file, &prefix, &names, |i| {
                atoms
                    .get(i)
                    .map(|(_, a)| a.radius)
                    .or(default.as_ref().map(|d| d.radius))
            })?;
            Ok(SeriesFrame {
                spheres,
                meshes: Vec::new(),
                file,
            })
        }
        SeriesKind::Mesh { .. } => {
            let import = load_obj_with(&file, None, options).map_err(|e| prefixed(e, &prefix))?;
            let mut meshes = import.geometry;
            for m in &mut meshes {
                m.material = None;
            }
            Ok(SeriesFrame {
                spheres: Vec::new(),
                meshes,
                file,
            })
        }
    }
}

/// The data files of movie frames `range` (inclusive) of `s` that do not exist: (movie frame,
/// file), the first movie frame showing each. `animation`: the scene's first and last frame.
pub fn missing_files(s: &SeriesDesc, animation: (u32, u32)) -> (usize, Vec<(u32, PathBuf)>) {
    let mut seen = std::collections::HashSet::new();
    let mut missing = Vec::new();
    for k in animation.0..=animation.1 {
        let d = s.data_frame(k, animation);
        if seen.insert(d) {
            let file = s.path(d);
            if !file.is_file() {
                missing.push((k, file));
            }
        }
    }
    (seen.len(), missing)
}

fn missing(s: &SeriesDesc, file: &Path, data_frame: u32, prefix: &str) -> SceneError {
    SceneError::At {
        at: s.files.at.clone(),
        message: format!(
            "{prefix}: data file `{}` does not exist; expected one file per data frame \
             (pattern `{}`, data frame {data_frame})",
            file.display(),
            shown(&s.files.value)
        ),
    }
}

/// `e` with `prefix: ` before its message.
fn prefixed(e: SceneError, prefix: &str) -> SceneError {
    match e {
        SceneError::At { at, message } => SceneError::At {
            at,
            message: format!("{prefix}: {message}"),
        },
        SceneError::File { path, message } => SceneError::File {
            path,
            message: format!("{prefix}: {message}"),
        },
        SceneError::Io { path, source } => SceneError::File {
            message: format!("{prefix}: cannot read `{}`: {source}", path.display()),
            path,
        },
    }
}

/// The words of `line` with their 1-based columns (in characters).
fn words(line: &str) -> Vec<(u32, &str)> {
    let mut out = Vec::new();
    let mut start: Option<(u32, usize)> = None;
    let mut col = 0u32;
    for (byte, c) in line.char_indices() {
        col += 1;
        match (c.is_whitespace(), start) {
            (false, None) => start = Some((col, byte)),
            (true, Some((at, from))) => {
                out.push((at, &line[from..byte]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some((at, from)) = start {
        out.push((at, &line[from..]));
    }
    out
}

/// The atoms of an `.xyz` file: (style, sphere) each, `style` the element's index in `names`
/// (`names.len()` when it is not there); `radius(style)` the style's radius, `None` for an
/// element no style draws.
fn read_xyz(
    text: &str,
    file: &Path,
    prefix: &str,
    names: &[&str],
    radius: impl Fn(usize) -> Option<f64>,
) -> Result<Vec<(u32, [f64; 4])>, SceneError> {
    let path = Arc::new(file.to_path_buf());
    let fail = |line: usize, col: u32, message: String| SceneError::At {
        at: Origin {
            file: path.clone(),
            line: u32::try_from(line).unwrap_or(u32::MAX),
            col,
        },
        message: format!("{prefix}: {message}"),
    };
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (count_line, first) = lines.next().unwrap_or((1, ""));
    let first = words(first);
    let count = match first.as_slice() {
        [(_, n)] => n.parse::<u64>().ok(),
        _ => None,
    };
    let Some(count) = count else {
        let col = first.first().map_or(1, |(c, _)| *c);
        let written = first.first().map_or("", |(_, w)| w);
        return Err(fail(
            count_line,
            col,
            format!(
                "line 1 is `{}`; expected the number of atoms alone (an .xyz file: the atom \
                 count, a comment line, then `element x y z [radius]` per atom)",
                shown(written)
            ),
        ));
    };
    // The comment line.
    let mut last_line = lines.next().map_or(1, |(i, _)| i);
    let mut atoms = Vec::with_capacity(usize::try_from(count.min(1 << 20)).unwrap_or(0));
    let expected = "expected `element x y z [radius]`";
    while (atoms.len() as u64) < count {
        let Some((n, line)) = lines.next() else {
            return Err(fail(
                last_line + 1,
                1,
                format!(
                    "the file ends after {} of {count} atoms; expected {count} atom lines \
                     (line 1 says {count})",
                    atoms.len()
                ),
            ));
        };
        last_line = n;
        let w = words(line);
        if w.len() < 4 || w.len() > 5 {
            let col = w.get(5).map_or(1, |(c, _)| *c);
            return Err(fail(
                n,
                col,
                format!("atom line has {} columns; {expected}", w.len()),
            ));
        }
        let mut v = [0.0; 4];
        for (slot, (col, word)) in v.iter_mut().zip(&w[1..]) {
            match word.parse::<f64>() {
                Ok(x) if x.is_finite() => *slot = x,
                _ => {
                    return Err(fail(
                        n,
                        *col,
                        format!("`{}` is not a number; {expected}", shown(word)),
                    ))
                }
            }
        }
        let (col, element) = w[0];
        let style = names
            .iter()
            .position(|e| *e == element)
            .unwrap_or(names.len());
        let Some(r) = radius(style) else {
            let known = if names.is_empty() {
                String::new()
            } else {
                format!("; expected one of {}", quoted_list(names.iter().copied()))
            };
            return Err(fail(
                n,
                col,
                format!(
                    "element `{}` has no entry in `atoms` and there is no `default_atom`{known}",
                    shown(element)
                ),
            ));
        };
        if w.len() == 5 {
            if v[3] <= 0.0 {
                return Err(fail(
                    n,
                    w[4].0,
                    format!("the radius `{}` is not positive; {expected}", shown(w[4].1)),
                ));
            }
        } else {
            v[3] = r;
        }
        atoms.push((style as u32, v));
    }
    for (n, line) in lines {
        if let Some((col, _)) = words(line).first() {
            return Err(fail(
                n,
                *col,
                format!(
                    "more atom lines than line 1's {count}; expected one data frame per file \
                     with its atom count on line 1"
                ),
            ));
        }
    }
    Ok(atoms)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xyz(text: &str) -> Result<Vec<(u32, [f64; 4])>, String> {
        let names = ["O", "H"];
        let r = |i: usize| [0.6, 0.3].get(i).copied();
        read_xyz(text, Path::new("t.xyz"), "p", &names, r).map_err(|e| e.to_string())
    }

    #[test]
    fn atoms_take_their_element_radius_or_the_fifth_column() {
        let a = xyz("3\nwater\nO 0 0 0\nH 1 0 0 0.5\n  H\t-1 0.5 2e0\n").unwrap();
        assert_eq!(
            a,
            vec![
                (0, [0.0, 0.0, 0.0, 0.6]),
                (1, [1.0, 0.0, 0.0, 0.5]),
                (1, [-1.0, 0.5, 2.0, 0.3])
            ]
        );
    }

    #[test]
    fn errors_point_at_the_word() {
        let e = xyz("2\nc\nO 0 0 0\n").unwrap_err();
        assert!(
            e.starts_with("t.xyz:4:1: p: the file ends after 1 of 2 atoms"),
            "{e}"
        );
        let e = xyz("1\nc\nO 0 1.2.3 0\n").unwrap_err();
        assert!(
            e.starts_with("t.xyz:3:5: p: `1.2.3` is not a number"),
            "{e}"
        );
        let e = xyz("1\nc\n Na 0 0 0\n").unwrap_err();
        assert!(
            e.starts_with("t.xyz:3:2: p: element `Na` has no entry"),
            "{e}"
        );
        assert!(e.contains("expected one of `O`, `H`"), "{e}");
        let e = xyz("two\nc\n").unwrap_err();
        assert!(e.starts_with("t.xyz:1:1: p: line 1 is `two`"), "{e}");
        let e = xyz("1\nc\nO 0 0 0\nH 0 0 0\n").unwrap_err();
        assert!(e.starts_with("t.xyz:4:1: p: more atom lines"), "{e}");
        let e = xyz("1\nc\nO 0 0 0 -1\n").unwrap_err();
        assert!(
            e.starts_with("t.xyz:3:9: p: the radius `-1` is not positive"),
            "{e}"
        );
    }
}

//! `series:`: time-sampled data, one file per data frame named by a pattern. One file's entries
//! are checked at their positions (`Checker::series`); once every file is merged,
//! `resolve_series` checks what they name (materials), that names are used once, that the
//! scene is animated, and that the range's last data frame has a number. The files themselves
//! are read frame by frame (`data_frames`).

use std::path::Path;

use crate::desc::*;
use crate::error::{shown, unknown_name, SceneError};
use crate::pattern::FramePattern;
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

type Result<T> = std::result::Result<T, SceneError>;

impl Checker<'_> {
    /// The series entry at `node`, its pattern relative to this file's directory.
    pub(crate) fn series(&self, s: raw::Series, node: &Node) -> Result<Spanned<SeriesDesc>> {
        let field = |name: &str| node.field(name).unwrap_or(node);
        let files_at = field("files");
        let pattern = match FramePattern::parse(&s.files) {
            Ok(Some(p)) => p,
            Ok(None) => {
                return Err(self.error(
                    files_at,
                    format!(
                        "the file pattern `{}` has no frame number; expected %d, %04d or #### \
                         where the data frame number goes",
                        shown(&s.files)
                    ),
                ))
            }
            Err(why) => return Err(self.error(files_at, why)),
        };
        let extension = Path::new(&pattern.name(0))
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let first = match s.first {
            Some(f) => self.whole(field("first"), "first", f, 0, u32::MAX)?,
            None => 0,
        };
        let per_frame = match s.per_frame {
            Some(f) => self.whole(field("per_frame"), "per_frame", f, 1, u32::MAX)?,
            None => 1,
        };
        let style = |a: raw::AtomStyle, at: &Node| -> Result<AtomStyle> {
            let radius = self.positive(at.field("radius").unwrap_or(at), "radius", a.radius)?;
            let material = a
                .material
                .map(|m| self.spanned(m, at.field("material").unwrap_or(at)));
            Ok(AtomStyle { radius, material })
        };
        let kind = match extension.as_deref() {
            Some("xyz") => {
                if s.material.is_some() {
                    return Err(self.error(
                        field("material"),
                        "`material` is for `.obj` series; an `.xyz` series gives each \
                         element's material in `atoms` (and `default_atom`)",
                    ));
                }
                let mut atoms = Vec::new();
                if let Some(named) = s.atoms {
                    let map = field("atoms");
                    self.names_once(map, "element", &named.0)?;
                    for (i, (name, a)) in named.0.into_iter().enumerate() {
                        let (_, at) = map.entry(i).unwrap_or((map, map));
                        atoms.push((name, style(a, at)?));
                    }
                }
                let default = match s.default_atom {
                    Some(a) => Some(style(a, field("default_atom"))?),
                    None => None,
                };
                if atoms.is_empty() && default.is_none() {
                    return Err(self.error(
                        node,
                        "an `.xyz` series needs `atoms` (element to radius and material) or \
                         `default_atom`; expected e.g. `atoms: { \"O\": (radius: 0.6, \
                         material: \"red\") }`",
                    ));
                }
                SeriesKind::Atoms { atoms, default }
            }
            Some("obj") => {
                for (name, given) in [
                    ("atoms", s.atoms.is_some()),
                    ("default_atom", s.default_atom.is_some()),
                ] {
                    if given {
                        return Err(self.error(
                            field(name),
                            format!(
                                "`{name}` is for `.xyz` series; an `.obj` series takes one \
                                 `material`"
                            ),
                        ));
                    }
                }
                SeriesKind::Mesh {
                    material: s.material.map(|m| self.spanned(m, field("material"))),
                }
            }
            _ => {
                return Err(self.error(
                    files_at,
                    format!(
                        "unsupported data file pattern `{}`; expected `.xyz` files (atoms) or \
                         `.obj` files (one mesh per data frame)",
                        shown(&s.files)
                    ),
                ))
            }
        };
        let dir = self
            .src
            .file
            .parent()
            .unwrap_or(Path::new(""))
            .to_path_buf();
        Ok(self.spanned(
            SeriesDesc {
                name: self.spanned(s.name, field("name")),
                files: self.spanned(s.files, files_at),
                pattern,
                dir,
                first,
                per_frame,
                kind,
            },
            node,
        ))
    }
}

/// After merging: series only in an animated scene, each name once, every material named
/// exists, and the last data frame of the animation's range has a number.
pub(crate) fn resolve_series(scene: &SceneDesc) -> Result<()> {
    let Some(first) = scene.series.first() else {
        return Ok(());
    };
    let Some(animation) = &scene.animation else {
        return Err(SceneError::at(
            first.at.clone(),
            "`series:` needs an `animation:` block (its frames choose the data frames); \
             expected e.g. `animation: (frames: (0, 47))`",
        ));
    };
    let materials: Vec<&str> = scene.materials.iter().map(|(n, _)| n.as_str()).collect();
    let material = |m: &Option<Spanned<String>>| match m {
        Some(m) if !materials.contains(&m.value.as_str()) => {
            let message = unknown_name("material", &m.value, "", materials.iter().copied());
            Err(SceneError::at(m.at.clone(), message))
        }
        _ => Ok(()),
    };
    let span = u64::from(animation.value.last - animation.value.first);
    for (k, s) in scene.series.iter().enumerate() {
        let s = &s.value;
        if let Some(before) = scene.series[..k]
            .iter()
            .find(|b| b.value.name.value == s.name.value)
        {
            return Err(SceneError::at(
                s.name.at.clone(),
                format!(
                    "the series name `{}` is already used at {}; expected each series name once",
                    shown(&s.name.value),
                    before.value.name.at
                ),
            ));
        }
        match &s.kind {
            SeriesKind::Atoms { atoms, default } => {
                for a in atoms.iter().map(|(_, a)| a).chain(default) {
                    material(&a.material)?;
                }
            }
            SeriesKind::Mesh { material: m } => material(m)?,
        }
        let last = u64::from(s.first) + span * u64::from(s.per_frame);
        if last > u64::from(u32::MAX) {
            return Err(SceneError::at(
                s.files.at.clone(),
                format!(
                    "series `{}`: the animation's last frame would show data frame {last}; \
                     expected data frame numbers up to {} (a smaller `first` or `per_frame`)",
                    shown(&s.name.value),
                    u32::MAX
                ),
            ));
        }
    }
    Ok(())
}

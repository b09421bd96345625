//! `luxon convert SCENE OUT.ron` (or `-o OUT.ron`): any scene Luxon reads (RON, NFF, OBJ,
//! Tachyon) written as an equivalent Luxon RON scene, to edit and render from then on: it renders
//! the picture Luxon renders from the source. Imported geometry becomes `luxon-shapes` objects
//! with inline arrays; materials keep their names (a Tachyon TEXDEF's name, NFF's `nff-N`);
//! includes and mesh files are merged into the one file. What the source says that the RON
//! scene cannot hold (the load's warnings) is printed and listed at the top of the file. See
//! `luxon_formats::to_ron`.

use luxon::Error;
use luxon_formats::to_ron;
use std::path::Path;

/// The RON text of the scene at `scene`, to be read from `output`.
pub fn convert(scene: &Path, output: &Path) -> Result<String, Error> {
    let options = luxon::budget::Budget::for_load(None, 1).load_options();
    let desc = luxon_formats::load_with(scene, &options)?;
    let base = output.parent().filter(|p| !p.as_os_str().is_empty());
    let text = to_ron(&desc, base.unwrap_or(Path::new("."))).map_err(Error::Render)?;
    // What is written must read back.
    luxon_formats::load_ron_str(&text, output).map_err(|e| {
        Error::Render(format!(
            "the converted scene does not read back as RON, so nothing was written ({e})"
        ))
    })?;
    super::warn_scene(&desc);
    if !desc.warnings.is_empty() {
        luxon::error::print_warning(&format!(
            "{}: what the {} above name{} is not carried over (listed at the top of the file)",
            output.display(),
            match desc.warnings.len() {
                1 => "warning".to_string(),
                n => format!("{n} warnings"),
            },
            if desc.warnings.len() == 1 { "s" } else { "" }
        ));
    }
    Ok(text)
}

pub fn run(scene: &Path, output: &Path) -> Result<(), Error> {
    let is_ron = |p: &Path| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ron"));
    if !is_ron(output) {
        return Err(Error::Usage(format!(
            "{}: expected a `.ron` file name (luxon convert writes RON scenes)",
            output.display()
        )));
    }
    if std::path::absolute(scene).ok() == std::path::absolute(output).ok() {
        return Err(Error::Usage(format!(
            "{}: the output would replace the scene it is converted from; name another file",
            output.display()
        )));
    }
    let text = convert(scene, output)?;
    let dir = |p: &Path| std::path::absolute(p.parent().unwrap_or(Path::new(""))).ok();
    if is_ron(scene) && dir(scene) != dir(output) {
        luxon::error::print_warning(
            "plugin parameters are copied as written: relative file names in them (image \
             textures, volume files) are read beside the scene file, so keep the new scene in \
             the old one's directory or make them absolute",
        );
    }
    luxon::files::write_atomic(output, text.as_bytes())?;
    eprintln!("luxon: wrote {}", output.display());
    Ok(())
}

//! `luxon spd`: generate Eric Haines' Standard Procedural Database scenes.

use luxon::Error;
use luxon_formats::spd::{self, OutputFormat};
use std::io::Write;
use std::path::Path;

/// Writes scene `name` at `size` (default: the SPD's) to `output`, in the format its extension
/// names (`.nff`, `.nff.gz`, `.ron`), atomically; `-` writes NFF to standard output. Without a
/// name, lists the scenes.
pub fn run(name: Option<&str>, size: Option<u32>, output: Option<&Path>) -> Result<(), Error> {
    let Some(name) = name else {
        list();
        return Ok(());
    };
    let usage = |e: spd::SpdError| Error::Usage(e.to_string());
    let (scene, size) = spd::find(name, size).map_err(usage)?;
    let Some(output) = output else {
        return Err(Error::Usage(format!(
            "`luxon spd {name}` needs -o FILE (.nff, .nff.gz or .ron; `-` for NFF on stdout)"
        )));
    };
    if output == Path::new("-") {
        let stdout = std::io::stdout();
        let mut lock = stdout.lock();
        spd::generate(scene.name, size, &mut lock).map_err(usage)?;
        return lock.flush().map_err(|source| Error::Io {
            path: output.to_path_buf(),
            source,
        });
    }
    let format = OutputFormat::of_path(output).ok_or_else(|| {
        Error::Usage(format!(
            "{}: unsupported output format; expected a name ending in .nff, .nff.gz or .ron",
            output.display()
        ))
    })?;
    // Removed on any error when `tmp` drops.
    let mut tmp = luxon::files::TempFile::create(output)?;
    let result = (|| -> Result<spd::Counts, spd::SpdError> {
        let file = tmp.file();
        let counts = spd::generate_as(scene.name, size, format, file)?;
        file.sync_all()?;
        Ok(counts)
    })();
    let c = match result {
        Ok(c) => {
            tmp.rename()?;
            c
        }
        Err(e) => {
            return Err(match e {
                spd::SpdError::Io(source) => Error::Io {
                    path: output.to_path_buf(),
                    source,
                },
                e => usage(e),
            });
        }
    };
    let mut parts = Vec::new();
    for (n, what) in [
        (c.spheres, "sphere"),
        (c.cones, "cone"),
        (c.polygons, "polygon"),
        (c.patches, "patch"),
    ] {
        match n {
            0 => {}
            1 => parts.push(format!("1 {what}")),
            n if what == "patch" => parts.push(format!("{n} patches")),
            n => parts.push(format!("{n} {what}s")),
        }
    }
    eprintln!(
        "luxon: wrote {} ({} -s {size}: {})",
        output.display(),
        scene.name,
        parts.join(", ")
    );
    Ok(())
}

fn list() {
    println!("SPD scenes (luxon spd NAME [--size N] -o FILE.nff|.nff.gz|.ron):");
    for s in spd::SCENES {
        println!(
            "  {:<8} default size {:<3} sizes {}..={:<5} {}",
            s.name, s.default_size, s.min_size, s.max_size, s.about
        );
    }
}

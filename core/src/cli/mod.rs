//! The subcommands of `luxon`, one module each.

pub mod check;
pub mod job;
pub mod plugins;
pub mod progress;
pub mod render;
pub mod shading;
pub mod spd;
pub mod sweep;

/// Prints the problems an importer worked around (`SceneDesc::warnings`) to standard error.
pub fn print_warnings(desc: &luxon_formats::SceneDesc) {
    for w in &desc.warnings {
        eprintln!("luxon: warning: {}: {}", w.at, w.value);
    }
}

/// `--res WIDTHxHEIGHT`.
pub fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{s}`"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in `{s}`"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in `{s}`"))?;
    if w == 0 || h == 0 || w > 65536 || h > 65536 || (w as u64 * h as u64) > (1 << 28) {
        return Err(format!(
            "resolution {w}x{h} out of range (1..=65536 each, at most 2^28 pixels)"
        ));
    }
    Ok((w, h))
}

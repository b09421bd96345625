//! The subcommands of `luxon`, one module each.

pub mod check;
pub mod convert;
pub mod frame_clock;
#[cfg(feature = "mpi")]
pub mod frame_groups;
pub mod job;
pub mod new_plugin;
pub mod plugins;
pub mod progress;
pub mod render;
pub mod resume;
pub mod sequence;
pub mod shading;
// The signal handlers and their pipe (libc).
#[allow(unsafe_code)]
pub mod signals;
pub mod spd;
pub mod sweep;
pub mod tachyon;
pub mod usage;

use luxon::error::Level;
use luxon::plugin::Registry;

/// Sends the library's log lines (plugin messages) to stderr as `luxon: {level}: {message}`;
/// debug lines only when `LUXON_DEBUG` is set. The library itself prints nothing.
pub fn log_to_stderr() {
    let debug = std::env::var_os("LUXON_DEBUG").is_some();
    luxon::error::set_log(Some(Box::new(move |level, message| {
        if level != Level::Debug || debug {
            luxon::error::print_line(level.name(), message);
        }
    })));
}

/// Warns about every file on the plugin search path that was skipped (a truncated library, a
/// FIFO named like a plugin...): the run goes on without it, but the user should know.
pub fn warn_skipped(registry: &Registry) {
    for p in &registry.problems {
        luxon::error::print_warning(&format!("skipped plugin file {p}"));
    }
}

/// Prints the scene's warnings (what the loaders accepted but want the user to know: an OBJ
/// `l` statement not drawn, an NFF negative radius...), one line each.
pub fn warn_scene(desc: &luxon_formats::SceneDesc) {
    for w in &desc.warnings {
        luxon::error::print_warning(&w.to_string());
    }
}

/// `--memory SIZE`: "6G", "512M", "1.5 GiB", "50%" (of the machine's memory).
pub fn parse_memory(s: &str) -> Result<luxon_formats::MemorySize, String> {
    luxon_formats::parse_memory_size(s)
        .map_err(|why| format!("expected {} ({why})", luxon_formats::MEMORY_SIZE_EXAMPLES))
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

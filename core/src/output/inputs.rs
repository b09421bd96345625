//! What a frame of a sequence is rendered from, as one hash (the *inputs hash* of its
//! completion record, see [`manifest`](super::manifest)): a frame whose inputs hash changed is
//! stale and rendered again.
//!
//! The scene hash covers luxon's version and plugin ABI; the text of every scene file the
//! loader read; the size and modification time of every file a string in those files names
//! (textures, volumes, meshes: plugins read their own files, so every path-like string that
//! names an existing file is stamped rather than guessing which ones are read); the size and
//! modification time of each plugin library the scene used; and the render settings
//! after the command line's overrides, except those proven not to change a pixel (threads,
//! tile size, decomposition, parallel mode, output I/O). The hash is 64-bit FNV-1a, our own
//! code: std's hashers are not stable across releases. A frame's inputs hash adds the data
//! files that frame reads (`frame_hash`).

use luxon_formats::RenderDesc;
use std::path::{Component, Path, PathBuf};

/// 64-bit FNV-1a.
#[derive(Clone, Copy, Debug)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    pub fn new() -> Fnv {
        Fnv::default()
    }

    pub fn bytes(&mut self, bytes: &[u8]) -> &mut Fnv {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        self
    }

    /// A field: its length first, so that consecutive fields cannot run into each other.
    pub fn field(&mut self, bytes: &[u8]) -> &mut Fnv {
        self.bytes(&(bytes.len() as u64).to_le_bytes()).bytes(bytes)
    }

    pub fn u64(&mut self, v: u64) -> &mut Fnv {
        self.bytes(&v.to_le_bytes())
    }

    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// One scene file as the loader read it: its path, the hash of its text, and the strings in
/// it (for the files they may name).
#[derive(Clone, Debug)]
pub struct SceneFile {
    pub path: PathBuf,
    pub text: u64,
    pub strings: Vec<String>,
}

impl SceneFile {
    pub fn new(path: &Path, text: &str) -> SceneFile {
        SceneFile {
            path: path.to_path_buf(),
            text: Fnv::new().bytes(text.as_bytes()).finish(),
            strings: ron_strings(text),
        }
    }
}

/// What goes into a scene hash besides the files read.
pub struct SceneInputs<'a> {
    pub files: &'a [SceneFile],
    pub render: &'a RenderDesc,
    /// Plugin libraries used.
    pub libraries: Vec<&'a Path>,
    /// Other settings that change pixels, as text (the command line's shading switches).
    pub extra: String,
    /// Files never stamped: the outputs (they change with every frame written).
    pub skip: &'a dyn Fn(&Path) -> bool,
}

/// The scene hash.
pub fn scene_hash(i: &SceneInputs) -> u64 {
    let mut h = Fnv::new();
    h.field(env!("CARGO_PKG_VERSION").as_bytes())
        .u64(u64::from(luxon_plugin::abi::ABI_VERSION));
    for f in i.files {
        // Not the paths: a scene run from another directory (or node) is the same scene.
        h.u64(f.text);
        let dir = f.path.parent().unwrap_or(Path::new(""));
        for s in &f.strings {
            if let Some(p) = named_file(dir, s) {
                if !(i.skip)(&p) {
                    stamp(&mut h, &p);
                }
            }
        }
    }
    for lib in &i.libraries {
        stamp(&mut h, lib);
    }
    h.field(pixel_settings(i.render).as_bytes())
        .field(i.extra.as_bytes());
    h.finish()
}

/// The inputs hash of frame `k`: the scene hash and the size and modification time of each
/// data file the frame reads (`files`: a `series:`'s data frames, see
/// [`DataFiles`](crate::scene::DataFiles)), so editing one makes stale only the frames that
/// read it.
pub fn frame_hash(scene: u64, k: u32, files: &[PathBuf]) -> u64 {
    let mut h = Fnv::new();
    h.u64(scene).u64(u64::from(k));
    for f in files {
        stamp(&mut h, f);
    }
    h.finish()
}

/// The render settings that change pixels, as text: the settings' debug form (so a setting
/// added later is covered) with the ones that cannot change a pixel set to their defaults, and
/// the outputs by writer and parameters (their names are checked file by file).
fn pixel_settings(r: &RenderDesc) -> String {
    let mut r = r.clone();
    let outputs: Vec<String> = r
        .outputs
        .drain(..)
        .map(|o| {
            let plugin = o.plugin.map(|p| p.value).unwrap_or_default();
            format!("{plugin} {}", o.params)
        })
        .collect();
    r.parallel = Default::default();
    format!("{r:?} outputs {outputs:?}")
}

/// `s` as a path relative to `dir`, when it names an existing regular file.
fn named_file(dir: &Path, s: &str) -> Option<PathBuf> {
    if s.is_empty() || s.len() > 4096 || s.contains(['\n', '\0']) {
        return None;
    }
    let p = dir.join(s);
    std::fs::metadata(&p).ok()?.is_file().then_some(p)
}

/// Size and modification time of `p` (a file that vanished hashes as such); which file it is
/// follows from the text that names it.
fn stamp(h: &mut Fnv, p: &Path) {
    match std::fs::metadata(p) {
        Ok(m) => {
            let mtime = m
                .modified()
                .ok()
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_nanos() as u64);
            h.u64(m.len()).u64(mtime);
        }
        Err(_) => {
            h.u64(u64::MAX);
        }
    }
}

/// `p` made absolute (against the working directory) with `.` and `..` removed by name, so
/// two spellings of one path compare equal.
pub fn absolute(p: &Path) -> PathBuf {
    let joined = match std::env::current_dir() {
        Ok(cwd) if p.is_relative() => cwd.join(p),
        _ => p.to_path_buf(),
    };
    let mut out = PathBuf::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

/// The string literals of RON text (`"..."` with escapes, raw `r#"..."#`), outside comments.
fn ron_strings(text: &str) -> Vec<String> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i = text[i + 2..].find("*/").map_or(b.len(), |e| i + 2 + e + 2);
            }
            b'r' if matches!(b.get(i + 1), Some(b'"' | b'#'))
                && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')) =>
            {
                let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
                let open = i + 1 + hashes;
                if b.get(open) != Some(&b'"') {
                    i += 1;
                    continue;
                }
                let close = format!("\"{}", "#".repeat(hashes));
                match text[open + 1..].find(&close) {
                    Some(e) => {
                        out.push(text[open + 1..open + 1 + e].to_string());
                        i = open + 1 + e + close.len();
                    }
                    None => i = b.len(),
                }
            }
            b'"' => {
                let mut s = String::new();
                let mut j = i + 1;
                let mut chars = text[j..].char_indices();
                let mut end = b.len();
                while let Some((at, c)) = chars.next() {
                    match c {
                        '"' => {
                            end = j + at + 1;
                            break;
                        }
                        '\\' => match chars.next() {
                            Some((_, 'n')) => s.push('\n'),
                            Some((_, 't')) => s.push('\t'),
                            Some((_, c)) => s.push(c),
                            None => {}
                        },
                        c => s.push(c),
                    }
                }
                j = end;
                out.push(s);
                i = j;
            }
            b'\'' => {
                // A character literal: '"' must not open a string.
                i += match (b.get(i + 1), b.get(i + 2), b.get(i + 3)) {
                    (Some(b'\\'), _, Some(b'\'')) => 4,
                    (Some(_), Some(b'\''), _) => 3,
                    _ => 1,
                };
            }
            _ => i += 1,
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_matches_the_reference_values() {
        assert_eq!(Fnv::new().finish(), 0xcbf2_9ce4_8422_2325);
        assert_eq!(Fnv::new().bytes(b"a").finish(), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(Fnv::new().bytes(b"foobar").finish(), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn strings_of_ron_text() {
        let text = r###"Scene( // "not/this.png"
            a: "tex/wood.png", /* "nor/this" */ b: r#"raw "q".obj"#, c: 'x', d: '"',
            e: "esc\"aped\\", f: br)"###;
        assert_eq!(
            ron_strings(text),
            ["tex/wood.png", "raw \"q\".obj", "esc\"aped\\"]
        );
    }

    #[test]
    fn absolute_paths_lose_dots() {
        assert_eq!(absolute(Path::new("/a/./b/../c")), PathBuf::from("/a/c"));
    }
}

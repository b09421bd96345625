//! One-way layering: a module of `core` (or of `formats`) may import only modules of lower layers
//! (the tables in the crate documentation, core/src/lib.rs and formats/src/lib.rs). Modules of one layer must not import each other,
//! so the layers are a strict order and nothing runs in a circle.
//!
//! The check reads the source: every `crate::…` path (`use` lines, grouped and multi-line uses,
//! inline paths such as `crate::x::f()`), and `super::…` paths that climb to the crate root.
//! Other `super::` paths stay inside their module. Comments and string literals are skipped.
//! The crate roots (`lib.rs`, `main.rs`) declare the modules and may use any of them.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of core/src, bottom to top: each module may import only the modules of the
/// layers before its own. Keep in step with the table in core/src/lib.rs.
const CORE: &[(&str, &[&str])] = &[
    ("math", &["math", "sampler", "error"]),
    ("arrays", &["arrays"]),
    ("motion", &["motion"]),
    ("memory", &["budget"]),
    ("ray", &["ray"]),
    ("image", &["framebuffer", "ppm", "metrics", "files"]),
    ("camera", &["camera", "adaptive"]),
    ("bvh", &["bvh"]),
    ("geometry", &["geometry"]),
    ("volume", &["volume"]),
    ("volume_render", &["volume_render"]),
    ("plugin", &["plugin"]),
    ("scene", &["scene"]),
    ("cache", &["cache"]),
    ("integrator", &["integrator"]),
    ("schedule", &["schedule"]),
    ("render", &["render"]),
    ("output", &["output", "sweep"]),
    ("api", &["api"]),
    ("cli", &["cli"]),
];

/// The layers of formats/src, bottom to top. Keep in step with the table in formats/src/lib.rs.
const FORMATS: &[(&str, &[&str])] = &[
    ("origin", &["origin"]),
    ("leaves", &["error", "geometry", "spans", "raw", "pattern"]),
    ("description", &["desc"]),
    ("text", &["ron_text"]),
    ("input", &["input", "print"]),
    ("scanner", &["scanner"]),
    ("checks", &["validate", "ron_error"]),
    (
        "conversion",
        &[
            "convert",
            "camera",
            "effects",
            "volume_render",
            "animation",
            "instances",
            "series",
        ],
    ),
    ("importers", &["nff", "obj", "tachyon"]),
    ("includes", &["includes"]),
    ("formats", &["ron_scene", "spd", "data_frames"]),
    ("front door", &["load", "fragment"]),
];

fn assert_layered(crate_dir: &str, layers: &[(&str, &[&str])]) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(crate_dir);
    let problems = check(&src, layers);
    assert!(
        problems.is_empty(),
        "layering of {crate_dir} broken ({} problems):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// The layer table in a crate's documentation (rows `//! | layer | modules | ...`, in either
/// order), as (layer, modules) bottom to top; module names are the words in backquotes or
/// brackets, `main.rs` left out.
fn documented_layers(lib_rs: &str) -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(lib_rs))
        .unwrap_or_else(|e| panic!("{lib_rs}: {e}"));
    let mut rows: Vec<(String, Vec<String>)> = text
        .lines()
        .filter_map(|l| l.strip_prefix("//! |"))
        .filter_map(|row| {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            let (layer, modules) = (*cells.first()?, *cells.get(1)?);
            if layer == "layer" || layer.starts_with('-') {
                return None;
            }
            let names = modules
                .split(',')
                .filter_map(|m| {
                    let m = m.split_whitespace().next()?;
                    let m = m.trim_matches(|c| "`[]".contains(c));
                    (m != "main.rs" && !m.is_empty()).then(|| m.to_string())
                })
                .collect();
            Some((layer.to_string(), names))
        })
        .collect();
    // core lists its layers top first, formats bottom first.
    if rows.first().is_some_and(|(l, _)| l == "cli") {
        rows.reverse();
    }
    rows
}

fn assert_documented(lib_rs: &str, layers: &[(&str, &[&str])]) {
    let want: Vec<(String, Vec<String>)> = layers
        .iter()
        .map(|(l, ms)| (l.to_string(), ms.iter().map(|m| m.to_string()).collect()))
        .collect();
    assert_eq!(
        documented_layers(lib_rs),
        want,
        "the layer table of {lib_rs} and this test's table differ"
    );
}

#[test]
fn the_documented_layer_tables_are_the_checked_ones() {
    assert_documented("core/src/lib.rs", CORE);
    assert_documented("formats/src/lib.rs", FORMATS);
}

#[test]
fn core_imports_only_from_lower_layers() {
    assert_layered("core/src", CORE);
}

#[test]
fn formats_imports_only_from_lower_layers() {
    assert_layered("formats/src", FORMATS);
}

/// The library prints nothing (the C library, core/capi, included): it reports through errors
/// and its log sink (tests/log.rs runs it). Printing belongs to the `luxon` command (`core/src/cli`, `main.rs`), the command's
/// stderr line in `error.rs`, and the abort path of an MPI job Luxon owns (`schedule/abort.rs`).
#[test]
fn the_library_prints_nothing() {
    const PRINTS: &[&str] = &[
        "println!",
        "print!",
        "dbg!",
        "stdout()",
        "stderr()",
        "print_error",
        "print_warning",
        "print_line",
    ];
    const ALLOWED: &[&str] = &["core/src/error.rs", "core/src/schedule/abort.rs"];
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("core/src"), &mut files);
    rust_files(&root.join("formats/src"), &mut files);
    rust_files(&root.join("core/capi/src"), &mut files);
    for plugin in std::fs::read_dir(root.join("plugins")).unwrap().flatten() {
        rust_files(&plugin.path().join("src"), &mut files);
    }
    assert!(files.len() > 50, "found only {} source files", files.len());
    let mut problems = Vec::new();
    for file in files {
        let rel = file
            .strip_prefix(root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel.starts_with("core/src/cli/")
            || rel == "core/src/main.rs"
            || ALLOWED.contains(&rel.as_str())
        {
            continue;
        }
        let code = strip(&std::fs::read_to_string(&file).unwrap());
        let code = String::from_utf8_lossy(&code).into_owned();
        for (n, line) in code.lines().enumerate() {
            for p in PRINTS.iter().filter(|p| line.contains(*p)) {
                problems.push(format!("{rel}:{}: {p}", n + 1));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "the library prints (log through luxon::error::log instead):\n{}",
        problems.join("\n")
    );
}

/// Checks the modules under `src_dir` against `layers` (name and modules of each layer, bottom
/// to top); returns one line per problem: an import of a higher layer or of another module of
/// the same layer, a module the table does not place, or a table entry that names no module.
pub fn check(src_dir: &Path, layers: &[(&str, &[&str])]) -> Vec<String> {
    let mut layer_of = BTreeMap::new();
    for (i, (_, modules)) in layers.iter().enumerate() {
        for m in *modules {
            layer_of.insert(m.to_string(), i);
        }
    }
    let mut files = Vec::new();
    rust_files(src_dir, &mut files);
    files.sort();
    let mut problems = Vec::new();
    let mut present = BTreeSet::new();
    // (path under src_dir, its module, text, text without comments and literals)
    let mut sources = Vec::new();
    // Re-exports at a crate root: `crate::Name` means the module `Name` comes from.
    let mut aliases = BTreeMap::new();
    for path in &files {
        let rel = path.strip_prefix(src_dir).unwrap_or(path).to_path_buf();
        let text = std::fs::read_to_string(path).unwrap_or_default();
        let code = strip(&text);
        match ModuleFile::of(&rel) {
            Some(file) => {
                present.insert(file.module.clone());
                sources.push((rel, file, text, code));
            }
            None => aliases.extend(root_aliases(&code)),
        }
    }
    let name_of = |i: usize| layers[i].0;
    for m in &present {
        if !layer_of.contains_key(m) {
            problems.push(format!(
                "module `{m}` is in no layer: add it to the layer table"
            ));
        }
    }
    for (_, modules) in layers {
        for m in *modules {
            if !present.contains(*m) {
                problems.push(format!(
                    "the layer table names `{m}`, which is no module under {}",
                    src_dir.display()
                ));
            }
        }
    }
    for (rel, file, text, code) in &sources {
        let Some(&from) = layer_of.get(&file.module) else {
            continue;
        };
        for r in references(code, file.depth) {
            let target = match aliases.get(&r.first) {
                Some(m) if !layer_of.contains_key(&r.first) => m.clone(),
                _ => r.first.clone(),
            };
            if target == file.module {
                continue;
            }
            let line = text.lines().nth(r.line - 1).unwrap_or("").trim();
            let at = format!("{}:{}: `{}` ({line})", rel.display(), r.line, r.path);
            let Some(&to) = layer_of.get(&target) else {
                problems.push(format!("{at}: `{target}` is no module of the layer table"));
                continue;
            };
            if to > from {
                problems.push(format!(
                    "{at}: module `{}` (layer `{}`) imports `{target}` of the higher layer `{}`",
                    file.module,
                    name_of(from),
                    name_of(to)
                ));
            } else if to == from {
                problems.push(format!(
                    "{at}: module `{}` imports `{target}` of its own layer `{}`; modules of one \
                     layer must not import each other",
                    file.module,
                    name_of(from)
                ));
            }
        }
    }
    problems
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// A source file's top-level module and how deep in the module tree the file's own module is
/// (`x.rs` and `x/mod.rs`: 1, `x/y.rs`: 2).
struct ModuleFile {
    module: String,
    depth: usize,
}

impl ModuleFile {
    /// `None` for a crate root (`lib.rs`, `main.rs`).
    fn of(rel: &Path) -> Option<ModuleFile> {
        let parts: Vec<String> = rel
            .iter()
            .map(|p| p.to_string_lossy().into_owned())
            .collect();
        let stem = |s: &str| s.strip_suffix(".rs").unwrap_or(s).to_string();
        match parts.as_slice() {
            [one] if one == "lib.rs" || one == "main.rs" => None,
            [one] => Some(ModuleFile {
                module: stem(one),
                depth: 1,
            }),
            [first, .., last] => Some(ModuleFile {
                module: first.clone(),
                depth: parts.len() - usize::from(last == "mod.rs"),
            }),
            [] => None,
        }
    }
}

/// A path to something at the crate root: its first segment (the top-level module), the path
/// as written (from the crate root), and its line (from 1).
#[derive(Debug, PartialEq)]
struct Reference {
    first: String,
    path: String,
    line: usize,
}

/// Comments and the contents of string and character literals blanked out (newlines kept, so
/// byte offsets and line numbers stay those of the file).
fn strip(text: &str) -> Vec<u8> {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let blank = |out: &mut Vec<u8>, i: usize| {
        if out[i] != b'\n' {
            out[i] = b' ';
        }
    };
    let mut i = 0;
    while i < b.len() {
        let rest = &b[i..];
        if rest.starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                blank(&mut out, i);
                i += 1;
            }
        } else if rest.starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    blank(&mut out, i);
                    blank(&mut out, i + 1);
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    blank(&mut out, i);
                    blank(&mut out, i + 1);
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, i);
                    i += 1;
                }
            }
        } else if let Some(hashes) = raw_string_at(b, i) {
            // A raw string r#"…"#: ends at a quote followed by as many hashes.
            let mut close = vec![b'"'];
            close.extend(std::iter::repeat_n(b'#', hashes));
            let start = i;
            i += 2 + hashes;
            while i < b.len() && !b[i..].starts_with(&close) {
                i += 1;
            }
            i = (i + close.len()).min(b.len());
            for k in start..i {
                blank(&mut out, k);
            }
        } else if b[i] == b'"' {
            blank(&mut out, i);
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    blank(&mut out, i);
                    i += 1;
                }
                if i < b.len() {
                    blank(&mut out, i);
                    i += 1;
                }
            }
            if i < b.len() {
                blank(&mut out, i);
                i += 1;
            }
        } else if b[i] == b'\'' {
            // A character literal ('x', '\n', 'θ'), or else a lifetime or label.
            let end = if rest.get(1) == Some(&b'\\') {
                rest[2..].iter().position(|&c| c == b'\'').map(|p| p + 3)
            } else {
                let len = text[i + 1..].chars().next().map_or(1, char::len_utf8);
                (rest.get(1 + len) == Some(&b'\'')).then_some(len + 2)
            };
            match end {
                Some(n) => {
                    for k in i..i + n {
                        blank(&mut out, k);
                    }
                    i += n;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The number of hashes when a raw string (`r"…"`, `r#"…"#`, `br"…"`) starts at `i`.
fn raw_string_at(b: &[u8], i: usize) -> Option<usize> {
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let starts_token = match i {
        0 => true,
        1 => !ident(b[0]) || b[0] == b'b',
        _ => !ident(b[i - 1]) || (b[i - 1] == b'b' && !ident(b[i - 2])),
    };
    if b[i] != b'r' || !starts_token {
        return None;
    }
    let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
    (b.get(i + 1 + hashes) == Some(&b'"')).then_some(hashes)
}

/// Every path from the crate root in `code` (as [`strip`] leaves it) of a file whose module is
/// `depth` deep: `crate::` paths, and `super::` paths that climb past the file's top module.
fn references(code: &[u8], depth: usize) -> Vec<Reference> {
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let line_of = |i: usize| code[..i].iter().filter(|&&c| c == b'\n').count() + 1;
    let word_at = |i: usize, w: &[u8]| {
        code[i..].starts_with(w)
            && (i == 0 || !(ident(code[i - 1]) || code[i - 1] == b':'))
            && code.get(i + w.len()).is_none_or(|&c| !ident(c))
    };
    let mut out = Vec::new();
    // Brace depths at which inline `mod name {` blocks opened: each is one more level of
    // module for `super::`.
    let mut braces = 0usize;
    let mut mods: Vec<usize> = Vec::new();
    let mut pending_mod = false;
    let mut i = 0;
    while i < code.len() {
        let c = code[i];
        if c == b'{' {
            if pending_mod {
                mods.push(braces);
                pending_mod = false;
            }
            braces += 1;
        } else if c == b'}' {
            braces = braces.saturating_sub(1);
            if mods.last() == Some(&braces) {
                mods.pop();
            }
        } else if c == b';' {
            pending_mod = false;
        }
        if word_at(i, b"mod") {
            pending_mod = true;
            i += 3;
            continue;
        }
        let rooted = if word_at(i, b"crate") || (c == b'$' && word_at(i + 1, b"crate")) {
            let start = i + usize::from(c == b'$') + 5;
            code[start..].starts_with(b"::").then_some((i, start + 2))
        } else if word_at(i, b"super") {
            // `super::` repeated: past the file's own levels and its inline modules, it
            // reaches the crate root.
            let mut at = i;
            let mut ups = 0;
            while code[at..].starts_with(b"super::") {
                ups += 1;
                at += 7;
            }
            (ups > 0 && ups == depth + mods.len()).then_some((i, at))
        } else {
            None
        };
        let Some((start, after)) = rooted else {
            i += 1;
            continue;
        };
        let mut j = after;
        while j < code.len() && code[j].is_ascii_whitespace() {
            j += 1;
        }
        if code.get(j) == Some(&b'{') {
            for at in group_items(code, j) {
                let path = path_at(code, at);
                let first = first_segment(&path);
                if !first.is_empty() && first != "self" {
                    out.push(Reference {
                        first,
                        path: format!("crate::{path}"),
                        line: line_of(at),
                    });
                }
            }
        } else {
            let path = path_at(code, j);
            let first = first_segment(&path);
            if !first.is_empty() {
                out.push(Reference {
                    first,
                    path: format!("crate::{path}"),
                    line: line_of(start),
                });
            }
        }
        i = after;
    }
    out
}

/// Where the top-level items of the `{…}` group opening at `open` start.
fn group_items(code: &[u8], open: usize) -> Vec<usize> {
    let mut items = Vec::new();
    let mut depth = 0;
    let mut start = open + 1;
    for (k, &c) in code.iter().enumerate().skip(open) {
        match c {
            b'{' => depth += 1,
            b'}' | b',' if depth == 1 => {
                let mut s = start;
                while s < k && code[s].is_ascii_whitespace() {
                    s += 1;
                }
                if s < k {
                    items.push(s);
                }
                start = k + 1;
                if c == b'}' {
                    break;
                }
            }
            b'}' => depth -= 1,
            _ => {}
        }
    }
    items
}

/// The path written at `at` (identifiers and `::`, up to a group, call, `;`, space...).
fn path_at(code: &[u8], at: usize) -> String {
    let end = code[at..]
        .iter()
        .position(|&c| !(c.is_ascii_alphanumeric() || c == b'_' || c == b':'))
        .map_or(code.len(), |p| at + p);
    String::from_utf8_lossy(&code[at..end])
        .trim_end_matches(':')
        .to_string()
}

fn first_segment(path: &str) -> String {
    path.split("::").next().unwrap_or("").to_string()
}

/// A crate root's re-exports of module items: (name at the root, module), e.g.
/// `pub use error::Error;` gives ("Error", "error").
fn root_aliases(code: &[u8]) -> Vec<(String, String)> {
    let text = String::from_utf8_lossy(code);
    let mut out = Vec::new();
    for stmt in text.split(';') {
        let Some(at) = stmt.find("use ") else {
            continue;
        };
        let tree = stmt[at + 4..].trim();
        let tree = tree.strip_prefix("crate::").unwrap_or(tree);
        let tree = tree.strip_prefix("self::").unwrap_or(tree);
        let module = first_segment(tree.trim());
        if module.is_empty() || !tree.contains("::") {
            continue;
        }
        // The names the statement brings in: last segments, or the names after `as`.
        let leaves = tree.split(['{', '}', ',']).filter_map(|leaf| {
            let leaf = leaf.trim();
            let name = match leaf.split_once(" as ") {
                Some((_, alias)) => alias.trim(),
                None => leaf.rsplit("::").next().unwrap_or("").trim(),
            };
            (!name.is_empty() && name != "*" && name != "self").then(|| name.to_string())
        });
        for name in leaves {
            if name != module {
                out.push((name, module.clone()));
            }
        }
    }
    out
}

/// Tests of the checker itself, on small made-up crates.
mod checker {
    use super::*;

    /// A temporary source directory with `files` (path, text); removed on drop.
    struct Src(PathBuf);

    impl Src {
        fn new(name: &str, files: &[(&str, &str)]) -> Src {
            let dir =
                std::env::temp_dir().join(format!("luxon-layers-{name}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            for (path, text) in files {
                let p = dir.join(path);
                std::fs::create_dir_all(p.parent().unwrap()).unwrap();
                std::fs::write(p, text).unwrap();
            }
            Src(dir)
        }
    }

    impl Drop for Src {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    const TWO: &[(&str, &[&str])] = &[("low", &["low"]), ("high", &["high"])];

    #[test]
    fn an_upward_import_is_reported_with_file_line_import_and_layers() {
        let src = Src::new(
            "upward",
            &[
                ("lib.rs", "pub mod high;\npub mod low;\n"),
                ("low.rs", "//! Low.\n\nuse crate::high::Thing;\n"),
                ("high.rs", "use crate::low;\npub struct Thing;\n"),
            ],
        );
        let problems = check(&src.0, TWO);
        assert_eq!(problems.len(), 1, "{problems:#?}");
        let p = &problems[0];
        for part in ["low.rs:3", "`crate::high::Thing`", "`low`", "`high`"] {
            assert!(p.contains(part), "{p} lacks {part}");
        }
    }

    #[test]
    fn grouped_multiline_inline_and_climbing_super_paths_are_found() {
        let a = "use crate::{\n    b::X,\n    c::{self, Y},\n};\n\
                 fn f() {\n    crate::d::g();\n}\n\
                 // crate::b::h() in a comment is not an import\n\
                 const S: &str = \"crate::b::h\";\n\
                 const C: char = '\"';\n\
                 fn l<'a>(x: &'a str) -> &'a str { x }\n\
                 mod inner {\n    use super::super::e::Z;\n    use super::f;\n}\n\
                 use super::e::W;\n\
                 const R: &str = r#\"crate::b::\"h\"\"#;\n";
        let refs: Vec<(String, usize)> = references(&strip(a), 1)
            .into_iter()
            .map(|r| (r.first, r.line))
            .collect();
        let want = [("b", 2), ("c", 3), ("d", 6), ("e", 13), ("e", 16)];
        let want: Vec<(String, usize)> = want.iter().map(|(m, l)| (m.to_string(), *l)).collect();
        assert_eq!(refs, want);
        // One level deeper (a file in a module directory), `super::` stays in the module.
        assert!(references(&strip("use super::x::Y;\n"), 2).is_empty());
    }

    #[test]
    fn downward_and_same_module_imports_pass() {
        let src = Src::new(
            "downward",
            &[
                ("lib.rs", "pub mod high;\npub mod low;\n"),
                ("low.rs", "pub struct Base;\n"),
                (
                    "high/mod.rs",
                    "mod part;\nuse crate::low::Base;\nuse crate::high::part::P;\n",
                ),
                (
                    "high/part.rs",
                    "use super::super::low::Base;\nuse super::P2;\npub struct P;\n",
                ),
            ],
        );
        assert_eq!(check(&src.0, TWO), Vec::<String>::new());
    }

    #[test]
    fn same_layer_imports_root_aliases_and_table_mistakes_are_reported() {
        let src = Src::new(
            "same",
            &[
                (
                    "lib.rs",
                    "pub mod a;\npub mod b;\npub mod c;\npub use c::Top;\n",
                ),
                ("a.rs", "use crate::b::B;\nuse crate::Top;\n"),
                ("b.rs", "pub struct B;\n"),
                ("c.rs", "pub struct Top;\n"),
                ("stray.rs", "\n"),
            ],
        );
        let layers: &[(&str, &[&str])] =
            &[("one", &["a", "b"]), ("two", &["c"]), ("three", &["gone"])];
        let problems = check(&src.0, layers);
        let has = |part: &str| problems.iter().any(|p| p.contains(part));
        assert!(has("a.rs:1") && has("its own layer `one`"), "{problems:#?}");
        assert!(has("a.rs:2") && has("higher layer `two`"), "{problems:#?}");
        assert!(has("module `stray` is in no layer"), "{problems:#?}");
        assert!(has("names `gone`, which is no module"), "{problems:#?}");
        assert_eq!(problems.len(), 4, "{problems:#?}");
    }
}

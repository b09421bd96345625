//! Finding plugin libraries, the handshake, and looking entries up by the names scenes use.
//!
//! Libraries are never unloaded: objects created by a plugin may live anywhere in the process,
//! and unloading libraries that have thread-local destructors crashes.
//!
//! A library is loaded when a scene first uses one of its names (`get`,
//! `writer_for_extension`; `load_all` for `luxon plugins`): the names, kinds and extensions
//! come from its name table section ([`luxon_plugin::names`]), read from the file with the
//! ELF check, and its handshake must declare exactly those entries. A library without a
//! readable table (an older SDK) is loaded while searching, as every library once was.
//!
//! Plugins are trusted code: loading one runs its initialisers. What Luxon checks first is the
//! file: a special file (FIFO, device, directory) named like a plugin is refused by its type, and
//! a library's ELF headers must fit in its file ([`super::elf`]), so a truncated copy is skipped
//! with its reason instead of killing every run. Skipped files are [`Problem`]s: `luxon plugins`
//! lists them, `render` and `check` warn about them, and a lookup that misses names them.
//!
//! Places the user named that gave nothing are [`Registry::notes`]: a directory given by
//! `$LUXON_PLUGIN_PATH` or a plugin path that does not exist, and a shared library in such a
//! directory that is not loaded because of its name. They are not warnings (a directory may
//! hold other libraries on purpose), but `luxon plugins` and a lookup that misses list them.

use luxon_plugin::abi;
use luxon_plugin::names;
use std::collections::HashMap;
use std::ffi::c_void;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PluginKind {
    Primitive,
    Texture,
    VolumeReader,
    Writer,
}

impl PluginKind {
    fn from_abi(k: u32) -> Option<PluginKind> {
        match k {
            abi::KIND_PRIMITIVE => Some(PluginKind::Primitive),
            abi::KIND_TEXTURE => Some(PluginKind::Texture),
            abi::KIND_VOLUME_READER => Some(PluginKind::VolumeReader),
            abi::KIND_WRITER => Some(PluginKind::Writer),
            _ => None,
        }
    }
}

/// An entry's function table, typed by its kind: the calls take the table they need from
/// here, so no caller casts a pointer by what an entry claims to be.
#[derive(Clone, Copy)]
pub(crate) enum Table {
    Primitive(&'static abi::PrimitiveVTable),
    Texture(&'static abi::TextureVTable),
    VolumeReader(&'static abi::VolumeReaderVTable),
    Writer(&'static abi::WriterVTable),
}

impl Table {
    /// The table of an entry of kind `kind`.
    ///
    /// # Safety
    /// `vtable` points to the table of that kind (the ABI's `Entry::vtable`), which stays valid
    /// and unchanged for the rest of the process (a static of a library never unloaded).
    unsafe fn new(kind: PluginKind, vtable: *const c_void) -> Table {
        // SAFETY: the caller's promise, for the type `kind` names.
        unsafe {
            match kind {
                PluginKind::Primitive => Table::Primitive(&*vtable.cast()),
                PluginKind::Texture => Table::Texture(&*vtable.cast()),
                PluginKind::VolumeReader => Table::VolumeReader(&*vtable.cast()),
                PluginKind::Writer => Table::Writer(&*vtable.cast()),
            }
        }
    }

    fn kind(&self) -> PluginKind {
        match self {
            Table::Primitive(_) => PluginKind::Primitive,
            Table::Texture(_) => PluginKind::Texture,
            Table::VolumeReader(_) => PluginKind::VolumeReader,
            Table::Writer(_) => PluginKind::Writer,
        }
    }
}

impl fmt::Debug for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Table({})", self.kind())
    }
}

impl fmt::Display for PluginKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PluginKind::Primitive => "primitive",
            PluginKind::Texture => "texture",
            PluginKind::VolumeReader => "volume reader",
            PluginKind::Writer => "writer",
        })
    }
}

/// A loaded library.
#[derive(Clone, Debug)]
pub struct Library {
    pub path: PathBuf,
    /// The name the library gives itself.
    pub name: String,
    pub sdk_version: String,
    pub abi_version: u32,
}

/// One named thing a library provides.
#[derive(Clone, Debug)]
pub struct Entry {
    pub kind: PluginKind,
    pub name: String,
    pub description: String,
    pub params_doc: String,
    /// Writers: file extensions (lower case, no dot).
    pub extensions: Vec<String>,
    /// Index into `Registry::libraries`.
    pub library: usize,
    pub(crate) table: Table,
    /// Set when an earlier library in the search order already provides this name.
    pub shadowed: bool,
}

/// A file that looked like a plugin but could not be used.
#[derive(Clone, Debug)]
pub struct Problem {
    pub path: PathBuf,
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.message)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum LookupError {
    #[error("{}", not_found_message(.name, .kind, .suggestion, .searched, .problems))]
    NotFound {
        name: String,
        kind: PluginKind,
        suggestion: Option<String>,
        searched: Vec<PathBuf>,
        problems: Vec<Problem>,
    },
    #[error("plugin `{name}` is a {found} (in {}), but a {expected} is expected here", .library.display())]
    WrongKind {
        name: String,
        found: PluginKind,
        expected: PluginKind,
        library: PathBuf,
    },
    /// The library whose name table lists `name` failed its handshake when it was loaded.
    #[error("plugin `{name}` is provided by {}, which cannot be used: {message}", .library.display())]
    Unusable {
        name: String,
        library: PathBuf,
        message: String,
    },
}

fn not_found_message(
    name: &str,
    kind: &PluginKind,
    suggestion: &Option<String>,
    searched: &[PathBuf],
    problems: &[Problem],
) -> String {
    let mut m = format!("no {kind} plugin named `{name}`");
    if let Some(s) = suggestion {
        m.push_str(&format!(", did you mean `{s}`?"));
    }
    let dirs: Vec<String> = searched.iter().map(|p| p.display().to_string()).collect();
    let sep = if suggestion.is_some() { " S" } else { "; s" };
    m.push_str(&format!(
        "{sep}earched: {} (add directories with the scene's `plugin_path` or $LUXON_PLUGIN_PATH)",
        if dirs.is_empty() {
            "nothing".to_string()
        } else {
            dirs.join(", ")
        }
    ));
    if !problems.is_empty() {
        let p: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
        m.push_str(&format!("; could not use: {}", p.join("; ")));
    }
    m
}

/// A library file on the search path that passed the file check, loaded now (no name table,
/// or `load_all`) or when a scene first uses one of its names.
struct Slot {
    path: PathBuf,
    /// Set once: the handshake's result.
    loaded: OnceLock<Result<Loaded, String>>,
    /// The names its section lists, checked against the declaration when it is loaded; `None`
    /// when it was loaded for want of a section.
    listed: Option<Vec<names::Named>>,
}

/// A library after its handshake.
struct Loaded {
    library: Library,
    entries: Vec<Entry>,
}

/// A name some library provides, known before (or without) loading it.
struct Named {
    kind: PluginKind,
    name: String,
    extensions: Vec<String>,
    /// Index into `Registry::slots`.
    library: usize,
}

#[derive(Default)]
pub struct Registry {
    /// Every usable library file, in search order.
    slots: Vec<Slot>,
    /// Every name of every library, in search order.
    names: Vec<Named>,
    /// Every directory (or file) searched, in order.
    pub searched: Vec<PathBuf>,
    /// Files that could not be used, found while searching (a library whose name table
    /// brought it in unloaded reports a failed handshake when it is first used, or by
    /// [`Registry::load_all`]).
    pub problems: Vec<Problem>,
    /// Places the user named that gave nothing, and why: a missing directory, a library not
    /// loaded for its name (see the module comment).
    pub notes: Vec<Problem>,
    /// The first of `names` for each name.
    by_name: HashMap<String, usize>,
    /// The libraries whose entries were looked up (by `get` or `writer_for_extension`).
    used: std::sync::Mutex<std::collections::BTreeSet<usize>>,
}

/// `HostTable::log`: a plugin's message, as `{plugin}: {message}`, to the library's log sink.
///
/// # Safety
/// Both strings are readable for the call (the ABI's calling contract).
unsafe extern "C" fn host_log(level: u32, plugin: abi::Str, message: abi::Str) {
    // SAFETY: the caller's promise; the strings are only used within this call.
    let (plugin, message) = unsafe { (plugin.as_str(), message.as_str()) };
    let (plugin, message) = (plugin.unwrap_or("?"), message.unwrap_or("(invalid UTF-8)"));
    // A panic the SDK caught where no error sink reaches: it goes into the call's error.
    if crate::geometry::custom::keep_plugin_panic(level, message) {
        return;
    }
    let level = crate::error::Level::from_code(level);
    crate::error::log(level, &format!("{plugin}: {message}"));
}

static HOST: abi::HostTable = abi::HostTable {
    abi_version: abi::ABI_VERSION,
    log: host_log,
};

/// File names scanned in directories: `libluxon_*.so` (`luxon_*.dll` on Windows, `.dylib` on
/// macOS). Files named explicitly in a plugin path are loaded whatever their name.
pub fn is_plugin_file_name(name: &str) -> bool {
    let prefix = format!("{}luxon_", std::env::consts::DLL_PREFIX);
    name.starts_with(&prefix) && name.ends_with(std::env::consts::DLL_SUFFIX)
}

/// Refuses what is not a regular file (after symbolic links) by its type, before opening it: a
/// FIFO would block the open, a device could be read forever.
fn regular_file(path: &Path) -> Result<(), String> {
    let m = std::fs::metadata(path).map_err(|e| format!("cannot be read: {e}"))?;
    if m.is_file() {
        return Ok(());
    }
    let what = luxon_plugin::files::kind_of(m.file_type());
    Err(format!(
        "is {what}; expected a plugin library (a regular file)"
    ))
}

/// The default search path after `extra`: `$LUXON_PLUGIN_PATH`, then the executable's directory
/// (and its parent when that is cargo's `deps`, so test binaries find the workspace's plugins).
pub fn search_path(extra: &[PathBuf]) -> Vec<PathBuf> {
    let (mut dirs, builtin) = search_places(extra);
    dirs.extend(builtin);
    dirs
}

/// The search path in two parts: the places the user named (`extra`, then
/// `$LUXON_PLUGIN_PATH`), and the executable's own directories.
fn search_places(extra: &[PathBuf]) -> (Vec<PathBuf>, Vec<PathBuf>) {
    let mut named: Vec<PathBuf> = extra.to_vec();
    if let Some(env) = std::env::var_os("LUXON_PLUGIN_PATH") {
        named.extend(std::env::split_paths(&env).filter(|p| !p.as_os_str().is_empty()));
    }
    let mut builtin = Vec::new();
    if let Ok(exe) = std::env::current_exe() {
        if let Some(dir) = exe.parent() {
            builtin.push(dir.to_path_buf());
            if dir.file_name().is_some_and(|n| n == "deps") {
                if let Some(up) = dir.parent() {
                    builtin.push(up.to_path_buf());
                }
            }
        }
    }
    (named, builtin)
}

/// A shared library by its name (`.so`, `.so.1`; `.dylib`, `.dll` elsewhere) that the scanner
/// does not load because of its name: the note that says why.
fn name_note(name: &str) -> Option<String> {
    let suffix = std::env::consts::DLL_SUFFIX;
    let versioned = suffix == ".so" && name.contains(".so.");
    if is_plugin_file_name(name) || !(name.ends_with(suffix) || versioned) {
        return None;
    }
    let prefix = format!("{}luxon_", std::env::consts::DLL_PREFIX);
    Some(format!(
        "not loaded: its name does not start with `{prefix}`; expected a file named \
         {prefix}NAME{suffix} (rename it, or give the file itself in the plugin path)"
    ))
}

impl Registry {
    /// Loads every plugin found on `search_path(extra)`.
    pub fn discover(extra: &[PathBuf]) -> Registry {
        Registry::discover_with_home(extra, None)
    }

    /// [`discover`](Self::discover), also searching `home` (the directory of the library
    /// Luxon runs from, when a host program loaded it: its plugins are installed beside it)
    /// after `$LUXON_PLUGIN_PATH` and before the executable's directory. Like the executable's,
    /// it is one of Luxon's own places: nothing is noted when it holds no plugins.
    pub fn discover_with_home(extra: &[PathBuf], home: Option<&Path>) -> Registry {
        let mut r = Registry::default();
        let (named, builtin) = search_places(extra);
        for dir in named {
            r.add_named_path(&dir);
        }
        if let Some(dir) = home {
            r.add_path(dir);
        }
        for dir in builtin {
            r.add_path(&dir);
        }
        r
    }

    /// Adds a directory (scanned for plugin file names) or a library file.
    pub fn add_path(&mut self, path: &Path) {
        self.scan(path, false);
    }

    /// [`add_path`](Self::add_path) for a place the user named: if it gives nothing, the
    /// registry's [`notes`](Self::notes) say why (it does not exist, or a library in it is not
    /// named like a plugin).
    pub fn add_named_path(&mut self, path: &Path) {
        self.scan(path, true);
    }

    fn scan(&mut self, path: &Path, named: bool) {
        if self.searched.iter().any(|p| p == path) {
            return;
        }
        self.searched.push(path.to_path_buf());
        match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => {}
            Err(e) if named => {
                let why = if e.kind() == std::io::ErrorKind::NotFound {
                    "no such file or directory".to_string()
                } else {
                    format!("cannot be read: {e}")
                };
                return self.notes.push(Problem {
                    path: path.to_path_buf(),
                    message: format!("{why}; expected a directory of plugins or a plugin file"),
                });
            }
            // The executable's directories are searched whether they hold plugins or not.
            Err(_) => return,
            Ok(_) => return self.load(path),
        }
        let Ok(read) = std::fs::read_dir(path) else {
            return;
        };
        let mut files = Vec::new();
        let mut misnamed = Vec::new();
        for p in read.filter_map(|e| e.ok()).map(|e| e.path()) {
            let Some(name) = p.file_name().and_then(|n| n.to_str()) else {
                continue;
            };
            if is_plugin_file_name(name) {
                files.push(p);
            } else if let Some(note) = name_note(name).filter(|_| named) {
                misnamed.push(Problem {
                    path: p,
                    message: note,
                });
            }
        }
        files.sort();
        misnamed.sort_by(|a, b| a.path.cmp(&b.path));
        self.notes.extend(misnamed);
        for f in files {
            self.load(&f);
        }
    }

    fn problem(&mut self, path: &Path, message: String) {
        self.problems.push(Problem {
            path: path.to_path_buf(),
            message,
        });
    }

    /// Takes a library file into the registry: its names from its name table when it has a
    /// readable one (it is loaded on first use), else by loading it now.
    fn load(&mut self, path: &Path) {
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        if self.slots.iter().any(|l| l.path == canonical) {
            return;
        }
        let checked = match regular_file(path).and_then(|()| super::elf::check_library(&canonical))
        {
            Ok(c) => c,
            Err(e) => return self.problem(path, e),
        };
        let index = self.slots.len();
        // A table that cannot be read is as good as none: the library is loaded to learn its
        // names, as one built before tables existed.
        let listed = checked.names.and_then(|b| names::parse(&b).ok());
        let listed = listed.filter(|l| l.iter().all(|n| PluginKind::from_abi(n.kind).is_some()));
        if let Some(listed) = listed {
            let named = listed.iter().map(|n| Named {
                kind: PluginKind::from_abi(n.kind).unwrap_or(PluginKind::Primitive),
                name: n.name.clone(),
                extensions: extension_list(&n.extensions),
                library: index,
            });
            self.add_names(named.collect());
            self.slots.push(Slot {
                path: canonical,
                loaded: OnceLock::new(),
                listed: Some(listed),
            });
            return;
        }
        let mut loaded = match handshake(&canonical, index) {
            Ok(l) => l,
            Err(e) => return self.problem(path, e),
        };
        let named = loaded.entries.iter().map(|e| Named {
            kind: e.kind,
            name: e.name.clone(),
            extensions: e.extensions.clone(),
            library: index,
        });
        self.add_names(named.collect());
        self.mark_shadowed(index, &mut loaded.entries);
        self.slots.push(Slot {
            path: canonical,
            loaded: OnceLock::from(Ok(loaded)),
            listed: None,
        });
    }

    /// Adds a library's names after those of the libraries before it: the first of a name wins.
    fn add_names(&mut self, named: Vec<Named>) {
        for n in named {
            if !self.by_name.contains_key(&n.name) {
                self.by_name.insert(n.name.clone(), self.names.len());
            }
            self.names.push(n);
        }
    }

    /// Marks the entries of library `index` whose names an earlier library (or an earlier
    /// entry of the same library) provides.
    fn mark_shadowed(&self, index: usize, entries: &mut [Entry]) {
        for k in 0..entries.len() {
            let first = self
                .by_name
                .get(&entries[k].name)
                .map(|&i| self.names[i].library);
            let again = entries[..k].iter().any(|e| e.name == entries[k].name);
            entries[k].shadowed = first != Some(index) || again;
        }
    }

    /// Library `index` after its handshake, which runs on the first call (from any thread):
    /// the error says why it cannot be used.
    fn loaded(&self, index: usize) -> Result<&Loaded, &str> {
        let slot = &self.slots[index];
        let r = slot.loaded.get_or_init(|| {
            let mut loaded = handshake(&slot.path, index)?;
            if let Some(listed) = &slot.listed {
                same_entries(listed, &loaded.entries)?;
            }
            self.mark_shadowed(index, &mut loaded.entries);
            Ok(loaded)
        });
        r.as_ref().map_err(String::as_str)
    }

    /// The entry named by `names[i]`, its library loaded.
    fn entry(&self, i: usize) -> Result<&Entry, LookupError> {
        let n = &self.names[i];
        let unusable = |message: String| LookupError::Unusable {
            name: n.name.clone(),
            library: self.slots[n.library].path.clone(),
            message,
        };
        let loaded = self
            .loaded(n.library)
            .map_err(|m| unusable(m.to_string()))?;
        let e = loaded
            .entries
            .iter()
            .find(|e| e.name == n.name && e.kind == n.kind)
            .ok_or_else(|| unusable(format!("it does not declare {} `{}`", n.kind, n.name)))?;
        let mut used = self.used.lock().unwrap_or_else(|e| e.into_inner());
        used.insert(n.library);
        Ok(e)
    }

    /// The entry a scene means by `name`, which must be of `kind`. Loads the library that
    /// provides it, if it is not loaded yet.
    pub fn get(&self, name: &str, kind: PluginKind) -> Result<&Entry, LookupError> {
        match self.by_name.get(name) {
            Some(&i) => {
                let n = &self.names[i];
                if n.kind != kind {
                    return Err(LookupError::WrongKind {
                        name: name.to_string(),
                        found: n.kind,
                        expected: kind,
                        library: self.slots[n.library].path.clone(),
                    });
                }
                self.entry(i)
            }
            None => {
                let candidates = self
                    .names
                    .iter()
                    .enumerate()
                    .filter(|(i, n)| n.kind == kind && self.by_name.get(&n.name) == Some(i))
                    .map(|(_, n)| n.name.as_str());
                Err(LookupError::NotFound {
                    name: name.to_string(),
                    kind,
                    suggestion: luxon_plugin::suggest(name, candidates).map(str::to_string),
                    searched: self.searched.clone(),
                    problems: self.problems.iter().chain(&self.notes).cloned().collect(),
                })
            }
        }
    }

    /// The writer claiming a file extension (first in search order), its library loaded.
    pub fn writer_for_extension(&self, ext: &str) -> Result<Option<&Entry>, LookupError> {
        let ext = ext.to_ascii_lowercase();
        let found = self
            .names
            .iter()
            .position(|n| n.kind == PluginKind::Writer && n.extensions.contains(&ext));
        found.map(|i| self.entry(i)).transpose()
    }

    /// Loads every library not loaded yet (what `luxon plugins` lists): the problems are those
    /// whose handshake failed, in search order (they are also what a lookup of their names
    /// reports).
    pub fn load_all(&self) -> Vec<Problem> {
        (0..self.slots.len())
            .filter_map(|i| {
                self.loaded(i).err().map(|m| Problem {
                    path: self.slots[i].path.clone(),
                    message: m.to_string(),
                })
            })
            .collect()
    }

    /// The libraries loaded so far, with their entries, in search order.
    pub fn loaded_libraries(&self) -> Vec<(&Library, &[Entry])> {
        self.slots
            .iter()
            .filter_map(|s| match s.loaded.get() {
                Some(Ok(l)) => Some((&l.library, &l.entries[..])),
                _ => None,
            })
            .collect()
    }

    /// Every name a scene can use (the first library's of each), with its kind and library
    /// file, in search order; known without loading the libraries.
    pub fn provided(&self) -> Vec<(PluginKind, &str, &Path)> {
        self.names
            .iter()
            .enumerate()
            .filter(|(i, n)| self.by_name.get(&n.name) == Some(i))
            .map(|(_, n)| {
                (
                    n.kind,
                    n.name.as_str(),
                    self.slots[n.library].path.as_path(),
                )
            })
            .collect()
    }

    /// How many library files were found usable (loaded or not yet).
    pub fn library_count(&self) -> usize {
        self.slots.len()
    }

    /// The libraries a scene used so far (whose entries were looked up), in search order:
    /// what a frame's completion record stamps.
    pub fn used_libraries(&self) -> Vec<&Library> {
        let used = self.used.lock().unwrap_or_else(|e| e.into_inner());
        used.iter().map(|&i| self.library(i)).collect()
    }

    /// Every extension some writer claims.
    pub fn writer_extensions(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .names
            .iter()
            .filter(|n| n.kind == PluginKind::Writer)
            .flat_map(|n| n.extensions.iter().cloned())
            .collect();
        v.sort();
        v.dedup();
        v
    }

    pub fn library_of(&self, e: &Entry) -> &Library {
        self.library(e.library)
    }

    /// Library `index`, which is loaded (an entry of it or a use of it exists).
    fn library(&self, index: usize) -> &Library {
        match self.slots[index].loaded.get() {
            Some(Ok(l)) => &l.library,
            _ => unreachable!("entries exist only of loaded libraries"),
        }
    }

    /// A registry of one loaded library with `entries` (whose `library` is 0), for tests of
    /// the calls with tables of their own.
    #[cfg(test)]
    pub(crate) fn with_library(library: Library, entries: Vec<Entry>) -> Registry {
        let mut r = Registry::default();
        let named = entries.iter().map(|e| Named {
            kind: e.kind,
            name: e.name.clone(),
            extensions: e.extensions.clone(),
            library: 0,
        });
        r.add_names(named.collect());
        r.slots.push(Slot {
            path: library.path.clone(),
            loaded: OnceLock::from(Ok(Loaded { library, entries })),
            listed: None,
        });
        r
    }
}

/// A writer's extension list as entries keep it: lower case, no blanks or empty items.
fn extension_list(s: &str) -> Vec<String> {
    s.split(',')
        .map(|s| s.trim().to_ascii_lowercase())
        .filter(|s| !s.is_empty())
        .collect()
}

/// The declaration's entries are those its name table listed, kind, name and extensions: a
/// scene was matched to this library by the table.
fn same_entries(listed: &[names::Named], entries: &[Entry]) -> Result<(), String> {
    let declared = |e: &Entry| format!("{} `{}`", e.kind, e.name);
    let all: Vec<String> = entries.iter().map(declared).collect();
    let all = if all.is_empty() {
        "nothing".to_string()
    } else {
        all.join(", ")
    };
    for n in listed {
        let kind = PluginKind::from_abi(n.kind);
        let ext = extension_list(&n.extensions);
        let found = entries
            .iter()
            .any(|e| Some(e.kind) == kind && e.name == n.name && e.extensions == ext);
        if !found {
            let what = kind.map_or_else(|| format!("kind {}", n.kind), |k| k.to_string());
            return Err(format!(
                "its name table lists {what} `{}`{}, but its declaration does not (it declares \
                 {all}); the library's file does not match its code",
                n.name,
                if ext.is_empty() {
                    String::new()
                } else {
                    format!(" [.{}]", ext.join(", ."))
                }
            ));
        }
    }
    for e in entries {
        let listed_too = listed.iter().any(|n| {
            PluginKind::from_abi(n.kind) == Some(e.kind)
                && n.name == e.name
                && extension_list(&n.extensions) == e.extensions
        });
        if !listed_too {
            return Err(format!(
                "its declaration has {} that its name table does not list; the library's file \
                 does not match its code",
                declared(e)
            ));
        }
    }
    Ok(())
}

/// The handshake with the library at `path` (checked, canonical): loads it and reads its
/// declaration. Its entries' `library` is `index`; none is marked shadowed yet.
fn handshake(path: &Path, index: usize) -> Result<Loaded, String> {
    // SAFETY: loading runs the library's initialisers, and from here on its code runs in
    // this process. Nothing here can check that code: plugin files are trusted by design
    // (the user put them on the search path), as is everything below that relies on a
    // library keeping the ABI's promises.
    let lib =
        unsafe { libloading::Library::new(path) }.map_err(|e| format!("cannot be loaded: {e}"))?;
    // SAFETY: `DeclareFn` is the type the ABI gives this symbol; the function pointer is
    // used while `lib` is loaded, which is forever (see the module comment).
    let declare: abi::DeclareFn = *unsafe { lib.get::<abi::DeclareFn>(abi::DECLARE_SYMBOL) }
        .map_err(|_| {
            "not a Luxon plugin (it does not export `luxon_plugin_declare`)".to_string()
        })?;
    // SAFETY: the handshake's one argument is the host table, valid for the process (a
    // static here).
    let header = unsafe { declare(&HOST) };
    // Never unload (see the module comment): the library stays whatever the checks below say.
    std::mem::forget(lib);
    if header.is_null() {
        return Err("not a Luxon plugin (its declaration is null)".into());
    }
    // SAFETY: a non-null header is the library's static, valid for the process. Its leading
    // `magic`, `abi_version` and `sdk_version` keep their layout in every ABI version, so
    // they are read on their own, before the version says what follows them; the version
    // string is only read (and copied) once the magic says this is a Luxon header.
    let (magic, abi_version) = unsafe { ((*header).magic, (*header).abi_version) };
    if magic != abi::MAGIC {
        return Err("not a Luxon plugin (bad magic in its declaration)".into());
    }
    // SAFETY: as above; the string is a static of the library.
    let sdk = unsafe { (*header).sdk_version.as_str() }
        .unwrap_or("?")
        .to_string();
    if abi_version != abi::ABI_VERSION {
        return Err(format!(
            "built for plugin ABI {} (luxon-plugin {sdk}), but this Luxon uses ABI {} \
             (luxon-plugin {}); rebuild it against luxon-plugin {}",
            abi_version,
            abi::ABI_VERSION,
            luxon_plugin::SDK_VERSION,
            luxon_plugin::SDK_VERSION
        ));
    }
    // From here on the library speaks this ABI version: its header, declaration, entries
    // and strings are statics of the library laid out as `abi` says, valid for the process.
    // SAFETY: see above.
    let Some(decl) = (unsafe { (*header).declaration.as_ref() }) else {
        return Err("plugin declares nothing (null declaration)".into());
    };
    // SAFETY: see above.
    let text = |s: &abi::Str| unsafe { s.as_str() }.unwrap_or("").to_string();
    let name = text(&decl.library);
    let raw: &[abi::Entry] = if decl.entry_count == 0 || decl.entries.is_null() {
        &[]
    } else {
        // SAFETY: see above; `entries` points to `entry_count` entries.
        unsafe { std::slice::from_raw_parts(decl.entries, decl.entry_count) }
    };
    let mut entries = Vec::new();
    for e in raw {
        let Some(kind) = PluginKind::from_abi(e.kind) else {
            return Err(format!("declares an unknown plugin kind {}", e.kind));
        };
        if e.vtable.is_null() {
            return Err(format!("entry `{}` has no function table", text(&e.name)));
        }
        entries.push(Entry {
            kind,
            name: text(&e.name),
            description: text(&e.description),
            params_doc: text(&e.params_doc),
            extensions: extension_list(&text(&e.extensions)),
            library: index,
            // SAFETY: a non-null `vtable` points to the table of the entry's kind, a static
            // of the library (see above).
            table: unsafe { Table::new(kind, e.vtable) },
            shadowed: false,
        });
    }
    Ok(Loaded {
        library: Library {
            path: path.to_path_buf(),
            name,
            sdk_version: sdk,
            abi_version,
        },
        entries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shared libraries not named like plugins get a note; plugins and other files do not.
    #[cfg(target_os = "linux")]
    #[test]
    fn libraries_not_named_like_plugins_get_a_note() {
        for name in ["libstripes.so", "luxon_stripes.so", "libfoo.so.1"] {
            let note = name_note(name).unwrap_or_else(|| panic!("no note for {name}"));
            assert!(
                note.starts_with("not loaded: its name does not start with `libluxon_`"),
                "{note}"
            );
        }
        for name in [
            "libluxon_stripes.so",
            "stripes.txt",
            "libstripes.a",
            "scene.ron",
        ] {
            assert_eq!(name_note(name), None, "{name}");
        }
    }

    /// A missing place the user named is a note; the executable's own directories are not.
    #[test]
    fn a_missing_named_directory_is_a_note() {
        let missing = std::env::temp_dir().join(format!("luxon-no-dir-{}", std::process::id()));
        let mut r = Registry::default();
        r.add_path(&missing);
        assert!(r.notes.is_empty());
        let mut r = Registry::default();
        r.add_named_path(&missing);
        assert_eq!(r.notes.len(), 1);
        assert_eq!(
            r.notes[0].to_string(),
            format!(
                "{}: no such file or directory; expected a directory of plugins or a plugin file",
                missing.display()
            )
        );
    }
}

//! The memory budget: how many bytes a scene's content may make Luxon allocate.
//!
//! A scene can ask for more memory than the machine has (a huge image, a volume of many
//! gigabytes, millions of primitives). Without a budget such a run ends when the system refuses
//! an allocation, which aborts the process with no useful message. With one, everything that
//! grows with the input is charged *before* it is allocated: a scene over budget is an error
//! naming what did not fit and how much it needed, and an allocation the system still refuses
//! (`try_reserve`) is an error too, never an abort.
//!
//! The budget comes from `--memory`, else the scene's `render: (memory: ...)`, else the
//! machine: 75% of its limit (the smallest of `MemTotal`, the cgroup's memory limit and the
//! process's `RLIMIT_AS`/`RLIMIT_DATA`), at most 90% of what was available at start
//! (`MemAvailable`), shared among the MPI ranks on the node. Percentages (`"50%"`) are of the
//! machine's limit. Small and bounded allocations are not charged: within the budget they
//! cannot fail unless the machine is out of memory anyway.

use crate::error::Error;
use luxon_formats::{LoadOptions, MemorySize, RenderDesc};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::Arc;

/// What the charged bytes hold (for the message that lists what is in use).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    /// Geometry an importer read (NFF, OBJ), held until the scene's own arrays hold it.
    Import,
    Geometry,
    Bvh,
    Volumes,
    Textures,
    Image,
    Output,
}

impl Use {
    const ALL: [Use; 7] = [
        Use::Import,
        Use::Geometry,
        Use::Bvh,
        Use::Volumes,
        Use::Textures,
        Use::Image,
        Use::Output,
    ];

    fn name(self) -> &'static str {
        match self {
            Use::Import => "imported geometry",
            Use::Geometry => "geometry",
            Use::Bvh => "BVH",
            Use::Volumes => "volumes",
            Use::Textures => "texture cache",
            Use::Image => "image",
            Use::Output => "output",
        }
    }
}

/// Over budget, or refused by the system: the message says what, how much and what to do.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct BudgetError(pub String);

impl From<BudgetError> for Error {
    fn from(e: BudgetError) -> Error {
        Error::Render(e.0)
    }
}

impl From<BudgetError> for String {
    fn from(e: BudgetError) -> String {
        e.0
    }
}

/// Bytes of memory parsing takes per byte of RON scene text (measured: a 654 MB scene peaks at
/// 7.9 GB), rounded up.
const PARSE_BYTES_PER_TEXT_BYTE: u64 = 16;

/// The texture cache when the scene does not set one: 1 GiB, at most a quarter of the budget.
const DEFAULT_TEXTURE_CACHE: u64 = 1 << 30;

/// A byte count for messages ("64 MiB", "1.5 GiB").
pub fn bytes(n: u64) -> String {
    luxon_plugin::files::bytes(n)
}

/// The bytes a run may allocate for what grows with its input, and what it has charged.
#[derive(Debug)]
pub struct Budget {
    /// `u64::MAX`: no limit.
    limit: u64,
    /// Where the limit came from, for `check` and `--stats`.
    source: String,
    texture_cache: u64,
    total: AtomicU64,
    used: [AtomicU64; 7],
}

impl Budget {
    /// No limit (library use, tests): charges are counted but never refused.
    pub fn unlimited() -> Budget {
        Budget::new(u64::MAX, "no limit".into(), None)
    }

    /// A limit of `limit` bytes, described by `source`. The texture cache gets `texture_cache`
    /// bytes (at most the limit), or by default 1 GiB, at most a quarter of the limit.
    pub fn new(limit: u64, source: String, texture_cache: Option<u64>) -> Budget {
        let texture_cache = match texture_cache {
            Some(n) => n.min(limit),
            None => DEFAULT_TEXTURE_CACHE.min(limit / 4),
        };
        Budget {
            limit,
            source,
            texture_cache,
            total: AtomicU64::new(0),
            used: Default::default(),
        }
    }

    /// The budget for a render: `cli` (`--memory`), else the scene's setting, else the
    /// machine's default, shared among `node_ranks` processes on this node (percentages and the
    /// default only: an explicit size is per process).
    pub fn for_render(render: &RenderDesc, cli: Option<MemorySize>, node_ranks: usize) -> Budget {
        let machine = Machine::read();
        let (size, from) = match (cli, render.memory) {
            (Some(m), _) => (Some(m), "--memory"),
            (None, Some(m)) => (Some(m), "the scene's `render: (memory: ...)`"),
            (None, None) => (None, ""),
        };
        let (limit, source) = match size {
            Some(MemorySize::Bytes(n)) => (n, format!("from {from}")),
            Some(MemorySize::Percent(p)) => {
                let (total, what) = machine.limit();
                let n = (total as f64 * p / 100.0) as u64;
                (n, format!("{p}% of {} {what}, from {from}", bytes(total)))
            }
            None => machine.default_budget(),
        };
        let (limit, source) = match (size, node_ranks) {
            (Some(MemorySize::Bytes(_)), _) | (_, 0 | 1) => (limit, source),
            (_, n) => (
                limit / n as u64,
                format!("{source}, shared by {n} ranks on this node"),
            ),
        };
        Budget::new(limit.max(1), source, render.texture_cache)
    }

    /// The budget a scene is loaded within: `--memory`, else the machine's default (the
    /// scene's own setting is read only with it), shared as [`for_render`](Self::for_render)
    /// shares it.
    pub fn for_load(cli: Option<MemorySize>, node_ranks: usize) -> Budget {
        Budget::for_render(&RenderDesc::default(), cli, node_ranks)
    }

    /// The limits of loading a scene within what is left of the budget: its RON text (a
    /// sixteenth of it, at most the default 1 GiB) and what the importers may hold.
    pub fn load_options(&self) -> LoadOptions {
        let default = LoadOptions::default();
        if self.limit().is_none() {
            return default;
        }
        let left = self.remaining();
        LoadOptions {
            max_scene_bytes: default
                .max_scene_bytes
                .min(left / PARSE_BYTES_PER_TEXT_BYTE),
            max_geometry: left,
            limit: format!(
                "the memory budget is {}; raise it with --memory",
                self.describe()
            ),
        }
    }

    /// The limit, `None` when there is none.
    pub fn limit(&self) -> Option<u64> {
        (self.limit != u64::MAX).then_some(self.limit)
    }

    /// "17.6 GiB (75% of 23.5 GiB MemTotal)".
    pub fn describe(&self) -> String {
        match self.limit() {
            Some(n) => format!("{} ({})", bytes(n), self.source),
            None => "none".into(),
        }
    }

    /// Bytes not yet charged (`u64::MAX` without a limit).
    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.total.load(Relaxed))
    }

    /// Bytes charged for `kind`.
    pub fn used(&self, kind: Use) -> u64 {
        self.used[kind as usize].load(Relaxed)
    }

    /// The texture cache's share: what texture plugins may keep decoded.
    pub fn texture_cache(&self) -> u64 {
        self.texture_cache
    }

    /// "geometry 1.2 GiB, volumes 64 MiB": what is charged, by kind.
    pub fn in_use(&self) -> String {
        let parts: Vec<String> = Use::ALL
            .iter()
            .filter(|&&k| self.used(k) > 0)
            .map(|&k| format!("{} {}", k.name(), bytes(self.used(k))))
            .collect();
        if parts.is_empty() {
            "nothing".into()
        } else {
            parts.join(", ")
        }
    }

    /// Charges `bytes` for `kind` until [`release`](Self::release)d, or fails naming `what`
    /// (e.g. "the image (8192x8192, 4 f32 channels)") when they do not fit.
    pub fn reserve(
        &self,
        kind: Use,
        n: u64,
        what: impl FnOnce() -> String,
    ) -> Result<(), BudgetError> {
        let fits = |t: u64| t.checked_add(n).filter(|&sum| sum <= self.limit);
        if let Err(before) = self.total.fetch_update(Relaxed, Relaxed, fits) {
            let left = self.limit.saturating_sub(before);
            return Err(BudgetError(format!(
                "{} needs {} more, but the memory budget of {} has {} left (in use: {}); raise \
                 it with --memory or `render: (memory: ...)`",
                what(),
                bytes(n),
                self.describe(),
                bytes(left),
                self.in_use()
            )));
        }
        self.used[kind as usize].fetch_add(n, Relaxed);
        Ok(())
    }

    /// Gives back bytes [`reserve`](Self::reserve)d for `kind`.
    pub fn release(&self, kind: Use, n: u64) {
        self.used[kind as usize].fetch_sub(n, Relaxed);
        self.total.fetch_sub(n, Relaxed);
    }

    /// Charges `bytes` for `kind` for as long as the returned guard lives.
    pub fn charge(
        self: &Arc<Self>,
        kind: Use,
        n: u64,
        what: impl FnOnce() -> String,
    ) -> Result<Charge, BudgetError> {
        self.reserve(kind, n, what)?;
        Ok(Charge {
            budget: self.clone(),
            kind,
            bytes: n,
        })
    }

    /// A guard over `n` bytes already [`reserve`](Self::reserve)d for `kind` (by
    /// [`grow`](Self::grow), say), which gives them back when it drops.
    pub fn guard(self: &Arc<Self>, kind: Use, n: u64) -> Charge {
        Charge {
            budget: self.clone(),
            kind,
            bytes: n,
        }
    }

    /// The error for an allocation of `n` bytes the system refused.
    pub fn refused(&self, n: u64, what: &str) -> BudgetError {
        let budget = match self.limit() {
            Some(l) => format!("the memory budget is {}, lower it with --memory", bytes(l)),
            None => "no memory budget is set; set one with --memory".into(),
        };
        BudgetError(format!(
            "could not allocate {} for {what} (the system refused; {budget})",
            bytes(n)
        ))
    }

    /// `n` copies of `value`, charged for `kind` (the guard holds the charge), allocated
    /// without aborting when the system refuses.
    pub fn alloc_vec<T: Clone>(
        self: &Arc<Self>,
        kind: Use,
        n: usize,
        value: T,
        what: impl Fn() -> String,
    ) -> Result<(Vec<T>, Charge), BudgetError> {
        let size = (n as u64).saturating_mul(std::mem::size_of::<T>() as u64);
        let charge = self.charge(kind, size, &what)?;
        let v = try_vec(n, value).ok_or_else(|| self.refused(size, &what()))?;
        Ok((v, charge))
    }

    /// `n` zeros (an image's black), charged for `kind` like [`alloc_vec`](Self::alloc_vec),
    /// from the allocator's zeroed memory: a large block comes as fresh pages the kernel has
    /// already zeroed, so no thread writes the zeros first (a 1024² image is 16 MB).
    pub fn alloc_zeroed_f32(
        self: &Arc<Self>,
        kind: Use,
        n: usize,
        what: impl Fn() -> String,
    ) -> Result<(Vec<f32>, Charge), BudgetError> {
        let size = (n as u64).saturating_mul(std::mem::size_of::<f32>() as u64);
        let charge = self.charge(kind, size, &what)?;
        let v = try_zeroed_f32(n).ok_or_else(|| self.refused(size, &what()))?;
        Ok((v, charge))
    }

    /// Makes room in `v` for `extra` more elements, charging the growth of its capacity for
    /// `kind` for good (doubling, as `Vec` grows, so that many small additions stay cheap).
    pub fn grow<T>(
        &self,
        v: &mut Vec<T>,
        extra: usize,
        kind: Use,
        what: impl Fn() -> String,
    ) -> Result<(), BudgetError> {
        let need = v.len().saturating_add(extra);
        if need <= v.capacity() {
            return Ok(());
        }
        let cap = need.max(v.capacity().saturating_mul(2));
        let size = std::mem::size_of::<T>() as u64;
        let more = (cap - v.capacity()) as u64 * size;
        self.reserve(kind, more, &what)?;
        if v.try_reserve_exact(cap - v.len()).is_err() {
            self.release(kind, more);
            return Err(self.refused(more, &what()));
        }
        Ok(())
    }
}

/// Bytes charged while the guard lives.
#[derive(Debug)]
pub struct Charge {
    budget: Arc<Budget>,
    kind: Use,
    bytes: u64,
}

impl Charge {
    /// The bytes charged.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// The same bytes charged to `budget` instead (this charge given back), unless they are
    /// charged to it already: for what outlives the build whose budget charged it.
    pub fn move_to(
        self,
        budget: &Arc<Budget>,
        what: impl FnOnce() -> String,
    ) -> Result<Charge, BudgetError> {
        if Arc::ptr_eq(&self.budget, budget) {
            return Ok(self);
        }
        let moved = budget.charge(self.kind, self.bytes, what)?;
        drop(self);
        Ok(moved)
    }

    /// Keeps the bytes charged for the life of the budget.
    pub fn keep(mut self) {
        self.bytes = 0;
    }
}

impl Drop for Charge {
    fn drop(&mut self) {
        if self.bytes > 0 {
            self.budget.release(self.kind, self.bytes);
        }
    }
}

/// `n` copies of `value`, or `None` when the system refuses the memory.
pub fn try_vec<T: Clone>(n: usize, value: T) -> Option<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).ok()?;
    v.resize(n, value);
    Some(v)
}

/// `n` zeros from zeroed memory, or `None` when the system refuses it.
#[allow(unsafe_code)]
pub fn try_zeroed_f32(n: usize) -> Option<Vec<f32>> {
    let layout = std::alloc::Layout::array::<f32>(n).ok()?;
    if layout.size() == 0 {
        return Some(Vec::new());
    }
    // SAFETY: the layout's size is not zero (checked above).
    let p = unsafe { std::alloc::alloc_zeroed(layout) }.cast::<f32>();
    if p.is_null() {
        return None;
    }
    // SAFETY: `p` comes from the global allocator with the layout of `n` f32 (capacity `n`,
    // f32's alignment), and all `n` values are initialised: all-zero bits are 0.0.
    Some(unsafe { Vec::from_raw_parts(p, n, n) })
}

/// What the machine allows this process, each figure from its source (`None`: unknown or no
/// limit).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Machine {
    pub mem_total: Option<u64>,
    pub mem_available: Option<u64>,
    pub cgroup: Option<u64>,
    pub rlimit_as: Option<u64>,
    pub rlimit_data: Option<u64>,
}

/// Limits at or above this mean "none" (cgroup v1 writes 2^63 rounded down to a page).
const NO_LIMIT: u64 = 1 << 60;

/// The memory assumed when the machine says nothing.
const UNKNOWN_MACHINE: u64 = 8 << 30;

impl Machine {
    /// The figures of this machine and process.
    pub fn read() -> Machine {
        let (rlimit_as, rlimit_data) = rlimits();
        let mut m = Machine {
            rlimit_as,
            rlimit_data,
            ..Machine::default()
        };
        if let Ok(text) = std::fs::read_to_string("/proc/meminfo") {
            (m.mem_total, m.mem_available) = parse_meminfo(&text);
        } else {
            m.mem_total = physical_memory();
        }
        if let Ok(text) = std::fs::read_to_string("/proc/self/cgroup") {
            m.cgroup = cgroup_limit(&text, Path::new("/sys/fs/cgroup"));
        }
        m
    }

    /// The smallest limit, and what it is ("MemTotal", "cgroup memory limit"...); 8 GiB when
    /// nothing is known.
    pub fn limit(&self) -> (u64, &'static str) {
        [
            (self.mem_total, "MemTotal"),
            (self.cgroup, "cgroup memory limit"),
            (self.rlimit_as, "RLIMIT_AS"),
            (self.rlimit_data, "RLIMIT_DATA"),
        ]
        .into_iter()
        .filter_map(|(n, what)| n.map(|n| (n, what)))
        .min_by_key(|&(n, _)| n)
        .unwrap_or((UNKNOWN_MACHINE, "assumed machine memory (none found)"))
    }

    /// The default budget and its description: 75% of the limit, at most 90% of what was
    /// available at start.
    pub fn default_budget(&self) -> (u64, String) {
        let (limit, what) = self.limit();
        let share = limit / 4 * 3;
        match self.mem_available {
            Some(free) if free / 10 * 9 < share => (
                free / 10 * 9,
                format!("90% of {} MemAvailable", bytes(free)),
            ),
            _ => (share, format!("75% of {} {what}", bytes(limit))),
        }
    }
}

/// `MemTotal` and `MemAvailable` of `/proc/meminfo` text, in bytes.
pub fn parse_meminfo(text: &str) -> (Option<u64>, Option<u64>) {
    let field = |name: &str| {
        text.lines().find_map(|l| {
            let rest = l.strip_prefix(name)?.strip_prefix(':')?;
            let kib: u64 = rest.trim().strip_suffix("kB")?.trim().parse().ok()?;
            kib.checked_mul(1024)
        })
    };
    (field("MemTotal"), field("MemAvailable"))
}

/// A cgroup limit file's value: `None` for `max` and for values that mean no limit.
pub fn parse_limit(text: &str) -> Option<u64> {
    let n: u64 = text.trim().parse().ok()?;
    (n < NO_LIMIT).then_some(n)
}

/// The memory limit of this process's cgroups, from `/proc/self/cgroup` text and the cgroup
/// file system mounted at `root`: the smallest limit from its cgroup up to the root, for
/// cgroup v2 (`0::/path`, `memory.max`) and v1 (the `memory` controller's line,
/// `memory/<path>/memory.limit_in_bytes`, or the hierarchy's root file when the path is not
/// visible, as inside a container).
pub fn cgroup_limit(proc_self_cgroup: &str, root: &Path) -> Option<u64> {
    let mut best: Option<u64> = None;
    let mut take = |n: Option<u64>| {
        if let Some(n) = n {
            best = Some(best.map_or(n, |b| b.min(n)));
        }
    };
    for line in proc_self_cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(id), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        if id == "0" && controllers.is_empty() {
            take(walk_up(root, path, "memory.max"));
        } else if controllers.split(',').any(|c| c == "memory") {
            let v1 = root.join("memory");
            let found = walk_up(&v1, path, "memory.limit_in_bytes");
            take(found.or_else(|| read_limit(&v1.join("memory.limit_in_bytes"))));
        }
    }
    best
}

/// The smallest limit in `file` from `root/path` up to `root` (directories that do not exist
/// are skipped).
fn walk_up(root: &Path, path: &str, file: &str) -> Option<u64> {
    let mut dir = root.join(path.trim_start_matches('/'));
    let mut best: Option<u64> = None;
    loop {
        if let Some(n) = read_limit(&dir.join(file)) {
            best = Some(best.map_or(n, |b| b.min(n)));
        }
        if dir == root || !dir.starts_with(root) || !dir.pop() {
            return best;
        }
    }
}

fn read_limit(file: &Path) -> Option<u64> {
    parse_limit(&std::fs::read_to_string(file).ok()?)
}

/// `RLIMIT_AS` and `RLIMIT_DATA`, when finite.
#[cfg(unix)]
#[allow(unsafe_code)]
fn rlimits() -> (Option<u64>, Option<u64>) {
    let get = |resource| {
        let mut r = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit writes the limit into `r`, a valid rlimit that lives across the
        // call.
        let ok = unsafe { libc::getrlimit(resource, &mut r) } == 0;
        // rlim_t is u64 on Linux, not on every Unix.
        #[allow(clippy::unnecessary_cast)]
        let n = r.rlim_cur as u64;
        (ok && r.rlim_cur != libc::RLIM_INFINITY && n < NO_LIMIT).then_some(n)
    };
    (get(libc::RLIMIT_AS), get(libc::RLIMIT_DATA))
}

#[cfg(not(unix))]
fn rlimits() -> (Option<u64>, Option<u64>) {
    (None, None)
}

/// Physical memory where there is no `/proc/meminfo`.
#[cfg(unix)]
#[allow(unsafe_code)]
fn physical_memory() -> Option<u64> {
    // SAFETY: sysconf only reads a system parameter.
    let (pages, size) = unsafe {
        (
            libc::sysconf(libc::_SC_PHYS_PAGES),
            libc::sysconf(libc::_SC_PAGESIZE),
        )
    };
    (pages > 0 && size > 0).then(|| pages as u64 * size as u64)
}

#[cfg(not(unix))]
fn physical_memory() -> Option<u64> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEMINFO: &str = "MemTotal:       24634284 kB\nMemFree:         1016888 kB\n\
                           MemAvailable:   12000000 kB\nBuffers:          301508 kB\n";

    /// Zeroed vectors hold `n` zeros (small ones from the heap, large ones mmapped); sizes the
    /// system cannot give are `None`, not an abort.
    #[test]
    fn zeroed_vectors_are_zeros_or_refused() {
        for n in [0, 1, 7, 1 << 20] {
            let v = try_zeroed_f32(n).unwrap();
            assert_eq!((v.len(), v.capacity()), (n, n));
            assert!(v.iter().all(|x| x.to_bits() == 0));
        }
        assert!(try_zeroed_f32(usize::MAX / 2).is_none());
        assert!(try_zeroed_f32(1 << 60).is_none());
    }

    #[test]
    fn meminfo_gives_total_and_available_in_bytes() {
        assert_eq!(
            parse_meminfo(MEMINFO),
            (Some(24634284 * 1024), Some(12000000 * 1024))
        );
        assert_eq!(parse_meminfo("MemTotal: 1 kB\n"), (Some(1024), None));
        assert_eq!(parse_meminfo("garbage"), (None, None));
        assert_eq!(
            parse_meminfo("MemTotalX: 5 kB\nMemTotal: x kB"),
            (None, None)
        );
    }

    #[test]
    fn limit_files_say_max_or_a_number() {
        assert_eq!(parse_limit("max\n"), None);
        assert_eq!(parse_limit("1073741824\n"), Some(1 << 30));
        // cgroup v1's "no limit": 2^63 rounded down to a page.
        assert_eq!(parse_limit("9223372036854771712"), None);
        assert_eq!(parse_limit(""), None);
    }

    /// Writes `files` (path, content) under a fresh directory.
    fn fixture(name: &str, files: &[(&str, &str)]) -> std::path::PathBuf {
        let root = std::env::temp_dir().join(format!("luxon-budget-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        for (path, text) in files {
            let p = root.join(path);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }
        root
    }

    #[test]
    fn cgroup_v2_takes_the_smallest_limit_up_to_the_root() {
        let root = fixture(
            "v2",
            &[
                ("memory.max", "max\n"),
                ("user.slice/memory.max", "2147483648\n"),
                ("user.slice/job/memory.max", "max\n"),
            ],
        );
        assert_eq!(cgroup_limit("0::/user.slice/job\n", &root), Some(2 << 30));
        assert_eq!(cgroup_limit("0::/\n", &root), None);
        // A path that is not there: the levels above it still count.
        assert_eq!(
            cgroup_limit("0::/user.slice/gone/deeper\n", &root),
            Some(2 << 30)
        );
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn cgroup_v1_reads_the_memory_controller_or_its_root() {
        let root = fixture(
            "v1",
            &[
                ("memory/memory.limit_in_bytes", "9223372036854771712\n"),
                ("memory/batch/memory.limit_in_bytes", "536870912\n"),
            ],
        );
        let text = "12:cpu,cpuacct:/batch\n4:memory:/batch\n1:name=systemd:/x\n";
        assert_eq!(cgroup_limit(text, &root), Some(512 << 20));
        // Inside a container the path is not visible: the hierarchy's root file counts.
        let _ = std::fs::write(root.join("memory/memory.limit_in_bytes"), "1073741824");
        assert_eq!(
            cgroup_limit("4:memory:/process_api/abc\n", &root),
            Some(1 << 30)
        );
        assert_eq!(cgroup_limit("", &root), None);
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn the_default_is_three_quarters_of_the_smallest_limit_within_what_is_free() {
        let m = Machine {
            mem_total: Some(16 << 30),
            mem_available: Some(15 << 30),
            cgroup: Some(8 << 30),
            rlimit_as: None,
            rlimit_data: None,
        };
        assert_eq!(m.limit(), (8 << 30, "cgroup memory limit"));
        assert_eq!(
            m.default_budget(),
            (6 << 30, "75% of 8 GiB cgroup memory limit".into())
        );
        let busy = Machine {
            mem_available: Some(2 << 30),
            ..m.clone()
        };
        let (n, why) = busy.default_budget();
        assert_eq!(n, (2u64 << 30) / 10 * 9);
        assert_eq!(why, "90% of 2 GiB MemAvailable");
        let limited = Machine {
            rlimit_as: Some(1 << 30),
            ..m
        };
        assert_eq!(limited.limit(), (1 << 30, "RLIMIT_AS"));
        assert_eq!(Machine::default().limit().0, 8 << 30);
    }

    #[test]
    fn charges_fit_or_fail_naming_what_and_guards_give_back() {
        let b = Arc::new(Budget::new(1000, "test".into(), None));
        b.reserve(Use::Geometry, 600, || "geometry".into()).unwrap();
        let held = b.charge(Use::Image, 300, || "the image".into()).unwrap();
        assert_eq!(b.remaining(), 100);
        let e = b
            .reserve(Use::Volumes, 200, || "volume `v`".into())
            .unwrap_err();
        assert_eq!(
            e.0,
            "volume `v` needs 200 bytes more, but the memory budget of 1000 bytes (test) has 100 \
             bytes left (in use: geometry 600 bytes, image 300 bytes); raise it with --memory or \
             `render: (memory: ...)`"
        );
        assert_eq!(b.remaining(), 100, "a refused charge takes nothing");
        drop(held);
        assert_eq!((b.remaining(), b.used(Use::Image)), (400, 0));
        b.charge(Use::Output, 50, String::new).unwrap().keep();
        assert_eq!(b.remaining(), 350);
        assert!(b.reserve(Use::Bvh, u64::MAX, String::new).is_err());
        assert_eq!(b.remaining(), 350);
    }

    #[test]
    fn vectors_grow_by_doubling_within_the_budget() {
        let b = Budget::new(4096, "test".into(), None);
        let mut v: Vec<u32> = Vec::new();
        b.grow(&mut v, 100, Use::Geometry, String::new).unwrap();
        assert_eq!((v.capacity(), b.used(Use::Geometry)), (100, 400));
        v.resize(100, 0);
        b.grow(&mut v, 1, Use::Geometry, String::new).unwrap();
        assert_eq!((v.capacity(), b.used(Use::Geometry)), (200, 800));
        let e = b
            .grow(&mut v, 2000, Use::Geometry, || "object 1".into())
            .unwrap_err();
        assert!(e.0.starts_with("object 1 needs 7.4 KiB more"), "{e}");
        assert_eq!(v.capacity(), 200);
    }

    #[test]
    fn the_texture_cache_is_a_quarter_of_the_budget_at_most_by_default() {
        assert_eq!(
            Budget::new(8 << 30, String::new(), None).texture_cache(),
            1 << 30
        );
        assert_eq!(
            Budget::new(1 << 30, String::new(), None).texture_cache(),
            256 << 20
        );
        let set = Budget::new(1 << 30, String::new(), Some(800 << 20));
        assert_eq!(set.texture_cache(), 800 << 20);
        assert_eq!(Budget::unlimited().texture_cache(), 1 << 30);
        assert_eq!(Budget::unlimited().limit(), None);
    }

    #[test]
    fn the_render_setting_and_the_flag_give_the_limit() {
        let mut r = RenderDesc {
            memory: Some(MemorySize::Bytes(64 << 20)),
            ..RenderDesc::default()
        };
        let b = Budget::for_render(&r, None, 4);
        assert_eq!(b.limit(), Some(64 << 20));
        assert_eq!(
            b.describe(),
            "64 MiB (from the scene's `render: (memory: ...)`)"
        );
        let b = Budget::for_render(&r, Some(MemorySize::Bytes(1 << 30)), 1);
        assert_eq!(b.describe(), "1 GiB (from --memory)");
        r.memory = Some(MemorySize::Percent(50.0));
        let (total, _) = Machine::read().limit();
        let b = Budget::for_render(&r, None, 2);
        assert_eq!(b.limit(), Some((total as f64 * 0.5) as u64 / 2));
        assert!(b.describe().ends_with(", shared by 2 ranks on this node)"));
    }
}

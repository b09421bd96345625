//! The texture cache: demand loading, lock-free hits, LRU eviction under a memory budget.
//!
//! Every image texture of the library goes through one [`Cache`] (a static in the plugin,
//! [`global`]); instances naming the same file (same resolved path, modification time and
//! `srgb`) share one [`CachedImage`]. The unit of caching is one MIP level of one image.
//!
//! **Hits.** A level lives behind an `AtomicPtr` (an `Arc<Level>` turned into a raw pointer).
//! A lookup announces itself on one of the image's reader counters (one per group of threads,
//! each on its own cache line), loads the pointers of the one or two levels it needs, samples
//! them and leaves. No mutex, no reference-count traffic, no waiting: readers never block.
//!
//! **Misses.** A missing level (never loaded, or evicted) is filled under the image's own load
//! mutex, so two threads never decode the same file at once while other images keep being
//! read: the file is decoded, its MIP pyramid built from the plan's first level on (`decode.rs`:
//! an image larger than the decode cap is used at a smaller size; a texture that reads only
//! the first level, nearest or bilinear, gets an entry of that level alone), and every level
//! not already resident is installed — the wanted ones marked as just used, the others as
//! never used, so they are the first to go. The missing thread samples through `Arc`s it
//! holds itself, so it makes progress even if its levels are evicted again at once.
//!
//! **Eviction.** After each install, while the resident texel bytes exceed the budget (each
//! level counted as float texels, 16 bytes each, also an 8-bit level 0 that holds 4: the count
//! is known before the file is read, and errs on the safe side), the least recently used
//! level (ties: the largest) is evicted: its pointer is swapped to null,
//! then the evicting thread waits until each of the image's reader counters has been seen at
//! zero (readers that saw the old pointer have finished; new ones see null and take the miss
//! path), and frees it. Recency is a clock that advances on every miss; a hit stamps its
//! levels with the current value (a relaxed store, only when the stamp is stale), so recency
//! is resolved to the interval between two misses, and a level used since the last miss is
//! newer than the levels that miss installed. The levels
//! a lookup is about to use are never evicted by that lookup, so an image larger than the
//! whole budget still renders: the cache then holds just the levels in use.
//!
//! **Pinning.** While the images pinned so far stay within an eighth of the budget, a newly
//! decoded image's levels are pinned: never evicted, freed only with the image. A lookup
//! whose levels are both pinned reads them without announcing itself (no locked
//! instruction). Pinned bytes count toward the budget like any others; the unpinned levels
//! are evicted to fit.
//!
//! **Thrashing.** When an image has to be decoded a second time (its data was evicted and is
//! needed again), the cache logs once, with the budget and the size of all registered texture
//! data. A decode failure is kept with the image: every lookup then fails with its message
//! (the texture's `try_eval` hands it to the host, which stops the render with it).

use crate::decode::{decode, size, Header, Plan};
use crate::mipmap::{level_sizes, Level};
use std::path::{Path, PathBuf};
use std::ptr;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU64, AtomicUsize, Ordering::*};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock, PoisonError};
use std::time::SystemTime;

/// The budget when the render settings give none (0): 1 GiB.
pub const DEFAULT_BUDGET: u64 = 1 << 30;

/// Reader counters per image; threads are spread over them by where their stacks lie.
const STRIPES: usize = 16;

/// Images are pinned while the pinned bytes stay within this fraction of the budget (1/8).
const PINNED_SHARE: u64 = 8;

/// Where log messages go: `(level, message)`, level 0 error, 1 warning.
pub type Log = Box<dyn Fn(u32, &str) + Send + Sync>;

#[repr(align(64))]
#[derive(Default)]
struct Stripe(AtomicUsize);

/// This thread's reader counter index, from the address of its stack: threads' stacks lie at
/// least a megabyte apart, so they mostly differ in the bits above 2^20. Any index is correct
/// (a guard leaves the counter it entered); distinct ones only spare the threads contention.
/// A thread-local index costs a `__tls_get_addr` call per lookup in a plugin library.
#[inline(always)]
fn stripe() -> usize {
    let marker = 0u8;
    let a = std::ptr::addr_of!(marker) as usize;
    ((a >> 20) ^ (a >> 24)) % STRIPES
}

/// One MIP level of one image.
struct Slot {
    /// `Arc::into_raw` of the level, or null when not resident.
    data: AtomicPtr<Level>,
    /// Clock value of the last use (0: never used).
    stamp: AtomicU64,
    /// Size of the level's texels.
    bytes: u64,
    /// Never evicted: set after `data` on install, cleared only when the image is freed.
    /// A lookup of pinned levels needs no reader counter (whose two locked instructions held
    /// about 2 % of Tachyon's fog scene's samples: its maps are read in every other sample).
    pinned: AtomicBool,
}

impl Slot {
    /// A counted reference to the resident level. The caller holds the cache's state lock,
    /// under which nothing is freed.
    fn get(&self, _locked: &State) -> Option<Arc<Level>> {
        let p = self.data.load(SeqCst);
        if p.is_null() {
            return None;
        }
        // SAFETY: `p` came from `Arc::into_raw` and is only released under the state lock,
        // which the caller holds; the count we add keeps it alive after the lock is dropped.
        unsafe {
            Arc::increment_strong_count(p);
            Some(Arc::from_raw(p))
        }
    }
}

/// An image known to the cache: where its texels come from and where they are when resident.
pub struct CachedImage {
    path: PathBuf,
    modified: Option<SystemTime>,
    srgb: bool,
    header: Header,
    /// From which MIP level of the file on the image is decoded: its level 0 is that one.
    plan: Plan,
    /// Size of the image as used (the plan's first level).
    size: (usize, usize),
    slots: Box<[Slot]>,
    readers: [Stripe; STRIPES],
    /// Held while decoding and installing this image.
    loading: Mutex<()>,
    /// Why the decode failed; lookups fail with it without trying again.
    failed: OnceLock<String>,
    /// How many times the file was decoded.
    decodes: AtomicU64,
}

/// Leaves the reader counter on drop (also when sampling panics).
struct ReadGuard<'a>(&'a AtomicUsize);

impl Drop for ReadGuard<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Release);
    }
}

impl CachedImage {
    /// Width of the image as used (smaller than the file's when its plan skips levels).
    pub fn width(&self) -> usize {
        self.size.0
    }

    pub fn height(&self) -> usize {
        self.size.1
    }

    pub fn levels(&self) -> usize {
        self.slots.len()
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes of the whole pyramid.
    pub fn bytes(&self) -> u64 {
        self.slots.iter().map(|s| s.bytes).sum()
    }

    /// Bytes of the pinned levels.
    fn pinned_bytes(&self) -> u64 {
        let pinned = self.slots.iter().filter(|s| s.pinned.load(Relaxed));
        pinned.map(|s| s.bytes).sum()
    }

    /// Whether level `i` is pinned (for tests).
    pub fn is_pinned(&self, i: usize) -> bool {
        self.slots[i].pinned.load(Relaxed)
    }

    /// Whether level `i` is resident now (for tests and statistics).
    pub fn is_resident(&self, i: usize) -> bool {
        !self.slots[i].data.load(SeqCst).is_null()
    }

    fn enter(&self) -> ReadGuard<'_> {
        let counter = &self.readers[stripe()].0;
        // SeqCst on both sides (this increment then the pointer loads; the evictor's swap then
        // its counter loads): a reader that saw the old pointer is seen by the evictor.
        counter.fetch_add(1, SeqCst);
        ReadGuard(counter)
    }

    /// Waits until every reader that may have seen a pointer swapped out before this call has
    /// left: each counter seen at zero once suffices (later readers see the new pointer).
    fn drain(&self) {
        for s in &self.readers {
            while s.0.load(SeqCst) != 0 {
                std::thread::yield_now();
            }
        }
    }

    /// Frees every resident level; returns the bytes freed. Only with no readers possible.
    fn free_all(&self) -> u64 {
        let mut freed = 0;
        for slot in self.slots.iter() {
            slot.pinned.store(false, Relaxed);
            let p = slot.data.swap(ptr::null_mut(), SeqCst);
            if !p.is_null() {
                // SAFETY: from `Arc::into_raw`; swapped out, so released exactly once; and no
                // lookup can be reading it: `free_all` runs only when none can run on this image
                // (on drop, or when `release` drops its last instance).
                drop(unsafe { Arc::from_raw(p) });
                freed += slot.bytes;
            }
        }
        freed
    }
}

impl Drop for CachedImage {
    fn drop(&mut self) {
        self.free_all();
    }
}

struct State {
    images: Vec<Arc<CachedImage>>,
    /// Bytes of resident levels.
    resident: u64,
    /// Bytes of the pinned ones among them.
    pinned: u64,
}

/// Counters, for tests and messages.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    pub resident: u64,
    /// Bytes of pinned levels (among `resident`).
    pub pinned: u64,
    pub decodes: u64,
    pub evictions: u64,
    pub images: usize,
}

pub struct Cache {
    state: Mutex<State>,
    budget: AtomicU64,
    /// The LRU clock: advances on every miss.
    clock: AtomicU64,
    log: Log,
    thrash_logged: AtomicBool,
    decodes: AtomicU64,
    evictions: AtomicU64,
}

/// The library's cache, shared by every image texture; logs through the host.
pub fn global() -> Arc<Cache> {
    static GLOBAL: OnceLock<Arc<Cache>> = OnceLock::new();
    GLOBAL
        .get_or_init(|| {
            Arc::new(Cache::new(
                DEFAULT_BUDGET,
                Box::new(|level, m| luxon_plugin::host_log("luxon-textures", level, m)),
            ))
        })
        .clone()
}

impl Cache {
    pub fn new(budget: u64, log: Log) -> Cache {
        Cache {
            state: Mutex::new(State {
                images: Vec::new(),
                resident: 0,
                pinned: 0,
            }),
            budget: AtomicU64::new(if budget == 0 { DEFAULT_BUDGET } else { budget }),
            clock: AtomicU64::new(1),
            log,
            thrash_logged: AtomicBool::new(false),
            decodes: AtomicU64::new(0),
            evictions: AtomicU64::new(0),
        }
    }

    /// The render settings' budget; 0 selects [`DEFAULT_BUDGET`]. The latest call wins.
    pub fn set_budget(&self, bytes: u64) {
        let b = if bytes == 0 { DEFAULT_BUDGET } else { bytes };
        self.budget.store(b, Relaxed);
    }

    pub fn budget(&self) -> u64 {
        self.budget.load(Relaxed)
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic while holding the lock leaves the state consistent (every update is a
        // single step), so poisoning is ignored.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    pub fn stats(&self) -> Stats {
        let st = self.lock();
        Stats {
            resident: st.resident,
            pinned: st.pinned,
            decodes: self.decodes.load(Relaxed),
            evictions: self.evictions.load(Relaxed),
            images: st.images.len(),
        }
    }

    /// The shared entry for an image file whose header was read and plan made at create time.
    /// Nothing is decoded until the first lookup. A new entry for an image used below its full
    /// size logs the plan's warning.
    pub fn register(
        &self,
        path: &Path,
        header: Header,
        srgb: bool,
        plan: Plan,
    ) -> Arc<CachedImage> {
        let given = path;
        let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let modified = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
        let mut st = self.lock();
        if let Some(img) = st.images.iter().find(|i| {
            i.path == path
                && i.srgb == srgb
                && i.header == header
                && i.modified == modified
                && i.plan.first_level == plan.first_level
                // An entry with MIP levels serves a texture that reads only the first.
                && (i.plan.mip || !plan.mip)
        }) {
            return img.clone();
        }
        if let Some(warning) = plan.warning(&given.display().to_string(), &header) {
            (self.log)(1, &warning);
        }
        let size = plan.size(&header);
        let levels = if plan.mip {
            level_sizes(size.0, size.1).len()
        } else {
            1
        };
        let slots = level_sizes(size.0, size.1)
            .into_iter()
            .take(levels)
            .map(|(w, h)| Slot {
                data: AtomicPtr::new(ptr::null_mut()),
                stamp: AtomicU64::new(0),
                bytes: (w * h * std::mem::size_of::<[f32; 4]>()) as u64,
                pinned: AtomicBool::new(false),
            })
            .collect();
        let img = Arc::new(CachedImage {
            path,
            modified,
            srgb,
            header,
            plan,
            size,
            slots,
            readers: Default::default(),
            loading: Mutex::new(()),
            failed: OnceLock::new(),
            decodes: AtomicU64::new(0),
        });
        st.images.push(img.clone());
        img
    }

    /// Called when an instance holding `img` goes away: the last one frees its levels.
    pub fn release(&self, img: &Arc<CachedImage>) {
        let mut st = self.lock();
        // Only `register` (under this lock) hands out new references: the registry's and the
        // caller's being the last two is a stable fact here.
        if Arc::strong_count(img) == 2 {
            st.images.retain(|i| !Arc::ptr_eq(i, img));
            st.pinned -= img.pinned_bytes();
            let freed = img.free_all();
            st.resident -= freed;
        }
    }

    fn touch(&self, slot: &Slot) {
        let now = self.clock.load(Relaxed);
        if slot.stamp.load(Relaxed) != now {
            slot.stamp.store(now, Relaxed);
        }
    }

    /// Runs `f` on levels `a` and `b` of `img` (equal indices allowed), loading them first when
    /// they are not resident. The error says why the image cannot be decoded.
    pub fn with_levels<R>(
        &self,
        img: &CachedImage,
        a: usize,
        b: usize,
        f: impl FnOnce(&Level, &Level) -> R,
    ) -> Result<R, String> {
        let (sa, sb) = (&img.slots[a], &img.slots[b]);
        if sa.pinned.load(Acquire) && sb.pinned.load(Acquire) {
            let (pa, pb) = (sa.data.load(Relaxed), sb.data.load(Relaxed));
            debug_assert!(!pa.is_null() && !pb.is_null());
            // SAFETY: a pinned slot's pointer was stored before its flag (whose release the
            // loads above acquired) and is neither evicted nor freed while a lookup can run.
            return Ok(f(unsafe { &*pa }, unsafe { &*pb }));
        }
        {
            let _reading = img.enter();
            let pa = img.slots[a].data.load(SeqCst);
            let pb = img.slots[b].data.load(SeqCst);
            if !pa.is_null() && !pb.is_null() {
                self.touch(&img.slots[a]);
                self.touch(&img.slots[b]);
                // SAFETY: non-null pointers from `Arc::into_raw`; an evictor that swaps them out
                // waits for our reader counter to drop before freeing them.
                return Ok(f(unsafe { &*pa }, unsafe { &*pb }));
            }
        }
        // Miss: no reader counter held from here on (the loader may wait for readers).
        if let Some(e) = img.failed.get() {
            return Err(e.clone());
        }
        let (la, lb) = self.load(img, a, b)?;
        Ok(f(&la, &lb))
    }

    /// [`Self::with_levels`] of one level (`a == b`): one pointer to check and stamp.
    #[inline]
    pub fn with_level<R>(
        &self,
        img: &CachedImage,
        a: usize,
        f: impl FnOnce(&Level) -> R,
    ) -> Result<R, String> {
        let slot = &img.slots[a];
        if slot.pinned.load(Acquire) {
            let pa = slot.data.load(Relaxed);
            debug_assert!(!pa.is_null());
            // SAFETY: as in `with_levels`.
            return Ok(f(unsafe { &*pa }));
        }
        {
            let _reading = img.enter();
            let pa = slot.data.load(SeqCst);
            if !pa.is_null() {
                self.touch(slot);
                // SAFETY: as in `with_levels`.
                return Ok(f(unsafe { &*pa }));
            }
        }
        self.with_levels(img, a, a, |l, _| f(l))
    }

    fn load(
        &self,
        img: &CachedImage,
        a: usize,
        b: usize,
    ) -> Result<(Arc<Level>, Arc<Level>), String> {
        let _loading = img.loading.lock().unwrap_or_else(PoisonError::into_inner);
        {
            // Another thread may have loaded them while we waited.
            let st = self.lock();
            if let (Some(la), Some(lb)) = (img.slots[a].get(&st), img.slots[b].get(&st)) {
                self.touch(&img.slots[a]);
                self.touch(&img.slots[b]);
                return Ok((la, lb));
            }
        }
        if let Some(e) = img.failed.get() {
            return Err(e.clone());
        }
        let decoded = decode(&img.path, &img.header, img.srgb, &img.plan).and_then(|levels| {
            if levels.len() == img.slots.len() {
                Ok(levels)
            } else {
                Err(format!(
                    "{} MIP levels decoded, {} expected",
                    levels.len(),
                    img.slots.len()
                ))
            }
        });
        let levels = match decoded {
            Ok(levels) => levels,
            Err(e) => {
                let e = format!("cannot decode image `{}`: {e}", img.path.display());
                return Err(img.failed.get_or_init(|| e).clone());
            }
        };
        self.decodes.fetch_add(1, Relaxed);
        let again = img.decodes.fetch_add(1, Relaxed) > 0;

        let mut st = self.lock();
        // Installed levels get `now`; hits from here on stamp `now + 1`, i.e. newer.
        let now = self.clock.fetch_add(2, Relaxed) + 1;
        let (mut out_a, mut out_b) = (None, None);
        // An image is pinned whole or not at all (a lookup reads two of its levels).
        let unpinned = img.bytes() - img.pinned_bytes();
        let pin = st.pinned + unpinned <= self.budget() / PINNED_SHARE;
        for (i, level) in levels.into_iter().enumerate() {
            let slot = &img.slots[i];
            let wanted = i == a || i == b;
            let arc = match slot.get(&st) {
                Some(resident) => resident,
                None => {
                    let arc = Arc::new(level);
                    slot.stamp.store(if wanted { now } else { 0 }, Relaxed);
                    slot.data
                        .store(Arc::into_raw(arc.clone()) as *mut Level, SeqCst);
                    st.resident += slot.bytes;
                    if pin {
                        st.pinned += slot.bytes;
                        // After the pointer: a lookup that sees the flag sees the level.
                        slot.pinned.store(true, Release);
                    }
                    arc
                }
            };
            if wanted {
                slot.stamp.store(now, Relaxed);
            }
            if i == a {
                out_a = Some(arc.clone());
            }
            if i == b {
                out_b = Some(arc);
            }
        }
        self.evict(&mut st, img, a, b);
        if again && !self.thrash_logged.swap(true, Relaxed) {
            let data: u64 = st.images.iter().map(|i| i.bytes()).sum();
            (self.log)(
                1,
                &format!(
                    "the texture cache is thrashing: the scene's image textures need {} \
                     (with their MIP levels) but the cache budget is {}; images are evicted \
                     and decoded again (`{}` just now), which is slow. Raise the budget with \
                     the render setting `texture_cache` (e.g. `render: (texture_cache: \"2 GiB\")`).",
                    size(data),
                    size(self.budget()),
                    img.path.display()
                ),
            );
        }
        match (out_a, out_b) {
            (Some(la), Some(lb)) => Ok((la, lb)),
            _ => Err(format!(
                "MIP level {a} or {b} of `{}` is missing after decoding",
                img.path.display()
            )),
        }
    }

    /// Evicts least recently used levels until the resident bytes fit the budget, sparing
    /// levels `a` and `b` of `keep`.
    fn evict(&self, st: &mut State, keep: &CachedImage, a: usize, b: usize) {
        let budget = self.budget();
        while st.resident > budget {
            let mut victim: Option<(usize, usize, (u64, std::cmp::Reverse<u64>))> = None;
            for (n, img) in st.images.iter().enumerate() {
                for (i, slot) in img.slots.iter().enumerate() {
                    if slot.data.load(SeqCst).is_null()
                        || slot.pinned.load(Relaxed)
                        || (ptr::eq(&**img, keep) && (i == a || i == b))
                    {
                        continue;
                    }
                    let key = (slot.stamp.load(Relaxed), std::cmp::Reverse(slot.bytes));
                    if victim.is_none_or(|(_, _, k)| key < k) {
                        victim = Some((n, i, key));
                    }
                }
            }
            let Some((n, i, _)) = victim else { break };
            let img = &st.images[n];
            let slot = &img.slots[i];
            let p = slot.data.swap(ptr::null_mut(), SeqCst);
            img.drain();
            // SAFETY: from `Arc::into_raw`, swapped out above (so released once), and every
            // reader that could have seen it has left.
            drop(unsafe { Arc::from_raw(p) });
            st.resident -= slot.bytes;
            self.evictions.fetch_add(1, Relaxed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::probe;
    use crate::testutil::{write_png, TempDir};

    /// Every level: the decode cap is not what these tests are about.
    const FULL: Plan = Plan {
        first_level: 0,
        cap: u64::MAX,
        mip: true,
    };

    /// Messages a test cache logged: (level, text).
    type Seen = Arc<Mutex<Vec<(u32, String)>>>;

    fn recorder() -> (Log, Seen) {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let s = seen.clone();
        (
            Box::new(move |l, m| s.lock().unwrap().push((l, m.to_string()))),
            seen,
        )
    }

    /// An 8×8 image filled with one grey level `v` (in 0..=255).
    fn flat(dir: &TempDir, name: &str, v: u8) -> PathBuf {
        let p = dir.path(name);
        write_png(&p, 8, 8, |_, _| [v, v, v, 255]);
        p
    }

    fn level0(cache: &Cache, img: &CachedImage) -> Result<f32, String> {
        cache.with_levels(img, 0, 0, |l, _| l.texels()[0][0])
    }

    #[test]
    fn demand_loading_shares_and_frees() {
        let dir = TempDir::new("cache-share");
        let p = flat(&dir, "a.png", 255);
        let (log, _) = recorder();
        let cache = Cache::new(0, log);
        let h = probe(&p).unwrap();
        let img = cache.register(&p, h, true, FULL);
        let same = cache.register(&dir.path("./a.png"), h, true, FULL);
        assert!(Arc::ptr_eq(&img, &same), "one entry per file");
        let linear = cache.register(&p, h, false, FULL);
        assert!(!Arc::ptr_eq(&img, &linear), "srgb is part of the key");
        // Nothing decoded at registration.
        assert_eq!(cache.stats().decodes, 0);
        assert!(!img.is_resident(0));
        assert_eq!(level0(&cache, &img), Ok(1.0));
        assert_eq!(cache.stats().decodes, 1);
        // The whole pyramid (8, 4, 2, 1) is resident: 85 texels of 16 bytes.
        assert_eq!(img.levels(), 4);
        assert!((0..4).all(|i| img.is_resident(i)));
        assert_eq!(cache.stats().resident, 85 * 16);
        assert_eq!(level0(&cache, &img), Ok(1.0));
        assert_eq!(cache.stats().decodes, 1, "a hit decodes nothing");
        cache.release(&same);
        drop(same);
        assert_eq!(cache.stats().resident, 85 * 16, "still used by `img`");
        cache.release(&img);
        drop(img);
        assert_eq!(cache.stats().resident, 0);
        assert_eq!(cache.stats().images, 1, "the linear entry remains");
    }

    #[test]
    fn tiny_budget_evicts_reloads_and_logs_thrashing_once() {
        let dir = TempDir::new("cache-tiny");
        let (log, seen) = recorder();
        // Room for one 8×8 level (1024 bytes) and a bit: never two images' level 0 at once.
        let cache = Cache::new(1500, log);
        let imgs: Vec<_> = [0u8, 255, 188]
            .iter()
            .map(|&v| {
                let want = crate::decode::srgb_to_linear(v as f32 / 255.0);
                let p = flat(&dir, &format!("g{v}.png"), v);
                (cache.register(&p, probe(&p).unwrap(), true, FULL), want)
            })
            .collect();
        for round in 0..4 {
            for (img, want) in &imgs {
                let got = level0(&cache, img).unwrap();
                assert_eq!(got, *want, "round {round}: ");
                let s = cache.stats();
                assert!(s.resident <= 1500, "{s:?}");
            }
        }
        let s = cache.stats();
        assert!(s.evictions > 0, "{s:?}");
        assert_eq!(
            s.decodes, 12,
            "every lookup evicted the previous image: {s:?}"
        );
        let seen = seen.lock().unwrap();
        let thrash: Vec<_> = seen
            .iter()
            .filter(|(_, m)| m.contains("thrashing"))
            .collect();
        assert_eq!(thrash.len(), 1, "{seen:?}");
        assert_eq!(thrash[0].0, 1, "a warning");
        assert!(thrash[0].1.contains("budget is 1.5 KiB"), "{}", thrash[0].1);
        // 3 images × 85 texels × 16 bytes = 4080 bytes.
        assert!(thrash[0].1.contains("need 4.0 KiB"), "{}", thrash[0].1);
    }

    #[test]
    fn an_image_larger_than_the_budget_still_renders() {
        let dir = TempDir::new("cache-huge");
        let p = flat(&dir, "big.png", 255);
        let (log, _) = recorder();
        let cache = Cache::new(100, log);
        let img = cache.register(&p, probe(&p).unwrap(), true, FULL);
        assert_eq!(level0(&cache, &img), Ok(1.0));
        // Only the level in use stays (it alone exceeds the budget).
        assert!(img.is_resident(0));
        assert!(!img.is_resident(1) && !img.is_resident(3));
        assert_eq!(cache.stats().resident, 1024);
        // Trilinear between levels 2 and 3: both kept, level 0 evicted.
        let v = cache
            .with_levels(&img, 2, 3, |a, b| (a.width, b.width))
            .unwrap();
        assert_eq!(v, (2, 1));
        assert!(!img.is_resident(0) && img.is_resident(2) && img.is_resident(3));
    }

    #[test]
    fn small_images_are_pinned_within_an_eighth_of_the_budget() {
        let dir = TempDir::new("cache-pinned");
        let (a, b) = (flat(&dir, "a.png", 255), flat(&dir, "b.png", 0));
        let (log, _) = recorder();
        // An eighth is 1500 bytes: room for one pyramid of 1360 bytes, not two.
        let cache = Cache::new(12_000, log);
        let ia = cache.register(&a, probe(&a).unwrap(), true, FULL);
        let ib = cache.register(&b, probe(&b).unwrap(), true, FULL);
        assert_eq!(level0(&cache, &ia), Ok(1.0));
        assert!((0..4).all(|i| ia.is_pinned(i)));
        assert_eq!(cache.stats().pinned, 1360);
        assert_eq!(level0(&cache, &ib), Ok(0.0));
        assert!((0..4).all(|i| !ib.is_pinned(i)));
        assert_eq!(cache.stats().pinned, 1360);
        // Pinned levels read as any other (no reader counter: not observable but by speed).
        let v = cache.with_levels(&ia, 1, 3, |l, m| (l.texels()[0][0], m.width));
        assert_eq!(v, Ok((1.0, 1)));
        // A budget too small for the rest evicts unpinned levels only.
        cache.set_budget(1500);
        let c = flat(&dir, "c.png", 128);
        let ic = cache.register(&c, probe(&c).unwrap(), true, FULL);
        level0(&cache, &ic).unwrap();
        assert!((0..4).all(|i| ia.is_resident(i)));
        assert!((0..4).all(|i| !ib.is_resident(i)));
        assert!(cache.stats().evictions > 0);
        // Releasing the image unpins and frees its levels.
        cache.release(&ia);
        drop(ia);
        assert_eq!(cache.stats().pinned, 0);
        assert!(cache.stats().resident <= 1500);
    }

    #[test]
    fn an_entry_without_mip_levels_holds_one_and_is_shared_only_downward() {
        let dir = TempDir::new("cache-no-mip");
        let p = flat(&dir, "a.png", 255);
        let (log, _) = recorder();
        let cache = Cache::new(0, log);
        let h = probe(&p).unwrap();
        let single = Plan { mip: false, ..FULL };
        let first = cache.register(&p, h, true, single);
        assert_eq!((first.levels(), first.bytes()), (1, 64 * 16));
        // A MIP texture needs an entry of its own...
        let mip = cache.register(&p, h, true, FULL);
        assert!(!Arc::ptr_eq(&first, &mip));
        assert_eq!(mip.levels(), 4);
        assert_eq!(level0(&cache, &first), Ok(1.0));
        assert_eq!(cache.stats().resident, 64 * 16);
        assert_eq!(level0(&cache, &mip), Ok(1.0));
        // ...while a plain texture can use a MIP entry's first level.
        let q = flat(&dir, "b.png", 0);
        let hq = probe(&q).unwrap();
        let mip = cache.register(&q, hq, true, FULL);
        assert!(Arc::ptr_eq(&cache.register(&q, hq, true, single), &mip));
    }

    #[test]
    fn lru_keeps_recently_used_levels() {
        let dir = TempDir::new("cache-lru");
        let (log, seen) = recorder();
        // Two 8×8 images fit (2 × 1024 bytes + small levels), not three.
        let cache = Cache::new(2 * 1024 + 300, log);
        let mk = |n: &str, v| {
            let p = flat(&dir, n, v);
            cache.register(&p, probe(&p).unwrap(), true, FULL)
        };
        let (a, b, c) = (mk("a.png", 10), mk("b.png", 20), mk("c.png", 30));
        level0(&cache, &a).unwrap();
        level0(&cache, &b).unwrap();
        level0(&cache, &a).unwrap(); // a is now more recent than b
        level0(&cache, &c).unwrap(); // evicts b's level 0, not a's
        assert!(a.is_resident(0) && c.is_resident(0), "{:?}", cache.stats());
        assert!(!b.is_resident(0));
        assert_eq!(cache.stats().decodes, 3);
        assert!(seen.lock().unwrap().is_empty(), "no reload yet, no message");
    }

    #[test]
    fn a_decode_failure_is_kept_and_every_lookup_fails_with_it() {
        let dir = TempDir::new("cache-broken");
        let p = flat(&dir, "broken.png", 128);
        let h = probe(&p).unwrap();
        // Keep the header (so create-time checks pass), drop the pixel data.
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(&p, &bytes[..40]).unwrap();
        let (log, seen) = recorder();
        let cache = Cache::new(0, log);
        let img = cache.register(&p, h, true, FULL);
        let e = level0(&cache, &img).unwrap_err();
        assert!(
            e.starts_with("cannot decode image `") && e.contains("broken.png`: "),
            "{e}"
        );
        // The file is not decoded again: even a good file there now fails the same way.
        flat(&dir, "broken.png", 128);
        for _ in 0..3 {
            assert_eq!(level0(&cache, &img), Err(e.clone()));
        }
        assert_eq!(cache.stats().decodes, 0);
        // The message travels with the lookups; nothing is logged.
        assert!(seen.lock().unwrap().is_empty());
    }

    #[test]
    fn concurrent_misses_and_hits_under_pressure() {
        let dir = TempDir::new("cache-threads");
        let (log, _) = recorder();
        let cache = Cache::new(3000, log);
        let imgs: Vec<_> = (0..4u8)
            .map(|k| {
                let v = 40 + 50 * k;
                let p = flat(&dir, &format!("t{k}.png"), v);
                (
                    cache.register(&p, probe(&p).unwrap(), false, FULL),
                    v as f32 / 255.0,
                )
            })
            .collect();
        std::thread::scope(|s| {
            for t in 0..4 {
                let (cache, imgs) = (&cache, &imgs);
                s.spawn(move || {
                    for i in 0..300 {
                        let (img, want) = &imgs[(i * (t + 1) + t) % 4];
                        let lv = (i + t) % 4;
                        let got = cache
                            .with_levels(img, lv, (lv + 1).min(3), |a, b| {
                                (a.texels()[0][1], b.texels()[0][2])
                            })
                            .unwrap();
                        assert_eq!(got, (*want, *want));
                    }
                });
            }
        });
        assert!(cache.stats().resident <= 3000 + 2 * 1024);
    }
}

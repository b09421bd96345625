//! Arrays Luxon reads in place: a simulation hands over its positions, radii or indices (in its
//! own layout: strided, unaligned, f32 or f64) and Luxon reads them where they are, or keeps a
//! packed copy of them, read by the same code.
//!
//! - An [`Array`] is a typed ([`Elem`]) strided sequence over a [`Source`], which owns the
//!   memory: Luxon's own vector ([`Array::copy`], [`Array::from_vec`]), a vector it shares with
//!   the caller ([`SharedVec`], whole through [`Array::shared`] or one field of a vector of
//!   structs through [`Array::field`]), or memory the caller keeps ([`Array::external`], for the
//!   C and Python layers).
//! - [`Array::pin`] holds the memory still for as long as the [`Pinned`] lives (a commit or a
//!   render), and gives [`View`]s: what geometry reads in its inner loops, every read checked
//!   against the length (past it, a read is `None`), unaligned, f32 widened to f64.
//! - Every source has a *generation* that changes whenever its content may have changed, so a
//!   commit knows what to read again.
//!
//! # Ownership rules
//!
//! 1. **Shared arrays are read in place** from the first commit or render that uses them until
//!    the last object using them is released, changed to another array, or its scene released;
//!    then the owner is dropped (a C deleter runs, a Python reference is released) on a thread
//!    that called Luxon, after the last read. Until then the memory must stay valid.
//! 2. **Do not write an array while a commit or render that uses it runs**, on any thread.
//!    [`SharedVec`] enforces this: [`SharedVec::write`] waits until no pin is held, and pins
//!    wait for a write guard to drop (so never render from a thread that holds one: the pin
//!    refuses). C and Python callers must keep the rule themselves.
//! 3. **After writing** between renders, mark the array modified ([`Array::mark_modified`];
//!    `luxon_array_mark_modified` in C). A [`SharedWrite`] guard does it when it drops. A
//!    forgotten mark shows stale geometry (bounds of old positions, so parts may be missed),
//!    never a read outside the array.
//! 4. **Copies** ([`Array::copy`]) are made at creation and changed by [`Array::update`]; the
//!    caller's memory may be reused as soon as the call returns.
//! 5. **Element data need no alignment**; counts, strides and the byte span are checked when the
//!    array is made. NaN or infinite coordinates, non-positive radii and out-of-range indices
//!    are errors of the commit that reads them, naming the object and element.
//! 6. **Volumes are copied into bricks** at commit: their arrays may change once that commit
//!    has returned (mark them modified to have them read again).
//!
//! Pins are reader locks that never wait for a waiting writer, so one thread may pin the same
//! vector twice (two fields of one vector of structs, say) while a writer waits; a writer waits
//! until all pins are gone.

use crate::error::Error;
use crate::math::DVec3;
use std::any::Any;
use std::marker::PhantomData;
use std::mem::size_of;
use std::ops::{Deref, DerefMut};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::RwLockWriteGuard;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError, RwLock, RwLockReadGuard};
use std::thread::ThreadId;

/// The type of an array's elements, as stored in memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Elem {
    F32,
    F64,
    U8,
    U16,
    U32,
    U64,
    F32x2,
    F32x3,
    F64x3,
    U32x3,
    U64x3,
}

impl Elem {
    /// Bytes per element.
    pub const fn size(self) -> usize {
        match self {
            Elem::U8 => 1,
            Elem::U16 => 2,
            Elem::F32 | Elem::U32 => 4,
            Elem::F64 | Elem::U64 | Elem::F32x2 => 8,
            Elem::F32x3 | Elem::U32x3 => 12,
            Elem::F64x3 | Elem::U64x3 => 24,
        }
    }

    pub const fn name(self) -> &'static str {
        match self {
            Elem::F32 => "f32",
            Elem::F64 => "f64",
            Elem::U8 => "u8",
            Elem::U16 => "u16",
            Elem::U32 => "u32",
            Elem::U64 => "u64",
            Elem::F32x2 => "f32x2",
            Elem::F32x3 => "f32x3",
            Elem::F64x3 => "f64x3",
            Elem::U32x3 => "u32x3",
            Elem::U64x3 => "u64x3",
        }
    }
}

impl std::fmt::Display for Elem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

mod sealed {
    pub trait Element {}
    pub trait Source {
        fn as_any(&self) -> &dyn std::any::Any;
    }
}

/// A Rust type an array's elements can have: plain numbers and vectors of them, whose bytes are
/// all initialised and for which every bit pattern is a value (so reading one from memory is
/// always sound). Sealed: the list below is complete.
pub trait Element: Copy + Send + Sync + 'static + sealed::Element {
    const ELEM: Elem;
}

macro_rules! elements {
    ($($t:ty => $e:ident),* $(,)?) => {$(
        impl sealed::Element for $t {}
        impl Element for $t {
            const ELEM: Elem = Elem::$e;
        }
        const _: () = assert!(size_of::<$t>() == Elem::$e.size());
    )*};
}

elements!(
    f32 => F32, f64 => F64, u8 => U8, u16 => U16, u32 => U32, u64 => U64,
    [f32; 2] => F32x2, glam::Vec2 => F32x2,
    [f32; 3] => F32x3, glam::Vec3 => F32x3,
    [f64; 3] => F64x3, glam::DVec3 => F64x3,
    [u32; 3] => U32x3, [u64; 3] => U64x3,
);

/// A fresh generation: unique in the process, so two arrays never share one either.
fn new_generation() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Who owns the memory of an array and how it is kept still while Luxon reads it. Sealed: the
/// sources are Luxon's own vectors, [`SharedVec`]s (whole or one field) and external memory.
pub trait Source: Send + Sync + 'static + sealed::Source {
    /// Holds the memory unchanged and in place until the returned pin drops; says where it is.
    fn pin(&self) -> Result<Pinned<'_>, Error>;
    /// Changes whenever the content may have changed.
    fn generation(&self) -> u64;
    /// Gives the source a new generation (its content changed behind Luxon's back).
    fn mark_modified(&self);
    /// Elements now.
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A guard kept alive by a [`Pinned`]: sendable, so pins can be held by a scene that moves
/// between threads (the guards only count readers, see [`GateHold`]).
trait Held: Send + Sync {}
impl<T: Send + Sync> Held for T {}

/// An array held still: its memory is neither written nor freed until this drops.
pub struct Pinned<'a> {
    base: *const u8,
    len: usize,
    stride: usize,
    elem: Elem,
    generation: u64,
    _guard: Option<Box<dyn Held + 'a>>,
}

impl<'a> Pinned<'a> {
    /// # Safety
    /// For every `i < len`, the `elem.size()` bytes at `base + i * stride` lie in one
    /// allocation, are initialised and readable from any thread, and are not written or freed
    /// while the returned value lives (`guard` holds writers off, or the source's maker
    /// promised it); `(len - 1) * stride + elem.size()` fits in an `isize`.
    unsafe fn new(
        base: *const u8,
        len: usize,
        stride: usize,
        elem: Elem,
        generation: u64,
        guard: Option<Box<dyn Held + 'a>>,
    ) -> Pinned<'a> {
        Pinned {
            base,
            len,
            stride,
            elem,
            generation,
            _guard: guard,
        }
    }

    /// The elements, for reading (as many views as needed, on any thread).
    pub fn view(&self) -> View<'_> {
        View {
            base: self.base,
            len: self.len,
            stride: self.stride,
            elem: self.elem,
            _pin: PhantomData,
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn elem(&self) -> Elem {
        self.elem
    }

    /// The generation of the content held.
    pub fn generation(&self) -> u64 {
        self.generation
    }
}

// SAFETY: a pin only reads its memory, which is not written or freed while it lives
// (`Pinned::new`'s contract), and its guard is `Send + Sync` (`Held`); so it may be moved to and
// shared by any thread.
unsafe impl Send for Pinned<'_> {}
// SAFETY: as for `Send`.
unsafe impl Sync for Pinned<'_> {}

/// Arrays pinned together, for as long as this lives (a commit and the render after it): it
/// holds clones of the arrays, so it borrows nothing and can be kept by a built scene.
pub struct Pins {
    // Dropped before the arrays whose sources they borrow.
    pinned: Vec<Pinned<'static>>,
    arrays: Vec<Array>,
}

impl Pins {
    /// Pins every array (fails as [`Array::pin`] does; those pinned already are released).
    pub fn new(arrays: &[Array]) -> Result<Pins, Error> {
        let arrays = arrays.to_vec();
        let mut pinned = Vec::with_capacity(arrays.len());
        for a in &arrays {
            let pin = a.pin()?;
            // SAFETY: the pin borrows `a`'s source, an `Arc` whose clone `arrays` keeps (the
            // source does not move when `arrays` does) and which outlives `pinned` (declared
            // first, so dropped first); no `Pinned<'static>` leaves this struct (only views
            // borrowing `self`).
            pinned.push(unsafe { std::mem::transmute::<Pinned<'_>, Pinned<'static>>(pin) });
        }
        Ok(Pins { pinned, arrays })
    }

    /// A view of the `k`-th array (an empty one past the last).
    #[inline]
    pub fn view(&self, k: usize) -> View<'_> {
        match self.pinned.get(k) {
            Some(p) => p.view(),
            None => View {
                base: std::ptr::null(),
                len: 0,
                stride: 0,
                elem: Elem::U8,
                _pin: PhantomData,
            },
        }
    }

    /// The generation of the `k`-th array's content held (0 past the last).
    pub fn generation(&self, k: usize) -> u64 {
        self.pinned.get(k).map_or(0, Pinned::generation)
    }

    /// The arrays pinned, in order.
    pub fn arrays(&self) -> &[Array] {
        &self.arrays
    }
}

/// A strided view of a pinned array: what geometry reads in its inner loops. Every read is
/// checked against the length and the element type (a read past the end, or of another type,
/// is `None`; callers treat it as a miss), and needs no alignment.
#[derive(Clone, Copy)]
pub struct View<'a> {
    base: *const u8,
    len: usize,
    stride: usize,
    elem: Elem,
    _pin: PhantomData<&'a [u8]>,
}

// SAFETY: a view only reads, and the memory it reads is not written while the pin it borrows
// lives (`Pinned::new`'s contract), so reads from several threads at once are sound.
unsafe impl Send for View<'_> {}
// SAFETY: as for `Send`: shared views only ever read memory nobody writes meanwhile.
unsafe impl Sync for View<'_> {}

impl View<'_> {
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn elem(&self) -> Elem {
        self.elem
    }

    /// Element `i` as a `T` of the view's own type; `None` past the end or for another type.
    #[inline]
    fn read<T: Element>(&self, i: usize) -> Option<T> {
        if T::ELEM != self.elem || i >= self.len {
            return None;
        }
        // SAFETY: `i < len`, so (`Pinned::new`'s contract) the `elem.size()` bytes at
        // `base + i * stride` are in one allocation (the offset fits an isize), initialised and
        // not written meanwhile; `T` has that size (`Element` checks it) and is plain, so every
        // bit pattern is a `T`; `read_unaligned` needs no alignment.
        Some(unsafe { self.base.add(i * self.stride).cast::<T>().read_unaligned() })
    }

    /// A 3-vector (f32x3 widened, or f64x3).
    #[inline]
    pub fn vec3(&self, i: usize) -> Option<DVec3> {
        match self.elem {
            Elem::F32x3 => self
                .read::<[f32; 3]>(i)
                .map(|v| DVec3::from(v.map(f64::from))),
            Elem::F64x3 => self.read::<[f64; 3]>(i).map(DVec3::from),
            _ => None,
        }
    }

    /// A 2-vector (f32x2), widened.
    #[inline]
    pub fn vec2(&self, i: usize) -> Option<[f64; 2]> {
        self.read::<[f32; 2]>(i).map(|v| v.map(f64::from))
    }

    /// A number of any scalar type as an f64 (u64 above 2^53 rounded).
    #[inline]
    pub fn scalar(&self, i: usize) -> Option<f64> {
        match self.elem {
            Elem::F32 => self.read::<f32>(i).map(f64::from),
            Elem::F64 => self.read::<f64>(i),
            Elem::U8 => self.read::<u8>(i).map(f64::from),
            Elem::U16 => self.read::<u16>(i).map(f64::from),
            Elem::U32 => self.read::<u32>(i).map(f64::from),
            Elem::U64 => self.read::<u64>(i).map(|v| v as f64),
            _ => None,
        }
    }

    /// An unsigned integer of any width.
    #[inline]
    pub fn index(&self, i: usize) -> Option<u64> {
        match self.elem {
            Elem::U8 => self.read::<u8>(i).map(u64::from),
            Elem::U16 => self.read::<u16>(i).map(u64::from),
            Elem::U32 => self.read::<u32>(i).map(u64::from),
            Elem::U64 => self.read::<u64>(i),
            _ => None,
        }
    }

    /// Three indices (u32x3 or u64x3): a triangle's corners.
    #[inline]
    pub fn index3(&self, i: usize) -> Option<[u64; 3]> {
        match self.elem {
            Elem::U32x3 => self.read::<[u32; 3]>(i).map(|v| v.map(u64::from)),
            Elem::U64x3 => self.read::<[u64; 3]>(i),
            _ => None,
        }
    }
}

/// Who holds a [`Shared`] vector: pins (and reads) never wait for a waiting writer, only for
/// one that writes; a writer waits until nobody holds it.
#[derive(Default)]
struct Gate {
    readers: usize,
    writer: Option<ThreadId>,
}

/// A vector behind a gate, with a generation.
struct Shared<T> {
    /// Locked in step with `gate` (readers only when it lets them, the writer only alone), so
    /// the lock itself never waits: it is there to hand out the slice safely.
    data: RwLock<Vec<T>>,
    gate: Mutex<Gate>,
    changed: Condvar,
    generation: AtomicU64,
    /// The vector's length (changed only by `replace`), read without waiting.
    len: AtomicUsize,
}

fn unpoisoned<G>(r: Result<G, PoisonError<G>>) -> G {
    // The data are plain values: a panic while they were written leaves values, not broken
    // invariants.
    r.unwrap_or_else(PoisonError::into_inner)
}

impl<T> Shared<T> {
    fn gate(&self) -> MutexGuard<'_, Gate> {
        unpoisoned(self.gate.lock())
    }

    /// Waits while a writer writes, then reads. `Err` if the writer is this thread (it would
    /// wait for itself).
    fn read(&self) -> Result<SharedRead<'_, T>, ThreadId> {
        let mut gate = self.gate();
        while let Some(writer) = gate.writer {
            if writer == std::thread::current().id() {
                return Err(writer);
            }
            gate = unpoisoned(self.changed.wait(gate));
        }
        gate.readers += 1;
        drop(gate);
        Ok(SharedRead {
            shared: self,
            data: Some(unpoisoned(self.data.read())),
        })
    }

    fn write_now(&self, mut gate: MutexGuard<'_, Gate>) -> SharedWrite<'_, T> {
        gate.writer = Some(std::thread::current().id());
        drop(gate);
        SharedWrite {
            shared: self,
            data: Some(unpoisoned(self.data.write())),
        }
    }

    fn write(&self) -> SharedWrite<'_, T> {
        let mut gate = self.gate();
        while gate.readers > 0 || gate.writer.is_some() {
            gate = unpoisoned(self.changed.wait(gate));
        }
        self.write_now(gate)
    }

    fn try_write(&self) -> Option<SharedWrite<'_, T>> {
        // The gate's mutex is only ever held for a moment (never while waiting).
        let gate = self.gate();
        (gate.readers == 0 && gate.writer.is_none()).then(|| self.write_now(gate))
    }

    fn busy(&self, by: ThreadId) -> Error {
        Error::Api(format!(
            "an array is being written by this thread ({by:?}): drop its SharedWrite guard \
             before rendering"
        ))
    }
}

/// A vector the caller and Luxon share: the caller writes it through [`SharedVec::write`]
/// between renders, Luxon reads it in place ([`Array::shared`], [`Array::field`]). A render
/// pins it, and a write waits for the render to end. Clones share the vector.
pub struct SharedVec<T>(Arc<Shared<T>>);

impl<T> Clone for SharedVec<T> {
    fn clone(&self) -> Self {
        SharedVec(self.0.clone())
    }
}

impl<T: Send + Sync + 'static> SharedVec<T> {
    pub fn new(v: Vec<T>) -> Self {
        SharedVec(Arc::new(Shared {
            gate: Mutex::default(),
            changed: Condvar::new(),
            generation: AtomicU64::new(new_generation()),
            len: AtomicUsize::new(v.len()),
            data: RwLock::new(v),
        }))
    }

    /// Waits until no render or reader holds the vector, then gives it for writing; the
    /// generation changes when the guard drops. Deadlocks if this thread holds a pin or read
    /// of it ([`SharedVec::try_write`] does not wait).
    pub fn write(&self) -> SharedWrite<'_, T> {
        self.0.write()
    }

    /// The vector for writing if nobody holds it now.
    pub fn try_write(&self) -> Option<SharedWrite<'_, T>> {
        self.0.try_write()
    }

    /// The vector for reading (waits while it is written).
    ///
    /// # Panics
    /// If this thread holds a write guard of it (it would wait forever).
    pub fn read(&self) -> SharedRead<'_, T> {
        match self.0.read() {
            Ok(read) => read,
            Err(by) => panic!("SharedVec::read on thread {by:?}, which is writing it"),
        }
    }

    /// Replaces the content (the length may change), as a write does.
    pub fn replace(&self, v: Vec<T>) {
        let mut w = self.0.write();
        if let Some(data) = w.data.as_mut() {
            self.0.len.store(v.len(), Ordering::Relaxed);
            **data = v;
        }
    }

    pub fn len(&self) -> usize {
        self.0.len.load(Ordering::Relaxed)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn generation(&self) -> u64 {
        self.0.generation.load(Ordering::Acquire)
    }
}

/// The vector being read: a slice.
pub struct SharedRead<'a, T> {
    shared: &'a Shared<T>,
    /// Some until dropped (released before the gate is told).
    data: Option<RwLockReadGuard<'a, Vec<T>>>,
}

impl<T> Deref for SharedRead<'_, T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        self.data.as_deref().map_or(&[], Vec::as_slice)
    }
}

impl<T> Drop for SharedRead<'_, T> {
    fn drop(&mut self) {
        self.data = None;
        let mut gate = self.shared.gate();
        gate.readers -= 1;
        drop(gate);
        self.shared.changed.notify_all();
    }
}

impl<'a, T> SharedRead<'a, T> {
    /// Keeps the vector read (writers held off) without its lock's guard, which may not
    /// leave its thread: the gate's reader count alone keeps writers off.
    fn into_hold(mut self) -> GateHold<'a, T> {
        self.data = None;
        let hold = GateHold(self.shared);
        std::mem::forget(self);
        hold
    }
}

/// A reader counted at a [`Shared`] vector's gate (writers wait until it drops). Its memory
/// stays put: every writer (and `replace`) passes the gate first.
struct GateHold<'a, T>(&'a Shared<T>);

impl<T> Drop for GateHold<'_, T> {
    fn drop(&mut self) {
        let mut gate = self.0.gate();
        gate.readers -= 1;
        drop(gate);
        self.0.changed.notify_all();
    }
}

/// The vector being written: a mutable slice (never the `Vec`, so the buffer cannot move while
/// pins may know where it is). Dropping it gives the vector a new generation.
pub struct SharedWrite<'a, T> {
    shared: &'a Shared<T>,
    data: Option<RwLockWriteGuard<'a, Vec<T>>>,
}

impl<T> Deref for SharedWrite<'_, T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        self.data.as_deref().map_or(&[], Vec::as_slice)
    }
}

impl<T> DerefMut for SharedWrite<'_, T> {
    fn deref_mut(&mut self) -> &mut [T] {
        self.data.as_deref_mut().map_or(&mut [], Vec::as_mut_slice)
    }
}

impl<T> Drop for SharedWrite<'_, T> {
    fn drop(&mut self) {
        // The new generation is visible before anyone can read the new content.
        self.shared
            .generation
            .store(new_generation(), Ordering::Release);
        self.data = None;
        self.shared.gate().writer = None;
        self.shared.changed.notify_all();
    }
}

/// A [`Shared`] vector of elements, whole and packed.
impl<T: Element> sealed::Source for Shared<T> {
    fn as_any(&self) -> &dyn Any {
        self
    }
}

impl<T: Element> Source for Shared<T> {
    fn pin(&self) -> Result<Pinned<'_>, Error> {
        let read = self.read().map_err(|by| self.busy(by))?;
        let (base, len) = (read.as_ptr().cast::<u8>(), read.len());
        let generation = self.generation.load(Ordering::Acquire);
        // SAFETY: the slice holds `len` initialised `T`s of `T::ELEM.size()` bytes each, packed
        // (stride = size), in one allocation (so the span fits an isize); `read` keeps every
        // writer off until the pin drops, and the buffer cannot move or be freed before that
        // (writes go through the same gate). `T: Sync`, so it may be read from any thread.
        Ok(unsafe {
            Pinned::new(
                base,
                len,
                size_of::<T>(),
                T::ELEM,
                generation,
                Some(Box::new(read.into_hold())),
            )
        })
    }

    fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    fn mark_modified(&self) {
        self.generation.store(new_generation(), Ordering::Release);
    }

    fn len(&self) -> usize {
        self.len.load(Ordering::Relaxed)
    }
}

type Getter<P, F> = dyn Fn(&P) -> &F + Send + Sync;

/// One field of every struct in a [`SharedVec`].
struct Field<P, F> {
    vec: Arc<Shared<P>>,
    get: Box<Getter<P, F>>,
    /// The generation whose content was checked, and the field's offset in it.
    checked: Mutex<Option<(u64, usize)>>,
}

/// Where `get` finds its field in every item: the same offset in each, inside the item, or an
/// error (a closure returning something else than a field of its argument).
fn field_offset<P, F>(items: &[P], get: &Getter<P, F>) -> Result<usize, Error> {
    let Some(first) = items.first() else {
        return Ok(0);
    };
    let offset_in = |item: &P| {
        let field = (get(item) as *const F).addr();
        field.wrapping_sub((item as *const P).addr())
    };
    let offset = offset_in(first);
    if offset
        .checked_add(size_of::<F>())
        .is_none_or(|end| end > size_of::<P>())
    {
        return Err(Error::Api(format!(
            "Array::field: the closure returned a reference outside its argument (a {}-byte \
             value); it must return one of the argument's fields",
            size_of::<P>()
        )));
    }
    match items.iter().position(|item| offset_in(item) != offset) {
        None => Ok(offset),
        Some(i) => Err(Error::Api(format!(
            "Array::field: the closure found item {i}'s field elsewhere than item 0's (at byte \
             {offset}); it must return the same field of every item"
        ))),
    }
}

impl<P: Send + Sync + 'static, F: Element> sealed::Source for Field<P, F> {
    fn as_any(&self) -> &dyn Any {
        self
    }
}

impl<P: Send + Sync + 'static, F: Element> Source for Field<P, F> {
    fn pin(&self) -> Result<Pinned<'_>, Error> {
        let read = self.vec.read().map_err(|by| self.vec.busy(by))?;
        let generation = self.vec.generation.load(Ordering::Acquire);
        let mut checked = unpoisoned(self.checked.lock());
        let offset = match *checked {
            Some((g, offset)) if g == generation => offset,
            _ => {
                // Checked once per content: an enum's variants may put the field in different
                // places, so every item is asked.
                let offset = field_offset(&read, &*self.get)?;
                *checked = Some((generation, offset));
                offset
            }
        };
        drop(checked);
        let base = read.as_ptr().cast::<u8>().wrapping_add(offset);
        let len = read.len();
        // SAFETY: `field_offset` checked, for this generation's content (which cannot change
        // while `read` is held: writers bump the generation before others may read), that item
        // i's `F` lies `offset` bytes into item i, i.e. at `base + i * size_of::<P>()`, and
        // within the item; being a live `&F`, its `F::ELEM.size()` bytes are initialised. The
        // items are one allocation, the buffer cannot move or be freed and nobody writes while
        // `read` is held, and `P: Sync`.
        Ok(unsafe {
            Pinned::new(
                base,
                len,
                size_of::<P>(),
                F::ELEM,
                generation,
                Some(Box::new(read.into_hold())),
            )
        })
    }

    fn generation(&self) -> u64 {
        self.vec.generation.load(Ordering::Acquire)
    }

    fn mark_modified(&self) {
        self.vec
            .generation
            .store(new_generation(), Ordering::Release);
    }

    fn len(&self) -> usize {
        self.vec.len.load(Ordering::Relaxed)
    }
}

/// Memory the caller keeps (C, Python), released by dropping `owner`.
struct External {
    base: *const u8,
    len: usize,
    stride: usize,
    elem: Elem,
    generation: AtomicU64,
    _owner: Box<dyn Any + Send + Sync>,
}

// SAFETY: `External` only reads its memory, which the caller of `Array::external` promised is
// readable from any thread and not written while pinned; the owner is `Send + Sync` itself.
unsafe impl Send for External {}
// SAFETY: as for `Send`.
unsafe impl Sync for External {}

impl sealed::Source for External {
    fn as_any(&self) -> &dyn Any {
        self
    }
}

impl Source for External {
    fn pin(&self) -> Result<Pinned<'_>, Error> {
        let generation = self.generation.load(Ordering::Acquire);
        // SAFETY: `Array::external`'s caller promised the elements readable, initialised and
        // unwritten while pinned, in memory valid until `_owner` drops (after this pin, which
        // borrows `self`); it checked the span fits an isize.
        Ok(unsafe {
            Pinned::new(
                self.base,
                self.len,
                self.stride,
                self.elem,
                generation,
                None,
            )
        })
    }

    fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    fn mark_modified(&self) {
        self.generation.store(new_generation(), Ordering::Release);
    }

    fn len(&self) -> usize {
        self.len
    }
}

/// Bytes copied from the caller's memory into arrays of Luxon's own since the process started.
static COPIED_BYTES: AtomicU64 = AtomicU64::new(0);

/// Bytes [`Array::copy`] and [`Array::update`] have copied since the process started: a
/// program that hands its data over in place checks with it that nothing was copied (the
/// in-situ example does, and its test).
pub fn copied_bytes() -> u64 {
    COPIED_BYTES.load(Ordering::Relaxed)
}

/// A typed, strided sequence Luxon reads: see the [module documentation](self). Clones share
/// the source.
#[derive(Clone)]
pub struct Array {
    source: Arc<dyn Source>,
    elem: Elem,
}

impl std::fmt::Debug for Array {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Array")
            .field("elem", &self.elem)
            .field("len", &self.len())
            .field("generation", &self.generation())
            .finish()
    }
}

impl Array {
    /// Luxon's own packed copy of `data` (changed later by [`Array::update`]).
    pub fn copy<T: Element>(data: &[T]) -> Result<Array, Error> {
        let mut v = Vec::new();
        v.try_reserve_exact(data.len())
            .map_err(|_| Error::OutOfMemory {
                what: format!("a copy of {} {} elements", data.len(), T::ELEM),
                bytes: data.len() as u128 * T::ELEM.size() as u128,
            })?;
        v.extend_from_slice(data);
        COPIED_BYTES.fetch_add(size_of::<T>() as u64 * data.len() as u64, Ordering::Relaxed);
        Ok(Array::from_vec(v))
    }

    /// The vector itself, owned by the array (no copy).
    pub fn from_vec<T: Element>(v: Vec<T>) -> Array {
        Array::shared(&SharedVec::new(v))
    }

    /// A shared vector of elements, read in place.
    pub fn shared<T: Element>(v: &SharedVec<T>) -> Array {
        Array {
            source: v.0.clone(),
            elem: T::ELEM,
        }
    }

    /// One field of every struct in a shared vector, read in place (stride: the struct's
    /// size), e.g. `Array::field(&atoms, |a: &Atom| &a.pos)`. `get` must return a field of its
    /// argument, the same for every item: checked now and, whenever the vector has changed, at
    /// the next pin.
    pub fn field<P, F>(
        v: &SharedVec<P>,
        get: impl Fn(&P) -> &F + Send + Sync + 'static,
    ) -> Result<Array, Error>
    where
        P: Send + Sync + 'static,
        F: Element,
    {
        let get: Box<Getter<P, F>> = Box::new(get);
        let checked = {
            let read = v.0.read().map_err(|by| v.0.busy(by))?;
            let offset = field_offset(&read, &*get)?;
            (v.0.generation.load(Ordering::Acquire), offset)
        };
        Ok(Array {
            source: Arc::new(Field {
                vec: v.0.clone(),
                get,
                checked: Mutex::new(Some(checked)),
            }),
            elem: F::ELEM,
        })
    }

    /// Memory the caller keeps: `len` elements of type `elem`, element `i` at
    /// `base + i * stride` bytes (stride 0: packed), read in place until the array and all its
    /// clones are dropped; then `owner` is dropped (its `Drop` releases the memory, if it
    /// should). Refused: a null `base` with `len > 0`, a stride below the element's size, and
    /// a span past the address space.
    ///
    /// # Safety
    /// Unless refused, for every `i < len` the `elem.size()` bytes at `base + i * stride` must
    /// lie in one allocation (or mapping), be initialised, readable from any thread, stay valid
    /// until `owner` is dropped, and not be written while the array is pinned (a commit or a
    /// render that uses it runs). With `len` 0 nothing is read.
    pub unsafe fn external(
        base: *const u8,
        len: usize,
        stride: usize,
        elem: Elem,
        owner: impl Any + Send + Sync,
    ) -> Result<Array, Error> {
        let size = elem.size();
        let stride = if stride == 0 { size } else { stride };
        if base.is_null() && len > 0 {
            return Err(Error::Api(format!(
                "an array of {len} {elem} elements at a null address"
            )));
        }
        if stride < size {
            return Err(Error::Api(format!(
                "an array of {elem} elements ({size} bytes each) with a stride of {stride} bytes: \
                 elements would overlap"
            )));
        }
        let span = match len.checked_sub(1) {
            None => Some(0),
            Some(last) => last.checked_mul(stride).and_then(|b| b.checked_add(size)),
        }
        .filter(|&span| span <= isize::MAX as usize && base.addr().checked_add(span).is_some());
        if span.is_none() {
            return Err(Error::Api(format!(
                "an array of {len} {elem} elements with a stride of {stride} bytes spans more \
                 than the address space"
            )));
        }
        Ok(Array {
            source: Arc::new(External {
                base,
                len,
                stride,
                elem,
                generation: AtomicU64::new(new_generation()),
                _owner: Box::new(owner),
            }),
            elem,
        })
    }

    /// Holds the memory still and says where it is (see [`Pinned`]). Fails if this thread
    /// is writing the vector, or if an [`Array::field`] closure no longer finds its field.
    pub fn pin(&self) -> Result<Pinned<'_>, Error> {
        self.source.pin()
    }

    /// Elements now (a shared vector may have been replaced by one of another length).
    pub fn len(&self) -> usize {
        self.source.len()
    }

    pub fn is_empty(&self) -> bool {
        self.source.is_empty()
    }

    pub fn elem(&self) -> Elem {
        self.elem
    }

    /// Changes whenever the content may have changed; different arrays never share one.
    pub fn generation(&self) -> u64 {
        self.source.generation()
    }

    /// Tells Luxon the content changed (memory written by the caller, not through a
    /// [`SharedWrite`]).
    pub fn mark_modified(&self) {
        self.source.mark_modified();
    }

    /// Whether both read the same source (a clone, or the same shared vector whole).
    pub fn same_source(&self, other: &Array) -> bool {
        std::ptr::addr_eq(Arc::as_ptr(&self.source), Arc::as_ptr(&other.source))
    }

    /// Writes `data` over elements `first..first + data.len()` of a packed array of `T`s
    /// ([`Array::copy`], [`Array::from_vec`], [`Array::shared`]), waiting for renders that read
    /// it, and changes its generation.
    pub fn update<T: Element>(&self, first: usize, data: &[T]) -> Result<(), Error> {
        let any = sealed::Source::as_any(&*self.source);
        let Some(shared) = any.downcast_ref::<Shared<T>>() else {
            return Err(Error::Api(format!(
                "update with {} elements: this array is not a packed array of them ({} \
                 elements{})",
                std::any::type_name::<T>(),
                self.elem,
                if any.is::<External>() {
                    ", in memory the caller keeps: write it and mark it modified"
                } else {
                    ""
                }
            )));
        };
        let mut w = shared.write();
        let end = first.checked_add(data.len()).filter(|&e| e <= w.len());
        let Some(end) = end else {
            return Err(Error::Api(format!(
                "update of elements {first}..{first}+{} of an array of {}",
                data.len(),
                w.len()
            )));
        };
        w[first..end].copy_from_slice(data);
        COPIED_BYTES.fetch_add(size_of::<T>() as u64 * data.len() as u64, Ordering::Relaxed);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicBool;
    use std::time::Duration;

    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Atom {
        kind: u8,
        pos: [f64; 3],
        q: f32,
    }

    fn atoms(n: usize) -> Vec<Atom> {
        (0..n)
            .map(|i| Atom {
                kind: i as u8,
                pos: [i as f64, 0.5 * i as f64, -(i as f64) - 0.25],
                q: i as f32 * 0.1,
            })
            .collect()
    }

    /// The counter the in-situ example checks (tests/insitu.rs: zero for shared arrays):
    /// copies and updates add their bytes (other tests may copy meanwhile: at least these).
    #[test]
    fn copies_are_counted() {
        let before = copied_bytes();
        let a = Array::copy(&[[1.0f64, 2.0, 3.0]; 10]).unwrap();
        a.update(2, &[[0.0f64; 3]; 3]).unwrap();
        assert!(copied_bytes() - before >= 13 * 24);
    }

    #[test]
    fn a_field_of_structs_is_read_in_place() {
        let v = SharedVec::new(atoms(100));
        let pos = Array::field(&v, |a: &Atom| &a.pos).unwrap();
        let q = Array::field(&v, |a: &Atom| &a.q).unwrap();
        let kind = Array::field(&v, |a: &Atom| &a.kind).unwrap();
        let (p, qp, kp) = (pos.pin().unwrap(), q.pin().unwrap(), kind.pin().unwrap());
        assert_eq!((p.len(), p.elem()), (100, Elem::F64x3));
        let (pv, qv, kv) = (p.view(), qp.view(), kp.view());
        for (i, a) in atoms(100).iter().enumerate() {
            assert_eq!(pv.vec3(i), Some(DVec3::from(a.pos)));
            assert_eq!(qv.scalar(i), Some(f64::from(a.q)));
            assert_eq!(kv.index(i), Some(u64::from(a.kind)));
        }
        // In place: the first position is the vector's own memory.
        let first = &v.read()[0].pos as *const [f64; 3];
        assert_eq!(p.base, first.cast::<u8>());
        assert_eq!(p.stride, size_of::<Atom>());
    }

    #[test]
    fn packed_f32_is_widened_and_vec3_types_read_alike() {
        let data: Vec<[f32; 3]> = (0..50).map(|i| [i as f32 * 0.1, 1.0, -2.5]).collect();
        let glam: Vec<glam::Vec3> = data.iter().map(|&v| glam::Vec3::from(v)).collect();
        let a = Array::copy(&data).unwrap();
        let b = Array::copy(&glam).unwrap();
        let (pa, pb) = (a.pin().unwrap(), b.pin().unwrap());
        for (i, v) in data.iter().enumerate() {
            let want = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            assert_eq!(pa.view().vec3(i), Some(want));
            assert_eq!(pb.view().vec3(i), Some(want));
        }
        assert_eq!(pa.view().vec3(50), None);
    }

    /// Reads past the end, of another type, or on an empty array, are `None`.
    #[test]
    fn reads_out_of_range_or_of_another_type_are_none() {
        let a = Array::from_vec(vec![1.5f64, 2.5]);
        let p = a.pin().unwrap();
        let v = p.view();
        assert_eq!(
            (v.scalar(0), v.scalar(1), v.scalar(2)),
            (Some(1.5), Some(2.5), None)
        );
        assert_eq!(v.scalar(usize::MAX), None);
        assert_eq!(
            (v.vec3(0), v.index(0), v.index3(0), v.vec2(0)),
            (None, None, None, None)
        );
        let empty = Array::from_vec(Vec::<[u32; 3]>::new());
        let p = empty.pin().unwrap();
        assert_eq!((p.len(), p.view().index3(0)), (0, None));
        let tri = Array::from_vec(vec![[1u32, 2, 3]]);
        assert_eq!(tri.pin().unwrap().view().index3(0), Some([1, 2, 3]));
    }

    /// f64 positions every 40 bytes of a buffer of the caller's, and f32 triples at odd
    /// addresses.
    #[test]
    fn external_memory_strided_and_unaligned() {
        let n = 64;
        let buffer: Vec<f64> = (0..n * 5).map(|k| k as f64).collect();
        let owned = Arc::new(buffer);
        let dropped = Arc::new(AtomicBool::new(false));
        struct Owner(#[allow(dead_code)] Arc<Vec<f64>>, Arc<AtomicBool>);
        impl Drop for Owner {
            fn drop(&mut self) {
                self.1.store(true, Ordering::SeqCst);
            }
        }
        // SAFETY: `owned` holds n * 5 f64s, so elements every 40 bytes from the second f64 are
        // in bounds; the owner keeps them alive and nothing writes them.
        let a = unsafe {
            Array::external(
                owned.as_ptr().add(1).cast(),
                n,
                40,
                Elem::F64x3,
                Owner(owned.clone(), dropped.clone()),
            )
        }
        .unwrap();
        let copy = a.clone();
        {
            let p = a.pin().unwrap();
            for i in 0..n {
                let k = (5 * i + 1) as f64;
                assert_eq!(p.view().vec3(i), Some(DVec3::new(k, k + 1.0, k + 2.0)));
            }
            assert_eq!(p.view().vec3(n), None);
        }
        drop(a);
        assert!(!dropped.load(Ordering::SeqCst), "a clone still reads it");
        drop(copy);
        assert!(
            dropped.load(Ordering::SeqCst),
            "the owner goes with the last clone"
        );

        // f32 triples packed from byte 1 of a byte buffer.
        let values: Vec<[f32; 3]> = (0..10).map(|i| [i as f32, 0.25, -1.0 / 3.0]).collect();
        let mut bytes = vec![0u8; 1 + 12 * values.len()];
        for (i, v) in values.iter().enumerate() {
            for (k, x) in v.iter().enumerate() {
                let at = 1 + 12 * i + 4 * k;
                bytes[at..at + 4].copy_from_slice(&x.to_ne_bytes());
            }
        }
        let bytes = Arc::new(bytes);
        // SAFETY: 10 packed 12-byte elements from byte 1 of a 121-byte buffer the owner keeps.
        let a = unsafe { Array::external(bytes[1..].as_ptr(), 10, 0, Elem::F32x3, bytes.clone()) }
            .unwrap();
        let p = a.pin().unwrap();
        for (i, v) in values.iter().enumerate() {
            assert_eq!(p.view().vec3(i), Some(DVec3::from(v.map(f64::from))));
        }
    }

    #[test]
    fn external_arrays_that_cannot_be_read_are_refused() {
        let refused = |base: *const u8, len: usize, stride: usize, elem: Elem| {
            // SAFETY: each of these is refused before anything is read.
            match unsafe { Array::external(base, len, stride, elem, ()) } {
                Err(Error::Api(m)) => m,
                other => panic!("{len} x {stride}: {other:?}"),
            }
        };
        let b = [0u8; 64];
        let m = refused(b.as_ptr(), usize::MAX / 8, 16, Elem::F32x3);
        assert!(
            m.contains(&format!("{} f32x3", usize::MAX / 8)) && m.contains("16 bytes"),
            "{m}"
        );
        let m = refused(b.as_ptr(), 3, usize::MAX / 2, Elem::F64);
        assert!(m.contains("address space"), "{m}");
        let m = refused(std::ptr::null(), 1, 0, Elem::U8);
        assert!(m.contains("null"), "{m}");
        let m = refused(b.as_ptr(), 4, 8, Elem::F32x3);
        assert!(
            m.contains("stride of 8 bytes") && m.contains("12 bytes"),
            "{m}"
        );
        // Near the top of the address space, the span would wrap.
        let top = std::ptr::without_provenance::<u8>(usize::MAX - 8);
        assert!(refused(top, 2, 0, Elem::F64).contains("address space"));
        // Nothing to read: accepted, whatever the base.
        // SAFETY: with no elements nothing is read.
        let empty = unsafe { Array::external(std::ptr::null(), 0, 0, Elem::F32x3, ()) }.unwrap();
        assert!(empty.pin().unwrap().view().vec3(0).is_none());
    }

    static ELSEWHERE: [f64; 3] = [0.0; 3];

    #[derive(Clone, Copy)]
    struct Pair {
        first: bool,
        a: [f64; 3],
        b: [f64; 3],
    }

    fn pick(p: &Pair) -> &[f64; 3] {
        if p.first {
            &p.a
        } else {
            &p.b
        }
    }

    #[test]
    fn field_closures_that_do_not_return_a_field_are_refused() {
        let v = SharedVec::new(atoms(4));
        let e = Array::field(&v, |_: &Atom| &ELSEWHERE).unwrap_err();
        assert!(e.to_string().contains("outside its argument"), "{e}");
        // Another field for some items: refused now, or at the pin after a write.
        let pairs = |firsts: &[bool]| -> Vec<Pair> {
            firsts
                .iter()
                .map(|&first| Pair {
                    first,
                    a: [1.0; 3],
                    b: [2.0; 3],
                })
                .collect()
        };
        let mixed = SharedVec::new(pairs(&[true, false]));
        let e = Array::field(&mixed, pick).unwrap_err();
        assert!(e.to_string().contains("item 1"), "{e}");
        let same = SharedVec::new(pairs(&[true, true, true]));
        let a = Array::field(&same, pick).unwrap();
        assert_eq!(a.pin().unwrap().view().vec3(2), Some(DVec3::splat(1.0)));
        same.write()[2].first = false;
        let e = a.pin().map(|_| ()).unwrap_err();
        assert!(e.to_string().contains("item 2"), "{e}");
        // An empty vector has no field to check until it has items.
        let empty = SharedVec::new(Vec::<Pair>::new());
        let a = Array::field(&empty, pick).unwrap();
        assert_eq!(a.pin().unwrap().len(), 0);
        empty.replace(pairs(&[false, true]));
        assert!(a.pin().is_err());
    }

    #[test]
    fn writes_wait_for_pins_and_change_the_generation_once_per_guard() {
        let v = SharedVec::new(vec![[0.0f32; 3]; 8]);
        let a = Array::shared(&v);
        let g0 = a.generation();
        assert_eq!(g0, v.generation());
        let pin = a.pin().unwrap();
        assert_eq!(pin.generation(), g0);
        let done = AtomicBool::new(false);
        std::thread::scope(|s| {
            assert!(s.spawn(|| v.try_write().is_none()).join().unwrap());
            let writer = s.spawn(|| {
                let mut w = v.write();
                w[0] = [1.0, 2.0, 3.0];
                w[1] = [4.0, 5.0, 6.0];
                done.store(true, Ordering::SeqCst);
            });
            std::thread::sleep(Duration::from_millis(50));
            assert!(!done.load(Ordering::SeqCst), "the write waits for the pin");
            // A second pin of the same vector on this thread does not wait for the writer.
            let x = Array::field(&v, |p: &[f32; 3]| &p[0]).unwrap();
            let again = x.pin().unwrap();
            assert_eq!(again.view().scalar(0), Some(0.0));
            assert_eq!(pin.view().vec3(0), Some(DVec3::ZERO));
            drop(again);
            drop(pin);
            writer.join().unwrap();
            assert!(done.load(Ordering::SeqCst));
        });
        let g1 = a.generation();
        assert_ne!(g1, g0, "the write changed the generation");
        assert_eq!(a.generation(), g1, "and only that write");
        assert_eq!(
            a.pin().unwrap().view().vec3(1),
            Some(DVec3::new(4.0, 5.0, 6.0))
        );
        drop(v.write());
        assert_ne!(a.generation(), g1, "one change per guard");
        // Rendering while this thread writes would wait forever: refused instead.
        let w = v.write();
        let e = a.pin().map(|_| ()).unwrap_err();
        assert!(e.to_string().contains("SharedWrite"), "{e}");
        drop(w);
        assert!(a.pin().is_ok());
    }

    #[test]
    fn replace_changes_the_length_and_the_generation() {
        let v = SharedVec::new(vec![1.0f32; 4]);
        let a = Array::shared(&v);
        let g = a.generation();
        v.replace(vec![2.0; 7]);
        assert_ne!(a.generation(), g);
        assert_eq!((a.len(), v.len()), (7, 7));
        let p = a.pin().unwrap();
        assert_eq!(
            (p.len(), p.view().scalar(6), p.view().scalar(7)),
            (7, Some(2.0), None)
        );
    }

    #[test]
    fn copies_are_updated_and_other_arrays_refuse_updates() {
        let mut data = vec![[1u32, 2, 3], [4, 5, 6], [7, 8, 9]];
        let a = Array::copy(&data).unwrap();
        data[0] = [0; 3];
        assert_eq!(a.pin().unwrap().view().index3(0), Some([1, 2, 3]), "a copy");
        let g = a.generation();
        a.update(1, &[[10u32, 11, 12], [13, 14, 15]]).unwrap();
        assert_ne!(a.generation(), g);
        let p = a.pin().unwrap();
        assert_eq!(p.view().index3(2), Some([13, 14, 15]));
        drop(p);
        let e = a.update(2, &[[0u32; 3], [0; 3]]).unwrap_err();
        assert!(e.to_string().contains("2..2+2 of an array of 3"), "{e}");
        assert!(a.update(usize::MAX, &[[0u32; 3]]).is_err());
        assert!(a.update(0, &[[0u64; 3]]).is_err(), "another type");
        let v = SharedVec::new(atoms(3));
        let field = Array::field(&v, |a: &Atom| &a.pos).unwrap();
        assert!(field.update(0, &[[0.0f64; 3]]).is_err());
        let m = a.clone();
        assert!(m.same_source(&a) && !field.same_source(&a));
        let g = field.generation();
        field.mark_modified();
        assert_ne!(field.generation(), g);
        assert_ne!(
            field.generation(),
            a.generation(),
            "generations are never shared"
        );
    }

    /// Views are read from several threads at once.
    #[test]
    fn views_are_read_on_many_threads() {
        let v = SharedVec::new(atoms(1000));
        let a = Array::field(&v, |a: &Atom| &a.pos).unwrap();
        let pin = a.pin().unwrap();
        let view = pin.view();
        let sums: Vec<f64> = std::thread::scope(|s| {
            let parts: Vec<_> = (0..4)
                .map(|t| {
                    s.spawn(move || {
                        (t * 250..(t + 1) * 250)
                            .map(|i| view.vec3(i).map_or(f64::NAN, |p| p.x))
                            .sum::<f64>()
                    })
                })
                .collect();
            parts.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(sums.iter().sum::<f64>(), (0..1000).sum::<usize>() as f64);
    }

    #[test]
    fn element_types_have_their_sizes() {
        for (e, size) in [
            (Elem::U8, 1),
            (Elem::U16, 2),
            (Elem::F32x2, 8),
            (Elem::F32x3, 12),
            (Elem::F64x3, 24),
            (Elem::U64x3, 24),
        ] {
            assert_eq!(e.size(), size, "{e}");
        }
        assert_eq!(<glam::DVec3 as Element>::ELEM, Elem::F64x3);
        assert_eq!(Elem::F32x3.to_string(), "f32x3");
    }
}

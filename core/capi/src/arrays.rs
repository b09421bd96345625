//! Arrays: the caller's memory read in place (shared arrays) or Luxon's copy of it (copy
//! arrays), named by `luxon_array` handles and used by the array objects and volumes of
//! scenes (`luxon_scene_add_spheres`...).

use crate::guard::guard;
use crate::handles::{luxon_array, Kind, Table};
use crate::status::{luxon_status, Failure};
use crate::text::put;
use luxon_core::arrays::{Array, Elem, Element};
use std::ffi::c_void;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

pub(crate) static ARRAYS: Table<ArrayEntry> = Table::new(Kind::Array);

/// An array handle's entry. Scene objects hold clones of `array`: the memory stays in use
/// after the handle is released, until the last object using it lets it go.
pub(crate) struct ArrayEntry {
    pub array: Array,
}

/// The type of an array's elements (`LUXON_FLOAT32`...).
pub type luxon_elem = i32;
/// `float`.
pub const LUXON_FLOAT32: luxon_elem = 1;
/// `double`.
pub const LUXON_FLOAT64: luxon_elem = 2;
/// `uint8_t`.
pub const LUXON_UINT8: luxon_elem = 3;
/// `uint16_t`.
pub const LUXON_UINT16: luxon_elem = 4;
/// `uint32_t`.
pub const LUXON_UINT32: luxon_elem = 5;
/// `uint64_t`.
pub const LUXON_UINT64: luxon_elem = 6;
/// `float[2]` (texture coordinates).
pub const LUXON_FLOAT32_VEC2: luxon_elem = 7;
/// `float[3]` (positions, normals, colours).
pub const LUXON_FLOAT32_VEC3: luxon_elem = 8;
/// `double[3]`.
pub const LUXON_FLOAT64_VEC3: luxon_elem = 9;
/// `uint32_t[3]` (a triangle's vertex indices).
pub const LUXON_UINT32_VEC3: luxon_elem = 10;
/// `uint64_t[3]`.
pub const LUXON_UINT64_VEC3: luxon_elem = 11;

fn elem(code: luxon_elem) -> Result<Elem, Failure> {
    Ok(match code {
        LUXON_FLOAT32 => Elem::F32,
        LUXON_FLOAT64 => Elem::F64,
        LUXON_UINT8 => Elem::U8,
        LUXON_UINT16 => Elem::U16,
        LUXON_UINT32 => Elem::U32,
        LUXON_UINT64 => Elem::U64,
        LUXON_FLOAT32_VEC2 => Elem::F32x2,
        LUXON_FLOAT32_VEC3 => Elem::F32x3,
        LUXON_FLOAT64_VEC3 => Elem::F64x3,
        LUXON_UINT32_VEC3 => Elem::U32x3,
        LUXON_UINT64_VEC3 => Elem::U64x3,
        _ => {
            return Err(Failure::invalid(format!(
                "element type {code}; expected one of LUXON_FLOAT32 (1) to LUXON_UINT64_VEC3 (11)"
            )))
        }
    })
}

/// Called when Luxon no longer reads a shared array: `user` is what was passed with it.
pub type luxon_deleter_fn = Option<unsafe extern "C" fn(user: *mut c_void)>;

/// Runs the caller's deleter when the last user of its memory drops it (unless disarmed: an
/// array that was refused leaves the memory to the caller).
struct Deleter {
    f: luxon_deleter_fn,
    user: *mut c_void,
    armed: AtomicBool,
}

// SAFETY: the deleter and its pointer are the caller's, who promises (luxon_array_create_shared)
// that the deleter may run on any thread; Luxon never reads through `user`.
unsafe impl Send for Deleter {}
// SAFETY: as for Send: the pointer is only handed back to the deleter, once.
unsafe impl Sync for Deleter {}

impl Drop for Deleter {
    fn drop(&mut self) {
        if let (Some(f), true) = (self.f, self.armed.load(Ordering::SeqCst)) {
            // SAFETY: the caller's deleter, called once with its own pointer (its contract).
            unsafe { f(self.user) };
        }
    }
}

/// An array over the caller's memory, read in place: `count` elements of type `type_`, element
/// `i` at `data + i * stride_bytes` (0: packed). No alignment is needed, so a field of an array
/// of structs is an array (`data` = the first struct's field, `stride_bytes` = the struct's
/// size).
///
/// Ownership rules:
/// 1. Luxon reads the memory in place at the commits and renders of the scenes whose objects use
///    the array, until the last such object is removed, given other arrays, or its scene
///    released; releasing the handle (`luxon_array_release`) does not end this. Then
///    `deleter(user)` runs (if not NULL), once, on a thread that called Luxon or one of Luxon's,
///    after the last read; it must not call Luxon. Until then the memory must stay valid.
/// 2. Do not write the memory while a commit or render of a scene using it runs (on any
///    thread): Luxon reads it only then.
/// 3. After writing it between renders, call `luxon_array_mark_modified`: the next commit reads
///    it again (refits the objects' BVHs, reads volumes again). Without it Luxon may show stale
///    geometry (never reads outside the array: every read is checked against `count`).
/// 4. Volumes are copied into Luxon's bricks at the commit that reads them: their arrays may be
///    written once it returned (mark them modified to have them read again).
///
/// Refused (LUXON_ERROR_INVALID_ARGUMENT): a NULL `data` with `count` > 0, an unknown type, a
/// stride below the element's size, a span past the address space. `out` is `{0}` on failure
/// (then the deleter is not called: the memory stays the caller's).
///
/// # Safety
/// `data` is valid as rule 1 says for reads of `count` elements at the stride; `out` is valid
/// for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_array_create_shared(
    data: *const c_void,
    count: usize,
    stride_bytes: usize,
    type_: luxon_elem,
    deleter: luxon_deleter_fn,
    user: *mut c_void,
    out: *mut luxon_array,
) -> luxon_status {
    guard("luxon_array_create_shared", || {
        // SAFETY: writable (caller); cleared first so a failure leaves {0}.
        unsafe { put(out, "out", luxon_array::default()) }?;
        let elem = elem(type_)?;
        let owner = Arc::new(Deleter {
            f: deleter,
            user,
            armed: AtomicBool::new(true),
        });
        // SAFETY: the caller's promise (rule 1).
        let array =
            unsafe { Array::external(data.cast(), count, stride_bytes, elem, owner.clone()) };
        let array = array.inspect_err(|_| owner.armed.store(false, Ordering::SeqCst))?;
        drop(owner);
        let id = ARRAYS.insert(ArrayEntry { array })?;
        // SAFETY: as above.
        unsafe { put(out, "out", luxon_array { id }) }
    })
}

/// Reads `count` elements of `T` at `data`, `stride` bytes apart.
///
/// # Safety
/// `data` is valid for reads of `count` elements at `stride` (≥ the element's size).
unsafe fn gather<T: Element>(
    data: *const u8,
    count: usize,
    stride: usize,
) -> Result<Vec<T>, Failure> {
    let mut v: Vec<T> = Vec::new();
    v.try_reserve_exact(count).map_err(|_| {
        Failure::from(luxon_core::Error::OutOfMemory {
            what: format!("a copy of {count} {} elements", T::ELEM),
            bytes: count as u128 * std::mem::size_of::<T>() as u128,
        })
    })?;
    for i in 0..count {
        // SAFETY: element i lies at data + i * stride (caller); no alignment needed.
        v.push(unsafe { data.add(i * stride).cast::<T>().read_unaligned() });
    }
    Ok(v)
}

/// What to do with the caller's elements once gathered as `T`s.
trait Take {
    type Out;
    fn take<T: Element>(self, v: Vec<T>) -> Result<Self::Out, Failure>;
}

/// Gathers `count` elements of type `elem` and hands them to `to` as a vector of their type.
///
/// # Safety
/// As [`gather`].
unsafe fn with_elements<K: Take>(
    elem: Elem,
    data: *const u8,
    count: usize,
    stride: usize,
    to: K,
) -> Result<K::Out, Failure> {
    // SAFETY: the caller's promise, for the element type's size.
    unsafe {
        match elem {
            Elem::F32 => to.take(gather::<f32>(data, count, stride)?),
            Elem::F64 => to.take(gather::<f64>(data, count, stride)?),
            Elem::U8 => to.take(gather::<u8>(data, count, stride)?),
            Elem::U16 => to.take(gather::<u16>(data, count, stride)?),
            Elem::U32 => to.take(gather::<u32>(data, count, stride)?),
            Elem::U64 => to.take(gather::<u64>(data, count, stride)?),
            Elem::F32x2 => to.take(gather::<[f32; 2]>(data, count, stride)?),
            Elem::F32x3 => to.take(gather::<[f32; 3]>(data, count, stride)?),
            Elem::F64x3 => to.take(gather::<[f64; 3]>(data, count, stride)?),
            Elem::U32x3 => to.take(gather::<[u32; 3]>(data, count, stride)?),
            Elem::U64x3 => to.take(gather::<[u64; 3]>(data, count, stride)?),
        }
    }
}

/// Checks a caller's span of `count` elements of `elem` at `stride` (0: packed); the stride.
fn span(data: *const c_void, count: usize, stride: usize, elem: Elem) -> Result<usize, Failure> {
    let size = elem.size();
    let stride = if stride == 0 { size } else { stride };
    if data.is_null() && count > 0 {
        return Err(Failure::invalid(format!(
            "`data` is NULL for {count} {elem} elements"
        )));
    }
    if stride < size {
        return Err(Failure::invalid(format!(
            "a stride of {stride} bytes for {elem} elements ({size} bytes each): elements \
             would overlap"
        )));
    }
    let end = match count.checked_sub(1) {
        None => Some(0),
        Some(last) => last.checked_mul(stride).and_then(|b| b.checked_add(size)),
    };
    if end.is_none_or(|e| e > isize::MAX as usize) {
        return Err(Failure::invalid(format!(
            "{count} {elem} elements with a stride of {stride} bytes span more than the \
             address space"
        )));
    }
    Ok(stride)
}

struct MakeCopy;

impl Take for MakeCopy {
    type Out = Array;
    fn take<T: Element>(self, v: Vec<T>) -> Result<Array, Failure> {
        Ok(Array::from_vec(v))
    }
}

/// An array holding Luxon's packed copy of `count` elements of type `type_` at `data`,
/// `stride_bytes` apart (0: packed). The caller's memory may be reused as soon as this returns;
/// `luxon_array_update` changes the copy. Refused as `luxon_array_create_shared` refuses;
/// LUXON_ERROR_OUT_OF_MEMORY when the copy does not fit.
///
/// # Safety
/// `data` is valid for reads of `count` elements at the stride; `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_array_create_copy(
    data: *const c_void,
    count: usize,
    stride_bytes: usize,
    type_: luxon_elem,
    out: *mut luxon_array,
) -> luxon_status {
    guard("luxon_array_create_copy", || {
        // SAFETY: writable (caller); cleared first so a failure leaves {0}.
        unsafe { put(out, "out", luxon_array::default()) }?;
        let elem = elem(type_)?;
        let stride = span(data, count, stride_bytes, elem)?;
        // SAFETY: readable as checked and promised (caller).
        let array = unsafe { with_elements(elem, data.cast(), count, stride, MakeCopy) }?;
        let id = ARRAYS.insert(ArrayEntry { array })?;
        // SAFETY: as above.
        unsafe { put(out, "out", luxon_array { id }) }
    })
}

struct Update<'a> {
    array: &'a Array,
    first: usize,
}

impl Take for Update<'_> {
    type Out = ();
    fn take<T: Element>(self, v: Vec<T>) -> Result<(), Failure> {
        Ok(self.array.update(self.first, &v)?)
    }
}

/// Writes `count` elements (of the array's type, `stride_bytes` apart at `data`; 0: packed)
/// over elements `first` to `first + count - 1` of a copy array (`luxon_array_create_copy`),
/// waiting for a render that reads it to end, and marks it modified. A shared array is refused
/// (write its memory and call `luxon_array_mark_modified`).
///
/// # Safety
/// `data` is valid for reads of `count` elements at the stride.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_array_update(
    array: luxon_array,
    data: *const c_void,
    first: usize,
    count: usize,
    stride_bytes: usize,
) -> luxon_status {
    guard("luxon_array_update", || {
        let entry = ARRAYS.get(array.id)?;
        let a = &entry.value.array;
        let elem = a.elem();
        let stride = span(data, count, stride_bytes, elem)?;
        let to = Update { array: a, first };
        // SAFETY: readable as checked and promised (caller).
        unsafe { with_elements(elem, data.cast(), count, stride, to) }
    })
}

/// Tells Luxon that elements `first` to `first + count - 1` of a shared array were written
/// (ownership rule 3 of `luxon_array_create_shared`): the next commit reads the objects using
/// the array again (today all of their elements). A range past the array is refused.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_array_mark_modified(
    array: luxon_array,
    first: usize,
    count: usize,
) -> luxon_status {
    guard("luxon_array_mark_modified", || {
        let entry = ARRAYS.get(array.id)?;
        let a = &entry.value.array;
        if first.checked_add(count).is_none_or(|end| end > a.len()) {
            return Err(Failure::invalid(format!(
                "elements {first} to {first}+{count} of an array of {}",
                a.len()
            )));
        }
        a.mark_modified();
        Ok(())
    })
}

/// The number of elements of an array.
///
/// # Safety
/// `count` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_array_count(array: luxon_array, count: *mut usize) -> luxon_status {
    guard("luxon_array_count", || {
        let entry = ARRAYS.get(array.id)?;
        // SAFETY: writable (caller).
        unsafe { put(count, "count", entry.value.array.len()) }
    })
}

/// Releases the handle: it is invalid from now on. Objects of scenes using the array keep it
/// (a shared array's memory is read until the last of them lets it go, then its deleter runs:
/// ownership rule 1 of `luxon_array_create_shared`); an array no object uses goes at once.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_array_release(array: luxon_array) -> luxon_status {
    guard("luxon_array_release", || ARRAYS.release(array.id).map(drop))
}

/// The array a handle names, for a scene object (`what`: the field, for messages); `{0}`:
/// `None`.
pub(crate) fn optional(array: luxon_array, what: &str) -> Result<Option<Array>, Failure> {
    if array.id == 0 {
        return Ok(None);
    }
    required(array, what).map(Some)
}

/// The array a handle names (`{0}` refused, naming the field `what`).
pub(crate) fn required(array: luxon_array, what: &str) -> Result<Array, Failure> {
    if array.id == 0 {
        return Err(Failure::new(
            crate::status::LUXON_ERROR_INVALID_HANDLE,
            format!("`{what}` is a null luxon_array"),
        ));
    }
    let entry = ARRAYS.get(array.id).map_err(|f| Failure {
        message: format!("`{what}`: {}", f.message),
        ..f
    })?;
    Ok(entry.value.array.clone())
}

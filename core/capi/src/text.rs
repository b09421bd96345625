//! Reading what the caller passes: C strings, versioned structs, out-pointers.

use crate::status::Failure;
use std::ffi::{c_char, CStr};

/// The UTF-8 text of a required C string argument named `what`.
///
/// # Safety
/// `p` is NULL or points to a NUL-terminated string that stays valid and unchanged for `'a`.
pub(crate) unsafe fn text<'a>(p: *const c_char, what: &str) -> Result<&'a str, Failure> {
    // SAFETY: as the caller guarantees.
    unsafe { optional_text(p, what) }?.ok_or_else(|| Failure::invalid(format!("`{what}` is NULL")))
}

/// [`text`] for an argument where NULL means "none".
///
/// # Safety
/// As [`text`].
pub(crate) unsafe fn optional_text<'a>(
    p: *const c_char,
    what: &str,
) -> Result<Option<&'a str>, Failure> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: not NULL, and NUL-terminated and valid for 'a as the caller guarantees.
    let bytes = unsafe { CStr::from_ptr(p) }.to_bytes();
    std::str::from_utf8(bytes).map(Some).map_err(|e| {
        Failure::invalid(format!(
            "`{what}` is not UTF-8 text (byte {} of {})",
            e.valid_up_to(),
            bytes.len()
        ))
    })
}

/// A repr(C) struct that starts with its own size (`uint32_t size` = `sizeof`), so fields can
/// be added in later versions: the bytes `size` covers are read (the rest keep the defaults)
/// or written. Its fields are integers, floats and pointers only (no `bool`: any bytes a caller
/// wrote must form a value).
pub(crate) trait Versioned: Copy + Default {}

/// Reads `*p` of type `T` (whose first field is a `u32` size).
///
/// # Safety
/// `p` is NULL or valid for reads of its `size` field and of the `min(size, sizeof(T))` bytes
/// that field covers.
pub(crate) unsafe fn read_sized<T: Versioned>(
    p: *const T,
    what: &str,
    required: usize,
) -> Result<T, Failure> {
    if p.is_null() {
        return Err(Failure::invalid(format!("`{what}` is NULL")));
    }
    // SAFETY: `p` is valid for the read of its leading u32 (the caller's guarantee); it may be
    // unaligned in a packed caller struct, so read it as such.
    let size = unsafe { p.cast::<u32>().read_unaligned() } as usize;
    if size < required {
        return Err(Failure::invalid(format!(
            "`{what}->size` is {size}; expected sizeof (at least {required} bytes; {} in this \
             version)",
            std::mem::size_of::<T>()
        )));
    }
    let mut value = T::default();
    let n = size.min(std::mem::size_of::<T>());
    // SAFETY: `n` bytes are readable at `p` (caller) and writable in `value` (n ≤ sizeof T);
    // T is `Versioned`: integers, floats and pointers only, so any bytes form a value of it.
    unsafe {
        std::ptr::copy_nonoverlapping(p.cast::<u8>(), (&mut value as *mut T).cast::<u8>(), n);
    }
    Ok(value)
}

/// Writes `value` through the out-pointer `out` (named `what`).
///
/// # Safety
/// `out` is NULL or valid for a write of a `T`.
pub(crate) unsafe fn put<T>(out: *mut T, what: &str, value: T) -> Result<(), Failure> {
    if out.is_null() {
        return Err(Failure::invalid(format!("`{what}` is NULL")));
    }
    // SAFETY: not NULL, and valid for the write as the caller guarantees.
    unsafe { out.write(value) };
    Ok(())
}

/// Writes `value` into the caller's struct at `out`, as far as its `size` field says (NULL:
/// nothing is written); the `size` field keeps the caller's value.
///
/// # Safety
/// `out` is NULL or valid for reads of its `size` field and writes of the bytes it covers.
pub(crate) unsafe fn put_sized<T: Versioned>(out: *mut T, value: &T) {
    if out.is_null() {
        return;
    }
    // SAFETY: the caller guarantees the size field is readable.
    let size = unsafe { out.cast::<u32>().read_unaligned() } as usize;
    let n = size.min(std::mem::size_of::<T>());
    if n <= 4 {
        return;
    }
    // SAFETY: `n` bytes after the size field's 4 are writable at `out` (caller) and readable in
    // `value` (n ≤ sizeof T); the two do not overlap (`value` is ours).
    unsafe {
        std::ptr::copy_nonoverlapping(
            (value as *const T).cast::<u8>().add(4),
            out.cast::<u8>().add(4),
            n - 4,
        );
    }
}

//! The guard every entry point runs in: panics caught, the last error set, the handles of a
//! call that panicked poisoned.

use crate::status::{luxon_status, Failure, LUXON_ERROR_PANIC, LUXON_OK};
use std::cell::{Cell, RefCell};
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Once};

thread_local! {
    /// This thread's last error message ("" after a call that succeeded).
    static LAST: RefCell<CString> = RefCell::new(CString::default());
    /// Whether this thread is inside a guarded call (the panic hook records instead of printing).
    static GUARDED: Cell<bool> = const { Cell::new(false) };
    /// The message and place of the last panic in a guarded call.
    static PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
    /// The handles the running call holds: poisoned if it panics.
    static HELD: RefCell<Vec<Arc<dyn Poison>>> = const { RefCell::new(Vec::new()) };
}

/// A handle's entry that an internal error can leave unusable.
pub(crate) trait Poison: Send + Sync {
    fn flag(&self) -> &AtomicBool;
}

/// Remembers that the running call holds `entry` (so a panic poisons it).
pub(crate) fn hold(entry: Arc<dyn Poison>) {
    HELD.with(|h| h.borrow_mut().push(entry));
}

/// Runs the body of the entry point `name`: its error (or panic) becomes the status and the
/// calling thread's last error; success clears the last error.
pub(crate) fn guard(name: &'static str, f: impl FnOnce() -> Result<(), Failure>) -> luxon_status {
    match guarded(name, f) {
        Ok(()) => LUXON_OK,
        Err(e) => e.status,
    }
}

/// [`guard`] for entry points that return a value: `fallback` when the body panics.
pub(crate) fn guard_value<T>(name: &'static str, fallback: T, f: impl FnOnce() -> T) -> T {
    let mut out = None;
    // A panic leaves `out` empty; its message is the last error.
    let _ = guarded(name, || {
        out = Some(f());
        Ok(())
    });
    out.unwrap_or(fallback)
}

fn guarded(name: &'static str, f: impl FnOnce() -> Result<(), Failure>) -> Result<(), Failure> {
    install_hook();
    // A callback may call Luxon from inside a call (a log line during a load): the inner call
    // holds what it adds after `mark`.
    let mark = HELD.with(|h| h.borrow().len());
    let outer = GUARDED.with(|g| g.replace(true));
    let run = catch_unwind(AssertUnwindSafe(|| {
        let result = f();
        // Tests make an entry point panic (after its work, holding its handles) to check the
        // guard, as LUXON_TEST_FAIL_RANK makes an MPI rank fail.
        if std::env::var_os("LUXON_TEST_PANIC").is_some_and(|v| v == name) {
            panic!("panic injected by LUXON_TEST_PANIC");
        }
        result
    }));
    GUARDED.with(|g| g.set(outer));
    let held: Vec<_> = HELD.with(|h| h.borrow_mut().drain(mark..).collect());
    let result = match run {
        Ok(r) => r,
        Err(payload) => {
            for e in &held {
                e.flag().store(true, Ordering::SeqCst);
            }
            let what = PANIC
                .with(|p| p.borrow_mut().take())
                .unwrap_or_else(|| payload_text(payload.as_ref()));
            Err(Failure::new(
                LUXON_ERROR_PANIC,
                format!("internal error in {name} (a bug in Luxon; please report it): {what}"),
            ))
        }
    };
    set_last(match &result {
        Ok(()) => "",
        Err(e) => &e.message,
    });
    result
}

fn payload_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic".to_string()
    }
}

fn set_last(message: &str) {
    let text = luxon_core::error::escape_controls(message).replace('\0', "\\0");
    let text = CString::new(text).unwrap_or_default();
    LAST.with(|l| *l.borrow_mut() = text);
}

/// Panics in a guarded call are recorded for its message instead of printed (the library
/// prints nothing); those of Luxon's render threads go to the log. Any other panic (a host
/// program in Rust that also links this crate) goes to the hook that was there before.
fn install_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let message = payload_text(info.payload());
            let text = match info.location() {
                Some(l) => format!("{message} at {}:{}", l.file(), l.line()),
                None => message,
            };
            if GUARDED.with(|g| g.get()) {
                PANIC.with(|p| *p.borrow_mut() = Some(text));
            } else if std::thread::current()
                .name()
                .is_some_and(|n| n.starts_with("luxon-"))
            {
                luxon_core::error::log(luxon_core::error::Level::Error, &text);
            } else {
                previous(info);
            }
        }));
    });
}

/// The calling thread's message of its last Luxon call that failed, or "" when that call
/// succeeded. Valid until the next Luxon call on this thread (this one excepted); never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_last_error() -> *const c_char {
    // Not through `guard`: reading the message must not clear it. Nothing here can panic
    // but a failed thread-local access (during thread exit), which `catch_unwind` stops.
    catch_unwind(|| LAST.with(|l| l.borrow().as_ptr())).unwrap_or(c"".as_ptr())
}

/// Copies the calling thread's last error message into `buf` (`len` bytes), NUL-terminated and
/// cut at a character boundary if it does not fit, and returns the length of the whole message
/// in bytes (without the NUL): a return value ≥ `len` means it was cut. `buf` may be NULL when
/// `len` is 0 (to ask for the length).
///
/// # Safety
/// `buf` must be valid for writes of `len` bytes (or `len` must be 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_last_error_copy(buf: *mut c_char, len: usize) -> usize {
    catch_unwind(|| {
        LAST.with(|l| {
            let l = l.borrow();
            let bytes = l.as_bytes();
            if buf.is_null() || len == 0 {
                return bytes.len();
            }
            let mut n = bytes.len().min(len - 1);
            // The message is UTF-8: cut before a continuation byte.
            while n > 0 && n < bytes.len() && (bytes[n] & 0xC0) == 0x80 {
                n -= 1;
            }
            // SAFETY: the caller gives `len` writable bytes at `buf`; `n + 1 <= len`, and the
            // message is our own buffer, so the two do not overlap.
            unsafe {
                std::ptr::copy_nonoverlapping(bytes.as_ptr(), buf.cast::<u8>(), n);
                buf.add(n).write(0);
            }
            bytes.len()
        })
    })
    .unwrap_or(0)
}

//! Status codes, and the failure every entry point turns into one and its message.

use luxon_core::Error;
use luxon_formats::SceneError;

/// What a call returns: `LUXON_OK` (0) or one of the `LUXON_ERROR_*` codes, with the reason in
/// `luxon_last_error()`.
pub type luxon_status = i32;

/// The call succeeded.
pub const LUXON_OK: luxon_status = 0;
/// NULL where a value is required, a bad number, text that is not UTF-8, a size that
/// overflows, an unknown format or type code, a buffer that cannot hold the image.
pub const LUXON_ERROR_INVALID_ARGUMENT: luxon_status = 1;
/// A null handle, a released one, one of another kind, or one made unusable by an internal
/// error (release it).
pub const LUXON_ERROR_INVALID_HANDLE: luxon_status = 2;
/// Scene content: a RON fragment (its message starts `<kind>:line:col:`), a scene file, a
/// plugin's error.
pub const LUXON_ERROR_SCENE: luxon_status = 3;
/// No plugin of that name and kind was found (the message lists where Luxon looked).
pub const LUXON_ERROR_PLUGIN_NOT_FOUND: luxon_status = 4;
/// An allocation sized by the caller's data was refused.
pub const LUXON_ERROR_OUT_OF_MEMORY: luxon_status = 5;
/// A file could not be read or written.
pub const LUXON_ERROR_IO: luxon_status = 6;
/// The render was cancelled (`luxon_renderer_cancel`, or a progress callback returned
/// non-zero); the target holds the pixels finished so far.
pub const LUXON_ERROR_CANCELLED: luxon_status = 7;
/// The scene is being rendered or committed on another thread; the call did nothing.
pub const LUXON_ERROR_BUSY: luxon_status = 8;
/// This library cannot do that here: it was built without MPI (the cargo feature `mpi`), or
/// for x86-64-v3 (AVX2, FMA, BMI2) and this CPU lacks them (rebuild with
/// RUSTFLAGS="-C target-cpu=x86-64").
pub const LUXON_ERROR_UNSUPPORTED: luxon_status = 9;
/// MPI cannot be used as asked: not initialised or already finalised, a thread level that
/// forbids the calling thread, a handle that is not a communicator.
pub const LUXON_ERROR_MPI: luxon_status = 10;
/// An internal error (a bug in Luxon; please report it). The process goes on; the handles the
/// call used are unusable from then on (they can only be released).
pub const LUXON_ERROR_PANIC: luxon_status = 11;

/// Why a call failed: its status code and its message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: luxon_status,
    pub message: String,
}

impl Failure {
    pub fn new(status: luxon_status, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }

    pub fn invalid(message: impl Into<String>) -> Failure {
        Failure::new(LUXON_ERROR_INVALID_ARGUMENT, message)
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Failure {
        Failure::new(status_of(&e), e.to_string())
    }
}

/// The status code of a library error.
pub(crate) fn status_of(e: &Error) -> luxon_status {
    match e {
        Error::Scene(SceneError::Io { .. } | SceneError::File { .. }) => LUXON_ERROR_IO,
        Error::Scene(SceneError::At { .. })
        | Error::At { .. }
        | Error::Plugin(_)
        | Error::Render(_) => LUXON_ERROR_SCENE,
        Error::Io { .. } => LUXON_ERROR_IO,
        Error::Usage(_) | Error::Target(_) | Error::Api(_) => LUXON_ERROR_INVALID_ARGUMENT,
        Error::Cancelled => LUXON_ERROR_CANCELLED,
        Error::OutOfMemory { .. } => LUXON_ERROR_OUT_OF_MEMORY,
        Error::Mpi(_) => LUXON_ERROR_MPI,
    }
}

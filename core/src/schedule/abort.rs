//! Ending an MPI job on failure (feature `mpi`): an error or panic on any rank, from any
//! thread, reaches rank 0's stderr and ends every rank (`MPI_Abort`) within seconds.
//!
//! The one place outside the `luxon` command where the library prints: this path belongs to a
//! job whose MPI Luxon owns (the command's), and it ends the process, so its message goes to
//! stderr directly rather than through a log sink that may not exist.

use crate::error::print_error;
use mpi::ffi;
use std::os::raw::{c_int, c_void};
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::{Duration, Instant};

/// Tag of the message carrying a failing rank's cause to rank 0.
pub(super) const TAG_ERROR: i32 = 6;

/// This process's rank while MPI is up (-1 before `MPI_Init_thread` and from `MPI_Finalize` on):
/// read by [`fail`] and [`abort_job`] from any thread.
static RANK: AtomicI32 = AtomicI32::new(-1);

/// Records this process's rank (MPI was just initialised with `MPI_THREAD_MULTIPLE`) and makes a
/// panic on any thread end the whole job.
pub(super) fn on_rank(rank: usize) {
    RANK.store(rank as i32, Ordering::SeqCst);
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        previous(info);
        let p = info.payload();
        let what = p
            .downcast_ref::<&str>()
            .copied()
            .or_else(|| p.downcast_ref::<String>().map(String::as_str))
            .unwrap_or("(no message)");
        let at = info
            .location()
            .map(|l| format!(" at {l}"))
            .unwrap_or_default();
        fail(&format!("panic{at}: {what}"));
    }));
}

/// Ends the whole job: prints `message` (rank 0 prints other ranks' causes for them), then
/// `MPI_Abort`. Callable from any thread, including a panic hook.
pub fn fail(message: &str) -> ! {
    let rank = RANK.load(Ordering::SeqCst);
    if rank > 0 {
        // Rank 0 normally prints the cause and aborts within milliseconds; if it is not
        // listening (busy in a collective), this rank prints it and aborts itself.
        let bytes = message.as_bytes();
        // SAFETY: MPI is up with `MPI_THREAD_MULTIPLE` (`RANK` is set only then), so any thread
        // may call it. The send may read `bytes` for as long as the process runs: this function
        // never returns and `abort_job` exits without unwinding, so `message` outlives it.
        // `req` and `flag` are locals; the `RSMPI_*` statics are rsmpi's constant handles.
        unsafe {
            let mut req = ffi::RSMPI_REQUEST_NULL;
            ffi::MPI_Isend(
                bytes.as_ptr() as *const c_void,
                bytes.len() as c_int,
                ffi::RSMPI_UINT8_T,
                0,
                TAG_ERROR,
                ffi::RSMPI_COMM_WORLD,
                &mut req,
            );
            let deadline = Instant::now() + Duration::from_secs(3);
            let mut flag: c_int = 0;
            while Instant::now() < deadline {
                if flag == 0 {
                    ffi::MPI_Test(&mut req, &mut flag, ffi::RSMPI_STATUS_IGNORE);
                }
                std::thread::sleep(Duration::from_millis(5));
            }
        }
        print_error(&format!("rank {rank}: {message}"));
    } else {
        print_error(message);
    }
    abort_job()
}

fn abort_job() -> ! {
    crate::files::discard_temp_files();
    if RANK.load(Ordering::SeqCst) >= 0 {
        // SAFETY: MPI is up with `MPI_THREAD_MULTIPLE` (`RANK` is set only then), and the call
        // takes the world communicator's handle (rsmpi's constant) and an error code.
        unsafe {
            ffi::MPI_Abort(ffi::RSMPI_COMM_WORLD, 1);
        }
    }
    std::process::exit(1)
}

/// MPI is about to be finalised: from now on a failure ends this process only.
pub(super) fn on_finalize() {
    RANK.store(-1, Ordering::SeqCst);
}

/// A failure injected by tests on one rank: `LUXON_TEST_FAIL_RANK=k` with
/// `LUXON_TEST_FAIL=error` (default) or `panic`, raised when rank k finishes its first unit.
pub(super) struct Injected {
    panic: bool,
    armed: bool,
    pub(super) raised: AtomicBool,
}

impl Injected {
    pub(super) fn from_env(rank: usize) -> Injected {
        let armed =
            std::env::var("LUXON_TEST_FAIL_RANK").is_ok_and(|r| r.trim() == rank.to_string());
        Injected {
            panic: std::env::var("LUXON_TEST_FAIL").is_ok_and(|m| m == "panic"),
            armed,
            raised: AtomicBool::new(false),
        }
    }
    /// The rank's render ended (guest mode): an error injected here if no unit raised it
    /// (under the dynamic decomposition a rank may get no tile at all).
    pub(super) fn on_end(&self) {
        if self.armed && !self.panic {
            self.raised.store(true, Ordering::Relaxed);
        }
    }

    pub(super) fn on_chunk(&self) {
        if self.armed {
            if self.panic {
                panic!("injected panic (LUXON_TEST_FAIL_RANK)");
            }
            self.raised.store(true, Ordering::Relaxed);
        }
    }
}

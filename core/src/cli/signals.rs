//! SIGTERM (what a batch system sends at the time limit), SIGINT (Ctrl-C) and SIGHUP end a run
//! cleanly: its temporary output files are removed, existing outputs stay as they were, and the
//! process exits with status 128 + the signal's number after one `luxon: error:` line.
//!
//! The handler only writes the signal's number into a pipe (all a signal handler may safely
//! do); a watcher thread reads it and does the rest.

#[cfg(unix)]
mod imp {
    use std::ffi::c_int;
    use std::sync::atomic::{AtomicI32, Ordering};

    /// The pipe's writing end, for the handler.
    static PIPE: AtomicI32 = AtomicI32::new(-1);

    const SIGNALS: [(c_int, &str); 3] = [
        (libc::SIGTERM, "SIGTERM"),
        (libc::SIGINT, "SIGINT"),
        (libc::SIGHUP, "SIGHUP"),
    ];

    extern "C" fn on_signal(sig: c_int) {
        let byte = sig as u8;
        // SAFETY: write(2) is async-signal-safe; the descriptor stays open for the process's
        // life, and a failed write only loses the signal's clean handling.
        unsafe {
            libc::write(PIPE.load(Ordering::Relaxed), (&byte as *const u8).cast(), 1);
        }
    }

    pub fn install() {
        let mut fds = [0 as c_int; 2];
        // SAFETY: `fds` has room for the two descriptors.
        if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
            return;
        }
        for fd in fds {
            // SAFETY: a descriptor just created; keeps it out of child processes.
            unsafe { libc::fcntl(fd, libc::F_SETFD, libc::FD_CLOEXEC) };
        }
        PIPE.store(fds[1], Ordering::Relaxed);
        let reader = fds[0];
        let watcher = std::thread::Builder::new()
            .name("signal-watcher".into())
            .spawn(move || loop {
                let mut byte = 0u8;
                // SAFETY: reads one byte into `byte`.
                let n = unsafe { libc::read(reader, (&mut byte as *mut u8).cast(), 1) };
                if n == 1 {
                    interrupted(c_int::from(byte));
                }
                if n == 0 {
                    return;
                }
            });
        if watcher.is_err() {
            return;
        }
        for (sig, _) in SIGNALS {
            // SAFETY: a zeroed sigaction is valid; the handler is async-signal-safe.
            unsafe {
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_signal as extern "C" fn(c_int) as libc::sighandler_t;
                action.sa_flags = libc::SA_RESTART;
                libc::sigemptyset(&mut action.sa_mask);
                libc::sigaction(sig, &action, std::ptr::null_mut());
            }
        }
    }

    fn interrupted(sig: c_int) -> ! {
        let name = SIGNALS
            .iter()
            .find(|(s, _)| *s == sig)
            .map_or("a signal", |(_, n)| n);
        let removed = luxon::files::remove_temp_files();
        let what = if removed > 0 {
            "; unfinished outputs removed, existing files left as they were"
        } else {
            ""
        };
        luxon::error::print_error(&format!("interrupted by {name}{what}"));
        // SAFETY: ends the process at once, without running exit handlers (an MPI library's
        // could wait for ranks that are still rendering).
        unsafe { libc::_exit(128 + sig) }
    }
}

/// Installs the handlers (before any other thread starts, so that every thread has them).
#[cfg(unix)]
pub fn install() {
    imp::install();
}

#[cfg(not(unix))]
pub fn install() {}

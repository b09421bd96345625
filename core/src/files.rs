//! Files appear whole: each is written to a temporary file in the same directory and renamed
//! over the target, so an existing file is never left half-written.
//!
//! A temporary file is named `.{target name}.{pid}.luxon-tmp` and locked (`flock`) by its
//! process for as long as it lives; the kernel drops the lock when the process dies, however it
//! dies. So a run that writes into a directory first removes every `*.luxon-tmp` there whose
//! lock it can take: those belong to dead processes (a render killed with SIGKILL, a node that
//! crashed). Temporary files of older versions (`.{target name}.{pid}.tmp`) are removed when no
//! process of that pid is alive on this host.
//!
//! Every temporary file of this process is recorded, so that a process ending at once (an MPI
//! abort, SIGTERM, SIGINT or SIGHUP: see [`remove_temp_files`]) removes them first.

use crate::error::Error;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The suffix of every temporary file (the sweep looks for it).
const SUFFIX: &str = ".luxon-tmp";

/// A temporary file beside its target, created by this process and locked while it lives.
/// Dropped without [`TempFile::rename`], it is removed.
pub struct TempFile {
    target: PathBuf,
    path: PathBuf,
    file: File,
    renamed: bool,
}

impl TempFile {
    /// Creates the temporary file for `target` (and missing directories), after removing
    /// the temporary files of dead processes in that directory.
    pub fn create(target: &Path) -> Result<TempFile, Error> {
        let io = |source| Error::Io {
            path: target.to_path_buf(),
            source,
        };
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .ok_or_else(|| {
                io(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "the path names no file",
                ))
            })?;
        std::fs::create_dir_all(&dir).map_err(io)?;
        sweep_stale(&dir, &name);
        let pid = std::process::id();
        // Another host's process may have this pid (a shared file system): then a suffix.
        for k in 0..64 {
            let tmp = match k {
                0 => dir.join(format!(".{name}.{pid}{SUFFIX}")),
                k => dir.join(format!(".{name}.{pid}-{k}{SUFFIX}")),
            };
            // Recorded before it exists, so that a signal never leaves it behind.
            pending(&tmp, true);
            let created = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create_new(true)
                .open(&tmp);
            let file = match created {
                Ok(f) => f,
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    pending(&tmp, false);
                    continue;
                }
                Err(e) => {
                    pending(&tmp, false);
                    return Err(io(e));
                }
            };
            let temp = TempFile {
                target: target.to_path_buf(),
                path: tmp,
                file,
                renamed: false,
            };
            match lock(&temp.file, &temp.path) {
                Ok(true) => return Ok(temp),
                // A sweeping process took it for a dead one's before the lock was taken (and
                // holds it, or removed it): make another.
                Ok(false) => continue,
                Err(e) => return Err(io(e)),
            }
        }
        Err(io(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "every temporary file name beside it is taken",
        )))
    }

    pub fn file(&mut self) -> &mut File {
        &mut self.file
    }

    /// The temporary file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file it will replace.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Drops this process's lock while the file stays in use: before MPI-IO writes it from
    /// every rank (on NFS, `flock` is a POSIX lock that MPI-IO's own byte-range locks of other
    /// nodes would wait for). [`OutputSet::commit`](crate::output::OutputSet::commit) still
    /// checks the file is in place.
    pub fn unlock(&self) {
        #[cfg(unix)]
        {
            use std::os::unix::io::AsRawFd;
            // SAFETY: a valid open descriptor.
            unsafe { libc::flock(self.file.as_raw_fd(), libc::LOCK_UN) };
        }
    }

    /// Flushes the file to disk.
    pub fn sync(&mut self) -> Result<(), Error> {
        self.file.sync_all().map_err(|source| Error::Io {
            path: self.target.clone(),
            source,
        })
    }

    /// Renames the file over its target (the commit point of that file).
    pub fn rename(mut self) -> Result<(), Error> {
        let mut files = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        std::fs::rename(&self.path, &self.target).map_err(|source| Error::Io {
            path: self.target.clone(),
            source,
        })?;
        self.renamed = true;
        files.retain(|f| f != &self.path);
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.renamed {
            let _ = std::fs::remove_file(&self.path);
            pending(&self.path, false);
        }
    }
}

/// Writes `bytes` to `path` atomically (temporary file + rename), creating missing directories.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let mut tmp = TempFile::create(path)?;
    tmp.file().write_all(bytes).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    tmp.sync()?;
    tmp.rename()
}

/// Takes this process's lock on a new temporary file; `false` when the file at `path` is no
/// longer the one opened (a sweep removed it in between). A file system without `flock` (Lustre
/// mounted without it, some FUSE ones) leaves the file unlocked: it is written all the same, and
/// a later sweep, unable to lock it either, leaves it alone.
#[cfg(unix)]
fn lock(file: &File, path: &Path) -> std::io::Result<bool> {
    use std::os::unix::fs::MetadataExt;
    use std::os::unix::io::AsRawFd;
    // SAFETY: a valid open descriptor.
    if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
        let e = std::io::Error::last_os_error();
        if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
            return Ok(false);
        }
    }
    let open = file.metadata()?;
    Ok(match std::fs::symlink_metadata(path) {
        Ok(now) => now.dev() == open.dev() && now.ino() == open.ino(),
        Err(_) => false,
    })
}

#[cfg(not(unix))]
fn lock(_: &File, _: &Path) -> std::io::Result<bool> {
    Ok(true)
}

/// A claim on one piece of work shared by several processes (a frame of a sequence): an
/// `flock`ed file that the kernel releases when its process ends, however it ends, so a claim
/// expires with its owner. The file holds "pid P on HOST" for the messages of the others, and
/// stays when the claim is dropped (removing it would race with a process opening it).
pub struct Claim {
    _file: File,
}

impl Claim {
    /// Takes the claim at `path` (creating the file): `None` when a live process holds it.
    /// A file system without `flock` cannot share work: every claim is then taken.
    pub fn try_take(path: &Path) -> std::io::Result<Option<Claim>> {
        // The file is checked to be the one at `path` once locked: if someone replaced it in
        // between, the lock protects nothing and is taken again.
        for _ in 0..16 {
            let mut file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(path)?;
            match lock(&file, path) {
                Ok(true) => {}
                Ok(false) if held_elsewhere(&file) => return Ok(None),
                Ok(false) => continue,
                Err(e) => return Err(e),
            }
            let note = format!("pid {} on {}\n", std::process::id(), host_name());
            file.set_len(0)?;
            file.write_all(note.as_bytes())?;
            return Ok(Some(Claim { _file: file }));
        }
        Err(std::io::Error::other(
            "the claim file kept being replaced by another program",
        ))
    }

    /// Who holds the claim at `path`, as its owner wrote it ("pid 4411 on node7").
    pub fn holder(path: &Path) -> Option<String> {
        let text = std::fs::read_to_string(path).ok()?;
        let line = text.lines().next()?.trim();
        (!line.is_empty()).then(|| line.to_string())
    }
}

/// Whether another open file holds the lock of `file` (a try that would block).
#[cfg(unix)]
fn held_elsewhere(file: &File) -> bool {
    use std::os::unix::io::AsRawFd;
    // SAFETY: a valid open descriptor; a lock taken here is dropped with the file.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    r != 0 && std::io::Error::last_os_error().raw_os_error() == Some(libc::EWOULDBLOCK)
}

#[cfg(not(unix))]
fn held_elsewhere(_: &File) -> bool {
    false
}

/// This machine's name (for messages about other processes).
#[cfg(unix)]
pub fn host_name() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is writable for its length; the name is NUL-terminated when it fits.
    let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if r != 0 {
        return "this host".into();
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

#[cfg(not(unix))]
pub fn host_name() -> String {
    "this host".into()
}

/// Removes the temporary files of dead processes in `dir`: every `*.luxon-tmp` whose lock can be
/// taken, and the old `.{name}.{pid}.tmp` of `name` whose process is gone. Silent: what cannot be
/// removed stays.
#[cfg(unix)]
pub fn sweep_stale(dir: &Path, name: &str) {
    use std::os::unix::io::AsRawFd;
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let legacy = format!(".{name}.");
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(n) = file_name.to_str() else {
            continue;
        };
        let path = entry.path();
        if n.starts_with('.') && n.ends_with(SUFFIX) {
            // Open without creating or following a link; a FIFO does not block the open.
            let Ok(f) = std::fs::OpenOptions::new()
                .read(true)
                .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
                .open(&path)
            else {
                continue;
            };
            // SAFETY: a valid open descriptor; the lock is dropped with `f`.
            if unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } == 0 {
                let _ = std::fs::remove_file(&path);
            }
        } else if let Some(pid) = n
            .strip_prefix(&legacy)
            .and_then(|rest| rest.strip_suffix(".tmp"))
            .and_then(|pid| pid.parse::<libc::pid_t>().ok())
        {
            // SAFETY: signal 0 only asks whether the process exists.
            let gone = pid > 0
                && unsafe { libc::kill(pid, 0) } != 0
                && std::io::Error::last_os_error().raw_os_error() == Some(libc::ESRCH);
            if gone {
                let _ = std::fs::remove_file(&path);
            }
        }
    }
}

#[cfg(not(unix))]
pub fn sweep_stale(_: &Path, _: &str) {}

#[cfg(unix)]
use std::os::unix::fs::OpenOptionsExt;

/// Temporary files of this process, removed by [`remove_temp_files`] when it must end at once.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Records (`add`) or forgets the temporary file `tmp`.
fn pending(tmp: &Path, add: bool) {
    let mut files = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    files.retain(|f| f != tmp);
    if add {
        files.push(tmp.to_path_buf());
    }
}

/// Removes this process's temporary files (before an exit that runs no destructor); returns
/// how many there were. Waits for a rename in progress, so no output is half committed.
pub fn remove_temp_files() -> usize {
    let mut files = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    for f in files.iter() {
        let _ = std::fs::remove_file(f);
    }
    std::mem::take(&mut *files).len()
}

/// [`remove_temp_files`] for a panic hook or an abort, which must not wait for a lock that the
/// failing thread may hold.
pub fn discard_temp_files() {
    if let Ok(mut files) = PENDING.try_lock() {
        for f in files.iter() {
            let _ = std::fs::remove_file(f);
        }
        files.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("luxon-files-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temp() {
        let d = dir("atomic");
        let p = d.join("sub").join("x.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(names(p.parent().unwrap()), ["x.bin"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_temp_file_dropped_unrenamed_is_removed() {
        let d = dir("drop");
        let p = d.join("out.png");
        let t = TempFile::create(&p).unwrap();
        assert_eq!(
            t.path().file_name().unwrap().to_string_lossy(),
            format!(".out.png.{}.luxon-tmp", std::process::id())
        );
        assert!(t.path().exists());
        drop(t);
        assert!(names(&d).is_empty());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_claim_is_held_until_dropped_and_names_its_owner() {
        let d = dir("claim");
        let p = d.join("7");
        let first = Claim::try_take(&p).unwrap().expect("a free claim is taken");
        // flock locks belong to an open file: a second open is another claimant.
        assert!(Claim::try_take(&p).unwrap().is_none());
        let holder = Claim::holder(&p).unwrap();
        assert!(
            holder.starts_with(&format!("pid {} on ", std::process::id())),
            "{holder}"
        );
        drop(first);
        assert!(Claim::try_take(&p).unwrap().is_some());
        assert!(p.exists(), "the claim file stays");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn stale_temps_are_swept_and_live_ones_kept() {
        let d = dir("sweep");
        // Unlocked: its process is gone.
        std::fs::write(d.join(".a.png.999999.luxon-tmp"), b"x").unwrap();
        std::fs::write(d.join(".other.exr.12.luxon-tmp"), b"x").unwrap();
        // An old-style temp of a pid that cannot exist (above any pid_max).
        std::fs::write(d.join(".a.png.2147483600.tmp"), b"x").unwrap();
        // A live one: this process's, locked.
        let live = TempFile::create(&d.join("b.png")).unwrap();
        // Not temporary files: kept.
        std::fs::write(d.join("a.png"), b"x").unwrap();
        std::fs::write(d.join(".a.png.notapid.tmp"), b"x").unwrap();
        let second = TempFile::create(&d.join("a.png")).unwrap();
        let mut want = vec![
            ".a.png.notapid.tmp".to_string(),
            "a.png".to_string(),
            live.path()
                .file_name()
                .unwrap()
                .to_string_lossy()
                .to_string(),
            second
                .path()
                .file_name()
                .unwrap()
                .to_string_lossy()
                .to_string(),
        ];
        want.sort();
        assert_eq!(names(&d), want);
        std::fs::remove_dir_all(&d).unwrap();
    }
}

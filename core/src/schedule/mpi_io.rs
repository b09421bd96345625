//! Concurrent output (the thesis's concurrent I/O): every rank writes the pixels it rendered
//! straight into one shared PPM file with a single collective `MPI_File_write_at_all`, its file
//! view listing where its pixels go. rsmpi has no safe MPI-IO, hence the raw calls.

use crate::framebuffer::Chunk;
use crate::ppm::srgb8;
use mpi::ffi;
use mpi::topology::SimpleCommunicator;
use mpi::traits::AsRaw;
use std::ffi::CString;
use std::os::raw::{c_int, c_void};
use std::path::Path;

/// This rank's bytes of the file (pixel rows start at `base`), as (file offset, length) runs
/// sorted by offset and merged where adjacent, and the bytes themselves.
fn runs(base: u64, header: &[u8], width: u32, chunks: &[Chunk]) -> (Vec<(u64, usize)>, Vec<u8>) {
    let mut pieces: Vec<(u64, Vec<u8>)> = Vec::new();
    if !header.is_empty() {
        pieces.push((0, header.to_vec()));
    }
    for c in chunks {
        let mut px = c.rgba.chunks_exact(4);
        for s in &c.spans {
            let row = base + s.y as u64 * width as u64 * 3;
            if s.step == 1 {
                let mut b = Vec::with_capacity(s.count as usize * 3);
                for _ in 0..s.count {
                    srgb8(px.next().unwrap_or(&[0.0; 4]), &mut b);
                }
                pieces.push((row + s.x0 as u64 * 3, b));
            } else {
                for x in s.xs() {
                    let mut b = Vec::with_capacity(3);
                    srgb8(px.next().unwrap_or(&[0.0; 4]), &mut b);
                    pieces.push((row + x as u64 * 3, b));
                }
            }
        }
    }
    pieces.sort_by_key(|p| p.0);
    let mut runs: Vec<(u64, usize)> = Vec::new();
    let mut data = Vec::new();
    for (off, b) in pieces {
        match runs.last_mut() {
            Some((o, n)) if *o + *n as u64 == off => *n += b.len(),
            _ => runs.push((off, b.len())),
        }
        data.extend(b);
    }
    (runs, data)
}

fn check(what: &str, code: c_int) -> Result<(), String> {
    if code == 0 {
        return Ok(());
    }
    let mut buf = vec![0u8; ffi::MPI_MAX_ERROR_STRING as usize];
    let mut len: c_int = 0;
    // SAFETY: MPI writes at most `MPI_MAX_ERROR_STRING` bytes (the library's own constant) to
    // the string, and `len` is a local.
    unsafe { ffi::MPI_Error_string(code, buf.as_mut_ptr() as *mut _, &mut len) };
    buf.truncate(len.max(0) as usize);
    Err(format!("{what} failed: {}", String::from_utf8_lossy(&buf)))
}

/// Collective over `comm`: writes this rank's pixels (and `header`, non-empty on one rank only)
/// of a `width`×`height` 8-bit PPM to `path`.
pub fn write_ppm(
    comm: &SimpleCommunicator,
    path: &Path,
    header: &[u8],
    width: u32,
    height: u32,
    chunks: &[Chunk],
) -> Result<(), String> {
    let base = crate::ppm::ppm_header(width, height).len() as u64;
    let total = ffi_len(base + width as u64 * height as u64 * 3)?;
    let (runs, data) = runs(base, header, width, chunks);
    let name = CString::new(path.to_string_lossy().as_bytes()).map_err(|e| e.to_string())?;
    let lens: Vec<c_int> = runs.iter().map(|r| r.1 as c_int).collect();
    let offsets: Vec<ffi::MPI_Aint> = runs.iter().map(|r| r.0 as ffi::MPI_Aint).collect();
    let count = ffi_len(data.len() as u64)?;
    let comm = comm.as_raw();
    // SAFETY: MPI is up and `comm` live (a `SimpleCommunicator` exists only while they are).
    // Every pointer is valid for the call it is passed to: `name` is NUL-terminated, `lens` and
    // `offsets` hold `lens.len()` entries each, `data` holds `count` bytes, and `file` and
    // `view` are locals; the `RSMPI_*` statics are rsmpi's constant handles. The derived datatype is freed before returning and the file is closed
    // on every path after a successful open.
    unsafe {
        let byte = ffi::RSMPI_UINT8_T;
        let mut file: ffi::MPI_File = ffi::RSMPI_FILE_NULL;
        let mode = (ffi::MPI_MODE_CREATE | ffi::MPI_MODE_WRONLY) as c_int;
        check(
            "MPI_File_open",
            ffi::MPI_File_open(comm, name.as_ptr(), mode, ffi::RSMPI_INFO_NULL, &mut file),
        )?;
        let mut result = check(
            "MPI_File_set_size",
            ffi::MPI_File_set_size(file, total as ffi::MPI_Offset),
        );
        // A rank with nothing to write still takes part, with a plain byte view.
        let mut view = byte;
        if result.is_ok() && !runs.is_empty() {
            result = check(
                "MPI_Type_create_hindexed",
                ffi::MPI_Type_create_hindexed(
                    lens.len() as c_int,
                    lens.as_ptr(),
                    offsets.as_ptr(),
                    byte,
                    &mut view,
                ),
            )
            .and_then(|_| check("MPI_Type_commit", ffi::MPI_Type_commit(&mut view)));
        }
        if result.is_ok() {
            let native = c"native";
            result = check(
                "MPI_File_set_view",
                ffi::MPI_File_set_view(file, 0, byte, view, native.as_ptr(), ffi::RSMPI_INFO_NULL),
            )
            .and_then(|_| {
                check(
                    "MPI_File_write_at_all",
                    ffi::MPI_File_write_at_all(
                        file,
                        0,
                        data.as_ptr() as *const c_void,
                        count,
                        byte,
                        ffi::RSMPI_STATUS_IGNORE,
                    ),
                )
            });
        }
        if !runs.is_empty() && view != byte {
            ffi::MPI_Type_free(&mut view);
        }
        let closed = check("MPI_File_close", ffi::MPI_File_close(&mut file));
        result.and(closed)
    }
}

fn ffi_len(n: u64) -> Result<c_int, String> {
    c_int::try_from(n).map_err(|_| format!("{n} bytes is too large for one MPI-IO write"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::framebuffer::Span;

    #[test]
    fn runs_are_sorted_and_merged() {
        let chunk = Chunk {
            spans: vec![
                Span {
                    y: 1,
                    x0: 0,
                    step: 1,
                    count: 2,
                },
                Span {
                    y: 0,
                    x0: 1,
                    step: 2,
                    count: 2,
                },
            ],
            rgba: vec![1.0; 16],
            depth: Vec::new(),
        };
        let (r, data) = runs(11, b"P6\n4 2\n255\n", 4, std::slice::from_ref(&chunk));
        // Header (11 bytes); pixel (1,0); pixel (3,0) ends where row 1 begins: merged.
        assert_eq!(r, vec![(0, 11), (14, 3), (20, 9)]);
        assert_eq!(data.len(), 11 + 12);
        // Without the header (another rank's share), pixels stay where they belong.
        let (r, _) = runs(11, b"", 4, &[chunk]);
        assert_eq!(r, vec![(14, 3), (20, 9)]);
    }
}

//! Careless and hostile input files, in every reader (RON and its includes, NFF plain and
//! gzip, OBJ and MTL, `meshes:`): special files refused by type without being read or
//! blocking, lines without end bounded, one UTF-8 byte-order mark skipped, UTF-16 and binary
//! data refused with a message that is safe to print.

mod common;
use common::TempDir;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use luxon_formats::{load, SceneDesc, SceneError};

/// A fresh directory under the system temp dir, removed when dropped.
/// A named pipe `name` in `dir`.
fn fifo(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: `c` is a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
    path
}
const CAMERA: &str = "camera: (position: (0, 0, -5), look_at: (0, 0, 0))";
const NFF: &str = "v\nfrom 0 -10 0\nat 0 0 0\nup 0 0 1\nangle 45\ns 0 0 0 1\n";
const OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// Loads `path` on a thread of its own and waits at most 10 s: a reader that blocks (opening
/// a FIFO waits for a writer) fails the test instead of hanging the suite.
fn load_within_seconds(path: &Path) -> Result<SceneDesc, SceneError> {
    let (tx, rx) = mpsc::channel();
    let path = path.to_path_buf();
    std::thread::spawn(move || {
        let _ = tx.send(load(&path));
    });
    rx.recv_timeout(Duration::from_secs(10))
        .expect("the load blocked on a special file")
}

fn error_text(path: &Path) -> String {
    load_within_seconds(path).unwrap_err().to_string()
}

#[cfg(unix)]
#[test]
fn devices_and_directories_are_refused_by_type() {
    let dir = TempDir::new("devices");
    for ext in ["ron", "nff", "obj"] {
        let link = dir.join(format!("z.{ext}"));
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let what = match ext {
            "ron" => "a scene file",
            "nff" => "an NFF scene file",
            _ => "a Wavefront .obj file",
        };
        assert_eq!(
            error_text(&link),
            format!(
                "`{}` is a character device; expected {what} (a regular file)",
                link.display()
            )
        );
    }
    let main = dir.write(
        "main.ron",
        format!("Scene(include: [\"/dev/zero\"], {CAMERA})"),
    );
    let e = load_within_seconds(&main).unwrap_err();
    let at = e.origin().unwrap();
    assert_eq!((at.line, at.col), (1, 17));
    assert!(
        e.to_string().ends_with(
            "cannot include `/dev/zero`: it is a character device; expected a scene file (a \
             regular file)"
        ),
        "{e}"
    );
    std::fs::create_dir(dir.join("sub.ron")).unwrap();
    dir.write(
        "main.ron",
        format!("Scene(include: [\"sub.ron\"], {CAMERA})"),
    );
    let e = error_text(&main);
    assert!(
        e.contains("it is a directory; expected a scene file"),
        "{e}"
    );
    dir.write(
        "main.ron",
        format!("Scene(meshes: [(file: \"z.obj\")], {CAMERA})"),
    );
    let e = error_text(&main);
    assert!(
        e.ends_with(
            "z.obj` is a character device; expected a Wavefront .obj file (a \
             regular file)"
        ),
        "{e}"
    );
}

#[cfg(unix)]
#[test]
fn fifos_are_refused_without_blocking() {
    let dir = TempDir::new("fifos");
    for name in ["f.ron", "f.nff", "f.obj"] {
        let fifo = fifo(&dir, name);
        let e = error_text(&fifo);
        assert!(e.contains("is a FIFO (named pipe); expected"), "{e}");
    }
    let main = dir.write("main.ron", format!("Scene(include: [\"f.ron\"], {CAMERA})"));
    let e = error_text(&main);
    assert!(e.contains("cannot include"), "{e}");
    assert!(e.contains("it is a FIFO (named pipe)"), "{e}");
    dir.write(
        "main.ron",
        format!("Scene(meshes: [(file: \"f.obj\")], {CAMERA})"),
    );
    assert!(error_text(&main).contains("is a FIFO (named pipe)"));
    // An MTL library on a FIFO: a warning, like any library that cannot be read.
    fifo(&dir, "m.mtl");
    let obj = dir.write("m.obj", format!("mtllib m.mtl\n{OBJ}"));
    let scene = load_within_seconds(&obj).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0]
            .message
            .contains("m.mtl`: it is a FIFO (named pipe), not a regular file"),
        "{}",
        scene.warnings[0]
    );
}

/// `bytes` written to `name`, gzip-compressed for `.gz`.
fn write_maybe_gz(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    if name.ends_with(".gz") {
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(bytes).unwrap();
        dir.write(name, e.finish().unwrap())
    } else {
        dir.write(name, bytes)
    }
}

const BOM: &[u8] = b"\xef\xbb\xbf";

fn with_bom(text: &str) -> Vec<u8> {
    [BOM, text.as_bytes()].concat()
}

#[test]
fn a_utf8_byte_order_mark_is_skipped_in_every_format() {
    let dir = TempDir::new("bom");
    dir.write(
        "inc.ron",
        with_bom("(lights: [Point(position: (0, 0, 0))])"),
    );
    let main = dir.write(
        "main.ron",
        with_bom(&format!("Scene(include: [\"inc.ron\"], {CAMERA})")),
    );
    assert_eq!(load(&main).unwrap().lights.len(), 1);
    for name in ["a.nff", "a.nff.gz"] {
        let nff = write_maybe_gz(&dir, name, &with_bom(NFF));
        let scene = load(&nff).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.inline[0].spheres.len(), 1, "{name}");
        // The geometry cache keeps the view lines: the first one must survive the mark.
        assert!(luxon_formats::nff::skeleton(&nff)
            .unwrap()
            .starts_with("v\nfrom"));
    }
    dir.write("m.mtl", with_bom("newmtl red\nKd 1 0 0\n"));
    let obj = dir.write(
        "a.obj",
        with_bom(&format!("mtllib m.mtl\nusemtl red\n{OBJ}")),
    );
    let scene = load(&obj).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.inline[0].mesh.positions.len(), 3);
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[0].1.value.color, [1.0, 0.0, 0.0]);
}

/// Columns on the first line count from after the mark, as editors show them.
#[test]
fn errors_after_a_byte_order_mark_keep_their_columns() {
    let dir = TempDir::new("bomcol");
    for (name, text) in [
        (
            "e.ron",
            "Scene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)), bogus: 1)",
        ),
        ("e.nff", "v\nfrom 0 0 0 7\n"),
    ] {
        let plain = dir.write(name, text);
        let at = load(&plain).unwrap_err().origin().unwrap().clone();
        let marked = dir.write(name, with_bom(text));
        let at_marked = load(&marked).unwrap_err().origin().unwrap().clone();
        assert_eq!((at.line, at.col), (at_marked.line, at_marked.col), "{name}");
    }
}

#[test]
fn utf16_text_is_refused() {
    let dir = TempDir::new("utf16");
    let utf16 = |text: &str| -> Vec<u8> {
        let mut b = vec![0xff, 0xfe];
        for u in text.encode_utf16() {
            b.extend_from_slice(&u.to_le_bytes());
        }
        b
    };
    for name in ["u.ron", "u.nff", "u.nff.gz", "u.obj"] {
        let path = write_maybe_gz(&dir, name, &utf16("v\n"));
        let e = error_text(&path);
        assert!(e.contains("is UTF-16 text; expected UTF-8"), "{name}: {e}");
    }
    let main = dir.write("main.ron", format!("Scene(include: [\"u.ron\"], {CAMERA})"));
    assert!(error_text(&main).contains("it is UTF-16 text; expected UTF-8"));
}

/// Binary data (here every byte value, as in a corrupt `.nff.gz`) is refused at its first
/// NUL byte, and the message carries no control characters to the terminal.
#[test]
fn binary_data_is_refused_with_a_printable_message() {
    let dir = TempDir::new("binary");
    let bytes: Vec<u8> = (0..=255u8).cycle().take(1024).collect();
    for name in ["b.ron", "b.nff", "b.nff.gz", "b.obj"] {
        let path = write_maybe_gz(&dir, name, &bytes);
        let e = error_text(&path);
        assert!(!e.chars().any(char::is_control), "{name}: {e:?}");
        assert!(
            e.contains("does not look like text (byte 0x00 at line 1, column 1)"),
            "{name}: {e}"
        );
    }
    // Control characters that are not NUL are escaped where a token is echoed.
    let nff = dir.write("c.nff", "\u{1b}[31m 1 2\n");
    let e = error_text(&nff);
    assert!(e.contains("unknown NFF keyword `\\u{1b}[31m`"), "{e}");
}

/// A line without an end (a sparse file, a device) is not collected without bound: NFF
/// lines may be 1 MiB long, OBJ lines 16 MiB.
#[test]
fn lines_without_end_are_bounded() {
    let dir = TempDir::new("lines");
    let nff = dir.write(
        "long.nff",
        format!("# {}\ns 0 0 0 1\n", "x".repeat(2 << 20)),
    );
    let e = load(&nff).unwrap_err();
    let at = e.origin().unwrap();
    assert_eq!((at.line, at.col), (1, 1));
    assert!(
        e.to_string().contains(
            "has a line longer than 1 MiB (line 1); expected an NFF scene file (plain text)"
        ),
        "{e}"
    );
    let obj = dir.write(
        "long.obj",
        format!("{OBJ}# {}\n", "x".repeat((16 << 20) + 1)),
    );
    let e = load(&obj).unwrap_err();
    assert_eq!(e.origin().unwrap().line, 5);
    assert!(
        e.to_string()
            .contains("has a line longer than 16 MiB (line 5)"),
        "{e}"
    );
}

//! Reading input files without trusting them. Shared by the scene readers (luxon-formats) and
//! by plugins that read files (textures, volumes), so that every reader refuses the same things
//! with the same words:
//!
//! - only regular files are opened, and the type is checked *before* `open`: a FIFO is never
//!   opened (opening one blocks until a writer comes), `/dev/zero` is never read (it never
//!   ends), a directory or socket is named as what it is;
//! - a file is read up to a size cap, counted while reading (a file that grows, or a size the
//!   file system does not know, cannot run past it);
//! - text: one UTF-8 byte-order mark at the start is skipped (editors on Windows write one),
//!   UTF-16 text and binary data (a NUL byte) are refused, and a line may be only so long
//!   ([`TextReader`], for readers that go line by line and would otherwise grow one line
//!   without bound).
//!
//! Errors are [`FileError`]s; [`FileError::sentence`] words one as a message naming the file.

use std::fmt;
use std::fs::File;
use std::io::{self, BufRead, Read};
use std::path::Path;

/// Why an input file was refused or could not be read.
#[derive(Debug)]
pub enum FileError {
    /// Nothing at the path.
    Missing,
    /// Not a regular file; says what it is ("a directory", "a FIFO (named pipe)"...).
    NotRegular(&'static str),
    /// Larger than the cap (`size`: what the file system says, or `max + 1` when it grew
    /// past the cap while being read).
    TooLarge { size: u64, max: u64 },
    /// Starts with a UTF-16 byte-order mark.
    Utf16,
    /// A byte no text has (NUL), or not UTF-8; 1-based line and column (in characters).
    NotText { line: u64, col: u64, byte: u8 },
    /// Line `line` is longer than `max` bytes.
    LineTooLong { line: u64, max: u64 },
    /// Any other failure of the system.
    Io(io::Error),
}

impl fmt::Display for FileError {
    /// The problem as a phrase that follows the file's name: "`a.ron` {error}".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FileError::Missing => f.write_str("does not exist"),
            FileError::NotRegular(kind) => write!(f, "is {kind}, not a regular file"),
            FileError::TooLarge { size, max } => write!(
                f,
                "is {}, more than the {} allowed",
                bytes(*size),
                bytes(*max)
            ),
            FileError::Utf16 => f.write_str("is UTF-16 text"),
            FileError::NotText { line, col, byte } => write!(
                f,
                "does not look like text (byte 0x{byte:02x} at line {line}, column {col})"
            ),
            FileError::LineTooLong { line, max } => {
                write!(f, "has a line longer than {} (line {line})", bytes(*max))
            }
            FileError::Io(e) => write!(f, "cannot be read: {e}"),
        }
    }
}

impl std::error::Error for FileError {}

impl FileError {
    /// A whole message: "`{path}` is a FIFO (named pipe); expected {what} (a regular file)".
    /// `what` names what the file should have been, with its article ("a scene file").
    pub fn sentence(&self, path: &Path, what: &str) -> String {
        match self {
            FileError::Io(e) => format!("cannot read `{}`: {e}; expected {what}", path.display()),
            _ => format!("`{}` {}", path.display(), self.explain(what)),
        }
    }

    /// The message without the file's name, to follow it: "is a FIFO (named pipe); expected
    /// {what} (a regular file)".
    pub fn explain(&self, what: &str) -> String {
        match self {
            FileError::Missing => format!("does not exist; expected {what}"),
            FileError::NotRegular(kind) => format!("is {kind}; expected {what} (a regular file)"),
            FileError::TooLarge { size, max } => {
                format!("is {}; {what} may be at most {}", bytes(*size), bytes(*max))
            }
            FileError::Utf16 => format!("is UTF-16 text; expected UTF-8 ({what})"),
            FileError::NotText { .. } | FileError::LineTooLong { .. } => {
                format!("{self}; expected {what} (plain text)")
            }
            FileError::Io(e) => format!("cannot be read: {e}; expected {what}"),
        }
    }

    /// Where in the file the problem is (1-based line and column), when it is in the text.
    pub fn position(&self) -> Option<(u64, u64)> {
        match *self {
            FileError::NotText { line, col, .. } => Some((line, col)),
            FileError::LineTooLong { line, .. } => Some((line, 1)),
            _ => None,
        }
    }

    /// The `FileError` a [`TextReader`] wrapped in an `io::Error`, or `Io(e)`.
    pub fn from_io(e: io::Error) -> FileError {
        if e.get_ref().is_some_and(|inner| inner.is::<FileError>()) {
            let kind = e.kind();
            return match e.into_inner().map(|inner| inner.downcast::<FileError>()) {
                Some(Ok(file_error)) => *file_error,
                Some(Err(other)) => FileError::Io(io::Error::new(kind, other)),
                None => FileError::Io(kind.into()),
            };
        }
        match e.kind() {
            io::ErrorKind::NotFound => FileError::Missing,
            _ => FileError::Io(e),
        }
    }

    fn into_io(self) -> io::Error {
        io::Error::new(io::ErrorKind::InvalidData, self)
    }
}

/// A byte count for messages: "512 bytes", "1 GiB", "1.5 MiB".
pub fn bytes(n: u64) -> String {
    const UNITS: [(u64, &str); 4] = [
        (1 << 40, "TiB"),
        (1 << 30, "GiB"),
        (1 << 20, "MiB"),
        (1 << 10, "KiB"),
    ];
    for (size, unit) in UNITS {
        if n >= size {
            return if n.is_multiple_of(size) {
                format!("{} {unit}", n / size)
            } else {
                format!("{:.1} {unit}", n as f64 / size as f64)
            };
        }
    }
    format!("{n} bytes")
}

/// What a file system object that is not a regular file is, in words ("a directory", "a FIFO
/// (named pipe)", ...); the host's plugin loader says it the same way.
#[cfg(unix)]
pub fn kind_of(t: std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

#[cfg(not(unix))]
pub fn kind_of(t: std::fs::FileType) -> &'static str {
    if t.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// Opens `path` for reading if it is a regular file of at most `max` bytes; returns it and
/// its size. The type is checked before opening (symbolic links are followed), and again on
/// the open file, in case the path was replaced in between.
pub fn open_regular(path: &Path, max: u64) -> Result<(File, u64), FileError> {
    let check = |meta: std::fs::Metadata| {
        if !meta.is_file() {
            return Err(FileError::NotRegular(kind_of(meta.file_type())));
        }
        if meta.len() > max {
            return Err(FileError::TooLarge {
                size: meta.len(),
                max,
            });
        }
        Ok(meta.len())
    };
    check(std::fs::metadata(path).map_err(FileError::from_io)?)?;
    let file = File::open(path).map_err(FileError::from_io)?;
    let len = check(file.metadata().map_err(FileError::Io)?)?;
    Ok((file, len))
}

/// The bytes of a regular file of at most `max` bytes (see [`open_regular`]).
pub fn read_capped(path: &Path, max: u64) -> Result<Vec<u8>, FileError> {
    let (file, len) = open_regular(path, max)?;
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(len as usize)
        .map_err(|e| FileError::Io(io::Error::new(io::ErrorKind::OutOfMemory, e)))?;
    // One byte past the cap tells a file that grew past it from one that fits.
    file.take(max.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(FileError::Io)?;
    if bytes.len() as u64 > max {
        return Err(FileError::TooLarge {
            size: bytes.len() as u64,
            max,
        });
    }
    Ok(bytes)
}

/// The text of a regular file of at most `max` bytes (see [`open_regular`] and [`text`]).
pub fn read_text(path: &Path, max: u64) -> Result<String, FileError> {
    text(read_capped(path, max)?)
}

/// Bytes as text: one leading UTF-8 byte-order mark removed; UTF-16, NUL bytes and invalid
/// UTF-8 refused with their position.
pub fn text(mut bytes: Vec<u8>) -> Result<String, FileError> {
    match bom(&bytes) {
        Bom::Utf8 => {
            bytes.drain(..3);
        }
        Bom::Utf16 => return Err(FileError::Utf16),
        Bom::None => {}
    }
    // The first NUL byte or invalid UTF-8, whichever comes first.
    let nul = bytes.iter().position(|&b| b == 0);
    let invalid = std::str::from_utf8(&bytes).err().map(|e| e.valid_up_to());
    let bad = match (nul, invalid) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    if let Some(at) = bad {
        let (line, col) = line_col(&bytes[..at]);
        return Err(FileError::NotText {
            line,
            col,
            byte: bytes[at],
        });
    }
    Ok(String::from_utf8(bytes).expect("checked to be UTF-8 above"))
}

/// 1-based line and column (in characters) just after `prefix`.
fn line_col(prefix: &[u8]) -> (u64, u64) {
    let line_start = prefix
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let line = 1 + prefix.iter().filter(|&&b| b == b'\n').count() as u64;
    (line, 1 + chars(&prefix[line_start..]))
}

/// Characters in UTF-8 bytes (continuation bytes do not count).
fn chars(bytes: &[u8]) -> u64 {
    bytes.iter().filter(|&&b| (b & 0xc0) != 0x80).count() as u64
}

enum Bom {
    None,
    Utf8,
    Utf16,
}

fn bom(start: &[u8]) -> Bom {
    if start.starts_with(&[0xef, 0xbb, 0xbf]) {
        Bom::Utf8
    } else if start.starts_with(&[0xff, 0xfe]) || start.starts_with(&[0xfe, 0xff]) {
        Bom::Utf16
    } else {
        Bom::None
    }
}

/// Text read as a stream: skips one UTF-8 byte-order mark at the start, refuses UTF-16 and
/// NUL bytes, and fails when a line grows longer than `max_line` bytes, so that a reader
/// that collects lines (or blocks of lines) never holds more than that of one line. Counts
/// lines for messages. Its errors are `io::Error`s holding a [`FileError`]
/// ([`FileError::from_io`] gets it back).
///
/// Works through `read` and through `fill_buf`/`consume`; checks what is handed out (by
/// `read`) or consumed, and reports a problem found while consuming at the next call.
pub struct TextReader<R> {
    inner: R,
    /// The first bytes, read to look for a byte-order mark, not yet handed out.
    head: [u8; 3],
    head_len: usize,
    head_pos: usize,
    started: bool,
    count: Counter,
    /// A problem found in bytes already consumed, reported by the next call.
    failed: Option<FileError>,
}

/// Lines of the text handed out so far.
struct Counter {
    max_line: u64,
    newlines: u64,
    /// Bytes and characters of the current line so far.
    line_bytes: u64,
    line_chars: u64,
    /// The last byte counted.
    last: u8,
}

impl Counter {
    /// The line the next byte is on.
    fn line(&self) -> u64 {
        self.newlines + 1
    }

    /// The line of the last byte counted (1 before any).
    fn last_line(&self) -> u64 {
        if self.last == b'\n' {
            self.newlines.max(1)
        } else {
            self.newlines + 1
        }
    }

    /// Accounts for `bytes`; the first problem in them, if any. Text is checked in parts of
    /// at most `PART` bytes: in a part, only its first and last line can be longer than the
    /// part, so a part without a NUL byte needs a search for its first and last newline
    /// (short, in text), a count of its newlines and a search for NUL (both vectorised),
    /// rather than a look at every line.
    fn check(&mut self, bytes: &[u8]) -> Result<(), FileError> {
        const PART: usize = 64 << 10;
        if self.max_line < PART as u64 {
            return self.check_lines(bytes);
        }
        for part in bytes.chunks(PART) {
            if part.contains(&0) {
                return self.check_lines(part);
            }
            match part.iter().position(|&b| b == b'\n') {
                None => {
                    self.fits(part.len())?;
                    self.line_bytes += part.len() as u64;
                    self.line_chars += chars(part);
                }
                Some(first) => {
                    self.fits(first)?;
                    let last = part.iter().rposition(|&b| b == b'\n').unwrap_or(first);
                    self.newlines += part.iter().filter(|&&b| b == b'\n').count() as u64;
                    let tail = &part[last + 1..];
                    self.line_bytes = tail.len() as u64;
                    self.line_chars = chars(tail);
                }
            }
            if let Some(&b) = part.last() {
                self.last = b;
            }
        }
        Ok(())
    }

    /// `check`, line by line: finds the NUL byte's column, and serves caps below a part.
    fn check_lines(&mut self, bytes: &[u8]) -> Result<(), FileError> {
        if let Some(at) = bytes.iter().position(|&b| b == 0) {
            self.check_lines(&bytes[..at])?;
            return Err(FileError::NotText {
                line: self.line(),
                col: self.line_chars + 1,
                byte: 0,
            });
        }
        let mut segments = bytes.split(|&b| b == b'\n');
        let mut segment = segments.next().unwrap_or_default();
        for next in segments {
            self.fits(segment.len())?;
            self.newlines += 1;
            self.line_bytes = 0;
            self.line_chars = 0;
            segment = next;
        }
        self.fits(segment.len())?;
        self.line_bytes += segment.len() as u64;
        self.line_chars += chars(segment);
        if let Some(&b) = bytes.last() {
            self.last = b;
        }
        Ok(())
    }

    /// The current line grown by `more` bytes must fit.
    fn fits(&self, more: usize) -> Result<(), FileError> {
        if self.line_bytes + more as u64 > self.max_line {
            return Err(FileError::LineTooLong {
                line: self.line(),
                max: self.max_line,
            });
        }
        Ok(())
    }
}

impl<R: Read> TextReader<R> {
    pub fn new(inner: R, max_line: u64) -> TextReader<R> {
        TextReader {
            inner,
            head: [0; 3],
            head_len: 0,
            head_pos: 0,
            started: false,
            count: Counter {
                max_line,
                newlines: 0,
                line_bytes: 0,
                line_chars: 0,
                last: b'\n',
            },
            failed: None,
        }
    }

    /// The 1-based line of the last byte handed out (or consumed): after a whole line has
    /// been read, that line.
    pub fn line(&self) -> u64 {
        self.count.last_line()
    }

    /// Reads the first bytes and looks for a byte-order mark.
    fn start(&mut self) -> io::Result<()> {
        if self.started {
            return Ok(());
        }
        while self.head_len < 3 {
            match self.inner.read(&mut self.head[self.head_len..]) {
                Ok(0) => break,
                Ok(n) => self.head_len += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        self.started = true;
        match bom(&self.head[..self.head_len]) {
            Bom::Utf8 => self.head_pos = 3,
            Bom::Utf16 => return Err(FileError::Utf16.into_io()),
            Bom::None => {}
        }
        Ok(())
    }
}

impl<R: Read> Read for TextReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if let Some(e) = self.failed.take() {
            return Err(e.into_io());
        }
        self.start()?;
        let n = if self.head_pos < self.head_len {
            let n = (self.head_len - self.head_pos).min(buf.len());
            buf[..n].copy_from_slice(&self.head[self.head_pos..self.head_pos + n]);
            self.head_pos += n;
            n
        } else {
            self.inner.read(buf)?
        };
        self.count.check(&buf[..n]).map_err(FileError::into_io)?;
        Ok(n)
    }
}

impl<R: BufRead> BufRead for TextReader<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if let Some(e) = self.failed.take() {
            return Err(e.into_io());
        }
        self.start()?;
        if self.head_pos < self.head_len {
            return Ok(&self.head[self.head_pos..self.head_len]);
        }
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        if amt == 0 {
            return;
        }
        let result = if self.head_pos < self.head_len {
            let n = amt.min(self.head_len - self.head_pos);
            self.head_pos += n;
            self.count
                .check(&self.head[self.head_pos - n..self.head_pos])
        } else {
            // The buffer is already filled: this returns it without reading.
            let result = match self.inner.fill_buf() {
                Ok(buf) => self.count.check(&buf[..amt.min(buf.len())]),
                Err(_) => Ok(()),
            };
            self.inner.consume(amt);
            result
        };
        if let Err(e) = result {
            self.failed.get_or_insert(e);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A fresh directory, removed when dropped.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> TempDir {
            let dir =
                std::env::temp_dir().join(format!("luxon-sdk-files-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            TempDir(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// Hands out one byte per `read`, as a slow pipe or decoder may.
    struct Trickle<'a>(&'a [u8]);

    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            match (self.0.split_first(), buf.first_mut()) {
                (Some((&b, rest)), Some(slot)) => {
                    *slot = b;
                    self.0 = rest;
                    Ok(1)
                }
                _ => Ok(0),
            }
        }
    }

    #[test]
    fn only_regular_files_are_opened() {
        let dir = TempDir::new("types");
        let missing = open_regular(&dir.0.join("nope"), 100).unwrap_err();
        assert!(matches!(missing, FileError::Missing), "{missing:?}");
        let e = open_regular(&dir.0, 100).unwrap_err();
        assert_eq!(
            e.sentence(&dir.0, "a scene file"),
            format!(
                "`{}` is a directory; expected a scene file (a regular file)",
                dir.0.display()
            )
        );
        let file = dir.0.join("ok.txt");
        std::fs::write(&file, "hello").unwrap();
        assert_eq!(open_regular(&file, 5).unwrap().1, 5);
        let e = open_regular(&file, 4).unwrap_err();
        assert!(
            matches!(e, FileError::TooLarge { size: 5, max: 4 }),
            "{e:?}"
        );
        assert!(
            e.sentence(&file, "a scene file")
                .ends_with("is 5 bytes; a scene file may be at most 4 bytes"),
            "{e}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_sockets_are_named() {
        let e = open_regular(Path::new("/dev/zero"), 1 << 30).unwrap_err();
        assert_eq!(e.to_string(), "is a character device, not a regular file");
        let dir = TempDir::new("socket");
        let path = dir.0.join("s");
        let _listener = std::os::unix::net::UnixListener::bind(&path).unwrap();
        let e = read_text(&path, 100).unwrap_err();
        assert_eq!(e.to_string(), "is a socket, not a regular file");
        // A symbolic link is followed to what it names.
        let link = dir.0.join("zero");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        assert!(matches!(
            read_capped(&link, 100),
            Err(FileError::NotRegular("a character device"))
        ));
    }

    #[test]
    fn text_skips_a_bom_and_refuses_utf16_and_binary() {
        assert_eq!(text(b"\xef\xbb\xbfScene()".to_vec()).unwrap(), "Scene()");
        // Only one mark is skipped: a second one is text.
        assert_eq!(
            text(b"\xef\xbb\xbf\xef\xbb\xbfx".to_vec()).unwrap(),
            "\u{feff}x"
        );
        assert!(matches!(
            text(b"\xff\xfeS\0".to_vec()),
            Err(FileError::Utf16)
        ));
        assert!(matches!(
            text(b"\xfe\xff\0S".to_vec()),
            Err(FileError::Utf16)
        ));
        let e = text("ab\ncé\0".as_bytes().to_vec()).unwrap_err();
        assert!(
            matches!(
                e,
                FileError::NotText {
                    line: 2,
                    col: 3,
                    byte: 0
                }
            ),
            "{e:?}"
        );
        assert_eq!(e.position(), Some((2, 3)));
        let e = text(b"\n\nabc\xff".to_vec()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "does not look like text (byte 0xff at line 3, column 4)"
        );
    }

    #[test]
    fn text_reader_skips_a_bom_however_the_bytes_come() {
        let input = b"\xef\xbb\xbfv 1 2 3\nf 1 2 3\n";
        let mut out = String::new();
        TextReader::new(Trickle(input), 100)
            .read_to_string(&mut out)
            .unwrap();
        assert_eq!(out, "v 1 2 3\nf 1 2 3\n");
        let lines: Vec<String> = TextReader::new(io::BufReader::new(&input[..]), 100)
            .lines()
            .map(Result::unwrap)
            .collect();
        assert_eq!(lines, ["v 1 2 3", "f 1 2 3"]);
        // Shorter than a mark.
        let mut out = String::new();
        TextReader::new(&b"ab"[..], 100)
            .read_to_string(&mut out)
            .unwrap();
        assert_eq!(out, "ab");
        let e = TextReader::new(&b"\xff\xfe\0a"[..], 100)
            .read_to_end(&mut Vec::new())
            .unwrap_err();
        assert!(matches!(FileError::from_io(e), FileError::Utf16));
    }

    #[test]
    fn text_reader_bounds_lines_and_refuses_nul() {
        let long = format!("a\nbb\n{}\nc\n", "x".repeat(11));
        // Through `read` (block readers)...
        let e = TextReader::new(Trickle(long.as_bytes()), 10)
            .read_to_end(&mut Vec::new())
            .unwrap_err();
        let e = FileError::from_io(e);
        assert!(
            matches!(e, FileError::LineTooLong { line: 3, max: 10 }),
            "{e:?}"
        );
        // ...and through `lines` (line readers): the lines before it come out whole.
        let mut lines =
            TextReader::new(io::BufReader::with_capacity(4, long.as_bytes()), 10).lines();
        assert_eq!(lines.next().unwrap().unwrap(), "a");
        assert_eq!(lines.next().unwrap().unwrap(), "bb");
        let e = FileError::from_io(lines.next().unwrap().unwrap_err());
        assert!(matches!(e, FileError::LineTooLong { line: 3, .. }), "{e:?}");
        // A line of exactly the cap is fine.
        let mut out = Vec::new();
        TextReader::new(&b"0123456789\n0123456789"[..], 10)
            .read_to_end(&mut out)
            .unwrap();
        assert_eq!(out.len(), 21);

        let e = TextReader::new("ok\né\0".as_bytes(), 100)
            .read_to_end(&mut Vec::new())
            .unwrap_err();
        let e = FileError::from_io(e);
        assert!(
            matches!(
                e,
                FileError::NotText {
                    line: 2,
                    col: 2,
                    byte: 0
                }
            ),
            "{e:?}"
        );
        let mut r = TextReader::new(&b"a\nb\nc"[..], 100);
        r.read_to_end(&mut Vec::new()).unwrap();
        assert_eq!(r.line(), 3);
        let mut r = TextReader::new(&b"a\nb\n"[..], 100);
        assert_eq!(r.line(), 1);
        r.read_line(&mut String::new()).unwrap();
        assert_eq!(r.line(), 1);
        r.read_line(&mut String::new()).unwrap();
        assert_eq!(r.line(), 2);
    }

    /// Caps of a part (64 KiB) or more take the fast path: the same lines and errors.
    #[test]
    fn text_reader_counts_lines_in_large_reads() {
        let mut text = "abc\n".repeat(100_000);
        let mut r = TextReader::new(text.as_bytes(), 1 << 20);
        r.read_to_end(&mut Vec::new()).unwrap();
        assert_eq!(r.line(), 100_000);
        text.push_str(&"x".repeat((1 << 20) + 1));
        text.push('\n');
        let e = TextReader::new(text.as_bytes(), 1 << 20)
            .read_to_end(&mut Vec::new())
            .unwrap_err();
        let e = FileError::from_io(e);
        assert!(
            matches!(
                e,
                FileError::LineTooLong {
                    line: 100_001,
                    max: 1_048_576
                }
            ),
            "{e:?}"
        );
        let text = format!("{}ab\0", "é\n".repeat(70_000));
        let e = TextReader::new(text.as_bytes(), 1 << 20)
            .read_to_end(&mut Vec::new())
            .unwrap_err();
        let e = FileError::from_io(e);
        assert!(
            matches!(
                e,
                FileError::NotText {
                    line: 70_001,
                    col: 3,
                    byte: 0
                }
            ),
            "{e:?}"
        );
    }

    #[test]
    fn byte_counts_read_well() {
        assert_eq!(bytes(512), "512 bytes");
        assert_eq!(bytes(1 << 30), "1 GiB");
        assert_eq!(bytes(3 << 19), "1.5 MiB");
    }
}

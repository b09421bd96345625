//! A plugin library's file checked before it is handed to the dynamic loader.
//!
//! `dlopen` maps a library's segments as its program headers declare them. When the file is
//! shorter than that (an interrupted copy or build), touching a page past its end raises SIGBUS
//! and the process dies without a word, even when the scene never uses that library. So the
//! loader reads the ELF header and the program headers first (two reads, no mapping) and refuses
//! a file whose segments or section headers lie beyond its end, or that was built for another
//! machine. The same pass finds the library's name table (`luxon_plugin::names`): the section
//! headers, their string table and the section, three small reads more. What stays out of
//! reach: a library rewritten while it is mapped, a truncated dependency of a plugin (`ld.so`
//! loads it), and a library whose initialisers crash.
//!
//! On platforms whose libraries are not ELF (macOS, Windows) the check passes everything.

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// What the check read beside its verdict.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Checked {
    /// The bytes of the library's name table section (`luxon_plugin::names::SECTION`), if it
    /// has one that lies in the file; `None` for a library built without it, or whose section
    /// headers this reader does not follow (it is then loaded to learn its names).
    pub names: Option<Vec<u8>>,
}

/// Checks the library at `path` (a regular file) before it is loaded, and reads its name table;
/// the error says why it cannot be loaded, in words that follow its path.
pub fn check_library(path: &Path) -> Result<Checked, String> {
    if !cfg!(all(unix, not(target_vendor = "apple"))) {
        return Ok(Checked::default());
    }
    let mut file = std::fs::File::open(path).map_err(|e| format!("cannot be read: {e}"))?;
    let len = file
        .metadata()
        .map_err(|e| format!("cannot be read: {e}"))?
        .len();
    check(&mut file, len, &Host::this())
}

/// What a library must have been built for.
struct Host {
    /// `ELFCLASS64` (2) or `ELFCLASS32` (1).
    class: u8,
    little_endian: bool,
    /// `e_machine`; `None` where this check does not know the architecture's number.
    machine: Option<u16>,
}

impl Host {
    fn this() -> Host {
        let machine = if cfg!(target_arch = "x86_64") {
            Some(62)
        } else if cfg!(target_arch = "aarch64") {
            Some(183)
        } else if cfg!(target_arch = "riscv64") {
            Some(243)
        } else if cfg!(target_arch = "powerpc64") {
            Some(21)
        } else if cfg!(target_arch = "x86") {
            Some(3)
        } else if cfg!(target_arch = "arm") {
            Some(40)
        } else {
            None
        };
        Host {
            class: if cfg!(target_pointer_width = "64") {
                2
            } else {
                1
            },
            little_endian: cfg!(target_endian = "little"),
            machine,
        }
    }
}

const ET_DYN: u16 = 3;
/// Program header types whose bytes the loader reads from the file.
const PT_LOAD: u32 = 1;
const PT_DYNAMIC: u32 = 2;
const PT_INTERP: u32 = 3;
const PT_NOTE: u32 = 4;
const PT_TLS: u32 = 7;
/// More program headers than this would be counted elsewhere (`PN_XNUM`): never in a plugin.
const MAX_PHNUM: u16 = 0xfffe;

/// Fields read in the file's byte order.
struct Fields<'a> {
    bytes: &'a [u8],
    little: bool,
}

impl Fields<'_> {
    fn u16(&self, at: usize) -> u16 {
        let b = [self.bytes[at], self.bytes[at + 1]];
        if self.little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        }
    }

    fn u32(&self, at: usize) -> u32 {
        let b: [u8; 4] = self.bytes[at..at + 4].try_into().unwrap_or_default();
        if self.little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        }
    }

    fn u64(&self, at: usize) -> u64 {
        let b: [u8; 8] = self.bytes[at..at + 8].try_into().unwrap_or_default();
        if self.little {
            u64::from_le_bytes(b)
        } else {
            u64::from_be_bytes(b)
        }
    }

    /// A 64-bit field of ELF64, a 32-bit one of ELF32.
    fn word(&self, wide: bool, at64: usize, at32: usize) -> u64 {
        if wide {
            self.u64(at64)
        } else {
            u64::from(self.u32(at32))
        }
    }
}

fn truncated(what: &str, start: u64, end: u64, len: u64) -> String {
    format!(
        "is a truncated ELF file: {what} needs bytes {start}..{end} but the file has {len} bytes \
         (an interrupted copy or build?)"
    )
}

/// The check itself, on any seekable bytes of length `len`.
fn check(file: &mut (impl Read + Seek), len: u64, host: &Host) -> Result<Checked, String> {
    let io = |e: std::io::Error| format!("cannot be read: {e}");
    let mut ident = [0u8; 64];
    let head_len = len.min(64) as usize;
    file.read_exact(&mut ident[..head_len]).map_err(io)?;
    if head_len < 4 || ident[..4] != *b"\x7fELF" {
        return Err("is not a shared library (no ELF header)".into());
    }
    let wide = match ident[4] {
        2 => true,
        1 => false,
        c => return Err(format!("is not a valid ELF file (class {c})")),
    };
    let header_len = if wide { 64 } else { 52 };
    if len < header_len {
        return Err(format!(
            "is a truncated ELF file: its header needs {header_len} bytes but the file has {len} bytes"
        ));
    }
    if ident[4] != host.class {
        let bits = if wide { 64 } else { 32 };
        return Err(format!("was built for a {bits}-bit system"));
    }
    let little = match ident[5] {
        1 => true,
        2 => false,
        d => return Err(format!("is not a valid ELF file (data encoding {d})")),
    };
    if little != host.little_endian {
        return Err("was built for another byte order".into());
    }
    let f = Fields {
        bytes: &ident,
        little,
    };
    let e_type = f.u16(16);
    if e_type != ET_DYN {
        return Err(format!("is not a shared library (ELF type {e_type})"));
    }
    let machine = f.u16(18);
    if host.machine.is_some_and(|m| m != machine) {
        return Err(format!(
            "was built for another processor (ELF machine {machine})"
        ));
    }
    let phoff = f.word(wide, 32, 28);
    let shoff = f.word(wide, 40, 32);
    let (phentsize, phnum) = if wide {
        (f.u16(54), f.u16(56))
    } else {
        (f.u16(42), f.u16(44))
    };
    let (shentsize, shnum) = if wide {
        (f.u16(58), f.u16(60))
    } else {
        (f.u16(46), f.u16(48))
    };
    let want_phentsize = if wide { 56 } else { 32 };
    if phentsize != want_phentsize || phnum == 0 || phnum > MAX_PHNUM {
        return Err(format!(
            "is not a valid shared library ({phnum} program headers of {phentsize} bytes)"
        ));
    }
    let table = u64::from(phnum) * u64::from(phentsize);
    let table_end = phoff.saturating_add(table);
    if table_end > len {
        return Err(truncated("its program header table", phoff, table_end, len));
    }
    // At most 0xfffe × 56 bytes (3.5 MiB); real libraries have about a dozen headers.
    let mut headers = vec![0u8; table as usize];
    file.seek(SeekFrom::Start(phoff)).map_err(io)?;
    file.read_exact(&mut headers).map_err(io)?;
    let f = Fields {
        bytes: &headers,
        little,
    };
    for k in 0..usize::from(phnum) {
        let at = k * usize::from(phentsize);
        let p_type = f.u32(at);
        if !matches!(p_type, PT_LOAD | PT_DYNAMIC | PT_INTERP | PT_NOTE | PT_TLS) {
            continue;
        }
        let offset = f.word(wide, at + 8, at + 4);
        let filesz = f.word(wide, at + 32, at + 16);
        let end = offset.saturating_add(filesz);
        if end > len {
            return Err(truncated(&format!("its segment {k}"), offset, end, len));
        }
    }
    // The loader does not need the section headers, but a file cut short of them is broken.
    if shoff == 0 {
        return Ok(Checked::default());
    }
    let end = shoff.saturating_add(u64::from(shnum) * u64::from(shentsize));
    if end > len {
        return Err(truncated("its section header table", shoff, end, len));
    }
    let shstrndx = f_u16(&ident, little, if wide { 62 } else { 50 });
    let sections = Sections {
        wide,
        little,
        shoff,
        shnum,
        shentsize,
        shstrndx,
        len,
    };
    Ok(Checked {
        names: sections.find(file, luxon_plugin::names::SECTION)?,
    })
}

fn f_u16(bytes: &[u8], little: bool, at: usize) -> u16 {
    Fields { bytes, little }.u16(at)
}

/// Undefined section index, and `e_shstrndx`'s escape to a larger index (not followed here).
const SHN_UNDEF: u16 = 0;
const SHN_XINDEX: u16 = 0xffff;
/// A section that occupies no bytes in the file.
const SHT_NOBITS: u32 = 8;
/// Section names longer than this are not looked at (`.shstrtab` is a few hundred bytes).
const MAX_SHSTRTAB: u64 = 1 << 20;

/// The section header table of a checked file (which lies inside it).
struct Sections {
    wide: bool,
    little: bool,
    shoff: u64,
    shnum: u16,
    shentsize: u16,
    shstrndx: u16,
    len: u64,
}

impl Sections {
    /// The bytes of the section named `name`: `None` when there is none, or when the table is
    /// laid out in a way not followed here (so the library is loaded as one without it); an
    /// error when the section's bytes lie past the end of the file.
    fn find(&self, file: &mut (impl Read + Seek), name: &str) -> Result<Option<Vec<u8>>, String> {
        let io = |e: std::io::Error| format!("cannot be read: {e}");
        let want = if self.wide { 64 } else { 40 };
        if self.shentsize != want
            || self.shnum == 0
            || matches!(self.shstrndx, SHN_UNDEF | SHN_XINDEX)
            || self.shstrndx >= self.shnum
        {
            return Ok(None);
        }
        let mut table = vec![0u8; usize::from(self.shnum) * usize::from(want)];
        file.seek(SeekFrom::Start(self.shoff)).map_err(io)?;
        file.read_exact(&mut table).map_err(io)?;
        let f = Fields {
            bytes: &table,
            little: self.little,
        };
        let w = self.wide;
        // (name offset, type, file offset, size) of section `k`.
        let header = |k: usize| {
            let at = k * usize::from(want);
            (
                f.u32(at),
                f.u32(at + 4),
                f.word(w, at + 24, at + 16),
                f.word(w, at + 32, at + 20),
            )
        };
        let (_, _, str_off, str_size) = header(usize::from(self.shstrndx));
        if str_size > MAX_SHSTRTAB || str_off.saturating_add(str_size) > self.len {
            return Ok(None);
        }
        let mut names = vec![0u8; str_size as usize];
        file.seek(SeekFrom::Start(str_off)).map_err(io)?;
        file.read_exact(&mut names).map_err(io)?;
        let named = |at: u32| {
            let rest = names.get(at as usize..).unwrap_or_default();
            let end = rest.iter().position(|&b| b == 0).unwrap_or(rest.len());
            &rest[..end]
        };
        let Some((_, kind, offset, size)) = (0..usize::from(self.shnum))
            .map(header)
            .find(|h| named(h.0) == name.as_bytes())
        else {
            return Ok(None);
        };
        if kind == SHT_NOBITS || size > luxon_plugin::names::MAX_TABLE as u64 {
            return Ok(None);
        }
        let end = offset.saturating_add(size);
        if end > self.len {
            return Err(truncated(
                &format!("its section {name}"),
                offset,
                end,
                self.len,
            ));
        }
        let mut bytes = vec![0u8; size as usize];
        file.seek(SeekFrom::Start(offset)).map_err(io)?;
        file.read_exact(&mut bytes).map_err(io)?;
        Ok(Some(bytes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    const X86_64: Host = Host {
        class: 2,
        little_endian: true,
        machine: Some(62),
    };

    /// A minimal little-endian ELF64 shared library for x86-64: the header, `phnum` program
    /// headers at byte 64 (the first a `PT_LOAD` of the whole file, the others `PT_NULL`), and
    /// section headers (2 of 64 bytes) at the end.
    fn image(phnum: u16) -> Vec<u8> {
        let ph_end = 64 + 56 * usize::from(phnum);
        let len = ph_end + 128;
        let mut b = vec![0u8; len];
        b[..4].copy_from_slice(b"\x7fELF");
        b[4] = 2;
        b[5] = 1;
        b[6] = 1;
        b[16..18].copy_from_slice(&ET_DYN.to_le_bytes());
        b[18..20].copy_from_slice(&62u16.to_le_bytes());
        b[32..40].copy_from_slice(&64u64.to_le_bytes());
        b[40..48].copy_from_slice(&(ph_end as u64).to_le_bytes());
        b[54..56].copy_from_slice(&56u16.to_le_bytes());
        b[56..58].copy_from_slice(&phnum.to_le_bytes());
        b[58..60].copy_from_slice(&64u16.to_le_bytes());
        b[60..62].copy_from_slice(&2u16.to_le_bytes());
        if phnum > 0 {
            b[64..68].copy_from_slice(&PT_LOAD.to_le_bytes());
            b[64 + 32..64 + 40].copy_from_slice(&(len as u64).to_le_bytes());
        }
        b
    }

    /// [`image`] of one program header whose sections are the null one, `.shstrtab` and a
    /// section named `name` holding `data`.
    fn with_section(name: &str, data: &[u8]) -> Vec<u8> {
        let mut b = image(1);
        b.truncate(64 + 56);
        let strtab_at = b.len();
        let strtab = format!("\0.shstrtab\0{name}\0");
        b.extend_from_slice(strtab.as_bytes());
        let data_at = b.len();
        b.extend_from_slice(data);
        let shoff = b.len();
        b.extend_from_slice(&[0u8; 64]);
        for (name_at, at, size) in [(1u32, strtab_at, strtab.len()), (11, data_at, data.len())] {
            let mut h = [0u8; 64];
            h[..4].copy_from_slice(&name_at.to_le_bytes());
            h[4..8].copy_from_slice(&1u32.to_le_bytes());
            h[24..32].copy_from_slice(&(at as u64).to_le_bytes());
            h[32..40].copy_from_slice(&(size as u64).to_le_bytes());
            b.extend_from_slice(&h);
        }
        b[40..48].copy_from_slice(&(shoff as u64).to_le_bytes());
        b[60..62].copy_from_slice(&3u16.to_le_bytes());
        b[62..64].copy_from_slice(&1u16.to_le_bytes());
        let len = b.len() as u64;
        b[64 + 32..64 + 40].copy_from_slice(&len.to_le_bytes());
        b
    }

    #[test]
    fn the_name_table_section_is_read_by_its_name() {
        let table = b"LUXNAMES-and-the-rest";
        let b = with_section(luxon_plugin::names::SECTION, table);
        assert_eq!(run(&b).unwrap().names.as_deref(), Some(&table[..]));
        // Another section's name: no table, the library will be loaded to learn its names.
        let b = with_section(".luxon_namez", table);
        assert_eq!(run(&b), Ok(Checked::default()));
        // The section's bytes past the end of the file.
        let mut b = with_section(luxon_plugin::names::SECTION, table);
        let shoff = u64::from_le_bytes(b[40..48].try_into().unwrap()) as usize;
        let size_at = shoff + 2 * 64 + 32;
        b[size_at..size_at + 8].copy_from_slice(&1000u64.to_le_bytes());
        let e = run(&b).unwrap_err();
        assert!(
            e.starts_with("is a truncated ELF file: its section .luxon_names needs bytes"),
            "{e}"
        );
        // A string table index out of range: followed no further.
        let mut b = with_section(luxon_plugin::names::SECTION, table);
        b[62..64].copy_from_slice(&7u16.to_le_bytes());
        assert_eq!(run(&b), Ok(Checked::default()));
    }

    fn run(b: &[u8]) -> Result<Checked, String> {
        check(&mut Cursor::new(b), b.len() as u64, &X86_64)
    }

    #[test]
    fn a_complete_library_passes() {
        assert_eq!(run(&image(3)), Ok(Checked::default()));
    }

    #[test]
    fn a_segment_past_the_end_is_reported_with_its_bytes() {
        let mut b = image(1);
        let len = b.len() as u64;
        // The segment claims 100 bytes more than the file has.
        b[64 + 32..64 + 40].copy_from_slice(&(len + 100).to_le_bytes());
        b[40..48].copy_from_slice(&0u64.to_le_bytes());
        let e = run(&b).unwrap_err();
        assert_eq!(
            e,
            format!(
                "is a truncated ELF file: its segment 0 needs bytes 0..{} but the file has \
                 {len} bytes (an interrupted copy or build?)",
                len + 100
            )
        );
    }

    #[test]
    fn a_file_cut_anywhere_is_refused() {
        let b = image(2);
        for cut in [0, 3, 10, 63, 64, 100, 120, b.len() - 1] {
            let e = run(&b[..cut]).unwrap_err();
            assert!(
                e.contains("truncated") || e.contains("no ELF header"),
                "{cut}: {e}"
            );
        }
    }

    #[test]
    fn program_headers_out_of_range_are_refused() {
        let mut b = image(1);
        b[32..40].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(run(&b)
            .unwrap_err()
            .contains("its program header table needs bytes"));
        let mut b = image(1);
        b[56..58].copy_from_slice(&0xffffu16.to_le_bytes());
        assert_eq!(
            run(&b).unwrap_err(),
            "is not a valid shared library (65535 program headers of 56 bytes)"
        );
    }

    #[test]
    fn section_headers_past_the_end_are_refused() {
        let mut b = image(1);
        b[60..62].copy_from_slice(&3u16.to_le_bytes());
        let e = run(&b).unwrap_err();
        assert!(
            e.starts_with("is a truncated ELF file: its section header table needs bytes"),
            "{e}"
        );
    }

    #[test]
    fn another_machine_class_or_type_is_named() {
        let mut b = image(1);
        b[18..20].copy_from_slice(&183u16.to_le_bytes());
        assert_eq!(
            run(&b).unwrap_err(),
            "was built for another processor (ELF machine 183)"
        );
        let mut b = image(1);
        b[4] = 1;
        assert_eq!(run(&b).unwrap_err(), "was built for a 32-bit system");
        let mut b = image(1);
        b[5] = 2;
        assert_eq!(run(&b).unwrap_err(), "was built for another byte order");
        let mut b = image(1);
        b[16..18].copy_from_slice(&2u16.to_le_bytes());
        assert_eq!(run(&b).unwrap_err(), "is not a shared library (ELF type 2)");
    }

    #[test]
    fn a_short_file_or_another_format_has_no_elf_header() {
        assert_eq!(
            run(b"0123456789").unwrap_err(),
            "is not a shared library (no ELF header)"
        );
        assert_eq!(
            run(b"#!/bin/sh\n").unwrap_err(),
            "is not a shared library (no ELF header)"
        );
    }

    #[cfg(all(unix, not(target_vendor = "apple")))]
    #[test]
    fn the_running_test_binary_matches_this_host() {
        // The test executable is an ELF file for this host (a shared object when PIE).
        let exe = std::env::current_exe().unwrap();
        let e = check_library(&exe);
        assert!(
            e.is_ok() || e.as_ref().unwrap_err().contains("ELF type"),
            "{e:?}"
        );
    }
}

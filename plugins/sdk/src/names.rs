//! A library's name table: what it provides (kind, name, a writer's extensions), readable
//! from the file without loading it.
//!
//! [`export!`](crate::export) puts the table in the library's [`SECTION`] section, built at
//! compile time from the same entries as the handshake's declaration. A host reads the section
//! from the file to learn which library provides which name, and loads (`dlopen`s) only the
//! libraries a scene uses; when it loads one, it checks that the declaration lists exactly the
//! table's entries. The section is additive: a host that does not read it, or a library built
//! before it existed, loads the library as always.
//!
//! Layout (all integers little-endian u32): [`MAGIC`], [`TABLE_VERSION`], the entry count,
//! then per entry its kind, the name's length and bytes, the extensions' length and bytes.

/// The section's name.
pub const SECTION: &str = ".luxon_names";
/// First eight bytes of the table.
pub const MAGIC: [u8; 8] = *b"LUXNAMES";
/// The table's layout version; a host that does not know it loads the library eagerly.
pub const TABLE_VERSION: u32 = 1;
/// A table longer than this is not trusted (a few hundred bytes is typical).
pub const MAX_TABLE: usize = 1 << 20;

/// One entry of a table, as `export!` builds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Item {
    /// The entry's kind (`abi::KIND_*`).
    pub kind: u32,
    /// The name a scene uses.
    pub name: &'static str,
    /// A writer's comma-separated extensions; empty otherwise.
    pub extensions: &'static str,
}

impl Item {
    /// The item of entry `D` of kind `kind` (`abi::KIND_*`), with a writer's `extensions`
    /// (empty for other kinds): what `export!` lists beside each handshake entry.
    pub const fn of<D: crate::Describe>(kind: u32, extensions: &'static str) -> Item {
        Item {
            kind,
            name: D::NAME,
            extensions,
        }
    }
}

/// Bytes of the table of `items`.
pub const fn table_len(items: &[Item]) -> usize {
    let mut n = 16;
    let mut i = 0;
    while i < items.len() {
        n += 12 + items[i].name.len() + items[i].extensions.len();
        i += 1;
    }
    n
}

/// The table of `items`; `N` must be [`table_len`] of them (anything else fails to compile
/// where `export!` uses it, as a const evaluation).
pub const fn table<const N: usize>(items: &[Item]) -> [u8; N] {
    assert!(N == table_len(items), "name table length");
    let mut out = [0u8; N];
    let mut at = put(&mut out, 0, &MAGIC);
    at = put(&mut out, at, &TABLE_VERSION.to_le_bytes());
    at = put(&mut out, at, &(items.len() as u32).to_le_bytes());
    let mut i = 0;
    while i < items.len() {
        let it = items[i];
        at = put(&mut out, at, &it.kind.to_le_bytes());
        at = put(&mut out, at, &(it.name.len() as u32).to_le_bytes());
        at = put(&mut out, at, it.name.as_bytes());
        at = put(&mut out, at, &(it.extensions.len() as u32).to_le_bytes());
        at = put(&mut out, at, it.extensions.as_bytes());
        i += 1;
    }
    out
}

const fn put<const N: usize>(out: &mut [u8; N], at: usize, bytes: &[u8]) -> usize {
    let mut i = 0;
    while i < bytes.len() {
        out[at + i] = bytes[i];
        i += 1;
    }
    at + bytes.len()
}

/// An entry read back from a table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Named {
    pub kind: u32,
    pub name: String,
    pub extensions: String,
}

/// The entries of a table; the error says what is wrong with it.
pub fn parse(bytes: &[u8]) -> Result<Vec<Named>, String> {
    let mut rest = bytes;
    let mut take = |n: usize, what: &str| -> Result<&[u8], String> {
        if rest.len() < n {
            return Err(format!("its name table ends inside {what}"));
        }
        let (a, b) = rest.split_at(n);
        rest = b;
        Ok(a)
    };
    if take(8, "the magic")? != MAGIC {
        return Err("its name table has a bad magic".into());
    }
    let word = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let version = word(take(4, "the version")?);
    if version != TABLE_VERSION {
        return Err(format!(
            "its name table has layout version {version}; this Luxon reads {TABLE_VERSION}"
        ));
    }
    let count = word(take(4, "the count")?) as usize;
    let mut out = Vec::new();
    for _ in 0..count {
        let kind = word(take(4, "an entry")?);
        let mut text = |what: &str| -> Result<String, String> {
            let n = word(take(4, what)?) as usize;
            String::from_utf8(take(n, what)?.to_vec())
                .map_err(|_| format!("its name table has {what} that is not UTF-8"))
        };
        let name = text("a name")?;
        let extensions = text("an extension list")?;
        out.push(Named {
            kind,
            name,
            extensions,
        });
    }
    if !rest.is_empty() {
        return Err(format!(
            "its name table has {} bytes after its {count} entries",
            rest.len()
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ITEMS: &[Item] = &[
        Item {
            kind: 1,
            name: "sphere",
            extensions: "",
        },
        Item {
            kind: 4,
            name: "ppm",
            extensions: "ppm,pnm",
        },
    ];

    #[test]
    fn a_table_reads_back_as_its_items() {
        const T: [u8; table_len(ITEMS)] = table(ITEMS);
        let back = parse(&T).unwrap();
        let want: Vec<Named> = ITEMS
            .iter()
            .map(|i| Named {
                kind: i.kind,
                name: i.name.into(),
                extensions: i.extensions.into(),
            })
            .collect();
        assert_eq!(back, want);
        assert_eq!(parse(&table::<16>(&[])).unwrap(), vec![]);
    }

    #[test]
    fn a_damaged_table_is_an_error() {
        const T: [u8; table_len(ITEMS)] = table(ITEMS);
        for cut in [0, 7, 8, 15, 16, 20, T.len() - 1] {
            assert!(
                parse(&T[..cut]).unwrap_err().contains("ends inside"),
                "{cut}"
            );
        }
        let mut b = T.to_vec();
        b[0] = b'X';
        assert_eq!(parse(&b).unwrap_err(), "its name table has a bad magic");
        let mut b = T.to_vec();
        b[8] = 2;
        assert!(parse(&b).unwrap_err().contains("layout version 2"));
        let mut b = T.to_vec();
        b.push(0);
        assert_eq!(
            parse(&b).unwrap_err(),
            "its name table has 1 bytes after its 2 entries"
        );
        let mut b = T.to_vec();
        b[24] = 0xff;
        assert!(parse(&b).unwrap_err().contains("not UTF-8"));
    }
}

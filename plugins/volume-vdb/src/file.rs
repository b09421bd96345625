//! The file around the grids: header, file metadata, grid descriptors, per-grid compression,
//! metadata and transform, then the tree.
//!
//! Header: the 8-byte magic `20 42 44 56 00 00 00 00` ("VDB " as a little-endian i64), file
//! format version u32, library major and minor u32, a byte saying whether grid offsets are
//! stored, and a 36-character UUID. Strings are a u32 length and the bytes. A grid descriptor
//! is the grid's unique name, its type (e.g. `Tree_float_5_4_3`, with `_HalfFloat` appended for
//! half floats), the name of the grid it instances (empty for most), and three i64 offsets:
//! grid, block (leaf values) and end.

use crate::bytes::Cursor;
use crate::transform::read_transform;
use crate::tree::read_tree;
use crate::values::{Encoding, ValueFormat};
use crate::{Grid, GridEntry, VdbError};

const MAGIC: [u8; 8] = [0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0];
/// Per-node compression metadata (222) is the oldest layout read; 224 is OpenVDB 6 to 12's.
const OLDEST: u32 = 222;
const NEWEST: u32 = 224;
/// Separates a grid's name from the suffix that makes duplicate names unique.
const UNIQUE_SEPARATOR: char = '\u{1e}';

struct Descriptor {
    name: String,
    type_name: String,
    instance_of: String,
    grid_pos: i64,
    block_pos: i64,
}

struct Contents {
    has_offsets: bool,
    grids: Vec<Descriptor>,
}

fn read_header(c: &mut Cursor) -> Result<bool, VdbError> {
    let magic = c.take(8.min(c.remaining()), "the header")?;
    if magic != MAGIC {
        return Err(VdbError::NotVdb(format!(
            "it starts with {:02x?}, not the OpenVDB signature {MAGIC:02x?}",
            magic
        )));
    }
    let version = c.u32("the file format version")?;
    if !(OLDEST..=NEWEST).contains(&version) {
        return Err(VdbError::Version(version));
    }
    c.u32("the library version")?;
    c.u32("the library version")?;
    let has_offsets = c.u8("the grid-offsets flag")? != 0;
    c.take(36, "the file's UUID")?;
    Ok(has_offsets)
}

/// A metadata entry: name, type name and value bytes.
type Meta<'a> = (String, String, &'a [u8]);

fn read_metadata<'a>(c: &mut Cursor<'a>) -> Result<Vec<Meta<'a>>, VdbError> {
    let n = c.count(12, "the metadata count")?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let name = c.string("a metadata name")?;
        let type_name = c.string("a metadata type")?;
        let size = c.u32("a metadata size")? as usize;
        let value = c.take(size, "a metadata value")?;
        out.push((name, type_name, value));
    }
    Ok(out)
}

fn read_contents(c: &mut Cursor) -> Result<Contents, VdbError> {
    let has_offsets = read_header(c)?;
    read_metadata(c)?;
    let n = c.count(36, "the grid count")?;
    let mut grids = Vec::with_capacity(n);
    for _ in 0..n {
        let unique = c.string("a grid name")?;
        let name = unique
            .split(UNIQUE_SEPARATOR)
            .next()
            .unwrap_or_default()
            .to_string();
        let type_name = c.string("a grid type")?;
        let instance_of = c.string("a grid's instance parent")?;
        let instance_of = instance_of
            .split(UNIQUE_SEPARATOR)
            .next()
            .unwrap_or_default()
            .to_string();
        let grid_pos = c.i64("a grid position")?;
        let block_pos = c.i64("a grid's block position")?;
        let end_pos = c.i64("a grid's end position")?;
        let descriptor = Descriptor {
            name,
            type_name,
            instance_of,
            grid_pos,
            block_pos,
        };
        if has_offsets {
            c.seek(end_pos, "a grid's end position")?;
        } else {
            // A stream: the grid follows its descriptor; read it to find the next one.
            let pos = c.pos() as i64;
            let descriptor = Descriptor {
                grid_pos: pos,
                ..descriptor
            };
            if !is_scalar(&descriptor) {
                // Only scalar grids can be read past; later grids stay unlisted.
                grids.push(descriptor);
                break;
            }
            if descriptor.instance_of.is_empty() {
                read_body(c, &descriptor, false)?;
            } else {
                read_head(c, &descriptor)?;
            }
            grids.push(descriptor);
            continue;
        }
        grids.push(descriptor);
    }
    Ok(Contents { has_offsets, grids })
}

/// The encodings of a grid type's node arrays and single values, or an error naming the type.
fn value_types(d: &Descriptor) -> Result<(Encoding, Encoding, &'static str), VdbError> {
    let (base, half) = match d.type_name.strip_suffix("_HalfFloat") {
        Some(b) => (b, true),
        None => (d.type_name.as_str(), false),
    };
    let (single, name) = match base {
        "Tree_float_5_4_3" => (Encoding::F32, "float"),
        "Tree_double_5_4_3" => (Encoding::F64, "double"),
        _ => return Err(wrong_type(d)),
    };
    Ok((if half { Encoding::Half } else { single }, single, name))
}

fn wrong_type(d: &Descriptor) -> VdbError {
    let short = d
        .type_name
        .strip_prefix("Tree_")
        .and_then(|t| t.split('_').next())
        .unwrap_or(&d.type_name);
    VdbError::WrongType {
        name: d.name.clone(),
        value_type: short.to_string(),
        type_name: d.type_name.clone(),
    }
}

fn is_scalar(d: &Descriptor) -> bool {
    value_types(d).is_ok()
}

/// Compression, metadata and transform of a grid.
struct Head {
    compression: u32,
    class: String,
    map: String,
    world_from_index: [f64; 12],
}

fn read_head(c: &mut Cursor, d: &Descriptor) -> Result<Head, VdbError> {
    c.seek(d.grid_pos, "a grid position")?;
    let compression = c.u32("the grid's compression flags")?;
    let meta = read_metadata(c)?;
    let class = meta
        .iter()
        .find(|(n, t, _)| n == "class" && t == "string")
        .map(|(_, _, v)| String::from_utf8_lossy(v).into_owned())
        .unwrap_or_else(|| "unknown".into());
    let (map, world_from_index) = read_transform(c)?;
    Ok(Head {
        compression,
        class,
        map,
        world_from_index,
    })
}

/// A whole float or double grid (its tree read from this descriptor, not through instances).
fn read_body(
    c: &mut Cursor,
    d: &Descriptor,
    offsets: bool,
) -> Result<(Head, crate::tree::Tree), VdbError> {
    let (array, single, _) = value_types(d)?;
    let head = read_head(c, d)?;
    let format = ValueFormat {
        compression: head.compression,
        array,
        single,
        background: 0.0,
    };
    let tree = read_tree(c, offsets.then_some(d.block_pos), format)?;
    Ok((head, tree))
}

/// Names and types of the grids in a file.
pub fn list_grids(bytes: &[u8]) -> Result<Vec<GridEntry>, VdbError> {
    let contents = read_contents(&mut Cursor::new(bytes))?;
    Ok(contents
        .grids
        .iter()
        .map(|d| GridEntry {
            name: d.name.clone(),
            type_name: d.type_name.clone(),
        })
        .collect())
}

fn listing(grids: &[Descriptor]) -> String {
    if grids.is_empty() {
        return "the file holds no grids".into();
    }
    let names: Vec<String> = grids
        .iter()
        .map(|d| {
            let t = value_types(d)
                .map(|(_, _, n)| n.to_string())
                .unwrap_or_else(|_| match wrong_type(d) {
                    VdbError::WrongType { value_type, .. } => value_type,
                    _ => d.type_name.clone(),
                });
            format!("`{}` ({t})", d.name)
        })
        .collect();
    format!("the file holds {}", names.join(", "))
}

/// Reads one float or double grid: the one named `grid_name`, or the first such grid.
pub fn read_grid(bytes: &[u8], grid_name: Option<&str>) -> Result<Grid, VdbError> {
    let mut c = Cursor::new(bytes);
    let contents = read_contents(&mut c)?;
    let grids = &contents.grids;
    let chosen = match grid_name {
        Some(name) => {
            grids
                .iter()
                .find(|d| d.name == name)
                .ok_or_else(|| VdbError::GridNotFound {
                    name: name.to_string(),
                    listing: listing(grids),
                })?
        }
        None => grids
            .iter()
            .find(|d| is_scalar(d))
            .ok_or_else(|| VdbError::NoScalarGrid {
                listing: listing(grids),
            })?,
    };
    let (_, _, value_type) = value_types(chosen)?;
    // An instance shares the tree of the grid it names, with its own transform.
    let source = if chosen.instance_of.is_empty() {
        chosen
    } else {
        grids
            .iter()
            .find(|d| d.name == chosen.instance_of && d.instance_of.is_empty())
            .ok_or_else(|| {
                c.corrupt(format!(
                    "grid `{}` is an instance of `{}`, which the file does not hold",
                    chosen.name, chosen.instance_of
                ))
            })?
    };
    let head = read_head(&mut c, chosen)?;
    let (_, tree) = read_body(&mut c, source, contents.has_offsets)?;
    Ok(Grid {
        name: chosen.name.clone(),
        value_type,
        half: chosen.type_name.ends_with("_HalfFloat"),
        class: head.class,
        map: head.map,
        world_from_index: head.world_from_index,
        background: tree.background,
        leaves: tree.leaves,
        tiles: tree.tiles,
    })
}

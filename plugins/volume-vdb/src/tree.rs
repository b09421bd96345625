//! The tree of a float or double grid (OpenVDB's standard 5-4-3 configuration): a root table of
//! 4096³ tiles and children, upper internal nodes of 32³ entries (each a child or a 128³ tile),
//! lower internal nodes of 16³ entries (each a leaf or an 8³ tile) and leaves of 8³ voxels.
//!
//! The topology (masks, tile values) comes first, depth first; then, at the grid's block
//! position, every leaf's values in the same order. Inside a node, entry `n` is at local
//! coordinates `x = n >> 2L, y = (n >> L) & (2^L - 1), z = n & (2^L - 1)`: z varies fastest.

use crate::bytes::Cursor;
use crate::values::{bit, read_mask, read_node_values, read_value, ValueFormat};
use crate::{Leaf, Tile, VdbError};
use std::collections::HashSet;

/// log2 of the edge of a node's table, from the upper internal node down to the leaf.
const UPPER: u32 = 5;
const LOWER: u32 = 4;
const LEAF: u32 = 3;

pub(crate) struct Tree {
    pub background: f32,
    pub leaves: Vec<Leaf>,
    pub tiles: Vec<Tile>,
}

/// Reads the topology at `c` and the leaf values at `buffers` (the block position, or `None`
/// when they follow the topology).
pub(crate) fn read_tree(
    c: &mut Cursor,
    buffers: Option<i64>,
    mut format: ValueFormat,
) -> Result<Tree, VdbError> {
    let at = c.pos();
    let buffer_count = c.i32("the tree's buffer count")?;
    if buffer_count != 1 {
        return Err(VdbError::Corrupt {
            offset: at,
            message: format!("the tree has {buffer_count} buffers; expected 1"),
        });
    }
    let background = read_value(c, format.single, "the background value")?;
    format.background = background;
    let mut tree = Tree {
        background,
        leaves: Vec::new(),
        tiles: Vec::new(),
    };
    let tile_bytes = 12 + format_size(format) + 1;
    let tiles = c.count(tile_bytes, "the root's tile count")?;
    let children = c.count(12, "the root's child count")?;
    let mut seen = HashSet::new();
    let mut root_origin = |c: &mut Cursor| -> Result<[i32; 3], VdbError> {
        let at = c.pos();
        let o = [
            c.i32("an origin")?,
            c.i32("an origin")?,
            c.i32("an origin")?,
        ];
        if o.iter().any(|v| v & 4095 != 0) || !seen.insert(o) {
            return Err(VdbError::Corrupt {
                offset: at,
                message: format!(
                    "root entry at {o:?} is not on the 4096-voxel lattice or appears twice"
                ),
            });
        }
        Ok(o)
    };
    for _ in 0..tiles {
        let origin = root_origin(c)?;
        let value = read_value(c, format.single, "a root tile's value")?;
        let active = c.u8("a root tile's active flag")? != 0;
        push_tile(&mut tree, origin, 1 << 12, value, active);
    }
    let mut pending = Vec::new();
    for _ in 0..children {
        let origin = root_origin(c)?;
        read_internal(c, &mut tree, &mut pending, origin, UPPER, &format)?;
    }
    if let Some(pos) = buffers {
        c.seek(pos, "the grid's block position")?;
    }
    // Leaf values, in topology order.
    for (origin, topology_mask) in pending {
        let mask = read_mask(c, 512, "a leaf's value mask")?;
        if mask != topology_mask {
            return Err(c.corrupt(format!(
                "the leaf at {origin:?} has a different value mask in its buffer than in the \
                 topology"
            )));
        }
        let values = read_node_values(c, 512, &mask, &format)?;
        let mut leaf = Leaf {
            origin,
            values: Box::new([0.0; 512]),
            active: [0; 8],
        };
        // OpenVDB order (z fastest) to ours (x fastest).
        for (n, v) in values.iter().enumerate() {
            let (x, y, z) = (n >> 6, (n >> 3) & 7, n & 7);
            let ours = x + 8 * y + 64 * z;
            leaf.values[ours] = *v;
            if bit(&mask, n) {
                leaf.active[ours >> 6] |= 1 << (ours & 63);
            }
        }
        tree.leaves.push(leaf);
    }
    Ok(tree)
}

fn format_size(f: ValueFormat) -> usize {
    match f.single {
        crate::values::Encoding::F64 => 8,
        crate::values::Encoding::F32 => 4,
        crate::values::Encoding::Half => 2,
    }
}

/// Keeps a tile only when it changes something: active, or a value other than the background.
fn push_tile(tree: &mut Tree, origin: [i32; 3], size: u32, value: f32, active: bool) {
    if active || value != tree.background || value.is_nan() {
        tree.tiles.push(Tile {
            origin,
            size,
            value,
            active,
        });
    }
}

/// An internal node with a table of `2^log2` entries per axis at `origin`; leaves are queued
/// with their topology masks in `pending` for the buffer pass.
fn read_internal(
    c: &mut Cursor,
    tree: &mut Tree,
    pending: &mut Vec<([i32; 3], Vec<u64>)>,
    origin: [i32; 3],
    log2: u32,
    format: &ValueFormat,
) -> Result<(), VdbError> {
    let entries = 1usize << (3 * log2);
    let child_mask = read_mask(c, entries, "an internal node's child mask")?;
    let value_mask = read_mask(c, entries, "an internal node's value mask")?;
    let values = read_node_values(c, entries, &value_mask, format)?;
    // log2 of the voxels an entry spans per axis.
    let child_span = if log2 == UPPER { LOWER + LEAF } else { LEAF };
    let dim = 1usize << log2;
    let at = |n: usize| {
        let local = [n >> (2 * log2), (n >> log2) & (dim - 1), n & (dim - 1)];
        // Inside the root entry's 4096³ block, whose origin is a multiple of 4096: no overflow.
        [0, 1, 2].map(|a| origin[a] + ((local[a] as i32) << child_span))
    };
    for (n, &value) in values.iter().enumerate() {
        if !bit(&child_mask, n) {
            push_tile(tree, at(n), 1 << child_span, value, bit(&value_mask, n));
        }
    }
    for n in 0..entries {
        if bit(&child_mask, n) {
            let child = at(n);
            if log2 == UPPER {
                read_internal(c, tree, pending, child, LOWER, format)?;
            } else {
                let mask = read_mask(c, 512, "a leaf's value mask")?;
                pending.push((child, mask));
            }
        }
    }
    Ok(())
}

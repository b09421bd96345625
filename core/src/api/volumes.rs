//! Volumes from arrays: a [`VolumeGrid`] is checked when added (element type, dimensions,
//! spacing, and that every voxel's element lies in the array) and copied through
//! [`VolumeBuilder`] at the commits that find it changed, so the readers' checks and the brick
//! collapse apply to it as to a volume a plugin reads.

use super::objects::{expect_elem, VolumeGrid, VOXEL};
use crate::arrays::{Elem, View};
use crate::budget::{Budget, Charge, Use};
use crate::error::Error;
use crate::volume::{Volume, VolumeBuilder, BRICK_SIZE, MAX_VOXELS};
use std::sync::Arc;

/// Checks what can be checked before the values are read (`what`: `volume grid `name``):
/// the element type, dims, origin, spacing and the span of the voxels over the array as long
/// as it is now.
pub(super) fn check(grid: &VolumeGrid, what: &str) -> Result<(), Error> {
    expect_elem(&format!("{what}'s values"), &grid.values, VOXEL)?;
    if grid.origin.iter().any(|c| !c.is_finite()) {
        return Err(Error::Api(format!(
            "{what}: origin {:?}; expected finite coordinates",
            grid.origin
        )));
    }
    if grid.spacing.iter().any(|s| !s.is_finite() || *s == 0.0) {
        return Err(Error::Api(format!(
            "{what}: spacing {:?}; expected finite, non-zero sizes",
            grid.spacing
        )));
    }
    layout(grid, grid.values.len()).map_err(|m| Error::Api(format!("{what}: {m}")))?;
    Ok(())
}

/// The strides in elements, after checking that voxel (0, 0, 0) to `dims - 1` all lie among
/// the array's `len` elements and that no axis repeats one element.
fn layout(grid: &VolumeGrid, len: usize) -> Result<[i64; 3], String> {
    let d = grid.dims;
    if d.contains(&0) {
        return Err(format!(
            "dims {d:?}; expected at least 1 voxel on every axis"
        ));
    }
    let voxels = d.iter().try_fold(1u64, |a, &n| a.checked_mul(n));
    if voxels.is_none_or(|v| v > MAX_VOXELS) {
        return Err(format!(
            "dims {d:?} hold more than 2^34 = {MAX_VOXELS} voxels, the most a volume may have"
        ));
    }
    let strides = match grid.strides {
        Some(s) => s,
        // Checked above: the products fit (≤ 2^34).
        None => [1, d[0] as i64, (d[0] * d[1]) as i64],
    };
    for a in 0..3 {
        if strides[a] == 0 && d[a] > 1 {
            return Err(format!(
                "stride 0 on axis {} repeats one element for its {} voxels; expected a \
                 non-zero stride (strides {strides:?}, in elements)",
                ["x", "y", "z"][a],
                d[a]
            ));
        }
    }
    // The lowest and highest element any voxel reads (i128: no overflow for any input).
    let (mut lo, mut hi) = (grid.first as i128, grid.first as i128);
    for a in 0..3 {
        let reach = (d[a] as i128 - 1) * strides[a] as i128;
        if reach < 0 {
            lo += reach;
        } else {
            hi += reach;
        }
    }
    if lo < 0 || hi >= len as i128 {
        let at = if lo < 0 { lo } else { hi };
        return Err(format!(
            "its voxels read element {at}, but the array has {len} elements (dims {d:?}, \
             strides {strides:?} in elements, first {})",
            grid.first
        ));
    }
    Ok(strides)
}

/// Copies the grid's voxels (`view`: its values, pinned) into a volume the scene calls `name`,
/// a slab of 8 z-slices at a time. A non-finite voxel is refused with its index. Its bricks are
/// charged to `budget` as they are made (one that does not fit is refused); the charge of the
/// finished volume is returned with it (given back when it drops).
pub(super) fn read(
    grid: &VolumeGrid,
    name: &str,
    view: View<'_>,
    budget: &Arc<Budget>,
) -> Result<(Volume, Charge), Error> {
    let before = budget.used(Use::Volumes);
    let volume = read_charged(grid, name, view, budget)?;
    // What the finished volume keeps charged (the builder charges and gives back as it goes).
    let held = budget.used(Use::Volumes).saturating_sub(before);
    Ok((volume, budget.guard(Use::Volumes, held)))
}

fn read_charged(
    grid: &VolumeGrid,
    name: &str,
    view: View<'_>,
    budget: &Arc<Budget>,
) -> Result<Volume, Error> {
    let fail = |m: String| Error::Api(format!("volume `{name}`: {m}"));
    // A builder error for want of memory is the budget's message: it names the volume and says
    // what to do.
    let built = |b: &VolumeBuilder, m: String| match b.out_of_memory() {
        true => Error::Render(m),
        false => fail(m),
    };
    let strides = layout(grid, view.len()).map_err(fail)?;
    let [nx, ny, nz] = grid.dims;
    let (o, s) = (grid.origin, grid.spacing);
    let mut b = VolumeBuilder::new(name, "array");
    b.charge_to(budget.clone());
    #[rustfmt::skip]
    let world_from_index = [
        s[0], 0.0, 0.0, o[0],
        0.0, s[1], 0.0, o[1],
        0.0, 0.0, s[2], o[2],
    ];
    let max = [nx, ny, nz].map(|n| n as i64 - 1);
    b.begin(world_from_index, 0.0, [0; 3], max, name)
        .map_err(|m| built(&b, m))?;
    let slab = BRICK_SIZE as u64;
    let per_slice = (nx * ny) as usize;
    let voxels = per_slice * slab.min(nz) as usize;
    // The element of voxel (i, j, k): in range for every voxel (`layout` checked it).
    let element = |i: u64, j: u64, k: u64| {
        (grid.first as i64 + i as i64 * strides[0] + j as i64 * strides[1] + k as i64 * strides[2])
            as usize
    };
    let lost = |e: usize| fail(format!("element {e} could not be read"));
    let divisor = |full: f32| if grid.normalize { full } else { 1.0 };
    match view.elem() {
        Elem::U8 | Elem::U16 => {
            let wide = view.elem() == Elem::U16;
            let mut bytes: Vec<u8> = Vec::new();
            let mut words: Vec<u16> = Vec::new();
            reserve(&mut bytes, if wide { 0 } else { voxels }, name)?;
            reserve(&mut words, if wide { voxels } else { 0 }, name)?;
            for z0 in (0..nz).step_by(slab as usize) {
                let dz = slab.min(nz - z0);
                bytes.clear();
                words.clear();
                for k in z0..z0 + dz {
                    for j in 0..ny {
                        for i in 0..nx {
                            let e = element(i, j, k);
                            let v = view.index(e).ok_or_else(|| lost(e))?;
                            match wide {
                                true => words.push(v as u16),
                                false => bytes.push(v as u8),
                            }
                        }
                    }
                }
                let (at, dims) = ([0, 0, z0 as i64], [nx, ny, dz]);
                match wide {
                    true => b.add_dense_u16(at, dims, &words, divisor(65535.0)),
                    false => b.add_dense_u8(at, dims, &bytes, divisor(255.0)),
                }
                .map_err(|m| built(&b, m))?;
            }
        }
        _ => {
            let mut floats: Vec<f32> = Vec::new();
            reserve(&mut floats, voxels, name)?;
            for z0 in (0..nz).step_by(slab as usize) {
                let dz = slab.min(nz - z0);
                floats.clear();
                for k in z0..z0 + dz {
                    for j in 0..ny {
                        for i in 0..nx {
                            let e = element(i, j, k);
                            let v = view.scalar(e).ok_or_else(|| lost(e))?;
                            let f = v as f32;
                            if !f.is_finite() {
                                return Err(fail(format!(
                                    "voxel ({i}, {j}, {k}) (element {e} of the array) is {v}; \
                                     expected finite values (within f32's range)"
                                )));
                            }
                            floats.push(f);
                        }
                    }
                }
                b.add_dense([0, 0, z0 as i64], [nx, ny, dz], &floats)
                    .map_err(|m| built(&b, m))?;
            }
        }
    }
    b.finish_or_refused()
        .map_err(|(m, out_of_memory)| match out_of_memory {
            true => Error::Render(m),
            false => fail(m),
        })
}

/// Room for a slab of `n` voxels, or the error saying it does not fit.
fn reserve<T>(v: &mut Vec<T>, n: usize, name: &str) -> Result<(), Error> {
    v.try_reserve_exact(n).map_err(|_| Error::OutOfMemory {
        what: format!("a slab of {n} voxels of volume `{name}`"),
        bytes: (n * std::mem::size_of::<T>()) as u128,
    })
}

//! Volume-reader plugins: `read` and the host side of `VolumeSink`. The storage and every check
//! of what a reader sends live in [`VolumeBuilder`]; this is the calling side.

use super::calls::{call_context, call_plugin, fail, plugin_label, slice, wrong_kind};
use super::registry::{Entry, PluginKind, Registry, Table};
use crate::budget::Budget;
use crate::volume::{Volume, VolumeBuilder};
use luxon_formats::Origin;
use luxon_plugin::abi;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::Arc;

/// Reads one volume with a volume-reader plugin. `instance` is the scene's name for the volume
/// (it becomes [`Volume::name`] and is passed to the plugin for its messages); its storage is
/// charged to `budget`. Errors carry the scene position: inside `params` when the plugin
/// reports one, otherwise `params_at`.
pub fn read_volume(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
    budget: &Arc<Budget>,
) -> Result<Volume, (Origin, String)> {
    let mut builder = VolumeBuilder::new(instance, &entry.name);
    builder.charge_to(budget.clone());
    read_volume_into(
        registry,
        entry,
        params,
        params_at,
        scene_dir,
        instance,
        &mut builder,
    )?;
    builder.finish().map_err(|m| {
        (
            params_at.clone(),
            format!("{} {m}", plugin_label(registry, entry)),
        )
    })
}

// The host side of `VolumeSink`. The plugin calls these during `read_volume_into`, on its
// thread and one at a time (ABI contract), with the `ctx` we put in the sink: our
// `VolumeBuilder`, which nothing else touches until `read` returns. Errors go to the plugin's
// `err`, null or valid for the call; the other pointers are null or valid for the call.

/// Runs one volume sink callback: never unwinds, and any failure (a panic included) stops the
/// volume so the read fails even if the plugin ignores the error.
///
/// # Safety
/// `ctx` is null or the `VolumeBuilder` of the running `read_volume_into`, not otherwise
/// borrowed during the call; `err` is null or valid for the call.
unsafe fn volume_call(
    ctx: *mut c_void,
    err: *const abi::ErrorSink,
    f: impl FnOnce(&mut VolumeBuilder) -> Result<(), String>,
) -> abi::Status {
    // SAFETY: the caller's promise.
    let (b, err) = unsafe { ((ctx as *mut VolumeBuilder).as_mut(), err.as_ref()) };
    let Some(b) = b else {
        return fail(err, "the volume sink has no context");
    };
    let message = match catch_unwind(AssertUnwindSafe(|| f(&mut *b))) {
        Ok(Ok(())) => return abi::STATUS_OK,
        Ok(Err(m)) => m,
        Err(_) => {
            let m = "internal error in the host while storing volume data";
            let _ = catch_unwind(AssertUnwindSafe(|| b.fail(m)));
            m.to_string()
        }
    };
    fail(err, &message)
}

/// # Safety
/// See the comment above [`volume_call`].
unsafe extern "C" fn volume_begin(
    ctx: *mut c_void,
    desc: *const abi::VolumeDesc,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller's promise: `desc` and its name are null or valid for the call.
    let desc = unsafe { desc.as_ref().map(|d| (d, d.grid_name.as_str())) };
    let begin = |b: &mut VolumeBuilder| {
        let Some((d, name)) = desc else {
            let m = "`begin` was given no grid description";
            b.fail(m);
            return Err(m.into());
        };
        let Ok(name) = name else {
            let m = "the grid name is not valid UTF-8";
            b.fail(m);
            return Err(m.into());
        };
        b.begin(
            d.world_from_index,
            d.background,
            d.index_min,
            d.index_max,
            name,
        )
    };
    // SAFETY: the caller keeps the ABI contract (see the comment above `volume_call`).
    unsafe { volume_call(ctx, err, begin) }
}

/// # Safety
/// See the comment above [`volume_call`]; `values` is null or `dims[0] * dims[1] * dims[2]`
/// values.
unsafe extern "C" fn volume_add_dense(
    ctx: *mut c_void,
    origin: *const [i64; 3],
    dims: *const [u64; 3],
    values: *const f32,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller's promise: both are null or valid for the call.
    let (origin, dims) = unsafe { (origin.as_ref().copied(), dims.as_ref().copied()) };
    let add = |b: &mut VolumeBuilder| {
        let (Some(origin), Some(dims)) = (origin, dims) else {
            let m = "`add_dense` was given a null origin or size";
            b.fail(m);
            return Err(m.into());
        };
        let n = match block_count(origin, dims, std::mem::size_of::<f32>()) {
            Ok(n) => n,
            Err(m) => {
                b.fail(&m);
                return Err(m);
            }
        };
        if values.is_null() && n > 0 {
            let m = format!("dense block at {origin:?} was given no values (a null pointer)");
            b.fail(&m);
            return Err(m);
        }
        // SAFETY: the caller's promise: `n` values, x fastest, borrowed for the call.
        let values = unsafe { slice(values, n) };
        b.add_dense(origin, dims, values)
    };
    // SAFETY: the caller keeps the ABI contract (see the comment above `volume_call`).
    unsafe { volume_call(ctx, err, add) }
}

/// The voxel count of a dense block, when it is addressable as `bytes`-byte values.
fn block_count(origin: [i64; 3], dims: [u64; 3], bytes: usize) -> Result<usize, String> {
    // The builder checks the size against the grid; here it only has to be addressable.
    dims.iter()
        .try_fold(1u64, |a, &d| a.checked_mul(d))
        .and_then(|n| usize::try_from(n).ok())
        .filter(|&n| n <= usize::MAX / bytes)
        .ok_or_else(|| {
            format!(
                "dense block at {origin:?} of {}x{}x{} voxels has too many voxels (the count \
                 overflows)",
                dims[0], dims[1], dims[2]
            )
        })
}

/// # Safety
/// See the comment above [`volume_call`]; `data` is null or `len` bytes, aligned for the
/// voxels of `format`.
#[allow(clippy::too_many_arguments)]
unsafe extern "C" fn volume_add_dense_typed(
    ctx: *mut c_void,
    origin: *const [i64; 3],
    dims: *const [u64; 3],
    format: u32,
    data: *const u8,
    len: usize,
    divisor: f32,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller's promise: both are null or valid for the call.
    let (origin, dims) = unsafe { (origin.as_ref().copied(), dims.as_ref().copied()) };
    let add = |b: &mut VolumeBuilder| {
        let checked = || {
            let (Some(origin), Some(dims)) = (origin, dims) else {
                return Err("`add_dense_typed` was given a null origin or size".to_string());
            };
            let (name, bytes, align) = match format {
                abi::VOXEL_U8 => ("u8", 1, 1),
                abi::VOXEL_U16 => ("u16", 2, std::mem::align_of::<u16>()),
                abi::VOXEL_F32 => ("f32", 4, std::mem::align_of::<f32>()),
                _ => {
                    return Err(format!(
                        "dense block at {origin:?} has the unknown voxel format {format}; \
                         expected {} (u8), {} (u16) or {} (f32)",
                        abi::VOXEL_U8,
                        abi::VOXEL_U16,
                        abi::VOXEL_F32
                    ))
                }
            };
            let n = block_count(origin, dims, bytes)?;
            let block = format!(
                "dense block at {origin:?} of {}x{}x{} {name} voxels",
                dims[0], dims[1], dims[2]
            );
            if len != n * bytes {
                return Err(format!(
                    "{block} comes with {len} bytes; expected {}",
                    n * bytes
                ));
            }
            if data.is_null() && n > 0 {
                return Err(format!("{block} was given no data (a null pointer)"));
            }
            if !data.addr().is_multiple_of(align) {
                return Err(format!(
                    "{block} was given data at an address not aligned for {name}"
                ));
            }
            Ok((origin, dims, n))
        };
        let (origin, dims, n) = checked().inspect_err(|m| b.fail(m))?;
        // SAFETY (each `slice` below): the caller's promise: `len` bytes at `data`, which
        // hold `n` voxels of the format (checked above, with the alignment), borrowed for the
        // call.
        match format {
            abi::VOXEL_U8 => {
                // SAFETY: see above.
                let v = unsafe { slice(data, n) };
                b.add_dense_u8(origin, dims, v, divisor)
            }
            abi::VOXEL_U16 => {
                // SAFETY: see above.
                let v = unsafe { slice(data as *const u16, n) };
                b.add_dense_u16(origin, dims, v, divisor)
            }
            _ => {
                // SAFETY: see above.
                let v = unsafe { slice(data as *const f32, n) };
                b.add_dense_f32(origin, dims, v, divisor)
            }
        }
    };
    // SAFETY: the caller keeps the ABI contract (see the comment above `volume_call`).
    unsafe { volume_call(ctx, err, add) }
}

/// # Safety
/// See the comment above [`volume_call`].
unsafe extern "C" fn volume_add_tile(
    ctx: *mut c_void,
    origin: *const [i64; 3],
    dims: *const [u64; 3],
    value: f32,
    err: *const abi::ErrorSink,
) -> abi::Status {
    // SAFETY: the caller's promise: both are null or valid for the call.
    let (origin, dims) = unsafe { (origin.as_ref().copied(), dims.as_ref().copied()) };
    let add = |b: &mut VolumeBuilder| {
        let (Some(origin), Some(dims)) = (origin, dims) else {
            let m = "`add_tile` was given a null origin or size";
            b.fail(m);
            return Err(m.into());
        };
        b.add_tile(origin, dims, value)
    };
    // SAFETY: the caller keeps the ABI contract (see the comment above `volume_call`).
    unsafe { volume_call(ctx, err, add) }
}

/// Runs a volume-reader plugin's `read` into `builder` (which must be fresh). `entry` must be a
/// volume reader.
#[allow(clippy::too_many_arguments)]
pub fn read_volume_into(
    registry: &Registry,
    entry: &Entry,
    params: &str,
    params_at: &Origin,
    scene_dir: &Path,
    instance: &str,
    builder: &mut VolumeBuilder,
) -> Result<(), (Origin, String)> {
    let Table::VolumeReader(vt) = entry.table else {
        return Err(wrong_kind(
            registry,
            entry,
            PluginKind::VolumeReader,
            params_at,
        ));
    };
    let sink = abi::VolumeSink {
        ctx: builder as *mut VolumeBuilder as *mut c_void,
        begin: volume_begin,
        add_dense: volume_add_dense,
        add_dense_typed: volume_add_dense_typed,
        add_tile: volume_add_tile,
    };
    let dir = scene_dir.to_string_lossy();
    let ctx = call_context(&dir, instance, Some(builder.budget()));
    call_plugin(registry, entry, params_at, |err| {
        // SAFETY: the calling contract: `params`, `ctx`, `sink` and `err` live across the
        // call; `sink.ctx` is `builder`, which this function borrows mutably and does not touch
        // until the plugin returns, and the callbacks only reach it through `ctx`.
        unsafe { (vt.read)(abi::Str::new(params), &ctx, &sink, err) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const IDENTITY: [f64; 12] = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.];

    /// A reader that misbehaves in the way its params say, through the real sink callbacks.
    ///
    /// # Safety
    /// The ABI's calling contract, as `read_volume_into` keeps it.
    unsafe extern "C" fn sloppy_read(
        params: abi::Str,
        _ctx: *const abi::CallContext,
        sink: *const abi::VolumeSink,
        err: *const abi::ErrorSink,
    ) -> abi::Status {
        // SAFETY: the host's sink and params are valid for the call.
        let (s, params) = unsafe { (&*sink, params.as_str().unwrap()) };
        let desc = abi::VolumeDesc {
            world_from_index: IDENTITY,
            background: 0.5,
            index_min: [0; 3],
            index_max: [3; 3],
            grid_name: abi::Str::new("sloppy"),
        };
        let origin = [2i64, 2, 2];
        let dims = [2u64, 2, 3];
        let values = [1.0f32; 12];
        // SAFETY: each call is to the host's sink with its own `ctx` and error sink, with
        // pointers to our locals or null (which the host checks for); "huge" claims more values
        // than it passes, which the host must refuse before reading any.
        unsafe {
            match params {
                // Data before `begin`, passing the host's error on.
                "early" => (s.add_tile)(s.ctx, &origin, &[1; 3], 1.0, err),
                // A block outside the box, its error ignored.
                "ignore" => {
                    (s.begin)(s.ctx, &desc, err);
                    (s.add_dense)(s.ctx, &origin, &dims, values.as_ptr(), err);
                    abi::STATUS_OK
                }
                "nobegin" => abi::STATUS_OK,
                "null" => {
                    (s.begin)(s.ctx, &desc, err);
                    (s.add_dense)(s.ctx, &origin, &[2; 3], std::ptr::null(), err)
                }
                "huge" => {
                    (s.begin)(s.ctx, &desc, err);
                    (s.add_dense)(s.ctx, &origin, &[u64::MAX; 3], values.as_ptr(), err)
                }
                // Typed blocks: bytes 0..8 over 2x2x2 voxels with divisor 2, and 8 u16 ones.
                "typed" => {
                    (s.begin)(s.ctx, &desc, err);
                    let bytes: [u8; 8] = std::array::from_fn(|i| i as u8);
                    let words = [7u16; 8];
                    let w = words.as_ptr() as *const u8;
                    let u8s = (s.add_dense_typed)(
                        s.ctx,
                        &origin,
                        &[2; 3],
                        abi::VOXEL_U8,
                        bytes.as_ptr(),
                        8,
                        2.0,
                        err,
                    );
                    if u8s != abi::STATUS_OK {
                        return u8s;
                    }
                    (s.add_dense_typed)(s.ctx, &[0; 3], &[2; 3], abi::VOXEL_U16, w, 16, 1.0, err)
                }
                "typed-len" => {
                    (s.begin)(s.ctx, &desc, err);
                    let words = [7u16; 8];
                    let w = words.as_ptr() as *const u8;
                    (s.add_dense_typed)(s.ctx, &origin, &[2; 3], abi::VOXEL_U16, w, 8, 1.0, err)
                }
                "typed-format" => {
                    (s.begin)(s.ctx, &desc, err);
                    let p = values.as_ptr() as *const u8;
                    (s.add_dense_typed)(s.ctx, &origin, &[2; 3], 7, p, 32, 1.0, err)
                }
                "typed-misaligned" => {
                    (s.begin)(s.ctx, &desc, err);
                    let words = [7u16; 9];
                    let w = (words.as_ptr() as *const u8).wrapping_add(1);
                    (s.add_dense_typed)(s.ctx, &origin, &[2; 3], abi::VOXEL_U16, w, 16, 1.0, err)
                }
                "typed-divisors" => {
                    (s.begin)(s.ctx, &desc, err);
                    let bytes = [1u8; 8];
                    let b = bytes.as_ptr();
                    let one = [1u64; 3];
                    (s.add_dense_typed)(s.ctx, &[0; 3], &one, abi::VOXEL_U8, b, 1, 255.0, err);
                    (s.add_dense_typed)(s.ctx, &[1; 3], &one, abi::VOXEL_U8, b, 1, 1.0, err)
                }
                "typed-zero" => {
                    (s.begin)(s.ctx, &desc, err);
                    let bytes = [1u8; 8];
                    let b = bytes.as_ptr();
                    (s.add_dense_typed)(s.ctx, &origin, &[2; 3], abi::VOXEL_U8, b, 8, 0.0, err)
                }
                _ => {
                    (s.begin)(s.ctx, &desc, err);
                    (s.add_dense)(s.ctx, &origin, &[2; 3], values.as_ptr(), err)
                }
            }
        }
    }

    static SLOPPY: abi::VolumeReaderVTable = abi::VolumeReaderVTable { read: sloppy_read };

    fn sloppy_registry() -> Registry {
        let library = crate::plugin::Library {
            path: "/plugins/libluxon_sloppy.so".into(),
            name: "sloppy".into(),
            sdk_version: luxon_plugin::SDK_VERSION.into(),
            abi_version: abi::ABI_VERSION,
        };
        let entry = Entry {
            kind: PluginKind::VolumeReader,
            name: "sloppy".into(),
            description: String::new(),
            params_doc: String::new(),
            extensions: Vec::new(),
            library: 0,
            table: Table::VolumeReader(&SLOPPY),
            shadowed: false,
        };
        Registry::with_library(library, vec![entry])
    }

    /// A volume's storage is charged to the budget: one that does not fit is an error naming
    /// the volume and the budget, and gives back what it had taken; one that fits stays charged.
    #[test]
    fn a_volume_over_the_budget_is_an_error_naming_it() {
        let reg = sloppy_registry();
        let entry = reg.get("sloppy", PluginKind::VolumeReader).unwrap();
        let at = Origin {
            file: std::sync::Arc::new("scene.ron".into()),
            line: 4,
            col: 9,
        };
        let tight = Arc::new(Budget::new(1000, "test".into(), None));
        let (o, m) = read_volume(&reg, entry, "ok", &at, Path::new("."), "v", &tight).unwrap_err();
        assert_eq!(o, at);
        assert!(
            m.contains(
                "volume `v` (its storage so far: 0 bytes) needs 2 KiB more, but the memory \
                 budget of 1000 bytes (test) has 1000 bytes left"
            ),
            "{m}"
        );
        assert_eq!(tight.remaining(), 1000);
        let roomy = Arc::new(Budget::new(1 << 20, "test".into(), None));
        let v = read_volume(&reg, entry, "ok", &at, Path::new("."), "v", &roomy).unwrap();
        let used = roomy.used(crate::budget::Use::Volumes);
        assert!((2048..1 << 16).contains(&used), "{used}");
        drop(v);
    }

    #[test]
    fn sink_errors_reach_the_scene_position_and_stick() {
        let reg = sloppy_registry();
        let entry = reg.get("sloppy", PluginKind::VolumeReader).unwrap();
        let at = Origin {
            file: std::sync::Arc::new("scene.ron".into()),
            line: 4,
            col: 9,
        };
        let free = Arc::new(Budget::unlimited());
        let read = |params: &str| read_volume(&reg, entry, params, &at, Path::new("."), "v", &free);

        let v = read("ok").unwrap();
        assert_eq!((v.value([3, 3, 3]), v.value([1, 1, 1])), (1.0, 0.5));
        assert_eq!((v.grid_name.as_str(), v.voxel_count()), ("sloppy", 8));

        let (o, m) = read("early").unwrap_err();
        assert_eq!(o, at);
        assert_eq!(
            m,
            "plugin `sloppy` (libluxon_sloppy.so) failed: tile at [2, 2, 2] of 1x1x1 voxels: \
             `add_tile` was called before `begin`; a reader must describe the grid first"
        );
        let (o, m) = read("ignore").unwrap_err();
        assert_eq!(o, at);
        assert!(
            m.starts_with("plugin `sloppy` (libluxon_sloppy.so) ignored an error")
                && m.contains("dense block at [2, 2, 2] of 2x2x3 voxels reaches from")
                && m.contains("outside the grid's index box [0, 0, 0] to [3, 3, 3]"),
            "{m}"
        );
        let (_, m) = read("nobegin").unwrap_err();
        assert!(m.contains("never called `begin`"), "{m}");
        let (_, m) = read("null").unwrap_err();
        assert!(m.contains("no values (a null pointer)"), "{m}");
        let (_, m) = read("huge").unwrap_err();
        assert!(m.contains("too many voxels"), "{m}");
    }

    #[test]
    fn typed_blocks_keep_their_values_and_are_checked() {
        let reg = sloppy_registry();
        let entry = reg.get("sloppy", PluginKind::VolumeReader).unwrap();
        let at = Origin {
            file: std::sync::Arc::new("scene.ron".into()),
            line: 4,
            col: 9,
        };
        let free = Arc::new(Budget::unlimited());
        let read = |params: &str| read_volume(&reg, entry, params, &at, Path::new("."), "v", &free);
        let v = read("typed").unwrap();
        // Voxel (x, y, z) of the u8 block at (2, 2, 2) is byte x + 2y + 4z, divided by 2.
        for (ijk, want) in [([2, 2, 2], 0.0), ([3, 2, 2], 0.5), ([3, 3, 3], 3.5)] {
            assert_eq!(v.value(ijk), want, "{ijk:?}");
        }
        assert_eq!((v.value([1, 1, 1]), v.value([1, 1, 2])), (7.0, 0.5));
        assert_eq!(v.min_max(), (0.0, 7.0));

        let (_, m) = read("typed-len").unwrap_err();
        assert!(
            m.contains(
                "dense block at [2, 2, 2] of 2x2x2 u16 voxels comes with 8 bytes; expected 16"
            ),
            "{m}"
        );
        let (_, m) = read("typed-format").unwrap_err();
        assert!(
            m.contains("unknown voxel format 7; expected 1 (u8), 2 (u16) or 3 (f32)"),
            "{m}"
        );
        let (_, m) = read("typed-misaligned").unwrap_err();
        assert!(m.contains("not aligned for u16"), "{m}");
        let (_, m) = read("typed-divisors").unwrap_err();
        assert!(
            m.contains(
                "dense block at [1, 1, 1] of 1x1x1 u8 voxels mixes divisors 255 and 1 \
                 for u8 blocks"
            ),
            "{m}"
        );
        let (_, m) = read("typed-zero").unwrap_err();
        assert!(
            m.contains("has the divisor 0; expected a finite number greater than 0"),
            "{m}"
        );
    }
}

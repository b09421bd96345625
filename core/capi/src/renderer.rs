//! Renderers: render scenes into the caller's buffers, report progress, cancel.

use crate::context::CONTEXTS;
use crate::guard::guard;
use crate::handles::{luxon_context, luxon_renderer, luxon_scene, Kind, Table};
use crate::scene::SCENES;
use crate::status::{luxon_status, Failure};
use crate::text::{put, put_sized, read_sized, Versioned};
use luxon_core::api::{Cancel, Color, Plane, Renderer, RendererOptions, Target};
use std::ffi::c_void;
use std::sync::Mutex;

pub(crate) static RENDERERS: Table<RendererEntry> = Table::new(Kind::Renderer);

pub(crate) struct RendererEntry {
    pub renderer: Renderer,
    cancel: Cancel,
    progress: Mutex<Option<ProgressTarget>>,
}

/// Told about finished pixels from the render threads, several at once: `done` of `total`
/// pixels. A non-zero return cancels the render (as `luxon_renderer_cancel`).
pub type luxon_progress_fn =
    Option<unsafe extern "C" fn(done: u64, total: u64, user: *mut c_void) -> i32>;

#[derive(Clone, Copy)]
struct ProgressTarget {
    call: unsafe extern "C" fn(u64, u64, *mut c_void) -> i32,
    user: *mut c_void,
}

// SAFETY: `luxon_renderer_set_progress`'s contract: the callback may be called from any thread,
// at once from several, with `user`.
unsafe impl Send for ProgressTarget {}
// SAFETY: as above.
unsafe impl Sync for ProgressTarget {}

/// A renderer on `context`'s pool (`threads` 0) or on a pool of its own of `threads` threads.
/// Its threads sleep between renders.
///
/// # Safety
/// `out` is valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_renderer_create(
    context: luxon_context,
    threads: u32,
    out: *mut luxon_renderer,
) -> luxon_status {
    guard("luxon_renderer_create", || {
        // SAFETY: NULL or writable (caller); cleared first so a failure leaves {0}.
        unsafe { put(out, "out", luxon_renderer::default()) }?;
        let ctx = CONTEXTS.get(context.id)?;
        let options = RendererOptions {
            threads: (threads > 0).then_some(threads as usize),
        };
        let renderer = Renderer::new(&ctx.value, options)?;
        let cancel = renderer.cancel_handle();
        let id = RENDERERS.insert(RendererEntry {
            renderer,
            cancel,
            progress: Mutex::new(None),
        })?;
        // SAFETY: as above.
        unsafe { put(out, "out", luxon_renderer { id }) }
    })
}

/// Releases a renderer; a render running on it on another thread finishes first.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_renderer_release(renderer: luxon_renderer) -> luxon_status {
    guard("luxon_renderer_release", || {
        RENDERERS.release(renderer.id).map(drop)
    })
}

/// Cancels the render running on `renderer` now, from any thread: it stops within a tile per
/// thread and returns `LUXON_ERROR_CANCELLED`. A render that starts later is not affected.
#[unsafe(no_mangle)]
pub extern "C" fn luxon_renderer_cancel(renderer: luxon_renderer) -> luxon_status {
    guard("luxon_renderer_cancel", || {
        RENDERERS.get(renderer.id)?.value.cancel.cancel();
        Ok(())
    })
}

/// The progress callback of the renderer's next renders (`fn` NULL: none).
///
/// # Safety
/// `fn` must be callable from any thread, at once from several, with `user`, while renders run
/// until it is replaced; it must not unwind (throw) into Luxon.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_renderer_set_progress(
    renderer: luxon_renderer,
    r#fn: luxon_progress_fn,
    user: *mut c_void,
) -> luxon_status {
    guard("luxon_renderer_set_progress", || {
        let r = RENDERERS.get(renderer.id)?;
        let target = r#fn.map(|call| ProgressTarget { call, user });
        *r.value.progress.lock().unwrap_or_else(|e| e.into_inner()) = target;
        Ok(())
    })
}

/// A target's pixel format (`luxon_target.format`).
pub type luxon_pixel_format = i32;
/// No colour (a depth-only render).
pub const LUXON_PIXELS_NONE: luxon_pixel_format = 0;
/// 4 bytes per pixel: R, G, B through the sRGB curve, alpha linear (a PNG's bytes).
pub const LUXON_PIXELS_RGBA8_SRGB: luxon_pixel_format = 1;
/// 4 floats per pixel: linear R, G, B, alpha (alpha is 1).
pub const LUXON_PIXELS_RGBA32F: luxon_pixel_format = 2;

/// Where a render's pixels go: the caller's memory, written row by row as tiles finish (no
/// image of Luxon's own is allocated). Rows are top to bottom; pixel (x, y) starts at byte
/// `y * row_bytes + x * pixel size`; bytes between rows are never touched.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct luxon_target {
    /// `sizeof(luxon_target)`.
    pub size: u32,
    pub width: u32,
    pub height: u32,
    /// `LUXON_PIXELS_*`.
    pub format: luxon_pixel_format,
    /// The colour plane, at least `(height - 1) * row_bytes + width * pixel size` bytes
    /// (floats aligned to 4 bytes); NULL only with `LUXON_PIXELS_NONE`.
    pub pixels: *mut c_void,
    /// Bytes from one row to the next (a multiple of the pixel size); 0: packed rows.
    pub row_bytes: usize,
    /// NULL, or per pixel the distance along its primary rays to the nearest surface they hit
    /// (INFINITY where none does): `(height - 1) * depth_row_bytes + width * 4` bytes,
    /// aligned to 4.
    pub depth: *mut f32,
    /// Bytes from one depth row to the next (a multiple of 4); 0: packed rows.
    pub depth_row_bytes: usize,
}

impl Default for luxon_target {
    fn default() -> Self {
        luxon_target {
            size: 0,
            width: 0,
            height: 0,
            format: LUXON_PIXELS_NONE,
            pixels: std::ptr::null_mut(),
            row_bytes: 0,
            depth: std::ptr::null_mut(),
            depth_row_bytes: 0,
        }
    }
}

impl Versioned for luxon_target {}

/// What a render did (`luxon_render`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct luxon_render_stats {
    /// `sizeof(luxon_render_stats)`.
    pub size: u32,
    /// Render threads.
    pub threads: u32,
    /// Rays of every kind.
    pub rays: u64,
    pub primary_rays: u64,
    pub shadow_rays: u64,
    /// Ray/primitive intersection tests.
    pub tests: u64,
    /// Pixels whose value was NaN or infinite (written as 0).
    pub nan_pixels: u64,
    /// Seconds the render took (the commit before it excluded).
    pub render_seconds: f64,
}

impl Versioned for luxon_render_stats {}

/// The caller's plane of `T` pixels at `p`, `row_bytes` apart (0: packed), for a `w`×`h` image.
///
/// # Safety
/// `p` is NULL or valid for reads and writes of the bytes the plane spans (as `luxon_target`
/// says), not accessed by anyone else during the render.
unsafe fn plane<'a, T>(
    p: *mut c_void,
    row_bytes: usize,
    w: u32,
    h: u32,
    what: &str,
) -> Result<(Plane<'a, T>, std::ops::Range<usize>), Failure> {
    let elem = std::mem::size_of::<T>();
    if p.is_null() {
        return Err(Failure::invalid(format!("`target->{what}` is NULL")));
    }
    if !p.cast::<T>().is_aligned() {
        return Err(Failure::invalid(format!(
            "`target->{what}` is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    let row_bytes = match row_bytes {
        0 => (w as usize).saturating_mul(elem),
        n => n,
    };
    if !row_bytes.is_multiple_of(elem) {
        return Err(Failure::invalid(format!(
            "the {what} plane's row_bytes {row_bytes} is not a multiple of its pixel size {elem}"
        )));
    }
    let stride = row_bytes / elem;
    let len = (h as usize - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(w as usize))
        .filter(|&n| {
            n.checked_mul(elem)
                .is_some_and(|b| b <= isize::MAX as usize)
        });
    let Some(len) = len else {
        return Err(Failure::invalid(format!(
            "the {what} plane of a {w}x{h} image with rows of {row_bytes} bytes is larger than \
             memory"
        )));
    };
    // SAFETY: the caller's plane spans `len` elements of T at `p` (checked: aligned, not NULL,
    // size within isize::MAX), valid and unaliased during the render.
    let data = unsafe { std::slice::from_raw_parts_mut(p.cast::<T>(), len) };
    let start = p as usize;
    Ok((Plane::new(data, stride), start..start + len * elem))
}

/// Renders `scene` (committing it first at the target's size) into the caller's `target`:
/// colour in its format, depth when `target->depth` is not NULL. Pixels are the same, bit for
/// bit, whatever the thread count. Blocks until done, cancelled (`LUXON_ERROR_CANCELLED`: the
/// target holds the pixels finished so far) or failed. While it runs, other calls on `scene`
/// return `LUXON_ERROR_BUSY`. `stats` may be NULL; its `size` must be set.
///
/// # Safety
/// `target` is a valid `luxon_target` whose planes are valid for writes of the bytes it says
/// and touched by no one else (no other thread either) until this returns; the two planes do
/// not overlap. `stats` is NULL or a `luxon_render_stats` whose `size` is set, writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn luxon_render(
    renderer: luxon_renderer,
    scene: luxon_scene,
    target: *const luxon_target,
    stats: *mut luxon_render_stats,
) -> luxon_status {
    guard("luxon_render", || {
        // SAFETY: a valid struct (caller).
        let t = unsafe { read_sized(target, "target", std::mem::size_of::<luxon_target>()) }?;
        let r = RENDERERS.get(renderer.id)?;
        let entry = SCENES.get(scene.id)?;
        if t.width == 0 || t.height == 0 {
            return Err(Failure::invalid(format!(
                "the target is {}x{} pixels; expected at least 1x1",
                t.width, t.height
            )));
        }
        let (w, h) = (t.width, t.height);
        let mut spans = Vec::new();
        let color = match t.format {
            LUXON_PIXELS_NONE => Color::None,
            LUXON_PIXELS_RGBA8_SRGB => {
                // SAFETY: the caller's colour plane (this function's contract).
                let (p, span) = unsafe { plane::<[u8; 4]>(t.pixels, t.row_bytes, w, h, "pixels") }?;
                spans.push(span);
                Color::Rgba8Srgb(p)
            }
            LUXON_PIXELS_RGBA32F => {
                // SAFETY: as above.
                let (p, span) =
                    unsafe { plane::<[f32; 4]>(t.pixels, t.row_bytes, w, h, "pixels") }?;
                spans.push(span);
                Color::Rgba32fLinear(p)
            }
            other => {
                return Err(Failure::invalid(format!(
                    "pixel format {other} is not one of LUXON_PIXELS_NONE (0), \
                     LUXON_PIXELS_RGBA8_SRGB (1), LUXON_PIXELS_RGBA32F (2)"
                )))
            }
        };
        let depth = match t.depth.is_null() {
            true => None,
            false => {
                // SAFETY: the caller's depth plane (this function's contract).
                let (p, span) =
                    unsafe { plane::<f32>(t.depth.cast(), t.depth_row_bytes, w, h, "depth") }?;
                spans.push(span);
                Some(p)
            }
        };
        if let [a, b] = &spans[..] {
            if a.start < b.end && b.start < a.end {
                return Err(Failure::invalid("the pixels and depth planes overlap"));
            }
        }
        // Ranks of a renderer with a communicator may render without planes (rank 0 gets
        // the image).
        let with_comm = crate::mpi::has_communicator(&r.value.renderer);
        if matches!(color, Color::None) && depth.is_none() && !with_comm {
            return Err(Failure::invalid(
                "the target has no colour (LUXON_PIXELS_NONE) and no depth plane",
            ));
        }
        let target = Target {
            width: w,
            height: h,
            color,
            depth,
        };
        let progress = *r.value.progress.lock().unwrap_or_else(|e| e.into_inner());
        let cancel = &r.value.cancel;
        let tell = |done: u64, total: u64| {
            if let Some(p) = progress {
                // SAFETY: the caller's callback, callable from any thread with its pointer
                // (luxon_renderer_set_progress's contract).
                if unsafe { (p.call)(done, total, p.user) } != 0 {
                    cancel.cancel();
                }
            }
        };
        let mut locked = entry.value.lock(scene.id, true)?;
        let done = r
            .value
            .renderer
            .render_with(&mut locked.state.scene, target, &tell)?;
        drop(locked);
        let c = &done.counters;
        let out = luxon_render_stats {
            size: 0,
            threads: u32::try_from(done.threads).unwrap_or(u32::MAX),
            rays: c.rays(),
            primary_rays: c.primary,
            shadow_rays: c.shadow,
            tests: c.tests,
            nan_pixels: c.nan_pixels,
            render_seconds: done.render_time.as_secs_f64(),
        };
        // SAFETY: NULL or writable as far as its size says (caller).
        unsafe { put_sized(stats, &out) };
        Ok(())
    })
}

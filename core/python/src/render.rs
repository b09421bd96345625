//! A render into a new numpy array, with the GIL released: the render runs on a thread of its
//! own while the calling thread waits in steps of [`TICK`], taking the GIL between them to run
//! Python's signal handlers (Ctrl-C) and the progress callback. Either raising cancels the
//! render, which stops within a tile per thread; the exception is what the call raises.

use crate::errors::{internal, panic_text, to_py, IntoPy};
use luxon::api::{self, Color, Plane, Renderer, Target};
use numpy::{PyArray3, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// How often the waiting thread looks at signals and reports progress.
const TICK: Duration = Duration::from_millis(100);

pub struct Request<'a, 'py> {
    pub width: u32,
    pub height: u32,
    pub samples: Option<u32>,
    pub dtype: &'a str,
    pub progress: Option<Bound<'py, PyAny>>,
}

pub fn render<'py>(
    py: Python<'py>,
    scene: &mut api::Scene,
    renderer: &Renderer,
    req: Request<'_, 'py>,
) -> PyResult<Bound<'py, PyAny>> {
    if req.width == 0 || req.height == 0 {
        return Err(PyValueError::new_err(format!(
            "image size {}x{}: width and height must be at least 1",
            req.width, req.height
        )));
    }
    let (w, h) = (req.width as usize, req.height as usize);
    // The sample count asked for holds for this render only.
    let before = scene.desc().render.clone();
    if let Some(n) = req.samples {
        let mut r = before.clone();
        r.samples = n;
        scene.set_render(r).py_err()?;
    }
    let rendered = match req.dtype {
        "uint8" => {
            let array = PyArray3::<u8>::zeros(py, [h, w, 4], false);
            // SAFETY: the array was made just above and no Python code has seen it yet, so
            // this is the only reference to its memory (C-contiguous, h*w*4 bytes).
            let bytes = unsafe { array.as_slice_mut() }?;
            let color = Color::Rgba8Srgb(Plane::new(bytes.as_chunks_mut::<4>().0, w));
            run(
                py,
                scene,
                renderer,
                target(&req, color),
                req.progress.as_ref(),
            )
            .map(|()| array.into_any())
        }
        "float32" => {
            let array = PyArray3::<f32>::zeros(py, [h, w, 4], false);
            // SAFETY: as above: a new array nothing else refers to.
            let floats = unsafe { array.as_slice_mut() }?;
            let color = Color::Rgba32fLinear(Plane::new(floats.as_chunks_mut::<4>().0, w));
            run(
                py,
                scene,
                renderer,
                target(&req, color),
                req.progress.as_ref(),
            )
            .map(|()| array.into_any())
        }
        other => Err(PyValueError::new_err(format!(
            "dtype {other:?}: expected \"uint8\" (sRGB, as a PNG holds it) or \"float32\" (linear)"
        ))),
    };
    if req.samples.is_some() {
        scene.set_render(before).py_err()?;
    }
    rendered
}

fn target<'a>(req: &Request<'_, '_>, color: Color<'a>) -> Target<'a> {
    Target {
        width: req.width,
        height: req.height,
        color,
        depth: None,
    }
}

/// Renders `target` on a thread of its own; this thread waits without the GIL.
fn run(
    py: Python<'_>,
    scene: &mut api::Scene,
    renderer: &Renderer,
    target: Target<'_>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let done = AtomicU64::new(0);
    let total = AtomicU64::new(0);
    let finished = AtomicBool::new(false);
    let waiter = std::thread::current();
    let cancel = renderer.cancel_handle();
    let counter = |d: u64, t: u64| {
        done.fetch_max(d, Ordering::Relaxed);
        total.store(t, Ordering::Relaxed);
    };
    let mut failure: Option<PyErr> = None;
    let mut reported = u64::MAX;
    let result = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let r = catch_unwind(AssertUnwindSafe(|| {
                renderer.render_with(scene, target, &counter)
            }));
            finished.store(true, Ordering::SeqCst);
            waiter.unpark();
            r
        });
        while !finished.load(Ordering::SeqCst) {
            py.detach(|| std::thread::park_timeout(TICK));
            if failure.is_some() || finished.load(Ordering::SeqCst) {
                continue;
            }
            let (d, t) = (done.load(Ordering::Relaxed), total.load(Ordering::Relaxed));
            // Nothing to say before the render has told its size (t == 0: still committing).
            let step = py.check_signals().and_then(|()| match progress {
                Some(cb) if t > 0 && d != reported => {
                    reported = d;
                    cb.call1((d, t)).map(|_| ())
                }
                _ => Ok(()),
            });
            if let Err(e) = step {
                failure = Some(e);
                cancel.cancel();
            }
        }
        worker.join()
    });
    if let Some(e) = failure {
        return Err(e);
    }
    match result {
        Ok(Ok(Ok(_stats))) => match progress {
            Some(cb) => {
                let t = total.load(Ordering::Relaxed);
                cb.call1((t, t)).map(|_| ())
            }
            None => Ok(()),
        },
        Ok(Ok(Err(e))) => Err(to_py(e)),
        Ok(Err(payload)) | Err(payload) => Err(internal(&panic_text(payload.as_ref()))),
    }
}

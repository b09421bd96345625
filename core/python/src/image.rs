//! Images out of Python: files through the writer plugins, and PNG bytes for Jupyter.

use crate::context::PyContext;
use crate::errors::{guard, IntoPy};
use image::ImageEncoder;
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::PathBuf;

/// Writes an `(h, w, 4)` image (uint8 sRGB or float32 linear) with the writer plugin the
/// path's extension names.
#[pyfunction]
pub fn write_image(
    py: Python<'_>,
    context: &Bound<'_, PyContext>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
) -> PyResult<()> {
    guard(|| {
        let (rgba, w, h) = linear_rgba(image)?;
        let ctx = context.get().ctx.clone();
        py.detach(|| luxon::api::write_image(&ctx, &path, &rgba, w, h))
            .py_err()
    })
}

/// PNG bytes of an `(h, w, 4)` image (uint8 sRGB or float32 linear), made in memory.
#[pyfunction]
pub fn encode_png<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyBytes>> {
    guard(|| {
        let (bytes, w, h) = srgb8(image)?;
        let mut png = Vec::new();
        image::codecs::png::PngEncoder::new(&mut png)
            .write_image(&bytes, w, h, image::ExtendedColorType::Rgba8)
            .map_err(|e| PyValueError::new_err(format!("PNG encoding: {e}")))?;
        Ok(PyBytes::new(py, &png))
    })
}

/// Height and width of an `(h, w, 4)` array, or why it is not one.
fn shape(dims: &[usize]) -> PyResult<(u32, u32)> {
    match dims {
        [h, w, 4] if *h > 0 && *w > 0 => {
            let fit =
                |n: usize| u32::try_from(n).map_err(|_| PyValueError::new_err("image too large"));
            Ok((fit(*h)?, fit(*w)?))
        }
        _ => Err(PyValueError::new_err(format!(
            "image of shape {dims:?}: expected (height, width, 4) RGBA"
        ))),
    }
}

fn dtype_error(image: &Bound<'_, PyAny>) -> PyErr {
    let what = image
        .getattr("dtype")
        .map(|d| d.to_string())
        .unwrap_or_else(|_| image.get_type().to_string());
    PyTypeError::new_err(format!(
        "image of {what}: expected a numpy array of uint8 (sRGB) or float32 (linear RGBA)"
    ))
}

/// The image as linear RGBA f32 values (uint8 sRGB decoded exactly as the writers encode).
fn linear_rgba(image: &Bound<'_, PyAny>) -> PyResult<(Vec<f32>, u32, u32)> {
    if let Ok(a) = image.cast::<PyArrayDyn<f32>>() {
        let (h, w) = shape(a.shape())?;
        return Ok((a.to_vec()?, w, h));
    }
    if let Ok(a) = image.cast::<PyArrayDyn<u8>>() {
        let (h, w) = shape(a.shape())?;
        let v = a.to_vec()?;
        let mut out = Vec::with_capacity(v.len());
        for px in v.chunks_exact(4) {
            out.extend(px[..3].iter().map(|&c| srgb_to_linear(c)));
            out.push(f32::from(px[3]) / 255.0);
        }
        return Ok((out, w, h));
    }
    Err(dtype_error(image))
}

/// The image as sRGB RGBA8 bytes (float32 linear encoded as the PNG writer does).
fn srgb8(image: &Bound<'_, PyAny>) -> PyResult<(Vec<u8>, u32, u32)> {
    if let Ok(a) = image.cast::<PyArrayDyn<u8>>() {
        let (h, w) = shape(a.shape())?;
        return Ok((a.to_vec()?, w, h));
    }
    if let Ok(a) = image.cast::<PyArrayDyn<f32>>() {
        let (h, w) = shape(a.shape())?;
        let to8 = |x: f32| (x * 255.0).round() as u8;
        let v = a.to_vec()?;
        let mut out = Vec::with_capacity(v.len());
        for px in v.chunks_exact(4) {
            out.extend(
                px[..3]
                    .iter()
                    .map(|&c| to8(luxon_plugin::linear_to_srgb(c))),
            );
            out.push(to8(if px[3].is_nan() {
                0.0
            } else {
                px[3].clamp(0.0, 1.0)
            }));
        }
        return Ok((out, w, h));
    }
    Err(dtype_error(image))
}

/// The linear value of an 8-bit sRGB code (the inverse of `luxon_plugin::linear_to_srgb`,
/// close enough that the writers give the same code back).
fn srgb_to_linear(c: u8) -> f32 {
    let s = f32::from(c) / 255.0;
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

//! `luxon._luxon`: the compiled half of the Python module `luxon` (the other half is the
//! package in `python/luxon`, which wraps these types with keyword arguments and docstrings).
//!
//! Everything here is thin over [`luxon::api`]: a context, a retained scene edited through the
//! scene files' RON text, and renders into numpy arrays with the GIL released. Every method
//! runs under `errors::guard`, so a Luxon error becomes a Python exception with the command
//! line's message, and a panic becomes `luxon.LuxonError`, never a Python-killing abort.

mod arrays;
mod context;
mod errors;
mod image;
mod render;
mod scene;

use pyo3::prelude::*;

#[pymodule]
fn _luxon(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<context::PyContext>()?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<scene::PyLightId>()?;
    m.add_class::<scene::PyObjectId>()?;
    m.add_function(wrap_pyfunction!(image::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(image::encode_png, m)?)?;
    Ok(())
}

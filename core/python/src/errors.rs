//! Luxon's errors as Python exceptions (the classes live in `luxon/_errors.py`), and the guard
//! that keeps panics from reaching Python.

use luxon::api::Error;
use luxon_formats::{Origin, SceneError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Runs `f`, turning a panic into `luxon.LuxonError("internal error: ...")`.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => Err(internal(&panic_text(payload.as_ref()))),
    }
}

/// A panic's message, as far as it has one.
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".into()
    }
}

/// `luxon.LuxonError` for a bug in Luxon (a panic): it says so, and asks for a report.
pub fn internal(what: &str) -> PyErr {
    Python::attach(|py| {
        raise(
            py,
            "LuxonError",
            &format!("internal error (a bug in Luxon; please report it): {what}"),
            None,
        )
    })
}

/// A Luxon error as the Python exception of its kind, with the message the command line prints.
pub fn to_py(e: Error) -> PyErr {
    Python::attach(|py| {
        let message = e.to_string();
        let (class, at) = match &e {
            Error::Scene(s) => ("SceneError", scene_place(s)),
            Error::At { at, .. } => ("SceneError", Some(place(at))),
            Error::Plugin(_) => ("PluginError", None),
            Error::Cancelled => ("CancelledError", None),
            Error::Api(_) | Error::Target(_) | Error::Usage(_) => ("UsageError", None),
            Error::OutOfMemory { .. } => ("OutOfMemoryError", None),
            Error::Io { path, .. } => ("FileError", Some(Place::file(path))),
            Error::Render(_) | Error::Mpi(_) => ("LuxonError", None),
        };
        raise(py, class, &message, at)
    })
}

/// Where in a file an error is: the exception's `file`, `line` and `column`.
pub struct Place {
    file: String,
    line: Option<u32>,
    column: Option<u32>,
}

impl Place {
    fn file(path: &std::path::Path) -> Place {
        Place {
            file: path.display().to_string(),
            line: None,
            column: None,
        }
    }
}

fn place(at: &Origin) -> Place {
    Place {
        file: at.file.display().to_string(),
        line: Some(at.line),
        column: Some(at.col),
    }
}

fn scene_place(e: &SceneError) -> Option<Place> {
    match e {
        SceneError::At { at, .. } => Some(place(at)),
        SceneError::Io { path, .. } | SceneError::File { path, .. } => Some(Place::file(path)),
    }
}

/// `luxon.<class>(message)` with its place set; falls back to RuntimeError if the package's
/// classes cannot be imported (the module used without its package).
fn raise(py: Python<'_>, class: &str, message: &str, at: Option<Place>) -> PyErr {
    let made = (|| -> PyResult<PyErr> {
        let cls = py.import("luxon._errors")?.getattr(class)?;
        let exc = cls.call1(PyTuple::new(py, [message])?)?;
        if let Some(at) = at {
            exc.setattr("file", at.file)?;
            exc.setattr("line", at.line)?;
            exc.setattr("column", at.column)?;
        }
        Ok(PyErr::from_value(exc))
    })();
    made.unwrap_or_else(|_| pyo3::exceptions::PyRuntimeError::new_err(message.to_string()))
}

/// `Result<T, Error>` into `PyResult<T>`.
pub trait IntoPy<T> {
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, Error> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

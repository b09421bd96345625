//! `luxon.Context`: the plugins found and the thread pool, shared by the scenes made with it.

use crate::errors::{guard, IntoPy};
use luxon::api::{Context, ContextOptions};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;

#[pyclass(module = "luxon._luxon", name = "Context", frozen, subclass)]
pub struct PyContext {
    pub ctx: Arc<Context>,
}

#[pymethods]
impl PyContext {
    #[new]
    #[pyo3(signature = (threads = 0, plugin_path = Vec::new()))]
    fn new(py: Python<'_>, threads: usize, plugin_path: Vec<PathBuf>) -> PyResult<Self> {
        guard(|| {
            let o = ContextOptions {
                plugin_path,
                threads,
            };
            // Loading plugins and starting threads takes a while; other Python threads run.
            let ctx = py.detach(|| Context::new(o)).py_err()?;
            Ok(PyContext { ctx: Arc::new(ctx) })
        })
    }

    /// Threads of the context's pool.
    #[getter]
    fn threads(&self) -> usize {
        self.ctx.threads()
    }

    /// The plugins found: `(kind, name, library path)` tuples, in search order.
    fn plugins(&self) -> Vec<(String, String, PathBuf)> {
        // From the libraries' name tables: listing them loads none.
        let r = self.ctx.registry();
        r.provided()
            .into_iter()
            .map(|(kind, name, path)| (kind.to_string(), name.to_string(), path.to_path_buf()))
            .collect()
    }

    /// Every directory or file searched for plugins, in order.
    fn searched(&self) -> Vec<PathBuf> {
        self.ctx.registry().searched.clone()
    }

    /// Plugin files that could not be used, and why: `(path, message)` tuples.
    fn problems(&self) -> Vec<(PathBuf, String)> {
        let r = self.ctx.registry();
        r.problems
            .iter()
            .chain(&r.notes)
            .map(|p| (p.path.clone(), p.message.clone()))
            .collect()
    }
}

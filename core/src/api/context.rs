//! [`Context`]: the plugins a program found and the thread pool its renders and builds run on.

use crate::error::Error;
use crate::plugin::{Problem, Registry};
use crate::schedule::{available_cpus, thread_pool};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How a [`Context`] starts.
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Directories searched for plugins before `$LUXON_PLUGIN_PATH` and the program's own.
    pub plugin_path: Vec<PathBuf>,
    /// Threads of the context's pool; 0: every CPU this process may run on.
    pub threads: usize,
}

/// The plugins found (searched once) and a thread pool of the size asked for. Every build,
/// load and render of the API runs on a context's or a renderer's pool, never on rayon's
/// global one, so an embedding program decides how many threads Luxon uses. Its threads sleep
/// between renders.
pub struct Context {
    pub(super) pool: Arc<rayon::ThreadPool>,
    pub(super) registry: Arc<Registry>,
}

impl Context {
    /// Discovers the plugins and starts the pool.
    pub fn new(o: ContextOptions) -> Result<Context, Error> {
        Context::with_plugin_home(o, None)
    }

    /// [`Context::new`] for a library that a host program loaded (the C API): its plugins
    /// are also searched in `home`, the library's directory, after `$LUXON_PLUGIN_PATH` and
    /// before the executable's (see [`Registry::discover_with_home`]).
    pub fn with_plugin_home(o: ContextOptions, home: Option<&Path>) -> Result<Context, Error> {
        let threads = match o.threads {
            0 => available_cpus(),
            n => n,
        };
        let pool = Arc::new(thread_pool(threads)?);
        let registry = Arc::new(Registry::discover_with_home(&o.plugin_path, home));
        Ok(Context { pool, registry })
    }

    /// Plugin files that were skipped (not loadable, wrong ABI...), with why. Nothing is
    /// printed or logged about them: telling the user is the caller's choice.
    pub fn plugin_problems(&self) -> &[Problem] {
        &self.registry.problems
    }

    /// The plugins found.
    pub fn registry(&self) -> &Registry {
        &self.registry
    }

    /// Threads of the context's pool.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Runs `f` on the context's pool (so any parallel work in it uses those threads).
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool.install(f)
    }
}

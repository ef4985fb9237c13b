//! A bake running on its own Rust thread, with the GIL released: Python polls its progress,
//! may cancel it, and collects the result when it is done.

use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use penumbra::scene::json::SceneJson;
use penumbra::{Bake, Progress};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::bake_result::to_py_dict;
use crate::error::Error;

type Outcome = Result<Arc<Bake>, Error>;

/// Handle of a running bake (`penumbra._core.start_bake`).
#[pyclass(frozen, module = "penumbra._core")]
pub struct BakeJob {
    progress: Arc<Progress>,
    thread: Mutex<Option<JoinHandle<Result<Bake, penumbra::BakeError>>>>,
    outcome: Mutex<Option<Outcome>>,
    n_lights: usize,
}

impl BakeJob {
    pub fn start(scene: SceneJson) -> Result<Self, Error> {
        let progress = Arc::new(Progress::new());
        let n_lights = scene.lights.len();
        let p = progress.clone();
        let thread = std::thread::Builder::new()
            .name("penumbra-bake".into())
            .spawn(move || {
                p.stage("validate");
                let scene = penumbra::scene::validate(&scene)?;
                penumbra::bake(&scene, &p)
            })
            .map_err(|e| Error::Internal(format!("could not start the bake thread: {e}")))?;
        Ok(BakeJob {
            progress,
            thread: Mutex::new(Some(thread)),
            outcome: Mutex::new(None),
            n_lights,
        })
    }

    /// Joins the thread once; later calls see the kept outcome.
    fn wait(&self) -> Outcome {
        let mut outcome = self.outcome.lock().unwrap_or_else(|e| e.into_inner());
        if outcome.is_none() {
            let handle = self.thread.lock().unwrap_or_else(|e| e.into_inner()).take();
            let joined = match handle {
                Some(h) => match h.join() {
                    Ok(r) => r.map(Arc::new).map_err(Error::from),
                    Err(panic) => Err(Error::Internal(panic_message(&panic))),
                },
                None => Err(Error::Internal("the bake thread is gone".into())),
            };
            *outcome = Some(joined);
        }
        outcome.clone().expect("set above")
    }
}

#[pymethods]
impl BakeJob {
    /// `(stage, fraction)`: the pipeline stage running now and how much of it is done.
    fn progress(&self) -> (&'static str, f64) {
        let (stage, fraction) = self.progress.get();
        (if stage.is_empty() { "starting" } else { stage }, fraction)
    }

    /// True once the bake has finished, failed or stopped after a cancel.
    fn done(&self) -> bool {
        if self
            .outcome
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .is_some()
        {
            return true;
        }
        self.thread
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .as_ref()
            .is_none_or(|h| h.is_finished())
    }

    /// Asks the bake to stop; it does at the next check between units of work, and
    /// `result()` then raises `BakeError` with `kind == "cancelled"`.
    fn cancel(&self) {
        self.progress.cancel();
    }

    fn cancelled(&self) -> bool {
        self.progress.is_cancelled()
    }

    /// Waits (GIL released) and returns the bake as a dict of numpy arrays, or raises
    /// `BakeError`.
    pub fn result<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let bake = py.detach(|| self.wait())?;
        to_py_dict(py, &bake, self.n_lights)
    }
}

impl Drop for BakeJob {
    /// A job dropped unfinished would otherwise keep both cores busy for nothing.
    fn drop(&mut self) {
        self.progress.cancel();
    }
}

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "panic".into()
    }
}

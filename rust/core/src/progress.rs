//! Progress reporting and cancellation, shared between a bake and whoever polls it
//! (the CLI's progress bar, the Python binding's modal operator).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;

use crate::BakeError;

#[derive(Debug, Default)]
pub struct Progress {
    stage: Mutex<&'static str>,
    fraction: AtomicU64,
    cancel: AtomicBool,
}

impl Progress {
    pub fn new() -> Self {
        Self::default()
    }

    /// Enters a stage; the fraction restarts at 0.
    pub fn stage(&self, name: &'static str) {
        *self.stage.lock().unwrap_or_else(|e| e.into_inner()) = name;
        self.fraction.store(0f64.to_bits(), Ordering::Relaxed);
    }

    pub fn set_fraction(&self, f: f64) {
        self.fraction
            .store(f.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
    }

    /// (stage name, fraction of that stage done in [0, 1]).
    pub fn get(&self) -> (&'static str, f64) {
        let s = *self.stage.lock().unwrap_or_else(|e| e.into_inner());
        (s, f64::from_bits(self.fraction.load(Ordering::Relaxed)))
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once `cancel` was called: stages call this between units of work.
    pub fn check(&self) -> Result<(), BakeError> {
        if self.is_cancelled() {
            Err(BakeError::Cancelled)
        } else {
            Ok(())
        }
    }
}

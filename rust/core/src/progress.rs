//! Progress reporting and cancellation, shared between a bake and whoever polls it
//! (the CLI's progress bar, the Python binding's modal operator).
//!
//! It is also the memory watchdog: the resource model (`scene::resources`) refuses what it
//! can foresee, and whatever it missed is caught here. Once armed with a budget, `check`
//! looks at the process's resident memory at most every 50 ms; when it has grown by more
//! than the budget since arming, the bake stops with a `max_memory` error (not a cancel).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use crate::BakeError;

#[derive(Debug, Default)]
pub struct Progress {
    stage: Mutex<&'static str>,
    fraction: AtomicU64,
    cancel: AtomicBool,
    /// Bytes the process may grow by (0: no watchdog), from `base` resident bytes.
    budget: AtomicU64,
    base: AtomicU64,
    /// Nanoseconds since `epoch()` before which `check` does not look at memory again.
    next_look: AtomicU64,
    /// Why the watchdog stopped the bake.
    tripped: Mutex<Option<BakeError>>,
}

/// Memory is looked at no more often than this.
const LOOK_EVERY_NS: u64 = 50_000_000;

fn epoch() -> Instant {
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
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

    /// `Err(Cancelled)` once `cancel` was called, or the watchdog's error once the bake
    /// has grown past its memory budget: stages call this between units of work.
    pub fn check(&self) -> Result<(), BakeError> {
        if !self.is_cancelled() && !self.memory_ok() {
            self.cancel();
        }
        if self.is_cancelled() {
            Err(self.stopped_by().unwrap_or(BakeError::Cancelled))
        } else {
            Ok(())
        }
    }

    /// Arms the watchdog: from now on the process may grow by `bytes` (`max_memory`).
    pub fn watch_memory(&self, bytes: u64) {
        if let Some(base) = crate::scene::machine::resident_bytes() {
            self.base.store(base, Ordering::Relaxed);
            self.budget.store(bytes, Ordering::Relaxed);
        }
    }

    /// The watchdog's error, when it stopped the bake.
    pub fn stopped_by(&self) -> Option<BakeError> {
        self.tripped
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// False once the process has grown by more than the budget (looked at every 50 ms).
    fn memory_ok(&self) -> bool {
        let budget = self.budget.load(Ordering::Relaxed);
        if budget == 0 {
            return true;
        }
        let now = epoch().elapsed().as_nanos() as u64;
        let next = self.next_look.load(Ordering::Relaxed);
        if now < next
            || self
                .next_look
                .compare_exchange(
                    next,
                    now + LOOK_EVERY_NS,
                    Ordering::Relaxed,
                    Ordering::Relaxed,
                )
                .is_err()
        {
            return true;
        }
        let Some(rss) = crate::scene::machine::resident_bytes() else {
            return true;
        };
        let grown = rss.saturating_sub(self.base.load(Ordering::Relaxed));
        if grown <= budget {
            return true;
        }
        let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
        *self.tripped.lock().unwrap_or_else(|e| e.into_inner()) = Some(BakeError::setting(
            "max_memory",
            format!(
                "the bake grew by {:.0} MiB, over max_memory = {:.0} MiB, in stage \"{}\" (the estimate before baking missed it; raise max_memory or the element sizes)",
                mib(grown),
                mib(budget),
                self.get().0
            ),
        ));
        false
    }
}

//! Delaunay refinement that a cancel can interrupt. spade's `refine` runs to the end once
//! called, and one large receiver (a floor under hundreds of shadows) can refine for
//! seconds. It cannot be handed its vertices in rounds either: a second call starts
//! afresh, without the first call's queue and without its record of which vertices it
//! added on input edges, the record that keeps encroachment splits from running away at
//! small input angles. Rounds of 20k vertices gave a mesh that depended on the round size
//! and made quads2000's floor refine in 6.5 s instead of 2.1 s (42 rounds, each one
//! re-examining every triangle).
//!
//! So a large refinement is one call, run on a thread of its own while the caller waits
//! for it, checking for a cancel every few milliseconds. A cancel returns at once and
//! abandons the triangulation to that thread, which drops it when spade is done: the
//! bake is cancelled within the check interval, and the refined mesh is byte for byte
//! the one a single call gives.

use std::sync::mpsc;
use std::time::Duration;

use spade::{RefinementParameters, Triangulation};

use crate::progress::Progress;
use crate::BakeError;

use super::Cdt;

/// Refinements allowed at most this many vertices run inline: some 50 ms in a release
/// build, so a thread is not worth it.
pub const INLINE_VERTICES: usize = 20_000;

/// How often the caller looks for a cancel while a refinement runs on its own thread.
const CHECK_INTERVAL: Duration = Duration::from_millis(10);

/// Refines `cdt` with `params`, adding at most `max_additional` vertices, and returns
/// `Cancelled` (or the watchdog's error) within [`CHECK_INTERVAL`] of `progress` asking for
/// it; `cdt` is then left empty.
pub fn refine_in_rounds(
    cdt: &mut Cdt,
    params: RefinementParameters<f64>,
    max_additional: usize,
    progress: &Progress,
) -> Result<(), BakeError> {
    progress.check()?;
    let params = params.with_max_additional_vertices(max_additional);
    if max_additional <= INLINE_VERTICES {
        cdt.refine(params);
        return Ok(());
    }
    let mut taken = std::mem::replace(cdt, Cdt::new());
    let (done, result) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        taken.refine(params);
        // The receiver is gone when the bake was cancelled: nothing to hand back.
        let _ = done.send(taken);
    });
    loop {
        match result.recv_timeout(CHECK_INTERVAL) {
            Ok(refined) => {
                *cdt = refined;
                return progress.check();
            }
            Err(mpsc::RecvTimeoutError::Timeout) => progress.check()?,
            // spade panicked: pass the panic on, as an inline call would.
            Err(mpsc::RecvTimeoutError::Disconnected) => match worker.join() {
                Err(panic) => std::panic::resume_unwind(panic),
                Ok(()) => unreachable!("the refinement thread ends by sending its result"),
            },
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use spade::Point2;

    /// Random points and crossing constraints in the unit square, seeded.
    fn triangulation() -> Cdt {
        let mut seed = 15u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut cdt = Cdt::new();
        for _ in 0..400 {
            let _ = cdt.insert(Point2::new(next(), next()));
        }
        for _ in 0..60 {
            let a = cdt.insert(Point2::new(next(), next())).unwrap();
            let b = cdt.insert(Point2::new(next(), next())).unwrap();
            if a != b {
                cdt.add_constraint_and_split(a, b, |p| p);
            }
        }
        cdt
    }

    fn params() -> RefinementParameters<f64> {
        RefinementParameters::new()
            .with_angle_limit(spade::AngleLimit::from_deg(25.0))
            .with_max_allowed_area(2e-5)
            .with_min_required_area(1e-8)
    }

    fn snapshot(cdt: &Cdt) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
        (
            cdt.vertices()
                .map(|v| [v.position().x, v.position().y])
                .collect(),
            cdt.inner_faces()
                .map(|f| f.vertices().map(|v| v.fix().index()))
                .collect(),
        )
    }

    /// A refinement larger than one inline call (42k vertices) gives exactly the mesh of a
    /// single spade call (the 20k-vertex rounds it replaces restarted spade each round).
    #[test]
    fn a_large_refinement_is_the_single_call_mesh() {
        let mut once = triangulation();
        let allowance = 1_000_000;
        once.refine(params().with_max_additional_vertices(allowance));
        assert!(
            once.num_vertices() > 2 * INLINE_VERTICES,
            "{}",
            once.num_vertices()
        );
        let mut ours = triangulation();
        refine_in_rounds(&mut ours, params(), allowance, &Progress::new()).unwrap();
        assert_eq!(snapshot(&ours), snapshot(&once));
    }

    #[test]
    fn a_cancel_returns_while_spade_refines() {
        let p = std::sync::Arc::new(Progress::new());
        let q = p.clone();
        let canceller = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(5));
            q.cancel();
            std::time::Instant::now()
        });
        let mut cdt = triangulation();
        // Small enough triangles that spade would add millions of vertices.
        let r = refine_in_rounds(
            &mut cdt,
            params()
                .with_max_allowed_area(1e-9)
                .with_min_required_area(0.0),
            10_000_000,
            &p,
        );
        let returned = std::time::Instant::now();
        let cancelled = canceller.join().unwrap();
        assert_eq!(r, Err(BakeError::Cancelled));
        let took = returned.saturating_duration_since(cancelled);
        assert!(took < Duration::from_millis(200), "{took:?}");
    }
}

//! Delaunay refinement that a cancel can interrupt. spade's `refine` runs to the end once
//! called, and one large receiver (a floor under hundreds of shadows) can refine for
//! seconds; so the vertex allowance is handed out in rounds, with a cancellation check
//! between them. A round that completes ends it, so a small receiver refines in one call
//! exactly as before; only receivers needing more than one round's vertices are refined
//! in several passes (each pass restarts from the current triangulation).

use spade::{ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};

use crate::progress::Progress;
use crate::BakeError;

/// Vertices one round may add: some 50 ms of refinement in a release build.
pub const ROUND_VERTICES: usize = 20_000;

/// Refines `cdt` with `params`, adding at most `max_additional` vertices in all, checking
/// `progress` for a cancel between rounds.
pub fn refine_in_rounds(
    cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
    params: RefinementParameters<f64>,
    max_additional: usize,
    progress: &Progress,
) -> Result<(), BakeError> {
    let mut left = max_additional;
    loop {
        progress.check()?;
        let round = left.min(ROUND_VERTICES);
        let before = cdt.num_vertices();
        let r = cdt.refine(params.clone().with_max_additional_vertices(round));
        let added = cdt.num_vertices().saturating_sub(before);
        left = left.saturating_sub(added);
        if r.refinement_complete || left == 0 || added == 0 {
            return Ok(());
        }
    }
}

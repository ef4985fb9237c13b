//! A point well inside a face, for classifying the face against shadow volumes.
//!
//! Horizontal scanlines through the middle of the tallest gaps between vertex heights cross
//! no vertex, so along each one the face is a set of intervals bounded by edges that span the
//! whole gap. The middle of each interval is a candidate; its clearance is estimated from the
//! gap height and the distance to the two edges bounding the interval, and candidates are
//! tried best first until one passes the exact inside test.

use glam::DVec2;

use super::{on_segment, winding};

/// Scanlines tried per face: enough to find a roomy spot in the faces we see, while keeping
/// the cost linear in the face size.
const MAX_LINES: usize = 16;

/// `walk`: every directed boundary edge of the face (outer loop counter-clockwise, holes
/// clockwise, dangling edges once each way), so that the winding number is 1 inside.
pub(super) fn point(pts: &[DVec2], walk: &[(u32, u32)]) -> DVec2 {
    let mut ys: Vec<f64> = walk.iter().map(|&(a, _)| pts[a as usize].y).collect();
    ys.sort_unstable_by(f64::total_cmp);
    ys.dedup();
    let mut gaps: Vec<(f64, f64)> = ys.windows(2).map(|w| (w[0], w[1])).collect();
    gaps.sort_unstable_by(|g, h| (h.1 - h.0).total_cmp(&(g.1 - g.0)));
    gaps.truncate(MAX_LINES);

    let mut candidates: Vec<(f64, DVec2)> = Vec::new();
    let mut crossings: Vec<(f64, i32, usize)> = Vec::new();
    for (lo, hi) in gaps {
        let y = 0.5 * (lo + hi);
        if !(y > lo && y < hi) {
            continue;
        }
        crossings.clear();
        for (i, &(a, b)) in walk.iter().enumerate() {
            let (pa, pb) = (pts[a as usize], pts[b as usize]);
            if (pa.y < y) != (pb.y < y) {
                let x = pa.x + (y - pa.y) * (pb.x - pa.x) / (pb.y - pa.y);
                crossings.push((x, if pb.y > pa.y { 1 } else { -1 }, i));
            }
        }
        crossings.sort_unstable_by(|p, q| p.0.total_cmp(&q.0));
        let mut w = 0;
        for pair in crossings.windows(2) {
            w += pair[0].1;
            let (x0, x1) = (pair[0].0, pair[1].0);
            if w == 0 || x1 <= x0 {
                continue;
            }
            let p = DVec2::new(0.5 * (x0 + x1), y);
            let clearance = [pair[0].2, pair[1].2]
                .iter()
                .map(|&i| line_distance(pts, walk[i], p))
                .fold(0.5 * (hi - lo), f64::min);
            candidates.push((clearance, p));
        }
    }
    candidates.sort_unstable_by(|p, q| q.0.total_cmp(&p.0));
    for &(_, p) in &candidates {
        if strictly_inside(pts, walk, p) {
            return p;
        }
    }
    // Only a face too thin for any scanline to land inside it in floating point gets here.
    candidates
        .first()
        .map_or_else(|| centroid(pts, walk), |c| c.1)
}

fn line_distance(pts: &[DVec2], (a, b): (u32, u32), p: DVec2) -> f64 {
    let (pa, pb) = (pts[a as usize], pts[b as usize]);
    (pb - pa).perp_dot(p - pa).abs() / (pb - pa).length()
}

/// Exact: off every boundary edge, and enclosed by the boundary.
fn strictly_inside(pts: &[DVec2], walk: &[(u32, u32)], p: DVec2) -> bool {
    !walk.iter().any(|&(a, b)| on_segment(pts, a, b, p))
        && winding(pts, walk.iter().copied(), p) != 0
}

fn centroid(pts: &[DVec2], walk: &[(u32, u32)]) -> DVec2 {
    let sum = walk
        .iter()
        .fold(DVec2::ZERO, |s, &(a, _)| s + pts[a as usize]);
    sum / walk.len().max(1) as f64
}

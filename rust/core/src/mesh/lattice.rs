//! Seed nodes: a triangular lattice per arrangement face, graded by the element size the
//! face asks for (`sizing`), and shrinking towards the ends of D0 lines when no refinement
//! to a tolerance follows.

use glam::DVec2;

use crate::geom::polygon::{orient, segment_distance as seg_dist};
use crate::regions::arrangement::ArrFace;

/// Ends of D0 lines (the feet of a box on the floor, where a solid passes through): there
/// the light depends on the direction one comes from, not on the distance, so no linear
/// element that touches such a point is right, however small. Elements shrink towards them
/// in proportion to the distance, which keeps each element's angular span, and with it the
/// interpolation error, bounded, and leaves the wrong values at the corner itself only a
/// tiny area.
pub(super) struct Corners {
    points: Vec<DVec2>,
    floor: f64,
}

/// Element size at most this fraction of the distance to a corner.
const PER_CORNER_DISTANCE: f64 = 0.7;
/// ... and never below this fraction of `element_size`.
const CORNER_FLOOR: f64 = 1.0 / 16.0;

impl Corners {
    pub(super) fn new(d0_lines: &[[DVec2; 2]], coarse: f64) -> Self {
        let mut points: Vec<DVec2> = d0_lines.iter().flat_map(|[a, b]| [*a, *b]).collect();
        points.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        points.dedup();
        Corners {
            points,
            floor: coarse * CORNER_FLOOR,
        }
    }

    /// `size` capped near corners, for anywhere within `reach` of `p` (a negative reach: the
    /// largest cap there).
    pub(super) fn cap(&self, size: f64, p: DVec2, reach: f64) -> f64 {
        let near = self
            .points
            .iter()
            .map(|c| (*c - p).length())
            .fold(f64::INFINITY, f64::min);
        if !near.is_finite() {
            return size;
        }
        size.min(((near - reach).max(0.0) * PER_CORNER_DISTANCE).max(self.floor))
    }

    pub(super) fn smallest(&self) -> f64 {
        if self.points.is_empty() {
            f64::INFINITY
        } else {
            self.floor
        }
    }
}

/// Lattice points in `f` whose spacing follows `size(p, reach)` (the size anywhere within
/// `reach` of `p`; a negative reach asks for the largest size there): the face's bounds are
/// split into blocks until the size varies little across each, then each block gets a
/// lattice at its smallest size. Blocks of one size share one global lattice, so they
/// join seamlessly; where sizes step, refinement mends the angles.
pub(super) fn graded_lattice(
    verts: &[DVec2],
    f: &ArrFace,
    size: &dyn Fn(DVec2, f64) -> f64,
    out: &mut Vec<DVec2>,
) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for &v in &f.outer {
        lo = lo.min(verts[v as usize]);
        hi = hi.max(verts[v as usize]);
    }
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        return;
    }
    let mut stack = vec![(lo, hi, 0u32)];
    while let Some((blo, bhi, depth)) = stack.pop() {
        let c = 0.5 * (blo + bhi);
        let reach = 0.5 * (bhi - blo).length();
        let small = size(c, reach);
        let large = size(c, -reach);
        let side = (bhi - blo).max_element();
        if large <= 1.5 * small || side <= 4.0 * small || depth >= 12 {
            lattice_in_face(verts, f, small, (blo, bhi), (lo, hi), out);
            continue;
        }
        let m = c;
        for (a, b) in [
            (blo, m),
            (DVec2::new(m.x, blo.y), DVec2::new(bhi.x, m.y)),
            (DVec2::new(blo.x, m.y), DVec2::new(m.x, bhi.y)),
            (m, bhi),
        ] {
            stack.push((a, b, depth + 1));
        }
    }
}

/// Triangular lattice points strictly inside `f` and in the block `[blo, bhi)` (closed on
/// the sides where the block meets the face's bounds `outer`), at least 0.35·h from the
/// face's boundary.
fn lattice_in_face(
    verts: &[DVec2],
    f: &ArrFace,
    h: f64,
    (blo, bhi): (DVec2, DVec2),
    outer: (DVec2, DVec2),
    out: &mut Vec<DVec2>,
) {
    if f.area < 0.2 * h * h {
        return;
    }
    let (lo, hi) = (blo, bhi);
    let in_block = |p: DVec2| {
        p.x >= blo.x
            && p.y >= blo.y
            && (p.x < bhi.x || bhi.x >= outer.1.x)
            && (p.y < bhi.y || bhi.y >= outer.1.y)
    };
    let dy = h * 0.866_025_403_784_438_6;
    let j0 = (lo.y / dy).floor() as i64;
    let j1 = (hi.y / dy).ceil() as i64;
    let i0 = (lo.x / h).floor() as i64 - 1;
    let i1 = (hi.x / h).ceil() as i64 + 1;
    let loops: Vec<&Vec<u32>> = std::iter::once(&f.outer).chain(f.holes.iter()).collect();
    let clearance = 0.35 * h;
    for j in j0..=j1 {
        let y = j as f64 * dy;
        let off = if j.rem_euclid(2) == 1 { 0.5 * h } else { 0.0 };
        for i in i0..=i1 {
            let p = DVec2::new(i as f64 * h + off, y);
            if p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y || !in_block(p) {
                continue;
            }
            if winding(verts, &f.outer, p) == 0
                || f.holes.iter().any(|hl| winding(verts, hl, p) != 0)
            {
                continue;
            }
            let near = loops.iter().any(|l| {
                (0..l.len()).any(|k| {
                    seg_dist(
                        verts[l[k] as usize],
                        verts[l[(k + 1) % l.len()] as usize],
                        p,
                    ) < clearance
                })
            });
            if !near {
                out.push(p);
            }
        }
    }
}

/// Winding number of the closed loop around `p` (exact orientation tests).
fn winding(verts: &[DVec2], l: &[u32], p: DVec2) -> i32 {
    let mut w = 0;
    for k in 0..l.len() {
        let a = verts[l[k] as usize];
        let b = verts[l[(k + 1) % l.len()] as usize];
        if a.y <= p.y {
            if b.y > p.y && orient(a, b, p) > 0.0 {
                w += 1;
            }
        } else if b.y <= p.y && orient(a, b, p) < 0.0 {
            w -= 1;
        }
    }
    w
}

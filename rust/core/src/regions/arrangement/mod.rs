//! Per receiver polygon: the planar arrangement of the discontinuity edges and the receiver
//! boundary, and the loops that bound its faces (paper §2.2 step 3 and §2.3).
//!
//! The paper adds edge sets incrementally and re-traces the loops they touch; we build the
//! whole arrangement of one receiver at once, which gives the same loops with less
//! bookkeeping. Stages, each in its own file:
//! 1. `snap`: one vertex per location (points closer than `snap` are one vertex).
//! 2. `split`: segments split at every crossing, touch and collinear overlap, found through a
//!    uniform grid rather than all pairs; overlapping pieces merged into one edge.
//! 3. `trace`: half-edges walked by the smallest-left-turn rule into loops; the winding of a
//!    loop says outer loop or hole; holes go to the face that contains them.
//! 4. `interior`: a point well inside each face, for the light relation test (§2.4).
//!
//! # Precision
//! Every yes/no decision about positions (does it cross, which side, which comes first
//! around a vertex, is it inside) is an exact predicate on the `f64` coordinates, except
//! the deliberate snapping ones (is it within `snap`), which compare `f64` distances.
//! Crossing points are rounded and then snapped to vertices within `snap`; a vertex within
//! `snap` of an edge splits it, or merges with its end if that is within a few `snap`.
//! Splitting is repeated until it finds nothing more, which takes a few rounds; the result
//! then has no two edges that cross, overlap or touch except at shared end vertices.

mod int_hash;
mod interior;
mod snap;
mod split;
mod trace;

#[cfg(test)]
mod test;

use glam::DVec2;

use crate::geom::polygon::orient;
use crate::{BakeError, Progress};

/// A discontinuity edge on the receiver, in the receiver's 2-D frame. `tag` is the caller's id
/// (it is carried to the output edges that lie on this segment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    pub a: DVec2,
    pub b: DVec2,
    pub tag: u32,
}

/// Largest coordinate magnitude accepted.
pub const MAX_COORD: f64 = 1e100;
/// Smallest receiver diameter accepted.
pub const MIN_DIAMETER: f64 = 1e-100;

/// Tag of the edges that lie on the receiver boundary.
pub const BOUNDARY_TAG: u32 = u32::MAX;

#[derive(Debug, Clone, Default)]
pub struct Arrangement {
    pub vertices: Vec<DVec2>,
    /// Undirected edges after all splitting/merging; `tags` = every input segment tag (and
    /// BOUNDARY_TAG for the receiver boundary) lying on it, sorted, deduplicated.
    pub edges: Vec<ArrEdge>,
    /// Bounded faces inside the boundary polygon, i.e. the regions the loops enclose.
    pub faces: Vec<ArrFace>,
}

#[derive(Debug, Clone)]
pub struct ArrEdge {
    /// Vertex indices, smaller first.
    pub v: [u32; 2],
    pub tags: Vec<u32>,
}

#[derive(Debug, Clone)]
pub struct ArrFace {
    /// Outer loop: vertex indices, counter-clockwise. Dangling edges are not in it (they
    /// are in `boundary_edges`); a vertex may repeat where the face pinches.
    pub outer: Vec<u32>,
    /// Hole loops (components floating inside this face): vertex indices, clockwise.
    /// A floating component without area (a lone segment, a tree of segments) has no loop
    /// here; its edges are in `boundary_edges`.
    pub holes: Vec<Vec<u32>>,
    /// A point strictly inside the face (inside `outer`, outside every hole, off every
    /// dangling edge), as far from the boundary as a few horizontal scanlines can find.
    pub interior: DVec2,
    /// Area of the face (outer minus holes).
    pub area: f64,
    /// Edge indices (into `edges`) on this face's boundary, outer, holes and dangling edges.
    pub boundary_edges: Vec<u32>,
}

impl ArrFace {
    /// Exact test: is `p` strictly inside the outer loop and strictly outside every hole?
    /// (Dangling edges are not considered.)
    pub fn contains(&self, vertices: &[DVec2], p: DVec2) -> bool {
        let mut loops = std::iter::once(&self.outer).chain(&self.holes);
        let on_edge = loops.any(|l| loop_edges(l).any(|(a, b)| on_segment(vertices, a, b, p)));
        if on_edge {
            return false;
        }
        let inside_outer = winding(vertices, loop_edges(&self.outer), p) != 0;
        inside_outer
            && self
                .holes
                .iter()
                .all(|h| winding(vertices, loop_edges(h), p) == 0)
    }
}

impl Arrangement {
    /// Index of the face strictly containing `p` (exact), if any. Linear in the size of the
    /// arrangement: meant for tests and occasional queries.
    pub fn locate(&self, p: DVec2) -> Option<usize> {
        self.faces
            .iter()
            .position(|f| f.contains(&self.vertices, p))
    }
}

/// Builds the arrangement of one receiver.
///
/// `boundary`: the receiver polygon, convex, counter-clockwise, ≥3 vertices (a clockwise one
/// is reversed).
/// `segments`: discontinuity edges, already clipped to the boundary (endpoints inside or on
/// it, up to rounding; what lies farther than `snap` outside is clipped away). They may
/// cross each other, touch, overlap collinearly, coincide with the boundary, be zero-length
/// (dropped) or dangle. A segment with a coordinate that is not finite or beyond
/// [`MAX_COORD`] is dropped.
/// `snap`: distance below which two points are the same vertex (the caller passes ~1e-9 ×
/// the receiver's diameter).
///
/// Returns an empty arrangement when the boundary has a non-finite coordinate, no area, a
/// coordinate beyond [`MAX_COORD`] or a diameter below [`MIN_DIAMETER`].
///
/// # Precision
/// The receiver corners keep their exact coordinates. Segment ends within `snap` outside
/// the boundary are moved onto it; a vertex within `snap` of an edge splits it, or merges
/// with the edge's end when that is within 4 × `snap`. See the module notes.
///
/// # Panics
/// Never: unusable input gives an empty arrangement or drops the offending segment.
///
/// ```
/// use glam::DVec2;
/// use penumbra::regions::arrangement::{build, Segment};
/// let square = [DVec2::new(0., 0.), DVec2::new(1., 0.), DVec2::new(1., 1.), DVec2::new(0., 1.)];
/// let chord = Segment { a: DVec2::new(0.5, 0.), b: DVec2::new(0.5, 1.), tag: 7 };
/// let arr = build(&square, &[chord], 1e-9);
/// assert_eq!(arr.faces.len(), 2);
/// assert!((arr.faces[0].area - 0.5).abs() < 1e-12);
/// ```
pub fn build(boundary: &[DVec2], segments: &[Segment], snap: f64) -> Arrangement {
    build_cancellable(boundary, segments, snap, &Progress::new()).unwrap_or_default()
}

/// `build`, checking `progress` every few thousand units of work (edge pairs, vertices,
/// loops), so that one huge receiver still returns `Cancelled` promptly.
pub fn build_cancellable(
    boundary: &[DVec2],
    segments: &[Segment],
    snap: f64,
    progress: &Progress,
) -> Result<Arrangement, BakeError> {
    let Some(boundary) = clean_boundary(boundary) else {
        return Ok(Arrangement::default());
    };
    let snap = if snap.is_finite() && snap > 0.0 {
        snap
    } else {
        0.0
    };
    let extent = boundary
        .iter()
        .fold(0.0f64, |m, p| m.max(p.x.abs()).max(p.y.abs()));
    let diameter = boundary
        .iter()
        .fold(0.0f64, |m, p| m.max((*p - boundary[0]).length()));
    // Beyond these, products of coordinate differences overflow or underflow and the exact
    // predicates lose their guarantee.
    if extent > MAX_COORD || diameter < MIN_DIAMETER {
        return Ok(Arrangement::default());
    }
    let mut pool = snap::VertexPool::new(snap, extent);

    let mut raw: Vec<split::Edge> = Vec::with_capacity(boundary.len() + segments.len());
    let bverts: Vec<u32> = boundary.iter().map(|&p| pool.insert(p)).collect();
    for i in 0..bverts.len() {
        let (a, b) = (bverts[i], bverts[(i + 1) % bverts.len()]);
        if a != b {
            raw.push(split::Edge::new(a, b, BOUNDARY_TAG));
        }
    }
    for (k, s) in segments.iter().enumerate() {
        if k % CHECK_EVERY == 0 {
            progress.check()?;
        }
        let Some((a, b)) = clip_to_convex(&boundary, s.a, s.b, snap) else {
            continue;
        };
        let (va, vb) = (pool.insert(a), pool.insert(b));
        if va != vb {
            raw.push(split::Edge::new(va, vb, s.tag));
        }
    }

    let edges = split::split_all(&mut pool, raw, snap, progress)?;
    let (vertices, edges) = drop_unused(pool.into_points(), edges);
    let faces = trace::faces(&vertices, &edges, progress)?;
    Ok(Arrangement {
        vertices,
        edges,
        faces,
    })
}

/// Units of work (segments, edge pairs, vertices, loops) between two cancel checks: a few
/// milliseconds at most.
const CHECK_EVERY: usize = 4096;

/// Removes the vertices no edge uses (ends of dropped zero-length segments), keeping order.
fn drop_unused(points: Vec<DVec2>, edges: Vec<split::Edge>) -> (Vec<DVec2>, Vec<ArrEdge>) {
    let mut used = vec![false; points.len()];
    for e in &edges {
        for &v in &e.v {
            used[v as usize] = true;
        }
    }
    let mut new_index = vec![u32::MAX; points.len()];
    let mut vertices = Vec::with_capacity(points.len());
    for (i, p) in points.into_iter().enumerate() {
        if used[i] {
            new_index[i] = vertices.len() as u32;
            vertices.push(p);
        }
    }
    let edges = edges
        .into_iter()
        .map(|e| {
            let (a, b) = (new_index[e.v[0] as usize], new_index[e.v[1] as usize]);
            ArrEdge {
                v: [a.min(b), a.max(b)],
                tags: e.tags,
            }
        })
        .collect();
    (vertices, edges)
}

/// The boundary without repeated points, counter-clockwise; `None` if unusable.
fn clean_boundary(boundary: &[DVec2]) -> Option<Vec<DVec2>> {
    if boundary.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let mut pts: Vec<DVec2> = Vec::with_capacity(boundary.len());
    for &p in boundary {
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    while pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    if pts.len() < 3 {
        return None;
    }
    let area = crate::geom::polygon::signed_area_2d(&pts);
    if area == 0.0 || area.is_nan() {
        return None;
    }
    if area < 0.0 {
        pts.reverse();
    }
    Some(pts)
}

/// Clips `a→b` to the convex counter-clockwise `poly`, leaving alone whatever is within
/// `snap` outside (so a segment lying on the boundary up to rounding survives and snaps
/// onto it). `None` when nothing is left or a coordinate is not finite.
fn clip_to_convex(poly: &[DVec2], a: DVec2, b: DVec2, snap: f64) -> Option<(DVec2, DVec2)> {
    let sane = |p: DVec2| p.is_finite() && p.abs().max_element() <= MAX_COORD;
    if !sane(a) || !sane(b) {
        return None;
    }
    let (t0, t1) = crate::geom::polygon::clip_segment_convex(a, b, poly, 0.0, snap)?;
    let pa = if t0 > 0.0 { a + (b - a) * t0 } else { a };
    let pb = if t1 < 1.0 { a + (b - a) * t1 } else { b };
    let (pa, pb) = (onto_boundary(poly, pa), onto_boundary(poly, pb));
    (pa.is_finite() && pb.is_finite()).then_some((pa, pb))
}

/// A point left a hair outside the boundary, moved onto it: otherwise the boundary edge
/// split there would bend outwards and the faces would outgrow the receiver.
fn onto_boundary(poly: &[DVec2], mut p: DVec2) -> DVec2 {
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if orient(a, b, p) < 0.0 {
            let d = b - a;
            p = a + d * ((p - a).dot(d) / d.length_squared());
        }
    }
    p
}

/// The directed edges of a closed loop given by its vertices.
fn loop_edges(l: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
    (0..l.len()).map(move |i| (l[i], l[(i + 1) % l.len()]))
}

/// Exact: does `p` lie on the closed segment between vertices `a` and `b`?
fn on_segment(pts: &[DVec2], a: u32, b: u32, p: DVec2) -> bool {
    let (a, b) = (pts[a as usize], pts[b as usize]);
    orient(a, b, p) == 0.0
        && p.x >= a.x.min(b.x)
        && p.x <= a.x.max(b.x)
        && p.y >= a.y.min(b.y)
        && p.y <= a.y.max(b.y)
}

/// Exact winding number of the directed edges around `p` (which must not lie on them).
fn winding(pts: &[DVec2], edges: impl Iterator<Item = (u32, u32)>, p: DVec2) -> i32 {
    let mut w = 0;
    for (a, b) in edges {
        let (a, b) = (pts[a as usize], pts[b as usize]);
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

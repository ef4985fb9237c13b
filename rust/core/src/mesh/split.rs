//! How refinement puts a vertex in: inside a region, or on a constraint (a D1/D0 edge or the
//! receiver's boundary) split in place so that the line stays one straight constraint line.
//! Each call reports the vertices whose triangles it changed, so that refinement re-checks
//! only those.

use glam::DVec2;
use spade::handles::FixedVertexHandle;
use spade::{Point2, PositionInTriangulation, Triangulation};

use super::refine::FLAT;
use super::Cdt;
use crate::geom::polygon::orient;

/// Inserts `p` unless rounding put it outside the hull (the receiver).
/// `near` is a vertex close by, where spade starts looking (from the last vertex put in, the
/// walk crossed a receiver; a sixth of cornell's refinement).
pub(super) fn insert_inside(cdt: &mut Cdt, p: Point2<f64>, near: FixedVertexHandle) {
    if !matches!(
        cdt.locate_with_hint(p, near),
        PositionInTriangulation::OutsideOfConvexHull(_)
    ) {
        let _ = cdt.insert_with_hint(p, near);
    }
}

/// Splits the CDT edge `a`→`b` (the failed triangle on its left) at its midpoint. An edge
/// inside a region takes the midpoint as a new vertex. A constraint (a D1/D0 edge, or the
/// receiver's boundary, which the frame put inside the triangulation) is split by the
/// triangulation itself (`split_constraint`).
/// Vertices that a split's helper vertex (removed again) was joined to: the triangles
/// around them changed besides those around the new vertices.
pub(super) fn split_edge(
    cdt: &mut Cdt,
    a: FixedVertexHandle,
    b: FixedVertexHandle,
    touched: &mut Vec<FixedVertexHandle>,
) {
    let (pa, pb) = (cdt.vertex(a).position(), cdt.vertex(b).position());
    let mid = Point2::new(0.5 * (pa.x + pb.x), 0.5 * (pa.y + pb.y));
    let Some(e) = cdt.get_edge_from_neighbors(a, b).map(|e| e.fix()) else {
        // Flipped away by an earlier split of this pass: the region still wants a vertex.
        insert_inside(cdt, mid, a);
        return;
    };
    let edge = cdt.directed_edge(e);
    if edge.as_undirected().is_part_of_convex_hull() {
        return;
    }
    if !edge.is_constraint_edge() {
        // An edge of a flat triangle (three points of one kinked constraint line, spanned
        // by the triangulation): its midpoint lies on that line to within rounding, and
        // would cut slivers that rounding may turn over (tests/mesh_validity.rs).
        let len = DVec2::new(pb.x - pa.x, pb.y - pa.y).length();
        let flat = [edge, edge.rev()].iter().any(|side| {
            side.opposite_position().is_some_and(|c| {
                let h = orient(
                    DVec2::new(pa.x, pa.y),
                    DVec2::new(pb.x, pb.y),
                    DVec2::new(c.x, c.y),
                )
                .abs()
                    / len.max(f64::MIN_POSITIVE);
                h < FLAT * len
            })
        });
        if flat {
            return;
        }
        insert_inside(cdt, mid, a);
        return;
    }
    split_constraint(cdt, e, mid, touched);
}

/// Splits a constraint edge at `mid` (its midpoint) in the triangulation's own structure.
/// Inserted as a point, a rounded midpoint lies a hair off the line, and the constraint put
/// back through it leaves a sliver between the line and the point, or a triangle that
/// rounding turns over (tests/mesh_validity.rs). spade splits an existing constraint in
/// place only where a new constraint crosses it, at a point its caller chooses: so a
/// constraint is drawn from the vertex opposite the edge on one side to the one on the
/// other, split at `mid`, and then unmarked, and the edge's halves stay one constraint line.
/// Where that line would leave the two triangles (their quadrilateral is not convex), it is
/// drawn to a vertex put for the purpose just beyond the midpoint, and removed after.
fn split_constraint(
    cdt: &mut Cdt,
    e: spade::handles::FixedDirectedEdgeHandle,
    mid: Point2<f64>,
    touched: &mut Vec<FixedVertexHandle>,
) {
    let edge = cdt.directed_edge(e);
    let (ha, hb) = (edge.from().fix(), edge.to().fix());
    let p2 = |p: Point2<f64>| DVec2::new(p.x, p.y);
    let (a, b) = (p2(edge.from().position()), p2(edge.to().position()));
    let (Some(c), Some(d)) = (
        edge.opposite_vertex().map(|v| v.fix()),
        edge.rev().opposite_vertex().map(|v| v.fix()),
    ) else {
        return;
    };
    let (pc, pd) = (p2(cdt.vertex(c).position()), p2(cdt.vertex(d).position()));
    let crosses = |from: DVec2, to: DVec2| {
        let (sa, sb) = (orient(from, to, a), orient(from, to, b));
        (sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0)
    };
    if crosses(pc, pd) {
        draw_and_unmark(cdt, (ha, hb), c, d, mid);
        return;
    }
    // A vertex strictly inside the triangle a, d, b, on the line from c through the
    // midpoint: the line from c to it crosses the edge and nothing else.
    let m = p2(mid);
    let side = orient(a, b, pd).signum();
    let inside = |q: DVec2| {
        orient(a, b, q) * side > 0.0
            && orient(b, pd, q) * side > 0.0
            && orient(pd, a, q) * side > 0.0
    };
    let mut t = 1.0;
    let mut beyond = None;
    for _ in 0..40 {
        let q = m + (m - pc) * t;
        if inside(q) && crosses(pc, q) {
            beyond = Some(q);
            break;
        }
        t *= 0.5;
    }
    let Some(q) = beyond else {
        return;
    };
    let Ok(temp) = cdt.insert_with_hint(Point2::new(q.x, q.y), c) else {
        return;
    };
    // Inserting legalises edges beyond the constraint only: c still faces the edge.
    if cdt.get_edge_from_neighbors(ha, hb).is_some() {
        draw_and_unmark(cdt, (ha, hb), c, temp, mid);
    }
    // Removing it re-triangulates the hole its triangles leave, between its neighbours.
    let first = touched.len();
    touched.extend(cdt.vertex(temp).out_edges().map(|e| e.to().fix()));
    cdt.remove(temp);
    // spade moves the last vertex into the removed one's place.
    let n = cdt.num_vertices();
    for h in &mut touched[first..] {
        if h.index() >= n {
            *h = temp;
        }
    }
}

/// Draws a constraint from `c` to `d` that splits what it crosses at `mid`, then unmarks
/// what it drew. Where `mid` is no valid split point, spade connects to a vertex nearby
/// instead, and the drawn line may then run along a constraint that was there before (a
/// boundary edge): that one stays marked, or the receiver would lose its boundary.
fn draw_and_unmark(
    cdt: &mut Cdt,
    (a, b): (FixedVertexHandle, FixedVertexHandle),
    c: FixedVertexHandle,
    d: FixedVertexHandle,
    mid: Point2<f64>,
) {
    // spade takes `mid` where it lies on the edge or in a triangle beside it; elsewhere (a
    // vertex there already, or rounding past a thin triangle) it would route the edge
    // through a vertex nearby instead, moving the constraint: left unsplit then.
    let Some(edge) = cdt.get_edge_from_neighbors(a, b) else {
        return;
    };
    let (e, left, right) = (
        edge.fix().as_undirected(),
        edge.face().fix(),
        edge.rev().face().fix(),
    );
    let valid = match cdt.locate_with_hint(mid, a) {
        PositionInTriangulation::OnEdge(x) => x.as_undirected() == e,
        PositionInTriangulation::OnFace(f) => {
            left.as_inner() == Some(f) || right.as_inner() == Some(f)
        }
        _ => false,
    };
    if !valid {
        return;
    }
    let mut before: Vec<(FixedVertexHandle, FixedVertexHandle)> = Vec::new();
    for v in [c, d] {
        for e in cdt.vertex(v).out_edges() {
            if e.is_constraint_edge() {
                let (x, y) = (e.from().fix(), e.to().fix());
                before.push((x.min(y), x.max(y)));
            }
        }
    }
    let drawn_edges = cdt.add_constraint_and_split(c, d, |_| mid);
    for drawn in drawn_edges {
        let e = cdt.directed_edge(drawn);
        let (x, y) = (e.from().fix(), e.to().fix());
        if !before.contains(&(x.min(y), x.max(y))) {
            cdt.remove_constraint_edge(drawn.as_undirected());
        }
    }
}

/// Puts four vertices around the receiver, so that its boundary edges lie inside the
/// triangulation with a triangle beyond them, and are split as the D1/D0 edges are
/// (`split_constraint`). Extraction leaves out the triangles between the boundary and the
/// frame (`extract`). Split from the hull instead, a boundary edge's midpoint becomes a hull
/// vertex, and removing a helper vertex beyond a straight run of boundary vertices left
/// flat triangles that stopped its splits.
pub(super) fn add_frame(cdt: &mut Cdt) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for v in cdt.vertices() {
        let p = DVec2::new(v.position().x, v.position().y);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if !(lo.x < hi.x && lo.y < hi.y) {
        return;
    }
    let pad = (hi - lo).max_element();
    let (lo, hi) = (lo - DVec2::splat(pad), hi + DVec2::splat(pad));
    for p in [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)] {
        let _ = cdt.insert(Point2::new(p.x, p.y));
    }
}

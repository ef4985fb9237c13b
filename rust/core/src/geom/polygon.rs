//! Convex polygon clipping (Sutherland–Hodgman against one plane or half-plane at a time),
//! areas, and exact point-in-convex-polygon tests.

use glam::{DVec2, DVec3};
use robust::{orient2d, Coord};

use super::Plane;

/// Keeps the part of a convex polygon on the non-negative side of `plane`.
/// Vertices within `eps` of the plane count as on it, so a polygon touching the plane
/// is not split into slivers.
pub fn clip_polygon_3d(poly: &[DVec3], plane: &Plane, eps: f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    clip_polygon_3d_into(poly, plane, eps, &mut out);
    out
}

/// [`clip_polygon_3d`] into `out` (cleared first). It allocates nothing when `out` has room,
/// which matters to the direct stage: it clips a light polygon tens of millions of times.
pub fn clip_polygon_3d_into(poly: &[DVec3], plane: &Plane, eps: f64, out: &mut Vec<DVec3>) {
    clip_by(poly, |p| plane.dist(p), eps, out);
}

/// Sutherland–Hodgman against one side: keeps the part of convex `poly` where `dist` ≥ 0,
/// vertices within `eps` counting as on the boundary. Generic over the point type so that
/// the 2-D and 3-D clips are one loop (monomorphised: no cost on the direct stage's path).
fn clip_by<T>(poly: &[T], dist: impl Fn(T) -> f64, eps: f64, out: &mut Vec<T>)
where
    T: Copy
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<f64, Output = T>,
{
    out.clear();
    let n = poly.len();
    if n == 0 {
        return;
    }
    let (mut keep_all, mut drop_all) = (true, true);
    for p in poly {
        let d = dist(*p);
        keep_all &= d >= -eps;
        drop_all &= d <= eps;
    }
    if keep_all {
        out.extend_from_slice(poly);
        return;
    }
    if drop_all {
        return;
    }
    let mut da = dist(poly[0]);
    for i in 0..n {
        let j = (i + 1) % n;
        let (a, b) = (poly[i], poly[j]);
        let db = dist(b);
        if da >= -eps {
            out.push(a);
        }
        if (da > eps && db < -eps) || (da < -eps && db > eps) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
        da = db;
    }
}

/// A 2-D half-plane `n·x ≥ c` (n need not be unit length).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfPlane {
    pub n: DVec2,
    pub c: f64,
}

impl HalfPlane {
    #[inline]
    pub fn eval(&self, p: DVec2) -> f64 {
        self.n.dot(p) - self.c
    }
}

/// Keeps the part of a convex 2-D polygon inside `h`. `eps` is in the units of `h.eval`
/// divided by |n| (i.e. a distance).
pub fn clip_polygon_2d(poly: &[DVec2], h: &HalfPlane, eps: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    clip_polygon_2d_into(poly, h, eps, &mut out);
    out
}

/// [`clip_polygon_2d`] into `out` (cleared first), allocating nothing when `out` has room.
pub fn clip_polygon_2d_into(poly: &[DVec2], h: &HalfPlane, eps: f64, out: &mut Vec<DVec2>) {
    let inv = 1.0 / h.n.length();
    clip_by(poly, |p| h.eval(p) * inv, eps, out);
}

/// Convex counter-clockwise `piece` minus convex counter-clockwise `c`, as disjoint convex
/// pieces appended to `out`: for each edge of `c`, the part of `piece` outside that edge and
/// inside the edges before it. Pieces of area at most `min_area` (clipping slivers) are left
/// out. A piece whose bounds miss `c`'s bounds stays whole.
pub fn subtract_convex(piece: Vec<DVec2>, c: &[DVec2], min_area: f64, out: &mut Vec<Vec<DVec2>>) {
    let (lo, hi) = crate::geom::box_grid::bounds(c);
    let (plo, phi) = crate::geom::box_grid::bounds(&piece);
    if phi.x <= lo.x || phi.y <= lo.y || plo.x >= hi.x || plo.y >= hi.y {
        out.push(piece);
        return;
    }
    let n = c.len();
    // An edge this short (two clip points of one corner, apart by rounding) has a direction
    // that is rounding noise: its half-plane could cut through `c` and hand back a part of
    // it as outside. Skipping it adds to `c` at most a triangle on that edge, of area near
    // its length squared.
    let tiny = (hi - lo).max_element() * 1e-12;
    let mut rest = piece;
    let mut next = Vec::with_capacity(rest.len() + n);
    for k in 0..n {
        let (a, b) = (c[k], c[(k + 1) % n]);
        let nrm = (b - a).perp();
        // A repeated vertex: no edge, no side.
        if nrm == DVec2::ZERO || nrm.length() <= tiny {
            continue;
        }
        let inside = HalfPlane {
            n: nrm,
            c: nrm.dot(a),
        };
        let outside = HalfPlane {
            n: -nrm,
            c: -inside.c,
        };
        let part = clip_polygon_2d(&rest, &outside, 0.0);
        if part.len() >= 3 && signed_area_2d(&part) > min_area {
            out.push(part);
        }
        clip_polygon_2d_into(&rest, &inside, 0.0, &mut next);
        std::mem::swap(&mut rest, &mut next);
        if rest.len() < 3 {
            return;
        }
    }
}

/// Signed area (positive when counter-clockwise).
pub fn signed_area_2d(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    let mut s = 0.0;
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        s += a.perp_dot(b);
    }
    0.5 * s
}

/// Length of the closed polyline `poly`.
pub fn perimeter(poly: &[DVec2]) -> f64 {
    (0..poly.len())
        .map(|k| (poly[(k + 1) % poly.len()] - poly[k]).length())
        .sum()
}

/// The half-planes inside each edge of the counter-clockwise convex polygon `c`: their
/// intersection is `c`.
pub fn inside_edges(c: &[DVec2]) -> Vec<HalfPlane> {
    let n = c.len();
    (0..n)
        .map(|k| {
            let (a, b) = (c[k], c[(k + 1) % n]);
            let nrm = (b - a).perp();
            HalfPlane {
                n: nrm,
                c: nrm.dot(a),
            }
        })
        .collect()
}

/// Whether both ends of segment a–b lie within `tol` of the line of one edge of `poly`:
/// the segment runs along that edge.
pub fn along_an_edge(poly: &[DVec2], a: DVec2, b: DVec2, tol: f64) -> bool {
    (0..poly.len()).any(|i| {
        let p = poly[i];
        let d = poly[(i + 1) % poly.len()] - p;
        let len = d.length();
        len > 0.0
            && (d.perp_dot(a - p) / len).abs() <= tol
            && (d.perp_dot(b - p) / len).abs() <= tol
    })
}

#[inline]
pub fn coord(p: DVec2) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

/// Exact orientation of `c` relative to the directed line `a → b`: > 0 left, < 0 right.
#[inline]
pub fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    orient2d(coord(a), coord(b), coord(c))
}

/// Exact test: is `p` strictly inside the counter-clockwise convex polygon `poly`?
pub fn strictly_inside_convex(poly: &[DVec2], p: DVec2) -> bool {
    let n = poly.len();
    if n < 3 {
        return false;
    }
    (0..n).all(|i| orient(poly[i], poly[(i + 1) % n], p) > 0.0)
}

/// Exact test: is `p` inside or on the boundary of the counter-clockwise convex polygon?
pub fn inside_convex(poly: &[DVec2], p: DVec2) -> bool {
    let n = poly.len();
    if n < 3 {
        return false;
    }
    (0..n).all(|i| orient(poly[i], poly[(i + 1) % n], p) >= 0.0)
}

/// Removes consecutive duplicates and vertices collinear with their neighbours (exact test),
/// which clipping leaves behind. Returns fewer than 3 points when nothing with area is left.
pub fn simplify_convex(poly: &[DVec2]) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = Vec::with_capacity(poly.len());
    for &p in poly {
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    while pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    let mut changed = true;
    while changed && pts.len() >= 3 {
        changed = false;
        let n = pts.len();
        for i in 0..n {
            let a = pts[(i + n - 1) % n];
            let b = pts[i];
            let c = pts[(i + 1) % n];
            if orient(a, b, c) <= 0.0 {
                pts.remove(i);
                changed = true;
                break;
            }
        }
    }
    pts
}

/// The one segment-against-convex clipper: the parameters `t0 < t1` along a–b (0 at a, 1 at
/// b) of the part of segment a–b inside the counter-clockwise convex `poly` (Cyrus–Beck),
/// or `None` when nothing is, or when no part lies at least `margin` inside every edge line.
/// An edge line cuts the segment only when an end lies more than `slack` beyond it.
///
/// Callers differ only in these two distances:
/// - `(0, 0)`: the exact part inside (critical lines in a penumbra, plane cuts in a receiver);
/// - `(margin, 0)`: umbra pruning decides with a margin whether a segment runs deep inside a
///   cover, then cuts it where it crosses the cover's edges, so that the pieces left end on
///   those edges (the arrangement snaps them there) instead of leaving stubs inside;
/// - `(0, snap)`: the arrangement, where a segment lying on the boundary up to rounding must
///   survive whole, so that snapping puts it onto the boundary instead of losing it.
///
/// # Precision
/// With both distances zero the decisions are scale-free and the edge-line values are used
/// unscaled; otherwise they are divided by the edge's length to be compared with distances.
pub fn clip_segment_convex(
    a: DVec2,
    b: DVec2,
    poly: &[DVec2],
    margin: f64,
    slack: f64,
) -> Option<(f64, f64)> {
    let euclidean = margin != 0.0 || slack != 0.0;
    if margin != 0.0 && slack == 0.0 {
        return clip_segment_deep(&convex_edges(poly), a, b, margin);
    }
    if margin != 0.0 {
        let deep = cyrus_beck(a, b, poly, margin, slack, euclidean)?;
        return Some(cyrus_beck(a, b, poly, 0.0, slack, euclidean).unwrap_or(deep));
    }
    cyrus_beck(a, b, poly, 0.0, slack, euclidean)
}

/// The edges of `poly` as `clip_segment_deep` takes them: start, direction and length, the
/// zero-length left out. A caller that clips many segments against one polygon makes them
/// once (umbra pruning: a sixth of room-8328's direct-only bake went to the edges' lengths).
pub fn convex_edges(poly: &[DVec2]) -> Vec<(DVec2, DVec2, f64)> {
    let mut out = Vec::with_capacity(poly.len());
    convex_edges_into(poly, &mut out);
    out
}

/// [`convex_edges`], appended to `out`.
pub fn convex_edges_into(poly: &[DVec2], out: &mut Vec<(DVec2, DVec2, f64)>) {
    for (i, &p) in poly.iter().enumerate() {
        let e = poly[(i + 1) % poly.len()] - p;
        if e != DVec2::ZERO {
            out.push((p, e, e.length()));
        }
    }
}

/// `clip_segment_convex(a, b, poly, margin, 0)` with `margin` > 0 for the polygon whose
/// edges are `edges` (`convex_edges`): the part of a–b inside it, when some of it lies at
/// least `margin` inside every edge line. Both of the clipper's passes (deep by the margin,
/// then the exact part) in one loop, to the same bits as two `cyrus_beck` runs.
pub fn clip_segment_deep(
    edges: &[(DVec2, DVec2, f64)],
    a: DVec2,
    b: DVec2,
    margin: f64,
) -> Option<(f64, f64)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let (mut s0, mut s1) = (0.0f64, 1.0f64);
    let mut outside = false;
    // As `cyrus_beck`: line values in lengths only where a margin asks for them.
    let euclidean = margin != 0.0;
    for &(p, e, len) in edges {
        let (f0, fd) = if euclidean {
            (e.perp_dot(a - p) / len, e.perp_dot(d) / len)
        } else {
            (e.perp_dot(a - p), e.perp_dot(d))
        };
        let g0 = f0 - margin;
        let (out_a, out_b) = (g0 < 0.0, g0 + fd < 0.0);
        if out_a && out_b {
            return None;
        }
        if out_a {
            t0 = t0.max(-g0 / fd);
        } else if out_b {
            t1 = t1.min(-g0 / fd);
        }
        let (out_a, out_b) = (f0 < 0.0, f0 + fd < 0.0);
        if out_a && out_b {
            outside = true;
        } else if out_a {
            s0 = s0.max(-f0 / fd);
        } else if out_b {
            s1 = s1.min(-f0 / fd);
        }
    }
    if t0 >= t1 {
        return None;
    }
    Some(if outside || s0 >= s1 {
        (t0, t1)
    } else {
        (s0, s1)
    })
}

/// The interval of a–b at least `margin` inside every edge line of `poly`, edges cutting
/// only where an end lies more than `slack` beyond them; line values in lengths when
/// `euclidean`, else unscaled.
fn cyrus_beck(
    a: DVec2,
    b: DVec2,
    poly: &[DVec2],
    margin: f64,
    slack: f64,
    euclidean: bool,
) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let d = b - a;
    let n = poly.len();
    for i in 0..n {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        let e = q - p;
        if e == DVec2::ZERO {
            continue;
        }
        // f0 at a (positive inside the line moved in by margin), changing by fd to b.
        let (f0, fd) = if euclidean {
            let len = e.length();
            (e.perp_dot(a - p) / len - margin, e.perp_dot(d) / len)
        } else {
            (e.perp_dot(a - p), e.perp_dot(d))
        };
        let (out_a, out_b) = (f0 < -slack, f0 + fd < -slack);
        if out_a && out_b {
            return None;
        }
        if out_a || out_b {
            let t = -f0 / fd;
            if out_a {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 < t1).then_some((t0, t1))
}

/// Distance from `p` to the segment a–b.
pub fn segment_distance(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t - p).length()
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn deep_clip_in_one_pass_agrees_with_two_cyrus_beck_passes() {
        use crate::geom::hash::{mix, unit};
        // Random convex polygons (points on a circle, counter-clockwise, one edge of zero
        // length) and random segments, with and without a margin.
        let mut draws = 0u64;
        let mut rnd = || {
            draws += 1;
            unit(mix(draws))
        };
        let mut compared = [0usize; 2];
        for _ in 0..2000 {
            let n = 3 + (rnd() * 5.0) as usize;
            let mut angles: Vec<f64> = (0..n).map(|_| rnd() * std::f64::consts::TAU).collect();
            angles.sort_by(f64::total_cmp);
            let mut poly: Vec<DVec2> = angles
                .iter()
                .map(|t| DVec2::new(t.cos(), t.sin()))
                .collect();
            poly.insert(1, poly[0]);
            if signed_area_2d(&poly) <= 1e-3 {
                continue;
            }
            let edges = convex_edges(&poly);
            let a = DVec2::new(rnd() * 3.0 - 1.5, rnd() * 3.0 - 1.5);
            let b = DVec2::new(rnd() * 3.0 - 1.5, rnd() * 3.0 - 1.5);
            let margin = if rnd() < 0.5 { 0.0 } else { 0.2 * rnd() };
            // The clipper as it was: deep by the margin, then the exact part.
            let eu = margin != 0.0;
            let want = cyrus_beck(a, b, &poly, margin, 0.0, eu)
                .map(|deep| cyrus_beck(a, b, &poly, 0.0, 0.0, eu).unwrap_or(deep));
            let got = clip_segment_deep(&edges, a, b, margin);
            match (want, got) {
                (None, None) => compared[0] += 1,
                (Some(w), Some(g)) => {
                    assert_eq!(w, g);
                    compared[1] += 1;
                }
                _ => panic!("{a} {b} {margin}: {want:?} against {got:?}"),
            }
        }
        assert!(compared[0] > 300 && compared[1] > 300, "{compared:?}");
    }

    /// A hidden part of a light (slab_crossing_the_floor_diagonally in interpenetration.rs)
    /// with two clip points 7e-16 apart: the edge between them pointed anywhere, and the
    /// light minus this part came out 2 % too bright.
    #[test]
    fn subtracting_a_polygon_with_a_rounding_short_edge_removes_all_of_it() {
        let light = vec![
            DVec2::new(-0.3, -0.3),
            DVec2::new(0.3, -0.3),
            DVec2::new(0.3, 0.3),
            DVec2::new(-0.3, 0.3),
        ];
        let mut part = vec![
            DVec2::new(-0.11755355016241997, 0.3),
            DVec2::new(0.30000000000000004, 0.3),
            DVec2::new(0.30000000000000004, 0.05648345328968524),
            DVec2::new(-0.30000000000000004, -0.05797155986760044),
            DVec2::new(-0.3, -0.05797155986759975),
            DVec2::new(-0.3, 0.24920236552438707),
        ];
        if signed_area_2d(&part) < 0.0 {
            part.reverse();
        }
        let mut out = Vec::new();
        subtract_convex(light.clone(), &part, 0.0, &mut out);
        let left: f64 = out.iter().map(|p| signed_area_2d(p)).sum();
        let want = signed_area_2d(&light) - signed_area_2d(&part);
        assert!((left - want).abs() < 1e-12, "{left} left, {want} expected");
    }

    fn square() -> Vec<DVec2> {
        vec![
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
            DVec2::new(1., 1.),
            DVec2::new(0., 1.),
        ]
    }

    #[test]
    fn one_segment_clipper_exact_deep_and_forgiving() {
        let (sq, p) = (square(), DVec2::new);
        // Exact: the part inside, cut at the edges.
        let (t0, t1) = clip_segment_convex(p(-1.0, 0.5), p(3.0, 0.5), &sq, 0.0, 0.0).unwrap();
        assert_eq!((t0, t1), (0.25, 0.5));
        assert!(clip_segment_convex(p(-1.0, 2.0), p(3.0, 2.0), &sq, 0.0, 0.0).is_none());
        // Along an edge: on the line is inside.
        assert_eq!(
            clip_segment_convex(p(0.2, 0.0), p(0.8, 0.0), &sq, 0.0, 0.0),
            Some((0.0, 1.0))
        );
        // Margin: near the edge is not deep; deep runs are still cut at the edges.
        assert!(clip_segment_convex(p(-1.0, 0.1), p(3.0, 0.1), &sq, 0.2, 0.0).is_none());
        let (t0, t1) = clip_segment_convex(p(-1.0, 0.5), p(3.0, 0.5), &sq, 0.2, 0.0).unwrap();
        assert_eq!((t0, t1), (0.25, 0.5));
        // Slack: a hair outside the bottom edge survives whole; farther out it is cut.
        let below = |y| clip_segment_convex(p(0.2, y), p(0.8, y), &sq, 0.0, 1e-6);
        assert_eq!(below(-1e-7), Some((0.0, 1.0)));
        assert!(below(-1e-5).is_none());
        let (t0, _) = clip_segment_convex(p(-0.5, 0.5), p(0.5, 0.5), &sq, 0.0, 1e-6).unwrap();
        assert_eq!(t0, 0.5);
    }

    #[test]
    fn clip_square_in_half() {
        let h = HalfPlane {
            n: DVec2::new(1.0, 0.0),
            c: 0.5,
        };
        let r = clip_polygon_2d(&square(), &h, 0.0);
        assert!((signed_area_2d(&r) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn clip_3d_keeps_positive_side() {
        let tri = [
            DVec3::new(0., 0., -1.),
            DVec3::new(1., 0., 1.),
            DVec3::new(0., 1., 1.),
        ];
        let r = clip_polygon_3d(&tri, &Plane::new(DVec3::Z, 0.0), 0.0);
        assert!(r.iter().all(|p| p.z >= -1e-15));
        assert_eq!(r.len(), 4);
    }

    #[test]
    fn inside_tests_are_exact_on_boundary() {
        let s = square();
        assert!(inside_convex(&s, DVec2::new(1.0, 0.5)));
        assert!(!strictly_inside_convex(&s, DVec2::new(1.0, 0.5)));
        assert!(strictly_inside_convex(&s, DVec2::new(0.5, 0.5)));
    }

    #[test]
    fn simplify_drops_collinear() {
        let p = vec![
            DVec2::new(0., 0.),
            DVec2::new(0.5, 0.),
            DVec2::new(1., 0.),
            DVec2::new(1., 1.),
            DVec2::new(1., 1.),
        ];
        assert_eq!(simplify_convex(&p).len(), 3);
    }
}

/// Convex hull (counter-clockwise, no collinear points) by Andrew's monotone chain with
/// exact orientation tests.
pub fn convex_hull_2d(pts: &[DVec2]) -> Vec<DVec2> {
    let mut p: Vec<DVec2> = pts.iter().copied().filter(|q| q.is_finite()).collect();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && orient(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod hull_test {
    use super::*;

    #[test]
    fn hull_of_square_with_inner_and_edge_points() {
        let pts = [
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
            DVec2::new(0.5, 0.0),
            DVec2::new(1., 1.),
            DVec2::new(0., 1.),
            DVec2::new(0.5, 0.5),
        ];
        let h = convex_hull_2d(&pts);
        assert_eq!(h.len(), 4);
        assert!((signed_area_2d(&h) - 1.0).abs() < 1e-15);
    }
}

/// Triangle `t` cut into four at its edges' midpoints.
pub fn split_in_four(t: &[DVec3; 3]) -> [[DVec3; 3]; 4] {
    let m = [
        (t[0] + t[1]) * 0.5,
        (t[1] + t[2]) * 0.5,
        (t[2] + t[0]) * 0.5,
    ];
    [
        [t[0], m[0], m[2]],
        [m[0], t[1], m[1]],
        [m[2], m[1], t[2]],
        [m[0], m[1], m[2]],
    ]
}

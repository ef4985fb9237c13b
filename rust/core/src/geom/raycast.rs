//! Visibility between points of the scene: does any face cross a segment or a ray?
//!
//! The BVH (obvhs, `f32`) only narrows the search; every decision is an `f64` test of the
//! segment against the face's own convex polygon. So that `f32` rounding can never drop a
//! face, the boxes handed to obvhs are padded well beyond it, and coordinates are taken
//! relative to the scene's centre before they are rounded.
//!
//! Faces are the BVH primitives as they are (convex and planar), not triangles: the `f64`
//! test against a convex polygon is as cheap as against a triangle, and there are no
//! internal diagonals along which a ray could slip through between two triangles.
//!
//! # Precision
//! A face blocks only where the segment crosses its plane with both ends more than the
//! tolerance ([`Occluders::tolerance`], 1e-9 of the scene size) off that plane. So points
//! lying on a surface (element vertices, samples on a patch) never hit their own face or a
//! face they touch, and a segment grazing along a face does not count as blocked. The
//! polygon is grown by the same tolerance, so a ray through the shared edge of two faces is
//! blocked by at least one of them.

use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::BvhBuildParams;

use crate::geom::{PlanarPolygon, Plane};

/// One face as the ray tests need it.
#[derive(Debug, Clone)]
struct Occluder {
    plane: Plane,
    verts: Vec<DVec3>,
    /// Per edge: unit in-plane normal pointing inwards, and its offset (inside: `m·p ≥ c`).
    edges: Vec<(DVec3, f64)>,
    lo: DVec3,
    hi: DVec3,
}

/// All faces of a scene, for visibility queries. Immutable after `new`, so `&self` queries are
/// safe from any number of threads.
pub struct Occluders {
    faces: Vec<Occluder>,
    /// Binary BVH for box queries (`candidates_upto`), and an 8-wide one over the same
    /// boxes for rays: fewer, wider nodes to visit per ray.
    bvh: Option<Bvh2>,
    wide: Option<CwBvh>,
    boxes: Vec<Aabb>,
    /// Per face: it has area and can block (`Occluder::edges` not empty).
    live: Vec<bool>,
    /// The scene's bounds grown by `pad`: queries are cut to it before going to `f32`.
    lo: DVec3,
    hi: DVec3,
    centre: DVec3,
    /// Padding of the `f32` boxes, in scene units.
    pad: f64,
    tol: f64,
}

impl Occluders {
    /// Indexes `faces` (face ids in queries are indices into this slice). Faces with fewer
    /// than 3 vertices or no normal are kept as ids but never block.
    pub fn new<F: PlanarPolygon>(faces: &[F]) -> Self {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in faces.iter().flat_map(|f| f.verts().iter()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let (centre, size, max_abs) = if lo.x <= hi.x {
            (
                (lo + hi) * 0.5,
                (hi - lo).length(),
                lo.abs().max(hi.abs()).max_element(),
            )
        } else {
            (DVec3::ZERO, 1.0, 1.0)
        };
        let size = if size > 0.0 { size } else { max_abs.max(1.0) };
        // Points computed on a face are off its plane by rounding, ~1e-16 of their
        // coordinates; 1e-9 of the scene leaves a wide margin yet is far below any feature
        // the mesher keeps.
        let tol = 1e-9 * size + 1e-13 * max_abs;
        // f32 coordinates relative to the centre are off by ~6e-8 of the scene size, and a
        // rounded direction drifts by ~1e-7 of the length; 1e-5 covers both many times.
        let pad = 1e-5 * size;

        let occluders: Vec<Occluder> = faces.iter().map(|f| occluder(f, tol)).collect();
        let boxes: Vec<Aabb> = occluders
            .iter()
            .map(|o| {
                if o.edges.is_empty() {
                    // Never blocks; a far-away point box keeps the BVH well formed.
                    let p = Vec3A::splat(f32::MAX / 4.0);
                    Aabb::new(p, p)
                } else {
                    Aabb::new(to_f32(o.lo - centre - pad), to_f32(o.hi - centre + pad))
                }
            })
            .collect();
        let (bvh, wide) = if boxes.is_empty() {
            (None, None)
        } else {
            let params = BvhBuildParams::medium_build();
            (
                Some(build_bvh2(&boxes, params, &mut Duration::default())),
                Some(build_cwbvh(&boxes, params, &mut Duration::default())),
            )
        };
        let (lo, hi) = if lo.x <= hi.x {
            (lo - pad, hi + pad)
        } else {
            (DVec3::ZERO, DVec3::ZERO)
        };
        let live = occluders.iter().map(|o| !o.edges.is_empty()).collect();
        Occluders {
            faces: occluders,
            bvh,
            wide,
            boxes,
            live,
            lo,
            hi,
            centre,
            pad,
            tol,
        }
    }

    /// Distance under which a point counts as lying on a face's plane.
    pub fn tolerance(&self) -> f64 {
        self.tol
    }

    pub fn len(&self) -> usize {
        self.faces.len()
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// True if a face crosses the open segment `a`–`b`.
    pub fn segment_blocked(&self, a: DVec3, b: DVec3) -> bool {
        self.segment_blocked_skip(a, b, &[])
    }

    /// As [`segment_blocked`](Self::segment_blocked), ignoring the faces in `skip` (say the
    /// shooter's and the receiver's own faces, which cannot block but cost a test).
    pub fn segment_blocked_skip(&self, a: DVec3, b: DVec3, skip: &[u32]) -> bool {
        self.segment_blocker_hinted(a, b, skip, None).is_some()
    }

    /// [`segment_blocked_skip`](Self::segment_blocked_skip), with the face that blocks (with
    /// no hint, the first the traversal finds), trying the face `hint` first: of a run of
    /// segments between two patches, most that are blocked are blocked by the face that
    /// blocked the one before (a box between them), and one exact test spares a traversal.
    /// The traversal finds every face that crosses (the boxes are padded), so whether the
    /// segment is blocked is the same with any hint; which face, not always.
    pub fn segment_blocker_hinted(
        &self,
        a: DVec3,
        b: DVec3,
        skip: &[u32],
        hint: Option<u32>,
    ) -> Option<u32> {
        let bvh = self.wide.as_ref()?;
        let d = b - a;
        let len = d.length();
        if !(len > self.tol) || !len.is_finite() {
            return None;
        }
        if let Some(f) = hint.filter(|f| !skip.contains(f)) {
            if self.face_crosses_segment(f, a, b) {
                return Some(f);
            }
        }
        let ray = wide_ray(self.bvh_ray(a, d / len, len)?);
        let mut found = None;
        bvh.ray_traverse_miss(ray, |ray, i| {
            let id = bvh.primitive_indices[i];
            if self.ray_meets_box(ray, id)
                && !skip.contains(&id)
                && self.face_crosses_segment(id, a, b)
            {
                found = Some(id);
                0.0
            } else {
                f32::INFINITY
            }
        });
        found
    }

    /// The first of `faces` that crosses the open segment `a`–`b`: for callers that already
    /// know the few faces that could be in the way.
    pub fn segment_blocker_among(&self, a: DVec3, b: DVec3, faces: &[u32]) -> Option<u32> {
        faces
            .iter()
            .copied()
            .find(|&f| self.face_crosses_segment(f, a, b))
    }

    /// [`segment_blocker_among`](Self::segment_blocker_among), trying `hint` (one of
    /// `faces`) first, as [`segment_blocker_hinted`](Self::segment_blocker_hinted) does.
    pub fn segment_blocker_among_hinted(
        &self,
        a: DVec3,
        b: DVec3,
        faces: &[u32],
        hint: Option<u32>,
    ) -> Option<u32> {
        hint.filter(|&f| self.face_crosses_segment(f, a, b))
            .or_else(|| self.segment_blocker_among(a, b, faces))
    }

    /// Whether face `id` blocks every segment from a point of the convex hull of `a` to a
    /// point of the convex hull of `b`: the two lie on opposite sides of its plane, each more
    /// than the tolerance off it, and every segment between their points crosses the plane
    /// inside the polygon, more than the tolerance from its edges. Where the plane cuts the
    /// hull of both sets it cuts it in the hull of those crossings, so the polygon, being
    /// convex, holds the whole cut: no ray between the two can pass.
    pub fn face_covers(&self, id: u32, a: &[DVec3], b: &[DVec3]) -> bool {
        let f = &self.faces[id as usize];
        if f.edges.is_empty() || a.is_empty() || b.is_empty() {
            return false;
        }
        let side = if f.plane.dist(a[0]) > 0.0 { 1.0 } else { -1.0 };
        let beyond = |p: &[DVec3], s: f64| p.iter().all(|&x| f.plane.dist(x) * s > self.tol);
        if !beyond(a, side) || !beyond(b, -side) {
            return false;
        }
        a.iter().all(|&p| {
            let dp = f.plane.dist(p);
            b.iter().all(|&q| {
                let dq = f.plane.dist(q);
                let x = p + (q - p) * (dp / (dp - dq));
                f.edges.iter().all(|(m, c)| m.dot(x) - c > self.tol)
            })
        })
    }

    /// Signed distance of `p` from face `id`'s plane.
    pub fn plane_dist(&self, id: u32, p: DVec3) -> f64 {
        self.faces[id as usize].plane.dist(p)
    }

    /// True if one of `faces` crosses the segment from `a` to `b`, each face given with
    /// `a`'s distance from its plane (`plane_dist`), which many segments from `a` share.
    pub fn segment_blocked_from(&self, a: DVec3, b: DVec3, faces: &[(u32, f64)]) -> bool {
        faces.iter().any(|&(id, da)| {
            let f = &self.faces[id as usize];
            let db = f.plane.dist(b);
            let crosses = (da > self.tol && db < -self.tol) || (da < -self.tol && db > self.tol);
            crosses && !f.edges.is_empty() && f.contains(a + (b - a) * (da / (da - db)), self.tol)
        })
    }

    /// True if a face crosses the ray from `origin` (excluded) along `dir` to infinity.
    pub fn ray_blocked(&self, origin: DVec3, dir: DVec3) -> bool {
        self.ray_blocked_skip(origin, dir, &[])
    }

    pub fn ray_blocked_skip(&self, origin: DVec3, dir: DVec3, skip: &[u32]) -> bool {
        let Some(bvh) = &self.wide else { return false };
        let len = dir.length();
        if !(len > 0.0) || !len.is_finite() {
            return false;
        }
        let dir = dir / len;
        let Some(ray) = self.bvh_ray(origin, dir, f64::INFINITY).map(wide_ray) else {
            return false;
        };
        !bvh.ray_traverse_miss(ray, |ray, i| {
            let id = bvh.primitive_indices[i];
            if !self.ray_meets_box(ray, id) {
                return f32::INFINITY;
            }
            if !skip.contains(&id) && self.face_crosses_ray(id, origin, dir) {
                0.0
            } else {
                f32::INFINITY
            }
        })
    }

    /// Appends to `out` (in no set order) every face that could cross a segment lying inside the box
    /// `lo`–`hi` and in front of (or on) each of `planes`: those whose box overlaps it and
    /// which are not wholly behind one of the planes. A face wholly behind a plane can meet
    /// such a segment only on that plane, which is where its ends are, and ends never block.
    pub fn candidates(
        &self,
        lo: DVec3,
        hi: DVec3,
        planes: &[Plane],
        skip: &[u32],
        out: &mut Vec<u32>,
    ) {
        self.candidates_upto(lo, hi, planes, skip, usize::MAX, out);
    }

    /// As [`candidates`](Self::candidates), stopping once `out` holds more than `cap` faces
    /// (then returns false): for callers that would rather cast rays through the BVH than
    /// sift a long list.
    pub fn candidates_upto(
        &self,
        lo: DVec3,
        hi: DVec3,
        planes: &[Plane],
        skip: &[u32],
        cap: usize,
        out: &mut Vec<u32>,
    ) -> bool {
        let Some(bvh) = &self.bvh else { return true };
        let query = Aabb::new(
            to_f32(lo - self.centre - self.pad),
            to_f32(hi - self.centre + self.pad),
        );
        bvh.aabb_traverse(query, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            for i in node.first_index..node.first_index + node.prim_count {
                let id = bvh.primitive_indices[i as usize];
                if !self.boxes[id as usize].intersect_aabb(&query) || skip.contains(&id) {
                    continue;
                }
                if self.in_front_of_all(id, planes) {
                    out.push(id);
                }
            }
            out.len() <= cap
        });
        out.len() <= cap
    }

    /// The `f32` ray for the part of `o + t·dir`, `t ∈ [0, len]`, inside the scene's bounds:
    /// cut there, its ends are never far from the centre, so rounding them stays well under
    /// the padding however far away the query starts. `None` when it misses the scene.
    fn bvh_ray(&self, o: DVec3, dir: DVec3, len: f64) -> Option<Ray> {
        let (mut t0, mut t1) = (0.0f64, len);
        for k in 0..3 {
            if dir[k] == 0.0 {
                if o[k] < self.lo[k] || o[k] > self.hi[k] {
                    return None;
                }
                continue;
            }
            let (a, b) = ((self.lo[k] - o[k]) / dir[k], (self.hi[k] - o[k]) / dir[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        if !(t0 <= t1) {
            return None;
        }
        let start = o + dir * t0;
        Some(Ray::new(
            to_f32(start - self.centre),
            to_f32(dir),
            0.0,
            (t1 - t0 + 2.0 * self.pad) as f32,
        ))
    }

    /// Whether face `id` has area and points in front of each of `planes`.
    ///
    /// Its padded box decides most faces without a load of its vertices (those loads were a
    /// third of room-8328's shaft queries): the box holds every vertex with `pad` to spare
    /// on each side, far more than the rounding of the `f64` sums, so a plane that has the
    /// whole box within the tolerance behind it has every vertex so, and one that has the
    /// whole box beyond it has every vertex beyond. The answer is the vertices' own.
    pub fn in_front_of_all(&self, id: u32, planes: &[Plane]) -> bool {
        if !self.live[id as usize] {
            return false;
        }
        let b = &self.boxes[id as usize];
        let (lo, hi) = (to_f64(b.min) + self.centre, to_f64(b.max) + self.centre);
        let (c, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let mut sure = true;
        for p in planes {
            let (mid, r) = (p.dist(c), p.n.abs().dot(half));
            if mid + r <= self.tol {
                return false;
            }
            sure &= mid - r > self.tol;
        }
        if sure {
            return true;
        }
        let f = &self.faces[id as usize];
        planes
            .iter()
            .all(|p| f.verts.iter().any(|v| p.dist(*v) > self.tol))
    }

    /// Whether face `id`'s bounds overlap the box `lo`–`hi` (both grown by the padding):
    /// narrows a list from [`candidates`](Self::candidates) down to a smaller box.
    pub fn box_overlaps(&self, id: u32, lo: DVec3, hi: DVec3) -> bool {
        let f = &self.faces[id as usize];
        (f.lo - self.pad).cmple(hi + self.pad).all() && (f.hi + self.pad).cmpge(lo - self.pad).all()
    }

    /// Whether face `id` could cross a segment from a point of the convex hull of `a` to a
    /// point of the box `lo`–`hi` (grown by the padding): only if its plane has points of
    /// both on opposite sides, each more than the tolerance off it. A face whose plane
    /// leaves the two on one side can be dropped from a list of blockers between them.
    pub fn straddled_by(&self, id: u32, a: &[DVec3], lo: DVec3, hi: DVec3) -> bool {
        let f = &self.faces[id as usize];
        if f.edges.is_empty() {
            return false;
        }
        let (mut a_lo, mut a_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in a {
            let d = f.plane.dist(*p);
            a_lo = a_lo.min(d);
            a_hi = a_hi.max(d);
        }
        let c = f.plane.dist((lo + hi) * 0.5);
        let r = f.plane.n.abs().dot((hi - lo) * 0.5 + self.pad);
        let (b_lo, b_hi) = (c - r, c + r);
        (a_hi > self.tol && b_lo < -self.tol) || (a_lo < -self.tol && b_hi > self.tol)
    }

    /// Whether the `f32` ray meets face `id`'s padded box, by the test the traversal applies
    /// to the BVH's nodes (so it never drops a face the node test would keep). A leaf holds
    /// up to 8 faces; on room-245's final gather this skipped 5 of every 6 exact tests.
    #[inline]
    fn ray_meets_box(&self, ray: &Ray, id: u32) -> bool {
        // Boxes are padded and the ray may start behind its segment (`wide_ray`): this only
        // spares the exact test, never decides a hit.
        self.boxes[id as usize].intersect_ray(ray) < ray.tmax
    }

    fn face_crosses_segment(&self, id: u32, a: DVec3, b: DVec3) -> bool {
        let f = &self.faces[id as usize];
        if f.edges.is_empty() {
            return false;
        }
        let da = f.plane.dist(a);
        let db = f.plane.dist(b);
        let crosses = (da > self.tol && db < -self.tol) || (da < -self.tol && db > self.tol);
        crosses && f.contains(a + (b - a) * (da / (da - db)), self.tol)
    }

    fn face_crosses_ray(&self, id: u32, o: DVec3, dir: DVec3) -> bool {
        let f = &self.faces[id as usize];
        if f.edges.is_empty() {
            return false;
        }
        let d0 = f.plane.dist(o);
        let dn = f.plane.n.dot(dir);
        let crosses = (d0 > self.tol && dn < 0.0) || (d0 < -self.tol && dn > 0.0);
        crosses && f.contains(o - dir * (d0 / dn), self.tol)
    }
}

impl Occluder {
    /// `p` (on the plane) inside the polygon grown by `tol`.
    #[inline]
    fn contains(&self, p: DVec3, tol: f64) -> bool {
        self.edges.iter().all(|(m, c)| m.dot(p) - c >= -tol)
    }
}

fn occluder(f: &impl PlanarPolygon, tol: f64) -> Occluder {
    let (verts, plane) = (f.verts(), f.plane());
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for v in verts {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    let n = plane.n;
    let mut edges = Vec::with_capacity(verts.len());
    let k = verts.len();
    if k >= 3 && n.is_finite() && n.length_squared() > 0.5 {
        for i in 0..k {
            let e = verts[(i + 1) % k] - verts[i];
            let m = n.cross(e);
            let l = m.length();
            // Repeated vertices give zero-length edges, which bound nothing.
            if l > tol {
                let m = m / l;
                edges.push((m, m.dot(verts[i])));
            }
        }
        if edges.len() < 3 {
            edges.clear();
        }
    }
    Occluder {
        plane,
        verts: verts.to_vec(),
        edges,
        lo,
        hi,
    }
}

#[inline]
fn to_f64(v: Vec3A) -> DVec3 {
    DVec3::new(v.x as f64, v.y as f64, v.z as f64)
}

#[inline]
fn to_f32(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

/// The 8-wide BVH's traversal counts a child box as missed when the ray leaves it under 1e-4
/// along the ray (obvhs' `cwbvh::node::EPSILON`), which misses a face a tenth of a millimetre
/// from a segment's start (a floor point beside a box's wall: 68k of room-78's rays). So its
/// rays start this far behind and run this much longer; the faces found are tested exactly
/// on the segment itself.
const WIDE_BACK: f32 = 2.0e-4;

fn wide_ray(r: Ray) -> Ray {
    Ray::new(
        r.origin - r.direction * WIDE_BACK,
        r.direction,
        0.0,
        r.tmax + WIDE_BACK,
    )
}

#[cfg(test)]
pub(crate) mod test {
    use super::*;

    /// A convex polygon from counter-clockwise (seen from the front) vertices.
    struct Poly {
        verts: Vec<DVec3>,
        plane: Plane,
    }

    impl PlanarPolygon for Poly {
        fn verts(&self) -> &[DVec3] {
            &self.verts
        }
        fn plane(&self) -> Plane {
            self.plane
        }
    }

    fn face(verts: &[DVec3], _albedo: DVec3, _emission: DVec3) -> Poly {
        let plane = Plane::from_polygon(verts).expect("face has area");
        let verts = verts
            .iter()
            .map(|v| *v - plane.n * plane.dist(*v))
            .collect();
        Poly { verts, plane }
    }

    fn quad(c: DVec3, u: DVec3, v: DVec3) -> Poly {
        face(
            &[c - u - v, c + u - v, c + u + v, c - u + v],
            DVec3::splat(0.5),
            DVec3::ZERO,
        )
    }

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// A unit square at z = 0 (facing up) and a wall at x = 2 (facing -x).
    fn two() -> Occluders {
        Occluders::new(&[
            quad(v(0., 0., 0.), v(0.5, 0., 0.), v(0., 0.5, 0.)),
            quad(v(2., 0., 0.), v(0., 0., 1.), v(0., 1., 0.)),
        ])
    }

    /// The box shortcut of `in_front_of_all` answers as the vertices do: for planes that
    /// leave a face wholly on one side (the box decides), and for planes that cut it or pass
    /// within the tolerance of a vertex (the vertices decide). Widening either of the box's
    /// tests by 0.01 fails this; by less than the padding (1e-5 of the scene) it would not
    /// change an answer.
    #[test]
    fn in_front_of_all_answers_as_the_vertices_do() {
        use crate::geom::hash::{mix, unit};
        let r = |i: u64| unit(mix(i)) * 2.0 - 1.0;
        let polys: Vec<Poly> = (0..64u64)
            .map(|i| {
                let c = v(r(i * 16), r(i * 16 + 1), r(i * 16 + 2));
                // Every fourth face lies in an axis plane, as room walls and boxes do.
                let (a, b) = if i % 4 == 0 {
                    (
                        v(0.3 * r(i * 16 + 3), 0., 0.),
                        v(0., 0.2 * r(i * 16 + 4), 0.),
                    )
                } else {
                    let a = v(r(i * 16 + 3), r(i * 16 + 4), r(i * 16 + 5)) * 0.3;
                    let b = v(r(i * 16 + 6), r(i * 16 + 7), r(i * 16 + 8)) * 0.3;
                    (a, b)
                };
                face(&[c, c + a, c + a + b], DVec3::ZERO, DVec3::ZERO)
            })
            .collect();
        let occ = Occluders::new(&polys);
        let mut planes = Vec::new();
        for (i, p) in polys.iter().enumerate() {
            let i = i as u64;
            // Through a vertex, a hair off it either way, and at random.
            let n = v(r(i * 7 + 1000), r(i * 7 + 1001), r(i * 7 + 1002)).normalize();
            let axis = [DVec3::X, DVec3::Y, DVec3::Z][i as usize % 3];
            for n in [n, axis, -axis] {
                let d = n.dot(p.verts[(i % 3) as usize]);
                for off in [0.0, 0.5e-9, -0.5e-9, 2e-9, -2e-9, r(i * 7 + 1003)] {
                    planes.push(Plane::new(n, d + off));
                }
            }
        }
        let mut agreed = [0; 2];
        for id in 0..polys.len() as u32 {
            for k in 0..planes.len() {
                let pl = [planes[k], planes[(k * 7 + 3) % planes.len()]];
                let f = &occ.faces[id as usize];
                let want = pl
                    .iter()
                    .all(|p| f.verts.iter().any(|x| p.dist(*x) > occ.tol));
                assert_eq!(occ.in_front_of_all(id, &pl), want, "face {id}, planes {k}");
                agreed[want as usize] += 1;
            }
        }
        assert!(agreed[0] > 1000 && agreed[1] > 1000, "{agreed:?}");
    }

    #[test]
    fn a_face_right_at_a_segments_start_blocks_it() {
        // The wide BVH's traversal skips boxes left under 1e-4 along a ray (`WIDE_BACK`):
        // a face 3e-5 from the start, in a scene small enough for the boxes' padding (1e-5 of
        // its size) to be thinner than that, among enough faces for the BVH to have levels.
        let mut faces: Vec<Poly> = (0..64)
            .map(|i| {
                let x = 0.3 + 0.08 * (i % 8) as f64;
                let y = 0.3 + 0.08 * (i / 8) as f64;
                quad(v(x, y, 0.0), v(0.03, 0., 0.), v(0., 0.03, 0.))
            })
            .collect();
        faces.push(quad(v(0.1, 0.1, 0.0), v(0.05, 0., 0.), v(0., 0.05, 0.)));
        let o = Occluders::new(&faces);
        for d in [1e-5, 3e-5, 1e-4, 3e-4] {
            let a = v(0.1, 0.1, d);
            assert!(o.segment_blocked(a, v(0.11, 0.095, -0.1)), "{d}");
            assert!(o.ray_blocked(a, v(0.1, -0.05, -1.0)), "{d}");
            assert!(!o.segment_blocked(a, v(0.11, 0.095, 0.1)), "{d}");
        }
    }

    #[test]
    fn hit_and_miss() {
        let o = two();
        assert!(o.segment_blocked(v(0.1, 0.2, 1.0), v(0.1, 0.2, -1.0)));
        assert!(o.segment_blocked(v(0.1, 0.2, -1.0), v(0.3, -0.2, 1.0)));
        assert!(!o.segment_blocked(v(0.6, 0.0, 1.0), v(0.6, 0.0, -1.0)));
        // Stops short of the square.
        assert!(!o.segment_blocked(v(0.1, 0.2, 1.0), v(0.1, 0.2, 0.001)));
        assert!(o.ray_blocked(v(0.1, 0.2, 1.0), v(0.0, 0.0, -3.0)));
        assert!(!o.ray_blocked(v(0.1, 0.2, 1.0), v(0.0, 0.0, 1.0)));
        assert!(o.ray_blocked(v(0.0, 0.0, 0.5), v(1.0, 0.0, 0.0)));
        assert!(!o.ray_blocked(v(0.0, 0.0, 1.5), v(1.0, 0.0, 0.0)));
        assert!(o.segment_blocked_skip(v(1.0, 0.0, 0.5), v(3.0, 0.1, 0.5), &[0]));
        assert!(!o.segment_blocked_skip(v(1.0, 0.0, 0.5), v(3.0, 0.1, 0.5), &[1]));
    }

    #[test]
    fn edges_block_and_just_outside_does_not() {
        let o = two();
        // Through the square's edge x = 0.5 and its corner: the closed polygon blocks.
        assert!(o.segment_blocked(v(0.5, 0.1, 1.0), v(0.5, 0.1, -1.0)));
        assert!(o.segment_blocked(v(0.5, 0.5, 1.0), v(0.5, 0.5, -1.0)));
        assert!(!o.segment_blocked(v(0.5 + 1e-6, 0.1, 1.0), v(0.5 + 1e-6, 0.1, -1.0)));
        // Slanted through the edge.
        assert!(o.segment_blocked(v(0.4, 0.1, 1.0), v(0.6, 0.1, -1.0)));
    }

    #[test]
    fn endpoints_on_surfaces_do_not_self_hit() {
        let o = two();
        // From a point on the square to a point on the wall: both ends lie on faces.
        assert!(!o.segment_blocked(v(0.3, 0.3, 0.0), v(2.0, 0.2, 0.5)));
        // Ending exactly on the square, from above and below.
        assert!(!o.segment_blocked(v(0.1, 0.1, 1.0), v(0.2, 0.2, 0.0)));
        assert!(!o.segment_blocked(v(0.1, 0.1, -1.0), v(0.2, 0.2, 0.0)));
        // Leaving the square's surface into its back: still not a hit.
        assert!(!o.ray_blocked(v(0.2, 0.2, 0.0), v(0.0, 0.0, -1.0)));
        // Starting on the wall going back through nothing, and through the square.
        assert!(!o.ray_blocked(v(2.0, 0.0, 0.5), v(1.0, 0.0, 0.0)));
        assert!(o.ray_blocked(v(2.0, 0.0, 0.5), v(-2.0, 0.0, -0.55)));
    }

    #[test]
    fn grazing_along_a_face_is_not_blocked() {
        let o = two();
        // In the square's plane, over the square.
        assert!(!o.segment_blocked(v(-1.0, 0.0, 0.0), v(1.0, 0.1, 0.0)));
        // Nearly parallel, crossing the plane inside the square: blocked.
        assert!(o.segment_blocked(v(-1.0, 0.0, 1e-3), v(1.0, 0.0, -1e-3)));
        // Nearly parallel, crossing the plane outside it.
        assert!(!o.segment_blocked(v(-1.0, 0.0, 1e-3), v(-0.6, 0.0, -1e-3)));
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles splitting a square along its diagonal; rays along the diagonal.
        let a = face(
            &[v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let b = face(
            &[v(0., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let o = Occluders::new(&[a, b]);
        for i in 0..=100 {
            let t = i as f64 / 100.0;
            assert!(o.segment_blocked(v(t, t, 1.0), v(t, t, -1.0)), "{t}");
        }
    }

    #[test]
    fn far_from_origin_and_tiny() {
        // A 1 mm square 10 km away: f32 rounding is 1 mm there, yet the f64 tests decide.
        let c = v(1e4, -1e4, 3e3);
        let o = Occluders::new(&[quad(c, v(5e-4, 0., 0.), v(0., 5e-4, 0.))]);
        assert!(o.segment_blocked(c + v(4e-4, 0.0, 1e-3), c + v(4e-4, 0.0, -1e-3)));
        assert!(!o.segment_blocked(c + v(6e-4, 0.0, 1e-3), c + v(6e-4, 0.0, -1e-3)));
        assert!(o.ray_blocked(c + v(0.0, 0.0, 1.0), v(1e-4, 0.0, -1.0)));
        assert!(!o.ray_blocked(c + v(0.0, 0.0, 1.0), v(1e-3, 0.0, -1.0)));
        // Queries from far outside the (1 mm) scene are cut to it before rounding.
        assert!(o.segment_blocked(c + v(4e-4, 0.0, 1e3), c + v(4e-4, 0.0, -1e3)));
        assert!(!o.segment_blocked(c + v(5.1e-4, 0.0, 1e3), c + v(5.1e-4, 0.0, -1e3)));
        assert!(o.ray_blocked(c + v(4.9e-4, 4.9e-4, 1e3), v(0.0, 0.0, -1.0)));
    }

    #[test]
    fn many_faces_agree_with_brute_force() {
        // A grid of small tilted quads, and seeded random segments.
        let mut faces = Vec::new();
        for i in 0..8 {
            for j in 0..8 {
                let c = v(i as f64, j as f64, ((i * 7 + j * 3) % 5) as f64 * 0.3);
                faces.push(quad(c, v(0.4, 0.0, 0.1), v(0.0, 0.35, -0.05)));
            }
        }
        let o = Occluders::new(&faces);
        let mut s = 0x2545f4914f6cdd1du64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut hits = 0;
        // The face that blocked the segment before, as the callers hint (it crosses some
        // segments and not others), and a face to skip.
        let (mut last, mut hinted) = (None, 0);
        for _ in 0..2000 {
            let a = v(rnd() * 9.0 - 1.0, rnd() * 9.0 - 1.0, rnd() * 4.0 - 1.5);
            let b = v(rnd() * 9.0 - 1.0, rnd() * 9.0 - 1.0, rnd() * 4.0 - 1.5);
            let brute = (0..faces.len() as u32).any(|f| o.face_crosses_segment(f, a, b));
            assert_eq!(o.segment_blocked(a, b), brute);
            hits += brute as u32;
            let mut cand = Vec::new();
            o.candidates(a.min(b), a.max(b), &[], &[], &mut cand);
            assert_eq!(o.segment_blocker_among(a, b, &cand).is_some(), brute);
            let hit = o.segment_blocker_hinted(a, b, &[], last);
            assert_eq!(hit.is_some(), brute);
            hinted += (hit.is_some() && hit == last) as u32;
            let hint = last.filter(|f| cand.contains(f));
            let among = o.segment_blocker_among_hinted(a, b, &cand, hint);
            assert_eq!(among.is_some(), brute);
            // A hint that is skipped is not taken.
            let skip = [last.unwrap_or(0)];
            let unskipped =
                (0..faces.len() as u32).any(|f| f != skip[0] && o.face_crosses_segment(f, a, b));
            assert_eq!(
                o.segment_blocker_hinted(a, b, &skip, last).is_some(),
                unskipped
            );
            last = hit.or(last);
        }
        assert!(hits > 200 && hits < 1800, "{hits}");
        assert!(hinted > 0, "no segment was blocked by its hint");
    }

    #[test]
    fn candidates_drop_faces_behind_a_plane() {
        let o = two();
        let mut out = Vec::new();
        o.candidates(v(-1., -1., -1.), v(3., 1., 1.), &[], &[], &mut out);
        out.sort_unstable();
        assert_eq!(out, vec![0, 1]);
        out.clear();
        // Segments in front of the plane x = 1 (facing +x) can only meet the wall.
        o.candidates(
            v(-1., -1., -1.),
            v(3., 1., 1.),
            &[Plane::new(DVec3::X, 1.0)],
            &[],
            &mut out,
        );
        assert_eq!(out, vec![1]);
        out.clear();
        o.candidates(v(-1., -1., -1.), v(3., 1., 1.), &[], &[1], &mut out);
        assert_eq!(out, vec![0]);
    }

    #[test]
    fn empty_scene_blocks_nothing() {
        let o = Occluders::new::<Poly>(&[]);
        assert!(!o.segment_blocked(DVec3::ZERO, DVec3::ONE));
        assert!(!o.ray_blocked(DVec3::ZERO, DVec3::ONE));
    }

    #[test]
    fn a_face_covers_only_what_every_segment_through_it_hides() {
        let o = two();
        let tri = |x: f64, y: f64, z: f64, s: f64| {
            vec![v(x - s, y - s, z), v(x + s, y - s, z), v(x, y + s, z)]
        };
        assert!(o.face_covers(0, &tri(0.0, 0.0, 1.0, 0.1), &tri(0.0, 0.0, -1.0, 0.1)));
        // Reaching past the square's edge below: a segment from above passes it by.
        assert!(!o.face_covers(0, &tri(0.0, 0.0, 1.0, 0.1), &tri(0.0, 0.0, -1.0, 0.95)));
        assert!(!o.segment_blocked(v(-0.1, -0.1, 1.0), v(-0.95, -0.95, -1.0)));
        // Both above, or one touching the plane: nothing to cover.
        assert!(!o.face_covers(0, &tri(0.0, 0.0, 1.0, 0.1), &tri(0.0, 0.0, 0.5, 0.1)));
        assert!(!o.face_covers(0, &tri(0.0, 0.0, 1.0, 0.1), &tri(0.0, 0.0, 0.0, 0.1)));

        // Random triangles on either side: where the square covers a pair, no segment
        // between points of the two gets by it.
        let mut k = 0u64;
        let mut next = || {
            k += 1;
            crate::geom::hash::unit(crate::geom::hash::mix(k))
        };
        let (mut covered, mut open) = (0, 0);
        for _ in 0..400 {
            let mut pick = |z: f64| {
                let (x, y, s) = (next() - 0.5, next() - 0.5, 0.3 * next());
                tri(1.2 * x, 1.2 * y, z * (0.05 + next()), s)
            };
            let (a, b) = (pick(1.0), pick(-1.0));
            if !o.face_covers(0, &a, &b) {
                open += 1;
                continue;
            }
            covered += 1;
            let mut point = |t: &[DVec3]| {
                let (mut u, mut w) = (next(), next());
                if u + w > 1.0 {
                    (u, w) = (1.0 - u, 1.0 - w);
                }
                t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * w
            };
            for _ in 0..50 {
                let (p, q) = (point(&a), point(&b));
                assert!(o.segment_blocked(p, q), "{a:?} {b:?}: {p} {q}");
            }
        }
        assert!(covered > 40 && open > 40, "{covered} covered, {open} not");
    }
}

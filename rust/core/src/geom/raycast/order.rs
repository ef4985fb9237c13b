//! The faces again, in the order in which a traversal of each BVH meets them (its
//! `primitive_indices`): the faces of one leaf then share cache lines, where by face id
//! each was a miss of its own (its box, its `Occluder`, then its edges or vertices on the
//! heap). On room-828, 3 paired whole-process runs: CPU 0.968 of reading them by id.

use glam::DVec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::CwBvh;

use super::{inside, Occluder};
use crate::geom::Plane;

/// The faces as a ray's traversal of the 8-wide BVH tests them, slot by slot of its
/// `primitive_indices`.
#[derive(Default)]
pub(super) struct LeafOrder {
    /// Padded boxes: a ray that misses one is spared the exact test. It is the test the
    /// traversal applies to the BVH's nodes, so it never drops a face the node test would
    /// keep. A leaf holds up to 8 faces; on room-245's final gather this skipped 5 of every
    /// 6 exact tests. Boxes are padded and the ray may start behind its segment
    /// (`wide_ray`): this only spares the exact test, never decides a hit.
    pub(super) boxes: Vec<Aabb>,
    planes: Vec<Plane>,
    /// Per slot, its edges in `edges`: `first[i]..first[i + 1]`, none for a face that
    /// cannot block.
    first: Vec<u32>,
    edges: Vec<(DVec3, f64)>,
}

impl LeafOrder {
    pub(super) fn new(wide: Option<&CwBvh>, faces: &[Occluder], boxes: &[Aabb]) -> Self {
        let Some(wide) = wide else {
            return LeafOrder::default();
        };
        let ids = &wide.primitive_indices;
        let mut order = LeafOrder {
            boxes: ids.iter().map(|&id| boxes[id as usize]).collect(),
            planes: ids.iter().map(|&id| faces[id as usize].plane).collect(),
            first: Vec::with_capacity(ids.len() + 1),
            edges: Vec::new(),
        };
        order.first.push(0);
        for &id in ids {
            order.edges.extend_from_slice(&faces[id as usize].edges);
            order.first.push(order.edges.len() as u32);
        }
        order
    }

    /// The edges of slot `i`'s face (inside: `m·p ≥ c`).
    #[inline]
    fn edges(&self, i: usize) -> &[(DVec3, f64)] {
        &self.edges[self.first[i] as usize..self.first[i + 1] as usize]
    }

    /// As [`Occluders::face_crosses_segment`], for the face in slot `i`.
    #[inline]
    pub(super) fn crosses_segment(&self, i: usize, a: DVec3, b: DVec3, tol: f64) -> bool {
        let edges = self.edges(i);
        if edges.is_empty() {
            return false;
        }
        let plane = &self.planes[i];
        let da = plane.dist(a);
        let db = plane.dist(b);
        let crosses = (da > tol && db < -tol) || (da < -tol && db > tol);
        crosses && inside(edges, a + (b - a) * (da / (da - db)), tol)
    }

    /// Whether the face in slot `i` crosses the ray from `o` (excluded) along `dir`.
    #[inline]
    pub(super) fn crosses_ray(&self, i: usize, o: DVec3, dir: DVec3, tol: f64) -> bool {
        let edges = self.edges(i);
        if edges.is_empty() {
            return false;
        }
        let plane = &self.planes[i];
        let d0 = plane.dist(o);
        let dn = plane.n.dot(dir);
        let crosses = (d0 > tol && dn < 0.0) || (d0 < -tol && dn > 0.0);
        crosses && inside(edges, o - dir * (d0 / dn), tol)
    }
}

/// The faces as a box query's traversal of the binary BVH tests them, slot by slot of its
/// `primitive_indices`: padded boxes, and the vertices of faces that have area (none for
/// the others, which never block).
#[derive(Default)]
pub(super) struct BoxOrder {
    pub(super) boxes: Vec<Aabb>,
    /// Per slot, its vertices in `verts`: `first[i]..first[i + 1]`.
    first: Vec<u32>,
    verts: Vec<DVec3>,
}

impl BoxOrder {
    pub(super) fn new(bvh: Option<&Bvh2>, faces: &[Occluder], boxes: &[Aabb]) -> Self {
        let Some(bvh) = bvh else {
            return BoxOrder::default();
        };
        let ids = &bvh.primitive_indices;
        let mut order = BoxOrder {
            boxes: ids.iter().map(|&id| boxes[id as usize]).collect(),
            first: Vec::with_capacity(ids.len() + 1),
            verts: Vec::new(),
        };
        order.first.push(0);
        for &id in ids {
            let f = &faces[id as usize];
            if !f.edges.is_empty() {
                order.verts.extend_from_slice(&f.verts);
            }
            order.first.push(order.verts.len() as u32);
        }
        order
    }

    #[inline]
    pub(super) fn verts(&self, i: usize) -> &[DVec3] {
        &self.verts[self.first[i] as usize..self.first[i + 1] as usize]
    }
}

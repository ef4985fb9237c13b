//! The element mesh of the whole scene after meshing: what lighting works on.
//! Vertices belong to exactly one receiver face (no sharing across faces), so each has one
//! normal; the output step welds coplanar neighbours afterwards.

use glam::DVec3;

use crate::regions::Region;

#[derive(Debug, Clone, Default)]
pub struct Elements {
    pub positions: Vec<DVec3>,
    /// Where lighting is evaluated for each vertex: its position, except for vertices on a
    /// D0 row, which sit a hair inside their own side so they take that side's limit.
    pub eval: Vec<DVec3>,
    /// Unit normal of the vertex's receiver face (its front).
    pub normals: Vec<DVec3>,
    /// Receiver face (index into `Scene::faces`) of each vertex.
    pub vertex_face: Vec<u32>,
    pub triangles: Vec<[u32; 3]>,
    /// Receiver face of each triangle.
    pub tri_face: Vec<u32>,
    /// Region (index into `regions`) of each triangle.
    pub tri_region: Vec<u32>,
    pub regions: Vec<Region>,
    /// Direct irradiance already computed at a vertex (by `mesh::refine`) with its light
    /// counts (umbra, lit, penumbra), or `None`; empty when nothing was, and once the
    /// direct light is done (`bake::run` frees it).
    pub known_direct: Vec<Option<(DVec3, [u64; 3])>>,
}

/// `more` after the per-vertex array `to`, in exactly the room they take: grown by
/// doubling, room-8328's per-vertex arrays would each hold 11.7M slots for its 6.0M
/// vertices once `subdivide`'s are added.
pub(crate) fn append<T>(to: &mut Vec<T>, more: Vec<T>) {
    to.reserve_exact(more.len());
    to.extend(more);
}

impl Elements {
    /// The triangle corners at each vertex, as (triangle, corner) in triangle order:
    /// `around[start[v]..start[v + 1]]`.
    pub fn corners_by_vertex(&self) -> (Vec<u32>, Vec<(u32, u8)>) {
        let nv = self.positions.len();
        let mut start = vec![0u32; nv + 1];
        for t in &self.triangles {
            for &v in t {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut around = vec![(0u32, 0u8); start[nv] as usize];
        for (t, tri) in self.triangles.iter().enumerate() {
            for (i, &v) in tri.iter().enumerate() {
                around[fill[v as usize] as usize] = (t as u32, i as u8);
                fill[v as usize] += 1;
            }
        }
        (start, around)
    }
}

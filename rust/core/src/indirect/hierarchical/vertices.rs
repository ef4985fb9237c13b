//! From the solution to element vertices. A leaf holds one value, and a link pushed down
//! from a large node gives all its leaves the value at that node's centroid: near another
//! face (a room's edge, a leg under a seat) that is off at first order. So each vertex
//! gathers again (a final gather): every link on the way from the root to one of its leaves,
//! with the factor from the vertex itself to the link's source, the link's visibility and the
//! source's final radiosity. Those links cover every source once.

use glam::DVec3;
use rayon::prelude::*;

use super::hierarchy::{Hierarchy, NONE};
use super::link::{planar_gather, point_coefficient};
use super::solve::{Gathering, Radiosity, Solver};
use crate::mesh::elements::Elements;
use crate::scene::Face;

/// Indirect irradiance at every element vertex by a final gather; vertices on no leaf
/// (under a cover) get 0.
pub fn gathered(
    h: &Hierarchy,
    faces: &[Face],
    el: &Elements,
    g: &Gathering,
    solver: &Solver,
    b: &Radiosity,
) -> Vec<DVec3> {
    let nv = el.positions.len();
    let mut parent = vec![NONE; h.nodes.len()];
    for (i, n) in h.nodes.iter().enumerate() {
        if !n.is_leaf() {
            parent[n.kids[0] as usize] = i as u32;
            parent[n.kids[1] as usize] = i as u32;
        }
    }
    let mut leaf_of = vec![NONE; nv];
    for (pos, &t) in h.order.iter().enumerate() {
        for &v in &el.triangles[t as usize] {
            if leaf_of[v as usize] == NONE {
                leaf_of[v as usize] = h.leaf_node[pos];
            }
        }
    }
    let bm = &b.mean;
    let out: Vec<DVec3> = (0..nv)
        .into_par_iter()
        .with_min_len(64)
        .map(|v| {
            let mut a = leaf_of[v];
            if a == NONE {
                return DVec3::ZERO;
            }
            // A hair towards the leaf's centre: a vertex on a face's border lies in the plane
            // of the face beyond it, and takes the limit from inside its own face.
            let p = el.eval.get(v).copied().unwrap_or(el.positions[v]);
            let p = p + (h.nodes[a as usize].centroid - p) * 1e-6;
            let face = el.vertex_face[v];
            let n = faces[face as usize].plane.n;
            let mut e = DVec3::ZERO;
            while a != NONE {
                let ls = &g.links[g.start[a as usize] as usize..g.start[a as usize + 1] as usize];
                for l in ls {
                    let s = &h.nodes[l.source as usize];
                    if s.is_planar() {
                        let ns = faces[s.face as usize].plane.n;
                        let x = planar_gather(h, el, p, n, l.source, ns, bm) * l.v as f64;
                        e += x;
                        continue;
                    }
                    let (k, u) = point_coefficient(h, faces, el, p, n, s);
                    let x = solver.sent(b, l.source, u) * (k * l.v as f64);
                    e += x;
                }
                a = parent[a as usize];
            }
            e
        })
        .collect();
    out
}

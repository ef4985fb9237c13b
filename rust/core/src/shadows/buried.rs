//! Buried geometry: what lies inside a closed convex solid takes no part in the direct light.
//! Clutter that interpenetrates (boxes heaped on a table, a chair leg through a rug) buries
//! most of itself: at a hundred thousand triangles on one table, more than half the box
//! faces lie inside another box. Without this every buried face is a receiver that collects
//! the shadow polygons, plane cuts and critical lines of all its neighbours (whose number
//! grows with the clutter's density, so the whole grows with its square) only for the
//! arrangement to find every face of it in umbra.
//!
//! Both tests are exact up to the usual contact tolerance `eps`:
//! - An occluder wholly inside solid `S` (closed) hides nothing `S` does not: every segment
//!   that meets it meets `S`. It casts no shadow volume. Of two equal solids, the first
//!   stays.
//! - A face wholly inside solid `S` (closed) and lying in none of `S`'s face planes has its
//!   relative interior inside `S`'s interior (a convex polygon in a convex solid that
//!   touches a face plane at an interior point lies in that plane), so no light reaches any
//!   of its points: it is in umbra of every light, which is what the region stage would
//!   have found for each of its faces.

use glam::DVec3;
use rayon::prelude::*;

use crate::geom::bvh::{Aabb, BoxTree};
use crate::geom::Plane;
use crate::scene::solids::{Occluder, Solid};
use crate::scene::Scene;

/// Per occluder and per face: buried or not.
#[derive(Debug, Clone, Default)]
pub struct Burial {
    pub occluders: Vec<bool>,
    pub faces: Vec<bool>,
}

/// Is every point within `eps` of solid `s` or inside it?
fn within(s: &Solid, pts: &[DVec3], eps: f64) -> bool {
    s.planes
        .iter()
        .all(|h| pts.iter().all(|p| h.dist(*p) <= eps))
}

/// The faces of `tree` (a box tree over the scene's faces) whose boxes come within `margin`
/// of the box of `verts`.
pub(crate) fn faces_near(tree: &BoxTree, verts: &[DVec3], margin: f64, eps: f64) -> Vec<u32> {
    let mut b = Aabb::from_points(verts);
    b.min -= DVec3::splat(margin);
    b.max += DVec3::splat(margin);
    let mut near = Vec::new();
    tree.query_volume(&box_planes(&b), eps, &mut near);
    near
}

/// The six planes whose positive sides meet in box `b`, for a box-tree query.
pub(crate) fn box_planes(b: &Aabb) -> [Plane; 6] {
    [
        Plane::new(DVec3::X, b.min.x),
        Plane::new(DVec3::Y, b.min.y),
        Plane::new(DVec3::Z, b.min.z),
        Plane::new(-DVec3::X, -b.max.x),
        Plane::new(-DVec3::Y, -b.max.y),
        Plane::new(-DVec3::Z, -b.max.z),
    ]
}

/// Finds the buried occluders and faces of `scene`.
pub fn burial(scene: &Scene, eps: f64) -> Burial {
    let solids: Vec<(u32, &Solid)> = scene
        .occluders
        .iter()
        .enumerate()
        .filter_map(|(i, o)| match o {
            Occluder::Solid { solid, .. } => Some((i as u32, solid)),
            Occluder::Face(_) => None,
        })
        .collect();
    if solids.is_empty() {
        return Burial {
            occluders: vec![false; scene.occluders.len()],
            faces: vec![false; scene.faces.len()],
        };
    }
    let tree = BoxTree::new(
        solids
            .iter()
            .map(|(_, s)| Aabb::from_points(&s.verts))
            .collect(),
    );
    // Solids (other than occluder `own`) whose box meets the box of `pts`.
    let around = |pts: &[DVec3], own: u32| -> Vec<usize> {
        let mut out = Vec::new();
        tree.query_volume(&box_planes(&Aabb::from_points(pts)), eps, &mut out);
        out.sort_unstable();
        out.into_iter()
            .map(|k| k as usize)
            .filter(|&k| solids[k].0 != own)
            .collect()
    };
    let occluders = scene
        .occluders
        .par_iter()
        .enumerate()
        .map(|(oi, o)| {
            let pts: &[DVec3] = match o {
                Occluder::Solid { solid, .. } => &solid.verts,
                Occluder::Face(f) => &scene.faces[*f as usize].verts,
            };
            around(pts, oi as u32).into_iter().any(|k| {
                let (si, s) = solids[k];
                // Equal solids contain one another: only the later one goes.
                let mutual = match o {
                    Occluder::Solid { solid, .. } => within(solid, &s.verts, eps),
                    Occluder::Face(_) => false,
                };
                within(s, pts, eps) && (!mutual || si < oi as u32)
            })
        })
        .collect();
    let faces = scene
        .faces
        .par_iter()
        .enumerate()
        .map(|(fi, f)| {
            let own = scene.face_occluder[fi];
            around(&f.verts, own).into_iter().any(|k| {
                let s = solids[k].1;
                within(s, &f.verts, eps)
                    && s.planes
                        .iter()
                        .all(|h| f.verts.iter().any(|p| h.dist(*p) < -eps))
            })
        })
        .collect();
    Burial { occluders, faces }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::scene::json::MeshJson;

    fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> MeshJson {
        let p = |i: usize| {
            [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ]
        };
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        MeshJson {
            name: "Box".into(),
            positions: (0..8).map(p).collect(),
            polygons: quads.iter().map(|q| q.to_vec()).collect(),
            albedo: None,
            emission: None,
            uv: None,
            output: None,
        }
    }

    /// One mesh per box, so that equal boxes stay two solids.
    fn scene(boxes: &[([f64; 3], [f64; 3])]) -> Scene {
        crate::scene::test::with_bulb(boxes.iter().map(|(lo, hi)| cuboid(*lo, *hi)).collect())
    }

    #[test]
    fn nested_box_is_buried_and_equal_boxes_keep_one() {
        let sc = scene(&[
            ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
            // Inside, its bottom on the big box's bottom.
            ([0.2, 0.2, 0.0], [0.5, 0.5, 0.5]),
            // Half out.
            ([0.8, 0.2, 0.2], [1.5, 0.5, 0.5]),
            // Twice the same box.
            ([3.0, 0.0, 0.0], [4.0, 1.0, 1.0]),
            ([3.0, 0.0, 0.0], [4.0, 1.0, 1.0]),
        ]);
        let b = burial(&sc, 1e-12);
        assert_eq!(b.occluders, vec![false, true, false, false, true]);
        // The nested box's bottom lies in the big box's bottom plane: not buried (it is the
        // floor's business); its five other faces are.
        let nested: Vec<bool> = b.faces[6..12].to_vec();
        assert_eq!(nested.iter().filter(|&&x| x).count(), 5);
        assert!(b.faces[..6].iter().all(|&x| !x));
        // Of the half-out box, only the face inside the big box.
        assert_eq!(b.faces[12..18].iter().filter(|&&x| x).count(), 1);
        assert!(b.faces[18..].iter().all(|&x| !x));
    }
}

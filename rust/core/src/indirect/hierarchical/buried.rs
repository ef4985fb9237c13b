//! Element triangles buried in another closed convex solid (boxes piled into each other, a
//! post sunk into a block): all they see is that solid's inside, and a solid's faces reflect
//! from the outside only, so they neither shoot nor receive, as covered parts do (`covered`).
//! The direct stage drops faces that are buried whole (`shadows::buried`); this is for the
//! triangles of faces that are buried in part.
//! In room-N's clutter, where N boxes stand on one table top and run into each other, most
//! of the boxes' area is buried; left in the hierarchy, every buried leaf was paired with its
//! neighbours and each pair cast rays that were all blocked.

use crate::geom::bvh::{Aabb, BoxTree};
use crate::mesh::elements::Elements;
use crate::scene::solids::Occluder;
use crate::scene::Scene;
use crate::shadows::buried::box_planes;

pub struct Buried<'a> {
    scene: &'a Scene,
    /// Boxes of the scene's solids; item `i` is occluder `solids[i]`.
    tree: BoxTree,
    solids: Vec<u32>,
    tol: f64,
}

impl<'a> Buried<'a> {
    /// `tol`: how far inside every plane of a solid a corner must lie.
    pub fn new(scene: &'a Scene, tol: f64) -> Self {
        let solids: Vec<u32> = (0..scene.occluders.len() as u32)
            .filter(|&o| matches!(scene.occluders[o as usize], Occluder::Solid { .. }))
            .collect();
        let boxes = solids
            .iter()
            .map(|&o| match &scene.occluders[o as usize] {
                Occluder::Solid { solid, .. } => Aabb::from_points(&solid.verts),
                Occluder::Face(_) => unreachable!(),
            })
            .collect();
        Buried {
            scene,
            tree: BoxTree::new(boxes),
            solids,
            tol,
        }
    }

    /// Whether element triangle `t` lies inside a solid that its face is not part of: its
    /// three corners inside or on every plane of one (a solid is convex, so the whole
    /// triangle is) and its centroid inside every one. The mesh follows the lines where one
    /// solid runs into another, so most buried triangles have a corner on such a line: on
    /// room-245, 4.7k triangles had all three corners inside and 17.8k more touched the
    /// line. A triangle lying on one of the solid's faces is a contact (`covered`), not
    /// buried.
    pub fn buried(&self, el: &Elements, t: u32) -> bool {
        if self.solids.is_empty() {
            return false;
        }
        let corners = el.triangles[t as usize].map(|v| el.positions[v as usize]);
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        let own = self.scene.face_occluder[el.tri_face[t as usize] as usize];
        let planes = box_planes(&Aabb::from_points(&corners));
        self.tree.any_in_volume(&planes, 0.0, |i| {
            let o = self.solids[i as usize];
            match &self.scene.occluders[o as usize] {
                Occluder::Solid { solid, .. } if o != own => solid.planes.iter().all(|p| {
                    p.dist(centroid) < -self.tol && corners.iter().all(|&c| p.dist(c) <= self.tol)
                }),
                _ => false,
            }
        })
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::indirect::patches::test::grid_elements;
    use crate::scenes::{cuboid, polygons_mesh};

    /// A post (x, y in 0.4–0.6, z 0–1) through a slab (z 0.2–0.8).
    fn post_through_slab() -> crate::scene::Scene {
        let post = polygons_mesh(
            "Post",
            cuboid([0.4, 0.4, 0.0], [0.6, 0.6, 1.0], false),
            Some([0.5; 3]),
        );
        let slab = polygons_mesh(
            "Slab",
            cuboid([0.0, 0.0, 0.2], [1.0, 1.0, 0.8], false),
            Some([0.5; 3]),
        );
        crate::scene::test::with_bulb(vec![post, slab])
    }

    #[test]
    fn triangles_inside_another_solid_are_buried() {
        // The post's sides between z 0.2 and 0.8 are inside the slab.
        let sc = post_through_slab();
        let el = grid_elements(&sc.faces, 6);
        let b = Buried::new(&sc, 1e-9);
        let inside = |t: usize| {
            el.triangles[t].iter().all(|&v| {
                let p = el.positions[v as usize];
                p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0 && p.z > 0.2 && p.z < 0.8
            })
        };
        let post_faces = (0..sc.faces.len())
            .filter(|&f| sc.faces[f].verts.iter().all(|v| v.x >= 0.4 && v.x <= 0.6))
            .count();
        assert_eq!(post_faces, 6);
        let (mut buried, mut post_kept) = (0, 0);
        for t in 0..el.triangles.len() {
            let f = &sc.faces[el.tri_face[t] as usize];
            let on_post = f.verts.iter().all(|v| v.x >= 0.4 && v.x <= 0.6);
            let got = b.buried(&el, t as u32);
            // The slab's own triangles never are, the post's exactly where they are inside.
            assert_eq!(got, on_post && inside(t), "triangle {t}");
            buried += got as usize;
            post_kept += (on_post && !got) as usize;
        }
        assert!(
            buried > 0 && post_kept > 0,
            "{buried} buried, {post_kept} kept"
        );
    }

    #[test]
    fn triangles_up_to_the_line_where_solids_meet_are_buried() {
        // Meshed 10 × 10, the elements follow the lines where the post enters and leaves
        // the slab (z 0.2 and 0.8 on the post, x and y 0.4 and 0.6 on the slab): what is
        // buried is the post's sides between them and the slab's top and bottom inside the
        // post, though every one of those triangles at the lines has corners on them.
        let sc = post_through_slab();
        let el = grid_elements(&sc.faces, 10);
        let b = Buried::new(&sc, 1e-9);
        let area = |t: usize| {
            let [p, q, r] = el.triangles[t].map(|v| el.positions[v as usize]);
            0.5 * (q - p).cross(r - p).length()
        };
        let buried: f64 = (0..el.triangles.len())
            .filter(|&t| b.buried(&el, t as u32))
            .map(area)
            .sum();
        assert!(
            (buried - (4.0 * 0.2 * 0.6 + 2.0 * 0.2 * 0.2)).abs() < 1e-9,
            "{buried}"
        );
    }
}

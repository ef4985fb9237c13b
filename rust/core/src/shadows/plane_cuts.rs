//! Plane cuts: where an occluder passes through a receiver (a box sunk into the floor, a leg
//! through a floor, two boxes that intersect), its faces cross the receiver's plane. The line
//! where a face crosses is a D0 discontinuity: on one side the receiver is inside the solid
//! (or behind the face) and light jumps there, yet no shadow volume has a plane along it.
//! The part of a receiver inside a closed solid gets no light at all.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::geom::bvh::BoxTree;
use crate::scene::solids::{Occluder, Solid};
use crate::scene::{Face, Scene, Tolerances};
use crate::shadows::polygons::{Exposure, ReceiverShadows};
use crate::shadows::volume::{clip_to_volume, Volume};

/// The segment where convex occluder face `verts` crosses receiver `r`'s plane, clipped to
/// `r`'s polygon, in `r`'s frame. `None` when the face only touches the plane (within
/// `touch`: a contact, handled as such) or the segment misses the receiver.
pub fn plane_cut(verts: &[DVec3], r: &Face, touch: f64) -> Option<[DVec2; 2]> {
    let d: Vec<f64> = verts.iter().map(|v| r.plane.dist(*v)).collect();
    if d.iter().all(|&x| x >= -touch) || d.iter().all(|&x| x <= touch) {
        return None;
    }
    let n = verts.len();
    let mut pts: Vec<DVec3> = Vec::with_capacity(2);
    for i in 0..n {
        let j = (i + 1) % n;
        let (da, db) = (d[i], d[j]);
        if da.abs() <= touch {
            pts.push(verts[i]);
        } else if db.abs() > touch && (da > 0.0) != (db > 0.0) {
            pts.push(verts[i] + (verts[j] - verts[i]) * (da / (da - db)));
        }
    }
    // A convex face meets a plane in one segment: its two farthest-apart points.
    let (mut a, mut b, mut best) = (pts[0], pts[0], 0.0);
    for (k, p) in pts.iter().enumerate() {
        for q in &pts[k + 1..] {
            let l = (*p - *q).length_squared();
            if l > best {
                (a, b, best) = (*p, *q, l);
            }
        }
    }
    if !(best > touch * touch) {
        return None;
    }
    clip_segment_convex(r.frame.to_2d(a), r.frame.to_2d(b), &r.poly2, touch)
}

/// The part of segment a–b inside the counter-clockwise convex polygon `poly`, or `None`
/// when less than `tol` of it is left.
fn clip_segment_convex(a: DVec2, b: DVec2, poly: &[DVec2], tol: f64) -> Option<[DVec2; 2]> {
    let d = b - a;
    let (t0, t1) = crate::geom::polygon::clip_segment_convex(a, b, poly, 0.0, 0.0)?;
    ((t1 - t0) * d.length() > tol).then(|| [a + d * t0, a + d * t1])
}

/// The part of receiver `r` inside closed convex `solid` (a convex polygon in its frame), or
/// `None` when the solid does not pass through it.
pub fn inside_solid(solid: &Solid, r: &Face, tol: &Tolerances) -> Option<Vec<DVec2>> {
    // A solid only on one side of r's plane (perhaps with a face lying in it) has no
    // inside on r: touching is a contact, handled apart.
    let (eps, touch) = (tol.eps, tol.touch);
    if solid.verts.iter().all(|v| r.plane.dist(*v) >= -touch)
        || solid.verts.iter().all(|v| r.plane.dist(*v) <= touch)
    {
        return None;
    }
    let planes = solid.planes.iter().map(|p| p.flipped()).collect();
    clip_to_volume(r, &Volume { planes, cap: 0 }, eps)
}

/// Where occluder `oi` meets receiver `r`, whatever the light: the edges it stands on
/// (`contacts`), the lines where its faces cross `r`'s plane (`plane_cuts`) and, for a
/// solid, the part of `r` inside it (`inside`). An occluder wholly on or behind `r`'s plane
/// meets nothing of its front.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solid_lines(
    r: &Face,
    oi: u32,
    scene: &Scene,
    outlines: &[(Vec<DVec3>, Vec<[DVec3; 2]>)],
    tol: &Tolerances,
    contacts: &mut Vec<[DVec2; 2]>,
    plane_cuts: &mut Vec<[DVec2; 2]>,
    inside: &mut Vec<Vec<DVec2>>,
) {
    let (verts, edges) = &outlines[oi as usize];
    let touch = tol.touch;
    if verts.iter().all(|v| r.plane.dist(*v) <= tol.eps) {
        return;
    }
    for [a, b] in edges {
        if r.plane.dist(*a).abs() <= touch && r.plane.dist(*b).abs() <= touch {
            contacts.push([r.frame.to_2d(*a), r.frame.to_2d(*b)]);
        }
    }
    let occ = &scene.occluders[oi as usize];
    for &f in occ.faces() {
        if let Some(c) = plane_cut(&scene.faces[f as usize].verts, r, touch) {
            plane_cuts.push(c);
        }
    }
    if let Occluder::Solid { solid, .. } = occ {
        if let Some(p) = inside_solid(solid, r, tol) {
            inside.push(p);
        }
    }
}

/// For faces of solids that no light reaches: where other occluders meet them
/// (`solid_lines`), found through `tree` (a box tree over the faces). They still receive
/// bounced light, and none where a solid cuts into them: without those lines their few
/// elements straddle the cut, and a corner inside a neighbour darkens the whole face
/// (room-245: the side of a box in a heap, two triangles with three corners inside other
/// boxes, 0.09 where Cycles gives 0.90).
pub(crate) fn unlit_solid_lines(
    scene: &Scene,
    tree: &BoxTree,
    outlines: &[(Vec<DVec3>, Vec<[DVec3; 2]>)],
    tol: &Tolerances,
    buried: &[bool],
    per_receiver: &mut [ReceiverShadows],
) {
    let faces = &scene.faces;
    per_receiver
        .par_iter_mut()
        .enumerate()
        .for_each(|(ri, pr)| {
            // A lone face's back (`indirect::hierarchical::back`) shares its triangles and
            // takes light that its front does not: what stands on the front does not touch
            // the back, and lines cut for it only re-cut the back's leaves (the floor under a
            // plane with a box on it moved by 3.5e-3 of its brightest, tests/two_sided.rs).
            let own = scene.face_occluder[ri];
            let solid = matches!(
                scene.occluders.get(own as usize),
                Some(Occluder::Solid { .. })
            );
            if !solid || buried[ri] || pr.exposure.iter().any(|e| *e != Exposure::Hidden) {
                return;
            }
            let r = &faces[ri];
            let near = super::buried::faces_near(tree, &r.verts, tol.touch, tol.eps);
            let mut occs: Vec<u32> = near
                .iter()
                .map(|&f| scene.face_occluder[f as usize])
                .filter(|&o| o != own && (o as usize) < scene.occluders.len())
                .collect();
            occs.sort_unstable();
            occs.dedup();
            let (mut contacts, mut plane_cuts) = (Vec::new(), Vec::new());
            for oi in occs {
                solid_lines(
                    r,
                    oi,
                    scene,
                    outlines,
                    tol,
                    &mut contacts,
                    &mut plane_cuts,
                    &mut pr.inside,
                );
            }
            // As the lights' pass keeps them: each line once.
            for (all, new) in [
                (&mut pr.contacts, contacts),
                (&mut pr.plane_cuts, plane_cuts),
            ] {
                for c in new {
                    if !all.contains(&c) {
                        all.push(c);
                    }
                }
            }
        });
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn segment_clipped_to_square() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let s =
            clip_segment_convex(DVec2::new(-1.0, 0.5), DVec2::new(3.0, 0.5), &sq, 1e-12).unwrap();
        assert!((s[0] - DVec2::new(0.0, 0.5)).length() < 1e-15);
        assert!((s[1] - DVec2::new(1.0, 0.5)).length() < 1e-15);
        assert!(
            clip_segment_convex(DVec2::new(-1.0, 2.0), DVec2::new(3.0, 2.0), &sq, 1e-12).is_none()
        );
    }
}

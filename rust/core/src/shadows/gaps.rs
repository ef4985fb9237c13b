//! Narrow gaps: where another face looks back at a receiver from close by (two boxes side
//! by side a few mm apart, a leg's top under a seat), the part of the receiver across from
//! it sees little but that face, and the light bounced there is far darker than on the rest
//! of the receiver. No shadow marks that part when the light does not reach the receiver (a
//! box's side facing away from it), so its few elements took the face's mean: room-78, a
//! box's side 2.8 mm from its neighbour's, Cycles 0.41 where we gave 0.95, and probes within
//! 5 mm of another box were 22 % of the scene's squared error. The outline of the facing
//! face, projected onto the receiver, becomes a region boundary (not a D0 line: the light is
//! continuous across it), so the hierarchy gives the part in the gap leaves of its own.

use glam::DVec2;
use rayon::prelude::*;

use crate::geom::bvh::BoxTree;
use crate::geom::polygon::{
    along_an_edge, clip_polygon_2d_into, inside_edges, perimeter, signed_area_2d,
};
use crate::scene::{Face, Scene, Tolerances};
use crate::shadows::polygons::ReceiverShadows;

/// A face faces the receiver when their normals are at least this far apart (cosine of
/// 30° from opposite): a wedge wider than that opens to the room.
const FACING: f64 = -0.866;
/// A gap is narrow when the facing face is no farther from the receiver than this times
/// the size of the part across (2 × area / perimeter, half a square's side): no wider than
/// the part across is wide. Light reaches into a gap about as far as it is wide, so a wider
/// one is lit through. (room-78 from Cycles at 1: 3.95 %, before the strip rule of `across`;
/// at 2 and at 4: 3.83 %.)
const NARROW: f64 = 2.0;

/// Adds to each receiver that is not `buried` the outlines of the faces that face it across
/// a narrow gap, clipped to it, as `ReceiverShadows::gaps`, and the parts they bound as
/// `gap_parts` (`Region::gap`: refinement splits links at them). `tree` is a box tree over
/// the scene's faces.
pub(crate) fn gap_lines(
    scene: &Scene,
    tree: &BoxTree,
    tol: &Tolerances,
    buried: &[bool],
    per_receiver: &mut [ReceiverShadows],
) {
    let faces = &scene.faces;
    per_receiver
        .par_iter_mut()
        .enumerate()
        .for_each(|(ri, pr)| {
            if buried[ri] {
                return;
            }
            let r = &faces[ri];
            let reach = NARROW * size(&r.poly2);
            if !(reach > tol.touch) {
                return;
            }
            let mut near = super::buried::faces_near(tree, &r.verts, reach, tol.eps);
            near.sort_unstable();
            let mut lines = Vec::new();
            for f in near {
                if f as usize != ri {
                    let n = lines.len();
                    if let Some(part) = across(r, &faces[f as usize], tol, &mut lines) {
                        if lines.len() > n {
                            pr.gap_parts.push(part);
                        }
                    }
                }
            }
            for l in lines {
                if !pr.gaps.contains(&l) {
                    pr.gaps.push(l);
                }
            }
        });
}

/// The edges of the part of `r` across a narrow gap from `f` (f's outline projected onto
/// `r`, clipped to it), leaving out those along `r`'s own boundary, or nearer to it than the
/// gap is wide: light varies over about the gap's width, and the thin strips those edges
/// cut off made leaves near everything (room-828: 1.40M links → 1.94M with them, 1.60M
/// without; the error was the same on room-78 and 0.1 % lower on room-245).
fn across(
    r: &Face,
    f: &Face,
    tol: &Tolerances,
    out: &mut Vec<[DVec2; 2]>,
) -> Option<(Vec<DVec2>, f64)> {
    if r.plane.n.dot(f.plane.n) > FACING {
        return None;
    }
    let mut far = 0.0f64;
    for v in &f.verts {
        let d = r.plane.dist(*v);
        // Touching or behind: contacts and plane cuts are another module's.
        if !(d > tol.touch) {
            return None;
        }
        far = far.max(d);
    }
    // f runs against r's orientation: reversed, its projection is counter-clockwise.
    let mut part: Vec<DVec2> = f.verts.iter().rev().map(|v| r.frame.to_2d(*v)).collect();
    let mut scratch = Vec::with_capacity(part.len() + r.poly2.len());
    for h in inside_edges(&r.poly2) {
        clip_polygon_2d_into(&part, &h, 0.0, &mut scratch);
        std::mem::swap(&mut part, &mut scratch);
        if part.len() < 3 {
            return None;
        }
    }
    if !(far <= NARROW * size(&part)) {
        return None;
    }
    for (i, &a) in part.iter().enumerate() {
        let b = part[(i + 1) % part.len()];
        if (b - a).length() > tol.touch && !along_an_edge(&r.poly2, a, b, far) {
            out.push([a, b]);
        }
    }
    Some((part, far))
}

/// 2 × area / perimeter of a convex polygon: its inradius for a regular one, half the
/// short side of a long rectangle.
fn size(poly: &[DVec2]) -> f64 {
    let p = perimeter(poly);
    if p > 0.0 {
        2.0 * signed_area_2d(poly).abs() / p
    } else {
        0.0
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::indirect::test::quad;
    use glam::DVec3;

    fn square(c: DVec3, u: DVec3, w: DVec3) -> Face {
        quad(c, u, w, 0.5, DVec3::ZERO)
    }

    #[test]
    fn a_face_across_a_narrow_gap_is_outlined_and_a_far_one_is_not() {
        let tol = Tolerances::new(10.0);
        // Receiver: the unit square at z = 0, facing up.
        let r = square(DVec3::new(0.5, 0.5, 0.0), DVec3::X * 0.5, DVec3::Y * 0.5);
        // Facing down 2 mm above: [0.7, 1.1]², over the receiver's corner.
        let (hx, hy) = (DVec3::X * 0.2, DVec3::Y * 0.2);
        let near = square(DVec3::new(0.9, 0.9, 0.002), hy, hx);
        assert!(near.plane.n.z < -0.99);
        let mut out = Vec::new();
        let (_, width) = across(&r, &near, &tol, &mut out).expect("a narrow gap");
        assert!((width - 0.002).abs() < 1e-12, "{width}");
        // The part across is [0.7, 1]², two of whose edges are the receiver's own.
        assert_eq!(out.len(), 2, "{out:?}");
        for [a, b] in &out {
            let (pa, pb) = (r.frame.to_3d(*a), r.frame.to_3d(*b));
            let on_x = (pa.x - 0.7).abs() < 1e-9 && (pb.x - 0.7).abs() < 1e-9;
            let on_y = (pa.y - 0.7).abs() < 1e-9 && (pb.y - 0.7).abs() < 1e-9;
            assert!(on_x || on_y, "{pa} {pb}");
            assert!(((pa - pb).length() - 0.3).abs() < 1e-9, "{pa} {pb}");
        }
        // The same square 0.35 above: wider than the part across (0.3).
        let high = square(DVec3::new(0.9, 0.9, 0.35), hy, hx);
        out.clear();
        across(&r, &high, &tol, &mut out);
        assert!(out.is_empty());
        // Reaching to 1 mm of the receiver's edge x = 0, 2 mm above: that edge cuts off a strip
        // narrower than the gap, and only the edge at y = 0.7 is kept.
        let wide = square(DVec3::new(0.5505, 0.9, 0.002), hy, DVec3::X * 0.5495);
        out.clear();
        across(&r, &wide, &tol, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        let (pa, pb) = (r.frame.to_3d(out[0][0]), r.frame.to_3d(out[0][1]));
        assert!(
            (pa.y - 0.7).abs() < 1e-9 && (pb.y - 0.7).abs() < 1e-9,
            "{pa} {pb}"
        );
        out.clear();
        // Facing up (the receiver's way), or below the receiver: no gap.
        let up = square(DVec3::new(0.5, 0.5, 0.002), hx, hy);
        across(&r, &up, &tol, &mut out);
        let below = square(DVec3::new(0.5, 0.5, -0.002), hy, hx);
        across(&r, &below, &tol, &mut out);
        assert!(out.is_empty());
    }
}

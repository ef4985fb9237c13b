//! Plane cuts: where an occluder passes through a receiver (a box sunk into the floor, a leg
//! through a floor, two boxes that intersect), its faces cross the receiver's plane. The line
//! where a face crosses is a D0 discontinuity: on one side the receiver is inside the solid
//! (or behind the face) and light jumps there, yet no shadow volume has a plane along it.
//! The part of a receiver inside a closed solid gets no light at all.

use glam::{DVec2, DVec3};

use crate::scene::solids::Solid;
use crate::scene::{Face, Tolerances};
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

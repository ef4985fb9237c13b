//! The parts of faces that lie against another face: a coplanar face facing the other way
//! that overlaps it (a box standing on the floor covers the floor under it, and the floor
//! covers the box's bottom). No light reaches such a part and none leaves it, so it must
//! neither shoot indirect light nor dilute the mean radiosity of the patch around it.

use std::collections::HashMap;

use glam::DVec2;

use crate::geom::polygon::{clip_polygon_2d, inside_edges, perimeter, signed_area_2d, HalfPlane};
use crate::scene::Face;

/// A convex part of a face that nothing covers: its polygon (in the face's frame) and the
/// half-planes that cut it out of the face (none when the face is uncovered).
#[derive(Debug, Clone)]
pub struct Open {
    pub poly: Vec<DVec2>,
    pub cuts: Vec<HalfPlane>,
}

/// Per face, its uncovered part as disjoint convex pieces. A face with no cover has one
/// piece, itself, without cuts; a face covered whole has none. `tol` is the distance under
/// which two planes count as the same.
#[cfg(test)]
pub fn open_parts(faces: &[Face], tol: f64) -> Vec<Vec<Open>> {
    open_parts_of(faces, &covers(faces, tol), tol)
}

/// `open_parts` from the faces' `covers` (as `covers` gives them).
pub fn open_parts_of(faces: &[Face], covers: &[Vec<Vec<DVec2>>], tol: f64) -> Vec<Vec<Open>> {
    let tol = tol.max(f64::MIN_POSITIVE);
    faces
        .iter()
        .zip(covers)
        .map(|(f, covers)| {
            let whole = vec![Open {
                poly: f.poly2.clone(),
                cuts: Vec::new(),
            }];
            covers
                .iter()
                .fold(whole, |parts, c| subtract(parts, c, tol))
        })
        .collect()
}

/// Per face, the coplanar opposite faces that overlap its plane, as polygons in the face's
/// frame, counter-clockwise. `tol` as for `open_parts`.
pub fn covers(faces: &[Face], tol: f64) -> Vec<Vec<Vec<DVec2>>> {
    let tol = tol.max(f64::MIN_POSITIVE);
    // Faces by their plane offset, in buckets of `tol`: a coplanar opposite face has the
    // negated offset, within a bucket of it.
    let key = |d: f64| (d / tol).floor() as i64;
    let mut by_offset: HashMap<i64, Vec<u32>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        by_offset.entry(key(f.plane.d)).or_default().push(i as u32);
    }
    faces
        .iter()
        .map(|f| {
            let k = key(-f.plane.d);
            (k - 1..=k + 1)
                .filter_map(|b| by_offset.get(&b))
                .flatten()
                .map(|&g| &faces[g as usize])
                .filter(|g| {
                    g.plane.n.dot(f.plane.n) < -1.0 + 1e-9
                        && g.verts.iter().all(|v| f.plane.dist(*v).abs() <= tol)
                })
                .map(|g| {
                    // Seen from f's front, g (facing away) runs clockwise.
                    let mut c: Vec<DVec2> = g.verts.iter().map(|v| f.frame.to_2d(*v)).collect();
                    c.reverse();
                    c
                })
                .filter(|c| signed_area_2d(c) > 0.0)
                .collect()
        })
        .collect()
}

/// `parts` minus the convex polygon `c` (counter-clockwise). A part that `c` misses stays
/// whole; one it overlaps splits into one piece per edge of `c`: outside that edge and
/// inside the edges before it.
fn subtract(parts: Vec<Open>, c: &[DVec2], tol: f64) -> Vec<Open> {
    let n = c.len();
    let inside = inside_edges(c);
    // Overlaps thinner than this are rounding, not cover.
    let min_area = |p: &[DVec2]| tol * perimeter(p);
    let mut out = Vec::with_capacity(parts.len());
    for part in parts {
        let overlap = inside
            .iter()
            .fold(part.poly.clone(), |p, h| clip_polygon_2d(&p, h, 0.0));
        if !(signed_area_2d(&overlap) > min_area(&part.poly)) {
            out.push(part);
            continue;
        }
        for k in 0..n {
            let outside = HalfPlane {
                n: -inside[k].n,
                c: -inside[k].c,
            };
            let mut poly = clip_polygon_2d(&part.poly, &outside, 0.0);
            for h in &inside[..k] {
                poly = clip_polygon_2d(&poly, h, 0.0);
            }
            if signed_area_2d(&poly) > min_area(&poly) {
                let mut cuts = part.cuts.clone();
                cuts.push(outside);
                cuts.extend_from_slice(&inside[..k]);
                out.push(Open { poly, cuts });
            }
        }
    }
    out
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::scene::test::face;
    use glam::DVec3;

    #[test]
    fn box_bottom_covers_the_floor_under_it_and_is_covered_whole() {
        let v = |x, y| DVec3::new(x, y, 0.0);
        let floor = face(
            &[v(0.0, 0.0), v(4.0, 0.0), v(4.0, 4.0), v(0.0, 4.0)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        // Facing down (clockwise seen from above), 1 × 1 at (1, 1).
        let bottom = face(
            &[v(1.0, 1.0), v(1.0, 2.0), v(2.0, 2.0), v(2.0, 1.0)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        // Facing down too but 1 above: no cover.
        let up = |x, y| DVec3::new(x, y, 1.0);
        let lid = face(
            &[up(1.0, 1.0), up(1.0, 2.0), up(2.0, 2.0), up(2.0, 1.0)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let q = floor.frame.to_2d(v(1.5, 1.5));
        let parts = open_parts(&[floor, bottom, lid], 1e-9);
        let area = |ps: &[Open]| ps.iter().map(|p| signed_area_2d(&p.poly)).sum::<f64>();
        assert!(
            (area(&parts[0]) - 15.0).abs() < 1e-12,
            "{}",
            area(&parts[0])
        );
        assert!(parts[1].is_empty());
        assert_eq!(parts[2].len(), 1);
        assert!(parts[2][0].cuts.is_empty());
        // The pieces' cuts keep a point under the box out of every piece.
        assert!(parts[0]
            .iter()
            .all(|p| p.cuts.iter().any(|h| h.eval(q) < 0.0)));
    }
}

//! Splits input polygons (Blender n-gons: possibly concave, possibly slightly non-planar)
//! into convex planar pieces, as the paper requires of receivers and occluders.

use glam::{DVec2, DVec3};

use crate::geom::polygon::{orient, signed_area_2d};
use crate::geom::{Frame, Plane};

/// Relative out-of-plane deviation above which a polygon is treated as non-planar and
/// split into triangles (each exactly planar) rather than flattened.
pub(crate) const PLANAR_TOL: f64 = 1e-7;

/// Convex pieces of `pts`, each counter-clockwise around the same side as the input.
/// Empty when the polygon has no area.
pub fn convex_pieces(pts: &[DVec3]) -> Vec<Vec<DVec3>> {
    let mut p: Vec<DVec3> = Vec::with_capacity(pts.len());
    for &q in pts {
        if p.last() != Some(&q) {
            p.push(q);
        }
    }
    while p.len() > 1 && p.first() == p.last() {
        p.pop();
    }
    if p.len() < 3 {
        return Vec::new();
    }
    let Some(plane) = Plane::from_polygon(&p) else {
        return Vec::new();
    };
    let extent = p.iter().map(|q| (*q - p[0]).length()).fold(0.0, f64::max);
    let planar = p
        .iter()
        .all(|q| plane.dist(*q).abs() <= PLANAR_TOL * extent);
    let frame = Frame::on_plane(&plane, p[0]);
    let p2: Vec<DVec2> = p.iter().map(|q| frame.to_2d(*q)).collect();

    if planar && is_convex(&p2) {
        let flat: Vec<DVec3> = p2.iter().map(|q| frame.to_3d(*q)).collect();
        return vec![flat];
    }
    let tris = ear_clip(&p2);
    tris.into_iter()
        .map(|[a, b, c]| {
            if planar {
                vec![frame.to_3d(p2[a]), frame.to_3d(p2[b]), frame.to_3d(p2[c])]
            } else {
                vec![p[a], p[b], p[c]]
            }
        })
        .filter(|t| Plane::from_polygon(t).is_some())
        .collect()
}

/// Convex and counter-clockwise (collinear runs allowed).
pub(crate) fn is_convex(p: &[DVec2]) -> bool {
    let n = p.len();
    if signed_area_2d(p) <= 0.0 {
        return false;
    }
    (0..n).all(|i| orient(p[(i + n - 1) % n], p[i], p[(i + 1) % n]) >= 0.0)
}

/// Ear clipping with exact orientation tests. Works for simple polygons of either winding
/// (the output keeps the input's winding); for self-intersecting input it still returns
/// triangles covering the polygon's vertices without panicking.
pub(crate) fn ear_clip(p: &[DVec2]) -> Vec<[usize; 3]> {
    let mut idx: Vec<usize> = (0..p.len()).collect();
    let ccw = signed_area_2d(p) >= 0.0;
    let sign = if ccw { 1.0 } else { -1.0 };
    let mut out = Vec::with_capacity(p.len().saturating_sub(2));
    let mut guard = 0usize;
    while idx.len() > 3 && guard < 4 * p.len() * p.len() + 16 {
        guard += 1;
        let n = idx.len();
        let mut clipped = false;
        for i in 0..n {
            let (ia, ib, ic) = (idx[(i + n - 1) % n], idx[i], idx[(i + 1) % n]);
            let (a, b, c) = (p[ia], p[ib], p[ic]);
            let o = orient(a, b, c) * sign;
            if o < 0.0 {
                continue;
            }
            if o == 0.0 {
                // A collinear vertex carries no area: drop it.
                idx.remove(i);
                clipped = true;
                break;
            }
            let blocked = idx.iter().any(|&j| {
                if j == ia || j == ib || j == ic {
                    return false;
                }
                let q = p[j];
                orient(a, b, q) * sign >= 0.0
                    && orient(b, c, q) * sign >= 0.0
                    && orient(c, a, q) * sign >= 0.0
            });
            if !blocked {
                out.push([ia, ib, ic]);
                idx.remove(i);
                clipped = true;
                break;
            }
        }
        if !clipped {
            // Not simple: fall back to a fan so the area is still covered.
            for k in 1..idx.len() - 1 {
                out.push([idx[0], idx[k], idx[k + 1]]);
            }
            return out;
        }
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    out
}

#[cfg(test)]
mod test {
    use super::*;

    fn area3(ps: &[Vec<DVec3>]) -> f64 {
        ps.iter()
            .map(|p| crate::geom::plane::newell_normal(p).length() * 0.5)
            .sum()
    }

    #[test]
    fn convex_quad_stays_whole() {
        let q = [DVec3::ZERO, DVec3::X, DVec3::new(1., 1., 0.), DVec3::Y];
        let r = convex_pieces(&q);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].len(), 4);
    }

    #[test]
    fn l_shape_is_split_and_keeps_area_and_facing() {
        let l = [
            DVec3::new(0., 0., 0.),
            DVec3::new(2., 0., 0.),
            DVec3::new(2., 1., 0.),
            DVec3::new(1., 1., 0.),
            DVec3::new(1., 2., 0.),
            DVec3::new(0., 2., 0.),
        ];
        let r = convex_pieces(&l);
        assert!(r.len() >= 2);
        assert!((area3(&r) - 3.0).abs() < 1e-12);
        for t in &r {
            assert!(Plane::from_polygon(t).unwrap().n.z > 0.99);
        }
    }

    #[test]
    fn degenerate_polygons_vanish() {
        assert!(convex_pieces(&[DVec3::ZERO, DVec3::X, DVec3::X]).is_empty());
        assert!(convex_pieces(&[DVec3::ZERO, DVec3::X, DVec3::X * 3.0]).is_empty());
    }

    #[test]
    fn nonplanar_quad_becomes_triangles_on_its_vertices() {
        let q = [DVec3::ZERO, DVec3::X, DVec3::new(1., 1., 0.3), DVec3::Y];
        let r = convex_pieces(&q);
        assert_eq!(r.len(), 2);
        for t in &r {
            for v in t {
                assert!(q.contains(v));
            }
        }
    }
}

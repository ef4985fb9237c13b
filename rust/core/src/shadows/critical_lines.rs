//! Critical events inside a penumbra (paper 2.2 keeps only the umbra and penumbra outlines;
//! the light is not smooth inside the penumbra either). Where a light vertex lines up with an
//! occluder edge (VE) or a light edge with an occluder vertex (EV), a new piece of the light
//! starts or stops being hidden, and the irradiance has a kink (D1) along the line those
//! critical planes cut on the receiver. Meshing along them too lets the mesh follow the light
//! exactly with few elements: without them the largest interpolation errors sit on these
//! lines.

use glam::{DVec2, DVec3};

use crate::geom::polygon::clip_polygon_3d;
use crate::geom::Plane;
use crate::scene::solids::Occluder;
use crate::scene::{Face, Tolerances};

/// Central projection of `x` from `l` onto the receiver's plane, if the ray from l through x
/// reaches it beyond x.
fn project(r: &Face, l: DVec3, x: DVec3) -> Option<DVec2> {
    let (dl, dx) = (r.plane.dist(l), r.plane.dist(x));
    if !(dl > dx) || dx < -1e-12 * dl.abs() {
        return None;
    }
    let t = dl / (dl - dx);
    Some(r.frame.to_2d(l + (x - l) * t))
}

/// The part of segment a–b whose distance to the receiver plane lies in [0, limit).
fn clip_height(r: &Face, a: DVec3, b: DVec3, limit: f64) -> Option<(DVec3, DVec3)> {
    let (da, db) = (r.plane.dist(a), r.plane.dist(b));
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (lo_ok, f0, f1) in [(true, da, db), (false, limit - da, limit - db)] {
        let _ = lo_ok;
        // Keep f ≥ 0 along the segment (f linear in t).
        if f0 < 0.0 && f1 < 0.0 {
            return None;
        }
        if f0 < 0.0 {
            t0 = t0.max(f0 / (f0 - f1));
        } else if f1 < 0.0 {
            t1 = t1.min(f0 / (f0 - f1));
        }
    }
    (t1 > t0).then(|| (a + (b - a) * t0, a + (b - a) * t1))
}

/// Clips a 2-D segment to a convex counter-clockwise polygon.
fn clip_to_convex(p: DVec2, q: DVec2, poly: &[DVec2]) -> Option<(DVec2, DVec2)> {
    let (t0, t1) = crate::geom::polygon::clip_segment_convex(p, q, poly, 0.0, 0.0)?;
    Some((p + (q - p) * t0, p + (q - p) * t1))
}

/// VE and EV segments of light `lv` (an area light's polygon, clipped to the receiver's front)
/// and occluder `occ` on receiver `r`, inside the penumbra polygon `pen` (receiver frame).
#[allow(clippy::too_many_arguments)]
pub fn critical_segments(
    lv: &[DVec3],
    lplane: &Plane,
    occ: &Occluder,
    faces: &[Face],
    r: &Face,
    pen: &[DVec2],
    tol: &Tolerances,
    out: &mut Vec<[DVec2; 2]>,
) {
    let (eps, min_len) = (tol.eps, tol.touch);
    let mut push = |a: DVec2, b: DVec2| {
        if let Some((a, b)) = clip_to_convex(a, b, pen) {
            if (b - a).length() > min_len {
                out.push([a, b]);
            }
        }
    };
    for (k, &l) in lv.iter().enumerate() {
        let l2 = lv[(k + 1) % lv.len()];
        let dl = r.plane.dist(l);
        // Occluder edges and vertices that can line up with this light vertex.
        let (edges, verts) = occluder_outline_from(occ, faces, lplane, l, eps);
        for (a, b) in edges {
            let Some((a, b)) = clip_height(r, a, b, dl * (1.0 - 1e-9)) else {
                continue;
            };
            if let (Some(pa), Some(pb)) = (project(r, l, a), project(r, l, b)) {
                push(pa, pb);
            }
        }
        // EV: the light edge l → l2 swept through each occluder vertex.
        for v in verts {
            if let (Some(pa), Some(pb)) = (project(r, l, v), project(r, l2, v)) {
                push(pa, pb);
            }
        }
    }
}

/// The occluder's edges and vertices as seen from light point `l`: a face's (clipped to the
/// light's front) all; a solid's silhouette.
fn occluder_outline_from(
    occ: &Occluder,
    faces: &[Face],
    lplane: &Plane,
    l: DVec3,
    eps: f64,
) -> (Vec<(DVec3, DVec3)>, Vec<DVec3>) {
    match occ {
        Occluder::Face(f) => {
            let o = clip_polygon_3d(&faces[*f as usize].verts, lplane, eps);
            let edges = (0..o.len()).map(|i| (o[i], o[(i + 1) % o.len()])).collect();
            (edges, o)
        }
        Occluder::Solid { solid: s, .. } => {
            let front: Vec<bool> = s.planes.iter().map(|p| p.dist(l) > 0.0).collect();
            let mut edges = Vec::new();
            let mut verts = Vec::new();
            for (e, fp) in s.edges.iter().zip(&s.edge_planes) {
                if front[fp[0] as usize] != front[fp[1] as usize] {
                    let (a, b) = (s.verts[e[0] as usize], s.verts[e[1] as usize]);
                    edges.push((a, b));
                    verts.push(a);
                }
            }
            (edges, verts)
        }
    }
}

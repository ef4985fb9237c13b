//! Screens: a face `F` screens occluder `B` from a receiver `R` under one light when every
//! segment from `R` to the light that meets `B` also meets `F`. Then `B` hides nothing that
//! the occluder owning `F` does not hide already, so its shadow polygons on `R` change no
//! relation and no light value, and `B` can be left out there altogether (with its edges,
//! their crossings and its place in every blocker list). Clutter on a table is screened from
//! the floor by the table top: without this each box casts a penumbra on the floor under the
//! table, and the floor's arrangement grows with the square of the number of boxes.
//!
//! The test, exact up to the usual contact tolerance: `B` lies on the light's side of `F`'s
//! plane, every light point is farther from that plane than every point of `B`, `R` lies
//! strictly on the other side, and the projections of `B`'s vertices from the light's
//! vertices onto the plane all lie in `F`. A segment from `p ∈ R` to a light point `l` that
//! meets `B` at `b` crosses the plane once, at a point of the ray from `l` through `b`
//! beyond `b`; with the light wholly farther than `B`, the set of those points is the
//! convex hull of the vertex projections (a central projection from each `l`, and from each
//! `b` a perspective map of the light polygon), so it lies in `F`.

use glam::{DVec2, DVec3};

use crate::geom::polygon::orient;
use crate::scene::Face;

/// Largest faces tried as screens per occluder (the test is a few dozen projections each).
const TRIED: usize = 8;

/// Faces among `candidates` (receivers `B`'s shadow reaches) that screen occluder `B`
/// (vertices `occ`) from everything strictly beyond them, under a light with vertices
/// `light` (one point for a point light). `own` tells `B`'s own faces.
pub fn screen_faces(
    light: &[DVec3],
    occ: &[DVec3],
    candidates: &[u32],
    faces: &[Face],
    own: impl Fn(u32) -> bool,
    eps: f64,
) -> Vec<u32> {
    if light.is_empty() || occ.is_empty() {
        return Vec::new();
    }
    let mut cand: Vec<u32> = candidates.iter().copied().filter(|&f| !own(f)).collect();
    cand.sort_by(|&a, &b| {
        faces[b as usize]
            .area
            .total_cmp(&faces[a as usize].area)
            .then(a.cmp(&b))
    });
    let mut out = Vec::new();
    for &f in cand.iter().take(TRIED) {
        if screens(light, occ, &faces[f as usize], eps) {
            out.push(f);
        }
    }
    out
}

fn screens(light: &[DVec3], occ: &[DVec3], f: &Face, eps: f64) -> bool {
    let pl = &f.plane;
    let db: Vec<f64> = occ.iter().map(|b| pl.dist(*b)).collect();
    let top = db.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if db.iter().any(|&d| !(d >= -eps)) {
        return false;
    }
    let dl: Vec<f64> = light.iter().map(|l| pl.dist(*l)).collect();
    if dl.iter().any(|&d| !(d > top + eps)) {
        return false;
    }
    let n = f.poly2.len();
    if n < 3 {
        return false;
    }
    let inside = |c: DVec2| (0..n).all(|i| orient(f.poly2[i], f.poly2[(i + 1) % n], c) >= 0.0);
    light.iter().zip(&dl).all(|(l, &d_l)| {
        occ.iter().zip(&db).all(|(b, &d_b)| {
            let c = *l + (*b - *l) * (d_l / (d_l - d_b));
            inside(f.frame.to_2d(c))
        })
    })
}

/// Is receiver `r` strictly beyond one of `screens` (so that they screen it)?
pub fn screened(r: &Face, screens: &[u32], faces: &[Face], eps: f64) -> bool {
    screens.iter().any(|&s| {
        let pl = &faces[s as usize].plane;
        r.verts.iter().all(|v| pl.dist(*v) < -eps)
    })
}

//! Vertex values fitted to the light over the elements, not sampled at the vertices.
//!
//! Linear interpolation of exact vertex values errs to one side wherever the light curves:
//! under a lamp, where the light is concave, every element reads low between its corners
//! (data1's worst probes at 1 %, all 0.3 % low). The continuous piecewise-linear function
//! closest to the light in the least-squares sense (Kavan, Bargteil and Sloan's
//! least-squares vertex baking, 2011, does the same for baked vertex colours) takes that
//! bias out: for a quadratic light it halves the RMS error of the interpolant and lowers
//! its largest error by a third, at the same elements. The light at every edge midpoint
//! gives each element's departure from linear, `e = Σ 4 b_k λ_i λ_j` over its edges k
//! (b_k: the light at the midpoint of edge k minus the interpolant there, λ the barycentric
//! coordinates); the shifts `s` of the vertex values solve `M s = r`, M the mass matrix,
//! r_v = Σ ∫ e φ_v, by a few Jacobi sweeps from the lumped solution.
//!
//! The bound refinement guarantees holds after the shift: each vertex moves at most
//! [`super::refine::SAFETY`] × tolerance × (its light + floor), so a point that refinement
//! left within that fraction of the bound stays within twice it. A vertex in the dark next
//! to a shadow's edge (light 0) moves by no more than the floor allows, and the limits at
//! D0 corners (`corner_split`) stay exact: each is one triangle's own value.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::refine::{key, Cache, Lights, FLOOR, SAFETY};
use super::ReceiverMesh;
use crate::regions::relation::Relation;

/// Jacobi sweeps on the consistent mass matrix after the lumped solution; the two differ
/// where element sizes change quickly (data1 at 3 %: 0.097 → 0.089 % from Cycles).
const SWEEPS: usize = 3;
/// Damping of the Jacobi sweeps: the eigenvalues of D⁻¹M lie in [1/2, 2] on any mesh of
/// linear triangles (Wathen 1987), so a factor below 1 converges, and 2/3 damps every mode.
const DAMPING: f64 = 2.0 / 3.0;

/// Shifts `m.known_direct` to the least-squares fit of the light over the elements.
/// `corner` marks the vertices `corner_split` gave each triangle, which keep their values.
/// Midpoints already read by refinement come from `cache`; the others are evaluated, but in
/// penumbra. Returns how many points were evaluated.
pub(super) fn fit(
    m: &mut ReceiverMesh,
    corner: &[bool],
    cache: &Cache,
    lights: &Lights,
    tolerance: f64,
) -> u64 {
    let n = m.positions.len();
    if n == 0 || m.known_direct.len() != n || m.known_direct.iter().any(Option::is_none) {
        return 0;
    }
    let value = |v: u32| m.known_direct[v as usize].expect("checked above").0;
    let dark = |r: u32| {
        m.regions[r as usize]
            .relations
            .iter()
            .all(|x| *x == Relation::Umbra)
    };

    // Edges, each with the regions of the triangles on either side (a midpoint on the line
    // between two regions is read with both, as refinement reads it).
    let mut ends: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * m.triangles.len());
    for (t, tri) in m.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            ends.push((a.min(b), a.max(b), m.tri_region[t]));
        }
    }
    ends.sort_unstable();
    ends.dedup();
    let mut edges: Vec<(u32, u32, [u32; 2])> = Vec::with_capacity(ends.len() * 2 / 3 + 1);
    for &(a, b, r) in &ends {
        match edges.last_mut() {
            Some(e) if e.0 == a && e.1 == b => e.2[1] = r,
            _ => edges.push((a, b, [r, r])),
        }
    }
    drop(ends);
    // A midpoint in penumbra costs an exact evaluation under every occluder: only those
    // refinement read are used, and an element with another is left out of the fit (room-8328
    // direct-only: reading them all took its meshing from 9.6 to 23.2 s). Lit midpoints, in
    // closed form, are read where refinement did not.
    let shaded = |r: u32| {
        m.regions[r as usize]
            .relations
            .contains(&Relation::Penumbra)
    };
    let read: Vec<Option<DVec3>> = edges
        .par_iter()
        .map(|&(a, b, [ra, rb])| {
            if dark(ra) && dark(rb) {
                return Some(DVec3::ZERO);
            }
            let p: DVec2 = 0.5 * (m.eval[a as usize] + m.eval[b as usize]);
            cache.get(&key(p)).map(|l| l.0)
        })
        .collect();
    let unread: Vec<usize> = (0..edges.len())
        .filter(|&i| read[i].is_none() && !edges[i].2.iter().any(|&r| shaded(r)))
        .collect();
    let evaluated: Vec<DVec3> = unread
        .par_iter()
        .map(|&i| {
            let (a, b, [ra, rb]) = edges[i];
            let p: DVec2 = 0.5 * (m.eval[a as usize] + m.eval[b as usize]);
            let l = if ra == rb {
                (lights.at)(p, &[&m.regions[ra as usize]])
            } else {
                (lights.at)(p, &[&m.regions[ra as usize], &m.regions[rb as usize]])
            };
            l.0
        })
        .collect();
    let count = evaluated.len() as u64;
    let mut mid = read;
    for (i, l) in unread.into_iter().zip(evaluated) {
        mid[i] = Some(l);
    }
    let edge = |a: u32, b: u32| -> usize {
        let (a, b) = (a.min(b), a.max(b));
        edges
            .binary_search_by(|e| (e.0, e.1).cmp(&(a, b)))
            .expect("every triangle edge is listed")
    };
    // The light at an edge's midpoint minus the interpolant there; none where unread.
    let bulge = |a: u32, b: u32| -> Option<DVec3> {
        let i = edge(a, b);
        if edges[i].2.iter().all(|&r| dark(r)) {
            return Some(DVec3::ZERO);
        }
        Some(mid[i]? - 0.5 * (value(a) + value(b)))
    };

    // r_v = ∫ e φ_v: over a triangle of area A, 4 ∫ λ_i λ_j λ_v is 2A/15 when v is an end of
    // the edge (i, j) and A/15 when it is the opposite corner.
    let mut load = vec![DVec3::ZERO; n];
    let mut lumped = vec![0.0f64; n];
    let mut bulges: Vec<[DVec3; 3]> = Vec::with_capacity(m.triangles.len());
    // An element with a midpoint unread weighs nothing.
    let areas: Vec<f64> = m
        .triangles
        .iter()
        .map(|tri| {
            let b = [0, 1, 2].map(|k| bulge(tri[k], tri[(k + 1) % 3]));
            bulges.push(b.map(|x| x.unwrap_or(DVec3::ZERO)));
            if b.iter().any(Option::is_none) {
                return 0.0;
            }
            let p = tri.map(|v| m.positions[v as usize]);
            0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]).abs()
        })
        .collect();
    for ((tri, &area), b) in m.triangles.iter().zip(&areas).zip(&bulges) {
        for (i, &v) in tri.iter().enumerate() {
            let (own, before, opposite) = (b[i], b[(i + 2) % 3], b[(i + 1) % 3]);
            load[v as usize] += area * ((own + before) * (2.0 / 15.0) + opposite / 15.0);
            lumped[v as usize] += area / 3.0;
        }
    }
    let mut shift: Vec<DVec3> = (0..n)
        .map(|v| {
            if lumped[v] > 0.0 {
                load[v] / lumped[v]
            } else {
                DVec3::ZERO
            }
        })
        .collect();
    for _ in 0..SWEEPS {
        // Consistent mass matrix: A/6 on the diagonal, A/12 off it, per triangle.
        let mut ms = vec![DVec3::ZERO; n];
        for (tri, &area) in m.triangles.iter().zip(&areas) {
            for i in 0..3 {
                let [v, w, u] = [tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]].map(|x| x as usize);
                ms[v] += area / 6.0 * shift[v] + area / 12.0 * (shift[w] + shift[u]);
            }
        }
        for v in 0..n {
            if lumped[v] > 0.0 {
                // The diagonal is half the lumped mass.
                shift[v] += DAMPING * (load[v] - ms[v]) / (0.5 * lumped[v]);
            }
        }
    }

    let brightest = m
        .known_direct
        .iter()
        .flatten()
        .fold(DVec3::ZERO, |b, l| b.max(l.0));
    let floor = brightest * FLOOR;
    for (v, s) in shift.into_iter().enumerate() {
        if corner.get(v).copied().unwrap_or(false) {
            continue;
        }
        let known = m.known_direct[v].as_mut().expect("checked above");
        let most = (known.0.abs() + floor) * (SAFETY * tolerance);
        known.0 = (known.0 + s.clamp(-most, most)).max(DVec3::ZERO);
    }
    count
}

#[cfg(test)]
mod test;

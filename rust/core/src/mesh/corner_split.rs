//! Corners of D0 lines (the foot corner of a box on a floor, the end of a plane cut): there
//! the light depends on the direction one comes from, so one vertex value cannot serve the
//! triangles around the corner (issue 13 measured 5–20× off in some). Every triangle there
//! gets its own copy of the corner vertex, evaluated a hair inside that triangle, so that
//! each carries the limit of the light from its own side, as the D0 rows do along a line.

use glam::DVec2;

use super::sides::nudge;
use super::ReceiverMesh;
use crate::geom::hash::IdMap;
use crate::scene::Tolerances;

/// Gives every triangle at a D0 line end (of `d0_lines`, or where the D0 rows of the split
/// end or turn) its own vertex there (after the D0 row split). Returns which vertices are
/// such corners (empty when there are none).
pub(crate) fn split(m: &mut ReceiverMesh, d0_lines: &[[DVec2; 2]], tol: &Tolerances) -> Vec<bool> {
    if m.d0_corners.is_empty() || m.positions.is_empty() {
        return Vec::new();
    }
    let scale = m
        .positions
        .iter()
        .fold(0.0f64, |a, p| a.max(p.abs().max_element()))
        .max(1e-300);
    // Ends in a hash grid; a vertex within `near` of one is that corner.
    let near = 1e-9 * scale;
    let cell = 1e-6 * scale;
    let at = |p: DVec2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut ends: IdMap<(i64, i64), Vec<DVec2>> = IdMap::default();
    // Only where the split found D0 rows that end or turn: a contact line along the
    // receiver's boundary (walls standing on a floor) parts nothing inside it, and its ends
    // there (the floor's corners) take one value, read at the vertex itself
    // (tests/round_lights.rs: a nudged corner read 2e-8 of the peak off).
    let _ = d0_lines;
    for e in m.d0_corners.iter().copied() {
        ends.entry(at(e)).or_default().push(e);
    }
    let is_corner = |p: DVec2| {
        let (i, j) = at(p);
        (i - 1..=i + 1).any(|x| {
            (j - 1..=j + 1).any(|y| {
                ends.get(&(x, y))
                    .is_some_and(|l| l.iter().any(|e| (*e - p).length() <= near))
            })
        })
    };
    let mut corner: Vec<bool> = m.positions.iter().map(|p| is_corner(*p)).collect();
    if !corner.iter().any(|&c| c) {
        return Vec::new();
    }
    // The first triangle met keeps the vertex; the others get copies.
    let mut taken = vec![false; m.positions.len()];
    for t in 0..m.triangles.len() {
        for k in 0..3 {
            let v = m.triangles[t][k] as usize;
            if !corner[v] {
                continue;
            }
            let id = if !taken[v] {
                taken[v] = true;
                v
            } else {
                m.positions.push(m.positions[v]);
                m.eval.push(m.positions[v]);
                corner.push(true);
                m.positions.len() - 1
            };
            m.triangles[t][k] = id as u32;
            // The evaluation point moves towards the triangle's centroid.
            let p = m.positions[v];
            let tri = m.triangles[t].map(|i| m.positions[i as usize]);
            if let Some(q) = nudge(p, std::iter::once(tri), tol) {
                m.eval[id] = q;
            }
        }
    }
    corner
}

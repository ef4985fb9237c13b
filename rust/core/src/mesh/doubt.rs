//! Which elements refinement checks against the exact light (`refine`). Checking costs an
//! exact evaluation per edge midpoint and centroid, three per element, against one per
//! vertex that the direct stage needs anyway; on a room of 100k triangles that was 4.35M
//! evaluations, three times the bake's own. The vertex values already say where the light
//! is nearly linear: across an edge inside one region the two elements' gradients differ
//! by about the light's second derivative times the distance between their centres, and a
//! linear element errs by about that curvature times its longest edge squared over 8. An
//! element whose estimate stays well under the allowed error is taken as is; the others
//! (and every element with fewer than two neighbours in its region, whose curvature is not
//! seen from two directions) are checked exactly. The estimate only chooses what to check:
//! what is split is still decided by the exact light.

use std::collections::HashMap;
use std::hash::BuildHasherDefault;

use super::refine::KeyHasher;

use glam::{DVec2, DVec3};

/// An element is checked when its estimated error passes this fraction of what it may err:
/// the estimate is a guess from neighbours, so it only screens out the clear cases.
pub const SCREEN: f64 = 0.25;

/// Per triangle, whether its estimated interpolation error may exceed `SCREEN` × its
/// allowed error, `allowed(t)` (per channel); `values` per vertex, `region` per triangle.
pub(crate) fn doubtful(
    positions: &[DVec2],
    triangles: &[[u32; 3]],
    region: &[u32],
    values: &dyn Fn(u32) -> DVec3,
    allowed: &dyn Fn(usize) -> DVec3,
) -> Vec<bool> {
    // Gradient of the linear interpolant, per channel (d/dx, d/dy), and the centroid.
    let grads: Vec<Option<(DVec3, DVec3)>> = triangles
        .iter()
        .map(|tri| {
            let [p0, p1, p2] = tri.map(|v| positions[v as usize]);
            let [f0, f1, f2] = tri.map(values);
            let (e1, e2) = (p1 - p0, p2 - p0);
            let det = e1.perp_dot(e2);
            if !(det.abs() > 0.0) {
                return None;
            }
            let (d1, d2) = (f1 - f0, f2 - f0);
            // Solve [e1; e2] · g = [d1; d2] per channel.
            let gx = (d1 * e2.y - d2 * e1.y) / det;
            let gy = (d2 * e1.x - d1 * e2.x) / det;
            Some((gx, gy))
        })
        .collect();
    let centre: Vec<DVec2> = triangles
        .iter()
        .map(|t| t.iter().map(|&v| positions[v as usize]).sum::<DVec2>() / 3.0)
        .collect();
    let mut by_edge: HashMap<(u32, u32), u32, BuildHasherDefault<KeyHasher>> =
        HashMap::with_capacity_and_hasher(triangles.len() * 2, Default::default());
    let mut neighbour = vec![[u32::MAX; 3]; triangles.len()];
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            // The neighbour runs the edge the other way.
            if let Some(&o) = by_edge.get(&(b, a)) {
                if region[o as usize] == region[t] {
                    neighbour[t][k] = o;
                    let ok = triangles[o as usize]
                        .iter()
                        .position(|&x| x == b)
                        .unwrap_or(0);
                    neighbour[o as usize][ok] = t as u32;
                }
            }
            by_edge.insert((a, b), t as u32);
        }
    }
    (0..triangles.len())
        .map(|t| {
            let Some((gx, gy)) = grads[t] else {
                return true;
            };
            let mut curvature = DVec3::ZERO;
            let mut seen = 0;
            for &o in &neighbour[t] {
                if o == u32::MAX {
                    continue;
                }
                let Some((ox, oy)) = grads[o as usize] else {
                    return true;
                };
                let d = (centre[o as usize] - centre[t]).length();
                if !(d > 0.0) {
                    return true;
                }
                let jump = ((ox - gx) * (ox - gx) + (oy - gy) * (oy - gy)).powf(0.5);
                curvature = curvature.max(jump / d);
                seen += 1;
            }
            if seen < 2 {
                return true;
            }
            let p = triangles[t].map(|v| positions[v as usize]);
            let longest = (p[1] - p[0])
                .length_squared()
                .max((p[2] - p[1]).length_squared())
                .max((p[0] - p[2]).length_squared());
            let estimate = curvature * (longest / 8.0);
            estimate.cmpgt(allowed(t) * SCREEN).any()
        })
        .collect()
}

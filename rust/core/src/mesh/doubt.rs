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

use glam::{DVec2, DVec3};

/// An element is checked when its estimated error passes this fraction of what it may err:
/// the estimate is a guess from neighbours, so it only screens out the clear cases.
pub const SCREEN: f64 = 0.25;

/// Gradient of the linear interpolant of `f` over the triangle `p`, per channel (d/dx,
/// d/dy); `None` for a flat triangle.
pub(crate) fn gradient(p: [DVec2; 3], f: [DVec3; 3]) -> Option<(DVec3, DVec3)> {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let det = e1.perp_dot(e2);
    if !(det.abs() > 0.0) {
        return None;
    }
    let (d1, d2) = (f[1] - f[0], f[2] - f[0]);
    // Solve [e1; e2] · g = [d1; d2] per channel.
    let gx = (d1 * e2.y - d2 * e1.y) / det;
    let gy = (d2 * e1.x - d1 * e2.x) / det;
    Some((gx, gy))
}

/// Outside every penumbra the light is the closed form of whole light polygons, smooth, and
/// the estimate follows it: there an element is checked only when its estimate passes
/// this fraction of what it may err (data1: 64k light evaluations with `SCREEN`, 37k with
/// this, 8 elements fewer of 23.9k). In a penumbra the light kinks along lines between
/// neighbours that the estimate averages away (data2 draft, screened like this: 2.3 × the
/// tolerance).
pub const SCREEN_SMOOTH: f64 = 1.0;

/// Whether the triangle `p` with vertex values `f` may err by more than `screen` × `allowed`
/// (per channel), judged from the gradients of its `neighbours` in its region (their centres
/// and gradients).
pub(crate) fn doubtful(
    p: [DVec2; 3],
    f: [DVec3; 3],
    neighbours: &[(DVec2, Option<(DVec3, DVec3)>)],
    allowed: DVec3,
    screen: f64,
) -> bool {
    let Some((gx, gy)) = gradient(p, f) else {
        return true;
    };
    let centre = (p[0] + p[1] + p[2]) / 3.0;
    let mut curvature = DVec3::ZERO;
    let mut seen = 0;
    for &(c, g) in neighbours {
        let Some((ox, oy)) = g else {
            return true;
        };
        let d = (c - centre).length();
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
    let longest = (p[1] - p[0])
        .length_squared()
        .max((p[2] - p[1]).length_squared())
        .max((p[0] - p[2]).length_squared());
    let estimate = curvature * (longest / 8.0);
    estimate.cmpgt(allowed * screen).any()
}

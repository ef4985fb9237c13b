//! Exact irradiance at a point from a uniform diffuse polygon (Lambert's contour formula).
//!
//! For a polygon of unit radiance seen from `p` with surface normal `n`,
//!
//! ```text
//! E = ½ · | Σ_i θ_i (n · Γ_i) |
//! ```
//!
//! where, for the edge from `a` to `b` (taken relative to `p`), `Γ_i = (a × b)/|a × b|` is the
//! unit normal of the plane through `p` and the edge and `θ_i` the angle the edge subtends at
//! `p`. The sum is a contour integral of the projected solid angle, so it is linear in the
//! winding number of the region: a hole is just another contour running the other way, and
//! any number of contours can be summed before the magnitude is taken.
//!
//! The formula only holds for the part of the polygon above the receiver's horizon, so every
//! contour is first clipped to the half-space `(x − p) · n ≥ 0`. Sutherland–Hodgman clipping
//! of a closed contour against one plane keeps its winding number on the kept side (the
//! connecting segments it adds lie on the plane), so clipping contour by contour is correct
//! for holed and non-convex regions too.
//!
//! # Precision
//! Angles come from `atan2(|a × b|, a · b)` (by `angle`), which is accurate for edges seen
//! under tiny angles (where `acos` of a dot product loses half the digits). Edge vectors are taken from
//! the caller's coordinates before moving the origin to `p`, so a polygon of size `s` at
//! distance `d` keeps its shape to relative `ε`; what remains is the cancellation between
//! opposite edges inherent in the contour sum, a relative error of about `ε · d / s`
//! (≈ 1e-13 for a light 1e-3 of its distance). Callers that want this bound should pass
//! coordinates whose origin is near the polygon, not near `p`.

// `!(x > 0.0)` is meant: NaN must take the "nothing here" branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::f64::consts::PI;

use glam::DVec3;

use super::polygon::clip_polygon_3d;
use super::Plane;

/// Irradiance (W/m² per unit radiance) at `p`, facing unit normal `n`, from the polygon
/// `poly` (any orientation, planar, simple). Only the part in front of `p`
/// (`(x − p) · n > 0`) counts. Multiply by the radiance to get W/m².
///
/// ```
/// use glam::DVec3;
/// use penumbra::geom::lambert::polygon_irradiance;
/// // A huge square far above the point covers nearly the whole hemisphere: E → π.
/// let s = 1e6;
/// let sq = [(-s, -s), (s, -s), (s, s), (-s, s)].map(|(x, y)| DVec3::new(x, y, 1.0));
/// let e = polygon_irradiance(DVec3::ZERO, DVec3::Z, &sq);
/// assert!((e - std::f64::consts::PI).abs() < 1e-5);
/// ```
pub fn polygon_irradiance(p: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    0.5 * horizon_clipped_sum(p, n, poly).abs()
}

/// Irradiance per unit radiance from a region bounded by several closed contours, e.g. a
/// polygon with holes or the result of a polygon boolean. The contours must be oriented
/// consistently: outer boundaries one way around the region's normal, holes the other way
/// (as polygon-boolean libraries output them). Disjoint pieces may be mixed freely as long
/// as they lie in one plane and follow the same rule.
pub fn contours_irradiance(p: DVec3, n: DVec3, contours: &[Vec<DVec3>]) -> f64 {
    let s: f64 = contours.iter().map(|c| horizon_clipped_sum(p, n, c)).sum();
    0.5 * s.abs()
}

/// Irradiance per unit radiance at `p` (normal `n`) from a planar region given by its
/// boundary as directed edges, in any order (the contour sum is additive over edges, so the
/// loops need not be traced): `Some` when the region lies wholly in front of `p`'s plane or
/// wholly behind it (0), `None` when it straddles the plane and must be clipped as closed
/// contours (`contours_irradiance`).
pub fn edges_irradiance(p: DVec3, n: DVec3, edges: &[[DVec3; 2]]) -> Option<f64> {
    // A vertex a rounding error behind the plane (a wall's foot seen from the floor) is on
    // it: the edges it ends contribute nothing there, so the sum needs no clipping.
    let (mut front, mut back) = (false, false);
    for [a, _] in edges {
        let r = *a - p;
        let h = r.dot(n);
        front |= h > 0.0;
        back |= h < -1e-9 * r.length();
    }
    if back {
        return if front {
            straddling_edges_irradiance(p, n, edges)
        } else {
            Some(0.0)
        };
    }
    let s: f64 = edges
        .iter()
        .map(|[a, b]| edge_term(n, *a - p, *b - *a, *b - p))
        .sum();
    Some(0.5 * s.abs())
}

/// `edges_irradiance` of a planar region that straddles `p`'s plane, without tracing its
/// loops. Clipping a loop to the half-space in front of `p` keeps the parts of its edges
/// there and adds segments along the line where the region's plane meets `p`'s, each from
/// where the loop leaves the half-space to where it comes back. Such a segment lies in `p`'s
/// plane, so its term is the angle it turns through about `n`: the difference of the
/// angles of its ends seen from `p`, measured from any one point of that line (a line seen
/// from a point off it spans under π, so the difference never wraps). The added segments'
/// terms thus sum to the angles of the points where edges come back less those where they
/// leave, edge by edge. `None` where `p` lies on that line (the region is seen edge-on
/// from `p`: let the caller clip).
fn straddling_edges_irradiance(p: DVec3, n: DVec3, edges: &[[DVec3; 2]]) -> Option<f64> {
    let mut sum = 0.0;
    let mut from: Option<DVec3> = None;
    let mut turns = 0.0;
    for [a, b] in edges {
        let (ra, rb) = (*a - p, *b - p);
        let (ha, hb) = (ra.dot(n), rb.dot(n));
        let (fa, fb) = (ha > 0.0, hb > 0.0);
        if fa && fb {
            sum += edge_term(n, ra, *b - *a, rb);
            continue;
        }
        if !fa && !fb {
            continue;
        }
        // Where the edge meets the plane, from its front end (kept exact there).
        let (rf, rk, hf, hk) = if fa {
            (ra, rb, ha, hb)
        } else {
            (rb, ra, hb, ha)
        };
        let x = rf + (rk - rf) * (hf / (hf - hk));
        let x = x - n * x.dot(n);
        if fa {
            sum += edge_term(n, ra, x - ra, x);
        } else {
            sum += edge_term(n, x, rb - x, rb);
        }
        let o = *from.get_or_insert(x);
        let c = o.cross(x);
        // Two crossings on opposite sides of p: the line runs through p.
        if !(o.length() > 0.0) || (c.length() <= 1e-12 * o.length() * x.length() && o.dot(x) < 0.0)
        {
            return None;
        }
        let angle = n.dot(c).atan2(o.dot(x));
        turns += if fa { -angle } else { angle };
    }
    Some(0.5 * (sum + turns).abs())
}

/// Signed `Σ θ_i (n · Γ_i)` over the part of a closed contour in front of `p`.
fn horizon_clipped_sum(p: DVec3, n: DVec3, contour: &[DVec3]) -> f64 {
    let k = contour.len();
    if k < 3 {
        return 0.0;
    }
    // No buffers here: the direct stage sums millions of small contours.
    let (mut below, mut above) = (true, true);
    for x in contour {
        let h = (*x - p).dot(n);
        below &= h <= 0.0;
        above &= h >= 0.0;
    }
    if below {
        return 0.0;
    }
    if above {
        // Differences of the caller's coordinates are exact for nearby vertices, which keeps a
        // small far polygon's shape intact (see the module's Precision note).
        return (0..k)
            .map(|i| {
                let j = (i + 1) % k;
                edge_term(n, contour[i] - p, contour[j] - contour[i], contour[j] - p)
            })
            .sum();
    }
    let rel: Vec<DVec3> = contour.iter().map(|x| *x - p).collect();
    let clipped = clip_polygon_3d(&rel, &Plane::new(n, 0.0), 0.0);
    let m = clipped.len();
    (0..m)
        .map(|i| {
            let (a, b) = (clipped[i], clipped[(i + 1) % m]);
            edge_term(n, a, b - a, b)
        })
        .sum()
}

/// `θ (n · Γ)` for the edge `a → b = a + e`, all relative to the receiver point.
#[inline]
fn edge_term(n: DVec3, a: DVec3, e: DVec3, b: DVec3) -> f64 {
    // a × b = a × (b − a): the edge vector keeps the cross product accurate when a and b are
    // nearly parallel, i.e. when the edge is seen under a tiny angle.
    let c = a.cross(e);
    let len = c.length();
    if !(len > 0.0) || !len.is_finite() {
        // The edge is seen end-on (its line passes through p): it subtends no angle, or p lies
        // on it, where the polygon is seen edge-on and contributes nothing either.
        return 0.0;
    }
    let theta = angle(len, a.dot(b));
    theta * n.dot(c) / len
}

/// `atan2(y, x)` for `y ≥ 0`, through `atan`: libm's `atan2` took twice as long, and
/// this is the inner loop of every exact factor, direct and indirect. `y / x` keeps its
/// relative precision, so a tiny angle is as accurate as `atan2` makes it.
#[inline]
pub(crate) fn angle(y: f64, x: f64) -> f64 {
    if x > 0.0 {
        (y / x).atan()
    } else if x < 0.0 {
        PI - (y / -x).atan()
    } else if y > 0.0 {
        0.5 * PI
    } else {
        0.0
    }
}

#[cfg(test)]
pub(crate) mod test {
    use super::*;
    use std::f64::consts::PI;

    /// Corner formula: irradiance per unit radiance at height `h` on the normal through a
    /// corner of a parallel `w × l` rectangle, E = π·F with
    /// F = 1/(2π)[a/√(1+a²)·atan(b/√(1+a²)) + b/√(1+b²)·atan(a/√(1+b²))], a = w/h, b = l/h.
    pub(crate) fn corner(w: f64, l: f64, h: f64) -> f64 {
        let (a, b) = (w / h, l / h);
        let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
        0.5 * (a / sa * (b / sa).atan() + b / sb * (a / sb).atan())
    }

    /// Irradiance per unit radiance at the origin (normal +z) from the rectangle
    /// [x0,x1]×[y0,y1] at height h, by signed corner rectangles (G is odd in x and y).
    pub(crate) fn parallel_rect(x0: f64, x1: f64, y0: f64, y1: f64, h: f64) -> f64 {
        let g = |x: f64, y: f64| x.signum() * y.signum() * corner(x.abs(), y.abs(), h);
        g(x1, y1) - g(x0, y1) - g(x1, y0) + g(x0, y0)
    }

    fn rect_z(x0: f64, x1: f64, y0: f64, y1: f64, z: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(x0, y0, z),
            DVec3::new(x1, y0, z),
            DVec3::new(x1, y1, z),
            DVec3::new(x0, y1, z),
        ]
    }

    fn rel_err(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn corner_of_parallel_rectangle() {
        let e = polygon_irradiance(DVec3::ZERO, DVec3::Z, &rect_z(0.0, 2.0, 0.0, 3.0, 1.5));
        assert!(
            rel_err(e, corner(2.0, 3.0, 1.5)) < 1e-12,
            "{e} vs {}",
            corner(2.0, 3.0, 1.5)
        );
        // The same rectangle wound the other way gives the same value.
        let mut r = rect_z(0.0, 2.0, 0.0, 3.0, 1.5);
        r.reverse();
        assert!(
            rel_err(
                polygon_irradiance(DVec3::ZERO, DVec3::Z, &r),
                corner(2.0, 3.0, 1.5)
            ) < 1e-12
        );
    }

    #[test]
    fn on_axis_and_off_axis_rectangles() {
        let p = DVec3::new(0.3, -0.2, 0.0);
        for (x0, x1, y0, y1, h) in [
            (-1.0, 1.0, -0.5, 0.5, 1.0),
            (0.5, 2.0, 1.0, 1.7, 0.8),
            (-3.0, -0.1, 0.2, 4.0, 2.5),
        ] {
            let poly = rect_z(x0 + p.x, x1 + p.x, y0 + p.y, y1 + p.y, h);
            let e = polygon_irradiance(p, DVec3::Z, &poly);
            let want = parallel_rect(x0, x1, y0, y1, h);
            assert!(rel_err(e, want) < 1e-9, "{e} vs {want}");
        }
    }

    /// Receiver at the origin facing +z; rectangle in the plane x = c, y ∈ [0, b], z ∈ [0, h].
    /// F = 1/(2π)[atan(b/c) − c/√(c²+h²)·atan(b/√(c²+h²))] (plane element to a rectangle in a
    /// perpendicular plane, one edge on the element's plane).
    fn perpendicular(b: f64, c: f64, h: f64) -> f64 {
        let r = (c * c + h * h).sqrt();
        0.5 * ((b / c).atan() - c / r * (b / r).atan())
    }

    fn rect_x(c: f64, y0: f64, y1: f64, z0: f64, z1: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(c, y0, z0),
            DVec3::new(c, y1, z0),
            DVec3::new(c, y1, z1),
            DVec3::new(c, y0, z1),
        ]
    }

    #[test]
    fn perpendicular_rectangle() {
        let e = polygon_irradiance(DVec3::ZERO, DVec3::Z, &rect_x(0.7, 0.0, 1.3, 0.0, 0.9));
        assert!(rel_err(e, perpendicular(1.3, 0.7, 0.9)) < 1e-12);
    }

    #[test]
    fn light_crossing_the_horizon_is_clipped() {
        // Half of the rectangle is below the receiver's plane and must not count (nor cancel).
        let e = polygon_irradiance(DVec3::ZERO, DVec3::Z, &rect_x(0.7, 0.0, 1.3, -2.0, 0.9));
        assert!(rel_err(e, perpendicular(1.3, 0.7, 0.9)) < 1e-12, "{e}");
        // A tilted receiver: the same check in a rotated frame.
        let rot = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
        let poly: Vec<DVec3> = rect_x(0.7, 0.0, 1.3, -2.0, 0.9)
            .iter()
            .map(|v| rot * *v + DVec3::ONE)
            .collect();
        let e = polygon_irradiance(DVec3::ONE, rot * DVec3::Z, &poly);
        assert!(rel_err(e, perpendicular(1.3, 0.7, 0.9)) < 1e-12, "{e}");
        // Entirely below: nothing.
        assert_eq!(
            polygon_irradiance(DVec3::ZERO, DVec3::Z, &rect_x(0.7, 0.0, 1.3, -2.0, 0.0)),
            0.0
        );
    }

    #[test]
    fn hole_contours_subtract() {
        let outer = rect_z(-1.0, 1.0, -1.0, 1.0, 1.0);
        let mut hole = rect_z(-0.2, 0.5, -0.4, 0.1, 1.0);
        hole.reverse();
        let e = contours_irradiance(DVec3::ZERO, DVec3::Z, &[outer, hole]);
        let want =
            parallel_rect(-1.0, 1.0, -1.0, 1.0, 1.0) - parallel_rect(-0.2, 0.5, -0.4, 0.1, 1.0);
        assert!(rel_err(e, want) < 1e-12);
    }

    /// Independent reference: ∫ cos_r cos_l / r² dA over the parallelogram o + sU + tV
    /// (s, t ∈ [0, 1]) by composite 5-point Gauss–Legendre on `cells × cells` cells. Only for
    /// parallelograms wholly in front of the receiver (the integrand is then smooth).
    pub(crate) fn quadrature(
        p: DVec3,
        n: DVec3,
        o: DVec3,
        u: DVec3,
        v: DVec3,
        cells: usize,
    ) -> f64 {
        const X: [f64; 5] = [
            -0.906_179_845_938_664,
            -0.538_469_310_105_683_1,
            0.0,
            0.538_469_310_105_683_1,
            0.906_179_845_938_664,
        ];
        const W: [f64; 5] = [
            0.236_926_885_056_189_1,
            0.478_628_670_499_366_5,
            0.568_888_888_888_888_9,
            0.478_628_670_499_366_5,
            0.236_926_885_056_189_1,
        ];
        let nl = u.cross(v);
        let area = nl.length();
        let nl = nl / area;
        let h = 1.0 / cells as f64;
        let mut sum = 0.0;
        for ci in 0..cells {
            for cj in 0..cells {
                for (xi, wi) in X.iter().zip(W) {
                    for (xj, wj) in X.iter().zip(W) {
                        let s = (ci as f64 + 0.5 + 0.5 * xi) * h;
                        let t = (cj as f64 + 0.5 + 0.5 * xj) * h;
                        let d = o + u * s + v * t - p;
                        let r2 = d.length_squared();
                        sum += wi * wj * n.dot(d) * nl.dot(-d).abs() / (r2 * r2);
                    }
                }
            }
        }
        sum * area * 0.25 * h * h
    }

    #[test]
    fn tilted_parallelogram_against_quadrature() {
        let p = DVec3::new(0.1, 0.2, -0.3);
        let n = DVec3::new(0.2, -0.1, 1.0).normalize();
        let (o, u, v) = (
            DVec3::new(-0.5, 0.3, 1.0),
            DVec3::new(1.2, 0.1, 0.4),
            DVec3::new(-0.3, 0.9, 0.2),
        );
        let poly = [o, o + u, o + u + v, o + v];
        let e = polygon_irradiance(p, n, &poly);
        let want = quadrature(p, n, o, u, v, 24);
        assert!(rel_err(e, want) < 1e-10, "{e} vs {want}");
    }

    #[test]
    fn tiny_far_polygon_keeps_its_digits() {
        // A ~1e-4 square at distance 10, far from the coordinate origin as well; the side is a
        // power of two so the vertices are exact and both sides see the same square.
        let off = DVec3::new(1234.5, -987.25, 0.0);
        let s = (-13f64).exp2();
        let (o, u, v) = (DVec3::new(3.0, 1.0, 10.0) + off, DVec3::X * s, DVec3::Y * s);
        let e = polygon_irradiance(off, DVec3::Z, &[o, o + u, o + u + v, o + v]);
        let want = quadrature(off, DVec3::Z, o, u, v, 1);
        assert!(
            rel_err(e, want) < 1e-9,
            "{e} vs {want}: {}",
            rel_err(e, want)
        );
    }

    #[test]
    fn whole_hemisphere_is_pi() {
        let s = 1e8;
        let e = polygon_irradiance(DVec3::ZERO, DVec3::Z, &rect_z(-s, s, -s, s, 1.0));
        assert!((e - PI).abs() < 1e-6);
    }

    #[test]
    fn straddling_region_as_edges_matches_its_clipped_loops() {
        // Regions across the receiver's plane, given as unordered edges of several loops (a
        // square with a square hole, and a separate triangle), against clipping each loop.
        use crate::geom::hash::{mix, unit};
        let mut seed = 7u64;
        let mut r = || {
            seed = mix(seed);
            unit(seed) * 2.0 - 1.0
        };
        let mut straddling = 0;
        for _ in 0..200 {
            let p = DVec3::new(r(), r(), r()) * 0.3;
            let n = DVec3::new(r(), r(), 1.0).normalize();
            let o = DVec3::new(r(), r(), r()) * 0.5;
            let u = DVec3::new(1.0, r() * 0.3, r()).normalize();
            let w = DVec3::new(r() * 0.3, r(), 1.0).cross(u).normalize();
            let at = |x: f64, y: f64| o + u * x + w * y;
            let outer = vec![at(-1.0, -1.0), at(1.0, -1.0), at(1.0, 1.0), at(-1.0, 1.0)];
            let hole = vec![at(-0.4, -0.3), at(-0.4, 0.5), at(0.2, 0.5), at(0.2, -0.3)];
            let tri = vec![at(1.5, 0.0), at(2.5, 0.2), at(1.8, 1.4)];
            let loops = [outer, hole, tri];
            let mut edges: Vec<[DVec3; 2]> = loops
                .iter()
                .flat_map(|l| (0..l.len()).map(move |i| [l[i], l[(i + 1) % l.len()]]))
                .collect();
            edges.reverse();
            let want = contours_irradiance(p, n, &loops);
            let got = edges_irradiance(p, n, &edges).unwrap();
            assert!(
                (got - want).abs() <= 1e-12 + 1e-10 * want,
                "{got} vs {want}"
            );
            let h: Vec<f64> = edges.iter().map(|e| (e[0] - p).dot(n)).collect();
            straddling += (h.iter().any(|&x| x > 0.0) && h.iter().any(|&x| x < 0.0)) as u32;
        }
        assert!(straddling > 100, "{straddling}");
        // A wall standing across a floor point's horizon, the case the final gather meets:
        // half of it below the plane.
        let wall = rect_x(1.0, -1.0, 1.0, -1.0, 1.0);
        let edges: Vec<[DVec3; 2]> = (0..4).map(|i| [wall[i], wall[(i + 1) % 4]]).collect();
        let got = edges_irradiance(DVec3::ZERO, DVec3::Z, &edges).unwrap();
        assert!(rel_err(got, 2.0 * perpendicular(1.0, 1.0, 1.0)) < 1e-12);
        // The point on the wall's plane, inside it: seen edge-on, the wall gives nothing,
        // and the crossings on either side of the point must not add half a turn.
        let p = DVec3::new(1.0, 0.0, 0.0);
        assert!(edges_irradiance(p, DVec3::Z, &edges).is_none_or(|e| e.abs() < 1e-12));
    }

    #[test]
    fn degenerate_input_is_zero_not_nan() {
        assert_eq!(
            polygon_irradiance(DVec3::ZERO, DVec3::Z, &[DVec3::X, DVec3::Y]),
            0.0
        );
        // p on the polygon's plane and inside it: seen edge-on.
        let e = polygon_irradiance(DVec3::ZERO, DVec3::X, &rect_z(-1.0, 1.0, -1.0, 1.0, 0.0));
        assert!(e.is_finite() && e.abs() < 1e-12);
    }
}

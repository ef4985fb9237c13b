//! Exact unoccluded form factor between two planar convex polygons, for near links: faces
//! that share an edge or a vertex, lie a few millimetres apart, or are tilted and close,
//! where a point-to-polygon factor at a centroid is far off.
//!
//! ```text
//! F(r ← s) = 1/A_r ∫_r ∫_s cosθ_r cosθ_s / (π d²) dA_s dA_r
//!          = 1/(2π A_r) Σ_i Σ_j (e_i · e_j) ∫_{e_i} ∫_{e_j} ln |x − y| dt ds
//! ```
//!
//! The second line is Stokes' theorem applied twice (Goral et al. 1984; Schröder & Hanrahan
//! 1993), `e_i` running over the edges of `r` and `e_j` over those of `s` as unit vectors,
//! each polygon counter-clockwise around its front. It holds only where each polygon lies in
//! front of the other, so `s` is first clipped to the front of `r`'s plane and `r` to the
//! front of `s`'s (the planes are fixed, so the clips are exact, not an approximation of
//! the cosines). Perpendicular edges contribute nothing.
//!
//! Each edge pair is integrated as follows.
//! - The inner integral over `e_j` is in closed form for any point `x`:
//!   `½ x_b ln r_b² − ½ x_a ln r_a² − L_j + h θ` (`x_a`, `x_b` the ends' offsets along
//!   the edge from the foot of `x`, `r` the distances to the ends, `h` the distance to the
//!   edge's line, `θ` the angle the edge subtends).
//! - Parallel edges near each other (in particular the collinear edges of two faces meeting
//!   along an edge, where the kernel is singular along the whole edge) have a closed form
//!   for the double integral too, and so do edges in one plane whose lines meet nearby
//!   (every pair of edges sharing a vertex, and the edges that a clip leaves in the other
//!   polygon's plane): `½ ln Q` with `Q = s² + t² − 2st cos φ` has the elementary primitive
//!   of [`coplanar_primitive`], where Schröder and Hanrahan's skew case needs dilogarithms.
//! - Otherwise (skew edges) the outer integral is Gauss–Legendre on panels graded toward the points where
//!   the integrand stops being analytic. These are known exactly: where the outer edge's
//!   line passes closest to an end of the inner edge, and where it passes closest to the
//!   inner edge's line (only if that is on the inner edge). Each panel is split until the
//!   nearest such point, taken as a complex singularity, is outside a Bernstein ellipse of
//!   ratio [`RHO_MIN`], and gets as many points as that ellipse needs for 1e-14 of the
//!   integral. A singularity on the edge itself (possible only if the lines meet, which
//!   the coplanar case takes unless they meet far out) is graded down to 1e-7 of the edge.
//!
//! # Precision
//! The logarithm makes each pair's integral depend on the unit of length; only the sum
//! over closed contours does not. Two things keep that sum from cancelling away digits:
//! coordinates are taken relative to the pair's centre in units of its size, and the outer
//! integrand is `I_j(x) − I_j(c)` with `c` the centroid of the smaller polygon (the outer
//! one): the subtracted term sums to zero around a closed contour, and what is left is of
//! the size of the result even when one polygon is 10⁴ times smaller than the other. The
//! closed forms difference corner values, so they are used only where those are of the
//! size of the pair (parallel edges within 4 lengths, the longer cut to a window around the
//! shorter; coplanar lines meeting within 2 lengths).
//!
//! Against closed forms and brute-force references the factor is good to 1e-12 or better;
//! what is left on grazing pairs is rounding in the contour sum, about 1e-15 of the areas
//! (see the tests).

// `!(x > 0.0)` is meant: NaN must take the "nothing here" branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::f64::consts::PI;
use std::sync::OnceLock;

use glam::DVec3;

use super::lambert::angle;
use super::plane::newell_normal;
use super::polygon::clip_polygon_3d_into;
use super::Plane;

/// A vertex this close to the other polygon's plane (in units of the pair's size) lies on
/// it: a polygon touching a plane is not clipped into slivers, and a polygon with nothing
/// farther in front sees nothing (coplanar pairs are 0).
const PLANE_EPS: f64 = 1e-12;
/// Edges shorter than this (in units of the pair's size) are rounding leftovers of a clip.
const TINY_EDGE: f64 = 1e-13;
/// Edges whose directions differ by less than this sine are treated as parallel.
const PARALLEL: f64 = 1e-9;
/// Edges whose lines pass closer than this (in units of the pair's size) are coplanar: the
/// closed form that ignores the distance is off by about its square.
const COPLANAR: f64 = 1e-9;
/// Coplanar edges use the closed form when their lines meet within this many times the
/// longer length (farther out, its corner values cancel away digits).
const FAR_CORNER: f64 = 2.0;
/// Parallel edges nearer than this many times the shorter length use the closed form.
const NEAR: f64 = 4.0;
/// The longer of two near parallel edges is cut to a window this many times the shorter one
/// on each side, the rest integrated numerically: the closed form differences values of the
/// size of the longer edge's square, and loses the ratio squared in digits.
const WINDOW: f64 = 2.0;
/// Smallest Bernstein ellipse ratio a panel may have with respect to a singularity.
const RHO_MIN: f64 = 3.5;
/// Relative accuracy asked of each panel, as a share of the whole edge's integral.
const EPS_QUAD: f64 = 1e-14;
/// Panels are not graded below this fraction of the edge.
const MIN_PANEL: f64 = 1e-7;
const MAX_POINTS: usize = 24;
/// Points on a panel that reached [`MIN_PANEL`] with a singularity still close.
const SMALL_PANEL_POINTS: usize = 6;

/// `F(r ← s)`: the fraction of the light leaving the front of `s` (uniform, diffuse) that
/// arrives on the front of `r`, averaged over `r`; equivalently the mean over `r` of the
/// point factor from `s`. No occlusion. Both polygons convex and planar, counter-clockwise
/// around their fronts. A polygon with no area, fewer than three vertices or non-finite
/// coordinates gives 0, as do coplanar polygons and polygons wholly behind one another.
///
/// ```
/// use glam::DVec3;
/// use penumbra::geom::polygon_factor::polygon_factor;
/// // Two unit squares at right angles sharing an edge: F = 0.200044 (Howell C-14).
/// let floor = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)].map(|(x, y)| DVec3::new(x, y, 0.0));
/// let wall = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)].map(|(y, z)| DVec3::new(0.0, y, z));
/// let f = polygon_factor(&floor, &wall);
/// assert!((f - 0.200_043_776_075).abs() < 1e-12, "{f}");
/// ```
pub fn polygon_factor(r: &[DVec3], s: &[DVec3]) -> f64 {
    if r.len() < 3 {
        return 0.0;
    }
    let area = 0.5 * newell_normal(r).length();
    if !(area > 0.0) || !area.is_finite() {
        return 0.0;
    }
    polygon_coupling(r, s) / area
}

/// `A_r F(r ← s) = A_s F(s ← r)`: the symmetric transfer between the fronts of two convex
/// planar polygons (counter-clockwise around their fronts), `∫∫ cosθ_r cosθ_s / (π d²)`.
/// One call serves both directions of a link. 0 for degenerate input (see
/// [`polygon_factor`]).
pub fn polygon_coupling(r: &[DVec3], s: &[DVec3]) -> f64 {
    if r.len() < 3 || s.len() < 3 {
        return 0.0;
    }
    let o = (r.iter().sum::<DVec3>() + s.iter().sum::<DVec3>()) / (r.len() + s.len()) as f64;
    let size = r
        .iter()
        .chain(s)
        .map(|v| (*v - o).length())
        .fold(0.0, f64::max);
    if !(size > 0.0) || !size.is_finite() {
        return 0.0;
    }
    let inv = 1.0 / size;
    let local = |p: &[DVec3]| -> Vec<DVec3> { p.iter().map(|v| (*v - o) * inv).collect() };
    let (r, s) = (local(r), local(s));
    let (nr, ns) = (newell_normal(&r), newell_normal(&s));
    if !(nr.length() > 0.0) || !(ns.length() > 0.0) {
        return 0.0;
    }
    let pr = Plane::from_point_normal(centroid(&r), nr);
    let ps = Plane::from_point_normal(centroid(&s), ns);
    // Nothing of one in front of the other (coplanar pairs included): no light passes.
    if s.iter().all(|v| pr.dist(*v) <= PLANE_EPS) || r.iter().all(|v| ps.dist(*v) <= PLANE_EPS) {
        return 0.0;
    }
    let mut rc = Vec::with_capacity(r.len() + 2);
    let mut sc = Vec::with_capacity(s.len() + 2);
    clip_polygon_3d_into(&r, &ps, PLANE_EPS, &mut rc);
    clip_polygon_3d_into(&s, &pr, PLANE_EPS, &mut sc);
    if rc.len() < 3 || sc.len() < 3 {
        return 0.0;
    }
    let sum = contour_sum(&rc, &sc);
    (sum / (2.0 * PI)).max(0.0) * size * size
}

fn centroid(p: &[DVec3]) -> DVec3 {
    p.iter().sum::<DVec3>() / p.len() as f64
}

/// `Σ_i Σ_j (e_i · e_j) ∫∫ ln |x − y|` over the edges of two closed contours.
fn contour_sum(a: &[DVec3], b: &[DVec3]) -> f64 {
    let loop_edges = |p: &[DVec3]| -> Vec<[DVec3; 2]> {
        (0..p.len()).map(|i| [p[i], p[(i + 1) % p.len()]]).collect()
    };
    edges_sum(&loop_edges(a), &loop_edges(b))
}

/// [`contour_sum`] for two regions given as directed boundary edges in any order (the sum
/// is additive over edges, so loops need not be traced, and a region may have holes).
fn edges_sum(a: &[[DVec3; 2]], b: &[[DVec3; 2]]) -> f64 {
    let mid = |p: &[[DVec3; 2]]| {
        let m: DVec3 = p.iter().map(|[u, v]| (*u + *v) * 0.5).sum();
        m / p.len().max(1) as f64
    };
    let extent = |p: &[[DVec3; 2]]| {
        let c = mid(p);
        p.iter()
            .map(|[v, _]| (*v - c).length_squared())
            .fold(0.0, f64::max)
    };
    // The smaller region is the outer variable, so that subtracting the inner integral at
    // its centre leaves an integrand of the size of the result (see the module's note).
    let (outer, inner) = if extent(a) <= extent(b) {
        (a, b)
    } else {
        (b, a)
    };
    let c = mid(outer);
    let mut sum = 0.0;
    for &[p0, p1] in outer {
        let ep = p1 - p0;
        let lp = ep.length();
        if !(lp > TINY_EDGE) {
            continue;
        }
        for &[q0, q1] in inner {
            let eq = q1 - q0;
            let lq = eq.length();
            if !(lq > TINY_EDGE) {
                continue;
            }
            let cos = ep.dot(eq) / (lp * lq);
            if cos.abs() < 1e-15 {
                continue;
            }
            sum += cos * edge_pair(Seg::new(p0, p1), Seg::new(q0, q1), c);
        }
    }
    sum
}

/// `A_r F(r ← s)` for two planar regions given as directed boundary edges (counter-clockwise
/// around their fronts, any order), each wholly in front of the other's plane or on it: the
/// caller clips them first where they are not (`edge_soup::clip_front`). For the groups of
/// element triangles of hierarchical radiosity's leaves.
pub fn edges_coupling(r: &[[DVec3; 2]], s: &[[DVec3; 2]]) -> f64 {
    let n = 2 * (r.len() + s.len());
    if r.len() < 3 || s.len() < 3 {
        return 0.0;
    }
    let o = r.iter().chain(s).map(|[a, b]| *a + *b).sum::<DVec3>() / n as f64;
    let size = r
        .iter()
        .chain(s)
        .map(|[a, _]| (*a - o).length())
        .fold(0.0, f64::max);
    if !(size > 0.0) || !size.is_finite() {
        return 0.0;
    }
    let inv = 1.0 / size;
    let local = |p: &[[DVec3; 2]]| -> Vec<[DVec3; 2]> {
        p.iter().map(|e| e.map(|v| (v - o) * inv)).collect()
    };
    let sum = edges_sum(&local(r), &local(s));
    (sum / (2.0 * PI)).max(0.0) * size * size
}

/// A segment with its length and unit direction.
#[derive(Clone, Copy, Debug)]
struct Seg {
    a: DVec3,
    b: DVec3,
    len: f64,
    dir: DVec3,
}

impl Seg {
    fn new(a: DVec3, b: DVec3) -> Self {
        let len = (b - a).length();
        Seg {
            a,
            b,
            len,
            dir: (b - a) / len,
        }
    }

    /// The part between parameters `t0` and `t1` (distances from `a`).
    fn part(&self, t0: f64, t1: f64) -> Self {
        Seg {
            a: self.a + self.dir * t0,
            b: self.a + self.dir * t1,
            len: t1 - t0,
            dir: self.dir,
        }
    }
}

/// `∫_p ∫_q ln |x − y| dt ds − L_p I_q(c)`, where `I_q(x) = ∫_q ln |x − y| dt`.
fn edge_pair(p: Seg, q: Seg, c: DVec3) -> f64 {
    let n = p.dir.cross(q.dir);
    let sin = n.length();
    if sin > PARALLEL {
        let w0 = q.a - p.a;
        if w0.dot(n).abs() <= COPLANAR * sin {
            // The lines meet at O; s and t are distances from O along p and q.
            let sin2 = sin * sin;
            let so = w0.cross(q.dir).dot(n) / sin2;
            let to = w0.cross(p.dir).dot(n) / sin2;
            let (s1, s2, t1, t2) = (-so, p.len - so, -to, q.len - to);
            let far = s1.abs().max(s2.abs()).max(t1.abs()).max(t2.abs());
            if far <= FAR_CORNER * p.len.max(q.len) {
                let cos = p.dir.dot(q.dir);
                let f = |s, t| coplanar_primitive(s, t, cos, sin);
                let j = f(s2, t2) - f(s1, t2) - f(s2, t1) + f(s1, t1);
                return j - p.len * inner(c, q);
            }
        }
    } else {
        // q's ends along p's line, and q's distance from that line.
        let (t0, t1) = ((q.a - p.a).dot(p.dir), (q.b - p.a).dot(p.dir));
        let (lo, hi) = (t0.min(t1), t0.max(t1));
        let gap = (lo - p.len).max(-hi).max(0.0);
        let h = ((q.a + q.b) * 0.5 - p.a).cross(p.dir).length();
        let short = p.len.min(q.len);
        if gap.hypot(h) <= NEAR * short {
            return parallel_pair(p, q, lo, h, c);
        }
    }
    quadrature_pair(p, q, c)
}

/// [`edge_pair`] for parallel edges near each other; `lo` is where q's end with the smaller
/// projection lies along p, `h` the distance between the lines.
fn parallel_pair(p: Seg, q: Seg, lo: f64, h: f64, c: DVec3) -> f64 {
    let w = WINDOW * p.len.min(q.len);
    if q.len > (1.0 + 2.0 * WINDOW) * p.len {
        // Cut q to the window around p; the rest is at least `w` away along the line.
        // q's parameter runs from q.a; `lo` is q.a's or q.b's projection.
        let forward = p.dir.dot(q.dir) > 0.0;
        let to_q = |s: f64| if forward { s - lo } else { q.len - (s - lo) };
        let (u0, u1) = (to_q(-w), to_q(p.len + w));
        let (u0, u1) = (u0.min(u1).max(0.0), u0.max(u1).min(q.len));
        if u1 <= u0 {
            // q lies wholly beyond the window: at least w away, nothing near to resolve.
            return quadrature_pair(p, q, c);
        }
        let mut sum = 0.0;
        if u0 > 0.0 {
            sum += quadrature_pair(p, q.part(0.0, u0), c);
        }
        if u1 < q.len {
            sum += quadrature_pair(p, q.part(u1, q.len), c);
        }
        let window = q.part(u0, u1);
        let wlo = (window.a - p.a).dot(p.dir).min((window.b - p.a).dot(p.dir));
        return sum + parallel_closed(p, window, wlo, h, c);
    }
    if p.len > (1.0 + 2.0 * WINDOW) * q.len {
        let (s0, s1) = ((lo - w).max(0.0), (lo + q.len + w).min(p.len));
        if s1 <= s0 {
            return quadrature_pair(p, q, c);
        }
        let mut sum = 0.0;
        if s0 > 0.0 {
            sum += quadrature_pair(p.part(0.0, s0), q, c);
        }
        if s1 < p.len {
            sum += quadrature_pair(p.part(s1, p.len), q, c);
        }
        return sum + parallel_closed(p.part(s0, s1), q, lo - s0, h, c);
    }
    parallel_closed(p, q, lo, h, c)
}

/// The closed form for parallel edges: with q running along p from `lo`,
/// `∫_0^{L_p} ∫_0^{L_q} ½ ln((s − t − lo)² + h²) dt ds` is a second difference of [`p2`].
fn parallel_closed(p: Seg, q: Seg, lo: f64, h: f64, c: DVec3) -> f64 {
    let cc = -lo;
    let j = p2(p.len + cc, h) - p2(cc, h) - p2(p.len + cc - q.len, h) + p2(cc - q.len, h);
    j - p.len * inner(c, q)
}

/// For lines meeting at an angle with cosine `c` and sine `k`, a function whose mixed
/// derivative in `s` and `t` is `½ ln Q`, `Q = s² + t² − 2cst` the squared distance between
/// the points at distances s and t from the meeting point (up to terms in s or t alone,
/// which the four corners cancel).
fn coplanar_primitive(s: f64, t: f64, c: f64, k: f64) -> f64 {
    let q = (s - c * t) * (s - c * t) + k * k * t * t;
    let lq = if q > 0.0 { q.ln() } else { 0.0 };
    // s² atan(…/s) → 0 as s → 0 from either side.
    let a = if s != 0.0 {
        s * s * ((t - c * s) / (k * s)).atan()
    } else {
        0.0
    };
    let b = if t != 0.0 {
        t * t * ((s - c * t) / (k * t)).atan()
    } else {
        0.0
    };
    lq * (0.5 * k * k * s * t - 0.25 * c * q) - 1.5 * s * t + 0.5 * k * (a + b)
}

/// Second primitive of `½ ln(x² + h²)` in `x`.
fn p2(x: f64, h: f64) -> f64 {
    let r2 = x * x + h * h;
    let lg = if r2 > 0.0 { r2.ln() } else { 0.0 };
    let at = if h > 0.0 { h * x * (x / h).atan() } else { 0.0 };
    0.25 * (x * x - h * h) * lg - 0.75 * x * x + at
}

/// `I_q(x) = ∫_q ln |x − y| dt` in closed form.
#[inline]
fn inner(x: DVec3, q: Seg) -> f64 {
    let (wa, wb) = (x - q.a, x - q.b);
    let (ra2, rb2) = (wa.length_squared(), wb.length_squared());
    let xlog = |x: f64, r2: f64| if r2 > 0.0 { x * r2.ln() } else { 0.0 };
    // |wa × eq| = h L_q; the edge vector keeps it accurate for an edge seen end-on.
    let hl = wa.cross(q.b - q.a).length();
    let theta = angle(hl, wa.dot(wb));
    0.5 * (xlog(-wb.dot(q.dir), rb2) - xlog(-wa.dot(q.dir), ra2)) - q.len + hl / q.len * theta
}

/// [`edge_pair`] by graded Gauss–Legendre over p of the closed-form inner integral.
fn quadrature_pair(p: Seg, q: Seg, c: DVec3) -> f64 {
    // Singularities of s ↦ I_q(p(s)) as (real part, imaginary part): the ends of q...
    let mut sing = [(0.0, 0.0); 3];
    for (k, e) in [q.a, q.b].into_iter().enumerate() {
        let d = e - p.a;
        sing[k] = (d.dot(p.dir), d.cross(p.dir).length());
    }
    // ...and the branch point of the distance to q's line, where p's line passes closest
    // to it; it cancels unless that closest point lies on q.
    let mut k = 2;
    let n = p.dir.cross(q.dir);
    let sin2 = n.length_squared();
    if sin2 > PARALLEL * PARALLEL {
        let w0 = p.a - q.a;
        let (b, d, e) = (p.dir.dot(q.dir), p.dir.dot(w0), q.dir.dot(w0));
        let (s0, t0) = ((b * e - d) / sin2, (e - b * d) / sin2);
        if t0 > -0.1 * q.len && t0 < 1.1 * q.len {
            let gap = w0.dot(n).abs() / sin2.sqrt();
            sing[2] = (s0, gap / sin2.sqrt());
            k = 3;
        }
    }
    let ic = inner(c, q);
    integrate(|s| inner(p.a + p.dir * s, q) - ic, p.len, &sing[..k])
}

/// `∫_0^len f` by Gauss–Legendre panels graded toward the complex singularities `sing`.
fn integrate(f: impl Fn(f64) -> f64, len: f64, sing: &[(f64, f64)]) -> f64 {
    let rules = rules();
    let mut stack = [(0.0f64, 0.0f64); 96];
    stack[0] = (0.0, len);
    let mut top = 1;
    let mut sum = 0.0;
    while top > 0 {
        top -= 1;
        let (x0, x1) = stack[top];
        let (m, hl) = (0.5 * (x0 + x1), 0.5 * (x1 - x0));
        if !(hl > 0.0) {
            continue;
        }
        let (mut rho, mut at) = (f64::INFINITY, m);
        for &(c, w) in sing {
            let r = bernstein_rho((c - m) / hl, w / hl);
            if r < rho {
                (rho, at) = (r, c);
            }
        }
        let small = x1 - x0 <= MIN_PANEL * len || top + 2 > stack.len();
        if rho < RHO_MIN && !small {
            let c = at.clamp(x0, x1);
            let cut = if c > x0 && c < x1 {
                c
            } else if c == x0 {
                x0 + (x1 - x0) / 3.0
            } else {
                x1 - (x1 - x0) / 3.0
            };
            stack[top] = (x0, cut);
            stack[top + 1] = (cut, x1);
            top += 2;
            continue;
        }
        let n = if rho < RHO_MIN {
            SMALL_PANEL_POINTS
        } else {
            // The error goes as ρ^(−2n); this panel's share of the tolerance grows as it
            // shrinks.
            let want = (EPS_QUAD * len / (x1 - x0)).min(0.1);
            ((-want.ln()) / (2.0 * rho.ln())).ceil() as usize
        };
        let rule = &rules[n.clamp(2, MAX_POINTS)];
        sum += hl * rule.iter().map(|&(x, w)| w * f(m + hl * x)).sum::<f64>();
    }
    sum
}

/// Ratio (semi-axes' sum) of the Bernstein ellipse with foci ±1 through `x + iy`.
#[inline]
fn bernstein_rho(x: f64, y: f64) -> f64 {
    let y2 = y * y;
    let a = 0.5 * (((x - 1.0) * (x - 1.0) + y2).sqrt() + ((x + 1.0) * (x + 1.0) + y2).sqrt());
    a + (a * a - 1.0).max(0.0).sqrt()
}

/// Gauss–Legendre rules on [−1, 1], indexed by the number of points.
fn rules() -> &'static [Vec<(f64, f64)>] {
    static RULES: OnceLock<Vec<Vec<(f64, f64)>>> = OnceLock::new();
    RULES.get_or_init(|| (0..=MAX_POINTS).map(gauss_legendre).collect())
}

/// Nodes and weights of the `n`-point Gauss–Legendre rule, by Newton's method on the
/// Legendre polynomial from the usual cosine guesses.
pub(crate) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let k = k as f64;
            (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
        }
        // P_n(x) and P_n'(x).
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::geom::lambert::polygon_irradiance;
    use crate::geom::polygon::clip_polygon_3d;
    use glam::{DQuat, DVec3 as V};

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// The parallelogram o, o + u, o + u + v, o + v (front along u × v).
    fn rect(o: V, u: V, v: V) -> Vec<V> {
        vec![o, o + u, o + u + v, o + v]
    }

    fn edges_of(loops: &[Vec<V>]) -> Vec<[V; 2]> {
        loops
            .iter()
            .flat_map(|p| (0..p.len()).map(move |i| [p[i], p[(i + 1) % p.len()]]))
            .collect()
    }

    #[test]
    fn edge_soups_match_their_convex_pieces() {
        // An L-shaped floor (two rectangles, their shared edge given both ways as two
        // triangulated leaves would give it) against a wall meeting it along an edge, and
        // against a plate 5 mm above: the sum of the pieces' couplings.
        let (x, y, z) = (V::X, V::Y, V::Z);
        let a = rect(V::ZERO, x, y * 0.5);
        let b = rect(y * 0.5, x * 0.5, y * 0.5);
        let wall = rect(V::ZERO, z, x);
        let plate = rect(z * 0.005 + x * 0.2, y * 0.6, x * 0.1);
        for other in [&wall, &plate] {
            let want = polygon_coupling(&a, other) + polygon_coupling(&b, other);
            let got = edges_coupling(
                &edges_of(&[a.clone(), b.clone()]),
                &edges_of(&[other.clone()]),
            );
            assert!(rel(got, want) < 1e-10, "{got} {want}");
            let back = edges_coupling(
                &edges_of(&[other.clone()]),
                &edges_of(&[b.clone(), a.clone()]),
            );
            assert!(rel(back, want) < 1e-10, "{back} {want}");
        }
        assert_eq!(edges_coupling(&[], &edges_of(&[wall])), 0.0);
    }

    /// Howell C-11: directly opposed parallel a × b rectangles at distance c.
    fn opposed_rectangles(a: f64, b: f64, c: f64) -> f64 {
        let (x, y) = (a / c, b / c);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        2.0 / (PI * x * y)
            * (0.5 * ((1.0 + x * x) * (1.0 + y * y) / (1.0 + x * x + y * y)).ln()
                + x * sy * (x / sy).atan()
                + y * sx * (y / sx).atan()
                - x * x.atan()
                - y * y.atan())
    }

    /// Howell C-14: from a w × l rectangle to an h × l rectangle at right angles to it,
    /// sharing the edge of length l.
    fn common_edge(w: f64, h: f64, l: f64) -> f64 {
        let (w, h) = (w / l, h / l);
        let (w2, h2) = (w * w, h * h);
        let s = (w2 + h2).sqrt();
        let lg = ((1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2)).ln()
            + w2 * (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).ln()
            + h2 * (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).ln();
        (w * (1.0 / w).atan() + h * (1.0 / h).atan() - s * (1.0 / s).atan() + 0.25 * lg) / (PI * w)
    }

    fn area(p: &[V]) -> f64 {
        0.5 * newell_normal(p).length()
    }

    /// Point factor from the front of `s` at `x` facing `n`: 0 behind `s`.
    fn point_factor(x: V, n: V, s: &[V]) -> f64 {
        if (x - centroid(s)).dot(newell_normal(s)) <= 0.0 {
            return 0.0;
        }
        polygon_irradiance(x, n, s) / PI
    }

    /// ∫ g over the convex polygon `r`: each fan triangle from r[0] by the Duffy map
    /// x = r0 + u (e1 + w e2), u graded geometrically toward r[0] when `graded` (for an
    /// integrand singular there), else `cells` uniform panels; `cells` panels in w.
    fn integrate_polygon(r: &[V], g: impl Fn(V) -> f64, graded: bool, cells: usize) -> f64 {
        let rule = gauss_legendre(16);
        let panels: Vec<(f64, f64)> = if graded {
            let sigma: f64 = 0.3;
            (0..45)
                .map(|k| (sigma.powi(k + 1), sigma.powi(k)))
                .collect()
        } else {
            (0..cells)
                .map(|k| (k as f64 / cells as f64, (k + 1) as f64 / cells as f64))
                .collect()
        };
        let mut sum = 0.0;
        for k in 1..r.len() - 1 {
            let (e1, e2) = (r[k] - r[0], r[k + 1] - r[k]);
            let jac = e1.cross(e2).length();
            for &(u0, u1) in &panels {
                for &(xu, wu) in &rule {
                    let u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * xu;
                    for c in 0..cells {
                        let (w0, w1) = (c as f64 / cells as f64, (c + 1) as f64 / cells as f64);
                        for &(xw, ww) in &rule {
                            let w = 0.5 * (w0 + w1) + 0.5 * (w1 - w0) * xw;
                            let x = r[0] + (e1 + e2 * w) * u;
                            sum += 0.25 * (u1 - u0) * (w1 - w0) * wu * ww * u * jac * g(x);
                        }
                    }
                }
            }
        }
        sum
    }

    /// F(r ← s) by brute force: the exact point factor integrated over the part of `r`
    /// in front of `s`.
    fn brute(r: &[V], s: &[V], graded: bool, cells: usize) -> f64 {
        let n = newell_normal(r).normalize();
        let ps = Plane::from_point_normal(centroid(s), newell_normal(s));
        let rc = clip_polygon_3d(r, &ps, 0.0);
        if rc.len() < 3 {
            return 0.0;
        }
        integrate_polygon(&rc, |x| point_factor(x, n, s), graded, cells) / area(r)
    }

    /// A rigid motion far from the origin, so that no test relies on axis-aligned input.
    fn moved(p: &[V]) -> Vec<V> {
        let q = DQuat::from_axis_angle(V::new(0.3, -1.0, 0.7).normalize(), 1.1);
        p.iter()
            .map(|v| q * *v + V::new(12.5, -3.25, 7.0))
            .collect()
    }

    #[test]
    fn opposed_parallel_rectangles_match_howell() {
        for (a, b, c) in [
            (1.0, 1.0, 1.0),
            (2.0, 0.5, 0.7),
            (0.3, 3.0, 2.0),
            (1.0, 1.0, 0.005),
        ] {
            let r = rect(V::ZERO, V::X * a, V::Y * b);
            let s = rect(V::Z * c, V::Y * b, V::X * a);
            let want = opposed_rectangles(a, b, c);
            for (r, s) in [(r.clone(), s.clone()), (moved(&r), moved(&s))] {
                let f = polygon_factor(&r, &s);
                assert!(rel(f, want) < 1e-10, "{a}x{b} at {c}: {f} vs {want}");
                // The same pair seen from s (same size: the same value).
                assert!(rel(polygon_factor(&s, &r), want) < 1e-10);
            }
        }
    }

    #[test]
    fn perpendicular_rectangles_sharing_an_edge_match_howell() {
        for (w, h, l) in [
            (1.0, 1.0, 1.0),
            (0.4, 2.5, 1.3),
            (3.0, 0.2, 0.5),
            (1e-3, 1.0, 1.0),
        ] {
            let floor = rect(V::ZERO, V::X * w, V::Y * l);
            let wall = rect(V::ZERO, V::Y * l, V::Z * h);
            let want = common_edge(w, h, l);
            for (r, s) in [(floor.clone(), wall.clone()), (moved(&floor), moved(&wall))] {
                let f = polygon_factor(&r, &s);
                assert!(rel(f, want) < 1e-10, "{w} {h} {l}: {f} vs {want}");
                let back = polygon_factor(&s, &r) * area(&s) / area(&r);
                assert!(rel(back, want) < 1e-10, "{w} {h} {l}: {back} vs {want}");
            }
        }
    }

    /// Rectangles in perpendicular planes touching at one corner only. Form-factor algebra
    /// on two strips sharing edges (Howell C-14 each) gives the value when both have the
    /// same width, by the symmetry that swaps the planes.
    #[test]
    fn perpendicular_rectangles_sharing_a_vertex() {
        let (w, l1, l2) = (0.7, 0.5, 1.2);
        let g = |l: f64| w * l * common_edge(w, w, l);
        let want = 0.5 * (g(l1 + l2) - g(l1) - g(l2));
        let r1 = rect(V::ZERO, V::X * w, V::Y * l1);
        let s2 = rect(V::Y * l1, V::Y * l2, V::Z * w);
        let c = polygon_coupling(&r1, &s2);
        assert!(rel(c, want) < 1e-10, "{c} vs {want}");
        assert!(rel(polygon_coupling(&moved(&s2), &moved(&r1)), want) < 1e-10);
    }

    #[test]
    fn triangles_sharing_a_vertex_match_brute_force() {
        let v = V::new(0.1, -0.2, 0.0);
        let r = vec![v, v + V::new(1.0, 0.0, 0.0), v + V::new(0.3, 0.9, 0.0)];
        let s = vec![v, v + V::new(-0.2, 0.8, 0.9), v + V::new(-0.3, -0.1, 0.8)];
        let f = polygon_factor(&r, &s);
        let want = brute(&r, &s, true, 6);
        assert!(rel(f, want) < 1e-9, "{f} vs {want}: {:e}", rel(f, want));
    }

    #[test]
    fn small_receiver_matches_the_point_factor_at_its_centroid() {
        let s = rect(
            V::new(-0.4, 0.3, 1.0),
            V::new(-0.1, 1.1, 0.4),
            V::new(1.5, 0.2, 0.3),
        );
        let n = V::new(0.2, 0.3, 1.0).normalize();
        let (t1, t2) = (
            n.any_orthonormal_pair().0 * 1e-4,
            n.any_orthonormal_pair().1 * 1e-4,
        );
        let p = V::new(0.2, 0.5, 0.1);
        let r = rect(p - (t1 + t2) * 0.5, t1, t2);
        let f = polygon_factor(&r, &s);
        let want = polygon_irradiance(p, n, &s) / PI;
        assert!(rel(f, want) < 1e-7, "{f} vs {want}: {:e}", rel(f, want));
        // The big one seeing the small one: reciprocity through the point factor.
        let back = polygon_factor(&s, &r) * area(&s) / area(&r);
        assert!(rel(back, want) < 1e-7, "{back} vs {want}");
        // The difference above is the point factor's curvature over the patch; the patch's
        // own mean is exact.
        let want = brute(&r, &s, false, 1);
        assert!(rel(f, want) < 1e-10, "{f} vs {want}: {:e}", rel(f, want));
    }

    /// Panels on [a, b], halving toward a down to 2^-levels of it.
    fn graded(a: f64, b: f64, levels: i32) -> Vec<(f64, f64)> {
        let mut p: Vec<(f64, f64)> = (0..levels)
            .map(|k| {
                (
                    a + (b - a) * 0.5f64.powi(k + 1),
                    a + (b - a) * 0.5f64.powi(k),
                )
            })
            .collect();
        p.push((a, a + (b - a) * 0.5f64.powi(levels)));
        p
    }

    /// ∫∫ g(x, y) over panels in x and y, 16-point Gauss–Legendre on each.
    fn tensor(px: &[(f64, f64)], py: &[(f64, f64)], g: impl Fn(f64, f64) -> f64) -> f64 {
        let rule = gauss_legendre(16);
        let mut sum = 0.0;
        for &(x0, x1) in px {
            for &(y0, y1) in py {
                for &(xi, wi) in &rule {
                    for &(yj, wj) in &rule {
                        let x = 0.5 * (x0 + x1 + (x1 - x0) * xi);
                        let y = 0.5 * (y0 + y1 + (y1 - y0) * yj);
                        sum += 0.25 * (x1 - x0) * (y1 - y0) * wi * wj * g(x, y);
                    }
                }
            }
        }
        sum
    }

    /// A floor and a wall leaning away at 60°, their edges a hair apart: the point factor
    /// varies on the scale of the gap along the whole edge, graded for in the reference.
    #[test]
    fn hinged_pair_a_hair_apart_matches_brute_force() {
        let r = rect(V::ZERO, V::X, V::Y);
        let d = V::new(-0.5, 0.0, 0.75f64.sqrt());
        for gap in [1e-2, 1e-3] {
            let s = rect(V::new(-gap, 0.0, 0.0), V::Y, d);
            let px = graded(0.0, 1.0, 24);
            let mut py = graded(0.0, 0.5, 24);
            py.extend(graded(1.0, 0.5, 24).iter().map(|&(a, b)| (b, a)));
            let want = tensor(&px, &py, |x, y| point_factor(V::new(x, y, 0.0), V::Z, &s));
            let f = polygon_factor(&r, &s);
            assert!(
                rel(f, want) < 1e-9,
                "{gap}: {f} vs {want}: {:e}",
                rel(f, want)
            );
        }
    }

    /// A small element on the floor against a long, low wall strip, touching along a part of
    /// its bottom edge (the closed form is cut to a window there). Form-factor algebra on
    /// strips of equal width w gives it: with floor strips f_k and wall strips w_k over
    /// [0, 0.3], [0.3, 0.31], [0.31, 1], G(f_B, w_A) = ½ (G_AB − G_A − G_B) by the symmetry
    /// that swaps the planes, each G a common-edge closed form (Howell C-14).
    #[test]
    fn small_element_against_a_long_wall_strip() {
        let w = 0.01;
        let g = |l: f64| w * l * common_edge(w, w, l);
        let want =
            0.5 * (g(0.31) - g(0.3) - g(0.01)) + g(0.01) + 0.5 * (g(0.7) - g(0.69) - g(0.01));
        let element = rect(V::new(0.0, 0.3, 0.0), V::X * w, V::Y * 0.01);
        let wall = rect(V::ZERO, V::Y, V::Z * w);
        let c = polygon_coupling(&element, &wall);
        assert!(rel(c, want) < 1e-10, "{c} vs {want}: {:e}", rel(c, want));
        let c = polygon_coupling(&moved(&wall), &moved(&element));
        assert!(rel(c, want) < 1e-10, "{c} vs {want}: {:e}", rel(c, want));
    }

    /// Regression: an element on the floor just past the end of a long, low wall strip, its
    /// edge on the line of the strip's bottom edge but beyond it. The window around the
    /// element's edge missed the strip's edge, the closed form ran over a negative length,
    /// and F came out 0 instead of 8.3e-4.
    #[test]
    fn element_past_the_end_of_a_wall_strip() {
        let element = rect(V::new(0.0, 1.13, 0.0), V::X * 0.05, V::Y * 0.05);
        let wall = rect(V::ZERO, V::Y, V::Z * 0.05);
        let f = polygon_factor(&element, &wall);
        let want = brute(&element, &wall, false, 4);
        assert!(rel(f, want) < 1e-10, "{f} vs {want}: {:e}", rel(f, want));
        let back = polygon_factor(&wall, &element) * area(&wall) / area(&element);
        assert!(rel(back, want) < 1e-10, "{back} vs {want}");
    }

    /// Near parallel edges of very different lengths: cutting the longer one to a window
    /// (whichever of the two is the outer variable) gives the plain closed form's value,
    /// also when the short edge lies beyond the long one's end and the window misses it.
    #[test]
    fn windowed_parallel_pairs_agree_with_the_plain_closed_form() {
        let c = V::new(0.03, 0.2, 0.1);
        let long = Seg::new(V::new(-0.4, 0.0, 0.0), V::new(0.6, 0.0, 0.0));
        for (a, h, rev) in [
            (0.02, 0.0, false),
            (0.3, 1e-3, true),
            (0.58, 0.0, true),
            (0.61, 0.01, false),
            (1.13, 0.0, false),
            (1.13, 2e-3, true),
        ] {
            let (x0, x1) = (V::new(a - 0.4, h, 0.0), V::new(a - 0.4 + 0.05, h, 0.0));
            let short = if rev {
                Seg::new(x1, x0)
            } else {
                Seg::new(x0, x1)
            };
            // J = ∫∫ ln |x − y| from either side.
            let j_short_outer = edge_pair(short, long, c) + short.len * inner(c, long);
            let j_long_outer = edge_pair(long, short, c) + long.len * inner(c, short);
            let lo = (short.a - long.a)
                .dot(long.dir)
                .min((short.b - long.a).dot(long.dir));
            let plain = parallel_closed(long, short, lo, h, c) + long.len * inner(c, short);
            assert!(
                (j_short_outer - plain).abs() < 1e-13,
                "{a}: {j_short_outer} vs {plain}"
            );
            assert!(
                (j_long_outer - plain).abs() < 1e-13,
                "{a}: {j_long_outer} vs {plain}"
            );
        }
    }

    /// Coplanar edges (touching, crossing, T, apart, nearly parallel) in closed form against
    /// the graded quadrature of the inner closed form.
    #[test]
    fn coplanar_edge_pairs_agree_with_quadrature() {
        let q = DQuat::from_axis_angle(V::new(0.3, -1.0, 0.7).normalize(), 1.1);
        let o = V::new(0.1, -0.2, 0.05);
        let c = V::new(0.2, 0.1, 0.3);
        for (angle, (s1, s2), (t1, t2)) in [
            (1.2, (0.0, 0.8), (0.0, 0.6)),
            (2.5, (0.8, 0.0), (0.0, 0.6)),
            (0.4, (-0.3, 0.5), (-0.4, 0.2)),
            (1.9, (0.0, 0.7), (-0.3, 0.6)),
            (0.7, (0.2, 0.9), (-0.6, -0.1)),
            (0.01, (0.3, 0.9), (0.35, 0.8)),
        ] {
            let (u, v) = (q * V::X, q * V::new(f64::cos(angle), f64::sin(angle), 0.0));
            let p = Seg::new(o + u * s1, o + u * s2);
            let r = Seg::new(o + v * t1, o + v * t2);
            let closed = edge_pair(p, r, c);
            let quad = quadrature_pair(p, r, c);
            assert!((closed - quad).abs() < 1e-13, "{angle}: {closed} vs {quad}");
        }
    }

    /// A chair leg's top 5 mm under the seat, off centre: the seat fills nearly all of the
    /// leg's hemisphere.
    #[test]
    fn leg_top_under_a_seat() {
        let seat = rect(V::new(0.0, 0.0, 0.455), V::Y * 0.4, V::X * 0.45);
        let leg = rect(V::new(0.02, 0.03, 0.45), V::X * 0.03, V::Y * 0.025);
        let f = polygon_factor(&leg, &seat);
        let want = brute(&leg, &seat, false, 8);
        assert!(rel(f, want) < 1e-9, "{f} vs {want}: {:e}", rel(f, want));
        assert!(f > 0.8 && f < 1.0);
    }

    /// Each polygon partly behind the other's plane; the clipped parts 0.2 apart.
    #[test]
    fn tilted_pair_with_partial_clips_matches_brute_force() {
        let r = rect(V::ZERO, V::X, V::Y);
        let d = V::new(0.5, 0.0, 0.75f64.sqrt());
        let s = rect(V::new(0.6, 1.2, 0.0) - d * 0.3, d * 1.2, V::Y);
        let f = polygon_factor(&r, &s);
        let want = brute(&r, &s, false, 6);
        assert!(f > 1e-3, "{f}");
        assert!(rel(f, want) < 1e-9, "{f} vs {want}: {:e}", rel(f, want));
        let (rm, sm) = (moved(&r), moved(&s));
        assert!(rel(polygon_factor(&rm, &sm), want) < 1e-9);
        // From s's side.
        let want = brute(&s, &r, false, 6);
        assert!(rel(polygon_factor(&s, &r), want) < 1e-9);
    }

    /// A unit cube's inside: the faces around one face, cut into pieces, take all of its
    /// light.
    #[test]
    fn inside_a_cube_the_factors_sum_to_one() {
        let face = |o: V, u: V, v: V, cuts: &[&[(f64, f64)]]| -> Vec<Vec<V>> {
            cuts.iter()
                .map(|c| c.iter().map(|&(a, b)| o + u * a + v * b).collect())
                .collect()
        };
        let whole: &[&[(f64, f64)]] = &[&[(0., 0.), (1., 0.), (1., 1.), (0., 1.)]];
        let corner: &[&[(f64, f64)]] = &[
            &[(0., 0.), (0.6, 0.), (0., 0.4)],
            &[(0.6, 0.), (1., 0.), (1., 1.), (0., 1.), (0., 0.4)],
        ];
        let grid: &[&[(f64, f64)]] = &[
            &[(0., 0.), (0.3, 0.), (0.3, 0.7), (0., 0.7)],
            &[(0.3, 0.), (1., 0.), (1., 0.7), (0.3, 0.7)],
            &[(0.3, 0.7), (1., 0.7), (1., 1.), (0.3, 1.)],
            &[(0., 0.7), (0.3, 0.7), (0.3, 1.), (0., 1.)],
        ];
        let m = (0.5, 0.45);
        let fan: &[&[(f64, f64)]] = &[
            &[(0., 0.), (1., 0.), m],
            &[(1., 0.), (1., 1.), m],
            &[(1., 1.), (0., 1.), m],
            &[(0., 1.), (0., 0.), m],
        ];
        let (x, y, z) = (V::X, V::Y, V::Z);
        let mut others = Vec::new();
        others.extend(face(z, y, x, grid)); // top, facing down
        others.extend(face(V::ZERO, y, z, corner)); // x = 0
        others.extend(face(x, z, y, fan)); // x = 1
        others.extend(face(V::ZERO, z, x, whole)); // y = 0
        others.extend(face(y, x, z, corner)); // y = 1
        let floor = face(V::ZERO, x, y, whole).remove(0);
        let sum: f64 = others.iter().map(|s| polygon_factor(&floor, s)).sum();
        assert!((sum - 1.0).abs() < 1e-9, "{sum}");
        // A piece of the floor sees the same walls; the rest of the floor adds nothing.
        for piece in face(V::ZERO, x, y, corner) {
            let mut all = others.clone();
            all.extend(face(V::ZERO, x, y, grid));
            let sum: f64 = all.iter().map(|s| polygon_factor(&piece, s)).sum();
            assert!((sum - 1.0).abs() < 1e-9, "{sum}");
        }
    }

    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn range(&mut self, a: f64, b: f64) -> f64 {
            a + (b - a) * self.next()
        }

        fn unit(&mut self) -> V {
            loop {
                let v = V::new(
                    self.range(-1., 1.),
                    self.range(-1., 1.),
                    self.range(-1., 1.),
                );
                if v.length() > 0.1 && v.length() < 1.0 {
                    return v.normalize();
                }
            }
        }

        /// A convex polygon of 3–8 vertices on an ellipse in a random plane.
        fn polygon(&mut self) -> Vec<V> {
            let k = 3 + (self.next() * 6.0) as usize;
            let mut angles: Vec<f64> = (0..k).map(|_| self.range(0.0, 2.0 * PI)).collect();
            angles.sort_by(f64::total_cmp);
            let (e1, e2) = self.unit().any_orthonormal_pair();
            let (a, b) = (self.range(0.1, 1.0), self.range(0.1, 1.0));
            let c = V::new(
                self.range(-1., 1.),
                self.range(-1., 1.),
                self.range(-1., 1.),
            );
            angles
                .iter()
                .map(|t| c + e1 * a * t.cos() + e2 * b * t.sin())
                .collect()
        }
    }

    /// Reciprocity, and additivity when a polygon is cut in two (the halves meet along the
    /// cut, so this exercises the touching cases with different edge pairs).
    #[test]
    fn polygon_factor_reciprocal_check_and_cuts_add_up() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut nonzero, mut worst) = (0, 0.0f64);
        for case in 0..300 {
            let r = rng.polygon();
            let s = if case % 3 == 0 {
                // Sharing an edge of r, leaving its plane.
                let i = (rng.next() * r.len() as f64) as usize % r.len();
                let (a, b) = (r[i], r[(i + 1) % r.len()]);
                let d = rng.unit();
                vec![
                    b,
                    a,
                    a + d * rng.range(0.1, 1.0),
                    b + d * rng.range(0.1, 1.0),
                ]
            } else {
                rng.polygon()
            };
            let (crs, csr) = (polygon_coupling(&r, &s), polygon_coupling(&s, &r));
            let (frs, fsr) = (polygon_factor(&r, &s), polygon_factor(&s, &r));
            assert!(crs.is_finite() && crs >= 0.0);
            if crs == 0.0 {
                assert_eq!(csr, 0.0);
                continue;
            }
            nonzero += 1;
            assert!(
                rel(area(&r) * frs, area(&s) * fsr) < 1e-9,
                "{case}: {frs} {fsr}"
            );
            assert!(rel(crs, csr) < 1e-9);
            // r cut by a plane through its centroid.
            let cut = Plane::from_point_normal(centroid(&r), rng.unit());
            let halves = [
                clip_polygon_3d(&r, &cut, 0.0),
                clip_polygon_3d(&r, &cut.flipped(), 0.0),
            ];
            let parts: f64 = halves.iter().map(|h| polygon_coupling(h, &s)).sum();
            // Relative to the result, or for a grazing pair (a factor down to 1e-12) to
            // 1e-5 of the areas: what is left there is rounding in the contour sum.
            let err = (parts - crs).abs() / crs.max(1e-5 * area(&r).min(area(&s)));
            worst = worst.max(err);
            assert!(err < 1e-9, "{case}: {parts} vs {crs}");
        }
        println!("{nonzero} pairs, worst cut error {worst:e}");
        assert!(nonzero > 100, "{nonzero}");
    }

    /// Architecture-like pairs: rectangles on a grid in a floor, a wall and a ceiling a
    /// little above, so that edges are collinear, parallel and near, with all length
    /// ratios; cutting the receiver along a grid line must not change the transfer.
    #[test]
    fn grid_rectangles_cut_add_up() {
        let mut rng = Rng(0x1234_5678);
        let mut grid = |n: f64| (rng.next() * n).floor() * 0.05;
        let mut checked = 0;
        for case in 0..400 {
            let (x0, y0) = (grid(10.0), grid(20.0));
            let (w, l) = (0.05 + grid(10.0), 0.05 + grid(20.0));
            let r = rect(V::new(x0, y0, 0.0), V::X * w, V::Y * l);
            let (a, b) = (grid(20.0), grid(10.0));
            let (da, db) = (0.05 + grid(20.0), 0.05 + grid(10.0));
            let s = match case % 3 {
                0 => rect(V::new(0.0, a, b), V::Y * da, V::Z * db),
                1 => rect(V::new(b, a, 0.0), V::Z * db, V::Y * da),
                _ => rect(V::new(b, a, 0.01 + grid(4.0)), V::Y * da, V::X * db),
            };
            let whole = polygon_coupling(&r, &s);
            if whole == 0.0 {
                continue;
            }
            checked += 1;
            let cut = x0 + 0.05 * (1.0 + (w / 0.05 - 1.0).floor().max(0.0) * 0.5).floor();
            let parts = if cut > x0 && cut < x0 + w {
                polygon_coupling(&rect(r[0], V::X * (cut - x0), V::Y * l), &s)
                    + polygon_coupling(
                        &rect(V::new(cut, y0, 0.0), V::X * (x0 + w - cut), V::Y * l),
                        &s,
                    )
            } else {
                let cut = y0 + l * 0.5;
                polygon_coupling(&rect(r[0], V::X * w, V::Y * (cut - y0)), &s)
                    + polygon_coupling(
                        &rect(V::new(x0, cut, 0.0), V::X * w, V::Y * (y0 + l - cut)),
                        &s,
                    )
            };
            let err = (parts - whole).abs() / whole.max(1e-5 * area(&r).min(area(&s)));
            assert!(err < 1e-9, "{case}: {parts} vs {whole}");
        }
        assert!(checked > 150, "{checked}");
    }

    #[test]
    fn degenerate_input_is_zero_not_nan() {
        let sq = rect(V::ZERO, V::X, V::Y);
        let above = rect(V::Z, V::Y, V::X);
        // Zero-area polygons, too few vertices, non-finite coordinates.
        let line = vec![V::ZERO, V::X, V::X * 2.0];
        let point = vec![V::Z; 4];
        let nan = vec![V::ZERO, V::X, V::new(f64::NAN, 1.0, 1.0)];
        for bad in [line, point, nan, vec![V::ZERO, V::X]] {
            assert_eq!(polygon_factor(&bad, &above), 0.0);
            assert_eq!(polygon_factor(&above, &bad), 0.0);
            assert_eq!(polygon_coupling(&bad, &above), 0.0);
        }
        // Coplanar (overlapping or side by side), back to back, wholly behind.
        assert_eq!(polygon_factor(&sq, &sq), 0.0);
        assert_eq!(polygon_factor(&sq, &rect(V::X, V::X, V::Y)), 0.0);
        let under = rect(-V::Z, V::X, V::Y);
        assert_eq!(polygon_factor(&sq, &under), 0.0);
        assert_eq!(polygon_factor(&under, &sq), 0.0);
        let mut flipped = above.clone();
        flipped.reverse();
        assert_eq!(polygon_factor(&sq, &flipped), 0.0);
        // A repeated vertex is an edge of no length: the same factor.
        let doubled = vec![sq[0], sq[1], sq[1], sq[2], sq[3]];
        assert!(
            rel(
                polygon_factor(&doubled, &above),
                polygon_factor(&sq, &above)
            ) < 1e-14
        );
        // A tiny sliver next to a big face stays finite.
        let sliver = rect(V::ZERO, V::Y, V::new(0.0, 0.0, 1e-300));
        assert!(polygon_factor(&sq, &sliver).is_finite());
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in 1..=MAX_POINTS {
            for k in 0..2 * n {
                let got: f64 = gauss_legendre(n)
                    .iter()
                    .map(|(x, w)| w * x.powi(k as i32))
                    .sum();
                let want = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k + 1) as f64
                };
                assert!((got - want).abs() < 1e-14, "{n} {k}: {got}");
            }
        }
    }

    type Pairs = Vec<(Vec<V>, Vec<V>)>;

    /// ns per call; `cargo test -p penumbra --release --lib polygon_factor_timing --
    /// --ignored --nocapture`.
    #[test]
    #[ignore]
    fn polygon_factor_timing() {
        let mut rng = Rng(7);
        let randoms: Pairs = (0..2000)
            .map(|_| (rng.polygon(), rng.polygon()))
            .filter(|(r, s)| polygon_coupling(r, s) > 0.0)
            .collect();
        let quads: Pairs = (0..2000)
            .map(|_| {
                let r = rect(V::ZERO, V::X, V::Y);
                let o = V::new(rng.range(-1., 1.), rng.range(-1., 1.), rng.range(0.5, 2.));
                let (u, v) = (rng.unit() * 0.7, rng.unit() * 0.7);
                let s = if u.cross(v).z < 0.0 {
                    rect(o, u, v)
                } else {
                    rect(o, v, u)
                };
                (r, s)
            })
            .filter(|(r, s)| polygon_coupling(r, s) > 0.0)
            .collect();
        let one = |r: &[V], s: &[V]| vec![(r.to_vec(), s.to_vec())];
        let v = V::new(0.1, -0.2, 0.0);
        let tri_r = vec![v, v + V::new(1.0, 0.0, 0.0), v + V::new(0.3, 0.9, 0.0)];
        let tri_s = vec![v, v + V::new(-0.2, 0.8, 0.9), v + V::new(-0.3, -0.1, 0.8)];
        let hinge = rect(
            V::new(-1e-3, 0.0, 0.0),
            V::Y,
            V::new(-0.5, 0.0, 0.75f64.sqrt()),
        );
        let cases: [(&str, Pairs); 8] = [
            ("triangles sharing a vertex", one(&tri_r, &tri_s)),
            (
                "hinged squares 1 mm apart at 120 degrees",
                one(&rect(V::ZERO, V::X, V::Y), &hinge),
            ),
            (
                "0.01 element against a 1 x 0.01 wall strip",
                one(
                    &rect(V::new(0.0, 0.3, 0.0), V::X * 0.01, V::Y * 0.01),
                    &rect(V::ZERO, V::Y, V::Z * 0.01),
                ),
            ),
            (
                "opposed unit squares 1 apart",
                one(&rect(V::ZERO, V::X, V::Y), &rect(V::Z, V::Y, V::X)),
            ),
            (
                "unit squares 5 mm apart",
                one(&rect(V::ZERO, V::X, V::Y), &rect(V::Z * 0.005, V::Y, V::X)),
            ),
            (
                "floor and wall sharing an edge",
                one(&rect(V::ZERO, V::X, V::Y), &rect(V::ZERO, V::Y, V::Z)),
            ),
            ("random quads, tilted, 0.5-2 apart", quads),
            ("random 3-8-gons, facing", randoms),
        ];
        for (name, pairs) in cases {
            let reps = (200_000 / pairs.len()).max(1);
            let t = std::time::Instant::now();
            let mut acc = 0.0;
            for _ in 0..reps {
                for (r, s) in &pairs {
                    acc += polygon_factor(std::hint::black_box(r), s);
                }
            }
            let ns = t.elapsed().as_nanos() as f64 / (reps * pairs.len()) as f64;
            println!(
                "{name}: {ns:.0} ns/call over {} pairs ({acc:.3})",
                pairs.len()
            );
        }
    }
}

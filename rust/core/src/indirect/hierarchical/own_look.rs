//! A point's own look at a source, in place of its link's mean visibility (`vertices`):
//! how many rays, and when what they found is trusted over the mean; and the helpers that
//! choose which links and which points look.

use glam::{DVec3, Vec3};

use super::from_point::{seen_from, AreaTable, Seen, Start};
use super::hierarchy::Node;
use super::vertices::SCREEN_RAYS;
use super::visibility::Visibility;
use crate::geom::hash::mix;

/// Rays from a vertex to a source that it checks in full; a vertex whose rays leave it in
/// doubt (see `own_visibility`) casts as many more at a time, up to `MAX_VERTEX_RAYS` in
/// all, and is judged again after each. Doubling (16, 32, 64) spent half of room-828's
/// leaf looks' rays on the looks in doubt; steps of 16 judge at 48 too, and cast 6 % fewer
/// of room-245's final gather's rays with the error from Cycles (`per_mesh.py`) the same:
/// room-78 2.984 → 2.982 %, cornell 0.940 → 0.942 %, room-245 5.214 → 5.211 %. Steps of
/// 8 spared 11 %, but room-78 went to 3.017 %: each judgement is a chance to stop on noise.
const REPLACE_RAYS: u32 = 16;
/// A look's first round casts every `PROBE`-th of its strata first (see `own_visibility`).
const PROBE: usize = 4;
const MAX_VERTEX_RAYS: u32 = 64;
/// A vertex's own visibility replaces the link's where the two differ by more than `SURE`
/// standard errors of the vertex's estimate, and is ignored under `NOISE` of them; between,
/// it is blended in smoothly.
const NOISE: f64 = 2.0;
const SURE: f64 = 4.0;
/// A leaf's slope of visibility (`slope`) is dropped under `SLOPE_NOISE` standard errors and
/// kept whole from `SLOPE_SURE`. A leaf's look often stops at 16 rays, which pin a slope
/// loosely. At 2 and 4 (a vertex's look's), the backrest test's rms was 0.42 % against
/// 0.31 %; at 0.5 and 2, against Cycles (`per_mesh.py`): chair 0.402 %, cornell 0.858 %,
/// data1 0.499 %, room-78 2.733 %, against 0.412, 0.857, 0.490 and 2.691 % at 1 and 3.
const SLOPE_NOISE: f64 = 1.0;
const SLOPE_SURE: f64 = 3.0;

/// `k` of `points` spread over them (farthest-point picks from the first), by index.
pub(super) fn spread(points: &[DVec3], k: usize) -> Vec<usize> {
    let mut chosen = vec![0usize];
    let mut near = vec![f64::INFINITY; points.len()];
    while chosen.len() < k.min(points.len()) {
        let last = points[*chosen.last().unwrap()];
        let mut far = 0;
        for (i, c) in points.iter().enumerate() {
            near[i] = near[i].min((*c - last).length_squared());
            if near[i] > near[far] {
                far = i;
            }
        }
        if near[far] <= 0.0 {
            break;
        }
        chosen.push(far);
    }
    chosen
}

/// The anchors' visibilities `from` (position, one per link) interpolated to `at` by
/// inverse square distance, into `own`.
pub(super) fn inverse_square<'x>(
    at: DVec3,
    from: impl Iterator<Item = (DVec3, &'x [f64])>,
    own: &mut [f64],
) {
    own.fill(0.0);
    let mut total = 0.0;
    for (p, f) in from {
        let w = 1.0 / ((at - p).length_squared() + 1e-30);
        total += w;
        own.iter_mut().zip(f).for_each(|(x, y)| *x += w * y);
    }
    own.iter_mut().for_each(|x| *x /= total);
}

/// Indices of `errs` from the largest down, as far as it takes for what is left to be
/// under `allowed` (a stable sort: the same order on every thread).
pub(super) fn by_error(errs: &[f64], allowed: f64) -> Vec<usize> {
    let mut left: f64 = errs.iter().sum();
    if left <= allowed {
        return Vec::new();
    }
    let mut order: Vec<usize> = (0..errs.len()).collect();
    order.sort_by(|&a, &b| errs[b].total_cmp(&errs[a]));
    let mut out = Vec::new();
    for i in order {
        if left <= allowed || errs[i] <= 0.0 {
            break;
        }
        left -= errs[i];
        out.push(i);
    }
    out
}

/// What a look found (`own_visibility`): the visibility to use, whether its rays found the
/// source in part, the rays it cast, and their sums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct OwnLook {
    pub v: f64,
    pub varies: bool,
    pub rays: u32,
    pub seen: Seen,
}

/// How the visibility of a source changes over a leaf: `v + grad·(p − at)` at a point `p`
/// of it, `v` the leaf's visibility. In single precision: leaves keep theirs for `looked`
/// (`LeafLook`), and in double it took room-245's bake from 282 to 346 MiB at its peak.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Slope {
    pub at: Vec3,
    pub grad: Vec3,
}

impl Slope {
    /// The visibility at `p`, within 0..1.
    pub fn at(&self, v: f64, p: DVec3) -> f64 {
        (v + self.grad.as_dvec3().dot(p - self.at.as_dvec3())).clamp(0.0, 1.0)
    }
}

/// The slope of the visibility over a leaf (normal `n`, centroid `c`) that looked at a
/// source (`seen`, from `Start::Node`), where its rays show one.
///
/// A leaf's mean serves its vertices badly where a blocker's edge runs near: seen from a
/// chair's backrest, the seat's front edge hides more of the floor the lower the point, and
/// over one leaf the floor's visible part went from 0.25 to 0.83 about a mean of 0.55.
/// The look's start points are stratified over the leaf, so a plane fitted to where its
/// rays got through (kernel-weighted least squares) gives that slope without more rays.
/// Its noise is judged as a vertex's look is: the slope is kept whole from `SLOPE_SURE`
/// standard errors (the Wald statistic, with a ray's variance v·(1 − v) over the effective
/// count), dropped under `SLOPE_NOISE`, and scaled smoothly between.
pub(super) fn slope(seen: &Seen, c: DVec3, n: DVec3) -> Option<Slope> {
    let (w, st) = (seen.total, &seen.starts);
    if !(w > 0.0 && seen.open > 0.0 && seen.open < w) {
        return None;
    }
    let v = seen.open / w;
    let (t1, t2) = n.normalize().any_orthonormal_pair();
    let mean = st.d / w;
    let (a1, a2) = (t1.dot(mean), t2.dot(mean));
    // The start points' covariance in the leaf's plane, and theirs with the rays' outcome.
    let s11 = st.second(t1, t1) / w - a1 * a1;
    let s12 = st.second(t1, t2) / w - a1 * a2;
    let s22 = st.second(t2, t2) / w - a2 * a2;
    let b1 = t1.dot(st.open_d) / w - a1 * v;
    let b2 = t2.dot(st.open_d) / w - a2 * v;
    let det = s11 * s22 - s12 * s12;
    if !(det > 1e-9 * (s11 + s22) * (s11 + s22)) {
        return None;
    }
    let g1 = (s22 * b1 - s12 * b2) / det;
    let g2 = (s11 * b2 - s12 * b1) / det;
    let z2 = (g1 * (s11 * g1 + s12 * g2) + g2 * (s12 * g1 + s22 * g2)) * seen.effective()
        / (v * (1.0 - v));
    let t = ((z2.sqrt() - SLOPE_NOISE) / (SLOPE_SURE - SLOPE_NOISE)).clamp(0.0, 1.0);
    let t = t * t * (3.0 - 2.0 * t);
    (t > 0.0).then(|| Slope {
        at: (c + mean).as_vec3(),
        grad: ((t1 * g1 + t2 * g2) * t).as_vec3(),
    })
}

/// The visibility of node `s` from the point `at` = (position, normal, scene face) that the
/// final gather uses in place of its link's mean `lv`, from `rays` rays at first.
///
/// The vertex's few rays are noisy, and the mean over the link's receiver is right for most
/// of its points (rays through slats see 40 % from everywhere): a vertex that took its own
/// estimate for every link would scatter about the right mean. What the final gather must
/// not miss is the vertex that sees much more or much less than the mean (under a table, a
/// link from the ceiling to a floor node reaching past its edge). So the vertex's estimate
/// `v` is tested against the mean: under the hypothesis that the vertex sees `lv`, its
/// estimate's variance is about `lv·(1 − lv) / m` (`m` the effective count of its rays;
/// stratification only lowers it), and `v·(1 − v) / m` when the vertex sees what it
/// found. The larger of the two sets `z = |v − lv| / σ`. Under `NOISE` the mean is kept;
/// from `SURE` on the vertex's own value is; in doubt between, the vertex casts
/// `REPLACE_RAYS` more (up to `MAX_VERTEX_RAYS`), then blends the two smoothly. Where the
/// first round's rays are all blocked by a face that hides the whole source from the start
/// (`Visibility::covers`), the visibility is 0, whatever the mean.
#[allow(clippy::too_many_arguments)]
pub(super) fn own_visibility(
    vis: &Visibility,
    table: &AreaTable,
    start: Start,
    s: &Node,
    blockers: Option<&[u32]>,
    lv: f64,
    seed: u64,
    screened: Option<Seen>,
) -> OwnLook {
    let done = |v, varies, rays, seen| OwnLook {
        v,
        varies,
        rays,
        seen,
    };
    // Nothing between the leaf and the source: all of it is in sight.
    if blockers.is_some_and(|l| l.is_empty()) {
        return done(1.0, false, 0, Seen::default());
    }
    // Rays cast here (not those of `screened`), for the stats.
    let mut rays = 0;
    let varies = |seen: &Seen| seen.open > 0.0 && seen.open < seen.total;
    let mut seen = Seen::default();
    let mut cast = 0;
    let mut k = REPLACE_RAYS;
    // A link whose rays all agreed (lv 0 or 1) is screened first by a few rays: if they all
    // agree too, the link's value stands.
    if lv == 0.0 || lv == 1.0 {
        seen = screened.unwrap_or_else(|| {
            let x = seen_from(
                vis,
                table,
                start,
                s,
                blockers,
                SCREEN_RAYS,
                seed,
                0..SCREEN_RAYS,
            );
            rays += x.rays;
            x
        });
        cast = SCREEN_RAYS;
        match seen.fraction() {
            Some(v) if v != lv => k = REPLACE_RAYS - SCREEN_RAYS,
            _ => return done(lv, false, rays, seen),
        }
    }
    // Every ray blocked: if the face that blocked them (or its solid) hides all of the
    // source from all of the start, it sees none of it, and no more rays can say otherwise.
    // The noise test alone kept a small mean there (0.2 after 16 blocked rays), and cast up
    // to 64 rays for a larger one.
    let hidden = |seen: &Seen| {
        seen.open == 0.0
            && seen.rays > 0
            && seen.blocker.is_some_and(|f| match start {
                Start::Node(r) => vis.covers(f, r, s),
                Start::Point(p, n, _) => vis.covers_from(f, &[p], Some(n), s),
            })
    };
    // The face the probe below found hiding every one of its rays, tried already.
    let mut tried = None;
    for round in 1u64.. {
        let seed = mix(seed ^ round);
        let more = if round == 1 && k == REPLACE_RAYS {
            // A first round probes with every `PROBE`-th stratum first: where a face hides
            // the source, the rest of the round is spared.
            let mut probe = seen_from(
                vis,
                table,
                start,
                s,
                blockers,
                k,
                seed,
                (0..k).step_by(PROBE),
            );
            rays += probe.rays;
            if hidden(&probe) {
                return done(0.0, false, rays, probe);
            }
            if probe.open == 0.0 {
                tried = probe.blocker;
            }
            let rest = (0..k).filter(|i| i % PROBE as u32 != 0);
            let rest = seen_from(vis, table, start, s, blockers, k, seed, rest);
            rays += rest.rays;
            probe.add(rest);
            probe
        } else {
            let more = seen_from(vis, table, start, s, blockers, k, seed, 0..k);
            rays += more.rays;
            more
        };
        seen.add(more);
        cast += k;
        if round == 1 && seen.blocker != tried && hidden(&seen) {
            return done(0.0, false, rays, seen);
        }
        let Some(v) = seen.fraction() else {
            return done(lv, false, rays, seen);
        };
        let d = (v - lv).abs();
        let var = (lv * (1.0 - lv)).max(v * (1.0 - v)) / seen.effective().max(1.0);
        let z = if d == 0.0 {
            0.0
        } else if var > 0.0 {
            d / var.sqrt()
        } else {
            f64::INFINITY
        };
        if z <= NOISE || z >= SURE || cast >= MAX_VERTEX_RAYS {
            let t = ((z - NOISE) / (SURE - NOISE)).clamp(0.0, 1.0);
            let v = lv + (v - lv) * t * t * (3.0 - 2.0 * t);
            return done(v, varies(&seen), rays, seen);
        }
        k = REPLACE_RAYS.min(MAX_VERTEX_RAYS - cast);
    }
    done(lv, false, rays, seen)
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::indirect::hierarchical::visibility::test::HalfBlocked;

    #[test]
    fn a_look_that_a_face_hides_wholly_is_dark_after_its_probe() {
        // Floor facing up, ceiling facing down, and a blocker between them over x < 0. A
        // link's mean of 0.2 (its receiver reaching past the blocker's edge) and a leaf
        // wholly under the blocker: its rays are all blocked, which under the noise test
        // alone (z = √(16 · 0.2 / 0.8) = 2 at most after a round of 16) would keep the mean;
        // the blocker covers the pair, so the leaf sees nothing, found by the first round's
        // probe (4 rays).
        let scene = HalfBlocked::new();
        let (h, vis) = (&scene.h, scene.vis());
        let table = AreaTable::new(h);
        let (under, over) = (scene.leaf_at(0, -0.2), scene.leaf_at(1, -0.2));
        let list = vis.blockers(under, over);
        assert_eq!(list.as_deref(), Some(&[2][..]));
        let look = |start| {
            let l = own_visibility(&vis, &table, start, over, list.as_deref(), 0.2, 7, None);
            (l.v, l.varies, l.rays)
        };
        let probe = REPLACE_RAYS / PROBE as u32;
        assert_eq!(look(Start::Node(under)), (0.0, false, probe));
        // From a point under the blocker too.
        let p = under.centroid;
        assert_eq!(look(Start::Point(p, DVec3::Z, 0)), (0.0, false, probe));
        // A pair the blocker hides in part: its rays find it, and the look goes on.
        let ceiling = &h.nodes[h.nodes[0]
            .kids
            .into_iter()
            .find(|&k| h.nodes[k as usize].face == 1)
            .unwrap() as usize];
        let OwnLook {
            v, varies, rays, ..
        } = own_visibility(
            &vis,
            &table,
            Start::Node(under),
            ceiling,
            list.as_deref(),
            0.2,
            7,
            None,
        );
        assert!(
            varies && v > 0.0 && rays >= REPLACE_RAYS,
            "{v} {varies} {rays}"
        );
        // Strata cast in two parts are the segments of one call for all of them (more
        // than a batch of them: none is lost between batches).
        let k = 40;
        let list = list.as_deref();
        let all = seen_from(&vis, &table, Start::Node(under), ceiling, list, k, 9, 0..k);
        let part = |f: fn(&u32) -> bool| {
            let which = (0..k).filter(f);
            seen_from(&vis, &table, Start::Node(under), ceiling, list, k, 9, which)
        };
        let mut two = part(|i| i % 3 == 0);
        two.add(part(|i| i % 3 != 0));
        assert_eq!(two.rays, k);
        assert_eq!(all.rays, k);
        assert!(
            (two.open - all.open).abs() <= 1e-12 * all.total,
            "{two:?} {all:?}"
        );
        assert!((two.total - all.total).abs() <= 1e-12 * all.total);
        assert!(all.open > 0.0 && all.open < all.total);
    }

    #[test]
    fn a_slope_is_fitted_where_the_rays_show_one_and_not_to_noise() {
        // Start points on a 16 × 16 lattice over a unit square leaf in a tilted plane (its
        // centroid at c), with uneven weights; what got through depends on where a ray
        // started.
        let n = DVec3::ONE.normalize();
        let (t1, t2) = n.any_orthonormal_pair();
        let c = DVec3::new(1.0, -2.0, 1.0);
        let seen_by = |open: &dyn Fn(f64, f64) -> bool| {
            let mut seen = Seen::default();
            for i in 0..16 {
                for j in 0..16 {
                    let (a, b) = ((i as f64 + 0.5) / 16.0 - 0.5, (j as f64 + 0.5) / 16.0 - 0.5);
                    let o = open(a, b);
                    let w = 1.0 + 0.1 * ((i * 7 + j) % 5) as f64;
                    seen.total += w;
                    seen.total_sq += w * w;
                    seen.open += if o { w } else { 0.0 };
                    seen.rays += 1;
                    seen.starts.add_ray(w, t1 * a + t2 * b, o);
                }
            }
            seen
        };
        let edge = seen_by(&|a, _| a > 0.1);
        let s = slope(&edge, c, n).expect("a clear slope");
        // The fitted plane's slope along t1 for a step at 0.1 over a uniform [−½, ½]:
        // cov(u, H(u − 0.1)) / var(u) = (½ · (¼ − 0.01)) / (1/12) = 1.44 (the lattice
        // and the weights move it a little).
        let g = s.grad.as_dvec3();
        assert!((g.dot(t1) - 1.44).abs() < 0.1, "{:?}", s);
        assert!(g.dot(t2).abs() < 0.05 && g.dot(n).abs() < 1e-6);
        // On the plane: below the edge less is seen than above it, within 0..1.
        let v = edge.fraction().unwrap();
        let (lo, hi) = (s.at(v, c - t1 * 0.4), s.at(v, c + t1 * 0.4));
        assert!(lo < 0.1 && hi > 0.85 && hi <= 1.0, "{lo} {hi}");
        // A pattern that does not follow the position (a checkerboard): no slope.
        let checker = seen_by(&|a, b| ((a * 16.0 + 8.0) as i32 + (b * 16.0 + 8.0) as i32) % 2 == 0);
        assert_eq!(slope(&checker, c, n), None);
        // All seen, or none: nothing to fit.
        assert_eq!(slope(&seen_by(&|_, _| true), c, n), None);
        assert_eq!(slope(&seen_by(&|_, _| false), c, n), None);
    }

    #[test]
    fn anchors_spread_to_the_far_corners_first() {
        // A 5 × 5 lattice: after the first point (a corner), the far corner, then the two
        // others, then the centre.
        let pts: Vec<DVec3> = (0..25)
            .map(|i| DVec3::new((i % 5) as f64, (i / 5) as f64, 0.0))
            .collect();
        let a = spread(&pts, 5);
        assert_eq!(a[..2], [0, 24]);
        let mut mid = a[2..4].to_vec();
        mid.sort();
        assert_eq!(mid, [4, 20]);
        assert_eq!(a[4], 12);
        // Fewer points than asked, or all in one place: no index twice.
        assert_eq!(spread(&pts[..3], 6), [0, 2, 1]);
        assert_eq!(spread(&[DVec3::ZERO; 4], 3), [0]);
    }
}

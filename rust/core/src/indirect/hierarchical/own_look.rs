//! A point's own look at a source, in place of its link's mean visibility (`vertices`):
//! how many rays, and when what they found is trusted over the mean; and the helpers that
//! choose which links and which points look.

use glam::DVec3;

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
) -> (f64, bool, u32) {
    // Nothing between the leaf and the source: all of it is in sight.
    if blockers.is_some_and(|l| l.is_empty()) {
        return (1.0, false, 0);
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
            _ => return (lv, false, rays),
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
                return (0.0, false, rays);
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
            return (0.0, false, rays);
        }
        let Some(v) = seen.fraction() else {
            return (lv, false, rays);
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
            return (lv + (v - lv) * t * t * (3.0 - 2.0 * t), varies(&seen), rays);
        }
        k = REPLACE_RAYS.min(MAX_VERTEX_RAYS - cast);
    }
    (lv, false, rays)
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
        let look = |start| own_visibility(&vis, &table, start, over, list.as_deref(), 0.2, 7, None);
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
        let (v, varies, rays) = own_visibility(
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

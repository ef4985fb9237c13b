//! How much of a node a point (or a leaf) sees, by rays to points of the node, for the
//! final gather at element vertices (`vertices`).
//!
//! The points are stratified over the node's area: its leaf positions are laid end to end
//! by area (`AreaTable`), the unit interval is cut into `k` strata, and each stratum takes
//! one point, jittered within it by a hash of the (vertex, source, stratum); the part of a
//! triangle's interval the point falls in is one coordinate of the point in the triangle
//! and a second hash the other, through the area-preserving square-to-triangle map. So
//! every point is uniform over the node's area, and the strata spread them over it. From a
//! leaf, the start points are drawn the same way, their strata in another order.
//!
//! The estimate is the ratio of the point-to-point kernel `cosθ·cosθs / d²`, times how
//! bright the segment's end on the source is (`Visibility::bright`), over the open segments
//! to the same over all of them. Where a segment is open depends on where the
//! blockers stand, its kernel on where its end is: with the points drawn independently of
//! the blockers the ratio's expectation is the kernel-weighted visible fraction for any
//! count, and where the two are correlated its bias is of the order of the weights' spread
//! over the count. Measured through slats that hide 60 %, 16 rays from one vertex to each
//! of its links' sources, 400 draws each: means within 0.01 of 4096 rays'. A lattice of
//! points, or hashes chained from consecutive seeds, falls in step with a regular blocker:
//! 8 such rays from one vertex through the same slats saw 0.48–0.62 of the emitter, not 0.40.

use glam::DVec3;

use super::hierarchy::{Hierarchy, Node};
use super::visibility::Visibility;
use crate::geom::hash::{mix, unit};

/// Cumulative area of the leaf positions (`Hierarchy::order`): position `p` spans
/// `cum[p]..cum[p + 1]`, and a node's range `lo..hi` spans `cum[lo]..cum[hi]`.
pub struct AreaTable {
    cum: Vec<f64>,
    /// Every `BLOCK`-th entry of the level below (`cum` for the first), up to one of at
    /// most `BLOCK` entries: a search reads one block of each level, from the top down.
    /// A bisection's loads each wait for the one before, and beside the BVH's nodes nearly
    /// every one missed cache (room-245 has 394k elements: a third of the search's time was
    /// one load of the old single index); a block's loads are independent, and their misses
    /// overlap.
    index: Vec<Vec<f64>>,
}

const BLOCK: usize = 64;

impl AreaTable {
    pub fn new(h: &Hierarchy) -> Self {
        Self::of_areas(&h.area)
    }

    fn of_areas(area: &[f64]) -> Self {
        let mut cum = Vec::with_capacity(area.len() + 1);
        let mut a = 0.0;
        cum.push(0.0);
        for &x in area {
            a += x.max(0.0);
            cum.push(a);
        }
        let mut index: Vec<Vec<f64>> = Vec::new();
        while index.last().unwrap_or(&cum).len() > BLOCK {
            let level = index
                .last()
                .unwrap_or(&cum)
                .iter()
                .step_by(BLOCK)
                .copied()
                .collect();
            index.push(level);
        }
        AreaTable { cum, index }
    }

    /// The leaf position of node `n` at the fraction `u` of its area, and the fraction of
    /// that position's own area that `u` falls at.
    fn at(&self, n: &Node, u: f64) -> (u32, f64) {
        let (lo, hi) = (n.lo as usize, n.hi as usize);
        let (a, b) = (self.cum[lo], self.cum[hi]);
        let x = a + u * (b - a);
        let pos = self.position(lo, hi, x);
        let (s, e) = (self.cum[pos], self.cum[pos + 1]);
        let t = if e > s { (x - s) / (e - s) } else { 0.5 };
        (pos as u32, t.clamp(0.0, 1.0 - 1e-12))
    }

    /// The last position of `lo..hi` whose start is at or below `x` (`lo` if none). `cum`
    /// never falls, so that is the last such entry of all of `cum`, clamped to the range.
    fn position(&self, lo: usize, hi: usize, x: f64) -> usize {
        if hi - lo <= 2 * BLOCK {
            return lo + at_or_below(&self.cum[lo + 1..hi], x);
        }
        // Entries at or below x in each level, from the top: the last of them in a level is
        // the first of a block of the level below, and all before that block are below x.
        let mut below = at_or_below(self.index.last().map_or(&self.cum, |v| v), x);
        for level in self.index.iter().rev().skip(1).chain([&self.cum]) {
            if below == 0 {
                break;
            }
            let start = (below - 1) * BLOCK;
            let end = (start + BLOCK).min(level.len());
            below = start + at_or_below(&level[start..end], x);
        }
        below.saturating_sub(1).clamp(lo, hi - 1)
    }
}

/// How many entries of the non-decreasing `c` are at or below `x`: its partition point,
/// without a chain of dependent loads.
fn at_or_below(c: &[f64], x: f64) -> usize {
    c.iter().map(|&v| usize::from(v <= x)).sum()
}

/// Sums of a run of rays from a point to a node: kernel over the open segments and over
/// all, the sum of squared kernels (for the effective count) and the rays cast; the face
/// that blocked the last blocked segment; and from a node, where on it the rays started.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Seen {
    pub open: f64,
    pub total: f64,
    pub total_sq: f64,
    pub rays: u32,
    pub blocker: Option<u32>,
    pub starts: Starts,
}

/// Kernel-weighted moments of the start points of a run of rays from a node, about the
/// node's centroid (offset `d`): Σw·d, Σw·d·dᵀ (xx, yy, zz, xy, xz, yz) and Σw·d over the
/// open segments. The slope of the visibility over the node is fitted to them
/// (`own_look::slope`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Starts {
    pub d: DVec3,
    pub dd: [f64; 6],
    pub open_d: DVec3,
}

impl Starts {
    pub(super) fn add_ray(&mut self, w: f64, d: DVec3, open: bool) {
        let wd = w * d;
        self.d += wd;
        self.dd[0] += wd.x * d.x;
        self.dd[1] += wd.y * d.y;
        self.dd[2] += wd.z * d.z;
        self.dd[3] += wd.x * d.y;
        self.dd[4] += wd.x * d.z;
        self.dd[5] += wd.y * d.z;
        if open {
            self.open_d += wd;
        }
    }

    fn add(&mut self, o: &Starts) {
        self.d += o.d;
        for (a, b) in self.dd.iter_mut().zip(o.dd) {
            *a += b;
        }
        self.open_d += o.open_d;
    }

    /// `aᵀ·(Σw·d·dᵀ)·b`.
    pub(super) fn second(&self, a: DVec3, b: DVec3) -> f64 {
        let [xx, yy, zz, xy, xz, yz] = self.dd;
        a.x * (xx * b.x + xy * b.y + xz * b.z)
            + a.y * (xy * b.x + yy * b.y + yz * b.z)
            + a.z * (xz * b.x + yz * b.y + zz * b.z)
    }
}

impl Seen {
    /// Kernel-weighted fraction of the node seen; `None` when no point of it faced the
    /// point.
    pub fn fraction(&self) -> Option<f64> {
        (self.total > 0.0).then(|| (self.open / self.total).clamp(0.0, 1.0))
    }

    /// The count of equally weighted samples as informative as these: (Σw)² / Σw².
    pub fn effective(&self) -> f64 {
        if self.total_sq > 0.0 {
            self.total * self.total / self.total_sq
        } else {
            0.0
        }
    }

    pub fn add(&mut self, o: Seen) {
        self.open += o.open;
        self.total += o.total;
        self.total_sq += o.total_sq;
        self.rays += o.rays;
        self.blocker = o.blocker.or(self.blocker);
        self.starts.add(&o.starts);
    }
}

/// Where segments start: one point (position, normal, scene face), or stratified points of
/// a planar node.
#[derive(Clone, Copy)]
pub enum Start<'a> {
    Point(DVec3, DVec3, u32),
    Node(&'a Node),
}

/// The segments of strata `which` (of `k`) from `start` to node `s`, drawn from the stream
/// `seed` (a different seed gives independent strata); strata cast in several calls give
/// the same segments as one call for all of them. `blockers` holds every face that could
/// cross one (`Visibility::blockers`), or `None` for the BVH.
#[allow(clippy::too_many_arguments)]
pub fn seen_from(
    vis: &Visibility,
    table: &AreaTable,
    start: Start,
    s: &Node,
    blockers: Option<&[u32]>,
    k: u32,
    seed: u64,
    mut which: impl Iterator<Item = u32>,
) -> Seen {
    let h = vis.h;
    let face = match start {
        Start::Point(_, _, f) => f,
        Start::Node(r) => h.real_face(r.face),
    };
    let mut skip = [face, face];
    if s.is_planar() {
        skip[1] = h.real_face(s.face);
    }
    let mut out = Seen::default();
    if s.hi <= s.lo || matches!(start, Start::Node(r) if r.hi <= r.lo) {
        return out;
    }
    let centre = match start {
        Start::Node(r) => Some(r.centroid),
        Start::Point(..) => None,
    };
    let k = k.max(1);
    // The points first, then the rays: finding a point misses cache (the area table's
    // search, the corners, the vertices), and apart from the traversals the processor
    // overlaps those misses across points. In two rounds, all the searches and then all
    // the corners, so that no point's search waits behind another's corners.
    let mut draws = [Draw::default(); BATCH];
    let mut ends = [(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO); BATCH];
    // The face that blocked the last blocked segment, tried first on the next.
    let mut hint = None;
    loop {
        let mut m = 0;
        // The draws first: `zip` asks its first iterator first, and a stratum taken when
        // the batch is full would be lost.
        for (d, i) in draws.iter_mut().zip(which.by_ref()) {
            *d = segment_draw(table, start, s, k, i, seed);
            m += 1;
        }
        if m == 0 {
            break;
        }
        for (d, e) in draws[..m].iter().zip(ends.iter_mut()) {
            *e = segment_ends(vis, start, d);
        }
        for (&(p, n, y, ny), draw) in ends[..m].iter().zip(&draws[..m]) {
            let d = y - p;
            let (ca, cb) = (n.dot(d), -ny.dot(d));
            if !(ca > 0.0 && cb > 0.0) {
                continue;
            }
            let d2 = d.length_squared();
            let w = ca * cb / (d2 * d2) * vis.bright(s, draw.end.0);
            if !w.is_finite() {
                continue;
            }
            out.total += w;
            out.total_sq += w * w;
            out.rays += 1;
            let hit = vis.blocker(p, y, blockers, &skip, hint);
            if hit.is_none() {
                out.open += w;
            } else {
                hint = hit;
            }
            if let Some(c) = centre {
                out.starts.add_ray(w, p - c, hit.is_none());
            }
        }
    }
    out.blocker = hint;
    out
}

/// Segments whose ends `seen_from` finds before it casts them.
const BATCH: usize = 16;

/// Where `seen_from`'s `i`-th of `k` segments from `start` to `s` (stream `seed`) ends:
/// per end, the leaf position, the fraction of its area and the triangle coordinate
/// (`point_at`); the start's are unused from a point.
#[derive(Clone, Copy, Default)]
struct Draw {
    end: (u32, f64, f64),
    start: (u32, f64, f64),
}

fn segment_draw(table: &AreaTable, start: Start, s: &Node, k: u32, i: u32, seed: u64) -> Draw {
    let r = mix(seed ^ mix(i as u64 + 1));
    let (pos, t) = table.at(s, (i as f64 + unit(r)) / k as f64);
    let mut d = Draw {
        end: (pos, t, unit(mix(r))),
        start: (0, 0.0, 0.0),
    };
    if let Start::Node(rn) = start {
        // The start's strata in another order (7 is prime to the powers of two the
        // counts are), so that the pairs do not run side by side across the two nodes.
        let j = (i as u64 * 7 + 3) % k as u64;
        let q = mix(r ^ 0x5851_f42d_4c95_7f2d);
        let (pos, t) = table.at(rn, (j as f64 + unit(q)) / k as f64);
        d.start = (pos, t, unit(mix(q)));
    }
    d
}

/// The ends of the segment `d` draws: start point and normal, end point and normal.
fn segment_ends(vis: &Visibility, start: Start, d: &Draw) -> (DVec3, DVec3, DVec3, DVec3) {
    let (y, ny) = point_at(vis, d.end);
    let (p, n) = match start {
        Start::Point(p, n, _) => (p, n),
        Start::Node(_) => point_at(vis, d.start),
    };
    (p, n, y, ny)
}

/// The point of leaf position `pos` at the part `t` of its triangle's share of the area and
/// `v` its coordinates in the triangle, through the area-preserving square-to-triangle map,
/// with its leaf's normal (a back leaf faces the other way from its triangle).
fn point_at(vis: &Visibility, (pos, t, v): (u32, f64, f64)) -> (DVec3, DVec3) {
    let h = vis.h;
    let [a, b, c, leaf_face] = h.corners[pos as usize];
    let [a, b, c] = [a, b, c].map(|i| vis.el.positions[i as usize]);
    let st = t.sqrt();
    let y = a * (1.0 - st) + b * (st * (1.0 - v)) + c * (st * v);
    (y, vis.faces[leaf_face as usize].plane.n)
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn a_large_range_finds_the_position_a_plain_search_finds() {
        // Areas with runs of zeros (a stretch of no area, several equal starts), over many
        // blocks of three levels of the index.
        let area: Vec<f64> = (0..5000u64)
            .map(|i| {
                if i % 7 == 3 || (400..460).contains(&i) {
                    0.0
                } else {
                    0.1 + unit(mix(i))
                }
            })
            .collect();
        let t = AreaTable::of_areas(&area);
        assert_eq!(t.index.len(), 2);
        let plain =
            |lo: usize, hi: usize, x: f64| lo + t.cum[lo + 1..hi].partition_point(|&c| c <= x);
        let ranges = [
            (0, 1000),
            (3, 997),
            (130, 900),
            (390, 470),
            (400, 600),
            (0, 5000),
            (63, 4097),
        ];
        for (lo, hi) in ranges {
            let (a, b) = (t.cum[lo], t.cum[hi]);
            let mut xs: Vec<f64> = (0..2000u64)
                .map(|i| a + unit(mix(i ^ 77)) * (b - a))
                .collect();
            // The entries themselves (ties), the ends, and beyond them.
            xs.extend(t.cum[lo..=hi].iter().copied());
            xs.extend([a - 1.0, b + 1.0, f64::NAN]);
            for x in xs {
                assert_eq!(t.position(lo, hi, x), plain(lo, hi, x), "{lo}..{hi} at {x}");
            }
        }
    }
}

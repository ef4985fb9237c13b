//! Link refinement (Hanrahan, Salzman & Aupperle 1991, with clusters as Smits, Arvo &
//! Greenberg 1994): starting from the root linked to itself, a link is split, by splitting the
//! larger of its two nodes, while
//! - the two are in each other's near field (closer than twice their sizes added up) and
//!   the power is over `eps / NEAR_POWER` or either is a cluster, or
//! - the error it could make, `B_s · F · A_r · (size / distance)²` (the source's largest
//!   radiosity, a form factor that errs high, the receiver's area, and the relative error
//!   of a point-to-disc factor), is over `eps`, or
//! - a face lies in the shaft between them and the power is over `eps / PARTIAL`, or
//! - rays find it partly hidden and the power is over `eps / SHADOW` (then the receiver
//!   is split first: a shadow varies over it; but a cluster source before it, below), or
//! - rays find it partly hidden and the receiver holds leaves across a narrow gap
//!   (`Region::gap`) and leaves out of it (then the receiver is split).
//!
//! Otherwise the link is kept with its visibility, but for a faint near pair of faces: that
//! one is split on down to leaves, its parts linked with its visibility and no rays of their
//! own (`FAINT_SPLIT_POWER`). Pairs on one face and pairs wholly behind
//! either plane carry nothing and are dropped, and so are pairs whose rays were all blocked
//! (after `CONFIRM_RAYS` more, unless the face that blocked the first ray, or the convex
//! solid it bounds, hides the whole pair: `Visibility::covers`). A face
//! that blocked a pair's ray is handed down to the pairs it splits into, which it may hide
//! whole without a ray (a box between two walls' elements). Leaf pairs are kept whatever they
//! carry. The recursion forks with `rayon::join` and concatenates in a fixed order, so the
//! links are the same for any thread count.
//!
//! A link's visibility is never the fraction of the rays that decided to keep it: a pair is
//! split when one of its rays is blocked and kept when all pass, so kept pairs whose rays all
//! passed would take v = 1 for shafts that a thin blocker crosses (a table leg between two
//! walls' nodes) while the blocker takes its own share of the light: counted twice. Likewise
//! a pair dropped because its first rays were all blocked. Such pairs take their visibility
//! from a second, independent set of rays (`second_look`), stratified over both nodes' area.
//! Measured with every pair's visibility from 1024 such rays as the truth, kept pairs' first
//! rays were 2.1 % high over planar pairs and 15 % over cluster pairs (room-78, weighted by
//! power), the second look within 0.1 % and 0.4 %; pairs dropped on their first rays were on
//! average 12.5 % visible. The power a closed room absorbs, which must be what its light
//! emits, per channel: room-78 101.0–101.8 % → 99.4–99.5 %, the Cornell box closed by a
//! fifth wall 100.3–100.7 % → 99.7–99.9 % (the empty room 99.9 %: its interpolation).
//! A cluster source found partly hidden is split before its receiver: a cluster link sends
//! all its faces' light with one visibility, and in clutter the faces are hidden each in its
//! own way, mostly by the cluster's other faces (a box's top sees the ceiling whole, its
//! sides little of it past the boxes beside them). A sum per mesh of what the links deliver
//! from each node's radiosity, against what its leaves send (a throw-away build), found
//! room-78's clutter delivering 0.930 of its light (blue), its table 0.976 and its room
//! 0.9994; the largest box top sent 0.59 of its light to the room where rays from it found
//! 0.92. Split so, the clutter delivers 0.954 and the table 0.979, with fewer links (604k
//! against 622k), and with looks weighted by brightness (`Visibility::bright`) 0.959.
//!
//! A kept pair's second look casts at least `CONFIRM_RAYS`: with the 4 rays of a faint pair
//! it scattered the final gather (the floor under a table: worst vertex 0.114–0.128 over
//! five seeds, 0.117 with 16). Against Cycles (`scripts/bench_lib/per_mesh.py`): room-78
//! 3.80 → 3.75 %, room-245 6.96 → 6.17 %, data1 0.52 → 0.51 %, chair 0.50 → 0.50 %, cornell
//! 0.69 → 0.94 %: every face of the open Cornell box is now darker than Cycles, where the
//! excess had hidden that.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use super::from_point::{seen_from, AreaTable, Start};
use super::hierarchy::Node;
use super::link::{Ends, Factor, Link};
use super::visibility::Visibility;
use crate::geom::hash::mix;
use crate::progress::Progress;

/// Near field: nodes whose centroids are closer than this times the sum of their radii are
/// split down to leaves, whose factors are exact (`link::exact_pair`); a factor between
/// larger nodes that near would need sampling over the receiver, which cost most of the
/// refinement.
const NEAR: f64 = 2.0;
/// Near pairs carrying under `eps / NEAR_POWER` are not split as the others are: in clutter
/// most near pairs are small faces lit by little, and splitting them down to leaf pairs
/// that each cast rays and take the exact factor cost more than the rest of the solve.
const NEAR_POWER: f64 = 1024.0;
/// A faint near pair between two faces carrying over `eps / FAINT_SPLIT_POWER` is still
/// split down to leaves, but its parts take its visibility and the factor at their
/// receiver's centroid: no rays, no exact pair. Linked whole, such pairs gave the sides of
/// boxes standing close on a table the mean of a face's light that varies most near them
/// (room-78: 4.73 % from Cycles whole, 4.35 % split so, 4.41 % split with rays of their
/// own, which doubled room-828's refinement).
const FAINT_SPLIT_POWER: f64 = 65536.0;
/// Links whose shaft holds a listed blocker are split while their power exceeds
/// `eps / PARTIAL`.
const PARTIAL: f64 = 16.0;
/// Links found partly hidden by rays are split while their power exceeds `eps / SHADOW`.
const SHADOW: f64 = 256.0;
/// A pair whose first rays were all blocked casts this many more, its second look, before it
/// is dropped: through slats that hide 60 %, 4 rays are all blocked one time in
/// eight, 20 three times in 100,000, and a vertex whose final gather looks again at the links
/// that were kept could only lose the dropped ones' light (room-78: 5.99 % from Cycles
/// without the second look, 4.64 % with it). Such pairs used to be kept for the final
/// gather, where every leaf below screened each with 8 rays of its own: room-828 made 14M
/// such looks for 4.4M pairs; the second look here costs 16 rays per pair, and room-828's
/// final gather went from 91 to 42 s (room-78 4.65 % before, cornell 0.73 → 0.70 %).
const CONFIRM_RAYS: u32 = 16;
/// Pairs carrying under `eps / CONFIRM_POWER` are dropped on their first rays all blocked,
/// with no second look. In clutter most confirmed pairs are that faint and nearly all are
/// hidden indeed: room-828 confirmed 2.50M pairs, of which 565k carried under this, and the
/// light their second looks found adds up to 0.4 eps (by the links' power bound) of the
/// 151 eps found by all (throw-away counters). Dropping them spared 5.3M of its 41.4M rays
/// (T_link 25.3 → 21.2 s), and the error from Cycles (`per_mesh.py`) stayed: room-78
/// 2.99 → 2.98 %, room-245 5.20 → 5.21 %, cornell, chair and data1 unchanged. At
/// `eps / 4096`, room-78 went to 3.14 %.
const CONFIRM_POWER: f64 = 16384.0;
/// Points of a receiver at which the factor's spread over it is sampled.
const VARY_POINTS: u32 = 6;
/// Receivers over which a source's factor varies by more than this fraction of its value
/// at the centroid are split, for links carrying over `eps / VARY_POWER`.
const VARY_REL: f64 = 0.1;
const VARY_POWER: f64 = 64.0;
/// Sources whose first radiosity varies by more than `VARY_REL` are split for links
/// carrying over `eps / SOURCE_VARY_POWER` of that variation.
const SOURCE_VARY_POWER: f64 = 64.0;
/// Pairs with fewer leaves than this (receiver × source) are refined on one thread.
const SERIAL_BELOW: u64 = 1 << 12;
/// Links a thread keeps before it adds them to the shared count (`Refiner::publish`), which
/// the budget (`max_links`) is checked against: it may run over by this much per thread.
const PUBLISH_EVERY: u64 = 1024;

pub struct Refiner<'a> {
    pub vis: Visibility<'a>,
    /// Upper bound of each node's radiosity over the solve (summed over channels).
    pub b_max: &'a [f64],
    /// How much each node's first radiosity varies over it.
    pub b_range: &'a [f64],
    pub eps: f64,
    /// Rays for links carrying more than `eps` (leaf pairs in the near field).
    pub rays: u32,
    pub max_links: u64,
    pub progress: &'a Progress,
    links: AtomicU64,
    /// Area pairs settled (linked or dropped), as `f64` bits: progress over the total.
    settled: AtomicU64,
    total: f64,
    stop: AtomicBool,
    /// Per node: it holds leaves across a narrow gap (`Region::gap`) and leaves that are not.
    mixed: Vec<bool>,
    /// The area laid out along the leaf positions, for the second look's points.
    table: AreaTable,
}

pub struct Refined {
    pub links: Vec<Link>,
    /// Pairs from planar sources dropped because all their rays were blocked.
    pub dropped: u64,
    pub rays: u64,
    /// The link budget ran out (`max_links`).
    pub over_budget: bool,
}

impl<'a> Refiner<'a> {
    pub fn new(
        vis: Visibility<'a>,
        b_max: &'a [f64],
        b_range: &'a [f64],
        eps: f64,
        rays: u32,
        max_links: u64,
        progress: &'a Progress,
    ) -> Self {
        let total = vis.h.nodes.first().map_or(0.0, |n| n.area * n.area);
        let mixed = mixed_nodes(&vis);
        let table = AreaTable::new(vis.h);
        Refiner {
            table,
            vis,
            b_max,
            b_range,
            eps,
            rays,
            max_links,
            progress,
            links: AtomicU64::new(0),
            settled: AtomicU64::new(0f64.to_bits()),
            total,
            stop: AtomicBool::new(false),
            mixed,
        }
    }

    /// All links, from the root's link to itself.
    pub fn run(&self) -> Refined {
        let mut out = Out::default();
        if !self.vis.h.nodes.is_empty() {
            self.refine(0, 0, Given::default(), &mut out);
        }
        self.publish(&mut out);
        Refined {
            links: join_runs(out.links),
            dropped: out.dropped,
            rays: out.rays,
            over_budget: self.links.load(Ordering::Relaxed) > self.max_links,
        }
    }

    fn node(&self, i: u32) -> &Node {
        &self.vis.h.nodes[i as usize]
    }

    /// Counts a settled pair in `out`, which hands its counts on now and then (`publish`).
    fn settle(&self, r: &Node, s: &Node, out: &mut Out) {
        out.settled += r.area * s.area;
    }

    /// Hands `out`'s counts of settled area and links to the shared ones, and reports
    /// progress. Shared counters touched at every pair made the two threads fight over
    /// their cache line: `publish` runs once per `PUBLISH_EVERY` links of a thread.
    fn publish(&self, out: &mut Out) {
        if out.settled > 0.0 {
            let add = std::mem::take(&mut out.settled);
            let mut cur = self.settled.load(Ordering::Relaxed);
            loop {
                let next = (f64::from_bits(cur) + add).to_bits();
                match self.settled.compare_exchange_weak(
                    cur,
                    next,
                    Ordering::Relaxed,
                    Ordering::Relaxed,
                ) {
                    Ok(_) => break,
                    Err(c) => cur = c,
                }
            }
        }
        let n = std::mem::take(&mut out.unpublished);
        if n > 0 {
            self.links.fetch_add(n, Ordering::Relaxed);
        }
        let done = f64::from_bits(self.settled.load(Ordering::Relaxed));
        self.progress.set_fraction(done / self.total.max(1e-300));
        if self.progress.is_cancelled() {
            self.stop.store(true, Ordering::Relaxed);
        }
    }

    fn refine(&self, r: u32, s: u32, given: Given<'_>, out: &mut Out) {
        if self.stop.load(Ordering::Relaxed) {
            return;
        }
        let (rn, sn) = (self.node(r), self.node(s));
        if r == s {
            if rn.is_leaf() || rn.is_planar() {
                self.settle(rn, sn, out);
                return;
            }
            let [a, b] = rn.kids;
            return self.split(&[(a, a), (a, b), (b, a), (b, b)], given, out);
        }
        // A face's front and back (`back`) see nothing of each other either.
        let h = self.vis.h;
        if rn.is_planar() && h.real_face(rn.face) == h.real_face(sn.face) {
            self.settle(rn, sn, out);
            return;
        }
        let mut ends = Ends::new(h, self.vis.faces, r, s);
        ends.defer_exact = true;
        // Wholly behind either plane: nothing passes.
        let behind = |n: &Node, plane_node: &Node, normal: Option<glam::DVec3>| {
            normal.is_some_and(|nrm| {
                let c = plane_node.centroid;
                let lo = n.lo_box - c;
                let hi = n.hi_box - c;
                // Largest of nrm·(x − c) over the box.
                let top = nrm.x.max(0.0) * hi.x
                    + nrm.x.min(0.0) * lo.x
                    + nrm.y.max(0.0) * hi.y
                    + nrm.y.min(0.0) * lo.y
                    + nrm.z.max(0.0) * hi.z
                    + nrm.z.min(0.0) * lo.z;
                top <= 0.0
            })
        };
        if behind(sn, rn, ends.nr) || behind(rn, sn, ends.ns) {
            self.settle(rn, sn, out);
            return;
        }
        // Hidden whole by the face, or the solid, that hid a pair above it.
        if given.hint.is_some_and(|f| self.vis.covers(f, rn, sn)) {
            return self.hidden(rn, sn, out);
        }
        let both_leaves = rn.is_leaf() && sn.is_leaf();
        let dist = ends.offset().length();
        let near = dist < NEAR * (rn.radius() + sn.radius());
        let power = self.b_max[s as usize] * ends.factor_bound() * rn.area;
        let faint_split = near && !both_leaves && power > self.eps / FAINT_SPLIT_POWER;
        if let Some(v) = given.seen {
            if faint_split && !self.over_budget() {
                return self.split_larger(r, s, given, out);
            }
            self.settle(rn, sn, out);
            let link = ends.link(h, self.vis.el, r, s, v as f64, false, Factor::Centroid);
            return self.push(out, link, &ends);
        }
        // The point and disc estimates are off by about (size / distance)²: the error the
        // link would make, not the light it carries, decides.
        let spread = ((rn.radius() + sn.radius()) / dist.max(1e-300)).min(1.0);
        let error = power * spread * spread;
        let faint = power <= self.eps / NEAR_POWER;
        // A cluster's link gives all its faces one direction and distance, which in the
        // near field is wrong for most of them however little the pair carries (room-78's
        // boxes on their table: 4.73 → 4.50 % from Cycles split so).
        let planar = rn.is_planar() && sn.is_planar();
        let faint_near = near && faint && planar;
        let near = near && (!faint || !planar);
        if !both_leaves && (near || error > self.eps) && !self.over_budget() {
            return self.split_larger(r, s, given, out);
        }
        // The link gives every point of the receiver its mean factor: where the factor
        // varies over the receiver (a wall whose part by a corner sees less of the far
        // walls), the light it would misplace decides, not only what the mean misses.
        if !rn.is_leaf() && !self.over_budget() {
            if let (Some(nr), Some(ns)) = (ends.nr, ends.ns) {
                let f0 = super::link::far_factor(rn.centroid, nr, sn, ns);
                let vary = (0..VARY_POINTS)
                    .map(|i| {
                        let (x, _) = self.vis.sample(rn, i, VARY_POINTS, 0);
                        (super::link::far_factor(x, nr, sn, ns) - f0).abs()
                    })
                    .fold(0.0, f64::max);
                // Every source's factor falls off the same way towards a corner, so these
                // errors add up coherently over the links: bound each one's relative spread.
                let carried = self.b_max[s as usize] * f0 * rn.area;
                if vary > VARY_REL * f0 && carried > self.eps / VARY_POWER {
                    let [a, b] = rn.kids;
                    return self.split(&[(a, s), (b, s)], given, out);
                }
            }
        }
        // The source sends its mean radiosity times the share of its light that reaches the
        // receiver: where the radiosity varies over the source, the share does too. The
        // factor is taken from where the source is bright (`Hierarchy::weigh`), but that is a
        // guess made before the solve; where the variation carries much, split the source.
        if !sn.is_leaf() && !self.over_budget() {
            let carried = self.b_range[s as usize] * ends.factor_bound() * rn.area;
            if self.b_range[s as usize] > VARY_REL * self.b_max[s as usize]
                && carried > self.eps / SOURCE_VARY_POWER
            {
                let [a, b] = sn.kids;
                return self.split(&[(r, a), (r, b)], given, out);
            }
        }
        // A faint pair is never split, so its shaft list would only spare it a few rays;
        // in clutter most shaft queries give up past their cap anyway (room-245: 2.1M of
        // 2.9M), and the query costs more than the rays. Nor is a pair queried whose shaft
        // lies in that of a pair above that gave up: the candidates thin out slowly as the
        // nodes halve, and those queries were a third of room-8328's refinement.
        let blockers = match given.blockers {
            Some(l) => Some(self.vis.blockers_among(rn, sn, l)),
            None if faint || given.crowded => None,
            None => self.vis.blockers(rn, sn),
        };
        let crowded = given.crowded || (!faint && given.blockers.is_none() && blockers.is_none());
        // A shaft with something in it is treated as partly blocked without a ray: a few
        // rays can miss a small blocker near one end (a leg under a seat).
        let listed = blockers.as_ref().is_some_and(|l| !l.is_empty());
        // Known to hold nothing: the shaft query found no face in it.
        let clear = blockers.as_ref().is_some_and(|l| l.is_empty());
        if listed && !both_leaves && power > self.eps / PARTIAL && !self.over_budget() {
            let given = Given::new(blockers.as_deref(), given.hint, false);
            return self.split_larger(r, s, given, out);
        }
        // Something may be in the way of a link carrying much: sample it more densely.
        let rays = if error > self.eps / 4.0 { self.rays } else { 4 };
        // A pair that any blocked segment would split needs no more rays after the first.
        let splits = !both_leaves && power > self.eps / SHADOW;
        let look = self
            .vis
            .fraction_among(rn, sn, blockers.as_deref(), rays, splits);
        let (mut v, mut cast) = (look.open, look.cast);
        // A face that blocked the first rays may hide the whole pair (a box between two
        // others): then it is fully blocked, with no second look and nothing to split.
        let covered = v == 0.0
            && look
                .blocker
                .is_some_and(|f| given.hint != Some(f) && self.vis.covers(f, rn, sn));
        // A few rays all blocked may have missed a gap (see `CONFIRM_RAYS`): the second
        // look alone says how much. A pair that splits on any blocked ray needs none, nor
        // one too faint for what a gap could pass to matter (`CONFIRM_POWER`).
        if v == 0.0 && !covered && cast > 0 && !splits && power > self.eps / CONFIRM_POWER {
            let (open, more) = self.second_look(r, s, blockers.as_deref(), CONFIRM_RAYS);
            (v, cast) = (open.unwrap_or(0.0), cast + more);
        }
        if cast > 0 {
            out.rays += cast as u64;
        }
        // Partly hidden: the shadow varies over the receiver, and a mean over it would
        // light its dark part (the seat right above a leg). Split the receiver first; but
        // a cluster source before it (see the module doc).
        if v < 1.0 && (v > 0.0 || cast > 0) && !covered && splits && !self.over_budget() {
            let given = Given::new(blockers.as_deref(), look.blocker.or(given.hint), crowded);
            if !sn.is_planar() {
                let [a, b] = sn.kids;
                return self.split(&[(r, a), (r, b)], given, out);
            }
            return if rn.is_leaf() {
                self.split_larger(r, s, given, out)
            } else {
                let [a, b] = rn.kids;
                self.split(&[(a, s), (b, s)], given, out)
            };
        }
        // A receiver that holds part of a narrow gap and more, partly hidden from the
        // source, sees it from its part in the gap only through the gap's mouth: its mean
        // lit the gap from outside, and the facing parts passed that back and forth
        // (room-245, two boxes' sides 3 mm apart: 0.72 deep in the gap, 0.47 split so;
        // error from Cycles 7.15 → 6.96 %, room-78 3.83 → 3.80 %, 3 % more links). Only
        // the receiver is split, down to the nodes that are wholly in the gap or out of it.
        // Rays that all got through do not say the gap sees the source: it is a small part
        // of such a receiver, and the face across it hides most of the source from it. So
        // unless the shaft is known clear, such a receiver is split as well (room-245, gap
        // leaves at `hierarchy::GAP_WIDTHS`: 0.31 of the light beside the slot deep in it
        // with rays in part only, 0.12 so; Cycles under 0.1).
        if v > 0.0
            && (v < 1.0 || !clear)
            && self.mixed[r as usize]
            && power > self.eps / FAINT_SPLIT_POWER
            && !self.over_budget()
        {
            let given = Given::new(blockers.as_deref(), look.blocker.or(given.hint), crowded);
            let [a, b] = rn.kids;
            return self.split(&[(a, s), (b, s)], given, out);
        }
        if v > 0.0 && faint_near && faint_split && !self.over_budget() {
            let mut given = Given::new(None, look.blocker.or(given.hint), crowded);
            given.seen = Some(v as f32);
            return self.split_larger(r, s, given, out);
        }
        // Kept because its rays all passed: see the module doc (and why at least
        // `CONFIRM_RAYS`).
        if v == 1.0 && cast > 0 && splits && !clear {
            let (open, more) = self.second_look(r, s, blockers.as_deref(), rays.max(CONFIRM_RAYS));
            v = open.unwrap_or(v);
            out.rays += more as u64;
        }
        self.settle(rn, sn, out);
        if v == 0.0 {
            if cast > 0 && sn.is_planar() {
                out.dropped += 1;
            }
            return;
        }
        let factor = if faint { Factor::Near } else { Factor::Sampled };
        let link = ends.link(h, self.vis.el, r, s, v, clear, factor);
        self.push(out, link, &ends);
    }

    /// Keeps `link` unless nothing can pass between its `ends`, and reports progress now
    /// and then.
    fn push(&self, out: &mut Out, link: Link, ends: &Ends<'_>) {
        if !(link.k > 0.0 || ends.factor_bound() > 0.0) {
            return;
        }
        match out.links.last_mut() {
            Some(run) => run.push(link),
            None => out.links.push(vec![link]),
        }
        out.unpublished += 1;
        if out.unpublished >= PUBLISH_EVERY {
            self.publish(out);
        }
    }

    /// The visibility of the pair (`r`, `s`) by `k` segments independent of the rays that
    /// decided its fate, from strata of both nodes' area jittered by a hash of the pair
    /// (the same for any thread count; `None` where no segment's ends faced each other);
    /// with the segments cast.
    fn second_look(&self, r: u32, s: u32, blockers: Option<&[u32]>, k: u32) -> (Option<f64>, u32) {
        let (rn, sn) = (self.node(r), self.node(s));
        let seed = mix(((r as u64) << 32 | s as u64) ^ 0x5ec0_d100_c0ff_ee00);
        let seen = seen_from(
            &self.vis,
            &self.table,
            Start::Node(rn),
            sn,
            blockers,
            k,
            seed,
            0..k.max(1),
        );
        (seen.fraction(), seen.rays)
    }

    /// Settles a pair that nothing passes between.
    fn hidden(&self, rn: &Node, sn: &Node, out: &mut Out) {
        self.settle(rn, sn, out);
        if sn.is_planar() {
            out.dropped += 1;
        }
    }

    fn over_budget(&self) -> bool {
        let over = self.links.load(Ordering::Relaxed) > self.max_links;
        if over {
            self.stop.store(true, Ordering::Relaxed);
        }
        over
    }

    fn split_larger(&self, r: u32, s: u32, given: Given<'_>, out: &mut Out) {
        let (rn, sn) = (self.node(r), self.node(s));
        let split_r = !rn.is_leaf() && (sn.is_leaf() || rn.area >= sn.area);
        if split_r {
            let [a, b] = rn.kids;
            self.split(&[(a, s), (b, s)], given, out)
        } else {
            let [a, b] = sn.kids;
            self.split(&[(r, a), (r, b)], given, out)
        }
    }

    /// Refines `pairs` into `out` in their order, in parallel when they are large.
    fn split(&self, pairs: &[(u32, u32)], given: Given<'_>, out: &mut Out) {
        let size = |&(r, s): &(u32, u32)| {
            let (a, b) = (self.node(r), self.node(s));
            (a.hi - a.lo) as u64 * (b.hi - b.lo) as u64
        };
        if pairs.len() < 2 || pairs.iter().map(size).sum::<u64>() < SERIAL_BELOW {
            for &(r, s) in pairs {
                self.refine(r, s, given, out);
            }
            return;
        }
        let (a, b) = pairs.split_at(pairs.len() / 2);
        let (la, lb) = rayon::join(
            || {
                let mut v = Out::default();
                self.split(a, given, &mut v);
                v
            },
            || {
                let mut v = Out::default();
                self.split(b, given, &mut v);
                v
            },
        );
        for mut part in [la, lb] {
            // A run grows by doubling; one that no longer grows gives back its slack.
            if let Some(run) = part.links.last_mut() {
                run.shrink_to_fit();
            }
            out.links.extend(part.links);
            out.dropped += part.dropped;
            out.rays += part.rays;
            out.settled += part.settled;
            out.unpublished += part.unpublished;
        }
    }
}

/// The runs laid end to end, each freed once copied (a copy of all of them at once would
/// hold every link twice).
fn join_runs(runs: Vec<Vec<Link>>) -> Vec<Link> {
    let mut all = Vec::with_capacity(runs.iter().map(Vec::len).sum());
    for run in runs {
        all.extend(run);
    }
    all
}

/// What a pair is handed from the pair it was split from.
#[derive(Clone, Copy, Default)]
struct Given<'b> {
    /// Every face that could block it, when known (`Visibility::blockers_among`).
    blockers: Option<&'b [u32]>,
    /// A face that blocked a segment of the pair above (which may hide this one whole).
    hint: Option<u32>,
    /// The shaft query of a pair above gave up (`Visibility::blockers` past its cap).
    crowded: bool,
    /// The visibility of a faint near pair above, which its parts take without rays.
    seen: Option<f32>,
}

impl<'b> Given<'b> {
    fn new(blockers: Option<&'b [u32]>, hint: Option<u32>, crowded: bool) -> Self {
        Given {
            blockers,
            hint,
            crowded,
            seen: None,
        }
    }
}

/// What a refinement (or one branch of it) made, in refinement order.
#[derive(Default)]
pub struct Out {
    /// In runs, in order: a branch's runs are moved to its parent's list, not copied into
    /// its vector at every level of the recursion.
    links: Vec<Vec<Link>>,
    dropped: u64,
    rays: u64,
    /// Settled area and links not yet added to the shared counts (`Refiner::publish`).
    settled: f64,
    unpublished: u64,
}

/// Nodes that hold both leaves across a narrow gap and leaves that are not (a leaf lies in
/// one region, so it is one or the other).
fn mixed_nodes(vis: &Visibility) -> Vec<bool> {
    let (h, el) = (vis.h, vis.el);
    let mut kinds = vec![0u8; h.nodes.len()];
    for i in (0..h.nodes.len()).rev() {
        let n = &h.nodes[i];
        kinds[i] = if n.is_leaf() {
            let t = h.order[n.lo as usize] as usize;
            let gap = el
                .regions
                .get(el.tri_region[t] as usize)
                .is_some_and(|r| r.gap.is_some());
            if gap {
                1
            } else {
                2
            }
        } else {
            kinds[n.kids[0] as usize] | kinds[n.kids[1] as usize]
        };
    }
    kinds.into_iter().map(|k| k == 3).collect()
}

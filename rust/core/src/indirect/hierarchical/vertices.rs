//! From the solution to element vertices. A leaf holds one value, and a link pushed down
//! from a large node gives all its leaves the value at that node's centroid: near another
//! face (a room's edge, a leg under a seat) that is off at first order. So each vertex
//! gathers again (a final gather): every link on the way from the root to one of its leaves,
//! with the factor from the vertex itself to the link's source, the link's visibility and the
//! source's final radiosity. Those links cover every source once.
//!
//! A link's visibility is a mean over its receiver, and where something stands between the
//! two (`Link::clear` false) a point may see more or less of the source than that: under a
//! table, a floor node reaching out past its edge sees the ceiling through the table top at
//! the mean (the floor under a table was 5.5–7.7 % too bright). Each such link from a planar
//! source errs at most by what it carries times max(v, 1 − v), and those errors add up over
//! many links with one sign (all of them see the table). So the final gather looks again,
//! in two steps:
//! - each leaf, for the links above it, the largest possible errors first until what is left
//!   is under `VISIBILITY_SCALE × convergence` of the indirect light at its centroid: rays
//!   between stratified points of the leaf and of the source (`from_point`), screened by a
//!   few when the link's own rays all agreed. Where they found the source in part, a plane
//!   fitted to where they got through gives the visibility's slope over the leaf
//!   (`own_look::slope`), which its vertices take in place of the leaf's mean;
//! - each vertex, for the links whose source the leaf saw in part (a shadow's edge crosses
//!   the leaf), by that budget of all its light: rays from the vertex itself; on a leaf with
//!   many vertices, only a few spread over it (`ANCHORS`), the others interpolating what
//!   theirs differ from the slope.
//!
//! A look replaces the mean only where it differs by more than its own noise
//! (`own_visibility`), so that rays through regular blockers (slats) do not scatter
//! neighbouring vertices about a mean that was right. Pairs whose rays were all blocked are
//! not links, so a vertex that saw more than its links' means could only lose light: that is
//! why refinement looks twice before it drops one (`refine::CONFIRM_RAYS`).
//! Cluster sources keep their links' means: a point that sees less of a cluster's far side
//! sees more of its near side, and a fraction of the whole says nothing of which.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;
use rayon::prelude::*;

use super::from_point::{seen_from, AreaTable, Start};
use super::hierarchy::{Hierarchy, NONE};
use super::link::{planar_gather, point_coefficient};
use super::own_look::{by_error, inverse_square, own_visibility, slope, spread, Slope};
use super::solve::{Gathering, Radiosity, Solver};
use super::visibility::Visibility;
use crate::geom::hash::{mix, IdMap};
use crate::mesh::elements::Elements;
use crate::scene::Face;

/// Rays that screen a link whose own rays all agreed (v = 0 or 1): a vertex whose rays all
/// agree too keeps the link's value.
pub(super) const SCREEN_RAYS: u32 = 8;
/// Vertices of a leaf that look at its sources themselves (spread over it); the others take
/// their visibilities interpolated from these (inverse square distance). A leaf holds about
/// 20 vertices where direct light's refinement made many (room-245: 217k vertices on 10.7k
/// leaves), and looking from each cost 44M of room-245's 90M rays; with 6 the final gather
/// took 7.9 s instead of 12.2 s, and the error from Cycles went 4.54 → 4.58 % on room-78
/// (10: 4.57 %), cornell unchanged at 0.70 %.
const ANCHORS: usize = 6;
/// `Gather::smooth` gives up where links whose mean visibility lies between `PARTLY` and
/// 1 − `PARTLY` bring over `PARTLY_SHARE` of the light.
const PARTLY: f64 = 0.02;
const PARTLY_SHARE: f64 = 0.25;

/// A point where the final gather is wanted besides the vertices (`subdivide`): where it is
/// evaluated and faces, and on which leaf.
pub struct Point {
    pub p: DVec3,
    pub n: DVec3,
    pub leaf: u32,
}

impl<'a> Gather<'a> {
    /// `direct` is the direct irradiance per vertex, and `tolerance` the share of a
    /// vertex's light (of a leaf's indirect light) it may leave to its links' mean
    /// visibilities.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        h: &'a Hierarchy,
        faces: &'a [Face],
        el: &'a Elements,
        g: &'a Gathering,
        solver: &'a Solver<'a>,
        b: &'a Radiosity,
        vis: &'a Visibility<'a>,
        direct: &'a [DVec3],
        tolerance: f64,
    ) -> Self {
        let mut parent = vec![NONE; h.nodes.len()];
        for (i, n) in h.nodes.iter().enumerate() {
            if !n.is_leaf() {
                parent[n.kids[0] as usize] = i as u32;
                parent[n.kids[1] as usize] = i as u32;
            }
        }
        Gather {
            h,
            faces,
            el,
            g,
            solver,
            b,
            vis,
            direct,
            tolerance,
            table: AreaTable::new(h),
            parent,
            rays: AtomicU64::new(0),
        }
    }

    /// Visibility rays the final gather has cast so far (segments whose ends faced each
    /// other; the same count for any thread count).
    pub fn rays(&self) -> u64 {
        self.rays.load(Ordering::Relaxed)
    }

    /// Leaf nodes and their ancestors, from the leaf up.
    fn chain(&self, leaf: u32) -> Vec<u32> {
        let mut chain = Vec::new();
        let mut a = leaf;
        while a != NONE {
            chain.push(a);
            a = self.parent[a as usize];
        }
        chain
    }

    /// The leaf node each vertex is gathered on (its first triangle's), or `NONE`.
    pub fn leaf_of(&self) -> Vec<u32> {
        let (h, el) = (self.h, self.el);
        let mut leaf_of = vec![NONE; el.positions.len()];
        for (pos, &t) in h.order.iter().enumerate() {
            // Backs of thin faces (`back`) share the front's triangles but not its vertices.
            if h.is_back(h.nodes[h.leaf_node[pos] as usize].face) {
                continue;
            }
            for &v in &el.triangles[t as usize] {
                if leaf_of[v as usize] == NONE {
                    leaf_of[v as usize] = h.leaf_node[pos];
                }
            }
        }
        leaf_of
    }

    /// Indirect irradiance at every element vertex by a final gather over the links `g`;
    /// vertices on no leaf (under a cover) get 0. Also each gathered leaf's look, for
    /// points on it later (`looked`), and each vertex's smooth value on that leaf.
    pub fn vertices(&self) -> AtVertices {
        let nv = self.el.positions.len();
        // The vertices of each leaf, in index order: they share the links above the leaf,
        // and the shafts from the leaf to those links' sources.
        let by_leaf = self.by_leaf();
        let groups: Vec<&[(u32, u32)]> = by_leaf.chunk_by(|x, y| x.0 == y.0).collect();
        let per_leaf: Vec<(Vec<(u32, DVec3, Option<DVec3>)>, LeafLook)> = groups
            .par_iter()
            .map(|grp| self.leaf(grp[0].0, &self.chain(grp[0].0), grp))
            .collect();
        let mut out = AtVertices {
            irradiance: vec![DVec3::ZERO; nv],
            looks: IdMap::with_capacity_and_hasher(groups.len(), Default::default()),
            smooth: vec![DVec3::NAN; nv],
        };
        for (grp, (vals, look)) in groups.iter().zip(per_leaf) {
            for (v, e, m) in vals {
                out.irradiance[v as usize] = e;
                out.smooth[v as usize] = m.unwrap_or(DVec3::NAN);
            }
            out.looks.insert(grp[0].0, look);
        }
        out
    }

    /// Indirect irradiance at `points` with their links' mean visibilities (no rays): smooth
    /// over a leaf, so that differences between such values show how the light curves, not
    /// the noise of rays. `None` where links seen in part (`PARTLY`) bring more than
    /// `PARTLY_SHARE` of the light: there a mean says little of a point (a slot between two
    /// boxes, lit by means over its mouth).
    pub fn smooth(&self, points: &[Point]) -> Vec<Option<DVec3>> {
        self.leaf_by_leaf(points, None, |_, chain, q| {
            let unsure = self.means(chain);
            q.map(|q| {
                self.gathered_at(q.p, q.n, chain, &unsure, |_, _| 0.0)
                    .smooth()
            })
            .collect()
        })
    }

    /// `f(leaf, its chain, its points)` for the leaf of each of `points` (on all threads):
    /// the points of a leaf share its links, found once. The values `f` gives, in the
    /// order of `points`.
    fn leaf_by_leaf<'p, T: Copy + Send + Sync>(
        &self,
        points: &'p [Point],
        fill: T,
        f: impl Fn(u32, &[u32], &mut dyn Iterator<Item = &'p Point>) -> Vec<T> + Sync,
    ) -> Vec<T> {
        let mut by_leaf: Vec<(u32, u32)> = (0..points.len() as u32)
            .map(|i| (points[i as usize].leaf, i))
            .collect();
        by_leaf.sort_unstable();
        let groups: Vec<&[(u32, u32)]> = by_leaf.chunk_by(|x, y| x.0 == y.0).collect();
        let per_leaf: Vec<Vec<T>> = groups
            .par_iter()
            .map(|grp| {
                let leaf = grp[0].0;
                let mut q = grp.iter().map(|&(_, i)| &points[i as usize]);
                f(leaf, &self.chain(leaf), &mut q)
            })
            .collect();
        let mut out = vec![fill; points.len()];
        for (grp, vals) in groups.iter().zip(per_leaf) {
            for (&(_, i), e) in grp.iter().zip(vals) {
                out[i as usize] = e;
            }
        }
        out
    }
}

/// A leaf's look at the links above it, as the final gather made it (`Gather::leaf`):
/// the visibilities the leaf found in place of its unsure links' means (index among them,
/// visibility, whether its rays found the source in part), and where it found some in
/// part, its anchors' own for those (as `offsets` makes them) and the slopes its rays
/// showed. Points on the leaf take those interpolated (`Gather::looked`) without casting
/// rays; a leaf with no look keeps its links' means.
/// Kept from the gather itself: made again with its rays, they were 18 % of room-78's
/// bake (perf samples).
#[derive(Default)]
pub struct LeafLook {
    /// Boxed, so without the slack of a vector grown by doubling: every leaf keeps its look
    /// to the end of `subdivide`, where room-8328's memory peaks.
    changed: Box<[(u32, f64, bool)]>,
    /// The slopes among them (`Unsure::slope`), apart: most changed links have none.
    slopes: Box<[(u32, Slope)]>,
    anchors: Vec<(DVec3, Vec<f64>)>,
    /// `Gather::partly_seen` of the leaf, where the look gathered at its centre (it does
    /// where a link's visibility is a mean).
    pub partly: Option<bool>,
}

impl LeafLook {
    /// What the leaf's look at its `unsure` links and its `anchors` (position, and the
    /// visibility each used for every unsure link) keep of it, and whether it is `partly`
    /// seen.
    fn keep(
        unsure: &[Unsure],
        partly: Option<bool>,
        anchors: impl Iterator<Item = (DVec3, Vec<f64>)>,
    ) -> Self {
        // A look that kept its link's mean changes nothing for `looked`: not kept.
        let changed = unsure
            .iter()
            .enumerate()
            .filter(|(_, u)| u.blockers.is_some() && (u.v != u.mean || u.varies))
            .map(|(i, u)| (i as u32, u.v, u.varies))
            .collect::<Box<_>>();
        let slopes = unsure
            .iter()
            .enumerate()
            .filter_map(|(i, u)| Some((i as u32, u.slope?)))
            .collect::<Box<_>>();
        let anchors = if unsure.iter().any(|u| u.varies) {
            let varied: Vec<&Unsure> = unsure.iter().filter(|u| u.varies).collect();
            let own = anchors.map(|(p, own)| {
                let own = own.iter().zip(unsure).filter(|(_, u)| u.varies);
                (p, own.map(|(&o, _)| o).collect())
            });
            offsets(&varied, own)
        } else {
            Vec::new()
        };
        LeafLook {
            changed,
            slopes,
            anchors,
            partly,
        }
    }
}

/// The final gather at the element vertices (`Gather::vertices`).
pub struct AtVertices {
    /// Indirect irradiance per vertex.
    pub irradiance: Vec<DVec3>,
    /// Each gathered leaf's look.
    pub looks: IdMap<u32, LeafLook>,
    /// Each vertex's smooth value (`Gather::smooth`) on the leaf it was gathered on, at the
    /// point the gather placed it; NaN where the means cannot judge or on no leaf. Made from
    /// the factors the gather found anyway: `subdivide` asks for these at most of its edges'
    /// ends, and gathering them again was a fifth of its smooth points (room-245).
    pub smooth: Vec<DVec3>,
}

/// What a gather over a leaf's links finds at a point (`Gather::gathered_at`).
struct Gathered {
    /// Irradiance with the visibilities given.
    e: DVec3,
    /// The error of each unsure link, by the caller's measure.
    errs: Vec<f64>,
    /// Irradiance with the links' mean visibilities, summed in the same order, so that it
    /// is bit for bit what a gather given the means finds.
    mean: DVec3,
    /// What links seen in part (mean visibility between `PARTLY` and 1 − `PARTLY`) bring
    /// to `mean`, channels summed.
    partly: f64,
}

impl Gathered {
    /// The smooth value: the irradiance with the means, unless links seen in part bring
    /// over `PARTLY_SHARE` of it.
    fn smooth(&self) -> Option<DVec3> {
        (self.partly <= PARTLY_SHARE * self.mean.element_sum()).then_some(self.mean)
    }
}

impl Gather<'_> {
    /// Each gathered vertex's leaf and the vertex, sorted: the leaf's vertices in the order
    /// the final gather took them (`vertices`).
    fn by_leaf(&self) -> Vec<(u32, u32)> {
        let leaf_of = self.leaf_of();
        let mut by_leaf: Vec<(u32, u32)> = (0..leaf_of.len() as u32)
            .filter(|&v| leaf_of[v as usize] != NONE)
            .map(|v| (leaf_of[v as usize], v))
            .collect();
        by_leaf.sort_unstable();
        by_leaf
    }

    /// Whether links seen in part bring over `PARTLY_SHARE` of the light at the centre of
    /// `leaf`: `smooth` gives up there, or nearly.
    pub fn partly_seen(&self, leaf: u32) -> bool {
        let node = &self.h.nodes[leaf as usize];
        let q = Point {
            p: node.centroid,
            n: self.faces[node.face as usize].plane.n,
            leaf,
        };
        self.smooth(std::slice::from_ref(&q))[0].is_none()
    }

    /// Indirect irradiance at `points` with their leaves' visibilities (`looks`; a leaf
    /// with none keeps its links' means), and its anchors' interpolated by inverse square
    /// distance where they differ over it: no new rays, and the values the final gather
    /// would give a vertex there that is not an anchor. The points are taken leaf by leaf,
    /// each leaf's links once.
    pub fn looked(&self, looks: &IdMap<u32, LeafLook>, points: &[Point]) -> Vec<DVec3> {
        let none = LeafLook::default();
        self.leaf_by_leaf(points, DVec3::ZERO, |leaf, chain, q| {
            let look = looks.get(&leaf).unwrap_or(&none);
            let mut unsure = self.means(chain);
            for &(i, v, varies) in look.changed.iter() {
                (unsure[i as usize].v, unsure[i as usize].varies) = (v, varies);
            }
            for &(i, slope) in look.slopes.iter() {
                unsure[i as usize].slope = Some(slope);
            }
            let varied: Vec<&Unsure> = unsure.iter().filter(|u| u.varies).collect();
            q.map(|q| self.looked_at(look, chain, &unsure, &varied, q))
                .collect()
        })
    }

    /// `looked` at one point `q` of the leaf of `look`, whose ancestors are `chain` and
    /// unsure links `unsure` (those whose source it saw in part, `varied`), with the look's
    /// visibilities.
    fn looked_at(
        &self,
        look: &LeafLook,
        chain: &[u32],
        unsure: &[Unsure],
        varied: &[&Unsure],
        q: &Point,
    ) -> DVec3 {
        let mut xs = Vec::with_capacity(unsure.len());
        let mut e = self
            .gathered_at(q.p, q.n, chain, unsure, |_, x| {
                xs.push(x);
                0.0
            })
            .e;
        if look.anchors.is_empty() {
            return e;
        }
        let mut own = vec![0.0; look.anchors[0].1.len()];
        interpolated(varied, q.p, &look.anchors, &mut own);
        let varied = unsure.iter().zip(xs).filter(|(u, _)| u.varies);
        for ((u, x), o) in varied.zip(own) {
            e += x * (o - u.v);
        }
        e
    }
}

pub struct Gather<'a> {
    h: &'a Hierarchy,
    faces: &'a [Face],
    el: &'a Elements,
    g: &'a Gathering,
    solver: &'a Solver<'a>,
    b: &'a Radiosity,
    vis: &'a Visibility<'a>,
    direct: &'a [DVec3],
    tolerance: f64,
    table: AreaTable,
    parent: Vec<u32>,
    /// Rays cast so far (`rays`).
    rays: AtomicU64,
}

/// A link above a leaf from a planar source whose visibility is a mean (`Link::clear`
/// false).
struct Unsure {
    source: u32,
    /// The link's visibility, and the leaf's own where it looked.
    v: f64,
    /// The link's visibility.
    mean: f64,
    /// The leaf's rays found the source in part: its vertices may differ.
    varies: bool,
    /// What may stand between the leaf and the source (`Visibility::blockers`), once found.
    blockers: Option<Option<Vec<u32>>>,
    /// How `v` changes over the leaf, where its rays showed that (`own_look::slope`).
    slope: Option<Slope>,
}

impl Unsure {
    /// The visibility at `p` of the leaf before a look of its own: `v`, or on its slope.
    fn base(&self, p: DVec3) -> f64 {
        self.slope.map_or(self.v, |s| s.at(self.v, p))
    }
}

/// The anchors' own visibilities of `links` (position, one per link) as `interpolated`
/// takes them: where a link has a slope, less what all the links' slopes give there
/// (`Unsure::base`), so that the slopes, not the anchors, carry how the visibility runs
/// across the leaf. Made once per leaf.
fn offsets(
    links: &[&Unsure],
    anchors: impl Iterator<Item = (DVec3, Vec<f64>)>,
) -> Vec<(DVec3, Vec<f64>)> {
    if !links.iter().any(|u| u.slope.is_some()) {
        return anchors.collect();
    }
    anchors
        .map(|(p, mut f)| {
            f.iter_mut().zip(links).for_each(|(x, u)| *x -= u.base(p));
            (p, f)
        })
        .collect()
}

/// The visibilities of `links` at `at` (into `own`) that the anchors' `offsets` give:
/// theirs interpolated by inverse square distance, on the links' slopes where any has one.
fn interpolated(links: &[&Unsure], at: DVec3, offsets: &[(DVec3, Vec<f64>)], own: &mut [f64]) {
    inverse_square(at, offsets.iter().map(|(p, f)| (*p, &f[..])), own);
    if links.iter().any(|u| u.slope.is_some()) {
        own.iter_mut()
            .zip(links)
            .for_each(|(x, u)| *x += u.base(at));
    }
}

impl Gather<'_> {
    fn links(&self, g: &Gathering, a: u32) -> std::ops::Range<usize> {
        g.start[a as usize] as usize..g.start[a as usize + 1] as usize
    }

    /// What the planar source `s` gives the point `p` (normal `n`) unhidden.
    fn unhidden(&self, p: DVec3, n: DVec3, s: u32) -> DVec3 {
        let ns = self.faces[self.h.nodes[s as usize].face as usize].plane.n;
        planar_gather(self.h, self.el, p, n, s, ns, &self.b.mean)
    }

    /// Irradiance at the vertices `verts` (leaf, vertex) of `leaf`, whose ancestors from
    /// itself up are `chain`: first the leaf looks at the links it is least sure of, then
    /// each vertex at those the leaf found in part.
    fn leaf(
        &self,
        leaf: u32,
        chain: &[u32],
        verts: &[(u32, u32)],
    ) -> (Vec<(u32, DVec3, Option<DVec3>)>, LeafLook) {
        // Rays counted here and added to the shared count once per leaf: an atomic add per
        // look made the two threads pass its cache line back and forth.
        let mut rays = 0;
        let (unsure, partly) = self.look(leaf, chain, &mut rays);
        let pos: Vec<DVec3> = verts
            .iter()
            .map(|&(_, v)| self.el.positions[v as usize])
            .collect();
        if verts.len() <= ANCHORS || !unsure.iter().any(|u| u.varies) {
            let (out, own): (Vec<(u32, DVec3, Option<DVec3>)>, Vec<Vec<f64>>) = verts
                .iter()
                .map(|&(_, v)| {
                    let (e, m, own) = self.at(v, leaf, chain, &unsure, &mut rays);
                    ((v, e, m), own)
                })
                .unzip();
            self.rays.fetch_add(rays, Ordering::Relaxed);
            let look = LeafLook::keep(&unsure, partly, pos.into_iter().zip(own));
            return (out, look);
        }
        let anchors = spread(&pos, ANCHORS);
        let mut out: Vec<(u32, DVec3, Option<DVec3>)> =
            verts.iter().map(|&(_, v)| (v, DVec3::ZERO, None)).collect();
        let mut seen: Vec<Vec<f64>> = Vec::with_capacity(anchors.len());
        for &i in &anchors {
            let (e, m, own) = self.at(verts[i].1, leaf, chain, &unsure, &mut rays);
            (out[i].1, out[i].2) = (e, m);
            seen.push(own);
        }
        let mut own = vec![0.0; unsure.len()];
        let links: Vec<&Unsure> = unsure.iter().collect();
        let from = anchors.iter().zip(&seen).map(|(&j, f)| (pos[j], f.clone()));
        let off = offsets(&links, from);
        for (i, &(_, v)) in verts.iter().enumerate() {
            if anchors.contains(&i) {
                continue;
            }
            interpolated(&links, pos[i], &off, &mut own);
            (out[i].1, out[i].2) = self.between(v, leaf, chain, &unsure, &own);
        }
        self.rays.fetch_add(rays, Ordering::Relaxed);
        let anchors = anchors.iter().map(|&j| pos[j]).zip(seen);
        let look = LeafLook::keep(&unsure, partly, anchors);
        (out, look)
    }

    /// The links above a leaf (ancestors `chain`) whose visibility is a mean, with their
    /// links' means.
    fn means(&self, chain: &[u32]) -> Vec<Unsure> {
        let (h, g) = (self.h, self.g);
        let mut unsure: Vec<Unsure> = Vec::new();
        for &a in chain {
            for l in &g.links[self.links(g, a)] {
                if !l.clear && h.nodes[l.source as usize].is_planar() {
                    unsure.push(Unsure {
                        source: l.source,
                        v: l.v as f64,
                        mean: l.v as f64,
                        varies: false,
                        blockers: None,
                        slope: None,
                    });
                }
            }
        }
        unsure
    }

    /// The links above `leaf` (ancestors `chain`) whose visibility is a mean, after the
    /// leaf's own look at them: the largest errors first, until what is left is under the
    /// tolerance of the indirect light at its centroid; where its rays found a source in
    /// part, also how that changes over the leaf (`Unsure::slope`). Also `partly_seen` of
    /// the leaf, which its gather at the centre tells, where it made one.
    fn look(&self, leaf: u32, chain: &[u32], cast: &mut u64) -> (Vec<Unsure>, Option<bool>) {
        let (h, faces) = (self.h, self.faces);
        let ln = &h.nodes[leaf as usize];
        let n = faces[ln.face as usize].plane.n;
        let mut unsure = self.means(chain);
        let mut partly = None;
        // Against the indirect light alone, not all of it as a vertex's look: one look
        // serves all the leaf's vertices, through its slope too. With the direct light
        // counted (the darkest vertex's), chair's backrest did not look (`slope`), and the
        // five solver scenes' errors from Cycles (`per_mesh.py`) were 0.525 % (chair),
        // 0.919 % (cornell), 0.491 % (data1), 2.958 % (room-78) and 5.173 % (room-245),
        // against 0.412, 0.857, 0.490, 2.691 and 4.664 % so; room-245's final gather cast
        // 18.5M rays, against 23.5M. The slope without this: chair 0.521 %, cornell
        // 0.880 %, room-78 2.835 %; this without the slope: chair 0.502 %, room-78 2.813 %.
        if !unsure.is_empty() {
            let c = ln.centroid;
            let g = self.gathered_at(c, n, chain, &unsure, |u, x| {
                x.element_sum() * u.v.max(1.0 - u.v)
            });
            partly = Some(g.smooth().is_none());
            let Gathered { e, errs, .. } = g;
            let allowed = self.tolerance * e.element_sum();
            for i in by_error(&errs, allowed) {
                let u = &mut unsure[i];
                let s = &h.nodes[u.source as usize];
                let seed = mix(mix(NONE as u64 ^ leaf as u64) ^ u.source as u64);
                let start = Start::Node(ln);
                // A link whose rays all got through is screened through the BVH first: most
                // screens agree, and the shaft's blocker list pays only over more rays.
                let screened = (u.v == 1.0).then(|| {
                    seen_from(
                        self.vis,
                        &self.table,
                        start,
                        s,
                        None,
                        SCREEN_RAYS,
                        seed,
                        0..SCREEN_RAYS,
                    )
                });
                if let Some(x) = screened {
                    *cast += x.rays as u64;
                }
                if screened.is_some_and(|x| x.fraction().is_none_or(|f| f == u.v)) {
                    continue;
                }
                let list = self.vis.blockers(ln, s);
                let own = own_visibility(
                    self.vis,
                    &self.table,
                    start,
                    s,
                    list.as_deref(),
                    u.v,
                    seed,
                    screened,
                );
                *cast += own.rays as u64;
                (u.v, u.varies, u.blockers) = (own.v, own.varies, Some(list));
                if own.varies {
                    u.slope = slope(&own.seen, ln.centroid, n);
                }
            }
        }
        (unsure, partly)
    }

    /// Where vertex `v` of `leaf` is and faces, a hair towards the leaf's centre: a vertex on
    /// a face's border lies in the plane of the face beyond it, and takes the limit from
    /// inside its own face.
    fn place(&self, v: u32, leaf: u32) -> (DVec3, DVec3, u32) {
        let (h, el) = (self.h, self.el);
        let p = el
            .eval
            .get(v as usize)
            .copied()
            .unwrap_or(el.positions[v as usize]);
        let p = p + (h.nodes[leaf as usize].centroid - p) * 1e-6;
        let face = el.vertex_face[v as usize];
        (p, self.faces[face as usize].plane.n, face)
    }

    /// Irradiance at a vertex that is not an anchor, with `own` the visibilities of the
    /// `unsure` links interpolated from the anchors', and its smooth value.
    fn between(
        &self,
        v: u32,
        leaf: u32,
        chain: &[u32],
        unsure: &[Unsure],
        own: &[f64],
    ) -> (DVec3, Option<DVec3>) {
        let (p, n, _) = self.place(v, leaf);
        let mut xs = Vec::with_capacity(unsure.len());
        let g = self.gathered_at(p, n, chain, unsure, |_, x| {
            xs.push(x);
            0.0
        });
        let mut e = g.e;
        for ((u, x), o) in unsure.iter().zip(xs).zip(own) {
            if u.varies {
                e += x * (o - u.v);
            }
        }
        (e, g.smooth())
    }

    /// Irradiance at `p` (normal `n`) over the links of `chain`, with the visibilities of
    /// `unsure` in place of their links', and for each of those its error by `err`
    /// (given what its source gives `p` unhidden); also with the links' own.
    fn gathered_at(
        &self,
        p: DVec3,
        n: DVec3,
        chain: &[u32],
        unsure: &[Unsure],
        mut err: impl FnMut(&Unsure, DVec3) -> f64,
    ) -> Gathered {
        let (h, g) = (self.h, self.g);
        let mut out = Gathered {
            e: DVec3::ZERO,
            errs: Vec::with_capacity(unsure.len()),
            mean: DVec3::ZERO,
            partly: 0.0,
        };
        let mut next = 0;
        for &a in chain {
            for l in &g.links[self.links(g, a)] {
                let s = &h.nodes[l.source as usize];
                if !s.is_planar() {
                    let (k, u) = point_coefficient(h, self.faces, self.el, p, n, s);
                    let x = self.solver.sent(self.b, l.source, u) * (k * l.v as f64);
                    out.e += x;
                    out.mean += x;
                    continue;
                }
                let x = self.unhidden(p, n, l.source);
                if l.clear {
                    out.e += x * l.v as f64;
                    out.mean += x * l.v as f64;
                } else {
                    let u = &unsure[next];
                    next += 1;
                    out.e += x * u.v;
                    out.mean += x * u.mean;
                    if u.mean > PARTLY && u.mean < 1.0 - PARTLY {
                        out.partly += x.element_sum() * u.mean;
                    }
                    out.errs.push(err(u, x));
                }
            }
        }
        out
    }

    /// Irradiance at vertex `v` of `leaf` (ancestors `chain`), given the leaf's look at its
    /// `unsure` links: the vertex looks itself at those the leaf found in part. Also returns
    /// its smooth value and the visibility it used for each of `unsure` (the
    /// link's where it did not look); the rays it cast are added to `cast`.
    fn at(
        &self,
        v: u32,
        leaf: u32,
        chain: &[u32],
        unsure: &[Unsure],
        cast: &mut u64,
    ) -> (DVec3, Option<DVec3>, Vec<f64>) {
        let seed = v as u64;
        self.at_point(
            self.place(v, leaf),
            seed,
            self.direct[v as usize],
            chain,
            unsure,
            cast,
        )
    }

    /// As `at`, at the point `(p, n, face)` with direct light `direct`, its rays drawn from
    /// `key`.
    fn at_point(
        &self,
        (p, n, face): (DVec3, DVec3, u32),
        key: u64,
        direct: DVec3,
        chain: &[u32],
        unsure: &[Unsure],
        cast: &mut u64,
    ) -> (DVec3, Option<DVec3>, Vec<f64>) {
        let h = self.h;
        let mut xs = Vec::with_capacity(unsure.len());
        let mut used: Vec<f64> = Vec::with_capacity(unsure.len());
        let g = self.gathered_at(p, n, chain, unsure, |u, x| {
            xs.push(x);
            let b = u.base(p);
            used.push(b);
            if u.varies {
                x.element_sum() * b.max(1.0 - b)
            } else {
                0.0
            }
        });
        let mut e = g.e;
        for ((u, x), b) in unsure.iter().zip(&xs).zip(&used) {
            if u.slope.is_some() {
                e += *x * (b - u.v);
            }
        }
        let allowed = self.tolerance * (e + direct).element_sum();
        for i in by_error(&g.errs, allowed) {
            let u = &unsure[i];
            let s = &h.nodes[u.source as usize];
            let list = u.blockers.as_ref().and_then(|b| b.as_deref());
            let seed = mix(mix(key) ^ u.source as u64);
            let start = Start::Point(p, n, face);
            let own = own_visibility(self.vis, &self.table, start, s, list, used[i], seed, None);
            *cast += own.rays as u64;
            e += xs[i] * (own.v - used[i]);
            used[i] = own.v;
        }
        (e, g.smooth(), used)
    }
}

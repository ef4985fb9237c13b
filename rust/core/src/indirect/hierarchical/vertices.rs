//! From the solution to element vertices. A leaf holds one value, and a link pushed down
//! from a large node gives all its leaves the value at that node's centroid: near another
//! face (a room's edge, a leg under a seat) that is off at first order. So each vertex
//! gathers again (a final gather): every link on the way from the root to one of its leaves,
//! with the factor from the vertex itself to the link's source, the link's visibility and the
//! source's final radiosity. Those links cover every source once.
//!
//! A link's visibility is a mean over its receiver, and where something stands between the
//! two (`Link::clear` false) a vertex may see more or less of the source than that: under a
//! table, a floor node reaching out past its edge sees the ceiling through the table top
//! at the mean. Each such link errs at most by what it carries times max(v, 1 − v), and
//! those errors add up over many links with one sign (all of them see the table). So each
//! vertex takes its own visibility for those links, the most uncertain first, until what
//! is left uncertain is under `VISIBILITY_SCALE × convergence` of its light.

use glam::DVec3;
use rayon::prelude::*;

use super::from_point::{mix, seen_from, AreaTable, Seen};
use super::hierarchy::{Hierarchy, Node, NONE};
use super::link::{planar_gather, point_coefficient};
use super::solve::{Gathering, Radiosity, Solver};
use super::visibility::Visibility;
use crate::mesh::elements::Elements;
use crate::scene::Face;

/// Rays that screen a link whose own rays all agreed (v = 0 or 1): a vertex whose rays all
/// agree too keeps the link's value.
const SCREEN_RAYS: u32 = 4;
/// Rays from a vertex to a source that it checks in full; a vertex whose rays leave it in
/// doubt (see `own_visibility`) casts as many again, up to `MAX_VERTEX_RAYS` in all.
const REPLACE_RAYS: u32 = 16;
const MAX_VERTEX_RAYS: u32 = 64;
/// A vertex's own visibility replaces the link's where the two differ by more than `SURE`
/// standard errors of the vertex's estimate, and is ignored under `NOISE` of them; between,
/// it is blended in smoothly.
const NOISE: f64 = 2.0;
const SURE: f64 = 4.0;

/// Indirect irradiance at every element vertex by a final gather over the links `g`; vertices
/// on no leaf (under a cover) get 0. `hidden` are the links whose rays were all blocked (left
/// out of the solve), `direct` the direct irradiance per vertex, and `tolerance` the share
/// of a vertex's light it may leave to its links' mean visibilities.
#[allow(clippy::too_many_arguments)]
pub fn gathered(
    h: &Hierarchy,
    faces: &[Face],
    el: &Elements,
    g: &Gathering,
    hidden: &Gathering,
    solver: &Solver,
    b: &Radiosity,
    vis: &Visibility,
    direct: &[DVec3],
    tolerance: f64,
) -> Vec<DVec3> {
    let nv = el.positions.len();
    let mut parent = vec![NONE; h.nodes.len()];
    for (i, n) in h.nodes.iter().enumerate() {
        if !n.is_leaf() {
            parent[n.kids[0] as usize] = i as u32;
            parent[n.kids[1] as usize] = i as u32;
        }
    }
    let mut leaf_of = vec![NONE; nv];
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
    // The vertices of each leaf, in index order: they share the links above the leaf, and
    // the shafts from the leaf to those links' sources.
    let mut by_leaf: Vec<(u32, u32)> = (0..nv as u32)
        .filter(|&v| leaf_of[v as usize] != NONE)
        .map(|v| (leaf_of[v as usize], v))
        .collect();
    by_leaf.sort_unstable();
    let groups: Vec<&[(u32, u32)]> = by_leaf.chunk_by(|x, y| x.0 == y.0).collect();
    let gather = Gather {
        h,
        faces,
        el,
        g,
        hidden,
        solver,
        b,
        vis,
        direct,
        tolerance,
        table: AreaTable::new(h),
    };
    let per_leaf: Vec<Vec<(u32, DVec3)>> = groups
        .par_iter()
        .map(|grp| {
            let mut chain = Vec::new();
            let mut a = grp[0].0;
            while a != NONE {
                chain.push(a);
                a = parent[a as usize];
            }
            let mut shafts = Shafts::default();
            grp.iter()
                .map(|&(leaf, v)| (v, gather.at(v, leaf, &chain, &mut shafts)))
                .collect()
        })
        .collect();
    let mut out = vec![DVec3::ZERO; nv];
    for (v, e) in per_leaf.into_iter().flatten() {
        out[v as usize] = e;
    }
    out
}

/// Per source, what may stand between a leaf and it (`Visibility::blockers`), found once
/// for the leaf's vertices: `Some(empty)` when nothing can, `None` when too much to list.
#[derive(Default)]
struct Shafts {
    of: Vec<(u32, Option<Vec<u32>>)>,
}

struct Gather<'a> {
    h: &'a Hierarchy,
    faces: &'a [Face],
    el: &'a Elements,
    g: &'a Gathering,
    hidden: &'a Gathering,
    solver: &'a Solver<'a>,
    b: &'a Radiosity,
    vis: &'a Visibility<'a>,
    direct: &'a [DVec3],
    tolerance: f64,
    table: AreaTable,
}

impl Gather<'_> {
    /// Irradiance at vertex `v` of leaf `leaf`, whose ancestors from itself up are `chain`.
    fn at(&self, v: u32, leaf: u32, chain: &[u32], shafts: &mut Shafts) -> DVec3 {
        let (h, faces, el, g, hidden) = (self.h, self.faces, self.el, self.g, self.hidden);
        let bm = &self.b.mean;
        let of =
            |g: &Gathering, a: u32| g.start[a as usize] as usize..g.start[a as usize + 1] as usize;
        // A hair towards the leaf's centre: a vertex on a face's border lies in the plane
        // of the face beyond it, and takes the limit from inside its own face.
        let p = el
            .eval
            .get(v as usize)
            .copied()
            .unwrap_or(el.positions[v as usize]);
        let p = p + (h.nodes[leaf as usize].centroid - p) * 1e-6;
        let face = el.vertex_face[v as usize];
        let n = faces[face as usize].plane.n;
        let mut e = DVec3::ZERO;
        // Planar sources whose visibility is a mean: (what the source would give the vertex
        // unhidden if known yet, how far off the mean could leave the vertex, the mean, the
        // source).
        let mut unsure: Vec<(Option<DVec3>, f64, f64, u32)> = Vec::new();
        let unhidden = |source: u32| {
            let ns = faces[h.nodes[source as usize].face as usize].plane.n;
            planar_gather(h, el, p, n, source, ns, bm)
        };
        for &a in chain {
            for l in &g.links[of(g, a)] {
                let s = &h.nodes[l.source as usize];
                let lv = l.v as f64;
                if !s.is_planar() {
                    let (k, u) = point_coefficient(h, faces, el, p, n, s);
                    e += self.solver.sent(self.b, l.source, u) * (k * lv);
                    continue;
                }
                let x = unhidden(l.source);
                e += x * lv;
                if !l.clear {
                    unsure.push((Some(x), x.element_sum() * lv.max(1.0 - lv), lv, l.source));
                }
            }
            // A link whose few rays were all blocked is left out of the solve, but a vertex
            // may see its source: links through slats that hide 60 % have all 4 rays blocked
            // one time in eight, and vertices that took their own visibility for the other
            // links only were 11 % too dark. What the source could give is taken from the
            // link's coefficient until the vertex looks.
            for l in &hidden.links[of(hidden, a)] {
                if h.nodes[l.source as usize].is_planar() {
                    let bound = (bm[l.source as usize] * l.k as f64).element_sum();
                    unsure.push((None, bound, 0.0, l.source));
                }
            }
        }
        let mut left: f64 = unsure.iter().map(|u| u.1).sum();
        let allowed = self.tolerance * (e + self.direct[v as usize]).element_sum();
        if left <= allowed {
            return e;
        }
        // The most uncertain first (a stable sort: the same order on every thread).
        unsure.sort_by(|x, y| y.1.total_cmp(&x.1));
        for &(x, err, lv, s) in &unsure {
            if left <= allowed {
                break;
            }
            left -= err;
            let node = &h.nodes[s as usize];
            let listed = match shafts.of.iter().position(|(src, _)| *src == s) {
                Some(i) => i,
                None => {
                    let leaf_node = &h.nodes[leaf as usize];
                    shafts.of.push((s, self.vis.blockers(leaf_node, node)));
                    shafts.of.len() - 1
                }
            };
            let blockers = shafts.of[listed].1.as_deref();
            let seed = mix(mix(v as u64) ^ s as u64);
            let at = (p, n, face);
            let own = own_visibility(self.vis, &self.table, at, node, blockers, lv, seed);
            if own != lv {
                e += x.unwrap_or_else(|| unhidden(s)) * (own - lv);
            }
        }
        e
    }
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
/// from `SURE` on the vertex's own value is; in doubt between, the vertex casts as many rays
/// again (up to `MAX_VERTEX_RAYS`), then blends the two smoothly.
fn own_visibility(
    vis: &Visibility,
    table: &AreaTable,
    at: (DVec3, DVec3, u32),
    s: &Node,
    blockers: Option<&[u32]>,
    lv: f64,
    seed: u64,
) -> f64 {
    let (p, n, face) = at;
    // Nothing between the leaf and the source: the vertex sees all of it.
    if blockers.is_some_and(|l| l.is_empty()) {
        return 1.0;
    }
    let mut seen = Seen::default();
    let mut cast = 0;
    let mut k = REPLACE_RAYS;
    // A link whose rays all agreed (lv 0 or 1) is screened first by a few rays: if they all
    // agree too, the vertex keeps the link's value.
    let unanimous = lv == 0.0 || lv == 1.0;
    if unanimous {
        seen = seen_from(vis, table, (p, n, face), s, blockers, SCREEN_RAYS, seed);
        cast = SCREEN_RAYS;
        match seen.fraction() {
            Some(v) if v != lv => k = REPLACE_RAYS - SCREEN_RAYS,
            _ => return lv,
        }
    }
    for round in 1u64.. {
        seen.add(seen_from(
            vis,
            table,
            (p, n, face),
            s,
            blockers,
            k,
            mix(seed ^ round),
        ));
        cast += k;
        let Some(v) = seen.fraction() else {
            return lv;
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
            return lv + (v - lv) * t * t * (3.0 - 2.0 * t);
        }
        k = cast.min(MAX_VERTEX_RAYS - cast);
    }
    lv
}

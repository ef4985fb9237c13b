//! A link: the light one node (the source) sends to another (the receiver), as a coefficient
//! fixed when the link is made, times the source's radiosity at solve time (Hanrahan,
//! Salzman & Aupperle 1991).
//!
//! Four kinds, by whether each end is planar (one face) or a cluster (Sillion 1995):
//! - planar ← planar: the receiver's irradiance is `B_s · k`, `k` the form factor from the
//!   receiver's centroid to the source: exact (Lambert's polygon formula over the source's
//!   triangles) for small sources, else the disc estimate `A·cosθs·cosθr / (π·d² + A)`.
//! - planar ← cluster: the cluster's radiant intensity towards the receiver comes from its
//!   projected-radiosity table (see `solve`), times `k = cosθr / (π·d'²)`.
//! - cluster ← anything: the irradiance arrives as a vector along `u` (from the receiver
//!   towards the source), and each leaf takes its own cosine when it is pushed down.
//!
//! `d'² = d² + A_s/π` keeps a near source finite, as the disc estimate does.

use glam::{DVec3, Vec3};

use super::hierarchy::{Hierarchy, Node};
use crate::geom::lambert::{edges_irradiance, polygon_irradiance};
use crate::geom::polygon::split_in_four;
use crate::mesh::elements::Elements;
use crate::scene::Face;

/// Sources with at most this many leaves get the exact point-to-triangles factor.
pub const EXACT_LEAVES: u32 = 8;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    pub receiver: u32,
    pub source: u32,
    /// Coefficient, visibility included (see the module doc for each kind).
    pub k: f32,
    /// Unit direction from the receiver's centroid to the source's.
    pub u: Vec3,
    /// Fraction of the source seen from the receiver.
    pub v: f32,
    /// The shaft between the two holds nothing: every point of the receiver sees all of
    /// the source. Otherwise `v` is a mean, and a point may see more or less (`vertices`).
    pub clear: bool,
}

/// How a link between two planar nodes takes its factor.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Factor {
    /// Exact for near leaves, the mean over points of a near receiver, second order for far.
    Sampled,
    /// As `Sampled`, but the factor at a near receiver's centroid (a link carrying little).
    Near,
    /// The factor at the receiver's centroid: for the parts of a faint near pair
    /// (`refine`), whose light is too little for a mean over the receiver or the exact pair.
    Centroid,
}

/// What a link needs to know of its two ends.
pub struct Ends<'a> {
    pub r: &'a Node,
    pub s: &'a Node,
    /// Receiver and source normals, for planar ends.
    pub nr: Option<DVec3>,
    pub ns: Option<DVec3>,
    /// A leaf pair's exact factor is left to `exact::fill` (the link's `k` is NaN until
    /// then), which takes each pair once for both directions.
    pub defer_exact: bool,
}

impl<'a> Ends<'a> {
    pub fn new(h: &'a Hierarchy, faces: &[Face], r: u32, s: u32) -> Self {
        let (r, s) = (&h.nodes[r as usize], &h.nodes[s as usize]);
        let normal = |n: &Node| n.is_planar().then(|| faces[n.face as usize].plane.n);
        Ends {
            r,
            s,
            nr: normal(r),
            ns: normal(s),
            defer_exact: false,
        }
    }

    /// Centroid-to-centroid offset, receiver to source.
    pub fn offset(&self) -> DVec3 {
        self.s.centroid - self.r.centroid
    }

    /// An estimate of the form factor from the receiver to the source that errs high: the
    /// cosines are taken as large as the nodes' sizes allow (1 for clusters).
    pub fn factor_bound(&self) -> f64 {
        let d = self.offset();
        let d2 = d.length_squared();
        let dist = d2.sqrt();
        let slack = if dist > 0.0 {
            (self.r.radius() + self.s.radius()) / dist
        } else {
            1.0
        };
        let u = if dist > 0.0 { d / dist } else { DVec3::Z };
        let cos = |n: Option<DVec3>, c: f64| n.map_or(1.0, |_| (c + slack).clamp(0.0, 1.0));
        let cr = cos(self.nr, self.nr.map_or(1.0, |n| n.dot(u)));
        let cs = cos(self.ns, self.ns.map_or(1.0, |n| -n.dot(u)));
        let a = self.s.area;
        a * cr * cs / (std::f64::consts::PI * d2 + a)
    }

    /// The link with visibility `v` (fraction of the source seen from the receiver), and
    /// `clear` when nothing lies in the shaft between the two; `factor` says how a planar
    /// pair's factor is taken.
    #[allow(clippy::too_many_arguments)]
    pub fn link(
        &self,
        h: &Hierarchy,
        el: &Elements,
        receiver: u32,
        source: u32,
        v: f64,
        clear: bool,
        factor: Factor,
    ) -> Link {
        let pi = std::f64::consts::PI;
        let d = self.offset();
        let d2 = d.length_squared();
        let u = d.normalize_or(DVec3::Z);
        let soft = pi * d2 + seen_area(self.s);
        let k = match (self.nr, self.ns) {
            (Some(nr), Some(ns)) if factor == Factor::Centroid => {
                planar_factor(h, el, self.r.centroid, nr, self.s, ns, POINT_DEPTH)
            }
            (Some(nr), Some(ns)) => {
                let near = self.r.radius() + self.s.radius() > RECEIVER_NEAR * d2.sqrt();
                let leaves = self.r.is_leaf() && self.s.is_leaf() && self.r.area > 0.0;
                let exact = if !near {
                    None
                } else if self.defer_exact && leaves {
                    Some(f64::NAN)
                } else {
                    exact_pair(h, receiver, source, nr, ns)
                };
                if let Some(k) = exact {
                    k
                } else if near && factor == Factor::Sampled {
                    // The factor varies over a receiver close to its source (two leaves
                    // meeting at a corner): its mean over points spread on the receiver,
                    // each point's taken exactly, keeps the light the receiver gets.
                    let f = |x: DVec3| planar_factor(h, el, x, nr, self.s, ns, POINT_DEPTH);
                    let tris = receiver_triangles(h, el, self.r, RECEIVER_POINTS);
                    let total: f64 = tris.iter().map(|&(_, w)| w).sum();
                    tris.iter()
                        .map(|&(t, w)| w * triangle_mean(&f, t, MEAN_DEPTH))
                        .sum::<f64>()
                        / total.max(1e-300)
                } else if near {
                    // A link carrying too little to sample: the factor at the receiver's
                    // centroid (the second-order term is a far-field one, and unbounded here).
                    planar_factor(h, el, self.r.centroid, nr, self.s, ns, POINT_DEPTH)
                } else {
                    planar_factor(h, el, self.r.centroid, nr, self.s, ns, POINT_DEPTH)
                        + receiver_term(self.r, nr, self.s, ns)
                }
            }
            (Some(nr), None) => nr.dot(u).max(0.0) / soft,
            (None, Some(ns)) => self.s.area * (-ns.dot(u)).max(0.0) / soft,
            (None, None) => 1.0 / soft,
        };
        Link {
            receiver,
            source,
            k: (k * v) as f32,
            u: u.as_vec3(),
            v: v as f32,
            clear,
        }
    }
}

/// The coefficient and direction of a link from the point `p` (normal `n`) to node `s`,
/// as for a planar receiver: the irradiance at `p` is the source's radiosity sent along
/// the direction (`solve`) times the coefficient. Visibility not included.
pub fn point_coefficient(
    h: &Hierarchy,
    faces: &[Face],
    el: &Elements,
    p: DVec3,
    n: DVec3,
    s: &Node,
) -> (f64, Vec3) {
    let d = s.centroid - p;
    let d2 = d.length_squared();
    let u = d.normalize_or(DVec3::Z);
    let soft = std::f64::consts::PI * d2 + seen_area(s);
    let k = if s.is_planar() {
        planar_factor(h, el, p, n, s, faces[s.face as usize].plane.n, POINT_DEPTH)
    } else {
        n.dot(u).max(0.0) / soft
    };
    (k, u.as_vec3())
}

/// The exact mean factor from leaf `s` (normal `ns`) over leaf `r` (normal `nr`)
/// (`exact::coupling` over the receiver's area); `None` when either is not a leaf.
fn exact_pair(h: &Hierarchy, r: u32, s: u32, nr: DVec3, ns: DVec3) -> Option<f64> {
    super::exact::coupling(h, r, s, nr, ns).map(|c| c / h.nodes[r as usize].area)
}

/// Form factor from the point `p` (normal `n`) to the triangles of the planar node `s`
/// (normal `ns`): each triangle counts only if `p` is in front of it.
pub fn exact_factor(h: &Hierarchy, el: &Elements, p: DVec3, n: DVec3, s: &Node, ns: DVec3) -> f64 {
    if s.is_leaf() {
        if (p - s.centroid).dot(ns) <= 0.0 {
            return 0.0;
        }
        if let Some(e) = edges_irradiance(p, n, h.leaf_edges(h.leaf_index(s))) {
            return e / std::f64::consts::PI;
        }
    }
    let mut f = 0.0;
    for pos in s.lo..s.hi {
        let t = h.order[pos as usize] as usize;
        let tri = el.triangles[t].map(|v| el.positions[v as usize]);
        if (p - tri[0]).dot(ns) <= 0.0 {
            continue;
        }
        f += polygon_irradiance(p, n, &tri);
    }
    f / std::f64::consts::PI
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::indirect::patches::test::grid_elements;
    use crate::scene::test::face;

    /// The hierarchy over two faces meshed 4×4, one leaf per triangle, and the nodes of
    /// face 0 (the receiver) and face 1.
    fn face_nodes(faces: &[Face]) -> (Hierarchy, Elements, u32, u32) {
        let el = grid_elements(faces, 4);
        let mut h = Hierarchy::build(faces, &el, |_| true, 0.0);
        h.set_boxes(faces, &el);
        let [a, b] = h.nodes[0].kids;
        let (r, s) = if h.nodes[a as usize].face == 0 {
            (a, b)
        } else {
            (b, a)
        };
        (h, el, r, s)
    }

    #[test]
    fn exact_and_estimated_factors_agree_far_away_and_bound_holds() {
        let v = DVec3::new;
        // A 0.1 square facing down at height 2 over a 0.1 square facing up.
        let top = face(
            &[
                v(0., 0., 2.),
                v(0., 0.1, 2.),
                v(0.1, 0.1, 2.),
                v(0.1, 0., 2.),
            ],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let bottom = face(
            &[
                v(0., 0., 0.),
                v(0.1, 0., 0.),
                v(0.1, 0.1, 0.),
                v(0., 0.1, 0.),
            ],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let faces = [bottom, top];
        let (h, el, r, s) = face_nodes(&faces);
        let ends = Ends::new(&h, &faces, r, s);
        let l = ends.link(&h, &el, r, s, 1.0, true, Factor::Sampled);
        // Exact: a point under a small square's centre: F ≈ A/(π·h²).
        let want = 0.01 / (std::f64::consts::PI * 4.0);
        assert!((l.k as f64 / want - 1.0).abs() < 2e-3, "{} vs {want}", l.k);
        assert!(ends.factor_bound() >= l.k as f64 * 0.999);
        // Half visible: half the coefficient.
        let half = ends.link(&h, &el, r, s, 0.5, false, Factor::Sampled);
        assert!((half.k * 2.0 - l.k).abs() < 1e-9);
        assert!((l.u - Vec3::Z).length() < 1e-6);
    }

    fn unit_square(z: f64, up: bool) -> Face {
        let v = DVec3::new;
        let mut p = vec![v(0., 0., z), v(1., 0., z), v(1., 1., z), v(0., 1., z)];
        if !up {
            p.reverse();
        }
        face(&p, DVec3::ONE, DVec3::ZERO)
    }

    #[test]
    fn a_far_source_sends_from_where_it_is_bright() {
        let faces = [unit_square(0.0, true)];
        let el = grid_elements(&faces, 4);
        let mut h = Hierarchy::build(&faces, &el, |_| true, 0.0);
        h.set_boxes(&faces, &el);
        let (p, n) = (DVec3::new(0.25, 0.5, 3.0), -DVec3::Z);
        let leaves = |h: &Hierarchy, left_only: bool| {
            let mut f = 0.0;
            for (i, nd) in h.nodes.iter().enumerate() {
                if nd.is_leaf() && (!left_only || nd.centroid.x < 0.5) {
                    f += exact_factor(h, &el, p, n, &h.nodes[i], DVec3::Z);
                }
            }
            f
        };
        // Evenly lit: the whole square's factor.
        let even = far_factor(p, n, &h.nodes[0], DVec3::Z);
        // (Second order: off by about (size / distance)⁴.)
        assert!((even / leaves(&h, false) - 1.0).abs() < 3e-3, "{even}");
        // Only its left half lit: the square's mean radiosity is half the left half's, so
        // the factor that carries it is twice the left half's.
        let w: Vec<f64> = h
            .order
            .iter()
            .map(|&t| {
                let c = el.triangles[t as usize]
                    .iter()
                    .map(|&v| el.positions[v as usize])
                    .sum::<DVec3>()
                    / 3.0;
                if c.x < 0.5 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        h.weigh(&el, &w);
        let root = &h.nodes[0];
        assert!((root.weight - 0.5).abs() < 1e-12);
        assert!((root.lit_centroid.x - 0.25).abs() < 1e-12);
        let lit = far_factor(p, n, root, DVec3::Z);
        let want = 2.0 * leaves(&h, true);
        assert!((lit / want - 1.0).abs() < 3e-3, "{lit} vs {want}");
        assert!(lit > even * 1.01, "{lit} vs {even}");
    }

    #[test]
    fn a_faint_link_between_near_plates_keeps_a_bounded_factor() {
        // Two unit squares 5 mm apart, each a node of 32 leaves: a link made between them
        // without sampling (it carries little) once took a far-field correction that is
        // unbounded this near, and the solve ran to 1e171.
        let faces = [unit_square(0.0, true), unit_square(0.005, false)];
        let (h, el, r, s) = face_nodes(&faces);
        assert!(!h.nodes[r as usize].is_leaf() && !h.nodes[s as usize].is_leaf());
        let ends = Ends::new(&h, &faces, r, s);
        let k = ends.link(&h, &el, r, s, 1.0, true, Factor::Near).k;
        // From the receiver's centre the other plate fills nearly all the hemisphere.
        assert!(k > 0.98 && k <= 1.0, "{k}");
    }
}

/// The area that keeps a near source's factor finite, as a disc's own area does in
/// `A / (π·d² + A)`: a planar node's area, or for a cluster the mean projected area of a
/// convex body, a quarter of its surface (its whole area would dim every cluster link).
fn seen_area(s: &Node) -> f64 {
    if s.is_planar() {
        s.area
    } else {
        0.25 * s.area
    }
}

/// A receiver is sampled at several points when the two nodes' radii add up to more than
/// this times their distance.
const RECEIVER_NEAR: f64 = 0.5;
pub(super) const RECEIVER_POINTS: u32 = 8;

/// Levels a receiver triangle may be split into four for a near link's mean factor.
const MEAN_DEPTH: u32 = 3;
/// A triangle's mean is taken as settled when splitting it changes it by less than this.
const MEAN_TOL: f64 = 0.02;

/// Up to `k` triangles of node `n` picked evenly along its range, each weighted by the area
/// of the stretch it stands for.
pub(super) fn receiver_triangles(
    h: &Hierarchy,
    el: &Elements,
    n: &Node,
    k: u32,
) -> Vec<([DVec3; 3], f64)> {
    let count = n.hi - n.lo;
    let picks: Vec<(u32, f64)> = if count <= k {
        (n.lo..n.hi).map(|p| (p, h.area[p as usize])).collect()
    } else {
        // Triangles spread over the leaf (farthest-point picks from the first), each
        // standing for the area of the triangles nearest to it: a leaf's triangles are in
        // id order, and every `count/k`-th of them bunched in one corner of a room's leaf.
        let centre = |pos: u32| {
            let t = h.order[pos as usize] as usize;
            el.triangles[t]
                .iter()
                .map(|&v| el.positions[v as usize])
                .sum::<DVec3>()
                / 3.0
        };
        let cs: Vec<DVec3> = (n.lo..n.hi).map(centre).collect();
        let chosen = super::own_look::spread(&cs, k as usize);
        let mut w = vec![0.0; chosen.len()];
        for (i, c) in cs.iter().enumerate() {
            let j = (0..chosen.len())
                .min_by(|&a, &b| {
                    (*c - cs[chosen[a]])
                        .length_squared()
                        .total_cmp(&(*c - cs[chosen[b]]).length_squared())
                })
                .unwrap();
            w[j] += h.area[n.lo as usize + i];
        }
        chosen
            .iter()
            .zip(w)
            .map(|(&i, w)| (n.lo + i as u32, w))
            .collect()
    };
    picks
        .into_iter()
        .map(|(pos, w)| {
            let t = h.order[pos as usize] as usize;
            (el.triangles[t].map(|v| el.positions[v as usize]), w)
        })
        .collect()
}

/// Mean of `f` over the triangle `t` by the degree-2 rule of three interior points
/// (Strang & Fix), split into four while that changes the mean by more than `MEAN_TOL`:
/// a factor to a face across a shared edge rises steeply towards that edge, and a fixed
/// rule over a leaf's few large triangles missed it by up to 40 % either way (the leaves
/// along a room's edges then took up to 8 % too much light in all).
pub(super) fn triangle_mean(f: &impl Fn(DVec3) -> f64, t: [DVec3; 3], depth: u32) -> f64 {
    let rule = |t: &[DVec3; 3]| {
        [[4.0, 1.0, 1.0], [1.0, 4.0, 1.0], [1.0, 1.0, 4.0]]
            .iter()
            .map(|[a, b, c]| f((t[0] * *a + t[1] * *b + t[2] * *c) / 6.0))
            .sum::<f64>()
            / 3.0
    };
    fn go(
        f: &impl Fn(DVec3) -> f64,
        t: [DVec3; 3],
        coarse: f64,
        depth: u32,
        rule: &impl Fn(&[DVec3; 3]) -> f64,
    ) -> f64 {
        let kids = split_in_four(&t);
        let vals = kids.map(|k| rule(&k));
        let fine = vals.iter().sum::<f64>() / 4.0;
        if depth == 0 || (fine - coarse).abs() <= MEAN_TOL * fine.abs().max(1e-12) {
            return fine;
        }
        kids.iter()
            .zip(vals)
            .map(|(k, v)| go(f, *k, v, depth - 1, rule))
            .sum::<f64>()
            / 4.0
    }
    let coarse = rule(&t);
    if depth == 0 {
        return coarse;
    }
    go(f, t, coarse, depth - 1, &rule)
}

/// Levels a point-to-node factor may descend into a near planar source.
const POINT_DEPTH: u32 = 4;
/// A planar source is split for a point factor while its radius exceeds this times its
/// distance: the disc estimate is off by about the square of that ratio.
const POINT_NEAR: f64 = 0.3;

/// Whether node `s` is near a point `d2` (squared) from its centroid, for `POINT_NEAR`:
/// squared, since this runs for every link at every gathered point.
fn point_near(s: &Node, d2: f64) -> bool {
    s.radius_squared() > POINT_NEAR * POINT_NEAR * d2
}

/// Irradiance at the point `p` (normal `n`) from the planar node `s` (normal `ns`) with
/// node radiosities `b`, visibility not included: as `planar_factor`, but where a near
/// source is split each part sends its own radiosity, not the source's mean (the floor
/// right beside a box lights the box's foot, whatever the rest of the floor does).
pub fn planar_gather(
    h: &Hierarchy,
    el: &Elements,
    p: DVec3,
    n: DVec3,
    s: u32,
    ns: DVec3,
    b: &[DVec3],
) -> DVec3 {
    let node = &h.nodes[s as usize];
    let d2 = (node.centroid - p).length_squared();
    if point_near(node, d2) {
        if node.is_leaf() {
            return b[s as usize] * exact_factor(h, el, p, n, node, ns);
        }
        return node
            .kids
            .iter()
            .map(|&k| planar_gather(h, el, p, n, k, ns, b))
            .sum();
    }
    b[s as usize] * far_factor(p, n, node, ns)
}

/// Form factor from the point `p` (normal `n`) to the planar node `s` (normal `ns`): exact
/// for small nodes, the sum over its children for near ones (down `depth` levels), else
/// the disc estimate.
fn planar_factor(
    h: &Hierarchy,
    el: &Elements,
    p: DVec3,
    n: DVec3,
    s: &Node,
    ns: DVec3,
    depth: u32,
) -> f64 {
    let d2 = (s.centroid - p).length_squared();
    // Far sources (small for their distance) take the disc estimate, off by about
    // (radius / distance)²; near ones are split, down to their triangles.
    if point_near(s, d2) {
        if s.is_leaf() || s.hi - s.lo <= EXACT_LEAVES {
            return exact_factor(h, el, p, n, s, ns);
        }
        if depth == 0 {
            // Out of levels but still near: every leaf below, exactly.
            let mut f = 0.0;
            let mut pos = s.lo;
            while pos < s.hi {
                let leaf = &h.nodes[h.leaf_node[pos as usize] as usize];
                f += share(leaf, s) * exact_factor(h, el, p, n, leaf, ns);
                pos = leaf.hi;
            }
            return f;
        }
        return s
            .kids
            .iter()
            .map(|&k| {
                let kid = &h.nodes[k as usize];
                share(kid, s) * planar_factor(h, el, p, n, kid, ns, depth - 1)
            })
            .sum();
    }
    far_factor(p, n, s, ns)
}

/// How much brighter the part `kid` of `s` is than `s` as a whole (`Hierarchy::weigh`):
/// a factor to `s` sums its parts' factors, each scaled so.
fn share(kid: &Node, s: &Node) -> f64 {
    if s.weight > 0.0 {
        kid.weight / s.weight
    } else {
        1.0
    }
}

/// What the mean of a point factor over the planar receiver `r` (normal `nr`) adds to its
/// value at `r`'s centroid, to second order: half the kernel's Hessian in the receiver point
/// against `r`'s area moment, times the source's area. The kernel is symmetric, so this is
/// `far_factor` with the two ends swapped, less its value at the centroids. Without it every
/// far link errs the same way (a wall's middle sees more of the opposite wall than its
/// mean does), and the errors add up over a leaf's links: 0.9 % too much light in a box.
fn receiver_term(r: &Node, nr: DVec3, s: &Node, ns: DVec3) -> f64 {
    if !(r.area > 0.0) {
        return 0.0;
    }
    let w = s.lit_centroid - r.centroid;
    let q = w.length_squared();
    let (a, b) = (nr.dot(w), -ns.dot(w));
    if a <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    let centre = s.area * a * b / (std::f64::consts::PI * q * q);
    s.area / r.area * kernel_mean(s.lit_centroid, ns, r.area, r.centroid, &r.moment, nr) - centre
}

/// Form factor from the point `p` (normal `n`) to a far planar node `s` (normal `ns`): the
/// kernel `cosθ·cosθs / (π·r²)` averaged over the source to second order, its value at the
/// centroid plus half its Hessian against the source's area moment. Unbiased to that order:
/// the disc estimate `A·cosθ·cosθs / (π·d² + A)` is right for a disc facing `p` head-on
/// but errs low by up to `A / (π·d²)` for tilted pairs (a wall beside a floor).
pub fn far_factor(p: DVec3, n: DVec3, s: &Node, ns: DVec3) -> f64 {
    kernel_mean(p, n, s.area, s.lit_centroid, &s.lit_moment, ns)
}

/// The kernel's mean over a planar patch of area `area`, centroid `c` and second moment
/// `moment`, times its area: `far_factor`'s second-order estimate.
fn kernel_mean(p: DVec3, n: DVec3, area: f64, c: DVec3, moment: &[f64; 6], ns: DVec3) -> f64 {
    // For x on the source's plane the kernel is h·(n·w)/|w|⁴, w = x − p, with the
    // height h = −ns·w the same for every x.
    let w = c - p;
    let h = -ns.dot(w);
    if h <= 0.0 {
        return 0.0;
    }
    let a = n.dot(w);
    let q = w.length_squared();
    let [xx, yy, zz, xy, xz, yz] = *moment;
    let mv = |v: DVec3| {
        DVec3::new(
            xx * v.x + xy * v.y + xz * v.z,
            xy * v.x + yy * v.y + yz * v.z,
            xz * v.x + yz * v.y + zz * v.z,
        )
    };
    let mw = mv(w);
    let trace = xx + yy + zz;
    // One division: this runs for every far link at every gathered point.
    let iq = 1.0 / q;
    let iq2 = iq * iq;
    let k0 = h * a * iq2;
    let hess = h * iq2 * iq * (-8.0 * n.dot(mw) - 4.0 * a * trace + 24.0 * a * w.dot(mw) * iq);
    (area * (k0 + 0.5 * hess) * std::f64::consts::FRAC_1_PI).max(0.0)
}

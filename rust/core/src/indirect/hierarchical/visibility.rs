//! Visibility between two nodes, deterministic: first a shaft test against the BVH (the faces
//! whose box meets the box around both nodes, in front of both nodes' planes, and whose plane
//! has points of the two on opposite sides: for convex objects and rooms, usually none), so
//! most links need no ray; the others are the fraction of a fixed stratified set of segments
//! between points of the two nodes that no face crosses.

use glam::DVec3;

use super::hierarchy::{Hierarchy, Node};
use crate::geom::raycast::Occluders;
use crate::geom::Plane;
use crate::mesh::elements::Elements;
use crate::scene::solids::{Occluder, Solid};
use crate::scene::Face;

/// The least weight `Visibility::bright` gives a point, against its source's mean: where
/// the estimate says dark (no direct light), light still arrives by bounces.
const BRIGHT_FLOOR: f64 = 0.05;

/// Blocker lists longer than this go to the BVH per segment instead.
pub const MAX_LISTED: usize = 32;
/// Shaft tests give up (and rays go through the BVH) past this many candidate faces: for
/// large nodes in clutter, sifting every face in the box costs more than a few rays. A
/// list past `MAX_LISTED` served only the pairs split from it, and in clutter most queries
/// give up anyway: at 64, room-8328's shaft queries were a quarter of its refinement
/// (perf), and at 32 its T_link went 153 → 141 s (at 16, 145 s and a slower final gather;
/// single runs) with links and rays within 0.01 %; the error from Cycles (`per_mesh.py`)
/// the same to three digits on data1, chair, cornell, room-78 and room-245.
const MAX_CANDIDATES: usize = MAX_LISTED;

pub struct Visibility<'a> {
    pub h: &'a Hierarchy,
    pub faces: &'a [Face],
    pub el: &'a Elements,
    pub occ: &'a Occluders,
    /// The scene's convex solids, by the faces `occ` indexes (empty: none known).
    pub solid_of: &'a [u32],
    pub occluders: &'a [Occluder],
}

impl Visibility<'_> {
    /// The planes of `r` and `s` that are planar, and their faces (which never block).
    fn planes(&self, r: &Node, s: &Node) -> (Vec<Plane>, Vec<u32>) {
        let mut planes: Vec<Plane> = Vec::with_capacity(2);
        let mut skip: Vec<u32> = Vec::with_capacity(2);
        for n in [r, s] {
            if n.is_planar() {
                planes.push(self.faces[n.face as usize].plane);
                skip.push(self.h.real_face(n.face));
            }
        }
        (planes, skip)
    }

    /// What could block some segment between `r` and `s`: nothing, a short list of faces,
    /// or too many to list (`None`: ask the BVH per segment).
    pub fn blockers(&self, r: &Node, s: &Node) -> Option<Vec<u32>> {
        let (planes, skip) = self.planes(r, s);
        let (lo, hi) = (r.lo_box.min(s.lo_box), r.hi_box.max(s.hi_box));
        let mut out = Vec::new();
        if !self
            .occ
            .candidates_upto(lo, hi, &planes, &skip, MAX_CANDIDATES, &mut out)
        {
            return None;
        }
        if out.is_empty() {
            return Some(out);
        }
        let corners = corners(r);
        out.retain(|&id| self.occ.straddled_by(id, &corners, s.lo_box, s.hi_box));
        Some(out)
    }

    /// `blockers` for nodes inside a pair whose blockers were `list`: each test only
    /// narrows as the nodes shrink, so the pair's list holds all of theirs (shaft culling
    /// with inherited candidates, Haines & Wallace 1994), and sifting it spares a walk of
    /// the BVH for every link under the pair.
    pub fn blockers_among(&self, r: &Node, s: &Node, list: &[u32]) -> Vec<u32> {
        if list.is_empty() {
            return Vec::new();
        }
        let (planes, skip) = self.planes(r, s);
        let (lo, hi) = (r.lo_box.min(s.lo_box), r.hi_box.max(s.hi_box));
        let corners = corners(r);
        list.iter()
            .copied()
            .filter(|&id| {
                !skip.contains(&id)
                    && self.occ.box_overlaps(id, lo, hi)
                    && self.occ.in_front_of_all(id, &planes)
                    && self.occ.straddled_by(id, &corners, s.lo_box, s.hi_box)
            })
            .collect()
    }

    /// The face that blocks the segment `a`–`b`: among `list` where it is short enough, else
    /// through the BVH past the faces `skip`; `hint` tried first
    /// (`Occluders::segment_blocker_hinted`).
    pub fn blocker(
        &self,
        a: DVec3,
        b: DVec3,
        list: Option<&[u32]>,
        skip: &[u32],
        hint: Option<u32>,
    ) -> Option<u32> {
        match list {
            Some(l) if l.len() <= MAX_LISTED => {
                self.occ.segment_blocker_among_hinted(a, b, l, hint)
            }
            _ => self.occ.segment_blocker_hinted(a, b, skip, hint),
        }
    }

    /// Fraction of `rays` segments between points of `r` and `s` that nothing blocks; 1
    /// without a ray when nothing can be in the way. Also returns the rays cast.
    #[cfg(test)]
    pub fn fraction(&self, r: &Node, s: &Node, rays: u32) -> (f64, u32) {
        let look = self.fraction_among(r, s, self.blockers(r, s).as_deref(), rays, false);
        (look.open, look.cast)
    }

    /// Whether face `id`, or the convex solid it belongs to, blocks every segment between
    /// `r` and `s` (judged by the triangles of a node of a few or the box of a larger one):
    /// then no ray need be cast.
    pub fn covers(&self, id: u32, r: &Node, s: &Node) -> bool {
        let (pa, na) = self.hull(r);
        let nr = r.is_planar().then(|| self.faces[r.face as usize].plane.n);
        self.covers_from(id, &pa[..na], nr, s)
    }

    /// `covers` from the points `a` (a node's corners, or one point) facing `na` where they
    /// lie in a plane.
    pub fn covers_from(&self, id: u32, a: &[DVec3], na: Option<DVec3>, s: &Node) -> bool {
        let (pb, nb) = self.hull(s);
        let b = &pb[..nb];
        if self.occ.face_covers(id, a, b) {
            return true;
        }
        match self
            .solid_of
            .get(id as usize)
            .and_then(|&o| self.occluders.get(o as usize))
        {
            Some(Occluder::Solid { solid, .. }) => {
                // The planar ends' normals, turned from `a` towards `s`.
                let mut normals = [DVec3::ZERO; 2];
                let mut k = 0;
                if let Some(n) = na {
                    normals[k] = n;
                    k += 1;
                }
                if s.is_planar() {
                    normals[k] = -self.faces[s.face as usize].plane.n;
                    k += 1;
                }
                solid_covers(solid, a, b, &normals[..k], self.occ.tolerance())
            }
            _ => false,
        }
    }

    /// Up to two triangles' corners, or a box's: on the stack, as `covers` runs for every
    /// pair under one that a face hid in part.
    fn hull(&self, n: &Node) -> ([DVec3; 8], usize) {
        if n.hi - n.lo <= 2 {
            let mut out = [DVec3::ZERO; 8];
            for (k, i) in (n.lo..n.hi).enumerate() {
                let [a, b, c, _] = self.h.corners[i as usize];
                for (j, v) in [a, b, c].into_iter().enumerate() {
                    out[3 * k + j] = self.el.positions[v as usize];
                }
            }
            (out, 3 * (n.hi - n.lo) as usize)
        } else {
            (corners(n), 8)
        }
    }

    /// `fraction`, given the `blockers` between `r` and `s` (`None`: unknown, use the BVH).
    /// With `until_blocked`, stops at the first blocked segment, with the fraction so far
    /// (under 1): for a caller that splits any pair something hides.
    pub fn fraction_among(
        &self,
        r: &Node,
        s: &Node,
        list: Option<&[u32]>,
        rays: u32,
        until_blocked: bool,
    ) -> Look {
        if list.is_some_and(|l| l.is_empty()) {
            return Look {
                open: 1.0,
                cast: 0,
                blocker: None,
            };
        }
        let skip: Vec<u32> = [r, s]
            .iter()
            .filter(|n| n.is_planar())
            .map(|n| self.h.real_face(n.face))
            .collect();
        let k = rays.max(1);
        // Only segments whose ends face each other carry light: on a cluster (a box), points
        // on faces turned away would be hidden by the box itself, and counting them would
        // dim a link whose light all comes from the faces turned towards the receiver.
        // Candidates are drawn from a longer fixed sequence until `k` such segments are found.
        // The first face found blocking (a hint for the pairs below), and the last, tried
        // first on the next segment: the first is found before any hint, so it is the one
        // the traversal finds.
        let (mut first, mut last) = (None, None);
        let mut blocked = |a: DVec3, b: DVec3| {
            let hit = self.blocker(a, b, list, &skip, last);
            first = first.or(hit);
            last = hit.or(last);
            hit.is_some()
        };
        // Each segment counts by its own point-to-point factor cosθ·cosθs / d²: the part
        // of a large source next to the receiver carries most of the light, and it is the
        // part least often hidden (a floor beside a box among clutter). And by how bright
        // its source end is (`bright`).
        let soft = s.area / (std::f64::consts::PI * k as f64);
        let (mut open, mut total, mut counted) = (0.0f64, 0.0f64, 0u32);
        for i in 0..4 * k {
            if counted >= k {
                break;
            }
            let (a, na) = self.sample(r, i % k, k, i / k);
            let (b, nb, pos) = self.sample_at(s, (i * 5 + 1) % k, k, i / k);
            let d = b - a;
            let (ca, cb) = (na.dot(d), -nb.dot(d));
            if ca > 0.0 && cb > 0.0 {
                counted += 1;
                let d2 = d.length_squared();
                let w = ca * cb / (d2 * (d2 + soft)) * self.bright(s, pos);
                total += w;
                if !blocked(a, b) {
                    open += w;
                } else if until_blocked {
                    break;
                }
            }
        }
        if counted > 0 && total > 0.0 {
            return Look {
                open: open / total,
                cast: counted,
                blocker: first,
            };
        }
        // No pair faces each other (a sliver seen edge-on): every segment counts.
        let open = (0..k)
            .filter(|&i| {
                let (a, _) = self.sample(r, i, k, 0);
                let (b, _) = self.sample(s, (i * 5 + 1) % k, k, 0);
                !blocked(a, b)
            })
            .count();
        Look {
            open: open as f64 / k as f64,
            cast: k,
            blocker: first,
        }
    }

    /// The `i`-th of `k` points on node `n` (in round `round`, which shifts the points within
    /// their leaf), with its face's normal: leaves spread over its range, and several points
    /// inside a leaf when there are fewer leaves than points.
    pub fn sample(&self, n: &Node, i: u32, k: u32, round: u32) -> (DVec3, DVec3) {
        let (p, normal, _) = self.sample_at(n, i, k, round);
        (p, normal)
    }

    /// How bright the leaf at position `pos` of source `n` is against `n` as a whole, by the
    /// estimate `Hierarchy::weigh` made (1 where `n` has none): a segment's weight in a look
    /// is the light it would carry. A link sends its source's mean radiosity times one
    /// visibility, so that visibility must be the share of the light that passes, not of
    /// the area: a box's lit top sees the ceiling whole, while its dark sides see little
    /// of it past the boxes beside them.
    pub fn bright(&self, n: &Node, pos: u32) -> f64 {
        if !(n.weight > 0.0) {
            return 1.0;
        }
        let leaf = &self.h.nodes[self.h.leaf_node[pos as usize] as usize];
        (leaf.weight / n.weight).max(BRIGHT_FLOOR)
    }

    /// `sample`, with the leaf position the point lies on.
    pub fn sample_at(&self, n: &Node, i: u32, k: u32, round: u32) -> (DVec3, DVec3, u32) {
        let count = n.hi - n.lo;
        let (leaf, j, m) = if count >= k {
            (
                n.lo + ((2 * i as u64 + 1) * count as u64 / (2 * k as u64)) as u32,
                0,
                1,
            )
        } else {
            (n.lo + i % count, i / count, k.div_ceil(count))
        };
        let [a, b, c, face] = self.h.corners[leaf as usize];
        let [a, b, c] = [a, b, c].map(|v| self.el.positions[v as usize]);
        let (mut u, mut v) = if m == 1 && round == 0 {
            (1.0 / 3.0, 1.0 / 3.0)
        } else {
            let m = m * (round + 1);
            let j = j * (round + 1) + round;
            let x = (j as f64 + 0.5) / m as f64;
            (x, (x * 0.618_033_988_749_895 * m as f64).fract())
        };
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        // The leaf's face, not the triangle's: a back leaf faces the other way.
        let normal = self.faces[face as usize].plane.n;
        (a * (1.0 - u - v) + b * u + c * v, normal, leaf)
    }
}

/// Whether the convex `solid` hides every segment from a point of the hull of `a` to a point
/// of the hull of `b`. A plane that separates the two hulls is crossed by those segments in
/// the hull of the crossings of the segments between their points (`Occluders::face_covers`);
/// if the solid, being convex, holds those crossings, each more than `tol` inside, every
/// segment passes through its inside, and it crosses a face of it on the way out to an end
/// that lies wholly outside (in front of one of its planes). Only one end need be outside:
/// from a node partly buried in the solid (clutter standing in clutter) every segment still
/// leaves through a face; two buried ends could see each other inside it.
///
/// The plane is tried across the axis between the two, then along the planar nodes' normals
/// (`normals`, pointing from `a` towards `b`), which separate some pairs the axis does not.
/// Any direction is sound: the crossings are only trusted where the plane separates the
/// two. On room-828 (clutter boxes standing in each other on a table) the buried ends
/// and the normals spare 0.43M and 0.34M of 42.2M rays; most pairs whose rays were all
/// blocked are hidden by several solids together, which no one of them covers (of the 2.1M
/// dropped after a second look, 138k were covered by a face one of its rays hit).
fn solid_covers(solid: &Solid, a: &[DVec3], b: &[DVec3], normals: &[DVec3], tol: f64) -> bool {
    let outside = |p: &[DVec3]| {
        solid
            .planes
            .iter()
            .any(|pl| p.iter().all(|&x| pl.dist(x) > tol))
    };
    if !outside(a) && !outside(b) {
        return false;
    }
    let mean = |p: &[DVec3]| p.iter().copied().sum::<DVec3>() / p.len() as f64;
    let axis = (mean(b) - mean(a)).try_normalize();
    axis.into_iter()
        .chain(normals.iter().copied())
        .any(|n| crossings_inside(solid, a, b, n, tol))
}

/// Whether the plane across `n` through the solid's centre (moved between `a` and `b` where
/// that is outside the gap between them) separates the two and the segments between their
/// points all cross it more than `tol` inside the solid.
fn crossings_inside(solid: &Solid, a: &[DVec3], b: &[DVec3], n: DVec3, tol: f64) -> bool {
    let a_top = a
        .iter()
        .map(|p| n.dot(*p))
        .fold(f64::NEG_INFINITY, f64::max);
    let b_low = b.iter().map(|p| n.dot(*p)).fold(f64::INFINITY, f64::min);
    if !(b_low - a_top > 2.0 * tol) {
        return false;
    }
    let d = n.dot(solid.centroid).clamp(a_top + tol, b_low - tol);
    a.iter().all(|&p| {
        let dp = n.dot(p) - d;
        b.iter().all(|&q| {
            let dq = n.dot(q) - d;
            let x = p + (q - p) * (dp / (dp - dq));
            solid.planes.iter().all(|pl| pl.dist(x) < -tol)
        })
    })
}

/// What a look along segments between two nodes found.
pub struct Look {
    /// Fraction of the light that passes.
    pub open: f64,
    /// Segments tested.
    pub cast: u32,
    /// A face that blocked one of them.
    pub blocker: Option<u32>,
}

fn corners(n: &Node) -> [DVec3; 8] {
    let (lo, hi) = (n.lo_box, n.hi_box);
    std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

#[cfg(test)]
pub(crate) mod test {
    use super::*;
    use crate::indirect::patches::test::grid_elements;
    use crate::scene::test::face;

    fn square(z: f64, s: f64, up: bool) -> Face {
        let v = |x, y| DVec3::new(x, y, z);
        let mut p = vec![v(-s, -s), v(s, -s), v(s, s), v(-s, s)];
        if !up {
            p.reverse();
        }
        face(&p, DVec3::ONE, DVec3::ZERO)
    }

    /// Floor facing up, ceiling facing down (2 × 2, one apart, as 4 × 4 grids of
    /// elements); a blocker in between covering half (x < 0).
    pub(crate) struct HalfBlocked {
        pub faces: Vec<Face>,
        pub el: Elements,
        pub occ: Occluders,
        pub h: Hierarchy,
    }

    impl HalfBlocked {
        pub fn new() -> Self {
            let v = |x, y| DVec3::new(x, y, 0.5);
            let half = face(
                &[v(-3.0, -3.0), v(0.0, -3.0), v(0.0, 3.0), v(-3.0, 3.0)],
                DVec3::ONE,
                DVec3::ZERO,
            );
            let faces = vec![square(0.0, 1.0, true), square(1.0, 1.0, false), half];
            let el = grid_elements(&faces[..2], 4);
            let occ = Occluders::new(&faces);
            let mut h = Hierarchy::build(&faces, &el, |_| true, 0.0);
            h.set_boxes(&faces, &el);
            HalfBlocked { faces, el, occ, h }
        }

        pub fn vis(&self) -> Visibility<'_> {
            Visibility {
                h: &self.h,
                faces: &self.faces,
                el: &self.el,
                occ: &self.occ,
                solid_of: &[],
                occluders: &[],
            }
        }

        /// A leaf of `face` (0 the floor, 1 the ceiling) wholly at x under `x`.
        pub fn leaf_at(&self, face: u32, x: f64) -> &Node {
            self.h
                .nodes
                .iter()
                .find(|n| n.is_leaf() && n.face == face && n.hi_box.x < x)
                .unwrap()
        }
    }

    #[test]
    fn open_half_and_fully_blocked_pairs() {
        let scene = HalfBlocked::new();
        let (h, el, vis) = (&scene.h, &scene.el, scene.vis());
        let (floor, ceil) = (scene.faces[0].clone(), scene.faces[1].clone());
        let [a, b] = h.nodes[0].kids.map(|k| &h.nodes[k as usize]);
        let (f, c) = if a.face == 0 { (a, b) } else { (b, a) };
        assert_eq!(vis.blockers(f, c), Some(vec![2]));
        let (v, rays) = vis.fraction(f, c, 16);
        assert_eq!(rays, 16);
        assert!(v > 0.1 && v < 0.9, "{v}");
        // A leaf wholly under the blocker sees nothing of a leaf over it.
        let (under, over) = (scene.leaf_at(0, -0.2), scene.leaf_at(1, -0.2));
        assert_eq!(vis.fraction(under, over, 4).0, 0.0);
        // Without the blocker: no candidates, no rays.
        let faces2 = vec![floor, ceil];
        let occ2 = Occluders::new(&faces2);
        let vis2 = Visibility {
            h,
            faces: &faces2,
            el,
            occ: &occ2,
            solid_of: &[],
            occluders: &[],
        };
        assert_eq!(vis2.fraction(f, c, 16), (1.0, 0));
    }

    #[test]
    fn a_solid_covers_pairs_outside_it_that_every_segment_crosses() {
        use crate::scenes::{cuboid, polygons_mesh};
        let sc = crate::scene::test::with_bulb(vec![polygons_mesh(
            "Box",
            cuboid([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], false),
            Some([0.5; 3]),
        )]);
        let Some(Occluder::Solid { solid, .. }) = sc.occluders.first() else {
            panic!("the box is one solid");
        };
        let occ = Occluders::new(&sc.faces);
        let tol = occ.tolerance();
        let tri = |x: f64, y: f64, z: f64, s: f64| {
            vec![
                DVec3::new(x, y - s, z - s),
                DVec3::new(x, y + s, z - s),
                DVec3::new(x, y, z + s),
            ]
        };
        // Across the box along x.
        let (a, b) = (tri(-1.0, 0.5, 0.5, 0.2), tri(2.0, 0.5, 0.5, 0.2));
        assert!(solid_covers(solid, &a, &b, &[], tol));
        // Given a direction that does not separate them (y, along which they overlap),
        // that plane says nothing and the axis still tells.
        assert!(solid_covers(solid, &a, &b, &[DVec3::Y], tol));
        // Much wider than the box: a segment passes beside it, along whichever direction
        // the plane is tried.
        let wide = tri(-1.0, 0.5, 0.5, 3.0);
        let dirs = [DVec3::X, DVec3::new(1.0, 1.0, 0.0).normalize(), DVec3::Z];
        assert!(!solid_covers(solid, &wide, &b, &dirs, tol));
        assert!(!occ.segment_blocked(wide[0], b[0]));
        // One end inside, or partly inside: every segment still leaves through a face.
        let buried = tri(0.1, 0.5, 0.5, 0.2);
        assert!(solid_covers(solid, &buried, &b, &[], tol));
        let straddling = vec![
            DVec3::new(-0.3, 0.4, 0.3),
            DVec3::new(0.3, 0.6, 0.3),
            DVec3::new(0.0, 0.5, 0.7),
        ];
        assert!(solid_covers(solid, &straddling, &b, &[], tol));
        // Both ends inside: they see each other through its inside, crossing no face.
        let deep = tri(0.9, 0.5, 0.5, 0.05);
        assert!(!solid_covers(solid, &buried, &deep, &dirs, tol));
        assert!(!occ.segment_blocked(buried[0], deep[1]));
        // Diagonally through two corners: every segment crosses it, though through two of
        // its faces, so no one face covers the pair.
        let (c, d) = (tri(-0.5, -0.5, 0.5, 0.05), tri(1.5, 1.5, 0.5, 0.05));
        assert!(solid_covers(solid, &c, &d, &[], tol));
        assert!((0..sc.faces.len() as u32).all(|f| !occ.face_covers(f, &c, &d)));
        for (p, q) in [(&a, &b), (&c, &d), (&buried, &b), (&straddling, &b)] {
            for &x in p.iter() {
                for &y in q.iter() {
                    assert!(occ.segment_blocked(x, y));
                    assert!(occ.segment_blocked((x + p[0]) * 0.5, (y + q[2]) * 0.5));
                }
            }
        }
    }
}

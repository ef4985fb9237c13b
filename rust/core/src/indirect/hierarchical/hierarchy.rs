//! The element hierarchy of hierarchical radiosity: a binary tree whose leaves are the element
//! triangles and whose inner nodes are, from the top, clusters of faces (split by spatial
//! median, as a BVH), a face, the face's regions (so a lit region, a penumbra and an umbra
//! never share a node below the face: a shooter's radiosity follows the shadows the direct
//! stage resolved), then a region's triangles split by centroid median.
//!
//! Nodes are laid out in depth-first order (a parent before its children), and each covers a
//! contiguous range of `order`, the leaf triangles in tree order: pull runs over the nodes
//! backwards, push forwards. A node is *planar* when all its leaves lie on one face; the
//! others are clusters (Sillion 1995), which keep a projected-area table instead of a normal.

use glam::DVec3;

use crate::mesh::elements::Elements;
use crate::scene::Face;

pub const NONE: u32 = u32::MAX;

#[derive(Debug, Clone)]
pub struct Node {
    /// Range of `Hierarchy::order` (leaf positions) under this node.
    pub lo: u32,
    pub hi: u32,
    /// Children, or `[NONE, NONE]` for a leaf.
    pub kids: [u32; 2],
    /// The face all leaves lie on, or `NONE` for a cluster.
    pub face: u32,
    pub area: f64,
    /// Area-weighted centroid.
    pub centroid: DVec3,
    pub lo_box: DVec3,
    pub hi_box: DVec3,
    /// Area second moment about the centroid, `∫(x − c)(x − c)ᵀ dA / A`, as
    /// `[xx, yy, zz, xy, xz, yz]`: a far source's factor to second order (`link`).
    pub moment: [f64; 6],
    /// The same two, weighted by an estimate of the radiosity over the node (`weigh`): a
    /// far source sends from where it is bright, not from its middle.
    pub lit_centroid: DVec3,
    pub lit_moment: [f64; 6],
    /// Mean of that estimate over the node (0 where it is dark).
    pub weight: f64,
}

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.kids[0] == NONE
    }

    pub fn is_planar(&self) -> bool {
        self.face != NONE
    }

    /// Half the box diagonal: no leaf point is farther than this from the box centre.
    pub fn radius(&self) -> f64 {
        0.5 * (self.hi_box - self.lo_box).length()
    }

    /// `radius` squared, without the square root (for tests run per link and point).
    pub fn radius_squared(&self) -> f64 {
        0.25 * (self.hi_box - self.lo_box).length_squared()
    }
}

#[derive(Debug, Clone, Default)]
pub struct Hierarchy {
    pub nodes: Vec<Node>,
    /// Element triangle of each leaf position.
    pub order: Vec<u32>,
    /// Node of each leaf position.
    pub leaf_node: Vec<u32>,
    /// Per leaf position, its triangle's vertices and its leaf's face: the rays' end points
    /// are drawn by position, and reading them through `order`, the triangles and the nodes
    /// cost a cache miss each (drawing them was 15 % of room-245's profile; the bake went
    /// about 4 % faster).
    pub corners: Vec<[u32; 4]>,
    /// Area of each leaf position's triangle.
    pub area: Vec<f64>,
    /// Per node, its boundary as directed edges (counter-clockwise about its face's normal)
    /// if it is a leaf: `edges[edge_start[i]..edge_start[i + 1]]` (`set_boxes`).
    pub edge_start: Vec<u32>,
    pub edges: Vec<[DVec3; 2]>,
    /// Face ids from `first_back` on are the backs of thin faces (`back`): id
    /// `first_back + k` is the back of face `back_face[k]`.
    pub first_back: u32,
    pub back_face: Vec<u32>,
    leaf_radius: f64,
    /// Per region of the element mesh, the largest leaf radius: `leaf_radius`, or less
    /// across a narrow gap (`GAP_WIDTHS`).
    region_radius: Vec<f64>,
}

/// Leaves across a narrow gap (`Region::gap`) have a radius of at most this many times its
/// width: the light bounced into a gap fades within a few widths of its mouth, and a leaf
/// reaching deeper gave all of the part across the light at its mouth, which its face's own
/// leaf size made one leaf (room-245: two boxes' sides 2 mm apart, Cycles 0.02 where we
/// gave 0.65). With elements as fine (`mesh::sizing`) and links into a gap split
/// (`refine`), room-245's error from Cycles (`per_mesh.py`) went 4.66 → 3.80 %, room-78's
/// 2.69 → 2.36 %; at 4 widths (elements at 8), room-245 3.91 %.
const GAP_WIDTHS: f64 = 2.0;

/// One leaf before the tree is built.
#[derive(Debug, Clone, Copy)]
struct Leaf {
    tri: u32,
    face: u32,
    region: u32,
    area: f64,
    centroid: DVec3,
}

impl Hierarchy {
    /// The tree over the element triangles of `el` for which `keep(triangle)` holds (say,
    /// those not under a cover) and whose area is positive.
    ///
    /// A region's triangles are split until a node's bounds have a radius under
    /// `leaf_radius`: the leaves are groups of element triangles about that size, so the
    /// tree (and the links) scale with the area over the leaf size, not with the element
    /// count, which follows direct light's penumbrae.
    // The bake builds with backs (`build_two_sided`); unit tests build without.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn build(
        faces: &[Face],
        el: &Elements,
        keep: impl Fn(u32) -> bool,
        leaf_radius: f64,
    ) -> Self {
        Self::build_two_sided(faces, el, keep, leaf_radius, &[])
    }

    /// `build`, with the backs of the faces `backs` as faces of their own: `faces` ends with
    /// one turned-round copy of each (`back`), whose leaves are all the face's triangles
    /// (`keep` is about fronts).
    pub fn build_two_sided(
        faces: &[Face],
        el: &Elements,
        keep: impl Fn(u32) -> bool,
        leaf_radius: f64,
        backs: &[u32],
    ) -> Self {
        let first_back = faces.len() - backs.len();
        let mut back_of = vec![NONE; first_back];
        for (k, &f) in backs.iter().enumerate() {
            back_of[f as usize] = (first_back + k) as u32;
        }
        let mut by_face: Vec<Vec<Leaf>> = vec![Vec::new(); faces.len()];
        for (t, tri) in el.triangles.iter().enumerate() {
            let p = tri.map(|v| el.positions[v as usize]);
            let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            if !(area > 0.0) || !area.is_finite() {
                continue;
            }
            let face = el.tri_face[t];
            let leaf = Leaf {
                tri: t as u32,
                face,
                region: el.tri_region[t],
                area,
                centroid: (p[0] + p[1] + p[2]) / 3.0,
            };
            let back = back_of[face as usize];
            if back != NONE {
                by_face[back as usize].push(Leaf { face: back, ..leaf });
            }
            if keep(t as u32) {
                by_face[face as usize].push(leaf);
            }
        }
        let mut groups: Vec<(DVec3, Vec<Leaf>)> = by_face
            .into_iter()
            .filter(|g| !g.is_empty())
            .map(|g| {
                let (lo, hi) = bounds(g.iter().map(|l| l.centroid));
                ((lo + hi) * 0.5, g)
            })
            .collect();
        let region_radius = el
            .regions
            .iter()
            .map(|r| {
                r.gap
                    .map_or(leaf_radius, |w| leaf_radius.min(GAP_WIDTHS * w))
            })
            .collect();
        let mut h = Hierarchy {
            leaf_radius,
            region_radius,
            first_back: first_back as u32,
            back_face: backs.to_vec(),
            ..Default::default()
        };
        if !groups.is_empty() {
            h.faces(&mut groups);
        }
        h.leaf_node = vec![NONE; h.order.len()];
        for (i, n) in h.nodes.iter().enumerate() {
            if n.is_leaf() {
                h.leaf_node[n.lo as usize..n.hi as usize].fill(i as u32);
            }
        }
        h.corners = (0..h.order.len())
            .map(|p| {
                let [a, b, c] = el.triangles[h.order[p] as usize];
                [a, b, c, h.nodes[h.leaf_node[p] as usize].face]
            })
            .collect();
        h
    }

    /// Cluster levels: faces split by the spatial median of their centres.
    fn faces(&mut self, groups: &mut [(DVec3, Vec<Leaf>)]) -> u32 {
        if groups.len() == 1 {
            let mut leaves = std::mem::take(&mut groups[0].1);
            leaves.sort_by_key(|l| (l.region, l.tri));
            return self.regions(&mut leaves);
        }
        let (lo, hi) = bounds(groups.iter().map(|g| g.0));
        let axis = longest_axis(hi - lo);
        let mid = groups.len() / 2;
        groups.select_nth_unstable_by(mid, |a, b| {
            a.0[axis]
                .total_cmp(&b.0[axis])
                .then(a.1[0].face.cmp(&b.1[0].face))
        });
        self.halves(groups, mid, Self::faces)
    }

    /// A face's levels: its regions, split into halves by leaf count, then each region's
    /// triangles. `leaves` is sorted by region.
    fn regions(&mut self, leaves: &mut [Leaf]) -> u32 {
        let (first, last) = (leaves[0].region, leaves[leaves.len() - 1].region);
        if first == last {
            return self.triangles(leaves);
        }
        // Cut at the region boundary nearest the middle (never at either end).
        let mid = leaves.len() / 2;
        let r = leaves[mid].region;
        let start = leaves.partition_point(|l| l.region < r);
        let end = leaves.partition_point(|l| l.region <= r);
        let cut = if start > 0 && (mid - start <= end - mid || end == leaves.len()) {
            start
        } else {
            end
        };
        self.halves(leaves, cut, Self::regions)
    }

    /// A region's triangles split at the median of their centroids on the longest axis.
    fn triangles(&mut self, leaves: &mut [Leaf]) -> u32 {
        let (lo, hi) = bounds(leaves.iter().map(|l| l.centroid));
        // Centroid bounds understate the triangles' own by about a triangle: a leaf is
        // judged by its centroids' spread, which is what refinement can still tell apart.
        let radius = self
            .region_radius
            .get(leaves[0].region as usize)
            .copied()
            .unwrap_or(self.leaf_radius);
        if leaves.len() == 1 || 0.5 * (hi - lo).length() <= radius {
            let pos = self.order.len() as u32;
            let area: f64 = leaves.iter().map(|l| l.area).sum();
            let centroid = leaves.iter().map(|l| l.centroid * l.area).sum::<DVec3>() / area;
            leaves.sort_by_key(|l| l.tri);
            for l in leaves.iter() {
                self.order.push(l.tri);
                self.area.push(l.area);
            }
            self.nodes.push(Node {
                lo: pos,
                hi: pos + leaves.len() as u32,
                kids: [NONE; 2],
                face: leaves[0].face,
                area,
                centroid,
                lo_box: DVec3::ZERO,
                hi_box: DVec3::ZERO,
                moment: [0.0; 6],
                lit_centroid: DVec3::ZERO,
                lit_moment: [0.0; 6],
                weight: 0.0,
            });
            return (self.nodes.len() - 1) as u32;
        }
        let axis = longest_axis(hi - lo);
        let mid = leaves.len() / 2;
        leaves.select_nth_unstable_by(mid, |a, b| {
            a.centroid[axis]
                .total_cmp(&b.centroid[axis])
                .then(a.tri.cmp(&b.tri))
        });
        self.halves(leaves, mid, Self::triangles)
    }

    /// An inner node over `items` cut at `cut`, each half built by `level`.
    fn halves<T>(
        &mut self,
        items: &mut [T],
        cut: usize,
        level: fn(&mut Self, &mut [T]) -> u32,
    ) -> u32 {
        let id = self.open();
        let (a, b) = items.split_at_mut(cut);
        let ka = level(self, a);
        let kb = level(self, b);
        self.close(id, [ka, kb]);
        id
    }

    /// A new inner node, filled in by `close` once its children exist.
    fn open(&mut self) -> u32 {
        let pos = self.order.len() as u32;
        self.nodes.push(Node {
            lo: pos,
            hi: pos,
            kids: [NONE; 2],
            face: NONE,
            area: 0.0,
            centroid: DVec3::ZERO,
            lo_box: DVec3::ZERO,
            hi_box: DVec3::ZERO,
            moment: [0.0; 6],
            lit_centroid: DVec3::ZERO,
            lit_moment: [0.0; 6],
            weight: 0.0,
        });
        (self.nodes.len() - 1) as u32
    }

    fn close(&mut self, id: u32, kids: [u32; 2]) {
        let (a, b) = (&self.nodes[kids[0] as usize], &self.nodes[kids[1] as usize]);
        let area = a.area + b.area;
        let centroid = if area > 0.0 {
            (a.centroid * a.area + b.centroid * b.area) / area
        } else {
            (a.centroid + b.centroid) * 0.5
        };
        let face = if a.face == b.face { a.face } else { NONE };
        let hi = b.hi;
        let n = &mut self.nodes[id as usize];
        n.hi = hi;
        n.kids = kids;
        n.face = face;
        n.area = area;
        n.centroid = centroid;
    }

    /// Sets every node's box from its leaves' triangles, and each leaf's boundary edges: the
    /// edges of its triangles that no other of its triangles shares. An exact form factor to
    /// a leaf then sums over its boundary, not over each of its triangles.
    pub fn set_boxes(&mut self, faces: &[Face], el: &Elements) {
        self.edge_start = Vec::with_capacity(self.nodes.len() + 1);
        self.edges.clear();
        self.edge_start.push(0);
        let mut directed: Vec<(u32, u32)> = Vec::new();
        let mut boundary: Vec<(u32, u32)> = Vec::new();
        for n in &self.nodes {
            if n.is_leaf() {
                directed.clear();
                let normal = faces[n.face as usize].plane.n;
                for &t in &self.order[n.lo as usize..n.hi as usize] {
                    let [a, b, c] = el.triangles[t as usize];
                    let [pa, pb, pc] = [a, b, c].map(|v| el.positions[v as usize]);
                    let ccw = (pb - pa).cross(pc - pa).dot(normal) >= 0.0;
                    let (b, c) = if ccw { (b, c) } else { (c, b) };
                    directed.extend([(a, b), (b, c), (c, a)]);
                }
                // An inner edge appears once each way: sorted by undirected key, such pairs
                // sit side by side.
                directed.sort_unstable_by_key(|&(a, b)| (a.min(b), a.max(b), a));
                boundary.clear();
                let mut i = 0;
                while i < directed.len() {
                    let (a, b) = directed[i];
                    if i + 1 < directed.len() && directed[i + 1] == (b, a) {
                        i += 2;
                        continue;
                    }
                    boundary.push((a, b));
                    i += 1;
                }
                merge_collinear(&mut boundary, &el.positions, &mut self.edges);
            }
            self.edge_start.push(self.edges.len() as u32);
        }
        for i in (0..self.nodes.len()).rev() {
            let (lo, hi) = if self.nodes[i].is_leaf() {
                let n = &self.nodes[i];
                bounds(
                    self.order[n.lo as usize..n.hi as usize]
                        .iter()
                        .flat_map(|&t| el.triangles[t as usize])
                        .map(|v| el.positions[v as usize]),
                )
            } else {
                let [a, b] = self.nodes[i].kids.map(|k| &self.nodes[k as usize]);
                (a.lo_box.min(b.lo_box), a.hi_box.max(b.hi_box))
            };
            self.nodes[i].lo_box = lo;
            self.nodes[i].hi_box = hi;
            self.nodes[i].moment = self.moment_of(i, el);
            // Until `weigh` says where the light is, evenly over the area.
            let n = &mut self.nodes[i];
            (n.lit_centroid, n.lit_moment, n.weight) = (n.centroid, n.moment, 0.0);
        }
    }

    /// Node `i`'s second moment: from its triangles for a leaf, from its children's
    /// (parallel axis theorem) otherwise.
    fn moment_of(&self, i: usize, el: &Elements) -> [f64; 6] {
        let n = &self.nodes[i];
        let mut m = [0.0; 6];
        let add = add_outer;
        if n.area <= 0.0 {
            return m;
        }
        if n.is_leaf() {
            // ∫ over a triangle of x xᵀ (about any origin) is A/12 · (Σ vᵢvᵢᵀ + s sᵀ),
            // s = Σ vᵢ: with vertices taken about the centroid, s = 3·(centroid offset).
            for pos in n.lo..n.hi {
                let t = self.order[pos as usize] as usize;
                let a = self.area[pos as usize] / n.area;
                let v = el.triangles[t].map(|v| el.positions[v as usize] - n.centroid);
                for x in v {
                    add(&mut m, x, a / 12.0);
                }
                add(&mut m, v[0] + v[1] + v[2], a / 12.0);
            }
            return m;
        }
        for k in n.kids {
            let kid = &self.nodes[k as usize];
            let a = kid.area / n.area;
            for (mi, ki) in m.iter_mut().zip(kid.moment) {
                *mi += a * ki;
            }
            add(&mut m, kid.centroid - n.centroid, a);
        }
        m
    }

    /// Sets each node's `weight`, `lit_centroid` and `lit_moment` from `w`, an estimate of
    /// the radiosity at each leaf position (`order`). The solve keeps one radiosity per node,
    /// so a link from a far node sends its mean: with the factor taken over the node's area
    /// evenly, a floor whose middle is lit by a lamp sends as much to the walls from its dark
    /// rim as from its bright middle, and the errors have one sign over all of a node's links
    /// (an empty lit room lost 1 % of its indirect light). Weighting the node's geometry by
    /// where its light is moves the link's factor to where the light leaves from.
    pub fn weigh(&mut self, el: &Elements, w: &[f64]) {
        let mut total = vec![0.0f64; self.nodes.len()];
        for i in (0..self.nodes.len()).rev() {
            let n = &self.nodes[i];
            let (mut c, mut m, mut wt) = (DVec3::ZERO, [0.0; 6], 0.0);
            if n.is_leaf() {
                for pos in n.lo as usize..n.hi as usize {
                    let a = self.area[pos] * w[pos].max(0.0);
                    let t =
                        el.triangles[self.order[pos] as usize].map(|v| el.positions[v as usize]);
                    c += a * (t[0] + t[1] + t[2]) / 3.0;
                    wt += a;
                }
                if wt > 0.0 {
                    c /= wt;
                    for pos in n.lo as usize..n.hi as usize {
                        let a = self.area[pos] * w[pos].max(0.0) / wt;
                        let t = el.triangles[self.order[pos] as usize]
                            .map(|v| el.positions[v as usize] - c);
                        for x in t {
                            add_outer(&mut m, x, a / 12.0);
                        }
                        add_outer(&mut m, t[0] + t[1] + t[2], a / 12.0);
                    }
                }
            } else {
                wt = n.kids.iter().map(|&k| total[k as usize]).sum();
                if wt > 0.0 {
                    c = n
                        .kids
                        .iter()
                        .map(|&k| self.nodes[k as usize].lit_centroid * total[k as usize])
                        .sum::<DVec3>()
                        / wt;
                    for k in n.kids {
                        let kid = &self.nodes[k as usize];
                        let a = total[k as usize] / wt;
                        for (mi, ki) in m.iter_mut().zip(kid.lit_moment) {
                            *mi += a * ki;
                        }
                        add_outer(&mut m, kid.lit_centroid - c, a);
                    }
                }
            }
            total[i] = wt;
            let n = &mut self.nodes[i];
            if wt > 0.0 && n.area > 0.0 {
                (n.lit_centroid, n.lit_moment, n.weight) = (c, m, wt / n.area);
            } else {
                (n.lit_centroid, n.lit_moment, n.weight) = (n.centroid, n.moment, 0.0);
            }
        }
    }

    /// The scene face that face id `f` lies on: itself, or for a back the face it is the
    /// back of.
    pub fn real_face(&self, f: u32) -> u32 {
        match f.checked_sub(self.first_back) {
            Some(k) => self.back_face.get(k as usize).copied().unwrap_or(f),
            None => f,
        }
    }

    /// Whether face id `f` is the back of a thin face.
    pub fn is_back(&self, f: u32) -> bool {
        f != NONE && self.real_face(f) != f
    }

    /// The boundary edges of node `i` if it is a leaf (`set_boxes`), else none.
    pub fn leaf_edges(&self, i: usize) -> &[[DVec3; 2]] {
        &self.edges[self.edge_start[i] as usize..self.edge_start[i + 1] as usize]
    }

    /// Index of the leaf node `n`.
    pub fn leaf_index(&self, n: &Node) -> usize {
        self.leaf_node[n.lo as usize] as usize
    }

    /// Bytes held per leaf (nodes; order, leaf index, area and corners per position; leaf
    /// edges), for the stats.
    pub fn bytes_per_leaf(&self) -> f64 {
        let n = self.order.len().max(1) as f64;
        (self.nodes.len() * (std::mem::size_of::<Node>() + 4)
            + self.order.len() * 32
            + self.edges.len() * 48) as f64
            / n
    }
}

/// Adds `w·d·dᵀ` to the symmetric matrix `m` (`[xx, yy, zz, xy, xz, yz]`).
fn add_outer(m: &mut [f64; 6], d: DVec3, w: f64) {
    m[0] += w * d.x * d.x;
    m[1] += w * d.y * d.y;
    m[2] += w * d.z * d.z;
    m[3] += w * d.x * d.y;
    m[4] += w * d.x * d.z;
    m[5] += w * d.y * d.z;
}

/// Appends the boundary `edges` (directed, by vertex) to `out` as position pairs, chains of
/// collinear edges joined into one: the penumbra's fine triangles split a leaf's straight
/// sides at many vertices, and each edge costs the exact factor an `atan2`. Where the edges
/// do not chain (a vertex starting two boundary edges) they are kept as they are.
fn merge_collinear(edges: &mut [(u32, u32)], positions: &[DVec3], out: &mut Vec<[DVec3; 2]>) {
    edges.sort_unstable();
    let next = |v: u32, edges: &[(u32, u32)]| -> Option<usize> {
        let i = edges.partition_point(|e| e.0 < v);
        (i < edges.len() && edges[i].0 == v && (i + 1 == edges.len() || edges[i + 1].0 != v))
            .then_some(i)
    };
    let mut used = vec![false; edges.len()];
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        // A run through the edge a loop starts at stays split there: one edge more.
        let first = start;
        let mut e = first;
        let mut from = positions[edges[e].0 as usize];
        loop {
            used[e] = true;
            let (_, b) = edges[e];
            let to = positions[b as usize];
            match next(b, edges) {
                Some(n) if !used[n] && collinear(from, to, positions[edges[n].1 as usize]) => {
                    e = n;
                }
                _ => {
                    out.push([from, to]);
                    match next(b, edges) {
                        Some(n) if !used[n] => {
                            e = n;
                            from = to;
                        }
                        _ => break,
                    }
                }
            }
        }
    }
}

/// Whether `b` lies on the segment `a`–`c`, within rounding.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let (u, w) = (b - a, c - b);
    u.dot(w) > 0.0 && u.cross(w).length() <= 1e-9 * u.length() * w.length()
}

pub fn bounds(pts: impl Iterator<Item = DVec3>) -> (DVec3, DVec3) {
    pts.fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

fn longest_axis(d: DVec3) -> usize {
    if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::indirect::patches::test::grid_elements;
    use crate::scene::test::face;

    #[test]
    fn tree_covers_every_leaf_once_and_groups_faces() {
        let v = DVec3::new;
        let f0 = face(
            &[v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let f1 = face(
            &[v(0., 0., 1.), v(0., 1., 1.), v(1., 1., 1.), v(1., 0., 1.)],
            DVec3::ONE,
            DVec3::ZERO,
        );
        let faces = [f0, f1];
        let mut el = grid_elements(&faces, 3);
        // Two regions on face 0: triangles by parity.
        for t in 0..el.triangles.len() {
            if el.tri_face[t] == 0 {
                el.tri_region[t] = (t % 2) as u32;
            }
        }
        let mut h = Hierarchy::build(&faces, &el, |t| t != 0, 0.0);
        h.set_boxes(&faces, &el);
        let n = el.triangles.len() - 1;
        assert_eq!(h.order.len(), n);
        let mut seen = h.order.clone();
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), n);
        assert!(!seen.contains(&0));
        let root = &h.nodes[0];
        assert_eq!((root.lo, root.hi), (0, n as u32));
        assert!(!root.is_planar());
        assert!((root.area - 2.0 + el_area(&el, 0)).abs() < 1e-12);
        // The root's children are the two faces; face 0's children its two regions.
        let [a, b] = root.kids.map(|k| &h.nodes[k as usize]);
        assert!(a.is_planar() && b.is_planar() && a.face != b.face);
        let f0n = if a.face == 0 { a } else { b };
        for k in f0n.kids {
            let kid = &h.nodes[k as usize];
            let regions: Vec<u32> = (kid.lo..kid.hi)
                .map(|i| el.tri_region[h.order[i as usize] as usize])
                .collect();
            assert!(regions.iter().all(|&r| r == regions[0]));
        }
        // Every node's area is its leaves' and its box holds its children's.
        for nd in &h.nodes {
            if !nd.is_leaf() {
                let [a, b] = nd.kids.map(|k| &h.nodes[k as usize]);
                assert!((nd.area - a.area - b.area).abs() < 1e-12);
                assert!(nd.lo_box.cmple(a.lo_box).all() && nd.hi_box.cmpge(b.hi_box).all());
                assert_eq!((nd.lo, nd.hi), (a.lo, b.hi));
                assert_eq!(a.hi, b.lo);
            }
        }
    }

    fn el_area(el: &Elements, t: usize) -> f64 {
        let p = el.triangles[t].map(|v| el.positions[v as usize]);
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    }
}

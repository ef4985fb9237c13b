//! A posteriori refinement to a tolerance on the direct light (issue 13). The exact direct
//! light is cheap to evaluate anywhere (closed form where lit, the visible part of the light
//! in penumbra, nothing in umbra), so after the conforming CDT each element is checked where
//! linear interpolation errs most, at its edge midpoints and its centroid, and split where
//! |interpolated − exact| > tolerance × (exact + floor). The floor, a fraction of the
//! receiver's brightest value, keeps dark regions from refining without end. Splits insert
//! points into the CDT, which keeps the D1/D0 constraint edges (a constraint edge is split
//! into two constraint halves) and the Delaunay property (spade re-legalises around each new
//! point). Nothing is split below the lower size bound.
//!
//! The light is handed in by the caller (`LightAt`), so the mesh stage does not reach into
//! the direct stage; every value computed here is returned with the mesh and reused as the
//! vertex's direct light.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::{Point2, PositionInTriangulation, Triangulation};

use super::{corner_split, doubt, extract, Cdt, ReceiverMesh};
use crate::geom::polygon::orient;
use crate::geom::Frame;
use crate::regions::relation::Relation;
use crate::regions::{ReceiverRegions, Region};
use crate::scene::settings::Settings;
use crate::scene::Tolerances;
use crate::BakeError;

/// Direct irradiance at a point of the receiver (2-D frame) that lies in or on the border of
/// the given regions, with its light counts (umbra skipped, lit, penumbra).
pub type LightAt<'a> = dyn Fn(DVec2, &[&Region]) -> (DVec3, [u64; 3]) + Sync + 'a;

/// The floor of the error bound, as a fraction of the receiver's brightest vertex (per
/// channel): an element is fine where its error is under tolerance × this much light.
pub const FLOOR: f64 = 0.01;
/// Elements are split when their error at a sample passes this fraction of the allowed
/// error: the midpoints and centroid are where linear interpolation errs most for a smooth
/// field, but not always, and the bound must hold at every point.
pub const SAFETY: f64 = 0.4;
/// Passes at most: each halves the elements that fail, so 30 passes span 2^30 in size.
pub const MAX_PASSES: u32 = 30;
/// A triangle lower than this fraction of an edge is flat: its edges are not split.
/// Rounding makes such triangles (three points of one kinked constraint line), and
/// splitting them cuts ever thinner slivers whose inner points cross the line
/// (tests/random_relations.rs at 1e-6); a strip that geometry made, along a receiver's edge
/// where light comes round the corner, is split like any other (at 1e-3, a leg's 5e-4-high
/// strips were left whole: room medium 2.8× the tolerance).
pub const FLAT: f64 = 1e-4;
/// The lower size bound as a fraction of `penumbra_element_size`.
pub const LOWER_BOUND: f64 = 1.0 / 16.0;

/// What refinement did on one receiver.
#[derive(Debug, Clone, Copy, Default)]
pub struct RefineStats {
    /// Passes that split at least one element.
    pub passes: u64,
    /// Vertices inserted by those passes.
    pub vertices_added: u64,
    /// Elements before the first pass and after the last.
    pub elements_before: u64,
    pub elements_after: u64,
    /// Light evaluations (vertices, midpoints, centroids).
    pub evaluations: u64,
}

/// The lower size bound for `settings`.
pub fn lower_bound(settings: &Settings) -> f64 {
    settings.penumbra_element_size * LOWER_BOUND
}

fn key(p: DVec2) -> [u64; 2] {
    [p.x.to_bits(), p.y.to_bits()]
}

/// A hasher for the light cache's keys (bits of two coordinates): the standard SipHash was a
/// sixth of a direct-only bake of data1 (`perf`), for keys no adversary chooses.
#[derive(Default, Clone, Copy)]
pub(crate) struct KeyHasher(u64);

impl std::hash::Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }
    fn write_u64(&mut self, x: u64) {
        // One multiply-rotate step per word (as rustc's FxHasher).
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }
}

type Cache = HashMap<[u64; 2], (DVec3, [u64; 3]), std::hash::BuildHasherDefault<KeyHasher>>;

/// Refines `cdt` until every element meets `settings.tolerance` or the lower bound, and
/// returns the element mesh (D0 rows and corners split) with the direct light known at
/// every vertex.
#[allow(clippy::too_many_arguments)]
pub(crate) fn refine(
    cdt: &mut Cdt,
    rr: &ReceiverRegions,
    shift: DVec2,
    frame: &Frame,
    settings: &Settings,
    tol: &Tolerances,
    light: &LightAt,
    budget: &AtomicU64,
    progress: &crate::Progress,
) -> Result<(ReceiverMesh, RefineStats), BakeError> {
    let lower = lower_bound(settings);
    let mut stats = RefineStats::default();
    let mut cache = Cache::default();
    add_frame(cdt);
    loop {
        progress.check()?;
        let mut m = extract(cdt, shift, rr, frame, false, tol);
        corner_split::split(&mut m, &rr.d0_lines, tol);
        let nv = m.positions.len();
        if stats.passes == 0 {
            stats.elements_before = m.triangles.len() as u64;
        }

        // Vertex values: each with the regions of the triangles around it (after the D0 and
        // corner splits, only those of its own side).
        let missing: Vec<usize> = (0..nv)
            .filter(|&v| !cache.contains_key(&key(m.eval[v])))
            .collect();
        let mut slot = vec![u32::MAX; nv];
        for (k, &v) in missing.iter().enumerate() {
            slot[v] = k as u32;
        }
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); missing.len()];
        for (t, tri) in m.triangles.iter().enumerate() {
            for &v in tri {
                let k = slot[v as usize];
                if k == u32::MAX {
                    continue;
                }
                let r = m.tri_region[t];
                if !around[k as usize].contains(&r) {
                    around[k as usize].push(r);
                }
            }
        }
        let values: Vec<_> = missing
            .par_iter()
            .zip(&around)
            .map(|(&v, around)| {
                let regs: Vec<&Region> = around.iter().map(|&r| &m.regions[r as usize]).collect();
                light(m.eval[v], &regs)
            })
            .collect();
        stats.evaluations += values.len() as u64;
        for (&v, val) in missing.iter().zip(values) {
            cache.insert(key(m.eval[v]), val);
        }
        progress.check()?;
        let vals: Vec<DVec3> = m.eval.iter().map(|p| cache[&key(*p)].0).collect();
        let value = |v: u32| vals[v as usize];
        let floor = vals.iter().fold(DVec3::ZERO, |a, b| a.max(*b)) * FLOOR;

        let used = budget.load(Ordering::Relaxed);
        if stats.passes >= MAX_PASSES as u64 || used >= settings.max_elements {
            return Ok(finish(m, &cache, stats));
        }

        // Samples: edge midpoints (edges at least twice the lower bound) and centroids
        // (elements whose edges are all splittable), at the mean of the evaluation points so
        // that a sample beside a D0 row or a corner lies on its element's side.
        // Checked exactly only where the vertex values leave the element in doubt.
        let allowed = |t: usize| {
            let least = m.triangles[t]
                .iter()
                .map(|&v| value(v).abs())
                .fold(DVec3::splat(f64::INFINITY), DVec3::min);
            (least + floor) * (settings.tolerance * SAFETY)
        };
        let doubtful = doubt::doubtful(&m.positions, &m.triangles, &m.tri_region, &value, &allowed);
        let mut samples: Vec<Sample> = Vec::new();
        for (t, tri) in m.triangles.iter().enumerate() {
            if !doubtful[t] {
                continue;
            }
            // In umbra of every light the exact light is nothing, and so are the vertices
            // (those on its border lie where the light comes in continuously, from nothing,
            // or on a D0 row whose copy on this side is dark): nothing to check.
            let region = &m.regions[m.tri_region[t] as usize];
            if region.relations.iter().all(|r| *r == Relation::Umbra) {
                continue;
            }
            let p = tri.map(|v| m.positions[v as usize]);
            let mut splittable = 0;
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if (p[k] - p[(k + 1) % 3]).length() < 2.0 * lower {
                    continue;
                }
                splittable += 1;
                samples.push(Sample {
                    tri: t as u32,
                    at: 0.5 * (m.eval[a as usize] + m.eval[b as usize]),
                    interp: 0.5 * (value(a) + value(b)),
                    split: Split::Edge(a, b),
                });
            }
            if splittable == 3 {
                let c = tri.map(|v| m.eval[v as usize]);
                samples.push(Sample {
                    tri: t as u32,
                    at: (c[0] + c[1] + c[2]) / 3.0,
                    interp: (value(tri[0]) + value(tri[1]) + value(tri[2])) / 3.0,
                    split: Split::Centroid((p[0] + p[1] + p[2]) / 3.0),
                });
                // In penumbra the light kinks along critical lines that no constraint
                // follows, and a kink inside an element errs most beside it, not at the
                // midpoints: three more points, halfway from the centroid to each corner.
                if region.relations.contains(&Relation::Penumbra) {
                    let centre = (p[0] + p[1] + p[2]) / 3.0;
                    let centre_eval = (c[0] + c[1] + c[2]) / 3.0;
                    let centre_value = (value(tri[0]) + value(tri[1]) + value(tri[2])) / 3.0;
                    for k in 0..3 {
                        samples.push(Sample {
                            tri: t as u32,
                            at: 0.5 * (centre_eval + c[k]),
                            interp: 0.5 * (centre_value + value(tri[k])),
                            split: Split::Centroid(0.5 * (centre + p[k])),
                        });
                    }
                }
            }
        }
        // A midpoint may become a vertex, whose value is then this one: on an edge between
        // two regions it takes both (a lit region's shortcut is right only inside it).
        let mut tri_of_edge: HashMap<(u32, u32), u32, std::hash::BuildHasherDefault<KeyHasher>> =
            HashMap::with_capacity_and_hasher(3 * m.triangles.len(), Default::default());
        for (t, tri) in m.triangles.iter().enumerate() {
            for k in 0..3 {
                tri_of_edge.insert((tri[k], tri[(k + 1) % 3]), t as u32);
            }
        }
        let mut todo: Vec<(DVec2, u32, u32)> = samples
            .iter()
            .filter(|s| !cache.contains_key(&key(s.at)))
            .map(|s| {
                let other = match s.split {
                    Split::Edge(a, b) => tri_of_edge.get(&(b, a)).copied().unwrap_or(s.tri),
                    Split::Centroid(_) => s.tri,
                };
                (s.at, s.tri, other)
            })
            .collect();
        todo.sort_unstable_by_key(|(p, _, _)| key(*p));
        todo.dedup_by_key(|(p, _, _)| key(*p));
        let values: Vec<_> = todo
            .par_iter()
            .map(|&(q, t, o)| {
                let (rt, ro) = (m.tri_region[t as usize], m.tri_region[o as usize]);
                if rt == ro {
                    light(q, &[&m.regions[rt as usize]])
                } else {
                    light(q, &[&m.regions[rt as usize], &m.regions[ro as usize]])
                }
            })
            .collect();
        stats.evaluations += values.len() as u64;
        for (&(q, _, _), val) in todo.iter().zip(values) {
            cache.insert(key(q), val);
        }
        progress.check()?;

        let fails = |s: &Sample| {
            let exact = cache[&key(s.at)].0;
            let err = (s.interp - exact).abs();
            let allowed = (exact.abs() + floor) * (settings.tolerance * SAFETY);
            err.cmpgt(allowed).any()
        };
        let mut edges: Vec<(u32, u32)> = Vec::new();
        let mut centroids: Vec<DVec2> = Vec::new();
        let mut edge_failed = vec![false; m.triangles.len()];
        for s in &samples {
            if let Split::Edge(a, b) = s.split {
                if fails(s) {
                    edge_failed[s.tri as usize] = true;
                    edges.push((a, b));
                }
            }
        }
        for s in &samples {
            if let Split::Centroid(c) = s.split {
                // One interior point per element and pass.
                if !edge_failed[s.tri as usize] && fails(s) {
                    edge_failed[s.tri as usize] = true;
                    centroids.push(c);
                }
            }
        }
        if edges.is_empty() && centroids.is_empty() {
            return Ok(finish(m, &cache, stats));
        }

        // Back to the CDT's vertices: copies made by the D0 and corner splits stand for the
        // CDT vertex at their position.
        let handle_at: HashMap<
            [u64; 2],
            FixedVertexHandle,
            std::hash::BuildHasherDefault<KeyHasher>,
        > = cdt
            .fixed_vertices()
            .map(|h| {
                let p = cdt.vertex(h).position();
                (key(DVec2::new(p.x, p.y) - shift), h)
            })
            .collect();
        // Directed as in their triangle (counter-clockwise), so that the triangle that failed
        // lies on the left.
        let mut pairs: Vec<(FixedVertexHandle, FixedVertexHandle)> = edges
            .iter()
            .filter_map(|&(a, b)| {
                let ha = *handle_at.get(&key(m.positions[a as usize]))?;
                let hb = *handle_at.get(&key(m.positions[b as usize]))?;
                (ha != hb).then_some((ha, hb))
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let before = cdt.num_vertices();
        let room = settings.max_elements.saturating_sub(used) as usize;
        for (k, &(a, b)) in pairs.iter().enumerate() {
            if k % 1024 == 0 {
                progress.check()?;
            }
            if cdt.num_vertices() - before >= room {
                break;
            }
            split_edge(cdt, a, b);
        }
        for &c in &centroids {
            if cdt.num_vertices() - before >= room {
                break;
            }
            let c = c + shift;
            insert_inside(cdt, Point2::new(c.x, c.y));
        }
        let added = (cdt.num_vertices() - before) as u64;
        budget.fetch_add(added, Ordering::Relaxed);
        stats.passes += 1;
        stats.vertices_added += added;
        // Every split was refused (kinked constraints, rounding): the next pass would find
        // the same elements.
        if added == 0 {
            return Ok(finish(
                extract_split(cdt, shift, rr, frame, tol),
                &cache,
                stats,
            ));
        }
    }
}

fn extract_split(
    cdt: &Cdt,
    shift: DVec2,
    rr: &ReceiverRegions,
    frame: &Frame,
    tol: &Tolerances,
) -> ReceiverMesh {
    let mut m = extract(cdt, shift, rr, frame, false, tol);
    corner_split::split(&mut m, &rr.d0_lines, tol);
    m
}

/// The mesh with the values known at its vertices.
fn finish(
    mut m: ReceiverMesh,
    cache: &Cache,
    mut stats: RefineStats,
) -> (ReceiverMesh, RefineStats) {
    stats.elements_after = m.triangles.len() as u64;
    m.known_direct = m
        .eval
        .iter()
        .map(|p| cache.get(&key(*p)).copied())
        .collect();
    (m, stats)
}

struct Sample {
    tri: u32,
    /// Where the light is evaluated.
    at: DVec2,
    /// The element's linear interpolant there.
    interp: DVec3,
    split: Split,
}

enum Split {
    /// Element vertices of the edge.
    Edge(u32, u32),
    /// Where to insert a vertex.
    Centroid(DVec2),
}

/// Inserts `p` unless rounding put it outside the hull (the receiver).
fn insert_inside(cdt: &mut Cdt, p: Point2<f64>) {
    if !matches!(
        cdt.locate(p),
        PositionInTriangulation::OutsideOfConvexHull(_)
    ) {
        let _ = cdt.insert(p);
    }
}

/// Splits the CDT edge `a`→`b` (the failed triangle on its left) at its midpoint. An edge
/// inside a region takes the midpoint as a new vertex. A constraint (a D1/D0 edge, or the
/// receiver's boundary, which the frame put inside the triangulation) is split by the
/// triangulation itself (`split_constraint`).
fn split_edge(cdt: &mut Cdt, a: FixedVertexHandle, b: FixedVertexHandle) {
    let (pa, pb) = (cdt.vertex(a).position(), cdt.vertex(b).position());
    let mid = Point2::new(0.5 * (pa.x + pb.x), 0.5 * (pa.y + pb.y));
    let Some(e) = cdt.get_edge_from_neighbors(a, b).map(|e| e.fix()) else {
        // Flipped away by an earlier split of this pass: the region still wants a vertex.
        insert_inside(cdt, mid);
        return;
    };
    let edge = cdt.directed_edge(e);
    if edge.as_undirected().is_part_of_convex_hull() {
        return;
    }
    if !edge.is_constraint_edge() {
        // An edge of a flat triangle (three points of one kinked constraint line, spanned
        // by the triangulation): its midpoint lies on that line to within rounding, and
        // would cut slivers that rounding may turn over (tests/mesh_validity.rs).
        let len = DVec2::new(pb.x - pa.x, pb.y - pa.y).length();
        let flat = [edge, edge.rev()].iter().any(|side| {
            side.opposite_position().is_some_and(|c| {
                let h = orient(
                    DVec2::new(pa.x, pa.y),
                    DVec2::new(pb.x, pb.y),
                    DVec2::new(c.x, c.y),
                )
                .abs()
                    / len.max(f64::MIN_POSITIVE);
                h < FLAT * len
            })
        });
        if flat {
            return;
        }
        insert_inside(cdt, mid);
        return;
    }
    split_constraint(cdt, e, mid);
}

/// Splits a constraint edge at `mid` (its midpoint) in the triangulation's own structure.
/// Inserted as a point, a rounded midpoint lies a hair off the line, and the constraint put
/// back through it leaves a sliver between the line and the point, or a triangle that
/// rounding turns over (tests/mesh_validity.rs). spade splits an existing constraint in
/// place only where a new constraint crosses it, at a point its caller chooses: so a
/// constraint is drawn from the vertex opposite the edge on one side to the one on the
/// other, split at `mid`, and then unmarked, and the edge's halves stay one constraint line.
/// Where that line would leave the two triangles (their quadrilateral is not convex), it is
/// drawn to a vertex put for the purpose just beyond the midpoint, and removed after.
fn split_constraint(cdt: &mut Cdt, e: spade::handles::FixedDirectedEdgeHandle, mid: Point2<f64>) {
    let edge = cdt.directed_edge(e);
    let (ha, hb) = (edge.from().fix(), edge.to().fix());
    let p2 = |p: Point2<f64>| DVec2::new(p.x, p.y);
    let (a, b) = (p2(edge.from().position()), p2(edge.to().position()));
    let (Some(c), Some(d)) = (
        edge.opposite_vertex().map(|v| v.fix()),
        edge.rev().opposite_vertex().map(|v| v.fix()),
    ) else {
        return;
    };
    let (pc, pd) = (p2(cdt.vertex(c).position()), p2(cdt.vertex(d).position()));
    let crosses = |from: DVec2, to: DVec2| {
        let (sa, sb) = (orient(from, to, a), orient(from, to, b));
        (sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0)
    };
    if crosses(pc, pd) {
        draw_and_unmark(cdt, (ha, hb), c, d, mid);
        return;
    }
    // A vertex strictly inside the triangle a, d, b, on the line from c through the
    // midpoint: the line from c to it crosses the edge and nothing else.
    let m = p2(mid);
    let side = orient(a, b, pd).signum();
    let inside = |q: DVec2| {
        orient(a, b, q) * side > 0.0
            && orient(b, pd, q) * side > 0.0
            && orient(pd, a, q) * side > 0.0
    };
    let mut t = 1.0;
    let mut beyond = None;
    for _ in 0..40 {
        let q = m + (m - pc) * t;
        if inside(q) && crosses(pc, q) {
            beyond = Some(q);
            break;
        }
        t *= 0.5;
    }
    let Some(q) = beyond else {
        return;
    };
    let Ok(temp) = cdt.insert(Point2::new(q.x, q.y)) else {
        return;
    };
    // Inserting legalises edges beyond the constraint only: c still faces the edge.
    if cdt.get_edge_from_neighbors(ha, hb).is_some() {
        draw_and_unmark(cdt, (ha, hb), c, temp, mid);
    }
    cdt.remove(temp);
}

/// Draws a constraint from `c` to `d` that splits what it crosses at `mid`, then unmarks
/// what it drew. Where `mid` is no valid split point, spade connects to a vertex nearby
/// instead, and the drawn line may then run along a constraint that was there before (a
/// boundary edge): that one stays marked, or the receiver would lose its boundary.
fn draw_and_unmark(
    cdt: &mut Cdt,
    (a, b): (FixedVertexHandle, FixedVertexHandle),
    c: FixedVertexHandle,
    d: FixedVertexHandle,
    mid: Point2<f64>,
) {
    // spade takes `mid` where it lies on the edge or in a triangle beside it; elsewhere (a
    // vertex there already, or rounding past a thin triangle) it would route the edge
    // through a vertex nearby instead, moving the constraint: left unsplit then.
    let Some(edge) = cdt.get_edge_from_neighbors(a, b) else {
        return;
    };
    let (e, left, right) = (
        edge.fix().as_undirected(),
        edge.face().fix(),
        edge.rev().face().fix(),
    );
    let valid = match cdt.locate(mid) {
        PositionInTriangulation::OnEdge(x) => x.as_undirected() == e,
        PositionInTriangulation::OnFace(f) => {
            left.as_inner() == Some(f) || right.as_inner() == Some(f)
        }
        _ => false,
    };
    if !valid {
        return;
    }
    let mut before: Vec<(FixedVertexHandle, FixedVertexHandle)> = Vec::new();
    for v in [c, d] {
        for e in cdt.vertex(v).out_edges() {
            if e.is_constraint_edge() {
                let (x, y) = (e.from().fix(), e.to().fix());
                before.push((x.min(y), x.max(y)));
            }
        }
    }
    let drawn_edges = cdt.add_constraint_and_split(c, d, |_| mid);
    for drawn in drawn_edges {
        let e = cdt.directed_edge(drawn);
        let (x, y) = (e.from().fix(), e.to().fix());
        if !before.contains(&(x.min(y), x.max(y))) {
            cdt.remove_constraint_edge(drawn.as_undirected());
        }
    }
}

/// Puts four vertices around the receiver, so that its boundary edges lie inside the
/// triangulation with a triangle beyond them, and are split as the D1/D0 edges are
/// (`split_constraint`). Extraction leaves out the triangles between the boundary and the
/// frame (`extract`). Split from the hull instead, a boundary edge's midpoint becomes a hull
/// vertex, and removing a helper vertex beyond a straight run of boundary vertices left
/// flat triangles that stopped its splits.
fn add_frame(cdt: &mut Cdt) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for v in cdt.vertices() {
        let p = DVec2::new(v.position().x, v.position().y);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if !(lo.x < hi.x && lo.y < hi.y) {
        return;
    }
    let pad = (hi - lo).max_element();
    let (lo, hi) = (lo - DVec2::splat(pad), hi + DVec2::splat(pad));
    for p in [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)] {
        let _ = cdt.insert(Point2::new(p.x, p.y));
    }
}

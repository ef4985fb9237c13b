//! Stage `mesh` (paper 2.5, T_m): elements. Per receiver, a constrained Delaunay triangulation (spade)
//! that conforms to every kept discontinuity edge and the receiver boundary. Nodes are seeded
//! on a lattice whose spacing depends on the region (fine in penumbra) and shrinks near the
//! lights (`sizing`), then Delaunay refinement fixes angles. Edges across which some light jumps from lit to umbra (D0:
//! contact shadows, point-light shadows) get two vertex rows, one per side.

pub mod cancel;
mod corner_split;
mod doubt;
pub mod elements;
pub mod refine;
pub mod sizing;

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::geom::Frame;
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use crate::geom::polygon::{orient, segment_distance as seg_dist};
use crate::mesh::sizing::Sizing;
use crate::regions::arrangement::ArrFace;
use crate::regions::relation::Relation;
use crate::regions::{ReceiverRegions, Region};
use crate::scene::settings::Settings;
use crate::scene::Tolerances;
use crate::BakeError;

/// The element mesh of one receiver, in its 2-D frame.
#[derive(Debug, Clone, Default)]
pub struct ReceiverMesh {
    pub positions: Vec<DVec2>,
    /// Where lighting is evaluated: the position, except on D0 rows, where it is moved a
    /// hair into the vertex's own side so that it takes that side's limit value.
    pub eval: Vec<DVec2>,
    pub triangles: Vec<[u32; 3]>,
    pub tri_region: Vec<u32>,
    pub regions: Vec<Region>,
    /// Direct light per vertex when refinement computed it (else empty).
    pub known_direct: Vec<Option<(DVec3, [u64; 3])>>,
    /// Vertices where D0 edges end or turn (a box's foot corner): `corner_split` gives
    /// each triangle there its own copy.
    pub d0_corners: Vec<DVec2>,
    pub refine: refine::RefineStats,
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Meshes one receiver. `budget` counts vertices over the whole scene so that a bake that
/// would exceed `max_elements` stops early with a clear error. Evaluation points on D0 rows
/// move at least `tol.d0_offset` off the line, so that the exact side tests of the light
/// stages see them on their own side. With `light`, elements are then refined until the
/// direct light meets `settings.tolerance` (`refine`); the lattice is then seeded at the lit
/// size everywhere, penumbrae included, and refinement finds where it must be finer.
#[allow(clippy::too_many_arguments)]
pub fn mesh_receiver(
    rr: &ReceiverRegions,
    sizing: &Sizing,
    settings: &Settings,
    tol: &Tolerances,
    budget: &AtomicU64,
    progress: &crate::Progress,
    light: Option<&refine::LightAt>,
) -> Result<ReceiverMesh, BakeError> {
    let light = light.filter(|_| !settings.uniform);
    let arr = &rr.arrangement;
    let shift = shift_away_from_zero(&arr.vertices);
    let mut cdt = Cdt::new();
    let mut handle: Vec<Option<FixedVertexHandle>> = vec![None; arr.vertices.len()];
    let mut inserted = 0usize;
    let mut vh = |cdt: &mut Cdt, v: u32| -> Option<FixedVertexHandle> {
        if let Some(h) = handle[v as usize] {
            return Some(h);
        }
        let p = arr.vertices[v as usize] + shift;
        let h = cdt.insert(Point2::new(p.x, p.y)).ok()?;
        handle[v as usize] = Some(h);
        inserted += 1;
        Some(h)
    };
    for (k, &e) in rr.kept_edges.iter().enumerate() {
        if k % 1024 == 0 {
            progress.check()?;
        }
        let [a, b] = arr.edges[e as usize].v;
        let (Some(ha), Some(hb)) = (vh(&mut cdt, a), vh(&mut cdt, b)) else {
            continue;
        };
        if ha != hb {
            cdt.add_constraint_and_split(ha, hb, |p| p);
        }
    }

    // Seed nodes: a lattice per face, spaced by the face's relation and the distance to the
    // lights.
    let coarse = settings.element_size;
    let corners = Corners::new(&rr.d0_lines, coarse);
    let mut seeds = Vec::new();
    for (f, rf) in arr.faces.iter().zip(&rr.faces) {
        progress.check()?;
        let penumbra = !settings.uniform
            && light.is_none()
            && rf.relations.iter().any(|r| *r == Relation::Penumbra);
        let seen = |l: usize| rf.relations.get(l).is_some_and(|r| *r != Relation::Umbra);
        let size = |p: DVec2, reach: f64| {
            let s = if penumbra {
                sizing.penumbra(p, reach, &seen)
            } else {
                sizing.lit(p, reach, &seen)
            };
            // Refinement finds what the corners need (and `corner_split` gives each
            // triangle there its own value): no grading towards them beforehand.
            if light.is_some() {
                s
            } else {
                corners.cap(s, p, reach)
            }
        };
        graded_lattice(&arr.vertices, f, &size, &mut seeds);
    }
    let used = budget.fetch_add(seeds.len() as u64 + inserted as u64, Ordering::Relaxed)
        + seeds.len() as u64;
    if used > settings.max_elements {
        return Err(BakeError::setting(
            "penumbra_element_size",
            format!(
                "the mesh would exceed max_elements = {} (raise element sizes or max_elements)",
                settings.max_elements
            ),
        ));
    }
    let dense = inserted > DENSE_RATIO * seeds.len().max(1);
    for (k, p) in seeds.into_iter().enumerate() {
        if k % 4096 == 0 {
            progress.check()?;
        }
        let p = p + shift;
        let _ = cdt.insert(Point2::new(p.x, p.y));
    }
    progress.check()?;
    let coarse_area = 0.433 * coarse * coarse;
    let fine = sizing
        .smallest()
        .min(settings.penumbra_element_size)
        .min(corners.smallest());
    let fine_area = 0.433 * fine * fine;
    let extra =
        (settings.max_elements.saturating_sub(used) as usize).min(cdt.num_vertices() * 4 + 64);
    let angles = RefinementParameters::new()
        .with_angle_limit(AngleLimit::from_deg(settings.min_angle))
        .with_max_allowed_area(coarse_area * 1.5)
        .with_min_required_area(fine_area * if dense { DENSE_MIN_AREA } else { 0.02 });
    cancel::refine_in_rounds(&mut cdt, angles.clone(), extra, progress)?;
    budget.fetch_add(
        cdt.num_vertices() as u64 - inserted as u64,
        Ordering::Relaxed,
    );
    if settings.uniform {
        let mut m = extract(&cdt, shift, rr, sizing.frame(), true, tol);
        m.regions = vec![rr.faces.first().cloned().unwrap_or(Region {
            relations: Vec::new(),
            blockers: Vec::new(),
        })];
        return Ok(m);
    }
    progress.check()?;
    if let Some(light) = light {
        let (mut m, stats) = refine::refine(
            &mut cdt,
            rr,
            shift,
            sizing.frame(),
            settings,
            tol,
            light,
            budget,
            progress,
        )?;
        m.refine = stats;
        return Ok(m);
    }
    Ok(extract(&cdt, shift, rr, sizing.frame(), false, tol))
}

/// A receiver is dense when its discontinuity vertices outnumber the lattice its element
/// sizes ask for by this much: the discontinuities alone then cut it finer than the finest
/// element (quads2000's floor: 211k arrangement vertices against some thousand lattice
/// points, under 2,000 overlapping penumbrae).
const DENSE_RATIO: usize = 16;
/// On a dense receiver, refinement for angles stops at triangles below this fraction of
/// the finest element's area (side about half the finest element) instead of 0.02 of it.
/// Such triangles lie between discontinuity edges, where the light is smooth, and a
/// linear element's value error there is bounded by its longest edge, not by its angles;
/// further splitting only multiplied vertices (quads2000: 622k vertices, 409k with this,
/// each one a visible-light computation under ~6 occluders).
const DENSE_MIN_AREA: f64 = 0.3;

/// Where the triangulation holds the receiver: its 2-D frame, moved so that every coordinate
/// lies between one and two times the receiver's span when some coordinate is a rounding
/// residue (nonzero, within 1e-12 of the span of zero). The frame's origin is one of the
/// receiver's vertices, so points on the edges through it have coordinates near zero, where
/// the rounding residue of a clipped point (1e-17 off a line through the origin) is itself a
/// representable coordinate: the triangulation then sees a boundary that zigzags at that scale,
/// and Delaunay refinement splits it without end, each split an encroachment of the next
/// (quads2000's floor: 450k of its 1.05M vertices, on the two sides through the origin). At
/// coordinates of one magnitude such residues round away, and a straight boundary stays
/// straight. The shift moves points by at most an ulp of the span, far below the
/// arrangement's snapping distance.
fn shift_away_from_zero(verts: &[DVec2]) -> DVec2 {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in verts {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        return DVec2::ZERO;
    }
    let span = (hi - lo).max_element();
    // Only a frame with such residues is moved: moving rounds every coordinate by up to an
    // ulp of the span, which changes the triangulation of any receiver a little, for no
    // gain where no coordinate sits within rounding of zero.
    let residue = 1e-12 * span;
    let near_zero = |c: f64| c != 0.0 && c.abs() <= residue;
    if !verts.iter().any(|p| near_zero(p.x) || near_zero(p.y)) {
        return DVec2::ZERO;
    }
    // A power of two: the coordinates then share one binade, [span, 2·span), and one ulp.
    let span = if span > 0.0 {
        2f64.powi(span.log2().ceil() as i32)
    } else {
        1.0
    };
    DVec2::new(span - lo.x, span - lo.y)
}

/// Ends of D0 lines (the feet of a box on the floor, where a solid passes through): there
/// the light depends on the direction one comes from, not on the distance, so no linear
/// element that touches such a point is right, however small. Elements shrink towards them
/// in proportion to the distance, which keeps each element's angular span, and with it the
/// interpolation error, bounded, and leaves the wrong values at the corner itself only a
/// tiny area.
struct Corners {
    points: Vec<DVec2>,
    floor: f64,
}

/// Element size at most this fraction of the distance to a corner.
const PER_CORNER_DISTANCE: f64 = 0.7;
/// ... and never below this fraction of `element_size`.
const CORNER_FLOOR: f64 = 1.0 / 16.0;

impl Corners {
    fn new(d0_lines: &[[DVec2; 2]], coarse: f64) -> Self {
        let mut points: Vec<DVec2> = d0_lines.iter().flat_map(|[a, b]| [*a, *b]).collect();
        points.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        points.dedup();
        Corners {
            points,
            floor: coarse * CORNER_FLOOR,
        }
    }

    /// `size` capped near corners, for anywhere within `reach` of `p` (a negative reach: the
    /// largest cap there).
    fn cap(&self, size: f64, p: DVec2, reach: f64) -> f64 {
        let near = self
            .points
            .iter()
            .map(|c| (*c - p).length())
            .fold(f64::INFINITY, f64::min);
        if !near.is_finite() {
            return size;
        }
        size.min(((near - reach).max(0.0) * PER_CORNER_DISTANCE).max(self.floor))
    }

    fn smallest(&self) -> f64 {
        if self.points.is_empty() {
            f64::INFINITY
        } else {
            self.floor
        }
    }
}

/// Lattice points in `f` whose spacing follows `size(p, reach)` (the size anywhere within
/// `reach` of `p`; a negative reach asks for the largest size there): the face's bounds are
/// split into blocks until the size varies little across each, then each block gets a
/// lattice at its smallest size. Blocks of one size share one global lattice, so they
/// join seamlessly; where sizes step, refinement mends the angles.
fn graded_lattice(
    verts: &[DVec2],
    f: &ArrFace,
    size: &dyn Fn(DVec2, f64) -> f64,
    out: &mut Vec<DVec2>,
) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for &v in &f.outer {
        lo = lo.min(verts[v as usize]);
        hi = hi.max(verts[v as usize]);
    }
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        return;
    }
    let mut stack = vec![(lo, hi, 0u32)];
    while let Some((blo, bhi, depth)) = stack.pop() {
        let c = 0.5 * (blo + bhi);
        let reach = 0.5 * (bhi - blo).length();
        let small = size(c, reach);
        let large = size(c, -reach);
        let side = (bhi - blo).max_element();
        if large <= 1.5 * small || side <= 4.0 * small || depth >= 12 {
            lattice_in_face(verts, f, small, (blo, bhi), (lo, hi), out);
            continue;
        }
        let m = c;
        for (a, b) in [
            (blo, m),
            (DVec2::new(m.x, blo.y), DVec2::new(bhi.x, m.y)),
            (DVec2::new(blo.x, m.y), DVec2::new(m.x, bhi.y)),
            (m, bhi),
        ] {
            stack.push((a, b, depth + 1));
        }
    }
}

/// Triangular lattice points strictly inside `f` and in the block `[blo, bhi)` (closed on
/// the sides where the block meets the face's bounds `outer`), at least 0.35·h from the
/// face's boundary.
fn lattice_in_face(
    verts: &[DVec2],
    f: &ArrFace,
    h: f64,
    (blo, bhi): (DVec2, DVec2),
    outer: (DVec2, DVec2),
    out: &mut Vec<DVec2>,
) {
    if f.area < 0.2 * h * h {
        return;
    }
    let (lo, hi) = (blo, bhi);
    let in_block = |p: DVec2| {
        p.x >= blo.x
            && p.y >= blo.y
            && (p.x < bhi.x || bhi.x >= outer.1.x)
            && (p.y < bhi.y || bhi.y >= outer.1.y)
    };
    let dy = h * 0.866_025_403_784_438_6;
    let j0 = (lo.y / dy).floor() as i64;
    let j1 = (hi.y / dy).ceil() as i64;
    let i0 = (lo.x / h).floor() as i64 - 1;
    let i1 = (hi.x / h).ceil() as i64 + 1;
    let loops: Vec<&Vec<u32>> = std::iter::once(&f.outer).chain(f.holes.iter()).collect();
    let clearance = 0.35 * h;
    for j in j0..=j1 {
        let y = j as f64 * dy;
        let off = if j.rem_euclid(2) == 1 { 0.5 * h } else { 0.0 };
        for i in i0..=i1 {
            let p = DVec2::new(i as f64 * h + off, y);
            if p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y || !in_block(p) {
                continue;
            }
            if winding(verts, &f.outer, p) == 0
                || f.holes.iter().any(|hl| winding(verts, hl, p) != 0)
            {
                continue;
            }
            let near = loops.iter().any(|l| {
                (0..l.len()).any(|k| {
                    seg_dist(
                        verts[l[k] as usize],
                        verts[l[(k + 1) % l.len()] as usize],
                        p,
                    ) < clearance
                })
            });
            if !near {
                out.push(p);
            }
        }
    }
}

/// Winding number of the closed loop around `p` (exact orientation tests).
fn winding(verts: &[DVec2], l: &[u32], p: DVec2) -> i32 {
    let mut w = 0;
    for k in 0..l.len() {
        let a = verts[l[k] as usize];
        let b = verts[l[(k + 1) % l.len()] as usize];
        if a.y <= p.y {
            if b.y > p.y && orient(a, b, p) > 0.0 {
                w += 1;
            }
        } else if b.y <= p.y && orient(a, b, p) < 0.0 {
            w -= 1;
        }
    }
    w
}

/// Triangles, their regions (connected components across non-constraint edges, classified
/// once each), and the D0 vertex split.
fn extract(
    cdt: &Cdt,
    shift: DVec2,
    rr: &ReceiverRegions,
    frame: &Frame,
    uniform: bool,
    tol: &Tolerances,
) -> ReceiverMesh {
    let nv = cdt.num_vertices();
    let mut positions: Vec<DVec2> = cdt
        .vertices()
        .map(|v| DVec2::new(v.position().x, v.position().y) - shift)
        .collect();
    let faces: Vec<_> = cdt.inner_faces().collect();
    // Spade numbers the outer face 0 and the inner faces from 1, in the order
    // `inner_faces` visits them; a hash map from handle to position cost quads2000's
    // floor (800k triangles) a second.
    let face_index =
        |f: spade::handles::FixedFaceHandle<spade::handles::InnerTag>| -> usize { f.index() - 1 };
    debug_assert!(faces
        .iter()
        .enumerate()
        .all(|(i, f)| face_index(f.fix()) == i));
    let mut triangles: Vec<[u32; 3]> = faces
        .iter()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();

    // Components across unconstrained edges.
    if uniform {
        let mut tri_region = vec![0; triangles.len()];
        drop_flat(&positions, frame, &mut triangles, &mut tri_region, tol);
        return ReceiverMesh {
            eval: positions.clone(),
            positions,
            triangles,
            tri_region,
            regions: Vec::new(),
            ..ReceiverMesh::default()
        };
    }
    let mut comp = vec![u32::MAX; faces.len()];
    // The largest triangle of each component, whose centre is classified.
    let mut largest: Vec<usize> = Vec::new();
    // Components that reach the hull across an edge that is not a constraint lie outside the
    // receiver, between its boundary and the frame refinement puts around it (`refine`).
    let mut outside: Vec<bool> = Vec::new();
    for start in 0..faces.len() {
        if comp[start] != u32::MAX {
            continue;
        }
        let id = largest.len() as u32;
        let mut stack = vec![start];
        comp[start] = id;
        let mut best = (0.0f64, start);
        let mut out = false;
        while let Some(i) = stack.pop() {
            let area = faces[i].area();
            if area > best.0 {
                best = (area, i);
            }
            for e in faces[i].adjacent_edges() {
                if e.is_constraint_edge() {
                    continue;
                }
                if e.rev().face().is_outer() {
                    out = true;
                }
                if let Some(nb) = e.rev().face().as_inner() {
                    let j = face_index(nb.fix());
                    if comp[j] == u32::MAX {
                        comp[j] = id;
                        stack.push(j);
                    }
                }
            }
        }
        largest.push(best.1);
        outside.push(out);
    }
    // A dense receiver has hundreds of thousands of components, each classified on its own.
    let centres: Vec<DVec2> = largest
        .iter()
        .map(|&t| {
            let c = faces[t].center();
            DVec2::new(c.x, c.y) - shift
        })
        .collect();
    let regions: Vec<Region> = centres
        .par_iter()
        .zip(&outside)
        .map(|(&c, &out)| {
            if out {
                Region {
                    relations: Vec::new(),
                    blockers: Vec::new(),
                }
            } else {
                rr.classify(c)
            }
        })
        .collect();

    // D0 split: group the triangles around each vertex into sectors that do not cross a
    // lit|umbra edge; every sector but the first gets its own copy of the vertex.
    let lit_umbra = |a: &Region, b: &Region| {
        a.relations.iter().zip(&b.relations).any(|(x, y)| {
            matches!(
                (x, y),
                (Relation::Lit, Relation::Umbra) | (Relation::Umbra, Relation::Lit)
            )
        })
    };
    let scale = positions
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()))
        .max(1e-300);
    // Contacts and plane cuts: an occluder meets the receiver there, so light jumps even
    // where both sides are in penumbra.
    let eps = 1e-9 * scale;
    // Boxes first: on a floor under hundreds of objects each constraint edge meets as many
    // contact lines, and refinement extracts the receiver once a pass (room-245: two
    // fifths of a direct-only bake in the distances).
    let near = |a: DVec2, b: DVec2, p: DVec2| {
        p.x >= a.x.min(b.x) - eps
            && p.x <= a.x.max(b.x) + eps
            && p.y >= a.y.min(b.y) - eps
            && p.y <= a.y.max(b.y) + eps
            && seg_dist(a, b, p) <= eps
    };
    let grid = LineGrid::new(&rr.d0_lines, eps);
    let on_contact = |p: DVec2, q: DVec2| {
        grid.at(p).iter().any(|&l| {
            let [a, b] = rr.d0_lines[l as usize];
            near(a, b, p) && near(a, b, q)
        })
    };
    type Edge<'a> = spade::handles::DirectedEdgeHandle<'a, Point2<f64>, (), spade::CdtEdge<()>, ()>;
    let is_d0_uncached = |e: Edge<'_>| -> bool {
        let (Some(fa), Some(fb)) = (e.face().as_inner(), e.rev().face().as_inner()) else {
            return false;
        };
        let (ca, cb) = (comp[face_index(fa.fix())], comp[face_index(fb.fix())]);
        if ca == cb || outside[ca as usize] || outside[cb as usize] {
            return false;
        }
        if lit_umbra(&regions[ca as usize], &regions[cb as usize]) {
            return true;
        }
        let (p, q) = (e.from().position(), e.to().position());
        on_contact(DVec2::new(p.x, p.y) - shift, DVec2::new(q.x, q.y) - shift)
    };
    // Asked again for every edge around each D0 vertex: decided once per edge.
    let d0_known: Vec<std::cell::Cell<u8>> =
        vec![std::cell::Cell::new(0); cdt.num_undirected_edges()];
    let is_d0_edge = |e: Edge<'_>| -> bool {
        if !e.is_constraint_edge() {
            return false;
        }
        let known = &d0_known[e.as_undirected().index()];
        if known.get() != 0 {
            return known.get() == 2;
        }
        let d0 = is_d0_uncached(e);
        known.set(if d0 { 2 } else { 1 });
        d0
    };
    let mut d0_vertices = Vec::new();
    for e in cdt.undirected_edges() {
        if !e.is_constraint_edge() {
            continue;
        }
        let d = e.as_directed();
        if is_d0_edge(d) {
            d0_vertices.push(d.from().fix());
            d0_vertices.push(d.to().fix());
        }
    }
    let mut eval = positions.clone();
    let mut d0_corners = Vec::new();
    d0_vertices.sort_unstable();
    d0_vertices.dedup();
    for vh in d0_vertices {
        let v = cdt.vertex(vh);
        // Outgoing edges in order around the vertex; faces between consecutive edges.
        let out: Vec<_> = v.out_edges().collect();
        let n = out.len();
        let mut sectors: Vec<Vec<usize>> = Vec::new();
        let mut current: Vec<usize> = Vec::new();
        // Start the walk just after a D0 edge so sectors do not wrap.
        let cut = |k: usize| -> bool { is_d0_edge(out[k]) };
        let Some(first_cut) = (0..n).find(|&k| cut(k)) else {
            continue;
        };
        let cuts: Vec<DVec2> = (0..n)
            .filter(|&k| cut(k))
            .map(|k| {
                let q = out[k].to().position();
                DVec2::new(q.x, q.y) - shift - positions[vh.index()]
            })
            .collect();
        let straight = cuts.len() == 2
            && cuts[0].dot(cuts[1]) < 0.0
            && cuts[0].perp_dot(cuts[1]).abs() <= 1e-9 * cuts[0].length() * cuts[1].length();
        if !straight {
            d0_corners.push(positions[vh.index()]);
        }
        for s in 0..n {
            let k = (first_cut + s) % n;
            if s > 0 && cut(k) && !current.is_empty() {
                sectors.push(std::mem::take(&mut current));
            }
            match out[k]
                .face()
                .as_inner()
                .filter(|f| !outside[comp[face_index(f.fix())] as usize])
            {
                Some(f) => current.push(face_index(f.fix())),
                // The receiver's boundary ends a sector too: on a boundary vertex the two
                // sides of a D0 line meet again only across the outside.
                None => {
                    if !current.is_empty() {
                        sectors.push(std::mem::take(&mut current));
                    }
                }
            }
        }
        if !current.is_empty() {
            sectors.push(current);
        }
        for (k, sector) in sectors.iter().enumerate() {
            let id = if k == 0 {
                vh.index() as u32
            } else {
                positions.push(positions[vh.index()]);
                eval.push(positions[vh.index()]);
                positions.len() as u32 - 1
            };
            // Nudge the evaluation point towards the sector's triangles.
            let p = positions[vh.index()];
            let mut dir = DVec2::ZERO;
            let mut shortest = f64::INFINITY;
            for &t in sector {
                let c = triangles[t]
                    .iter()
                    .map(|&i| positions[i as usize])
                    .sum::<DVec2>()
                    / 3.0;
                dir += (c - p).normalize_or_zero();
                for &i in &triangles[t] {
                    let d = (positions[i as usize] - p).length();
                    if d > 0.0 {
                        shortest = shortest.min(d);
                    }
                }
            }
            if dir != DVec2::ZERO && shortest.is_finite() {
                let step = (shortest * 1e-6).max(tol.d0_offset).min(0.25 * shortest);
                eval[id as usize] = p + dir.normalize() * step;
            }
            if k > 0 {
                for &t in sector {
                    for x in triangles[t].iter_mut() {
                        if *x == vh.index() as u32 {
                            *x = id;
                        }
                    }
                }
            }
        }
    }
    let _ = nv;
    let mut tri_region = comp;
    if outside.iter().any(|&o| o) {
        drop_outside(
            &outside,
            &mut positions,
            &mut eval,
            &mut triangles,
            &mut tri_region,
        );
    }
    drop_flat(&positions, frame, &mut triangles, &mut tri_region, tol);
    ReceiverMesh {
        positions,
        eval,
        triangles,
        tri_region,
        regions,
        d0_corners,
        ..ReceiverMesh::default()
    }
}

/// Segments by the cells of a grid their boxes (grown by `eps`) cover, for point queries.
struct LineGrid {
    lo: DVec2,
    cell: f64,
    n: usize,
    cells: Vec<Vec<u32>>,
}

impl LineGrid {
    /// Cells along each axis at most.
    const SIDE: usize = 64;

    fn new(lines: &[[DVec2; 2]], eps: f64) -> Self {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for [a, b] in lines {
            lo = lo.min(a.min(*b));
            hi = hi.max(a.max(*b));
        }
        let n = if lines.len() < 16 { 1 } else { Self::SIDE };
        if !(lo.x <= hi.x && lo.y <= hi.y) {
            return LineGrid {
                lo: DVec2::ZERO,
                cell: 1.0,
                n: 1,
                cells: vec![Vec::new()],
            };
        }
        let lo = lo - DVec2::splat(2.0 * eps);
        let cell = ((hi - lo).max_element() + 4.0 * eps) / n as f64;
        let cell = if cell > 0.0 { cell } else { 1.0 };
        let mut grid = LineGrid {
            lo,
            cell,
            n,
            cells: vec![Vec::new(); n * n],
        };
        for (l, [a, b]) in lines.iter().enumerate() {
            let (i0, j0) = grid.index(a.min(*b) - DVec2::splat(eps));
            let (i1, j1) = grid.index(a.max(*b) + DVec2::splat(eps));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    grid.cells[j * n + i].push(l as u32);
                }
            }
        }
        grid
    }

    fn index(&self, p: DVec2) -> (usize, usize) {
        let f = (p - self.lo) / self.cell;
        let clamp = |x: f64| (x.max(0.0) as usize).min(self.n - 1);
        (clamp(f.x), clamp(f.y))
    }

    /// The segments whose grown boxes may hold `p` (and others).
    fn at(&self, p: DVec2) -> &[u32] {
        let (i, j) = self.index(p);
        &self.cells[j * self.n + i]
    }
}

/// Removes the triangles of components outside the receiver, and the vertices only they
/// used (the frame's corners).
fn drop_outside(
    outside: &[bool],
    positions: &mut Vec<DVec2>,
    eval: &mut Vec<DVec2>,
    triangles: &mut Vec<[u32; 3]>,
    tri_region: &mut Vec<u32>,
) {
    let keep: Vec<bool> = tri_region.iter().map(|&r| !outside[r as usize]).collect();
    let mut k = keep.iter();
    triangles.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    tri_region.retain(|_| *k.next().unwrap_or(&true));
    let mut new_id = vec![u32::MAX; positions.len()];
    for t in triangles.iter() {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut n = 0u32;
    for (v, id) in new_id.iter_mut().enumerate() {
        if *id == 0 {
            *id = n;
            positions[n as usize] = positions[v];
            eval[n as usize] = eval[v];
            n += 1;
        }
    }
    positions.truncate(n as usize);
    eval.truncate(n as usize);
    for t in triangles.iter_mut() {
        for v in t.iter_mut() {
            *v = new_id[*v as usize];
        }
    }
}

/// Removes triangles narrower than 1e-12 of the scene size (twice the area over the longest
/// side). Spade splits constraint edges at computed points (midpoints when refining) that
/// lie an ulp or so off the exact line; its exact predicates then see a kink there, keep
/// triangles spanned by three points of one line (e.g. filling the dent the kink makes in
/// the hull), and refinement near a kink can run away, halving ever thinner triangles. Such
/// a triangle is a thousand times narrower than the distance below which the arrangement
/// merges points (~1e-9 of the scene), so it stands for no discontinuity; it carries no
/// light (area under 1e-12 × scene × its length), and its facing is decided by rounding,
/// so in 3-D it may point against its polygon. Dropping it leaves a slit of that width. It
/// is done after the D0 split so that, while sectors and regions are formed, it still joins
/// its neighbours.
fn drop_flat(
    positions: &[DVec2],
    frame: &Frame,
    triangles: &mut Vec<[u32; 3]>,
    tri_region: &mut Vec<u32>,
    tol: &Tolerances,
) {
    // Judged in 3-D: far from the origin, points apart in the receiver's frame can round
    // to one point in the scene.
    let p3: Vec<DVec3> = positions.iter().map(|p| frame.to_3d(*p)).collect();
    let scale = p3.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    // Rounding alone moves a point off a line by a few ulps of the coordinates.
    let tol = (64.0 * f64::EPSILON * scale).max(tol.flat);
    let keep: Vec<bool> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p3[i as usize]);
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            (b - a).cross(c - a).length() > tol * longest
        })
        .collect();
    if keep.iter().all(|&k| k) {
        return;
    }
    let mut k = keep.iter();
    triangles.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    tri_region.retain(|_| *k.next().unwrap_or(&true));
}

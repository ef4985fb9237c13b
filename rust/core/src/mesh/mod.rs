//! Stage `mesh` (paper 2.5, T_m): elements. Per receiver, a constrained Delaunay triangulation (spade)
//! that conforms to every kept discontinuity edge and the receiver boundary. Nodes are seeded
//! on a lattice whose spacing depends on the region (fine in penumbra) and shrinks near the
//! lights (`sizing`), then Delaunay refinement fixes angles. Edges across which some light jumps from lit to umbra (D0:
//! contact shadows, point-light shadows) get two vertex rows, one per side.

pub mod cancel;
mod check;
mod corner_split;
mod doubt;
pub mod elements;
mod extract;
mod fit;
mod lattice;
mod readings;
pub mod refine;
mod sides;
pub mod sizing;
mod split;

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec2, DVec3};

use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use crate::mesh::sizing::Sizing;
use crate::regions::relation::Relation;
use crate::regions::{ReceiverRegions, Region};
use crate::scene::settings::Settings;
use crate::scene::Tolerances;
use crate::BakeError;
use extract::extract;
use lattice::{graded_lattice, Corners};

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

/// Which component of the triangulation (faces joined across edges that are not
/// constraints) a face belongs to, while refinement runs; `u32::MAX` on faces spade has just
/// made, until refinement labels them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Label(pub u32);

impl Default for Label {
    fn default() -> Self {
        Label(u32::MAX)
    }
}

pub(crate) type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>, (), (), Label>;

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
    light: Option<&refine::Lights>,
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
            let s = rf.gap.map_or(s, |w| s.min(sizing.gap(w)));
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
    // Splitting a constraint edge that a vertex encroaches on ignores the area bound, and on
    // a dense receiver nearly every discontinuity edge has a close neighbour: room-8328's
    // floor went from 206k vertices to 1.03M that way, each one then an exact light
    // evaluation under many occluders. Refined to a tolerance, such a receiver gets its
    // vertices where the light needs them (`refine`), so its discontinuity edges stay whole
    // here and only triangles clear of them are refined for angles.
    let angles = if dense && light.is_some() {
        angles.keep_constraint_edges()
    } else {
        angles
    };
    cancel::refine_in_rounds(&mut cdt, angles.clone(), extra, progress)?;
    budget.fetch_add(
        cdt.num_vertices() as u64 - inserted as u64,
        Ordering::Relaxed,
    );
    if settings.uniform {
        let mut m = extract(&cdt, shift, rr, sizing.frame(), true, tol);
        m.regions = vec![rr.faces.first().cloned().unwrap_or_default()];
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

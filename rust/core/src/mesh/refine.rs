//! A posteriori refinement to a tolerance on the direct light (issue 13). The exact direct
//! light is cheap to evaluate anywhere (closed form where lit, the visible part of the light
//! in penumbra, nothing in umbra), so after the conforming CDT each element is checked where
//! linear interpolation errs most, at its edge midpoints and its centroid, and split where
//! |interpolated − exact| > tolerance × (exact + floor), there and across its longest edge
//! (`check`: bisection keeps elements from flattening towards an edge). The floor, a fraction of the
//! receiver's brightest value, keeps dark regions from refining without end. Splits insert
//! points into the CDT, which keeps the D1/D0 constraint edges (a constraint edge is split
//! into two constraint halves) and the Delaunay property (spade re-legalises around each new
//! point). Nothing is split below the lower size bound.
//!
//! The light is handed in by the caller (`LightAt`), so the mesh stage does not reach into
//! the direct stage; every value computed here is returned with the mesh and reused as the
//! vertex's direct light, fitted over the elements around it unless `vertex_values` is
//! "exact" (`fit`).

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec2, DVec3};
use spade::handles::FixedVertexHandle;
use spade::{Point2, Triangulation};

use super::check::check_faces;
use super::extract::{components, extract_with, face_index, scale, Components};
use super::readings::{Kind, View};
use super::sides::{D0Test, Face};
use super::{corner_split, fit, split, Cdt, Label, ReceiverMesh};
use crate::geom::hash::IdMap;
use crate::geom::Frame;
use crate::regions::{ReceiverRegions, Region};
use crate::scene::settings::{Settings, VertexValues};
use crate::scene::Tolerances;
use crate::BakeError;

/// Direct irradiance at a point of the receiver (2-D frame) that lies in or on the border of
/// the given regions, with its light counts (umbra skipped, lit, penumbra).
pub type LightAt<'a> = dyn Fn(DVec2, &[&Region]) -> (DVec3, [u64; 3]) + Sync + 'a;

/// What refinement knows of the lights: the exact direct light, and per light whether its
/// light inside a penumbra kinks only along lines the arrangement already holds (a polygon
/// light: its VE/EV critical lines) unless several occluders overlap there.
pub struct Lights<'a> {
    pub at: &'a LightAt<'a>,
    pub polygonal: Vec<bool>,
}

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
    /// Light evaluations (vertices, midpoints, centroids; and the midpoints the fit of the
    /// vertex values read, `fit`).
    pub evaluations: u64,
}

/// ... and at most this fraction of the receiver's extent: a small object (clutter on a
/// table) catches penumbrae of its own size, from its neighbours a few mm away, which a
/// bound set by the scene's size leaves unresolved (room-78 direct at 1 %: its worst probes
/// were 2.5× the light on clutter faces, in elements at the bound, with exact corners).
pub const RECEIVER_LOWER: f64 = 1.0 / 64.0;

/// The lower size bound for `settings` on a receiver `extent` across.
pub fn lower_bound(settings: &Settings, extent: f64) -> f64 {
    let global = settings.penumbra_element_size * LOWER_BOUND;
    if extent > 0.0 {
        global.min(extent * RECEIVER_LOWER)
    } else {
        global
    }
}

/// The larger side of the bounding box of `points`.
fn extent(points: &[DVec2]) -> f64 {
    let (lo, hi) = crate::geom::box_grid::bounds(points);
    let d = hi - lo;
    if d.x.is_finite() && d.y.is_finite() {
        d.x.max(d.y)
    } else {
        0.0
    }
}

pub(super) fn key(p: DVec2) -> [u64; 2] {
    [p.x.to_bits(), p.y.to_bits()]
}

/// A light value with its light counts, as `LightAt` gives them.
pub(super) type Light = (DVec3, [u64; 3]);

/// The light at every point read so far, by the bits of its coordinates. The map holds an
/// index into `values`, not the values: room-8328's floor reads millions of points on one
/// thread, and growing a map of 64-byte entries (each doubling faulting in fresh pages) was
/// a seventh of its meshing (`perf`, call graphs); entries of 24 bytes move a third of that.
#[derive(Default)]
pub(super) struct Cache {
    index: IdMap<[u64; 2], u32>,
    values: Vec<Light>,
}

impl Cache {
    pub fn contains_key(&self, k: &[u64; 2]) -> bool {
        self.index.contains_key(k)
    }

    pub fn get(&self, k: &[u64; 2]) -> Option<&Light> {
        self.index.get(k).map(|&i| &self.values[i as usize])
    }

    pub fn reserve(&mut self, more: usize) {
        self.index.reserve(more);
        self.values.reserve(more);
    }

    pub fn insert(&mut self, k: [u64; 2], v: Light) {
        match self.index.entry(k) {
            std::collections::hash_map::Entry::Occupied(e) => self.values[*e.get() as usize] = v,
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(self.values.len() as u32);
                self.values.push(v);
            }
        }
    }
}

impl std::ops::Index<&[u64; 2]> for Cache {
    type Output = Light;
    fn index(&self, k: &[u64; 2]) -> &Light {
        &self.values[self.index[k] as usize]
    }
}

/// Refines `cdt` until every element meets `settings.tolerance` or the lower bound, and
/// returns the element mesh (D0 rows and corners split) with the direct light known at
/// every vertex. Incremental: components are classified once and kept on the faces
/// (`Label`); each pass checks only the triangles around the vertices the last pass put in
/// (and re-screens their neighbours); the receiver is extracted once, at the end.
#[allow(clippy::too_many_arguments)]
pub(crate) fn refine(
    cdt: &mut Cdt,
    rr: &ReceiverRegions,
    shift: DVec2,
    frame: &Frame,
    settings: &Settings,
    tol: &Tolerances,
    lights: &Lights,
    budget: &AtomicU64,
    progress: &crate::Progress,
) -> Result<(ReceiverMesh, RefineStats), BakeError> {
    let mut stats = RefineStats::default();
    let mut cache = Cache::default();
    split::add_frame(cdt);
    let Components {
        comp,
        mut regions,
        mut outside,
    } = components(cdt, shift, rr);
    let faces: Vec<Face> = cdt.fixed_inner_faces().collect();
    for f in faces {
        *cdt.face_data_mut(f) = Label(comp[face_index(f)]);
    }
    drop(comp);
    let test = D0Test::new(rr, scale(cdt, shift), shift);
    let lower = lower_bound(settings, extent(&rr.arrangement.vertices));
    let mut kinds: Vec<Kind> = Vec::new();
    let mut brightest = DVec3::ZERO;
    let mut check: Vec<Face> = {
        let outside = &outside;
        cdt.fixed_inner_faces()
            .filter(|f| !outside[cdt.face(*f).data().0 as usize])
            .collect()
    };
    stats.elements_before = check.len() as u64;
    // The faces around what the last pass changed, to be checked in this one.
    let mut around: Option<Vec<Face>> = None;
    loop {
        progress.check()?;
        let view = View {
            cdt,
            shift,
            tol,
            regions: &regions,
            outside: &outside,
            test: &test,
        };
        if let Some(around) = around.take() {
            // The triangles around what changed are checked again, and their neighbours
            // too, whose screening sees new gradients.
            let mut mark = vec![false; cdt.num_all_faces()];
            check.clear();
            for &f in &around {
                if view.inside(f) && !std::mem::replace(&mut mark[f.index()], true) {
                    check.push(f);
                }
            }
            for k in 0..check.len() {
                let f = check[k];
                for n in view.neighbours(f).collect::<Vec<_>>() {
                    if view.inside(n) && !std::mem::replace(&mut mark[n.index()], true) {
                        check.push(n);
                    }
                }
            }
        }
        let found = check_faces(
            &view,
            &check,
            &mut kinds,
            &mut cache,
            &mut brightest,
            settings,
            lower,
            lights,
            &mut stats,
            progress,
        )?;
        let used = budget.load(Ordering::Relaxed);
        if stats.passes >= MAX_PASSES as u64 || used >= settings.max_elements {
            break;
        }
        let Some((mut edges, centroids)) = found else {
            break;
        };
        edges.sort_unstable();
        edges.dedup();
        let before = cdt.num_vertices();
        let mut touched = Vec::new();
        let room = settings.max_elements.saturating_sub(used) as usize;
        for (k, &(a, b)) in edges.iter().enumerate() {
            if k % 1024 == 0 {
                progress.check()?;
            }
            if cdt.num_vertices() - before >= room {
                break;
            }
            split::split_edge(cdt, a, b, &mut touched);
        }
        for &(c, near) in &centroids {
            if cdt.num_vertices() - before >= room {
                break;
            }
            let c = c + shift;
            split::insert_inside(cdt, Point2::new(c.x, c.y), near);
        }
        let added = (cdt.num_vertices() - before) as u64;
        budget.fetch_add(added, Ordering::Relaxed);
        stats.passes += 1;
        stats.vertices_added += added;
        touched.extend((before..cdt.num_vertices()).map(FixedVertexHandle::from_index));
        touched.sort_unstable();
        touched.dedup();
        // A split that adds no vertex may still have changed faces (a constraint split
        // whose helper vertex came and went): they are labelled before any exit.
        around = Some(label_new_faces(
            cdt,
            &touched,
            rr,
            shift,
            &mut regions,
            &mut outside,
        ));
        // Every split was refused (kinked constraints, rounding): the next pass would find
        // the same elements.
        if added == 0 {
            break;
        }
    }
    debug_assert!(labels_agree(cdt, &regions));
    let comp: Vec<u32> = cdt.inner_faces().map(|f| f.data().0).collect();
    let mut m = extract_with(
        cdt,
        shift,
        rr,
        frame,
        tol,
        Components {
            comp,
            regions,
            outside,
        },
    );
    let corner = corner_split::split(&mut m, &rr.d0_lines, tol);
    let (mut m, mut stats) = finish(m, &cache, stats);
    if settings.vertex_values == VertexValues::Fitted {
        stats.evaluations += fit::fit(&mut m, &corner, &cache, lights, settings.tolerance);
    }
    Ok((m, stats))
}

/// Whether every edge that is not a constraint joins faces whose labels stand for the same
/// region, as the components they were classified from do.
fn labels_agree(cdt: &Cdt, regions: &[Region]) -> bool {
    cdt.inner_faces().all(|f| {
        let l = f.data().0;
        l != u32::MAX
            && f.adjacent_edges().iter().all(|e| {
                let Some(g) = e.rev().face().as_inner() else {
                    return true;
                };
                let m = g.data().0;
                e.is_constraint_edge()
                    || (m != u32::MAX
                        && regions[l as usize].relations == regions[m as usize].relations
                        && regions[l as usize].blockers == regions[m as usize].blockers)
            })
    })
}

/// Labels the faces around `touched` (all that spade changed) anew, each with the label of a
/// neighbour across an edge that is not a constraint, starting from the faces spade left
/// alone: spade gives a face it makes no data and may hand a face it reuses to a triangle on
/// the other side of a constraint (hard_cases' fifty occluders: 64 edges inside a component
/// between two labels). Returns every face around `touched`.
fn label_new_faces(
    cdt: &mut Cdt,
    touched: &[FixedVertexHandle],
    rr: &ReceiverRegions,
    shift: DVec2,
    regions: &mut Vec<Region>,
    outside: &mut Vec<bool>,
) -> Vec<Face> {
    let mut around: Vec<Face> = Vec::new();
    for &v in touched {
        for e in cdt.vertex(v).out_edges() {
            if let Some(f) = e.face().as_inner() {
                around.push(f.fix());
            }
        }
    }
    around.sort_unstable();
    around.dedup();
    for &f in &around {
        *cdt.face_data_mut(f) = Label::default();
    }
    let mut fresh = around.clone();
    while !fresh.is_empty() {
        let mut next = Vec::new();
        for &f in &fresh {
            let known = cdt.face(f).adjacent_edges().into_iter().find_map(|e| {
                if e.is_constraint_edge() {
                    return None;
                }
                let l = e.rev().face().as_inner()?.data().0;
                (l != u32::MAX).then_some(l)
            });
            match known {
                Some(l) => *cdt.face_data_mut(f) = Label(l),
                None => next.push(f),
            }
        }
        if next.len() == fresh.len() {
            // A component whose faces all changed: one face is labelled afresh and the
            // others follow it. Faces that reach the hull lie outside the receiver (its
            // boundary is a constraint), so those go first; else the largest face, whose
            // centre lies clear of the region's lines, is classified.
            let touches_hull = |f: Face| {
                cdt.face(f)
                    .adjacent_edges()
                    .iter()
                    .any(|e| !e.is_constraint_edge() && e.rev().face().is_outer())
            };
            let seed = match next.iter().copied().find(|&f| touches_hull(f)) {
                Some(f) => {
                    let l = match outside.iter().position(|&o| o) {
                        Some(l) => l,
                        None => {
                            regions.push(Region::default());
                            outside.push(true);
                            regions.len() - 1
                        }
                    };
                    (f, l)
                }
                None => {
                    let f = next
                        .iter()
                        .copied()
                        .max_by(|a, b| cdt.face(*a).area().total_cmp(&cdt.face(*b).area()))
                        .expect("not empty");
                    let c = cdt.face(f).center();
                    regions.push(rr.classify(DVec2::new(c.x, c.y) - shift));
                    outside.push(false);
                    (f, regions.len() - 1)
                }
            };
            *cdt.face_data_mut(seed.0) = Label(seed.1 as u32);
            next.retain(|&f| f != seed.0);
        }
        fresh = next;
    }
    around
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

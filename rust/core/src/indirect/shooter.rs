//! A shot: one patch sends its unshot radiosity to every receiver vertex, in parallel over
//! runs of vertex groups, and keeps the factors for its next shot.

use std::borrow::Cow;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;

use super::gather::Gather;
use super::pair::{Blockers, Pair, Reached};
use super::{mean, CHUNK, FACTOR_BUDGET};
use crate::geom::raycast::Occluders;
use crate::indirect::patches::Patch;
use crate::mesh::elements::Elements;
use crate::scene::Scene;

/// Vertex groups of at most this many vertices, each seeing the shooter by one ray, cast
/// their rays through the BVH instead of first asking it for what could block them.
const ONE_RAY_GROUP: usize = 8;

/// What a shot needs about the scene, built once.
pub(super) struct Shooter<'a> {
    pub(super) scene: &'a Scene,
    pub(super) el: &'a Elements,
    pub(super) patches: &'a [Patch],
    pub(super) occ: &'a Occluders,
    /// Element vertices, by face and within a face by group.
    pub(super) face_verts: Vec<u32>,
    /// Groups of nearby vertices of face f (one per patch of f):
    /// `groups[group_start[f]..group_start[f + 1]]`. Occluders are looked for between a
    /// shooter and each group: the box around a whole floor would hold everything in a room.
    pub(super) group_start: Vec<u32>,
    pub(super) groups: Vec<Group>,
    /// Patches of face f: `patch_start[f]..patch_start[f + 1]` (patches are sorted by face).
    pub(super) patch_start: Vec<u32>,
    /// Faces that have element vertices.
    pub(super) receivers: Vec<u32>,
    /// Vertex positions nudged into their face (see `Shooter::new`).
    pub(super) points: Vec<DVec3>,
    /// Irradiance under which a vertex's share of a shot is too small to be worth full
    /// visibility sampling.
    pub(super) negligible: f64,
    pub(super) tol: f64,
    /// Per shooter face, filled on its first shot: the receiver faces that something could
    /// stand in front of, ascending, with what (for the whole face: each patch narrows it
    /// down). `None` inside when over the memory budget: then each patch asks the BVH.
    /// Fronts first, then backs (`face + faces`).
    pub(super) face_blockers: Vec<OnceLock<Option<Vec<Reached>>>>,
    /// The backs of thin faces that receive.
    pub(super) backs: super::back::Backs,
    /// `face_blockers` for back receivers, same keys (`back::BackReach`).
    pub(super) back_blockers: Vec<OnceLock<Option<super::back::BackReach>>>,
    pub(super) kept: AtomicUsize,
    /// Per patch, after its first shot: the faces it reached and each of their vertices'
    /// form factor times visibility. A patch shoots again whenever light came back to it
    /// (in a closed room, many times), and the geometry has not changed.
    pub(super) factors: Vec<OnceLock<Factors>>,
    pub(super) factors_kept: AtomicUsize,
    /// Whether far vertex groups may be fitted (`fit.rs`) instead of evaluated vertex by
    /// vertex, and how many vertices were.
    pub(super) fit: bool,
    pub(super) fitted_verts: AtomicUsize,
    /// Each patch's weighted mean (`Patch::weights`) over kept vertices only (`gather`).
    pub(super) patch_weights: Vec<Vec<(u32, f64)>>,
}

/// A patch's shot, kept for the next: form factor times visibility for the vertices
/// `face_verts[s..e]` of each run `(s, e)`, runs one after the other (vertices in no run
/// got nothing); and per receiving patch (ascending), the weighted mean of that over its
/// vertices (patches that got nothing left out).
#[derive(Clone)]
pub(super) struct Factors {
    pub(super) runs: Vec<(u32, u32)>,
    pub(super) factors: Vec<f32>,
    pub(super) to_patches: Vec<(u32, f64)>,
}

/// Vertices `face_verts[start..end]` and their bounds.
pub(super) struct Group {
    pub(super) start: u32,
    pub(super) end: u32,
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
}

impl<'a> Shooter<'a> {
    pub(super) fn new(
        scene: &'a Scene,
        el: &'a Elements,
        patches: &'a [Patch],
        occ: &'a Occluders,
        emitted: f64,
        gather: &Gather,
    ) -> Self {
        let nf = scene.faces.len();
        let mut vert_start = vec![0u32; nf + 1];
        for &f in &el.vertex_face {
            vert_start[f as usize + 1] += 1;
        }
        for f in 0..nf {
            vert_start[f + 1] += vert_start[f];
        }
        // Fronts only: the backs of thin faces come after them all (`back`).
        let mut patch_start = vec![0u32; nf + 1];
        for p in patches.iter().filter(|p| !p.back) {
            patch_start[p.face as usize + 1] += 1;
        }
        for f in 0..nf {
            patch_start[f + 1] += patch_start[f];
        }
        let patch_weights: Vec<Vec<(u32, f64)>> = patches
            .par_iter()
            .map(|p| gather.compose(&p.weights))
            .collect();
        // Each kept vertex joins the group of the first patch it weighs in; vertices in no
        // patch (in no triangle) form one last group of their face.
        let mut group_of = vec![u32::MAX; el.positions.len()];
        for (i, w) in patch_weights.iter().enumerate() {
            for &(v, _) in w {
                if group_of[v as usize] == u32::MAX {
                    group_of[v as usize] = i as u32;
                }
            }
        }
        let mut order: Vec<u32> = (0..el.positions.len() as u32)
            .filter(|&v| gather.kept[v as usize])
            .collect();
        order.sort_by_key(|&v| (el.vertex_face[v as usize], group_of[v as usize], v));
        let mut face_verts = Vec::with_capacity(order.len());
        let mut groups: Vec<Group> = Vec::new();
        let mut group_start = vec![0u32; nf + 1];
        for (k, &v) in order.iter().enumerate() {
            let x = el.positions[v as usize];
            let f = el.vertex_face[v as usize];
            let new_group = k == 0
                || el.vertex_face[order[k - 1] as usize] != f
                || group_of[order[k - 1] as usize] != group_of[v as usize];
            if new_group {
                groups.push(Group {
                    start: k as u32,
                    end: k as u32,
                    lo: x,
                    hi: x,
                });
                group_start[f as usize + 1] += 1;
            }
            let g = groups.last_mut().expect("a group was opened");
            g.end += 1;
            g.lo = g.lo.min(x);
            g.hi = g.hi.max(x);
            face_verts.push(v);
        }
        for f in 0..nf {
            group_start[f + 1] += group_start[f];
        }
        let receivers = (0..nf as u32)
            .filter(|&f| vert_start[f as usize + 1] > vert_start[f as usize])
            .collect();
        // A vertex on the edge where a wall meets the floor lies in the wall's plane and
        // would see the wall edge-on: no light from it at all, though a point a hair inside
        // the floor gets plenty. Evaluating a hair inside gives the limit from the face,
        // which is what the element's interior shows.
        let tol = occ.tolerance();
        let centres: Vec<DVec3> = scene
            .faces
            .iter()
            .map(|f| f.verts.iter().copied().sum::<DVec3>() / f.verts.len().max(1) as f64)
            .collect();
        // A vertex on a D0 row (the floor along a box's foot) has a copy per side, and its
        // evaluation point a hair into its own side: the nudge must go that way, not to the
        // face's centre, which may lie under the box (all light blocked there).
        let points = el
            .positions
            .iter()
            .enumerate()
            .zip(&el.vertex_face)
            .map(|((i, x), &f)| {
                let e = el.eval.get(i).unwrap_or(x);
                let d = centres[f as usize] - *x;
                let l = d.length();
                if !(l > 0.0) {
                    return *x;
                }
                let step = crate::geom::hair(l, 100.0 * tol);
                let side = *e - *x;
                if side.length() > 0.0 {
                    *x + side.normalize() * step
                } else {
                    *x + d * (step / l)
                }
            })
            .collect();
        let area: f64 = patches.iter().map(|p| p.area).sum();
        let negligible = 1e-3 * scene.settings.convergence * emitted / area.max(f64::MIN_POSITIVE);
        Shooter {
            scene,
            el,
            patches,
            occ,
            face_verts,
            group_start,
            groups,
            patch_start,
            receivers,
            points,
            negligible,
            tol,
            face_blockers: (0..2 * nf).map(|_| OnceLock::new()).collect(),
            backs: super::back::Backs::new(patches),
            back_blockers: (0..2 * nf).map(|_| OnceLock::new()).collect(),
            kept: AtomicUsize::new(0),
            factors: (0..patches.len()).map(|_| OnceLock::new()).collect(),
            factors_kept: AtomicUsize::new(0),
            fit: true,
            fitted_verts: AtomicUsize::new(0),
            patch_weights,
        }
    }

    pub(super) fn patches_of(&self, f: u32) -> std::ops::Range<usize> {
        self.patch_start[f as usize] as usize..self.patch_start[f as usize + 1] as usize
    }

    /// Form factor times visibility from patch `p` to every receiver vertex: kept from its
    /// first shot if the budget allows (borrowed then), else computed anew (owned). The
    /// radiosity `b` shot only decides how hard to look. A fresh computation also hands back
    /// the factors in `f64` (along the runs), to add this shot at full precision.
    pub(super) fn factors(&self, p: usize, b: DVec3) -> (Cow<'_, Factors>, Option<Vec<f64>>) {
        if let Some(known) = self.factors[p].get() {
            return (Cow::Borrowed(known), None);
        }
        let patch = &self.patches[p];
        let plane = patch.plane;
        let known = self.face_blockers(patch.face, patch.back);
        let pairs: Vec<Pair> = self
            .receivers
            .par_iter()
            .with_min_len(32)
            .filter_map(|&f| self.pair(&patch.poly, patch.face, &plane, f, known))
            .collect();
        // Work items: runs of whole groups of one face, about CHUNK vertices each.
        let mut chunks: Vec<(usize, usize, usize)> = Vec::new();
        for (k, pair) in pairs.iter().enumerate() {
            let (g0, g1) = (
                self.group_start[pair.face as usize] as usize,
                self.group_start[pair.face as usize + 1] as usize,
            );
            let mut first = g0;
            let mut count = 0;
            for g in g0..g1 {
                count += (self.groups[g].end - self.groups[g].start) as usize;
                if count >= CHUNK || g + 1 == g1 {
                    chunks.push((k, first, g + 1));
                    first = g + 1;
                    count = 0;
                }
            }
        }
        let values: Vec<Vec<f64>> = chunks
            .par_iter()
            .map(|&(k, g0, g1)| {
                let pair = &pairs[k];
                let mut out = Vec::new();
                for group in &self.groups[g0..g1] {
                    // A few vertices, one ray each: rays beat the box query (`one_ray`).
                    let few = (group.end - group.start) as usize <= ONE_RAY_GROUP;
                    let blockers = if few && self.one_ray(patch, pair, group) {
                        Blockers::Any
                    } else {
                        self.blockers(patch.face, &patch.poly, &plane, pair, group)
                    };
                    if self.fit && matches!(blockers, Blockers::None) {
                        if let Some(vals) = self.fitted(patch, &plane, pair, group) {
                            out.extend(vals);
                            continue;
                        }
                    }
                    let verts = &self.face_verts[group.start as usize..group.end as usize];
                    out.extend(
                        verts
                            .iter()
                            .map(|&v| self.receive(patch, &plane, pair, &blockers, v, b)),
                    );
                }
                out
            })
            .collect();
        // Each receiving patch's weighted mean of its vertices' factors: what it gains per
        // unit of radiosity shot, so that a repeat shot costs one product per patch.
        let mut g_of = vec![0.0; self.points.len()];
        for (&(_, g0, g1), vals) in chunks.iter().zip(&values) {
            let (s, e) = (
                self.groups[g0].start as usize,
                self.groups[g1 - 1].end as usize,
            );
            for (&v, g) in self.face_verts[s..e].iter().zip(vals) {
                g_of[v as usize] = *g;
            }
        }
        let touched: Vec<usize> = pairs
            .iter()
            .flat_map(|pair| self.patches_of(pair.face))
            .collect();
        let mut to_patches: Vec<(u32, f64)> = touched
            .par_iter()
            .with_min_len(64)
            .map(|&q| (q as u32, mean(&self.patch_weights[q], &g_of)))
            .collect::<Vec<_>>()
            .into_iter()
            .filter(|&(_, m)| m != 0.0)
            .collect();
        // The backs of thin faces, after every front (`back`).
        to_patches.extend(self.back_gains(patch, b));
        // Kept group by group, leaving out the groups that got nothing (behind the shooter,
        // or in shadow), which are often most of them.
        let mut known = Factors {
            runs: Vec::new(),
            factors: Vec::new(),
            to_patches,
        };
        let mut exact = Vec::new();
        for (&(_, g0, g1), vals) in chunks.iter().zip(&values) {
            let mut vals = &vals[..];
            for group in &self.groups[g0..g1] {
                let (here, rest) = vals.split_at((group.end - group.start) as usize);
                vals = rest;
                if here.iter().any(|g| *g != 0.0) {
                    known.runs.push((group.start, group.end));
                    known.factors.extend(here.iter().map(|&g| g as f32));
                    exact.extend_from_slice(here);
                }
            }
        }
        let n = known.factors.len() + 2 * known.runs.len() + 4 * known.to_patches.len();
        if self.factors_kept.load(Ordering::Relaxed) + n <= FACTOR_BUDGET {
            self.factors_kept.fetch_add(n, Ordering::Relaxed);
            return (
                Cow::Borrowed(self.factors[p].get_or_init(|| known)),
                Some(exact),
            );
        }
        (Cow::Owned(known), Some(exact))
    }

    /// Adds to `irradiance` what each vertex got from `b` through `factors`.
    /// `g` runs along `factors.runs`: the kept `factors.factors`, or their `f64` originals.
    pub(super) fn add_to<T: Copy + Into<f64>>(
        &self,
        factors: &Factors,
        g: &[T],
        b: DVec3,
        irradiance: &mut [DVec3],
    ) {
        let verts = factors
            .runs
            .iter()
            .flat_map(|&(s, e)| &self.face_verts[s as usize..e as usize]);
        for (&v, &g) in verts.zip(g) {
            irradiance[v as usize] += b * g.into();
        }
    }

    /// Adds to `irradiance` what all kept shots of each patch sent (their radiosity summed
    /// in `shot_total`): the sum of products is the product with the sum, so a patch's
    /// vertices are visited once per bake instead of once per shot.
    pub(super) fn add_kept(&self, shot_total: &[DVec3], irradiance: &mut [DVec3]) {
        for (p, b) in shot_total.iter().enumerate() {
            if let (Some(known), true) = (self.factors[p].get(), *b != DVec3::ZERO) {
                self.add_to(known, &known.factors, *b, irradiance);
            }
        }
    }
}

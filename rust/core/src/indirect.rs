//! Stage 7: indirect light by progressive refinement (Cohen, Chen, Wallace & Greenberg 1988),
//! as in the paper's §2.6: the patch with the most unshot power shoots it to every element
//! vertex that can see it, until what is left is a small fraction of what was emitted.
//!
//! Units follow `DESIGN.md`: irradiance E and radiosity B in W/m² per RGB channel; a face's
//! `emission` is radiance, so it leaves the face as radiosity π·Le.
//!
//! Form factors are exact point-to-polygon integrals (Lambert's formula) times a visible
//! fraction from rays to stratified points on the patch, each ray weighted by its own
//! point-to-point form factor. Most pairs need no rays: a face can only be in the way if it
//! pokes out in front of both the shooter's and the receiver's planes inside the box around
//! the shooter and a group of receiver vertices ([`Occluders::candidates`]), which for
//! convex objects and floors is never. Rays to far patches are fewer (1 or ~4). Shots are parallel over receiver vertices; each vertex's value is
//! computed alone and added in a fixed order, so results do not depend on the thread count.

use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;

use crate::elements::Elements;
use crate::geom::polygon::clip_polygon_3d;
use crate::geom::raycast::Occluders;
use crate::geom::Plane;
use crate::patches::{build_patches, Patch};
use crate::progress::Progress;
use crate::scene::Scene;
use crate::BakeError;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct IndirectResult {
    /// Indirect irradiance (W/m², RGB) at each element vertex: everything that arrives after
    /// at least one diffuse bounce, plus what emissive faces send.
    pub irradiance: Vec<DVec3>,
    pub patches: u64,
    pub shots: u64,
    /// Unshot power left at the end over the power emitted (reflected direct light plus
    /// emission), before any ambient term.
    pub unshot_fraction: f64,
}

/// Patches whose apparent size (radius over distance) falls under these use 1 or ~4 rays
/// instead of `visibility_rays`: a far patch is seen nearly all or nothing.
const FEW_RAYS_BELOW: f64 = 0.15;
const ONE_RAY_BELOW: f64 = 0.06;
/// Candidate occluder lists longer than this are handed to the BVH instead.
const MAX_LISTED_OCCLUDERS: usize = 24;
/// Per shooter face, candidate lists (for all its patches) longer than this are not kept:
/// each group of receiver vertices asks the BVH for its own, which beats sifting a long
/// list once per group.
const MAX_FACE_OCCLUDERS: usize = 64;
/// Face ids kept in those lists over the whole bake (4 bytes each).
const FACE_OCCLUDER_BUDGET: usize = 1 << 24;
/// Form factors kept for repeat shots, over the whole bake (4 bytes each: 256 MB at most;
/// a closed room of 24k vertices and 2.6k patches keeps 41M).
const FACTOR_BUDGET: usize = 1 << 26;
/// Receiver vertices per parallel work item.
const CHUNK: usize = 256;

/// Progressive-refinement radiosity over the element mesh `el` of `scene`, starting from
/// the direct irradiance `direct` (one per element vertex). Checks `progress` for
/// cancellation between shots.
pub fn indirect(
    scene: &Scene,
    el: &Elements,
    direct: &[DVec3],
    occ: &Occluders,
    progress: &Progress,
) -> Result<IndirectResult, BakeError> {
    let settings = &scene.settings;
    let nv = el.positions.len();
    if direct.len() != nv {
        return Err(BakeError::invalid(
            "indirect",
            "direct",
            format!("{} values for {nv} element vertices", direct.len()),
        ));
    }
    let open = crate::covered::open_parts(&scene.faces, 1e-6 * scene.diagonal());
    let patches = build_patches(
        &scene.faces,
        &open,
        el,
        settings.patch_size,
        settings.visibility_rays,
    );
    let albedo = |p: &Patch| scene.faces[p.face as usize].albedo;
    let mut unshot: Vec<DVec3> = patches
        .iter()
        .map(|p| albedo(p) * mean(&p.weights, direct) + PI * scene.faces[p.face as usize].emission)
        .collect();
    let power = |b: DVec3, p: &Patch| b.element_sum() * p.area;
    let emitted: f64 = unshot.iter().zip(&patches).map(|(b, p)| power(*b, p)).sum();
    let mut irradiance = vec![DVec3::ZERO; nv];
    let mut result = IndirectResult {
        patches: patches.len() as u64,
        ..Default::default()
    };
    if !(emitted > 0.0) || !emitted.is_finite() {
        result.irradiance = irradiance;
        return Ok(result);
    }

    let shooter = Shooter::new(scene, el, &patches, occ, emitted);
    let mut received = vec![DVec3::ZERO; nv];
    let mut remaining;
    loop {
        progress.check()?;
        let mut best = 0;
        remaining = 0.0;
        for (i, (b, p)) in unshot.iter().zip(&patches).enumerate() {
            let w = power(*b, p);
            remaining += w;
            if w > power(unshot[best], &patches[best]) {
                best = i;
            }
        }
        let fraction = remaining / emitted;
        let by_energy = (fraction.max(1e-300).ln() / settings.convergence.ln()).clamp(0.0, 1.0);
        progress
            .set_fraction(by_energy.max(result.shots as f64 / settings.max_shots.max(1) as f64));
        if fraction < settings.convergence || result.shots >= settings.max_shots {
            break;
        }

        let b = std::mem::take(&mut unshot[best]);
        let faces = shooter.shoot(best, b, &mut received);
        let touched: Vec<usize> = faces.iter().flat_map(|&f| shooter.patches_of(f)).collect();
        let gained: Vec<DVec3> = touched
            .par_iter()
            .with_min_len(64)
            .map(|&p| albedo(&patches[p]) * mean(&patches[p].weights, &received))
            .collect();
        for (&p, g) in touched.iter().zip(gained) {
            unshot[p] += g;
        }
        for f in faces {
            for &v in shooter.verts_of(f) {
                irradiance[v as usize] += received[v as usize];
                received[v as usize] = DVec3::ZERO;
            }
        }
        result.shots += 1;
    }
    result.unshot_fraction = remaining / emitted;

    if settings.ambient {
        let amb = ambient(&patches, &unshot, |p| albedo(p));
        irradiance.iter_mut().for_each(|e| *e += amb);
    }
    result.irradiance = irradiance;
    Ok(result)
}

/// Cohen et al.'s ambient term: the unshot radiosity, averaged over the scene's area, after
/// endless bounces off a surface of the average reflectance. Assumes a closed scene; in an
/// open one part of that light would escape, so this overestimates.
fn ambient(patches: &[Patch], unshot: &[DVec3], albedo: impl Fn(&Patch) -> DVec3) -> DVec3 {
    let area: f64 = patches.iter().map(|p| p.area).sum();
    if !(area > 0.0) {
        return DVec3::ZERO;
    }
    let rho = patches.iter().map(|p| albedo(p) * p.area).sum::<DVec3>() / area;
    let u = unshot
        .iter()
        .zip(patches)
        .map(|(b, p)| *b * p.area)
        .sum::<DVec3>()
        / area;
    // A white scene would bounce forever; cap the series at a thousand bounces.
    u / (DVec3::ONE - rho.min(DVec3::splat(0.999)))
}

fn mean(weights: &[(u32, f64)], values: &[DVec3]) -> DVec3 {
    weights.iter().map(|&(v, w)| values[v as usize] * w).sum()
}

/// What a shot needs about the scene, built once.
struct Shooter<'a> {
    scene: &'a Scene,
    el: &'a Elements,
    patches: &'a [Patch],
    occ: &'a Occluders,
    /// Element vertices of face f: `face_verts[vert_start[f]..vert_start[f + 1]]`, ordered
    /// by group.
    vert_start: Vec<u32>,
    face_verts: Vec<u32>,
    /// Groups of nearby vertices of face f (one per patch of f):
    /// `groups[group_start[f]..group_start[f + 1]]`. Occluders are looked for between a
    /// shooter and each group: the box around a whole floor would hold everything in a room.
    group_start: Vec<u32>,
    groups: Vec<Group>,
    /// Patches of face f: `patch_start[f]..patch_start[f + 1]` (patches are sorted by face).
    patch_start: Vec<u32>,
    /// Faces that have element vertices.
    receivers: Vec<u32>,
    /// Vertex positions nudged into their face (see `Shooter::new`).
    points: Vec<DVec3>,
    /// Irradiance under which a vertex's share of a shot is too small to be worth full
    /// visibility sampling.
    negligible: f64,
    tol: f64,
    /// Per shooter face, filled on its first shot: the receiver faces that something could
    /// stand in front of, ascending, with what (for the whole face: each patch narrows it
    /// down). `None` inside when over the memory budget: then each patch asks the BVH.
    face_blockers: Vec<OnceLock<Option<Vec<Reached>>>>,
    kept: AtomicUsize,
    /// Per patch, after its first shot: the faces it reached and each of their vertices'
    /// form factor times visibility. A patch shoots again whenever light came back to it
    /// (in a closed room, many times), and the geometry has not changed.
    factors: Vec<OnceLock<Factors>>,
    factors_kept: AtomicUsize,
}

/// A patch's shot, kept for the next: the faces it reached, and form factor times
/// visibility for the vertices `face_verts[s..e]` of each run `(s, e)`, runs one after the
/// other (vertices in no run got nothing).
struct Factors {
    faces: Vec<u32>,
    runs: Vec<(u32, u32)>,
    factors: Vec<f32>,
}

/// Vertices `face_verts[start..end]` and their bounds.
struct Group {
    start: u32,
    end: u32,
    lo: DVec3,
    hi: DVec3,
}

/// A receiver face and what could stand between it and a shooter face.
type Reached = (u32, FaceBlockers);

enum FaceBlockers {
    Listed(Vec<u32>),
    Many,
}

/// A receiver face in one shot: the shooter clipped to the face's front half-space, and
/// which faces could block the rays between them.
struct Pair<'s> {
    face: u32,
    poly: Vec<DVec3>,
    /// Bounds of `poly`.
    lo: DVec3,
    hi: DVec3,
    /// A point of `poly`, for when no sample of the patch lies in front of the face.
    inner: DVec3,
    /// `None`: nothing can block. `Some(Some(list))`: only these (for the whole face).
    /// `Some(None)`: ask the BVH.
    known: Option<Option<&'s [u32]>>,
}

enum Blockers {
    None,
    Listed(Vec<u32>),
    Any,
}

impl<'a> Shooter<'a> {
    fn new(
        scene: &'a Scene,
        el: &'a Elements,
        patches: &'a [Patch],
        occ: &'a Occluders,
        emitted: f64,
    ) -> Self {
        let nf = scene.faces.len();
        let mut vert_start = vec![0u32; nf + 1];
        for &f in &el.vertex_face {
            vert_start[f as usize + 1] += 1;
        }
        for f in 0..nf {
            vert_start[f + 1] += vert_start[f];
        }
        let mut patch_start = vec![0u32; nf + 1];
        for p in patches {
            patch_start[p.face as usize + 1] += 1;
        }
        for f in 0..nf {
            patch_start[f + 1] += patch_start[f];
        }
        // Each vertex joins the group of the first patch it weighs in; vertices in no patch
        // (in no triangle) form one last group of their face.
        let mut group_of = vec![u32::MAX; el.positions.len()];
        for (i, p) in patches.iter().enumerate() {
            for &(v, _) in &p.weights {
                if group_of[v as usize] == u32::MAX {
                    group_of[v as usize] = i as u32;
                }
            }
        }
        let mut order: Vec<u32> = (0..el.positions.len() as u32).collect();
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
                let step = (1e-6 * l).max(100.0 * tol).min(0.5 * l);
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
            vert_start,
            face_verts,
            group_start,
            groups,
            patch_start,
            receivers,
            points,
            negligible,
            tol,
            face_blockers: (0..nf).map(|_| OnceLock::new()).collect(),
            kept: AtomicUsize::new(0),
            factors: (0..patches.len()).map(|_| OnceLock::new()).collect(),
            factors_kept: AtomicUsize::new(0),
        }
    }

    fn verts_of(&self, f: u32) -> &[u32] {
        &self.face_verts
            [self.vert_start[f as usize] as usize..self.vert_start[f as usize + 1] as usize]
    }

    fn patches_of(&self, f: u32) -> std::ops::Range<usize> {
        self.patch_start[f as usize] as usize..self.patch_start[f as usize + 1] as usize
    }

    /// Shoots radiosity `b` from patch `p`: adds each vertex's irradiance to `received`
    /// and returns the faces that got some (ascending).
    fn shoot(&self, p: usize, b: DVec3, received: &mut [DVec3]) -> Vec<u32> {
        if let Some(known) = self.factors[p].get() {
            let verts = known
                .runs
                .iter()
                .flat_map(|&(s, e)| &self.face_verts[s as usize..e as usize]);
            for (&v, &g) in verts.zip(&known.factors) {
                received[v as usize] = b * g as f64;
            }
            return known.faces.clone();
        }
        let patch = &self.patches[p];
        let plane = self.scene.faces[patch.face as usize].plane;
        let known = self.face_blockers(patch.face);
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
                    let blockers = self.blockers(patch.face, &plane, pair, group);
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
        for (&(_, g0, g1), vals) in chunks.iter().zip(&values) {
            let (s, e) = (
                self.groups[g0].start as usize,
                self.groups[g1 - 1].end as usize,
            );
            for (&v, g) in self.face_verts[s..e].iter().zip(vals) {
                received[v as usize] = b * *g;
            }
        }
        let faces: Vec<u32> = pairs.iter().map(|p| p.face).collect();
        // Kept group by group, leaving out the groups that got nothing (behind the shooter,
        // or in shadow), which are often most of them.
        let mut known = Factors {
            faces: faces.clone(),
            runs: Vec::new(),
            factors: Vec::new(),
        };
        for (&(_, g0, g1), vals) in chunks.iter().zip(&values) {
            let mut vals = &vals[..];
            for group in &self.groups[g0..g1] {
                let (here, rest) = vals.split_at((group.end - group.start) as usize);
                vals = rest;
                if here.iter().any(|g| *g != 0.0) {
                    known.runs.push((group.start, group.end));
                    known.factors.extend(here.iter().map(|&g| g as f32));
                }
            }
        }
        let n = known.factors.len() + 2 * known.runs.len();
        if self.factors_kept.load(Ordering::Relaxed) + n <= FACTOR_BUDGET {
            self.factors_kept.fetch_add(n, Ordering::Relaxed);
            let _ = self.factors[p].set(known);
        }
        faces
    }

    /// The receivers of shots from face `fp` that something could stand in front of.
    fn face_blockers(&self, fp: u32) -> Option<&[Reached]> {
        let cell = self.face_blockers[fp as usize].get_or_init(|| {
            if self.kept.load(Ordering::Relaxed) > FACE_OCCLUDER_BUDGET {
                return None;
            }
            let face = &self.scene.faces[fp as usize];
            let found: Vec<Reached> = self
                .receivers
                .par_iter()
                .filter_map(|&f| {
                    let (lo, hi) = self.shaft(&face.verts, fp, &face.plane, f)?;
                    let mut list = Vec::new();
                    let planes = [face.plane, self.scene.faces[f as usize].plane];
                    self.occ.candidates(lo, hi, &planes, &[fp, f], &mut list);
                    match list.len() {
                        0 => None,
                        n if n <= MAX_FACE_OCCLUDERS => Some((f, FaceBlockers::Listed(list))),
                        _ => Some((f, FaceBlockers::Many)),
                    }
                })
                .collect();
            let size = found.len()
                + found
                    .iter()
                    .map(|(_, b)| match b {
                        FaceBlockers::Listed(l) => l.len(),
                        FaceBlockers::Many => 0,
                    })
                    .sum::<usize>();
            self.kept.fetch_add(size, Ordering::Relaxed);
            Some(found)
        });
        cell.as_deref()
    }

    /// Whether a shooter polygon `poly` on face `fp` (plane `plane`) can light receiver face
    /// `f`, and then the box around the part of it in front of `f` and `f`.
    fn shaft(&self, poly: &[DVec3], fp: u32, plane: &Plane, f: u32) -> Option<(DVec3, DVec3)> {
        if f == fp {
            return None;
        }
        let face = &self.scene.faces[f as usize];
        // The face's vertices lie in its polygon, so if its corners are all behind the
        // shooter, so are they.
        if face.verts.iter().all(|v| plane.dist(*v) <= self.tol) {
            return None;
        }
        if poly.iter().all(|v| face.plane.dist(*v) <= self.tol) {
            return None;
        }
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in poly.iter().chain(&face.verts) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        Some((lo, hi))
    }

    /// The shooter (patch polygon `poly` on face `fp`) as receiver face `f` sees it, or
    /// `None` if no vertex of `f` can get light from it.
    fn pair<'s>(
        &self,
        poly: &[DVec3],
        fp: u32,
        plane: &Plane,
        f: u32,
        known: Option<&'s [Reached]>,
    ) -> Option<Pair<'s>> {
        self.shaft(poly, fp, plane, f)?;
        let face = &self.scene.faces[f as usize];
        let poly = clip_polygon_3d(poly, &face.plane, self.tol);
        if poly.len() < 3 {
            return None;
        }
        let inner = poly.iter().copied().sum::<DVec3>() / poly.len() as f64;
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for v in &poly {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let known = match known.map(|k| k.binary_search_by_key(&f, |e| e.0).map(|i| &k[i].1)) {
            Some(Err(_)) => None,
            Some(Ok(FaceBlockers::Listed(l))) => Some(Some(&l[..])),
            Some(Ok(FaceBlockers::Many)) | None => Some(None),
        };
        Some(Pair {
            face: f,
            poly,
            lo,
            hi,
            inner,
            known,
        })
    }

    /// What could stand between the shooter and the vertices of `group`.
    fn blockers(&self, fp: u32, plane: &Plane, pair: &Pair, group: &Group) -> Blockers {
        let Some(known) = pair.known else {
            return Blockers::None;
        };
        let (lo, hi) = (pair.lo.min(group.lo), pair.hi.max(group.hi));
        let mut list = Vec::new();
        match known {
            Some(l) => list.extend(
                l.iter()
                    .copied()
                    .filter(|&o| self.occ.box_overlaps(o, lo, hi)),
            ),
            None => {
                let planes = [*plane, self.scene.faces[pair.face as usize].plane];
                self.occ
                    .candidates(lo, hi, &planes, &[fp, pair.face], &mut list);
            }
        }
        match list.len() {
            0 => Blockers::None,
            n if n <= MAX_LISTED_OCCLUDERS => Blockers::Listed(list),
            _ => Blockers::Any,
        }
    }

    /// Form factor from vertex `v` to the shooter times the fraction of it in view: the
    /// vertex gets `b` times this. (`b` only decides how hard to look.)
    fn receive(
        &self,
        patch: &Patch,
        plane: &Plane,
        pair: &Pair,
        blockers: &Blockers,
        v: u32,
        b: DVec3,
    ) -> f64 {
        let x = self.points[v as usize];
        if plane.dist(x) <= self.tol {
            return 0.0;
        }
        let n = self.el.normals[v as usize];
        let ff = form_factor(x, n, &pair.poly);
        if !(ff > 0.0) {
            return 0.0;
        }
        let e = b * ff;
        let vis = match blockers {
            Blockers::None => 1.0,
            blockers => {
                let size = patch.radius / (patch.centroid - x).length();
                let level = if e.max_element() < self.negligible || size < ONE_RAY_BELOW {
                    0
                } else if size < FEW_RAYS_BELOW {
                    1
                } else {
                    2
                };
                let skip = [patch.face, pair.face];
                let blocked = |s: DVec3| match blockers {
                    Blockers::Listed(list) => self.occ.segment_blocked_by(x, s, list),
                    _ => self.occ.segment_blocked_skip(x, s, &skip),
                };
                // Each ray counts by its own point-to-point form factor, cosθ·cosθ'/r², not
                // one each (Wallace, Elmquist & Haines 1989): with the near half of a patch
                // hidden, an unweighted count would keep twice too much light.
                let np = plane.n;
                let (mut seen, mut total) = (0.0, 0.0);
                for &s in &patch.samples[level] {
                    let d = s - x;
                    let w = n.dot(d) * -np.dot(d) / d.length_squared().powi(2);
                    if w > 0.0 {
                        total += w;
                        if !blocked(s) {
                            seen += w;
                        }
                    }
                }
                if !(total > 0.0) {
                    (!blocked(pair.inner)) as u8 as f64
                } else {
                    seen / total
                }
            }
        };
        ff * vis
    }
}

/// Irradiance at `x` (unit normal `n`) from a polygon of unit radiance, over π: the
/// point-to-polygon form factor by Lambert's formula, ½·Σ θ_k (n·Γ_k) / π, with θ_k the
/// angle the k-th edge subtends at `x` and Γ_k the unit normal of the plane through `x`
/// and that edge. The polygon must run counter-clockwise seen from its front, with `x` in
/// front of it and the polygon in front of `x` (clip it to `x`'s tangent plane first).
fn form_factor(x: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    let mut s = 0.0;
    let Some(last) = poly.last() else { return 0.0 };
    let mut a = *last - x;
    for q in poly {
        let b = *q - x;
        let c = a.cross(b);
        let l = c.length();
        // θ from atan2 stays accurate for edges seen nearly end-on, where acos of the
        // normalised dot product loses all its digits.
        if l > 0.0 {
            s += l.atan2(a.dot(b)) * n.dot(c) / l;
        }
        a = b;
    }
    // Seen from its front the polygon runs clockwise, so each n·Γ_k is negative.
    (-s / (2.0 * PI)).max(0.0)
}

#[cfg(test)]
mod test;

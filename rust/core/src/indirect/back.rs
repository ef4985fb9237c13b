//! The backs of thin surfaces. Cycles' diffuse surfaces reflect from both sides, so a single
//! plane lit from behind (a ceiling panel over a lamp facing up, a leaf, a sheet) sends
//! that light on into the half-space behind it. Cycles bakes only a face's front, and so
//! do we (the elements are on the front); what the back changes is the light it reflects
//! onto other surfaces, so the back is a shooter and a receiver of this stage only.
//!
//! A face is two-sided when it is thin: not part of a closed convex solid
//! (`scene::solids`), the same rule as for emissive faces (`scene::emitters`). A solid's
//! faces are one-sided: their backs face its inside, which nothing outside sees.
//!
//! Cost stays where light goes: a thin face gets back patches only when some other face
//! lies behind it with its front (or, if thin, its back) turned towards it, so that light
//! from the back has somewhere to land. The back patches are the face's grid cells
//! (`patches::Grid`), whole: the cover rule (`coplanar_contacts`) is about a face lying
//! against the front, and leaves the back open. A back patch's radiosity is its albedo
//! times the mean irradiance at its stratified points: direct light there
//! (`direct::back`), and what the shots send to about four of them, or its centroid when
//! it is small seen from the shooter (`back_gains`).

use std::sync::atomic::Ordering;

use glam::DVec3;
use rayon::prelude::*;

use super::pair::{Blockers, FaceBlockers, Pair, Reached};
use super::patches::{patch, Grid, Patch};
use super::shooter::{Group, Shooter};
use super::{FACE_OCCLUDER_BUDGET, FEW_RAYS_BELOW, MAX_FACE_OCCLUDERS, ONE_RAY_BELOW};
use crate::geom::bvh::{Aabb, BoxTree};
use crate::geom::polygon::{signed_area_2d, simplify_convex};
use crate::geom::raycast::Occluders;
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::scene::solids::Occluder;
use crate::scene::Scene;
use crate::BakeError;

/// The faces with back patches, and where those are in the patch list.
pub(super) struct Backs {
    /// `(face, first patch, end)`, ascending.
    faces: Vec<(u32, u32, u32)>,
}

impl Backs {
    /// From the patch list (backs after all fronts, by face).
    pub(super) fn new(patches: &[Patch]) -> Self {
        let mut faces: Vec<(u32, u32, u32)> = Vec::new();
        for (i, p) in patches.iter().enumerate().filter(|(_, p)| p.back) {
            match faces.last_mut() {
                Some(last) if last.0 == p.face => last.2 = i as u32 + 1,
                _ => faces.push((p.face, i as u32, i as u32 + 1)),
            }
        }
        Backs { faces }
    }
}

/// Whether face `f` is thin (reflects from both sides).
pub(crate) fn is_thin(scene: &Scene, f: u32) -> bool {
    let o = scene.face_occluder[f as usize] as usize;
    matches!(scene.occluders[o], Occluder::Face(_))
}

/// The thin faces whose backs can light another face, ascending: they reflect or emit
/// (`emission`: what the indirect stage sends for each face), and some other face has a
/// part more than `tol` behind them and its front turned their way (or, itself thin, its
/// back).
pub(super) fn two_sided(scene: &Scene, emission: &[DVec3], tol: f64) -> Vec<u32> {
    let faces = &scene.faces;
    let tree = BoxTree::new(faces.iter().map(|f| Aabb::from_points(&f.verts)).collect());
    (0..faces.len() as u32)
        .into_par_iter()
        .filter(|&f| {
            let face = &faces[f as usize];
            let bright =
                face.albedo.max_element() > 0.0 || emission[f as usize].max_element() > 0.0;
            if !bright || !is_thin(scene, f) {
                return false;
            }
            let back = face.plane.flipped();
            // Boxes wholly within `tol` in front of the face are passed over.
            tree.any_in_volume(&[back], -tol, |g| {
                let other = &faces[g as usize];
                g != f
                    && other.verts.iter().any(|v| back.dist(*v) > tol)
                    && face.verts.iter().any(|v| {
                        let d = other.plane.dist(*v);
                        d > tol || (d < -tol && is_thin(scene, g))
                    })
            })
        })
        .collect()
}

/// Back patches of `faces` (ascending): each face's grid cells, turned round.
pub(super) fn back_patches(
    scene: &Scene,
    faces: &[u32],
    el: &Elements,
    patch_size: f64,
    rays: u32,
) -> Vec<Patch> {
    faces
        .par_iter()
        .flat_map_iter(|&fi| {
            let f = &scene.faces[fi as usize];
            let grid = Grid::new(&f.poly2, patch_size);
            let (nx, ny) = grid.n;
            let mut out = Vec::new();
            for j in 0..ny {
                for i in 0..nx {
                    let poly2 = simplify_convex(&grid.clip(&f.poly2, (i, j)));
                    if poly2.len() < 3 || !(signed_area_2d(&poly2) > 0.0) {
                        continue;
                    }
                    // Seeded apart from the front's cells.
                    let seed = 1 << 63 ^ (fi as u64) << 40 ^ j << 20 ^ i;
                    let mut p = patch(fi, f, &poly2, &[], el, rays, seed);
                    p.poly.reverse();
                    p.plane = f.plane.flipped();
                    p.back = true;
                    out.push(p);
                }
            }
            out
        })
        .collect()
}

/// Each back patch's mean direct irradiance (lights and world) over its stratified points.
pub(super) fn back_direct(
    scene: &Scene,
    occ: &Occluders,
    backs: &[Patch],
    progress: &Progress,
) -> Result<Vec<DVec3>, BakeError> {
    let (mut points, mut faces) = (Vec::new(), Vec::new());
    for p in backs {
        points.extend_from_slice(&p.samples[2]);
        faces.extend(std::iter::repeat_n(p.face, p.samples[2].len()));
    }
    let e = crate::direct::back::back_irradiance(scene, occ, &points, &faces, progress)?;
    let mut at = 0;
    Ok(backs
        .iter()
        .map(|p| {
            let n = p.samples[2].len();
            let sum: DVec3 = e[at..at + n].iter().copied().sum();
            at += n;
            sum / n.max(1) as f64
        })
        .collect())
}

/// Per shooter face and side: the back receivers its light can reach (index into
/// `Backs::faces`), and of those the ones something could stand in front of, with what (for
/// the whole shooter face; each patch narrows it down), as `face_blockers` keeps for fronts.
pub(super) struct BackReach {
    reach: Vec<u32>,
    blockers: Vec<Reached>,
}

impl Shooter<'_> {
    /// The back receivers of shots from face `fp` (from its back if `back`): `None` over the
    /// memory budget, then every back is tried and each patch asks the BVH.
    fn back_reach(&self, fp: u32, back: bool) -> Option<&BackReach> {
        let nf = self.scene.faces.len();
        let cell = self.back_blockers[fp as usize + back as usize * nf].get_or_init(|| {
            if self.kept.load(Ordering::Relaxed) > FACE_OCCLUDER_BUDGET {
                return None;
            }
            let face = &self.scene.faces[fp as usize];
            let plane = self.side_plane(fp, back);
            let single = self.side_patches(fp, back) == 1;
            let found: Vec<(u32, Option<FaceBlockers>)> = self
                .backs
                .faces
                .par_iter()
                .enumerate()
                .filter_map(|(k, &(g, start, end))| {
                    let side = self.scene.faces[g as usize].plane.flipped();
                    let (lo, hi) = self.shaft(&face.verts, fp, &plane, g, &side)?;
                    // One patch to one patch: the query for the pair's own box is the
                    // same work, narrower; a face-wide list would only add to it.
                    if single && end - start == 1 {
                        return Some((k as u32, Some(FaceBlockers::Many)));
                    }
                    let mut list = Vec::new();
                    self.occ
                        .candidates(lo, hi, &[plane, side], &[fp, g], &mut list);
                    let blockers = match list.len() {
                        0 => None,
                        n if n <= MAX_FACE_OCCLUDERS => Some(FaceBlockers::Listed(list)),
                        _ => Some(FaceBlockers::Many),
                    };
                    Some((k as u32, blockers))
                })
                .collect();
            let mut reach = Vec::with_capacity(found.len());
            let mut blockers = Vec::new();
            for (k, b) in found {
                reach.push(k);
                if let Some(b) = b {
                    blockers.push((self.backs.faces[k as usize].0, b));
                }
            }
            let size = reach.len()
                + blockers
                    .iter()
                    .map(|(_, b)| match b {
                        FaceBlockers::Listed(l) => 1 + l.len(),
                        FaceBlockers::Many => 1,
                    })
                    .sum::<usize>();
            self.kept.fetch_add(size, Ordering::Relaxed);
            Some(BackReach { reach, blockers })
        });
        cell.as_ref()
    }

    /// Whether `patch` is seen from every point of `group`'s box by one ray
    /// (`receive_at`), with something possibly in the way: then a ray through the BVH per
    /// point costs less than the box query that would look for what it might cross.
    pub(super) fn one_ray(&self, patch: &Patch, pair: &Pair, group: &Group) -> bool {
        let nearest = patch.centroid.clamp(group.lo, group.hi);
        pair.known.is_some() && patch.radius < ONE_RAY_BELOW * (patch.centroid - nearest).length()
    }

    /// How many patches face `f` has on its back (if `back`) or front.
    pub(super) fn side_patches(&self, f: u32, back: bool) -> usize {
        if !back {
            return self.patches_of(f).len();
        }
        let faces = &self.backs.faces;
        match faces.binary_search_by_key(&f, |e| e.0) {
            Ok(i) => (faces[i].2 - faces[i].1) as usize,
            Err(_) => 0,
        }
    }

    /// What each back patch gains per unit of radiosity shot by `patch`: the mean over its
    /// points of form factor times visibility; `b` only decides how hard to look. Patches
    /// that gain nothing are left out.
    pub(super) fn back_gains(&self, patch: &Patch, b: DVec3) -> Vec<(u32, f64)> {
        let plane = patch.plane;
        let reach = self.back_reach(patch.face, patch.back);
        let all: Vec<u32>;
        let (faces, known) = match reach {
            Some(r) => (&r.reach[..], Some(&r.blockers[..])),
            None => {
                all = (0..self.backs.faces.len() as u32).collect();
                (&all[..], None)
            }
        };
        faces
            .par_iter()
            .flat_map_iter(|&k| {
                let (g, start, end) = self.backs.faces[k as usize];
                let side = self.scene.faces[g as usize].plane.flipped();
                let pair = self.pair_on(&patch.poly, patch.face, &plane, g, side, known);
                let mut out = Vec::new();
                let Some(pair) = pair else { return out };
                for q in start..end {
                    // A back patch small as seen from the shooter takes the factor at its
                    // centroid, as a far shooter gets one ray (`ONE_RAY_BELOW`).
                    let back = &self.patches[q as usize];
                    let size = back.radius / (back.centroid - patch.centroid).length();
                    let points = &back.samples[if size < FEW_RAYS_BELOW { 0 } else { 1 }];
                    let (lo, hi) = points.iter().fold((points[0], points[0]), |(lo, hi), x| {
                        (lo.min(*x), hi.max(*x))
                    });
                    let group = Group {
                        start: 0,
                        end: 0,
                        lo,
                        hi,
                    };
                    // One point that will see the shooter by one ray (`receive_at`): a
                    // ray through the BVH costs less than the box query that would look
                    // for what it might cross.
                    let blockers = if points.len() == 1 && self.one_ray(patch, &pair, &group) {
                        Blockers::Any
                    } else {
                        self.blockers(patch.face, &patch.poly, &plane, &pair, &group)
                    };
                    let sum: f64 = points
                        .iter()
                        .map(|&x| self.receive_at(patch, &plane, &pair, &blockers, x, side.n, b))
                        .sum();
                    let gain = sum / points.len() as f64;
                    if gain != 0.0 {
                        out.push((q, gain));
                    }
                }
                out
            })
            .collect()
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::scene::json::{LightJson, SceneJson, SettingsJson};
    use crate::scenes::{cuboid, polygons_mesh};

    fn quad(z: f64, h: f64, up: bool) -> Vec<[f64; 3]> {
        let mut v = vec![[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]];
        if !up {
            v.reverse();
        }
        v
    }

    fn scene(meshes: Vec<crate::scene::json::MeshJson>) -> Scene {
        crate::scene::validate(&SceneJson {
            format: "penumbra-scene".into(),
            version: 1,
            meshes,
            lights: vec![LightJson {
                name: "Bulb".into(),
                point: Some([0.3, 0.2, 0.5]),
                intensity: Some([1.0; 3]),
                ..Default::default()
            }],
            settings: SettingsJson::default(),
        })
        .unwrap()
    }

    #[test]
    fn only_thin_faces_with_something_behind_are_two_sided() {
        // A floor with nothing under it; a plane facing up over it (the floor is behind
        // it, facing it); a box above that (a solid); a black plane facing down, whose
        // back sees the box but reflects nothing.
        let sc = scene(vec![
            polygons_mesh("Floor", vec![quad(0.0, 2.0, true)], None),
            polygons_mesh("Plane", vec![quad(1.0, 1.0, true)], None),
            polygons_mesh(
                "Box",
                cuboid([-0.5, -0.5, 1.5], [0.5, 0.5, 2.0], false),
                None,
            ),
            polygons_mesh("Black", vec![quad(1.2, 0.2, false)], Some([0.0; 3])),
        ]);
        let emission = vec![DVec3::ZERO; sc.faces.len()];
        assert_eq!(two_sided(&sc, &emission, 1e-9), vec![1]);
        // Turned down with nothing above, the plane's back has nowhere to send light.
        let sc = scene(vec![
            polygons_mesh("Floor", vec![quad(0.0, 2.0, true)], None),
            polygons_mesh("Plane", vec![quad(1.0, 1.0, false)], None),
        ]);
        let emission = vec![DVec3::ZERO; sc.faces.len()];
        assert!(two_sided(&sc, &emission, 1e-9).is_empty());
    }
}

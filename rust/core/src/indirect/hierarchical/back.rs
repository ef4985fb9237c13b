//! The backs of thin faces in the hierarchy. A face that is not part of a closed convex solid
//! reflects from both sides, as Cycles' diffuse surfaces do (`indirect::back` says why and
//! how the progressive solver does it); we bake only its front, but its back receives light
//! (direct and bounced) and sends it on into the half-space behind the face.
//!
//! Here the back of such a face is a face of its own: an id after the scene's faces whose
//! `Face` is the front's turned round (normal, plane, vertex order and frame), with its own
//! subtree of the hierarchy over the same element triangles (`Hierarchy::build_two_sided`).
//! Everything that asks a node's face for its normal then sees the back's: the leaves'
//! boundary edges run counter-clockwise about it, links and the shaft test take its plane,
//! the solve pulls and pushes along it, visibility samples leave from it. Only three places
//! map a back to its scene face (`Hierarchy::real_face`): a face's front and back never
//! link (`refine`), the scene face is no blocker of its own links (`visibility`), and the
//! back has no element vertices, so the final gather starts from front leaves only
//! (`vertices`). Back and front sit side by side in the cluster tree (same centre), so a
//! cluster over a thin face sends from both sides along their own normals.
//!
//! Cost stays where light goes: a thin face has a back only where something lies behind
//! it that the back can light (`indirect::back::two_sided`, the progressive solver's rule).
//! The cover rule (`coplanar_contacts`: a box standing on a plane hides the plane's front
//! under it) is about the front, so a back takes all of its face's triangles.
//!
//! A back's direct irradiance comes from `direct::back` (each light with the ray index's
//! candidates as blockers, and the world), as for the progressive solver's back patches.
//! The element mesh follows the front's shadows, not the back's, so each back leaf takes the
//! mean over its triangles by a degree-2 rule of three points per triangle, each triangle
//! split into four while those values are not what its corners' give them linearly (a
//! shadow edge crosses it), in rounds of one batch each; every position of the leaf gets
//! that mean (the solve only uses a leaf's mean: nothing below a leaf sends or receives on
//! its own).

use std::borrow::Cow;

use glam::{DVec2, DVec3};

use super::hierarchy::Hierarchy;
use super::link::receiver_triangles;
use crate::geom::frame::Frame;
use crate::geom::polygon::split_in_four;
use crate::geom::raycast::Occluders;
use crate::mesh::elements::Elements;
use crate::progress::Progress;
use crate::scene::{Face, Scene};
use crate::BakeError;

/// Triangles of a back leaf at which its direct light is taken (spread over the leaf and
/// weighted by the area each stands for, `link::receiver_triangles`, when it has more).
const BACK_TRIANGLES: u32 = 16;
/// Times a triangle may be split into four for its mean direct light.
const SPLIT_DEPTH: u32 = 5;
/// Points evaluated in all, at most this times the first round's plus `POINT_FLOOR`.
const POINT_BUDGET: usize = 16;
const POINT_FLOOR: usize = 1 << 16;
/// A triangle is split when the values at the rule's points differ from those the corners'
/// values give them (linearly) by more than this fraction of the largest value found on any
/// back.
const SPLIT_REL: f64 = 0.01;

/// The scene's faces followed by the backs of the thin faces that need one.
pub struct Backs<'a> {
    /// `faces[scene.faces.len() + k]` is the back of `of[k]`.
    pub faces: Cow<'a, [Face]>,
    /// The faces with a back, ascending.
    pub of: Vec<u32>,
}

impl<'a> Backs<'a> {
    /// The thin faces of `scene` whose backs can light another face (`tol`: `occ`'s
    /// "same place" distance), each turned round after the scene's faces.
    pub fn new(scene: &'a Scene, occ: &Occluders) -> Self {
        // What the indirect stage sends per face: emissive faces that are also area lights
        // have sent their light as direct light.
        let mut emission: Vec<DVec3> = scene.faces.iter().map(|f| f.emission).collect();
        for l in &scene.lights {
            if let Some(f) = l.from_face {
                emission[f as usize] = DVec3::ZERO;
            }
        }
        let of = crate::indirect::back::two_sided(scene, &emission, occ.tolerance());
        if of.is_empty() {
            return Backs {
                faces: Cow::Borrowed(&scene.faces),
                of,
            };
        }
        let mut faces = Vec::with_capacity(scene.faces.len() + of.len());
        faces.extend_from_slice(&scene.faces);
        faces.extend(of.iter().map(|&f| turned(&scene.faces[f as usize])));
        Backs {
            faces: Cow::Owned(faces),
            of,
        }
    }
}

/// Face `f` seen from behind: the same polygon, counter-clockwise about the other normal.
fn turned(f: &Face) -> Face {
    let mut verts = f.verts.clone();
    verts.reverse();
    // Swapping the frame's axes turns its normal round (u × v = n); a polygon's
    // coordinates swapped and reversed run counter-clockwise in it again.
    let frame = Frame {
        origin: f.frame.origin,
        u: f.frame.v,
        v: f.frame.u,
        n: -f.frame.n,
    };
    let poly2 = f.poly2.iter().rev().map(|p| DVec2::new(p.y, p.x)).collect();
    Face {
        verts,
        plane: f.plane.flipped(),
        frame,
        poly2,
        ..f.clone()
    }
}

/// Sets `direct` (per leaf position) on every back leaf of `h` to the mean direct irradiance
/// over its triangles on the back of its face (see the module doc). Returns the number of
/// points at which the light was taken.
pub fn set_direct(
    scene: &Scene,
    occ: &Occluders,
    el: &Elements,
    h: &Hierarchy,
    direct: &mut [DVec3],
    progress: &Progress,
) -> Result<usize, BakeError> {
    let leaves: Vec<u32> = (0..h.nodes.len() as u32)
        .filter(|&i| {
            let n = &h.nodes[i as usize];
            n.is_leaf() && h.is_back(n.face)
        })
        .collect();
    if leaves.is_empty() {
        return Ok(0);
    }
    // Triangles still to integrate: (back leaf, corners, weight, splits left).
    let mut items: Vec<(u32, [DVec3; 3], f64, u32)> = Vec::new();
    for (k, &i) in leaves.iter().enumerate() {
        let n = &h.nodes[i as usize];
        for (t, w) in receiver_triangles(h, el, n, BACK_TRIANGLES) {
            items.push((k as u32, t, w, SPLIT_DEPTH));
        }
    }
    // The scale of direct light in the scene: the fronts' (all that `direct` holds yet), or
    // the backs' where only they are lit. Not the backs' alone: a back that only rounding
    // lights (inside a closed box that is no convex solid) would split on noise of 1e-14.
    let front = direct.iter().map(|e| e.element_sum()).fold(0.0, f64::max);
    let mut sum = vec![DVec3::ZERO; leaves.len()];
    let mut weight = vec![0.0f64; leaves.len()];
    let mut scale = None;
    let mut budget = None;
    let mut evaluated = 0;
    while !items.is_empty() {
        progress.check()?;
        let mut points = Vec::with_capacity(6 * items.len());
        let mut faces = Vec::with_capacity(6 * items.len());
        for &(k, t, _, _) in &items {
            let f = h.real_face(h.nodes[leaves[k as usize] as usize].face);
            points.extend(rule_points(&t));
            // The corners too, a hair inside, only to see a shadow that cuts a corner off
            // and misses the rule's points (a ninth of the triangle beyond each).
            let c = (t[0] + t[1] + t[2]) / 3.0;
            points.extend(t.map(|x| x + (c - x) * 1e-6));
            faces.extend([f; 6]);
        }
        let e = crate::direct::back::back_irradiance(scene, occ, &points, &faces, progress)?;
        evaluated += points.len();
        let scale = *scale.get_or_insert_with(|| {
            e.iter().map(|x| x.element_sum()).fold(front, f64::max) * SPLIT_REL
        });
        let budget = budget.get_or_insert(POINT_BUDGET * points.len() + POINT_FLOOR);
        *budget = budget.saturating_sub(points.len());
        // Splits that would overrun the budget are not made: the cost stays bounded
        // whatever the light does.
        let splitting = |v: &[DVec3]| {
            let s: [f64; 6] = std::array::from_fn(|i| v[i].element_sum());
            // How far the rule's values stray from the plane through the corners' values:
            // nothing where the light varies linearly, a sixth of the jump or more where a
            // shadow edge separates a corner from the others.
            let bend = (0..3)
                .map(|i| {
                    (s[i] - (4.0 * s[3 + i] + s[3 + (i + 1) % 3] + s[3 + (i + 2) % 3]) / 6.0).abs()
                })
                .fold(0.0, f64::max);
            bend > scale
        };
        let wanted = items
            .iter()
            .zip(e.chunks_exact(6))
            .filter(|(it, v)| it.3 > 0 && splitting(v))
            .count();
        let split_now = 24 * wanted <= *budget;
        let mut next = Vec::new();
        for (&(k, t, w, depth), v) in items.iter().zip(e.chunks_exact(6)) {
            if split_now && depth > 0 && splitting(v) {
                next.extend(split_in_four(&t).map(|q| (k, q, 0.25 * w, depth - 1)));
                continue;
            }
            sum[k as usize] += (v[0] + v[1] + v[2]) * (w / 3.0);
            weight[k as usize] += w;
        }
        items = next;
    }
    for (k, &i) in leaves.iter().enumerate() {
        let n = &h.nodes[i as usize];
        let mean = sum[k] / weight[k].max(1e-300);
        direct[n.lo as usize..n.hi as usize].fill(mean);
    }
    Ok(evaluated)
}

/// The degree-2 rule's three points of triangle `t` (Strang & Fix), each of weight 1/3.
fn rule_points(t: &[DVec3; 3]) -> [DVec3; 3] {
    [[4.0, 1.0, 1.0], [1.0, 4.0, 1.0], [1.0, 1.0, 4.0]]
        .map(|[a, b, c]| (t[0] * a + t[1] * b + t[2] * c) / 6.0)
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::geom::plane::newell_normal;
    use crate::geom::polygon::signed_area_2d;
    use crate::indirect::patches::test::grid_elements;
    use crate::indirect::test::{quad, scene, v};
    use crate::scene::{Light, LightKind};

    #[test]
    fn a_turned_face_is_the_same_polygon_seen_from_behind() {
        let f = quad(
            v(0.1, 0.2, 0.3),
            v(0.5, 0.1, 0.2),
            v(-0.1, 0.4, 0.3),
            0.5,
            DVec3::ZERO,
        );
        let b = turned(&f);
        assert_eq!(b.plane.n, -f.plane.n);
        assert!((b.frame.u.cross(b.frame.v) - b.plane.n).length() < 1e-12);
        assert!((newell_normal(&b.verts).normalize() - b.plane.n).length() < 1e-12);
        assert!((signed_area_2d(&b.poly2) - f.area).abs() < 1e-12);
        for (x, p) in b.verts.iter().zip(&b.poly2) {
            assert!((b.frame.to_2d(*x) - *p).length() < 1e-12);
        }
    }

    /// A sun shining up at angle `theta` onto a 2×2 plane at height 1 (facing up), over a
    /// black 0.9 × 0.8 floor that shades part of the plane's back.
    fn lit_from_below(theta: f64) -> Scene {
        let floor = quad(
            v(0., 0., 0.),
            v(0.45, 0., 0.),
            v(0., 0.4, 0.),
            0.0,
            DVec3::ZERO,
        );
        let plane = quad(
            v(0., 0., 1.),
            v(1., 0., 0.),
            v(0., 1., 0.),
            0.8,
            DVec3::ZERO,
        );
        let mut sc = scene(vec![floor, plane], |_| {});
        sc.lights.push(Light {
            name: "Sun".into(),
            index: 0,
            kind: LightKind::Sun {
                direction: v(theta.sin(), 0.0, theta.cos()),
                irradiance: DVec3::splat(3.0),
                half_angle: 0.0,
            },
            from_face: None,
        });
        sc
    }

    #[test]
    fn a_back_takes_every_triangle_of_its_face_and_the_direct_light_behind_it() {
        let theta: f64 = 0.37;
        let sc = lit_from_below(theta);
        let occ = Occluders::new(&sc.faces);
        // The black floor has no back; the plane's back sees the floor.
        let backs = Backs::new(&sc, &occ);
        assert_eq!(backs.of, vec![1]);
        assert_eq!(backs.faces.len(), 3);
        // Coarse elements, so that the floor's shadow cuts through them; half the plane's
        // front covered (say, by a box standing on it): its back is whole all the same.
        let el = grid_elements(&sc.faces, 6);
        let keep = |t: u32| el.tri_face[t as usize] == 0 || t % 2 == 0;
        let mut h = Hierarchy::build_two_sided(&backs.faces, &el, keep, 0.0, &backs.of);
        h.set_boxes(&backs.faces, &el);
        let on = |face: u32| {
            let mut t: Vec<u32> = (0..h.order.len())
                .filter(|&p| h.nodes[h.leaf_node[p] as usize].face == face)
                .map(|p| h.order[p])
                .collect();
            t.sort();
            t
        };
        let plane: Vec<u32> = (0..el.triangles.len() as u32)
            .filter(|&t| el.tri_face[t as usize] == 1)
            .collect();
        assert_eq!(on(2), plane);
        assert_eq!(on(1).len(), plane.len() / 2);
        assert_eq!(h.real_face(2), 1);
        assert!(h.is_back(2) && !h.is_back(1));
        // Its direct light: E·cos θ outside the floor's shadow (the floor shifted by tan θ,
        // wholly on the plane), nothing inside.
        let mut direct = vec![DVec3::ZERO; h.order.len()];
        let points = set_direct(&sc, &occ, &el, &h, &mut direct, &Progress::new()).unwrap();
        // The shadow's edges are followed down: more points than the first round's.
        assert!(points > 6 * plane.len(), "{points}");
        let full = 3.0 * theta.cos();
        let power: f64 = (0..h.order.len())
            .filter(|&p| h.is_back(h.nodes[h.leaf_node[p] as usize].face))
            .map(|p| direct[p].x * h.area[p])
            .sum();
        let want = full * (4.0 - 0.72);
        // Measured 4.9e-4 off (the shadow's edges run along the triangles' legs, so each
        // level's error has one sign along an edge).
        assert!((power / want - 1.0).abs() < 2e-3, "{power} vs {want}");
        assert!(direct
            .iter()
            .all(|e| e.x >= 0.0 && e.x <= full * (1.0 + 1e-12)));
        // Fronts keep what they were given (here nothing).
        assert!((0..h.order.len())
            .filter(|&p| !h.is_back(h.nodes[h.leaf_node[p] as usize].face))
            .all(|p| direct[p] == DVec3::ZERO));
    }

    #[test]
    fn backs_that_no_light_reaches_are_not_split() {
        // The built-in chair's backrest is a box that is no convex solid (it stands on the
        // seat), so its faces are thin and their backs face its inside, where light arrives
        // only through rounding (values of 1e-14 where the faces meet). Split against the
        // largest of those, they once took 800k points (6 s of a 0.6 s bake).
        let sc = crate::scene::validate(&crate::scenes::chair()).unwrap();
        let occ = Occluders::new(&sc.faces);
        let backs = Backs::new(&sc, &occ);
        assert!(!backs.of.is_empty());
        let el = grid_elements(&sc.faces, 4);
        let mut h = Hierarchy::build_two_sided(&backs.faces, &el, |_| true, 0.0, &backs.of);
        h.set_boxes(&backs.faces, &el);
        // The fronts' direct light, as the bake hands it on (about the seat's).
        let mut direct = vec![DVec3::splat(10.0); h.order.len()];
        let points = set_direct(&sc, &occ, &el, &h, &mut direct, &Progress::new()).unwrap();
        let tris = backs
            .of
            .iter()
            .map(|&f| el.tri_face.iter().filter(|&&g| g == f).count())
            .sum::<usize>();
        assert_eq!(points, 6 * tris);
        for p in 0..h.order.len() {
            if h.is_back(h.nodes[h.leaf_node[p] as usize].face) {
                assert!(direct[p].max_element() < 1e-9, "{}", direct[p]);
            }
        }
    }
}

//! Stage 6: direct irradiance (W/m², per RGB channel) at a receiver point, per light, driven
//! by the region's relation to that light (paper 2.6): umbra costs nothing, lit is one exact
//! Lambert integral, and only penumbra (or an unprocessed region) looks at the occluders.
//!
//! Penumbra, exact: the visible part of an area light is the light polygon minus the parts
//! of it hidden by each occluder. The part hidden by a convex occluder `O` is the set of light
//! points `l` for which the segment `[p, l]` meets `O`: the light clipped by the planes through
//! `p` and each edge of `O` (keeping `O`'s side) and by `O`'s plane (keeping the far side).
//! Clipping by planes through `p` never projects anything to infinity, so occluders beside,
//! behind or crossing the light need no special case. Several hidden parts overlap, so their
//! union is taken in the light's plane with `i_overlay` before the contour integral.
//!
//! Penumbra, sampled (the paper's way): the exact unoccluded integral times the visible
//! fraction of stratified points on the light. The paper counts points; here each point is
//! weighted by the integrand (`cos·cos/r²`), so the estimate converges to the exact value
//! instead of to a biased one when the light is large seen from the receiver.
//!
//! Touching is not blocking: an occluder whose plane holds the receiver point (the receiver
//! itself, a face the point lies on) or the light (a ceiling the light is mounted on) hides
//! nothing there. "Holds" allows a relative [`TOUCH`] so that rounding cannot flip it.

// `!(x > 0.0)` is meant: NaN must take the "nothing here" branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::{DVec2, DVec3};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::overlay::FloatOverlay;
use robust::{orient3d, Coord3D};

use crate::geom::box_grid::bounds;
use crate::geom::lambert::{contours_irradiance, polygon_irradiance};
use crate::geom::plane::newell_normal;
use crate::geom::polygon::{clip_polygon_3d, inside_convex, signed_area_2d, subtract_convex};
use crate::geom::{Frame, Plane};
use crate::relation::Relation;
use crate::scene::Spot;
use crate::settings::PenumbraVisibility;

/// Distances below this fraction of the configuration's size count as contact (see the
/// module note): a million times the rounding of f64 coordinates, and small enough that an
/// occluder crossing the light moves its hidden part by no more than 1e-10 relative.
/// Contact that is only exact to f32 precision (1e-7) is not recognised; Cycles does not
/// recognise it either, and shadows such a light as well.
pub const TOUCH: f64 = 1e-10;

/// Direct irradiance at `p` (unit normal `n`) from a uniform diffuse convex polygon light of
/// `radiance` (W·sr⁻¹·m⁻² per channel) that emits from its front (`light_plane.n`, the side
/// its vertices run counter-clockwise around). `blockers` are the convex occluders that may
/// hide part of the light from `p` (any orientation); they are looked at only when
/// `relation` is [`Relation::Penumbra`] or [`Relation::Unprocessed`]. `samples` is used by
/// [`PenumbraVisibility::Sampled`] only.
///
/// ```
/// use glam::DVec3;
/// use penumbra::direct::area_light;
/// use penumbra::geom::Plane;
/// use penumbra::relation::Relation::{Lit, Penumbra};
/// use penumbra::settings::PenumbraVisibility::Exact;
/// let quad = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64| {
///     [(x0, y0), (x1, y0), (x1, y1), (x0, y1)].map(|(x, y)| DVec3::new(x, y, z))
/// };
/// // A 2×2 light at height 1 facing down (wound clockwise seen from above), and an
/// // occluder halfway up that hides exactly its x < 0 half from the origin.
/// let mut light = quad(-1.0, 1.0, -1.0, 1.0, 1.0);
/// light.reverse();
/// let plane = Plane::from_polygon(&light).unwrap();
/// let half = quad(-2.0, 0.0, -2.0, 2.0, 0.5);
/// let (p, n, white) = (DVec3::ZERO, DVec3::Z, DVec3::ONE);
/// let lit = area_light(p, n, &light, &plane, white, Lit, &[], Exact, 0);
/// let pen = area_light(p, n, &light, &plane, white, Penumbra, &[&half], Exact, 0);
/// assert!((pen.x - 0.5 * lit.x).abs() < 1e-12);
/// ```
#[allow(clippy::too_many_arguments)]
pub fn area_light(
    p: DVec3,
    n: DVec3,
    light_verts: &[DVec3],
    light_plane: &Plane,
    radiance: DVec3,
    relation: Relation,
    blockers: &[&[DVec3]],
    mode: PenumbraVisibility,
    samples: u32,
) -> DVec3 {
    if relation == Relation::Umbra || light_verts.len() < 3 {
        return DVec3::ZERO;
    }
    // Origin at the light: its small coordinates then keep their digits however far the
    // scene is from the world origin (the Lambert sum needs the light's shape, not p's).
    let c = light_verts.iter().copied().sum::<DVec3>() / light_verts.len() as f64;
    let q = p - c;
    let ln = light_plane.n;
    if ln.dot(q) <= 0.0 {
        return DVec3::ZERO;
    }
    let light: Vec<DVec3> = light_verts.iter().map(|v| *v - c).collect();
    let unoccluded = polygon_irradiance(q, n, &light);
    if unoccluded == 0.0 || relation == Relation::Lit || blockers.is_empty() {
        return radiance * unoccluded;
    }
    let blockers: Vec<Vec<DVec3>> = blockers
        .iter()
        .map(|b| b.iter().map(|v| *v - c).collect())
        .collect();
    let view = View {
        q,
        n,
        light: &light,
        ln,
    };
    let e = match mode {
        PenumbraVisibility::Exact => view.exact_visible(&blockers, unoccluded),
        PenumbraVisibility::Sampled => unoccluded * view.visible_fraction(&blockers, samples),
    };
    radiance * e
}

/// A receiver point `q` with unit normal `n` and a light polygon with front normal `ln`, in
/// coordinates relative to the light's centroid.
struct View<'a> {
    q: DVec3,
    n: DVec3,
    light: &'a [DVec3],
    ln: DVec3,
}

impl View<'_> {
    /// Irradiance per unit radiance from the visible part of the light.
    fn exact_visible(&self, blockers: &[Vec<DVec3>], unoccluded: f64) -> f64 {
        let View { q, n, light, .. } = *self;
        let reach = light.iter().map(|l| (*l - q).length()).fold(0.0, f64::max);
        let mut hidden: Vec<Vec<DVec3>> = Vec::with_capacity(blockers.len());
        for o in blockers {
            if let Some(h) = self.hidden_part(o, reach) {
                // No clipping plane cut the light: all of it is hidden.
                if h.as_slice() == light {
                    return 0.0;
                }
                hidden.push(h);
            }
        }
        if hidden.len() > 1 {
            hidden = self.drop_nested(hidden);
        }
        match hidden.len() {
            0 => unoccluded,
            // One hidden part lies inside the light, so the visible integral is a difference.
            1 => (unoccluded - polygon_irradiance(q, n, &hidden[0])).clamp(0.0, unoccluded),
            _ => self.light_minus_union(&hidden).min(unoccluded),
        }
    }

    /// The hidden parts without those inside another one (exact test in the light's plane):
    /// the union is the same, and among many small occluders behind a large one (clutter
    /// seen through a table) most parts are nested.
    fn drop_nested(&self, hidden: Vec<Vec<DVec3>>) -> Vec<Vec<DVec3>> {
        let frame = Frame::new(DVec3::ZERO, self.ln);
        let flat: Vec<Vec<DVec2>> = hidden
            .iter()
            .map(|h| {
                let mut c: Vec<DVec2> = h.iter().map(|v| frame.to_2d(*v)).collect();
                if signed_area_2d(&c) < 0.0 {
                    c.reverse();
                }
                c
            })
            .collect();
        let area: Vec<f64> = flat.iter().map(|c| signed_area_2d(c)).collect();
        let mut order: Vec<usize> = (0..flat.len()).collect();
        order.sort_by(|&a, &b| area[b].total_cmp(&area[a]).then(a.cmp(&b)));
        let boxes: Vec<(DVec2, DVec2)> = flat.iter().map(|c| bounds(c)).collect();
        let mut kept: Vec<usize> = Vec::with_capacity(flat.len());
        for &i in &order {
            let (lo, hi) = boxes[i];
            let nested = kept.iter().any(|&j| {
                let (jlo, jhi) = boxes[j];
                jlo.x <= lo.x
                    && jlo.y <= lo.y
                    && jhi.x >= hi.x
                    && jhi.y >= hi.y
                    && flat[i].iter().all(|&v| inside_convex(&flat[j], v))
            });
            if !nested {
                kept.push(i);
            }
        }
        kept.sort_unstable();
        let mut hidden: Vec<Option<Vec<DVec3>>> = hidden.into_iter().map(Some).collect();
        kept.iter().filter_map(|&i| hidden[i].take()).collect()
    }

    /// Irradiance per unit radiance from the light minus the union of several hidden parts:
    /// the light is cut into disjoint convex pieces by subtracting the parts one by one,
    /// largest first, in the light's plane. Seen from deep among clutter the large parts
    /// leave a few small pieces that most other parts miss, so this takes a fraction of a
    /// general polygon boolean; when the pieces multiply instead, the boolean takes over.
    fn light_minus_union(&self, hidden: &[Vec<DVec3>]) -> f64 {
        let frame = Frame::new(DVec3::ZERO, self.ln);
        let flat = |c: &[DVec3]| -> Vec<DVec2> {
            let mut f: Vec<DVec2> = c.iter().map(|v| frame.to_2d(*v)).collect();
            if signed_area_2d(&f) < 0.0 {
                f.reverse();
            }
            f
        };
        let light = flat(self.light);
        // Slivers this thin change the integral by less than its rounding.
        let min_area = 1e-15 * signed_area_2d(&light);
        let mut parts: Vec<(f64, Vec<DVec2>)> = hidden
            .iter()
            .map(|h| {
                let f = flat(h);
                (signed_area_2d(&f), f)
            })
            .filter(|(a, _)| *a > min_area)
            .collect();
        parts.sort_by(|a, b| b.0.total_cmp(&a.0));
        let limit = 8 * hidden.len() + 32;
        let mut pieces = vec![light];
        let mut next = Vec::new();
        for (_, h) in &parts {
            next.clear();
            for p in pieces.drain(..) {
                subtract_convex(p, h, min_area, &mut next);
            }
            std::mem::swap(&mut pieces, &mut next);
            if pieces.is_empty() {
                return 0.0;
            }
            if pieces.len() > limit {
                return self.boolean_minus_union(hidden);
            }
        }
        let lift = |c: &Vec<DVec2>| c.iter().map(|x| frame.to_3d(*x)).collect();
        let contours: Vec<Vec<DVec3>> = pieces.iter().map(lift).collect();
        contours_irradiance(self.q, self.n, &contours)
    }

    /// The same by a general polygon boolean in the light's plane.
    fn boolean_minus_union(&self, hidden: &[Vec<DVec3>]) -> f64 {
        let frame = Frame::new(DVec3::ZERO, self.ln);
        let to2 = |v: &DVec3| frame.to_2d(*v).to_array();
        let subj: Vec<[f64; 2]> = self.light.iter().map(to2).collect();
        let clip: Vec<Vec<[f64; 2]>> = hidden
            .iter()
            .filter_map(|h| {
                let mut c: Vec<[f64; 2]> = h.iter().map(to2).collect();
                let a = signed_area_2d(&c.iter().map(|x| DVec2::from(*x)).collect::<Vec<_>>());
                // Under the non-zero rule a clockwise part would cancel a counter-clockwise
                // one where they overlap instead of adding to the union.
                if a < 0.0 {
                    c.reverse();
                }
                (a.abs() > 0.0).then_some(c)
            })
            .collect();
        // The i64 grid resolves 2^-60 of the light's extent, far below the f64 rounding of
        // the integral, so the boolean adds no visible error.
        let shapes = FloatOverlay::<[f64; 2], i64>::from_subj_and_clip(&subj, &clip)
            .overlay(OverlayRule::Difference, FillRule::NonZero);
        let lift = |c: &Vec<[f64; 2]>| c.iter().map(|x| frame.to_3d(DVec2::from(*x))).collect();
        let contours: Vec<Vec<DVec3>> = shapes.iter().flatten().map(lift).collect();
        contours_irradiance(self.q, self.n, &contours)
    }

    /// The part of the light that convex occluder `o` hides from `q`, or `None` when nothing with
    /// area is hidden. `reach` is the largest distance from `q` to the light.
    fn hidden_part(&self, o: &[DVec3], reach: f64) -> Option<Vec<DVec3>> {
        let (q, light) = (self.q, self.light);
        if o.len() < 3 {
            return None;
        }
        let no = newell_normal(o).normalize_or_zero();
        if no == DVec3::ZERO {
            return None;
        }
        let co = o.iter().copied().sum::<DVec3>() / o.len() as f64;
        let h = no.dot(q - co);
        let size = o.iter().map(|v| (*v - q).length()).fold(0.0, f64::max);
        if !(h.abs() > TOUCH * size) {
            return None;
        }
        let s = h.signum();
        let mut part = light.to_vec();
        // O's plane first: it discards the whole light in the common case of an occluder that is
        // not between the point and the light.
        let far = -s * no;
        part = clip_polygon_3d(&part, &Plane::new(far, far.dot(co) + TOUCH * reach), 0.0);
        for i in 0..o.len() {
            if part.len() < 3 {
                return None;
            }
            let (a, b) = (o[i] - q, o[(i + 1) % o.len()] - q);
            // With O counter-clockwise about `no`, its inside is where (a × b)·(x − q) has
            // the sign of −h; the sign of h turns this around for an occluder facing away.
            let m = (-s * a.cross(b)).normalize_or_zero();
            if m == DVec3::ZERO {
                return None;
            }
            part = clip_polygon_3d(&part, &Plane::new(m, m.dot(q)), 0.0);
        }
        (part.len() >= 3).then_some(part)
    }

    /// Integrand-weighted visible fraction of the light from `samples` stratified points
    /// (a Hammersley set, a (0, m, 2)-net when `samples` is a power of two), spread over the
    /// light by an area-preserving map so the strata keep equal areas.
    fn visible_fraction(&self, blockers: &[Vec<DVec3>], samples: u32) -> f64 {
        let View { q, n, light, ln } = *self;
        let fan: Vec<[DVec3; 3]> = (1..light.len() - 1)
            .map(|i| [light[0], light[i], light[i + 1]])
            .collect();
        let areas: Vec<f64> = fan
            .iter()
            .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
            .collect();
        let total: f64 = areas.iter().sum();
        if !(total > 0.0) {
            return 1.0;
        }
        let samples = samples.max(1);
        let (mut seen, mut all) = (0.0, 0.0);
        for k in 0..samples {
            let mut t = (k as f64 + 0.5) / samples as f64 * total;
            let mut i = 0;
            while i + 1 < fan.len() && t >= areas[i] {
                t -= areas[i];
                i += 1;
            }
            let u = (t / areas[i]).clamp(0.0, 1.0);
            let v = radical_inverse(k);
            let [a, b, c] = fan[i];
            let su = u.sqrt();
            let l = a * (1.0 - su) + b * (su * (1.0 - v)) + c * (su * v);
            let d = l - q;
            let r2 = d.length_squared();
            let w = n.dot(d).max(0.0) * (-ln.dot(d)).max(0.0) / (r2 * r2);
            if !(w > 0.0) || !w.is_finite() {
                continue;
            }
            all += w;
            if !blockers.iter().any(|o| segment_blocked(q, l, o)) {
                seen += w;
            }
        }
        if all > 0.0 {
            seen / all
        } else {
            0.0
        }
    }
}

/// Van der Corput radical inverse in base 2.
fn radical_inverse(k: u32) -> f64 {
    k.reverse_bits() as f64 * (1.0 / 4_294_967_296.0)
}

/// Does convex polygon `o` block the segment from `a` to `b`? The ends are pulled in by
/// [`TOUCH`] of the length (contact is not blocking); the test on the pulled-in segment is
/// exact: per fan triangle, the ends lie strictly on opposite sides of its plane and the
/// segment's line passes inside or on all three of its edges.
pub fn segment_blocked(a: DVec3, b: DVec3, o: &[DVec3]) -> bool {
    if o.len() < 3 {
        return false;
    }
    // Coordinates relative to `a` keep the pulled-in ends accurate far from the world origin.
    let d = b - a;
    let (a3, b3) = (c3(d * TOUCH), c3(d - d * TOUCH));
    let o0 = c3(o[0] - a);
    (1..o.len() - 1).any(|i| {
        let (t1, t2) = (c3(o[i] - a), c3(o[i + 1] - a));
        let (sa, sb) = (orient3d(o0, t1, t2, a3), orient3d(o0, t1, t2, b3));
        if !((sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0)) {
            return false;
        }
        let side = |u, v| orient3d(a3, b3, u, v);
        let e = [side(o0, t1), side(t1, t2), side(t2, o0)];
        e.iter().all(|&x| x >= 0.0) || e.iter().all(|&x| x <= 0.0)
    })
}

#[inline]
fn c3(v: DVec3) -> Coord3D<f64> {
    let [x, y, z] = v.to_array();
    Coord3D { x, y, z }
}

/// Direct irradiance at `p` (unit normal `n`) from an isotropic point light of `intensity`
/// (W/sr per channel) at `position`, optionally masked by a spot cone: `I·cos θ / r²`,
/// 0 behind the receiver. In penumbra (or unprocessed) regions one exact segment test
/// against `blockers` decides visibility; lit regions are not tested.
pub fn point_light(
    p: DVec3,
    n: DVec3,
    position: DVec3,
    intensity: DVec3,
    spot: Option<&Spot>,
    relation: Relation,
    blockers: &[&[DVec3]],
) -> DVec3 {
    if relation == Relation::Umbra {
        return DVec3::ZERO;
    }
    let d = position - p;
    let r2 = d.length_squared();
    let cos = n.dot(d) / r2.sqrt();
    if !(cos > 0.0) || !(r2 > 0.0) {
        return DVec3::ZERO;
    }
    let mask = spot.map_or(1.0, |s| spot_mask(s, -d));
    if mask == 0.0
        || (needs_test(relation) && blockers.iter().any(|o| segment_blocked(p, position, o)))
    {
        return DVec3::ZERO;
    }
    intensity * (mask * cos / r2)
}

/// Blender Cycles' spot cone mask for light travelling along `to_point` (from the light to
/// the receiver, any length), as Cycles 4.x/5.x computes it: `spot_light_attenuation` in
/// `intern/cycles/kernel/light/spot.h` is `smoothstepf((x − cos_half_spot_angle) ·
/// spot_smooth)`, with `spot_smooth = 1 / ((1 − cos_half_spot_angle) · blend)` set in
/// `intern/cycles/scene/light.cpp` (`device_update_lights`), `smoothstepf` clamped to [0, 1]
/// in `intern/cycles/util/math_float.h`, and `blend = spot_blend`, angle `= spot_size` (full
/// cone) from `intern/cycles/blender/light.cpp`. That is:
///
/// ```text
/// x = cos(angle between to_point and the spot axis)
/// f = (x − cos_half_angle) / ((1 − cos_half_angle) · blend)
/// mask = smoothstep(f) = 0 if f ≤ 0, 1 if f ≥ 1, else 3f² − 2f³
/// ```
///
/// i.e. a smoothstep in the cosine, not in the angle; the blend band is the top `blend`
/// fraction of `[cos_half_angle, 1]`. The spot's object scale is taken as 1 (Cycles scales
/// the local ray by the light's non-uniform scale first). With `blend = 0` the edge is hard.
pub fn spot_mask(spot: &Spot, to_point: DVec3) -> f64 {
    let x = to_point.normalize_or_zero().dot(spot.direction);
    let width = (1.0 - spot.cos_half_angle) * spot.blend;
    if !(width > 0.0) {
        return if x > spot.cos_half_angle { 1.0 } else { 0.0 };
    }
    let f = (x - spot.cos_half_angle) / width;
    if f <= 0.0 {
        0.0
    } else if f >= 1.0 {
        1.0
    } else {
        f * f * (3.0 - 2.0 * f)
    }
}

/// Direct irradiance at `p` (unit normal `n`) from a sun whose light travels along unit
/// `direction`, giving `irradiance` (W/m² per channel) on a surface facing it. Visibility in
/// penumbra (or unprocessed) regions: one exact test of the ray from `p` toward the sun.
pub fn sun_light(
    p: DVec3,
    n: DVec3,
    direction: DVec3,
    irradiance: DVec3,
    relation: Relation,
    blockers: &[&[DVec3]],
) -> DVec3 {
    if relation == Relation::Umbra {
        return DVec3::ZERO;
    }
    let w = -direction.normalize_or_zero();
    let cos = n.dot(w);
    if !(cos > 0.0) {
        return DVec3::ZERO;
    }
    if needs_test(relation) {
        // A ray that meets a convex polygon does so within the polygon's farthest vertex
        // distance, so a segment twice that long stands in for the ray exactly.
        let verts = blockers.iter().flat_map(|o| o.iter());
        let far = p + w * (2.0 * verts.map(|v| (*v - p).length()).fold(0.0, f64::max));
        if blockers.iter().any(|o| segment_blocked(p, far, o)) {
            return DVec3::ZERO;
        }
    }
    irradiance * cos
}

#[inline]
fn needs_test(r: Relation) -> bool {
    matches!(r, Relation::Penumbra | Relation::Unprocessed)
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::geom::lambert::test::{parallel_rect, quadrature};
    use PenumbraVisibility as Vis;
    use PenumbraVisibility::{Exact, Sampled};
    use Relation::{Lit, Penumbra, Umbra, Unprocessed};

    type Rect = [f64; 4];
    const LIGHT: Rect = [-0.5, 0.5, -0.5, 0.5];
    const OCC: Rect = [-0.4, 0.4, -0.4, 0.4];
    const OCC2: Rect = [0.0, 0.6, -0.3, 0.3];
    const Z: DVec3 = DVec3::Z;

    /// [x0,x1]×[y0,y1] at height z, counter-clockwise about +z, or about −z when `down`.
    fn rect(r: Rect, z: f64, down: bool) -> Vec<DVec3> {
        let corners = [(r[0], r[2]), (r[1], r[2]), (r[1], r[3]), (r[0], r[3])];
        let mut v: Vec<DVec3> = corners.iter().map(|&(x, y)| DVec3::new(x, y, z)).collect();
        if down {
            v.reverse();
        }
        v
    }

    type Blockers<'a> = &'a [&'a [DVec3]];

    /// Irradiance per unit radiance from light `l` (its plane from its winding).
    fn eval_with(l: &[DVec3], p: DVec3, n: DVec3, r: Relation, b: Blockers, m: Vis, s: u32) -> f64 {
        let plane = Plane::from_polygon(l).unwrap();
        area_light(p, n, l, &plane, DVec3::ONE, r, b, m, s).x
    }

    /// The same from the scene's light: side 1 at height 2, facing down.
    fn eval(p: DVec3, n: DVec3, r: Relation, b: Blockers, m: Vis, s: u32) -> f64 {
        eval_with(&rect(LIGHT, 2.0, true), p, n, r, b, m, s)
    }

    /// Closed form: irradiance per unit radiance at p (facing +z) from `r` at height 2.
    fn e_rect(p: DVec3, r: Rect) -> f64 {
        if r[0] >= r[1] || r[2] >= r[3] {
            return 0.0;
        }
        parallel_rect(r[0] - p.x, r[1] - p.x, r[2] - p.y, r[3] - p.y, 2.0 - p.z)
    }

    /// The part of the light hidden from floor point p by an axis-aligned occluder at height
    /// z: its shadow on the light's plane by similar triangles, cut to the light.
    fn hidden(p: DVec3, o: Rect, z: f64) -> Rect {
        let f = |i: usize, px: f64| px + 2.0 / z * (o[i] - px);
        isect([f(0, p.x), f(1, p.x), f(2, p.y), f(3, p.y)], LIGHT)
    }

    fn isect(a: Rect, b: Rect) -> Rect {
        let (lo, hi) = (|i: usize| a[i].max(b[i]), |i: usize| a[i].min(b[i]));
        [lo(0), hi(1), lo(2), hi(3)]
    }

    /// [y0,y1]×[z0,z1] in the plane x = const.
    fn wall(r: Rect, x: f64) -> Vec<DVec3> {
        let yz = rect(r, x, false);
        yz.iter().map(|v| DVec3::new(v.z, v.x, v.y)).collect()
    }

    fn rel_err(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn square_over_floor_matches_similar_triangles() {
        let l = rect(LIGHT, 2.0, true);
        let plane = Plane::from_polygon(&l).unwrap();
        assert!((plane.n + Z).length() < 1e-15, "the light faces down");
        let rad = DVec3::new(1.0, 2.0, 0.5);
        for (x, y) in [(0.5, 0.0), (0.7, 0.45), (1.0, -0.9), (-0.35, 0.1)] {
            let p = DVec3::new(x, y, 0.0);
            let h = hidden(p, OCC, 1.0);
            let want = e_rect(p, LIGHT) - e_rect(p, h);
            assert!(want > 0.0 && e_rect(p, h) > 0.0, "{p} is not in penumbra");
            for down in [false, true] {
                let o = rect(OCC, 1.0, down);
                let e = area_light(p, Z, &l, &plane, rad, Penumbra, &[&o], Exact, 0);
                let err = (e / rad - DVec3::splat(want)).abs().max_element() / want;
                assert!(err < 1e-9, "{p}: {e} vs {want}");
            }
        }
    }

    #[test]
    fn two_overlapping_blockers_by_inclusion_exclusion() {
        let (o1, o2) = (rect(OCC, 1.0, false), rect(OCC2, 1.5, true));
        for p in [DVec3::new(0.6, 0.2, 0.0), DVec3::new(0.9, -0.3, 0.0)] {
            let (h1, h2) = (hidden(p, OCC, 1.0), hidden(p, OCC2, 1.5));
            let both = isect(h1, h2);
            assert!(e_rect(p, both) > 0.0, "no overlap at {p}");
            let want = e_rect(p, LIGHT) - e_rect(p, h1) - e_rect(p, h2) + e_rect(p, both);
            let e = eval(p, Z, Penumbra, &[&o1, &o2], Exact, 0);
            assert!(rel_err(e, want) < 1e-9, "{p}: {e} vs {want}");
            assert_eq!(eval(p, Z, Unprocessed, &[&o1, &o2], Exact, 0), e);
        }
    }

    #[test]
    fn umbra_lit_and_back_side() {
        let o = rect(OCC, 1.0, false);
        // Under the occluder's middle the whole light is hidden even when asked for penumbra.
        let p = DVec3::new(0.1, -0.2, 0.0);
        assert!(eval(p, Z, Penumbra, &[&o], Exact, 0) <= 1e-12 * e_rect(p, LIGHT));
        assert_eq!(eval(p, Z, Umbra, &[&o], Exact, 0), 0.0);
        // Far out the occluder hides nothing; lit regions skip it altogether.
        let p = DVec3::new(2.0, 0.3, 0.0);
        assert!(rel_err(eval(p, Z, Lit, &[&o], Exact, 0), e_rect(p, LIGHT)) < 1e-12);
        assert!(rel_err(eval(p, Z, Penumbra, &[&o], Exact, 0), e_rect(p, LIGHT)) < 1e-12);
        // Behind the light or on its plane: nothing, whatever the receiver faces.
        assert_eq!(eval(DVec3::new(0.0, 0.0, 3.0), -Z, Lit, &[], Exact, 0), 0.0);
        let on_plane = DVec3::new(3.0, 0.0, 2.0);
        assert_eq!(eval(on_plane, -DVec3::X, Lit, &[], Exact, 0), 0.0);
    }

    #[test]
    fn contact_coplanar_and_crossing_occluders() {
        let p = DVec3::new(0.5, 0.0, 0.0);
        let full = e_rect(p, LIGHT);
        let floor = rect([-5.0, 5.0, -5.0, 5.0], 0.0, false);
        let ceiling = rect([-5.0, 5.0, -5.0, 5.0], 2.0, true);
        let wall_through_p = wall([-1.0, 1.0, 0.0, 1.9], 0.5);
        let collinear = [0.0, 0.1, 0.2].map(|x| DVec3::new(x, 0.0, 1.0)).to_vec();
        let all = [&floor, &ceiling, &wall_through_p, &collinear];
        for mode in [Exact, Sampled] {
            for b in all {
                let e = eval(p, Z, Penumbra, &[b], mode, 256);
                assert!(rel_err(e, full) < 1e-12, "{mode:?} {b:?}: {e} vs {full}");
            }
            let e = eval(p, Z, Penumbra, &all.map(|b| b.as_slice()), mode, 256);
            assert!(rel_err(e, full) < 1e-12, "{mode:?} all: {e}");
        }
        // A wall in x = 0 crossing the light: from p it hides exactly the strip x ∈ [−1/6, 0)
        // of the light (segments reach x = 0 at height ≥ 1.5 only from there). TOUCH moves
        // that edge by 1e-10 relative.
        let wall = wall([-1.0, 1.0, 1.5, 2.5], 0.0);
        let want = e_rect(p, [-0.5, -1.0 / 6.0, -0.5, 0.5]) + e_rect(p, [0.0, 0.5, -0.5, 0.5]);
        let e = eval(p, Z, Penumbra, &[&wall], Exact, 0);
        assert!(rel_err(e, want) < 1e-9, "{e} vs {want}");
        let b = [wall.as_slice(), &rect(OCC, 1.0, false), &ceiling];
        let e = eval(p, Z, Penumbra, &b, Exact, 0);
        assert!(e.is_finite() && e >= 0.0 && e < want);
    }

    #[test]
    fn sampled_converges_to_exact() {
        let (o1, o2) = (rect(OCC, 1.0, false), rect(OCC2, 1.5, true));
        let tilted = DVec3::new(0.3, -0.2, 1.0).normalize();
        let cases: [(DVec3, DVec3, &[&[DVec3]]); 2] = [
            (DVec3::new(0.7, 0.45, 0.0), Z, &[&o1]),
            (DVec3::new(0.6, 0.2, 0.0), tilted, &[&o1, &o2]),
        ];
        for (p, n, b) in cases {
            let exact = eval(p, n, Penumbra, b, Exact, 0);
            let errs = [16, 256, 4096].map(|s| rel_err(eval(p, n, Penumbra, b, Sampled, s), exact));
            // Measured: 3.3e-2, 3.5e-3, 1.6e-3 and 3.1e-2, 3.1e-2, 6.7e-3.
            assert!(errs[2] < 1e-2 && errs[2] < errs[0], "{p}: errors {errs:?}");
        }
    }

    /// Seeded random configurations: tilted triangles and quads anywhere between the floor and
    /// above the light, crossing it or each other. Exact must stay within the sampled
    /// estimate's noise, and neither may leave [0, unoccluded] or turn NaN.
    #[test]
    fn random_occluders_agree_with_sampling() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = |lo: f64, hi: f64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            lo + (hi - lo) * (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..40 {
            let p = DVec3::new(rnd(-1.5, 1.5), rnd(-1.5, 1.5), 0.0);
            let n = DVec3::new(rnd(-0.5, 0.5), rnd(-0.5, 0.5), 1.0).normalize();
            let occ: Vec<Vec<DVec3>> = (0..3)
                .map(|_| {
                    let c = DVec3::new(rnd(-1.0, 1.0), rnd(-1.0, 1.0), rnd(0.2, 2.3));
                    let (u, v) = (
                        DVec3::new(rnd(-0.6, 0.6), rnd(-0.6, 0.6), rnd(-0.6, 0.6)),
                        DVec3::new(rnd(-0.6, 0.6), rnd(-0.6, 0.6), rnd(-0.6, 0.6)),
                    );
                    let quad = [c - u - v, c + u - v, c + u + v, c - u + v];
                    quad[..if rnd(0.0, 1.0) < 0.5 { 3 } else { 4 }].to_vec()
                })
                .collect();
            let b: Vec<&[DVec3]> = occ.iter().map(|o| o.as_slice()).collect();
            let full = eval(p, n, Lit, &[], Exact, 0);
            let exact = eval(p, n, Penumbra, &b, Exact, 0);
            let sampled = eval(p, n, Penumbra, &b, Sampled, 4096);
            assert!(exact >= 0.0 && exact <= full && sampled >= 0.0 && sampled <= full);
            assert!(
                (exact - sampled).abs() < 5e-3 * full,
                "{p} {n}: {exact} vs {sampled} of {full}"
            );
        }
    }

    #[test]
    fn scale_and_translation_invariance() {
        let p = DVec3::new(0.6, 0.2, 0.0);
        let tilted = DVec3::new(0.3, -0.2, 1.0).normalize();
        let scene = [(LIGHT, 2.0, true), (OCC, 1.0, false), (OCC2, 1.5, true)];
        let run = |s: f64, t: DVec3, k: usize| {
            let place = |(r, z, down): (Rect, f64, bool)| {
                rect(r, z, down)
                    .iter()
                    .map(|v| *v * s + t)
                    .collect::<Vec<_>>()
            };
            let [l, o1, o2] = scene.map(place);
            let b = [o1.as_slice(), &o2];
            eval_with(&l, p * s + t, tilted, Penumbra, &b[..k], Exact, 0)
        };
        // Far from the world origin (1e3 times the scene's size) only the position's own
        // rounding (1e-16 of it) is lost, as the work is done relative to the light.
        let far = DVec3::new(1e3, -2e3, 5e2);
        for k in [1, 2] {
            let e1 = run(1.0, DVec3::ZERO, k);
            for s in [1e-3, 1e4] {
                assert!(rel_err(run(s, DVec3::ZERO, k), e1) < 1e-9, "scale {s}, {k}");
                assert!(
                    rel_err(run(s, far * s, k), e1) < 1e-9,
                    "moved, scale {s}, {k}"
                );
            }
        }
    }

    #[test]
    fn tiny_light_behind_a_large_occluder() {
        // Light 1e-3 wide, occluder 1 wide: the penumbra on the floor is 1e-3 wide too. From
        // p the occluder's edge cuts the light at x = −2e-4 (similar triangles).
        let s = 1e-3;
        let l = rect([-s / 2.0, s / 2.0, -s / 2.0, s / 2.0], 2.0, true);
        let p = DVec3::new(1.0002, 0.0, 0.0);
        let e = eval_with(&l, p, Z, Penumbra, &[&rect(LIGHT, 1.0, false)], Exact, 0);
        let visible = DVec3::new(-2e-4, -s / 2.0, 2.0);
        let want = quadrature(p, Z, visible, DVec3::X * 7e-4, DVec3::Y * s, 1);
        assert!(rel_err(e, want) < 1e-9, "{e} vs {want}");
    }

    #[test]
    fn point_light_inverse_square_cosine_and_shadow() {
        let pos = DVec3::new(1.0, 0.0, 2.0);
        let i = DVec3::new(10.0, 5.0, 1.0);
        let at =
            |pos: DVec3, r: Relation, b: Blockers| point_light(DVec3::ZERO, Z, pos, i, None, r, b);
        let e = at(pos, Lit, &[]);
        assert!((e - i * (2.0 / 5f64.sqrt() / 5.0)).length() < 1e-14);
        assert_eq!(at(DVec3::new(1.0, 0.0, -2.0), Lit, &[]), DVec3::ZERO);
        let o = rect([-1.0, 2.0, -1.0, 1.0], 1.0, false);
        assert_eq!(at(pos, Penumbra, &[&o]), DVec3::ZERO);
        assert_eq!(at(pos, Umbra, &[]), DVec3::ZERO);
        // Lit means no test, and a bulb on the ceiling is not shadowed by the ceiling.
        assert_eq!(at(pos, Lit, &[&o]), e);
        let ceiling = rect([-5.0, 5.0, -5.0, 5.0], 2.0, true);
        assert_eq!(at(pos, Penumbra, &[&ceiling]), e);
    }

    #[test]
    fn spot_cone_and_blend_as_cycles() {
        let cos_half = 30f64.to_radians().cos();
        let spot = Spot {
            direction: -Z,
            cos_half_angle: cos_half,
            blend: 0.5,
        };
        let pos = DVec3::new(0.0, 0.0, 2.0);
        let at = |x: f64| point_light(x * DVec3::X, Z, pos, DVec3::ONE, Some(&spot), Lit, &[]).x;
        assert!((at(0.0) - 0.25).abs() < 1e-15, "on axis: full");
        assert_eq!(at(2.0), 0.0, "45° is outside a 30° half angle");
        // Just inside the cone edge the mask is small but not zero: smoothstep of f ≈ 0.013.
        let edge = at(2.0 * 29.9f64.to_radians().tan());
        assert!(edge > 0.0 && edge < 1e-3 * 0.25, "{edge}");
        // In the blend band: the cosine a quarter of the way in gives smoothstep(¼) = 5/32.
        let width = (1.0 - cos_half) * 0.5;
        for (f, mask) in [(0.25, 5.0 / 32.0), (0.5, 0.5), (1.0, 1.0), (-0.1, 0.0)] {
            let x = (cos_half + f * width).min(1.0);
            let px = 2.0 * (1.0 - x * x).sqrt() / x;
            let r2 = px * px + 4.0;
            let want = mask * (2.0 / r2.sqrt()) / r2;
            assert!((at(px) - want).abs() < 1e-12, "f = {f}");
        }
        let hard = Spot { blend: 0.0, ..spot };
        assert_eq!(spot_mask(&hard, DVec3::new(0.1, 0.0, -1.0)), 1.0);
        assert_eq!(spot_mask(&hard, DVec3::new(1.0, 0.0, -1.0)), 0.0);
    }

    #[test]
    fn sun_cosine_and_ray_shadow() {
        let dir = DVec3::new(0.0, -1.0, -1.0).normalize();
        let at = |d: DVec3, r: Relation, b: Blockers| {
            sun_light(DVec3::ZERO, Z, d, 3.0 * DVec3::ONE, r, b).x
        };
        let e = at(dir, Lit, &[]);
        assert!((e - 3.0 / 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(at(-dir, Lit, &[]), 0.0);
        // An occluder up the ray (toward +y, +z) shadows; one below the receiver does not.
        let up = rect([-0.5, 0.5, 0.5, 1.5], 1.0, false);
        let down = rect([-0.5, 0.5, -1.5, -0.5], -1.0, false);
        assert_eq!(at(dir, Penumbra, &[&up]), 0.0);
        assert_eq!(at(dir, Lit, &[&up]), e);
        assert_eq!(at(dir, Penumbra, &[&down]), e);
    }

    #[test]
    fn segment_test_is_exact_on_fan_diagonals_and_contact() {
        let sq = rect([-1.0, 1.0, -1.0, 1.0], 1.0, false);
        let hits = |a: DVec3, b: DVec3| segment_blocked(a, b, &sq);
        // Through the fan's diagonal (o0–o2), exactly: blocked.
        assert!(hits(DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0)));
        assert!(hits(DVec3::new(-0.5, -0.5, 0.0), DVec3::new(0.5, 0.5, 2.0)));
        // Ending on the polygon or passing beside it: not blocked.
        assert!(!hits(DVec3::ZERO, DVec3::new(0.0, 0.0, 1.0)));
        assert!(!hits(DVec3::ZERO, DVec3::new(3.0, 0.0, 2.0)));
    }
}

//! The exact direct light: irradiance (W/m², per RGB channel) at a receiver point, per light, driven
//! by the region's relation to that light (paper 2.6): umbra costs nothing, lit is one exact
//! Lambert integral, and only penumbra (or an unprocessed region) looks at the occluders.
//!
//! Penumbra, exact: the visible part of an area light is the light polygon minus the parts
//! of it hidden by each occluder. The part hidden by a convex occluder `O` is the set of light
//! points `l` for which the segment `[p, l]` meets `O`: the light clipped by the planes through
//! `p` and each edge of `O` (keeping `O`'s side) and by `O`'s plane (keeping the far side).
//! Clipping by planes through `p` never projects anything to infinity, so occluders beside,
//! behind or crossing the light need no special case. Hidden parts may overlap, so their
//! union is cut into disjoint convex pieces in the light's plane (each part minus the parts
//! before it), and the visible light is the unoccluded integral minus the pieces'; where
//! the pieces multiply, a general polygon boolean (`i_overlay`) takes over.
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
use crate::geom::polygon::{clip_polygon_3d_into, signed_area_2d, subtract_convex};
use crate::geom::{Frame, Plane};
use crate::regions::relation::Relation;
use crate::scene::settings::PenumbraVisibility;
use crate::scene::Spot;

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
/// use penumbra::direct::exact::area_light;
/// use penumbra::geom::Plane;
/// use penumbra::regions::relation::Relation::{Lit, Penumbra};
/// use penumbra::scene::settings::PenumbraVisibility::Exact;
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
    let view = View {
        q,
        n,
        light: &light,
        ln,
    };
    let e = match mode {
        PenumbraVisibility::Exact => view.exact_visible(blockers, c, unoccluded),
        PenumbraVisibility::Sampled => {
            let blockers: Vec<Vec<DVec3>> = blockers
                .iter()
                .map(|b| b.iter().map(|v| *v - c).collect())
                .collect();
            unoccluded * view.visible_fraction(&blockers, samples)
        }
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

/// Buffers reused from one point to the next on each thread: the direct stage computes
/// the visible light at hundreds of thousands of points, each under a dozen occluders, and
/// allocating for every occluder and part cost a fifth of its time.
#[derive(Default)]
struct Scratch {
    occluder: Vec<DVec3>,
    a: Vec<DVec3>,
    b: Vec<DVec3>,
    /// The hidden parts one after another: part k ends at `ends[k]`.
    parts: Vec<DVec3>,
    ends: Vec<usize>,
    /// The light, then the parts, in the light's plane.
    flat: Vec<DVec2>,
    meta: Vec<Part>,
    lifted: Vec<DVec3>,
}

impl Scratch {
    fn start(&self, k: usize) -> usize {
        if k == 0 {
            0
        } else {
            self.ends[k - 1]
        }
    }
}

/// A hidden part with area, in the light's plane: `flat` indexes `Scratch::flat`.
struct Part {
    area: f64,
    index: usize,
    flat: std::ops::Range<usize>,
    lo: DVec2,
    hi: DVec2,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

impl View<'_> {
    /// Irradiance per unit radiance from the visible part of the light; `blockers` are in
    /// world coordinates, `c` is the light's centroid (the origin of `self`).
    fn exact_visible(&self, blockers: &[&[DVec3]], c: DVec3, unoccluded: f64) -> f64 {
        SCRATCH.with_borrow_mut(|s| self.exact_visible_in(s, blockers, c, unoccluded))
    }

    fn exact_visible_in(
        &self,
        s: &mut Scratch,
        blockers: &[&[DVec3]],
        c: DVec3,
        unoccluded: f64,
    ) -> f64 {
        let View { q, n, light, .. } = *self;
        let reach = light.iter().map(|l| (*l - q).length()).fold(0.0, f64::max);
        s.parts.clear();
        s.ends.clear();
        for o in blockers {
            s.occluder.clear();
            s.occluder.extend(o.iter().map(|v| *v - c));
            if self.hidden_part(&s.occluder, &mut s.a, &mut s.b, reach) {
                // No clipping plane cut the light: all of it is hidden.
                if s.a.as_slice() == light {
                    return 0.0;
                }
                s.parts.extend_from_slice(&s.a);
                s.ends.push(s.parts.len());
            }
        }
        let covered = match s.ends.len() {
            0 => return unoccluded,
            1 => polygon_irradiance(q, n, &s.parts),
            _ => match self.union_irradiance(s) {
                Some(e) => e,
                None => {
                    let hidden: Vec<Vec<DVec3>> = (0..s.ends.len())
                        .map(|k| s.parts[s.start(k)..s.ends[k]].to_vec())
                        .collect();
                    return self.boolean_minus_union(&hidden).min(unoccluded);
                }
            },
        };
        // The hidden parts lie inside the light, so the visible integral is a difference.
        (unoccluded - covered).clamp(0.0, unoccluded)
    }

    /// Irradiance per unit radiance from the union of the hidden parts in `s`, as a sum over
    /// disjoint convex pieces: each part (largest first) minus the parts before it, in the
    /// light's plane. A part whose bounds meet no earlier part's is a piece as it stands, so
    /// small occluders side by side (each hiding its own patch of the light) cost one
    /// contour integral each, and a part nested in a larger one leaves nothing. `None` when
    /// the pieces multiply (many parts crossing each other): the general boolean then.
    ///
    /// # Precision
    /// The visible light is the unoccluded integral minus this sum, so where nearly all the
    /// light is hidden its absolute error is that of the sum, a few ulps of the unoccluded
    /// value. Pieces of area below 1e-15 of the light's (clipping slivers) are left out.
    fn union_irradiance(&self, s: &mut Scratch) -> Option<f64> {
        let View { q, n, .. } = *self;
        let frame = Frame::new(DVec3::ZERO, self.ln);
        // The light and the parts in the light's plane, counter-clockwise.
        let flatten = |c: &[DVec3], out: &mut Vec<DVec2>| {
            let start = out.len();
            out.extend(c.iter().map(|v| frame.to_2d(*v)));
            if signed_area_2d(&out[start..]) < 0.0 {
                out[start..].reverse();
            }
            signed_area_2d(&out[start..])
        };
        s.flat.clear();
        let min_area = 1e-15 * flatten(self.light, &mut s.flat);
        s.flat.clear();
        s.meta.clear();
        for k in 0..s.ends.len() {
            let start = s.flat.len();
            let area = flatten(&s.parts[s.start(k)..s.ends[k]], &mut s.flat);
            if area > min_area {
                let (lo, hi) = bounds(&s.flat[start..]);
                s.meta.push(Part {
                    area,
                    index: k,
                    flat: start..s.flat.len(),
                    lo,
                    hi,
                });
            }
        }
        s.meta
            .sort_by(|a, b| b.area.total_cmp(&a.area).then(a.index.cmp(&b.index)));
        let limit = 8 * s.ends.len() + 32;
        let (mut total, mut count) = (0.0, 0);
        let (mut pieces, mut next): (Vec<Vec<DVec2>>, Vec<Vec<DVec2>>) = (Vec::new(), Vec::new());
        let Scratch {
            parts,
            ends,
            flat,
            meta,
            lifted,
            ..
        } = s;
        for (k, part) in meta.iter().enumerate() {
            let apart = |o: &Part| {
                o.hi.x <= part.lo.x
                    || o.hi.y <= part.lo.y
                    || o.lo.x >= part.hi.x
                    || o.lo.y >= part.hi.y
            };
            if meta[..k].iter().all(apart) {
                let start = if part.index == 0 {
                    0
                } else {
                    ends[part.index - 1]
                };
                total += polygon_irradiance(q, n, &parts[start..ends[part.index]]);
                count += 1;
                continue;
            }
            pieces.clear();
            pieces.push(flat[part.flat.clone()].to_vec());
            for earlier in meta[..k].iter().filter(|o| !apart(o)) {
                next.clear();
                for p in pieces.drain(..) {
                    subtract_convex(p, &flat[earlier.flat.clone()], min_area, &mut next);
                }
                std::mem::swap(&mut pieces, &mut next);
                if pieces.is_empty() {
                    break;
                }
            }
            count += pieces.len();
            if count > limit {
                return None;
            }
            for p in &pieces {
                lifted.clear();
                lifted.extend(p.iter().map(|x| frame.to_3d(*x)));
                total += polygon_irradiance(q, n, lifted);
            }
        }
        Some(total)
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

    /// Puts into `part` the part of the light that convex occluder `o` (relative to the
    /// light's centroid) hides from `q`; `false` when nothing with area is hidden. `reach` is
    /// the largest distance from `q` to the light; `next` is a buffer.
    fn hidden_part(
        &self,
        o: &[DVec3],
        part: &mut Vec<DVec3>,
        next: &mut Vec<DVec3>,
        reach: f64,
    ) -> bool {
        let (q, light) = (self.q, self.light);
        if o.len() < 3 {
            return false;
        }
        let no = newell_normal(o).normalize_or_zero();
        if no == DVec3::ZERO {
            return false;
        }
        let co = o.iter().copied().sum::<DVec3>() / o.len() as f64;
        let h = no.dot(q - co);
        let size = o.iter().map(|v| (*v - q).length()).fold(0.0, f64::max);
        if !(h.abs() > TOUCH * size) {
            return false;
        }
        let s = h.signum();
        // O's plane first: it discards the whole light in the common case of an occluder that is
        // not between the point and the light.
        let far = -s * no;
        let plane = Plane::new(far, far.dot(co) + TOUCH * reach);
        clip_polygon_3d_into(light, &plane, 0.0, part);
        for i in 0..o.len() {
            if part.len() < 3 {
                return false;
            }
            let (a, b) = (o[i] - q, o[(i + 1) % o.len()] - q);
            // With O counter-clockwise about `no`, its inside is where (a × b)·(x − q) has
            // the sign of −h; the sign of h turns this around for an occluder facing away.
            let m = (-s * a.cross(b)).normalize_or_zero();
            if m == DVec3::ZERO {
                return false;
            }
            clip_polygon_3d_into(part, &Plane::new(m, m.dot(q)), 0.0, next);
            std::mem::swap(part, next);
        }
        part.len() >= 3
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
mod test;

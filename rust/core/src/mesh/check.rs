//! One pass of refinement's checks over the triangles that changed: the light at their
//! corners (and their neighbours', for the screening), then, where the vertex values leave an
//! element in doubt, at its edge midpoints, its centroid and the points around it, in stages.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::Triangulation;

use super::doubt;
use super::readings::{Kind, View};
use super::refine::{key, Cache, Lights, RefineStats, FLOOR, SAFETY};
use super::sides::Face;
use crate::regions::relation::Relation;
use crate::regions::Region;
use crate::scene::settings::Settings;
use crate::BakeError;

/// Edges to split (their vertices) and interior points to insert, found on the faces
/// `check`; `None` when all pass.
pub(super) type Splits = (
    Vec<(FixedVertexHandle, FixedVertexHandle)>,
    Vec<(DVec2, FixedVertexHandle)>,
);

/// One pass of checks: the light at the corners of `check` and of their neighbours (for
/// the screening), then at the samples of the faces in doubt.
#[allow(clippy::too_many_arguments)]
pub(super) fn check_faces(
    view: &View<'_>,
    check: &[Face],
    kinds: &mut Vec<Kind>,
    cache: &mut Cache,
    brightest: &mut DVec3,
    settings: &Settings,
    lower: f64,
    lights: &Lights,
    stats: &mut RefineStats,
    progress: &crate::Progress,
) -> Result<Option<Splits>, BakeError> {
    let cdt = view.cdt;
    let light = lights.at;
    // Faces whose corner values are needed: those checked and their neighbours.
    let mut slot = vec![u32::MAX; cdt.num_all_faces()];
    let mut faces: Vec<Face> = Vec::with_capacity(check.len() * 2);
    for &f in check {
        slot[f.index()] = faces.len() as u32;
        faces.push(f);
    }
    for &f in check {
        for n in view.neighbours(f) {
            if slot[n.index()] == u32::MAX {
                slot[n.index()] = faces.len() as u32;
                faces.push(n);
            }
        }
    }
    kinds.resize(cdt.num_vertices(), Kind::Unknown);
    // A receiver under thousands of shadows (room-8328's table top: 13 s of meshing) holds
    // one thread for its whole mesh but for what it splits itself; a vertex's kind walks its
    // D0 edges, so the kinds are found on all threads.
    let mut unknown: Vec<FixedVertexHandle> = faces
        .iter()
        .flat_map(|&f| view.vertices(f))
        .filter(|v| kinds[v.index()] == Kind::Unknown)
        .collect();
    unknown.sort_unstable();
    unknown.dedup();
    let found: Vec<Kind> = unknown.par_iter().map(|&v| view.kind(v)).collect();
    for (v, k) in unknown.into_iter().zip(found) {
        kinds[v.index()] = k;
    }
    let kinds = &*kinds;
    let readings: Vec<[DVec2; 3]> = faces
        .par_iter()
        .map(|&f| {
            let vs = view.vertices(f);
            [0, 1, 2].map(|k| view.reading(f, k, kinds[vs[k].index()]))
        })
        .collect();
    let mut todo: Vec<(DVec2, u32, u8)> = Vec::new();
    for (i, r) in readings.iter().enumerate() {
        for (k, p) in r.iter().enumerate() {
            if !cache.contains_key(&key(*p)) {
                todo.push((*p, i as u32, k as u8));
            }
        }
    }
    todo.sort_unstable_by_key(|(p, _, _)| key(*p));
    todo.dedup_by_key(|(p, _, _)| key(*p));
    let values: Vec<_> = todo
        .par_iter()
        .map(|&(p, i, k)| {
            let f = faces[i as usize];
            let kind = kinds[view.vertices(f)[k as usize].index()];
            let labels = view.reading_labels(f, k as usize, kind);
            let regs: Vec<&Region> = labels.iter().map(|&l| &view.regions[l as usize]).collect();
            light(p, &regs)
        })
        .collect();
    stats.evaluations += values.len() as u64;
    cache.reserve(todo.len());
    for (&(p, _, _), val) in todo.iter().zip(values) {
        *brightest = brightest.max(val.0);
        cache.insert(key(p), val);
    }
    progress.check()?;
    let floor = *brightest * FLOOR;
    let vals: Vec<[DVec3; 3]> = readings
        .iter()
        .map(|r| r.map(|p| cache[&key(p)].0))
        .collect();
    let tris: Vec<[DVec2; 3]> = faces.iter().map(|&f| view.triangle(f)).collect();
    let grads: Vec<_> = tris
        .iter()
        .zip(&vals)
        .map(|(p, v)| doubt::gradient(*p, *v))
        .collect();

    // Samples: edge midpoints (edges at least twice the lower bound) and centroids
    // (elements whose edges are all splittable), at the mean of the reading points so that
    // a sample beside a D0 row or a corner lies on its element's side. Checked exactly only
    // where the vertex values leave the element in doubt, and in stages: an element that
    // fails at a midpoint is split there, so its interior is not read this pass; one that
    // fails at its centroid is split there, so the points around it are not read either.
    let mut edge_samples: Vec<Sample> = Vec::new();
    let mut inner: Vec<u32> = Vec::new();
    for (i, &f) in check.iter().enumerate() {
        // In umbra of every light the exact light is nothing, and so are the vertices
        // (those on its border lie where the light comes in continuously, from nothing,
        // or on a D0 row whose copy on this side is dark): nothing to check.
        let label = view.label(f);
        let region = &view.regions[label as usize];
        if region.relations.iter().all(|r| *r == Relation::Umbra) {
            continue;
        }
        let value = vals[i];
        let least = value
            .iter()
            .map(|v| v.abs())
            .fold(DVec3::splat(f64::INFINITY), DVec3::min);
        let allowed = (least + floor) * (settings.tolerance * SAFETY);
        let neighbours: Vec<_> = view
            .neighbours(f)
            .map(|n| {
                let j = slot[n.index()] as usize;
                let t = tris[j];
                ((t[0] + t[1] + t[2]) / 3.0, grads[j])
            })
            .collect();
        let p = tris[i];
        let screen = if region.relations.contains(&Relation::Penumbra) {
            doubt::SCREEN
        } else {
            doubt::SCREEN_SMOOTH
        };
        if !doubt::doubtful(p, value, &neighbours, allowed, screen) {
            continue;
        }
        let vs = view.vertices(f);
        let c = readings[i];
        let edges = cdt.face(f).adjacent_edges();
        let mut splittable = 0;
        for k in 0..3 {
            if (p[k] - p[(k + 1) % 3]).length() < 2.0 * lower {
                continue;
            }
            splittable += 1;
            // A midpoint may become a vertex, whose value is then this one: on an edge
            // between two regions it takes both (a lit region's shortcut is right only
            // inside it).
            let other = edges[k]
                .rev()
                .face()
                .as_inner()
                .map(|g| g.fix())
                .filter(|&g| view.inside(g))
                .map_or(label, |g| view.label(g));
            edge_samples.push(Sample {
                face: i as u32,
                at: 0.5 * (c[k] + c[(k + 1) % 3]),
                interp: 0.5 * (value[k] + value[(k + 1) % 3]),
                other,
                split: Split::Edge(vs[k], vs[(k + 1) % 3]),
            });
        }
        if splittable == 3 {
            inner.push(i as u32);
        }
    }
    let read = |samples: &[Sample], cache: &mut Cache, stats: &mut RefineStats| {
        let mut todo: Vec<(DVec2, u32, u32)> = samples
            .iter()
            .filter(|s| !cache.contains_key(&key(s.at)))
            .map(|s| (s.at, view.label(check[s.face as usize]), s.other))
            .collect();
        todo.sort_unstable_by_key(|(p, _, _)| key(*p));
        todo.dedup_by_key(|(p, _, _)| key(*p));
        let values: Vec<_> = todo
            .par_iter()
            .map(|&(q, a, b)| {
                let (ra, rb) = (&view.regions[a as usize], &view.regions[b as usize]);
                if a == b {
                    light(q, &[ra])
                } else {
                    light(q, &[ra, rb])
                }
            })
            .collect();
        stats.evaluations += values.len() as u64;
        cache.reserve(todo.len());
        for (&(q, _, _), val) in todo.iter().zip(values) {
            cache.insert(key(q), val);
        }
    };
    let fails = |s: &Sample, cache: &Cache| {
        let exact = cache[&key(s.at)].0;
        let err = (s.interp - exact).abs();
        let allowed = (exact.abs() + floor) * (settings.tolerance * SAFETY);
        err.cmpgt(allowed).any()
    };

    read(&edge_samples, cache, stats);
    progress.check()?;
    let mut edges = Vec::new();
    let mut failed = vec![false; check.len()];
    for s in &edge_samples {
        if let Split::Edge(a, b) = s.split {
            if fails(s, cache) {
                failed[s.face as usize] = true;
                edges.push((a.min(b), a.max(b)));
            }
        }
    }
    drop(edge_samples);

    // One interior point per element and pass: the centroid, else (where the light may
    // kink along lines that no constraint follows, `kinks_inside`, and a kink inside an
    // element errs most beside it, not at the midpoints) the first of three points halfway
    // from the centroid to each corner that fails.
    let mut centroids: Vec<(DVec2, FixedVertexHandle)> = Vec::new();
    for stage in 0..2 {
        let mut samples: Vec<Sample> = Vec::new();
        for &i in &inner {
            if failed[i as usize] {
                continue;
            }
            let f = check[i as usize];
            let label = view.label(f);
            if stage == 1 && !kinks_inside(&view.regions[label as usize], &lights.polygonal) {
                continue;
            }
            let (p, value) = (tris[i as usize], vals[i as usize]);
            let c = readings[i as usize];
            let centre = (p[0] + p[1] + p[2]) / 3.0;
            let centre_eval = (c[0] + c[1] + c[2]) / 3.0;
            let centre_value = (value[0] + value[1] + value[2]) / 3.0;
            if stage == 0 {
                samples.push(Sample {
                    face: i,
                    at: centre_eval,
                    interp: centre_value,
                    other: label,
                    split: Split::Centroid(centre),
                });
            } else {
                for k in 0..3 {
                    samples.push(Sample {
                        face: i,
                        at: 0.5 * (centre_eval + c[k]),
                        interp: 0.5 * (centre_value + value[k]),
                        other: label,
                        split: Split::Centroid(0.5 * (centre + p[k])),
                    });
                }
            }
        }
        read(&samples, cache, stats);
        progress.check()?;
        for s in &samples {
            if let Split::Centroid(c) = s.split {
                if !failed[s.face as usize] && fails(s, cache) {
                    failed[s.face as usize] = true;
                    centroids.push((c, view.vertices(check[s.face as usize])[0]));
                }
            }
        }
    }
    // A failing element is also cut across its longest edge (Rivara's bisection), which
    // its samples may pass: a midpoint can fall where the light's curve along the edge
    // crosses its chord. Cut only at what failed, an element along such an edge gets
    // flatter each pass, its apex halving its way down to the edge (clutter at high: strips
    // 1e-7 high and 2 mm long along a box's contact line, 6.2× the tolerance).
    for (i, &f) in check.iter().enumerate() {
        if !failed[i] {
            continue;
        }
        let p = tris[i];
        let k = (0..3)
            .max_by(|&a, &b| {
                (p[a] - p[(a + 1) % 3])
                    .length_squared()
                    .total_cmp(&(p[b] - p[(b + 1) % 3]).length_squared())
            })
            .expect("three edges");
        if (p[k] - p[(k + 1) % 3]).length() < 2.0 * lower {
            continue;
        }
        let vs = view.vertices(f);
        let (a, b) = (vs[k], vs[(k + 1) % 3]);
        edges.push((a.min(b), a.max(b)));
    }
    Ok((!edges.is_empty() || !centroids.is_empty()).then_some((edges, centroids)))
}

/// Whether the light may kink inside `region` along lines that no constraint follows: in
/// the penumbra of a round light (its outline facing each point is a disc), or of a polygon
/// light behind more than one occluder (where their outlines seen from the point cross, EEE
/// events, which the arrangement does not hold). Behind one occluder, a polygon light's
/// kinks are its VE/EV critical lines, which are constraints (`shadows::critical_lines`).
fn kinks_inside(region: &Region, polygonal: &[bool]) -> bool {
    region
        .relations
        .iter()
        .zip(&region.blockers)
        .enumerate()
        .any(|(l, (r, b))| {
            *r == Relation::Penumbra && (b.len() > 1 || !polygonal.get(l).copied().unwrap_or(false))
        })
}

struct Sample {
    /// Index of the face in the checked list.
    face: u32,
    /// Where the light is evaluated.
    at: DVec2,
    /// The element's linear interpolant there.
    interp: DVec3,
    /// The component across the edge sampled (the face's own for interior samples).
    other: u32,
    split: Split,
}

enum Split {
    /// Vertices of the edge.
    Edge(FixedVertexHandle, FixedVertexHandle),
    /// Where to insert a vertex.
    Centroid(DVec2),
}

//! The whole bake, stage by stage, and its output (the bake JSON of DESIGN.md).

mod coverage;

use std::sync::atomic::AtomicU64;
use std::time::Instant;

use std::f64::consts::PI;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::direct;
use crate::geom::raycast::Occluders;
use crate::indirect;
use crate::mesh::elements::{append, Elements};
use crate::mesh::sizing::Sizing;
use crate::mesh::{self, ReceiverMesh};
use crate::regions::{self, ReceiverRegions, RegionTimes};
use crate::shadows;

use crate::progress::Progress;
use crate::scene::json::SceneJson;
use crate::scene::{Scene, Tolerances};
use crate::BakeError;

/// Figures named as in the paper's tables (times in seconds).
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
#[allow(non_snake_case)]
pub struct Stats {
    /// Receivers before the loop split (convex faces).
    pub N_f1: u64,
    /// Faces after the loop split (regions bounded by loops).
    pub N_f2: u64,
    /// Discontinuity edges.
    pub N_d: u64,
    /// Patches (shooters of indirect light).
    pub N_p: u64,
    /// Elements (output triangles).
    pub N_e: u64,
    /// Output vertices.
    pub N_v: u64,
    pub T_sdw: f64,
    pub T_isr: f64,
    pub T_idd: f64,
    pub T_lop: f64,
    pub T_lit: f64,
    pub T_div: f64,
    /// Meshing: its share by CPU time of the pass that builds each receiver's regions and
    /// then its mesh (the region sub-stages T_idd…T_div share the rest), plus assembling.
    pub T_m: f64,
    pub T_direct: f64,
    pub T_rs: f64,
    pub T_total: f64,
    /// Shooting steps of progressive refinement, and the unshot power left at the end as a
    /// fraction of the emitted power.
    pub shots: u64,
    pub unshot_fraction: f64,
    /// Element vertices at which indirect light was computed (the rest interpolate).
    pub N_gather: u64,
    /// Hierarchical solver: links, the visibility rays cast to make them, and memory of the
    /// hierarchy and links per leaf (element triangle) in bytes.
    pub N_links: u64,
    pub rays: u64,
    pub bytes_per_leaf: f64,
    /// Hierarchical solver: pairs from planar sources dropped because all their rays were
    /// blocked, and the seconds of T_rs spent refining links and in the final gather.
    pub N_hidden: u64,
    pub T_link: f64,
    pub T_gather: f64,
    /// Hierarchical solver: visibility rays the final gather cast (`rays` counts
    /// refinement's only).
    pub gather_rays: u64,
    /// Vertex×light pairs: skipped in umbra, computed unoccluded in lit regions, computed
    /// with visibility in penumbra.
    pub pairs_umbra: u64,
    pub pairs_lit: u64,
    pub pairs_penumbra: u64,
    /// (light, occluder) pairs that got shadow volumes, and that were culled.
    pub shadow_pairs: u64,
    pub shadow_pairs_culled: u64,
    /// Refinement to `settings.tolerance` (mesh::refine): passes on the receiver that needed
    /// most, elements it added over the scene, and exact light evaluations it made (each
    /// reused as vertex light where it became a vertex), the fit's of lit midpoints
    /// (`mesh::fit`) included.
    pub refine_passes: u64,
    pub refine_elements_added: u64,
    pub refine_evaluations: u64,
    /// Splitting for indirect light (indirect::hierarchical::subdivide): passes, and
    /// vertices it added.
    pub indirect_passes: u64,
    pub indirect_vertices_added: u64,
}

/// One output mesh per input mesh (same name and order).
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct BakedMesh {
    pub name: String,
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Linear RGB outgoing radiance per vertex.
    pub colors: Vec<[f64; 3]>,
    /// Per triangle: index of the input polygon it lies in.
    pub source_polygon: Vec<u32>,
    /// Per triangle: one relation code per light (1 lit, 2 penumbra, 3 umbra), in the order
    /// of the input `lights`.
    pub relation: Vec<Vec<u8>>,
}

#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Bake {
    pub format: &'static str,
    pub version: u32,
    pub meshes: Vec<BakedMesh>,
    pub stats: Stats,
    pub warnings: Vec<String>,
}

impl Bake {
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("bake output is always serialisable")
    }

    /// The same JSON written as it is made: room-8328's is 142 MB, which as one string (grown
    /// by doubling) was the top of a direct-only bake's memory.
    pub fn write_json(&self, w: impl std::io::Write) -> std::io::Result<()> {
        let mut w = std::io::BufWriter::new(w);
        serde_json::to_writer(&mut w, self).map_err(std::io::Error::from)?;
        std::io::Write::flush(&mut w)
    }
}

/// Parses, validates and bakes scene JSON text.
pub fn bake_scene_json(text: &str, progress: &Progress) -> Result<Bake, BakeError> {
    let json = SceneJson::from_str(text)?;
    let scene = crate::scene::validate(&json)?;
    bake(&scene, progress)
}

/// Bakes a validated scene on `settings.threads` threads (all cores by default).
pub fn bake(scene: &Scene, progress: &Progress) -> Result<Bake, BakeError> {
    progress.watch_memory(scene.settings.max_memory);
    // A stage that sees the watchdog's cancel may report a plain `Cancelled`.
    let stopped = |e: BakeError| progress.stopped_by().unwrap_or(e);
    match scene.settings.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build()
            .map_err(|e| BakeError::setting("threads", e.to_string()))?
            .install(|| run(scene, progress))
            .map_err(stopped),
        None => run(scene, progress).map_err(stopped),
    }
}

fn run(scene: &Scene, progress: &Progress) -> Result<Bake, BakeError> {
    let t_start = Instant::now();
    let mut stats = Stats {
        N_f1: scene.faces.len() as u64,
        ..Stats::default()
    };

    progress.stage("shadow volumes");
    // Contact lines and plane cuts stay discontinuities even in umbra on both sides when
    // indirect light follows: bounced light reaches the floor beside a box, never under it.
    let keep_contacts = scene.settings.indirect;
    let tol = scene.tolerances();
    let (shadows, es) = shadows::shadow_polygons(scene, &tol, progress)?;
    stats.T_sdw = es.t_sdw;
    stats.T_isr = es.t_isr;
    stats.shadow_pairs = es.shadow_pairs;
    stats.shadow_pairs_culled = es.culled_pairs;

    progress.stage("discontinuity loops");
    progress.check()?;
    let t = Instant::now();
    // Scenery (a mesh without output) is there only to shadow and reflect light to the
    // outputs: when indirect light needs its elements, a uniform mesh at the element size
    // will do, without discontinuity edges or fine penumbra elements (a large unselected
    // room around a baked chair would otherwise cost most of the bake). Its vertices' direct
    // light stays exact; what it reflects is smeared over an element across its shadow
    // edges (3 % on a box's underside lit only by a scenery floor, tests/scope.rs).
    let scenery =
        |f: &crate::scene::Face| scene.settings.indirect && !scene.meshes[f.mesh as usize].output;
    let scenery_settings = crate::scene::settings::Settings {
        uniform: true,
        penumbra_element_size: scene.settings.element_size,
        ..scene.settings.clone()
    };
    let budget = AtomicU64::new(0);
    let outlines = direct::outlines(scene);
    // Round lights (a disc facing each point) kink along curves inside their penumbrae.
    let polygonal: Vec<bool> = scene
        .lights
        .iter()
        .map(|l| match l.kind {
            crate::scene::LightKind::Point { radius, .. } => radius == 0.0,
            crate::scene::LightKind::Sun { half_angle, .. } => half_angle == 0.0,
            _ => true,
        })
        .collect();
    let mesh_one = |rr: &ReceiverRegions, f: &crate::scene::Face| {
        // A mesh without output needs elements only to reflect light to the others.
        if !scene.meshes[f.mesh as usize].output && !scene.settings.indirect {
            return Ok(ReceiverMesh::default());
        }
        let settings = if scenery(f) {
            &scenery_settings
        } else {
            &scene.settings
        };
        let sizing = Sizing::new(f, &scene.lights, settings);
        // The exact direct light, for refinement to the tolerance.
        let face = rr.face;
        let light = |q: glam::DVec2, regs: &[&regions::Region]| {
            direct::light_at(
                scene,
                &tol,
                face,
                f.frame.to_3d(q),
                f.plane.n,
                regs,
                &outlines,
            )
        };
        let lights = mesh::refine::Lights {
            at: &light,
            polygonal: polygonal.clone(),
        };
        mesh::mesh_receiver(
            rr,
            &sizing,
            settings,
            &tol,
            &budget,
            progress,
            Some(&lights),
        )
    };
    // Each receiver is meshed as soon as its regions are built, and its regions are dropped
    // then, and the receivers go out largest first (by the shadow lines they hold). Built
    // in scene order, regions then meshes, room-8328's floor and table top (2 + 16 s and 6 +
    // 13 s) fell on one thread one after the other, and the table top's mesh ended alone on
    // one core 13 s after the rest. The stage is called "meshing" once the last receiver's
    // regions are built. The first `Cancelled` stops the receivers being handed out; a large
    // receiver's arrangement checks on its own.
    let weight = |sh: &shadows::ReceiverShadows| {
        sh.polys.len()
            + sh.contacts.len()
            + sh.plane_cuts.len()
            + sh.inside.len()
            + sh.events.len()
            + sh.gaps.len()
    };
    let mut work: Vec<(usize, shadows::ReceiverShadows)> =
        shadows.into_iter().enumerate().collect();
    work.sort_by_key(|(i, sh)| (std::cmp::Reverse(weight(sh)), *i));
    let building = std::sync::atomic::AtomicUsize::new(work.len());
    let mut built: Vec<(usize, ReceiverMesh, RegionTimes, f64, [u64; 2])> = work
        .into_iter()
        .par_bridge()
        .map(|(i, sh)| {
            progress.check()?;
            let f = &scene.faces[i];
            let uniform = scene.settings.uniform || scenery(f);
            let (rr, times) =
                regions::build_regions(f, sh, &tol, uniform, keep_contacts, progress)?;
            if building.fetch_sub(1, std::sync::atomic::Ordering::Relaxed) == 1 {
                progress.stage("meshing");
            }
            progress.check()?;
            let t = Instant::now();
            let m = mesh_one(&rr, f)?;
            let counts = [rr.n_discontinuity, rr.n_regions];
            Ok((i, m, times, t.elapsed().as_secs_f64(), counts))
        })
        .collect::<Result<_, BakeError>>()?;
    built.sort_unstable_by_key(|b| b.0);
    // Stage times are wall time, split between sub-stages by their share of CPU time.
    let wall = t.elapsed().as_secs_f64();
    let parts = built.iter().fold([0.0; 5], |a, (_, _, t, m, _)| {
        [
            a[0] + t.t_idd,
            a[1] + t.t_lop,
            a[2] + t.t_lit,
            a[3] + t.t_div,
            a[4] + m,
        ]
    });
    let cpu: f64 = parts.iter().sum::<f64>().max(1e-300);
    stats.T_idd = wall * parts[0] / cpu;
    stats.T_lop = wall * parts[1] / cpu;
    stats.T_lit = wall * parts[2] / cpu;
    stats.T_div = wall * parts[3] / cpu;
    stats.T_m = wall * parts[4] / cpu;
    stats.N_d = built.iter().map(|b| b.4[0]).sum();
    stats.N_f2 = built.iter().map(|b| b.4[1]).sum();
    let meshes: Vec<ReceiverMesh> = built.into_iter().map(|b| b.1).collect();
    let t = Instant::now();
    for m in &meshes {
        stats.refine_passes = stats.refine_passes.max(m.refine.passes);
        stats.refine_elements_added += m
            .refine
            .elements_after
            .saturating_sub(m.refine.elements_before);
        stats.refine_evaluations += m.refine.evaluations;
    }
    let mut elements = assemble(scene, &meshes);
    // The per-receiver meshes are done with. Freeing them (a million small
    // allocations on a floor under a thousand shadows; 0.2 s in a debug build) happens on a
    // thread of its own, so that neither a cancel in a later stage nor the end of the bake
    // waits for it.
    std::thread::spawn(move || drop(meshes));
    stats.T_m += t.elapsed().as_secs_f64();
    stats.N_e = elements.triangles.len() as u64;
    stats.N_v = elements.positions.len() as u64;

    progress.stage("direct light");
    let t = Instant::now();
    let (direct, pairs) = match direct::direct_irradiance(scene, &tol, &elements, progress) {
        Ok(d) => d,
        Err(e) => {
            // Cancelled: return now and free the elements aside (see above).
            std::thread::spawn(move || drop(elements));
            return Err(e);
        }
    };
    stats.T_direct = t.elapsed().as_secs_f64();
    [stats.pairs_umbra, stats.pairs_lit, stats.pairs_penumbra] = pairs;
    // Its values are in `direct` now; at 56 bytes a vertex (room-8328: 0.33 GB) it would
    // stay through the indirect light's peak for nothing.
    elements.known_direct = Vec::new();

    let mut irradiance = direct;
    let occluders = (scene.settings.indirect || scene.settings.world != DVec3::ZERO)
        .then(|| Occluders::new(&scene.faces));
    if let (Some(occ), true) = (&occluders, scene.settings.world != DVec3::ZERO) {
        progress.stage("world light");
        let t = Instant::now();
        let w = direct::world::world_irradiance(
            scene.settings.world,
            &elements,
            occ,
            scene.settings.visibility_rays,
            progress,
        )?;
        stats.T_direct += t.elapsed().as_secs_f64();
        for (e, x) in irradiance.iter_mut().zip(&w) {
            *e += *x;
        }
    }
    if let (Some(occluders), true) = (&occluders, scene.settings.indirect) {
        progress.stage("indirect light");
        let t = Instant::now();
        let mut ind = indirect::indirect(scene, &elements, &irradiance, occluders, progress)?;
        if let Some(sub) = ind.subdivided.take() {
            stats.indirect_passes = sub.passes;
            stats.indirect_vertices_added = sub.positions.len() as u64;
            append(&mut irradiance, sub.direct);
            append(&mut elements.positions, sub.positions);
            append(&mut elements.eval, sub.eval);
            append(&mut elements.normals, sub.normals);
            append(&mut elements.vertex_face, sub.vertex_face);
            elements.triangles = sub.triangles;
            elements.tri_face = sub.tri_face;
            elements.tri_region = sub.tri_region;
            stats.N_e = elements.triangles.len() as u64;
            stats.N_v = elements.positions.len() as u64;
        }
        stats.T_rs = t.elapsed().as_secs_f64();
        stats.N_p = ind.patches;
        stats.shots = ind.shots;
        stats.unshot_fraction = ind.unshot_fraction;
        stats.N_gather = ind.gather_vertices;
        stats.N_links = ind.links;
        stats.rays = ind.rays;
        stats.bytes_per_leaf = ind.bytes_per_leaf;
        stats.N_hidden = ind.hidden;
        stats.T_link = ind.t_refine;
        stats.T_gather = ind.t_gather;
        stats.gather_rays = ind.gather_rays;
        for (e, i) in irradiance.iter_mut().zip(&ind.irradiance) {
            *e += *i;
        }
    }
    let radiance = colors(scene, &elements, &irradiance);
    let out = output(scene, &tol, &elements, &radiance);
    coverage::check(scene, &out)?;
    stats.T_total = t_start.elapsed().as_secs_f64();
    Ok(Bake {
        format: "penumbra-bake",
        version: 1,
        meshes: out,
        stats,
        warnings: scene.warnings.clone(),
    })
}

/// All receivers' meshes in one vertex/triangle space, in 3-D.
fn assemble(scene: &Scene, meshes: &[ReceiverMesh]) -> Elements {
    let mut el = Elements::default();
    for (fi, (f, m)) in scene.faces.iter().zip(meshes).enumerate() {
        let v0 = el.positions.len() as u32;
        let r0 = el.regions.len() as u32;
        el.positions
            .extend(m.positions.iter().map(|p| f.frame.to_3d(*p)));
        el.eval.extend(m.eval.iter().map(|p| f.frame.to_3d(*p)));
        el.normals
            .extend(std::iter::repeat_n(f.plane.n, m.positions.len()));
        el.vertex_face
            .extend(std::iter::repeat_n(fi as u32, m.positions.len()));
        el.triangles
            .extend(m.triangles.iter().map(|t| t.map(|i| i + v0)));
        el.tri_face
            .extend(std::iter::repeat_n(fi as u32, m.triangles.len()));
        el.tri_region.extend(m.tri_region.iter().map(|r| r + r0));
        if m.known_direct.len() == m.positions.len() {
            el.known_direct.resize(v0 as usize, None);
            el.known_direct.extend(m.known_direct.iter().copied());
        }
        el.regions.extend(m.regions.iter().cloned());
    }
    el
}

/// Outgoing radiance of a Lambertian surface, `albedo · E / π + emission` (what Cycles'
/// Diffuse bake with direct, indirect and colour gives), or `E / π` for lighting only.
fn colors(scene: &Scene, el: &Elements, irradiance: &[DVec3]) -> Vec<[f64; 3]> {
    irradiance
        .iter()
        .zip(&el.vertex_face)
        .map(|(e, &f)| {
            let face = &scene.faces[f as usize];
            let c = if scene.settings.lighting_only {
                *e / PI
            } else {
                face.albedo * *e / PI + face.emission
            };
            c.to_array()
        })
        .collect()
}

/// Which vertex stands for each vertex in the output: vertices of different faces of one
/// mesh that coincide, face the same way and carry the same colour become one, so that a
/// polygon split into convex pieces, or a flat floor of many quads, comes out as one
/// connected surface. D0 rows keep their two vertices (their colours differ), and so do
/// creases (their normals differ).
fn weld(scene: &Scene, tol: &Tolerances, el: &Elements, colors: &[[f64; 3]]) -> Vec<u32> {
    let q = tol.weld;
    let cmax = colors
        .iter()
        .flat_map(|c| c.iter())
        .fold(0.0f64, |a, &b| a.max(b.abs()));
    // Vertices sorted by (mesh, rounded position), then each run of one key welded in index
    // order, on all threads: each vertex stands for itself or for the first earlier vertex
    // of its run that it may join and that stands for itself. A map of runs filled vertex
    // by vertex gave the same on one thread, in the last seconds of room-8328's bake where
    // one core idled (6M vertices).
    let mut keyed: Vec<((u32, [i64; 3]), u32)> = (0..el.positions.len())
        .into_par_iter()
        .map(|v| {
            let face = el.vertex_face[v] as usize;
            let key = (
                scene.faces[face].mesh,
                el.positions[v].to_array().map(|x| (x / q).round() as i64),
            );
            (key, v as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    let runs: Vec<&[((u32, [i64; 3]), u32)]> = keyed.chunk_by(|a, b| a.0 == b.0).collect();
    let joined: Vec<(u32, u32)> = runs
        .par_iter()
        .flat_map_iter(|run| {
            let mut own: Vec<u32> = Vec::new();
            let mut joined = Vec::new();
            for &(_, v) in run.iter() {
                let v = v as usize;
                let face = el.vertex_face[v] as usize;
                let c = colors[v];
                let same = own.iter().copied().find(|&w| {
                    let w = w as usize;
                    el.vertex_face[w] as usize != face
                        && el.normals[w].dot(el.normals[v]) > 1.0 - 1e-9
                        && (0..3).all(|k| {
                            (colors[w][k] - c[k]).abs()
                                <= 1e-6 * c[k].abs().max(colors[w][k].abs()) + 1e-12 * cmax
                        })
                });
                match same {
                    Some(w) => joined.push((v as u32, w)),
                    None => own.push(v as u32),
                }
            }
            joined
        })
        .collect();
    drop(runs);
    drop(keyed);
    let mut canon: Vec<u32> = (0..el.positions.len() as u32).collect();
    for (v, w) in joined {
        canon[v as usize] = w;
    }
    canon
}

/// Splits the scene-wide elements back into one mesh per input mesh.
fn output(scene: &Scene, tol: &Tolerances, el: &Elements, colors: &[[f64; 3]]) -> Vec<BakedMesh> {
    let mut out: Vec<BakedMesh> = scene
        .meshes
        .iter()
        .map(|m| BakedMesh {
            name: m.name.clone(),
            ..BakedMesh::default()
        })
        .collect();
    let canon = weld(scene, tol, el, colors);
    let input_lights = scene
        .lights
        .iter()
        .filter(|l| l.from_face.is_none())
        .count();
    let mut remap = vec![u32::MAX; el.positions.len()];
    // Per output mesh, the element triangles it keeps, in order.
    let mut kept: Vec<Vec<u32>> = vec![Vec::new(); out.len()];
    for (t, tri) in el.triangles.iter().enumerate() {
        let f = &scene.faces[el.tri_face[t] as usize];
        if !scene.meshes[f.mesh as usize].output {
            continue;
        }
        let m = &mut out[f.mesh as usize];
        let c = tri.map(|v| canon[v as usize]);
        // Two corners welded into one (a triangle under the weld distance, 1e-9 of the
        // scene): nothing left to draw, and its facing would be rounding.
        if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
            continue;
        }
        let mut idx = [0u32; 3];
        for (k, &v) in c.iter().enumerate() {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = m.positions.len() as u32;
                m.positions.push(el.positions[v as usize].to_array());
                m.colors.push(colors[v as usize]);
            }
            idx[k] = remap[v as usize];
        }
        m.triangles.push(idx);
        m.source_polygon.push(f.source_polygon);
        kept[f.mesh as usize].push(t as u32);
    }
    // The relation codes on all threads (one small allocation per triangle: 3.3M of them
    // at the end of room-8328's bake). One code per input light: lights made from emissive
    // faces come after them and are not in the input's `lights` array.
    for (m, kept) in out.iter_mut().zip(kept) {
        m.relation = kept
            .par_iter()
            .map(|&t| {
                el.regions[el.tri_region[t as usize] as usize]
                    .relations
                    .iter()
                    .take(input_lights)
                    .map(|r| r.code())
                    .collect()
            })
            .collect();
    }
    out
}

/// The stats as a text table in the layout of the paper's Tables 2 and 4.
pub fn stats_table(s: &Stats) -> String {
    let mut t = String::new();
    let rows: [(&str, String); 32] = [
        ("receivers before loop split  N_f1", s.N_f1.to_string()),
        ("faces after loop split       N_f2", s.N_f2.to_string()),
        ("discontinuity edges          N_d", s.N_d.to_string()),
        ("patches                      N_p", s.N_p.to_string()),
        ("elements                     N_e", s.N_e.to_string()),
        ("element vertices             N_v", s.N_v.to_string()),
        (
            "shadow volumes (pairs)",
            format!("{} ({} culled)", s.shadow_pairs, s.shadow_pairs_culled),
        ),
        (
            "shadow polyhedra       T_sdw (s)",
            format!("{:.4}", s.T_sdw),
        ),
        (
            "polyhedra ∩ receivers  T_isr (s)",
            format!("{:.4}", s.T_isr),
        ),
        (
            "edge ∩ edge            T_idd (s)",
            format!("{:.4}", s.T_idd),
        ),
        (
            "loop update            T_lop (s)",
            format!("{:.4}", s.T_lop),
        ),
        (
            "light relation         T_lit (s)",
            format!("{:.4}", s.T_lit),
        ),
        (
            "receiver split         T_div (s)",
            format!("{:.4}", s.T_div),
        ),
        (
            "discontinuity total    T_d (s)",
            format!(
                "{:.4}",
                s.T_sdw + s.T_isr + s.T_idd + s.T_lop + s.T_lit + s.T_div
            ),
        ),
        ("mesh                   T_m (s)", format!("{:.4}", s.T_m)),
        (
            "direct light           T_direct (s)",
            format!("{:.4}", s.T_direct),
        ),
        ("radiosity              T_rs (s)", format!("{:.4}", s.T_rs)),
        ("indirect at vertices   N_gather", s.N_gather.to_string()),
        (
            "links / rays           N_links",
            format!("{} / {}", s.N_links, s.rays),
        ),
        ("all-blocked, dropped   N_hidden", s.N_hidden.to_string()),
        (
            "  of which refinement  T_link (s)",
            format!("{:.4}", s.T_link),
        ),
        (
            "  final gather         T_gather (s)",
            format!("{:.4}", s.T_gather),
        ),
        ("  final gather's rays", s.gather_rays.to_string()),
        (
            "bytes per leaf (hierarchy+links)",
            format!("{:.0}", s.bytes_per_leaf),
        ),
        ("total                  (s)", format!("{:.4}", s.T_total)),
        (
            "shots / unshot fraction",
            format!("{} / {:.2e}", s.shots, s.unshot_fraction),
        ),
        ("vertex×light in umbra (skipped)", s.pairs_umbra.to_string()),
        ("vertex×light lit (no visibility)", s.pairs_lit.to_string()),
        ("vertex×light in penumbra", s.pairs_penumbra.to_string()),
        (
            "refinement passes / elements added",
            format!("{} / {}", s.refine_passes, s.refine_elements_added),
        ),
        (
            "refinement light evaluations",
            s.refine_evaluations.to_string(),
        ),
        (
            "indirect splits: passes / vertices added",
            format!("{} / {}", s.indirect_passes, s.indirect_vertices_added),
        ),
    ];
    for (k, v) in rows {
        t.push_str(&format!("{k:<36} {v:>14}\n"));
    }
    t
}

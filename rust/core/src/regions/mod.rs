//! Stage `regions` (paper 2.3–2.4; T_idd, T_lop, T_lit, T_div): per receiver, the arrangement of discontinuity edges and the
//! receiver boundary, split into faces bounded by loops, each with its relation to every
//! light. Edges that separate two faces which are both in umbra of every light that made the
//! edge are no discontinuity at all (the mosaic of one closed mesh's face shadows inside its
//! umbra); they are dropped, so that the mesh conforms only to real boundaries.

pub mod arrangement;
pub mod relation;

use glam::DVec2;
use rayon::prelude::*;

use crate::geom::box_grid::{bounds, BoxGrid};
use crate::geom::polygon::{along_an_edge, inside_convex};
use crate::geom::union_find::UnionFind;
use crate::regions::relation::Relation;
use crate::scene::{Face, Tolerances};
use crate::shadows::umbra_pruning::{trim_lines, UmbraCover};
use crate::shadows::{Exposure, ReceiverShadows, ShadowPolygon};
use crate::{BakeError, Progress};
use arrangement::{Arrangement, Segment, BOUNDARY_TAG};

/// A region (a face of the arrangement, or an element-mesh region): one relation per
/// light, and for each light the occluders whose penumbra polygon contains the region (the
/// only ones that can hide part of that light from a point of it). The receiver face it
/// lies on is known where it is stored (`ReceiverRegions::face`, `Elements::tri_face`).
#[derive(Debug, Clone, Default)]
pub struct Region {
    pub relations: Vec<Relation>,
    pub blockers: Vec<Vec<u32>>,
    /// Across a narrow gap from another face (`shadows::gaps`): the gap's width (the
    /// narrowest, where gaps overlap).
    pub gap: Option<f64>,
}

/// The receiver split into faces, with the edges that the mesh must conform to.
#[derive(Debug, Clone)]
pub struct ReceiverRegions {
    pub face: u32,
    pub arrangement: Arrangement,
    pub faces: Vec<Region>,
    /// Arrangement edges kept as discontinuities (plus boundary edges).
    pub kept_edges: Vec<u32>,
    /// Discontinuity edges kept (boundary excluded): the paper's N_d.
    pub n_discontinuity: u64,
    /// Faces after merging across dropped edges: the paper's N_f2.
    pub n_regions: u64,
    /// Lines across which light jumps whatever the relations say (contact lines and plane
    /// cuts, D0), in the receiver's frame: the mesh keeps vertex rows apart there, and
    /// elements shrink towards their ends.
    pub d0_lines: Vec<[DVec2; 2]>,
    /// The receiver's shadows, for the relation of any point.
    classifier: Classifier,
}

impl ReceiverRegions {
    /// Relation and blockers of the point `q` (strictly inside some region).
    pub fn classify(&self, q: DVec2) -> Region {
        self.classifier.classify(q)
    }
}

/// A receiver's shadow polygons with their bounding boxes in a grid, for a cheap first test.
#[derive(Debug, Clone)]
struct Classifier {
    polys: Vec<ShadowPolygon>,
    boxes: Vec<(DVec2, DVec2)>,
    grid: BoxGrid,
    /// Parts of the receiver inside closed solids.
    inside: Vec<Vec<DVec2>>,
    exposure: Vec<Exposure>,
    gap_parts: Vec<(Vec<DVec2>, f64)>,
}

impl Classifier {
    fn new(
        polys: Vec<ShadowPolygon>,
        inside: Vec<Vec<DVec2>>,
        exposure: Vec<Exposure>,
        gap_parts: Vec<(Vec<DVec2>, f64)>,
    ) -> Self {
        let boxes: Vec<(DVec2, DVec2)> = polys.iter().map(|p| bounds(&p.poly)).collect();
        let grid = BoxGrid::new(&boxes);
        Classifier {
            polys,
            boxes,
            grid,
            inside,
            exposure,
            gap_parts,
        }
    }

    /// Relation and blockers of the point `q` (strictly inside some arrangement face).
    fn classify(&self, q: DVec2) -> Region {
        let exposure = &self.exposure;
        let n = exposure.len();
        let mut relations = vec![Relation::Lit; n];
        let mut blockers = vec![Vec::new(); n];
        if self.inside.iter().any(|p| inside_convex(p, q)) {
            return Region {
                relations: vec![Relation::Umbra; n],
                blockers,
                gap: None,
            };
        }
        for (l, e) in exposure.iter().enumerate() {
            if *e == Exposure::Hidden {
                relations[l] = Relation::Umbra;
            }
        }
        for &k in self.grid.at(q) {
            let (p, (lo, hi)) = (&self.polys[k as usize], &self.boxes[k as usize]);
            let l = p.light as usize;
            if relations[l] == Relation::Umbra
                || q.x < lo.x
                || q.y < lo.y
                || q.x > hi.x
                || q.y > hi.y
            {
                continue;
            }
            if !inside_convex(&p.poly, q) {
                continue;
            }
            if p.umbra {
                // Keep the occluder: a vertex where umbra meets light without a D0 split
                // needs it to compute its value exactly.
                relations[l] = Relation::Umbra;
                if p.occluder != crate::shadows::BEHIND_LIGHT {
                    blockers[l] = vec![p.occluder];
                } else {
                    blockers[l].clear();
                }
            } else {
                relations[l] = Relation::Penumbra;
                blockers[l].push(p.occluder);
            }
        }
        for b in &mut blockers {
            b.sort_unstable();
            b.dedup();
        }
        Region {
            relations,
            blockers,
            gap: self
                .gap_parts
                .iter()
                .filter(|(p, _)| inside_convex(p, q))
                .map(|&(_, w)| w)
                .reduce(f64::min),
        }
    }
}

pub struct RegionTimes {
    pub t_idd: f64,
    pub t_lop: f64,
    pub t_lit: f64,
    pub t_div: f64,
}

pub fn build_regions(
    r: &Face,
    mut sh: ReceiverShadows,
    tol: &Tolerances,
    uniform: bool,
    keep_contacts: bool,
    progress: &Progress,
) -> Result<(ReceiverRegions, RegionTimes), BakeError> {
    let t0 = std::time::Instant::now();
    let snap = tol.snap(r);
    // Parts of edges deep inside an umbra of their own light would only be dropped again
    // after the arrangement; a few snap distances keep rounding off the umbra boundaries.
    // For a bake of direct light only, the one light reaching the receiver covers the lines
    // of every light too (contacts need not stay: no bounced light jumps across them).
    let cover = UmbraCover::new(
        &sh.polys,
        &sh.inside,
        &sh.exposure,
        8.0 * snap,
        !keep_contacts,
    );
    trim_lines(&cover, &mut sh.plane_cuts, &mut sh.contacts, &mut sh.events);
    // Gaps belong to every light, as plane cuts do.
    trim_lines(&cover, &mut sh.gaps, &mut Vec::new(), &mut Vec::new());
    if uniform {
        return Ok((
            uniform_regions(r, sh, tol),
            RegionTimes {
                t_idd: 0.0,
                t_lop: 0.0,
                t_lit: 0.0,
                t_div: 0.0,
            },
        ));
    }
    // Every segment cut here carries its light, so the only-light rule never applies.
    let (mut scratch, mut pieces) = (Vec::new(), Vec::new());
    let mut segs = Vec::new();
    for (k, p) in sh.polys.iter().enumerate() {
        if k % 1024 == 0 {
            progress.check()?;
        }
        for i in 0..p.poly.len() {
            let a = p.poly[i];
            let b = p.poly[(i + 1) % p.poly.len()];
            if a != b && !along_an_edge(&r.poly2, a, b, tol.boundary) {
                pieces.clear();
                cover.uncovered(
                    a,
                    b,
                    Some(p.light),
                    Some(k as u32),
                    &mut scratch,
                    &mut pieces,
                );
                segs.extend(pieces.iter().map(|&(a, b)| Segment {
                    a,
                    b,
                    tag: k as u32,
                }));
            }
        }
    }
    drop(cover);
    // Critical lines, plane cuts and contacts were trimmed above (`trim_lines`).
    let n_polys = sh.polys.len() as u32;
    for (k, (_, [a, b])) in sh.events.iter().enumerate() {
        segs.push(Segment {
            a: *a,
            b: *b,
            tag: n_polys + k as u32,
        });
    }
    let n_events = sh.events.len() as u32;
    // Contacts too when indirect light follows: where a solid meets the receiver in umbra on
    // both sides, bounced light still reaches the side outside it and never the inside.
    let contacts: &[[DVec2; 2]] = if keep_contacts { &sh.contacts } else { &[] };
    // Gaps last: like contacts they belong to no light, and they are not D0 lines.
    let gaps: &[[DVec2; 2]] = if keep_contacts { &sh.gaps } else { &[] };
    for (k, [a, b]) in sh.plane_cuts.iter().chain(contacts).chain(gaps).enumerate() {
        segs.push(Segment {
            a: *a,
            b: *b,
            tag: n_polys + n_events + k as u32,
        });
    }
    let t_idd = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    let arr = arrangement::build_cancellable(&r.poly2, &segs, snap, progress)?;
    let t_lop = t1.elapsed().as_secs_f64();

    let t2 = std::time::Instant::now();
    let classifier = Classifier::new(sh.polys, sh.inside, sh.exposure, sh.gap_parts);
    // Each face on its own: a dense receiver has hundreds of thousands.
    let faces: Vec<Region> = arr
        .faces
        .par_chunks(4096)
        .map(|chunk| {
            progress.check()?;
            Ok(chunk
                .iter()
                .map(|f| classifier.classify(f.interior))
                .collect::<Vec<_>>())
        })
        .collect::<Result<Vec<_>, BakeError>>()?
        .into_iter()
        .flatten()
        .collect();
    let t_lit = t2.elapsed().as_secs_f64();

    let t3 = std::time::Instant::now();
    // Which faces lie on each side of each edge.
    let mut sides: Vec<[u32; 2]> = vec![[u32::MAX; 2]; arr.edges.len()];
    for (fi, f) in arr.faces.iter().enumerate() {
        for &e in &f.boundary_edges {
            let s = &mut sides[e as usize];
            if s[0] == u32::MAX {
                s[0] = fi as u32;
            } else if s[1] == u32::MAX {
                s[1] = fi as u32;
            }
        }
    }
    // The light an edge belongs to; `None` for a plane cut or contact, which belongs to
    // every light.
    let light_of = |t: u32| {
        if t < n_polys {
            Some(classifier.polys[t as usize].light)
        } else if t < n_polys + n_events {
            Some(sh.events[(t - n_polys) as usize].0)
        } else {
            None
        }
    };
    let n_lights = classifier.exposure.len();
    let mut merged = UnionFind::new(arr.faces.len());
    let mut kept = Vec::new();
    let mut n_disc = 0u64;
    for (ei, e) in arr.edges.iter().enumerate() {
        if e.tags.contains(&BOUNDARY_TAG) {
            kept.push(ei as u32);
            continue;
        }
        let [a, b] = sides[ei];
        let redundant = a != u32::MAX
            && b != u32::MAX
            && e.tags.iter().all(|&t| {
                let both_umbra = |l: usize| {
                    faces[a as usize].relations[l] == Relation::Umbra
                        && faces[b as usize].relations[l] == Relation::Umbra
                };
                match light_of(t) {
                    Some(l) => both_umbra(l as usize),
                    // Solid on one side, open floor on the other: indirect light differs.
                    None if keep_contacts => false,
                    None => (0..n_lights).all(both_umbra),
                }
            });
        if redundant {
            merged.union(a, b);
        } else if a != b {
            kept.push(ei as u32);
            n_disc += 1;
        }
    }
    let n_regions = merged.count_sets() as u64;
    let t_div = t3.elapsed().as_secs_f64();
    Ok((
        ReceiverRegions {
            face: sh.face,
            arrangement: arr,
            faces,
            kept_edges: kept,
            n_discontinuity: n_disc,
            n_regions,
            d0_lines: sh.contacts.into_iter().chain(sh.plane_cuts).collect(),
            classifier,
        },
        RegionTimes {
            t_idd,
            t_lop,
            t_lit,
            t_div,
        },
    ))
}

/// The whole receiver as one region, for uniform meshing: every light that reaches it is
/// treated as penumbra with every occluder that shadows any part of it as candidate, so the
/// light at each vertex is still exact.
fn uniform_regions(r: &Face, sh: ReceiverShadows, tol: &Tolerances) -> ReceiverRegions {
    let arr = arrangement::build(&r.poly2, &[], tol.snap(r));
    let n = sh.exposure.len();
    let mut rf = Region {
        relations: vec![Relation::Lit; n],
        blockers: vec![Vec::new(); n],
        gap: None,
    };
    for (l, e) in sh.exposure.iter().enumerate() {
        if *e == Exposure::Hidden {
            rf.relations[l] = Relation::Umbra;
        }
    }
    for p in &sh.polys {
        let l = p.light as usize;
        if rf.relations[l] == Relation::Umbra && sh.exposure[l] == Exposure::Hidden {
            continue;
        }
        rf.relations[l] = Relation::Penumbra;
        if p.occluder != crate::shadows::BEHIND_LIGHT {
            rf.blockers[l].push(p.occluder);
        }
    }
    for b in &mut rf.blockers {
        b.sort_unstable();
        b.dedup();
    }
    let kept = (0..arr.edges.len() as u32).collect();
    let faces = vec![rf; arr.faces.len()];
    ReceiverRegions {
        face: sh.face,
        arrangement: arr,
        faces,
        kept_edges: kept,
        n_discontinuity: 0,
        n_regions: 1,
        d0_lines: sh.contacts.into_iter().chain(sh.plane_cuts).collect(),
        classifier: Classifier::new(sh.polys, sh.inside, sh.exposure, Vec::new()),
    }
}

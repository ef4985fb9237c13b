//! Occluders. Every face is an occluder on its own, except where a mesh has a closed convex
//! component (a box, a UV sphere, a chair leg): that component occludes as one convex solid.
//! One solid casts one penumbra and one umbra; its faces one by one would leave the inside of
//! its umbra a mosaic of false penumbra slivers (the union of the faces' umbras is smaller
//! than the solid's umbra), and would cost a volume per face.

use std::collections::HashMap;

use glam::DVec3;

use super::json::MeshJson;
use super::Face;
use crate::geom::union_find::UnionFind;
use crate::geom::Plane;

/// A closed convex polyhedron made of scene faces.
#[derive(Debug, Clone)]
pub struct Solid {
    pub verts: Vec<DVec3>,
    /// Undirected edges (indices into `verts`) with the two polygons (indices into `planes`)
    /// that meet there.
    pub edges: Vec<[u32; 2]>,
    pub edge_planes: Vec<[u32; 2]>,
    /// Outward planes of the component's input polygons.
    pub planes: Vec<Plane>,
    pub centroid: DVec3,
}

#[derive(Debug, Clone)]
pub enum Occluder {
    /// One convex face (thin, two-sided).
    Face(u32),
    /// A convex solid: its faces and its polyhedron.
    Solid { faces: Vec<u32>, solid: Solid },
}

impl Occluder {
    pub fn faces(&self) -> &[u32] {
        match self {
            Occluder::Face(f) => std::slice::from_ref(f),
            Occluder::Solid { faces, .. } => faces,
        }
    }
}

/// Finds the closed convex components of mesh `m` (whose faces are `faces[first..]`, with
/// `source_polygon` indices into `m.polygons`). Returns the solids and the set of polygons
/// they use.
pub fn find_solids(m: &MeshJson, faces: &[Face], first: usize) -> Vec<Occluder> {
    // Weld by exact position: meshes written polygon by polygon repeat their vertices.
    let mut canon: HashMap<[u64; 3], u32> = HashMap::new();
    let mut pos: Vec<DVec3> = Vec::new();
    let ids: Vec<u32> = m
        .positions
        .iter()
        .map(|p| {
            let key = p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
            *canon.entry(key).or_insert_with(|| {
                pos.push(DVec3::from_array(*p));
                pos.len() as u32 - 1
            })
        })
        .collect();
    let polys: Vec<Vec<u32>> = m
        .polygons
        .iter()
        .map(|p| {
            let mut v: Vec<u32> = p.iter().map(|&i| ids[i as usize]).collect();
            v.dedup();
            while v.len() > 1 && v.first() == v.last() {
                v.pop();
            }
            v
        })
        .collect();
    // Directed edge → polygon.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    let mut bad_edge = vec![false; polys.len()];
    for (pi, p) in polys.iter().enumerate() {
        for k in 0..p.len() {
            let e = (p[k], p[(k + 1) % p.len()]);
            if directed.insert(e, pi as u32).is_some() {
                bad_edge[pi] = true;
            }
        }
    }
    // Components over shared edges.
    let mut sets = UnionFind::new(polys.len());
    let mut closed = vec![true; polys.len()];
    for (&(a, b), &pi) in &directed {
        match directed.get(&(b, a)) {
            Some(&qi) => {
                sets.union(pi, qi);
            }
            None => closed[pi as usize] = false,
        }
    }
    let mut comps: HashMap<u32, Vec<u32>> = HashMap::new();
    for pi in 0..polys.len() as u32 {
        let r = sets.find(pi);
        comps.entry(r).or_default().push(pi);
    }
    // Faces of each polygon.
    let mut poly_faces: Vec<Vec<u32>> = vec![Vec::new(); polys.len()];
    for (fi, f) in faces.iter().enumerate().skip(first) {
        poly_faces[f.source_polygon as usize].push(fi as u32);
    }
    let mut out = Vec::new();
    let mut keys: Vec<_> = comps.keys().copied().collect();
    keys.sort_unstable();
    for k in keys {
        let comp = &comps[&k];
        if comp.len() < 4
            || comp.iter().any(|&p| {
                !closed[p as usize] || bad_edge[p as usize] || poly_faces[p as usize].is_empty()
            })
        {
            continue;
        }
        if let Some(solid) = convex_solid(&pos, &polys, comp) {
            let faces = comp
                .iter()
                .flat_map(|&p| poly_faces[p as usize].iter().copied())
                .collect();
            out.push(Occluder::Solid { faces, solid });
        }
    }
    out
}

fn convex_solid(pos: &[DVec3], polys: &[Vec<u32>], comp: &[u32]) -> Option<Solid> {
    let mut vmap: HashMap<u32, u32> = HashMap::new();
    let mut verts = Vec::new();
    for &p in comp {
        for &v in &polys[p as usize] {
            vmap.entry(v).or_insert_with(|| {
                verts.push(pos[v as usize]);
                verts.len() as u32 - 1
            });
        }
    }
    let lo = verts
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |a, v| a.min(*v));
    let hi = verts
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |a, v| a.max(*v));
    let tol = 1e-9 * (hi - lo).length();
    let global = comp.len() * verts.len() <= 1 << 20;
    let mut planes = Vec::with_capacity(comp.len());
    for &p in comp {
        let pts: Vec<DVec3> = polys[p as usize].iter().map(|&v| pos[v as usize]).collect();
        let pl = Plane::from_polygon(&pts)?;
        // Planar polygons only; and every vertex of the solid behind every face (convex),
        // checked here in full while that is cheap, else locally at every edge below.
        if pts.iter().any(|x| pl.dist(*x).abs() > tol)
            || (global && verts.iter().any(|x| pl.dist(*x) > tol))
        {
            return None;
        }
        planes.push(pl);
    }
    let local: HashMap<u32, u32> = comp
        .iter()
        .enumerate()
        .map(|(i, &p)| (p, i as u32))
        .collect();
    let mut edge_index: HashMap<(u32, u32), usize> = HashMap::new();
    let mut edges = Vec::new();
    let mut edge_planes: Vec<[u32; 2]> = Vec::new();
    for &p in comp {
        let poly = &polys[p as usize];
        for k in 0..poly.len() {
            let (a, b) = (vmap[&poly[k]], vmap[&poly[(k + 1) % poly.len()]]);
            let key = (a.min(b), a.max(b));
            match edge_index.get(&key) {
                Some(&e) => edge_planes[e][1] = local[&p],
                None => {
                    edge_index.insert(key, edges.len());
                    edges.push([key.0, key.1]);
                    edge_planes.push([local[&p], u32::MAX]);
                }
            }
        }
    }
    // Flat pieces of one plane (coplanar neighbours) make no silhouette: fine, but an edge
    // with one polygon would mean the component is not closed after all.
    if edge_planes.iter().any(|e| e[1] == u32::MAX) {
        return None;
    }
    if !global {
        // Convex at every edge, and a topological sphere (V − E + F = 2): together these make
        // a closed surface the boundary of a convex body (a locally convex closed polyhedral
        // surface of genus 0 is convex unless it passes through itself).
        let behind = |a: u32, b: u32| {
            polys[comp[b as usize] as usize]
                .iter()
                .all(|&v| planes[a as usize].dist(pos[v as usize]) <= tol)
        };
        if edge_planes
            .iter()
            .any(|&[a, b]| !behind(a, b) || !behind(b, a))
        {
            return None;
        }
        if verts.len() as i64 - edges.len() as i64 + comp.len() as i64 != 2 {
            return None;
        }
    }
    let centroid = verts.iter().copied().sum::<DVec3>() / verts.len() as f64;
    Some(Solid {
        verts,
        edges,
        edge_planes,
        planes,
        centroid,
    })
}

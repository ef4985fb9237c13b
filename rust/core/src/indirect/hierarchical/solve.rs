//! Jacobi sweeps with push–pull over the links (Hanrahan, Salzman & Aupperle 1991):
//! 1. each leaf's radiosity is `ρ·(E_direct + E_indirect) + π·Le`; *pull* gives every
//!    planar node its area-weighted mean and every cluster its projected-radiosity table,
//!    `P[axis][sign] = Σ B·A·max(0, ±n_axis)` over its leaves, so that its radiant intensity
//!    towards a direction `w` is `Σ_axis |w_axis|·P[axis][sign of w_axis] / π` (exact for
//!    faces along the axes, as rooms and furniture mostly are);
//! 2. *gather*: each receiver sums its links in their fixed order (scalar irradiance for a
//!    planar receiver, a vector for a cluster);
//! 3. *push*: each leaf's indirect irradiance is the sum over its ancestors, a cluster's
//!    vector taken along the leaf's normal (clamped at 0) where a face begins.
//!
//! Jacobi rather than Gauss–Seidel: every receiver is independent within a sweep, so the
//! sweep runs in parallel and gives the same bits for any thread count.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::hierarchy::{Hierarchy, NONE};
use super::link::Link;
use crate::progress::Progress;
use crate::scene::Face;
use crate::BakeError;

/// Leaf positions per chunk of the solve's sums of change.
const SUM_CHUNK: usize = 4096;

/// Per axis, irradiance from sources on its + side and on its − side.
type Dirs = [[DVec3; 2]; 3];

/// Per leaf position: what the solve starts from.
pub struct Leaves {
    pub direct: Vec<DVec3>,
    pub albedo: Vec<DVec3>,
    /// π·Le.
    pub emitted: Vec<DVec3>,
}

pub struct Solution {
    /// Indirect irradiance per leaf position.
    pub irradiance: Vec<DVec3>,
    pub sweeps: u64,
    /// Power the last sweep added (reflected), over the emitted power.
    pub last_change: f64,
    /// Area-weighted mean irradiance the last sweep added.
    pub last_delta: DVec3,
    /// Every node's radiosity from the final irradiance.
    pub radiosity: Option<Radiosity>,
}

/// Links sorted by receiver, with each receiver's range.
pub struct Gathering {
    pub links: Vec<Link>,
    pub start: Vec<u32>,
}

impl Gathering {
    pub fn new(mut links: Vec<Link>, nodes: usize) -> Self {
        // Stable: each receiver keeps its links in refinement order.
        links.par_sort_by_key(|l| l.receiver);
        let mut start = vec![0u32; nodes + 1];
        for l in &links {
            start[l.receiver as usize + 1] += 1;
        }
        for i in 0..nodes {
            start[i + 1] += start[i];
        }
        Gathering { links, start }
    }
}

/// Radiosity of every node: a planar node's mean, a cluster's projected table.
pub struct Radiosity {
    pub mean: Vec<DVec3>,
    /// Per cluster: `[axis][0: +, 1: −]`.
    table: Vec<[[DVec3; 2]; 3]>,
}

pub struct Solver<'a> {
    pub h: &'a Hierarchy,
    pub faces: &'a [Face],
    pub g: &'a Gathering,
    /// Cluster index of each node (`NONE` for planar nodes).
    pub cluster: Vec<u32>,
    clusters: usize,
    /// The node of each cluster.
    cluster_node: Vec<u32>,
}

impl<'a> Solver<'a> {
    pub fn new(h: &'a Hierarchy, faces: &'a [Face], g: &'a Gathering) -> Self {
        let mut cluster_node = Vec::new();
        let cluster = h
            .nodes
            .iter()
            .enumerate()
            .map(|(i, n)| {
                if n.is_planar() {
                    NONE
                } else {
                    cluster_node.push(i as u32);
                    cluster_node.len() as u32 - 1
                }
            })
            .collect();
        Solver {
            h,
            faces,
            g,
            cluster,
            clusters: cluster_node.len(),
            cluster_node,
        }
    }

    /// Sweeps until the power a sweep adds is under `tol` of `emitted_power`, or `max_sweeps`.
    pub fn solve(
        &self,
        leaves: &Leaves,
        emitted_power: f64,
        tol: f64,
        max_sweeps: u64,
        progress: &Progress,
    ) -> Result<Solution, BakeError> {
        let nl = self.h.order.len();
        let mut e = vec![DVec3::ZERO; nl];
        let mut sol = Solution {
            irradiance: Vec::new(),
            sweeps: 0,
            last_change: 1.0,
            last_delta: DVec3::ZERO,
            radiosity: None,
        };
        let area = self.h.nodes.first().map_or(0.0, |n| n.area);
        while sol.sweeps < max_sweeps {
            progress.check()?;
            let b = self.pull(leaves, &e);
            let next = self.push(&self.gather(&b));
            // Over fixed chunks on all threads, added in chunk order: the same bits for any
            // thread count (one thread took room-245's solve a sixth of its time).
            let (change, delta) = (0..nl)
                .into_par_iter()
                .step_by(SUM_CHUNK)
                .map(|lo| {
                    let (mut change, mut delta) = (0.0, DVec3::ZERO);
                    for i in lo..(lo + SUM_CHUNK).min(nl) {
                        let (d, a) = (next[i] - e[i], self.h.area[i]);
                        change += (d.abs() * leaves.albedo[i]).element_sum() * a;
                        delta += d * a;
                    }
                    (change, delta)
                })
                .collect::<Vec<_>>()
                .into_iter()
                .fold((0.0, DVec3::ZERO), |(c, d), (x, y)| (c + x, d + y));
            sol.last_delta = delta / area.max(1e-300);
            e = next;
            sol.sweeps += 1;
            sol.last_change = change / emitted_power;
            let by_energy = (sol.last_change.max(1e-300).ln() / tol.ln()).clamp(0.0, 1.0);
            progress.set_fraction(by_energy);
            if sol.last_change < tol {
                break;
            }
        }
        sol.radiosity = Some(self.pull(leaves, &e));
        sol.irradiance = e;
        Ok(sol)
    }

    fn pull(&self, leaves: &Leaves, e: &[DVec3]) -> Radiosity {
        let h = self.h;
        // Leaves on all threads, then the nodes above them from the bottom up.
        let mut mean: Vec<DVec3> = h
            .nodes
            .par_iter()
            .with_min_len(256)
            .map(|n| {
                if !n.is_leaf() {
                    return DVec3::ZERO;
                }
                let sum: DVec3 = (n.lo as usize..n.hi as usize)
                    .map(|p| {
                        (leaves.albedo[p] * (leaves.direct[p] + e[p]) + leaves.emitted[p])
                            * h.area[p]
                    })
                    .sum();
                sum / n.area.max(1e-300)
            })
            .collect();
        let mut table = vec![[[DVec3::ZERO; 2]; 3]; self.clusters];
        for i in (0..h.nodes.len()).rev() {
            let n = &h.nodes[i];
            if n.is_leaf() {
                continue;
            }
            let [a, b] = n.kids.map(|k| k as usize);
            let (na, nb) = (&h.nodes[a], &h.nodes[b]);
            mean[i] = if n.area > 0.0 {
                (mean[a] * na.area + mean[b] * nb.area) / n.area
            } else {
                (mean[a] + mean[b]) * 0.5
            };
            let c = self.cluster[i];
            if c == NONE {
                continue;
            }
            let mut t = [[DVec3::ZERO; 2]; 3];
            for k in [a, b] {
                let kid = &h.nodes[k];
                if self.cluster[k] != NONE {
                    let kt = &table[self.cluster[k] as usize];
                    for ax in 0..3 {
                        t[ax][0] += kt[ax][0];
                        t[ax][1] += kt[ax][1];
                    }
                } else {
                    let nrm = self.faces[kid.face as usize].plane.n;
                    let p = mean[k] * kid.area;
                    for ax in 0..3 {
                        t[ax][0] += p * nrm[ax].max(0.0);
                        t[ax][1] += p * (-nrm[ax]).max(0.0);
                    }
                }
            }
            table[c as usize] = t;
        }
        Radiosity { mean, table }
    }

    /// Radiosity sent by node `s` towards `-u` (away from it, along the link back to the
    /// receiver): its mean for a planar node (the cosine is in the link), its projected
    /// table over its area for a cluster.
    pub fn sent(&self, b: &Radiosity, s: u32, u: Vec3) -> DVec3 {
        let c = self.cluster[s as usize];
        if c == NONE {
            return b.mean[s as usize];
        }
        let t = &b.table[c as usize];
        let w = -u.as_dvec3();
        (0..3)
            .map(|ax| t[ax][if w[ax] >= 0.0 { 0 } else { 1 }] * w[ax].abs())
            .sum()
    }

    /// Per node, scalar irradiance (zero for a cluster); per cluster, the irradiance
    /// arriving along each axis from either side, `[axis][0: towards +, 1: towards −]` (a
    /// vector sum would cancel light from below against light from above). Apart because a
    /// cluster's six vectors, held for every node, were 168 bytes a node each sweep (room-8328:
    /// the solve's fresh pages were much of its time).
    fn gather(&self, b: &Radiosity) -> (Vec<DVec3>, Vec<Dirs>) {
        let links =
            |r: usize| &self.g.links[self.g.start[r] as usize..self.g.start[r + 1] as usize];
        let e = (0..self.h.nodes.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|r| {
                let mut e = DVec3::ZERO;
                if self.cluster[r] == NONE {
                    for l in links(r) {
                        e += self.sent(b, l.source, l.u) * l.k as f64;
                    }
                }
                e
            })
            .collect();
        let dirs = self
            .cluster_node
            .par_iter()
            .with_min_len(64)
            .map(|&r| {
                let mut ev: Dirs = [[DVec3::ZERO; 2]; 3];
                for l in links(r as usize) {
                    let x = self.sent(b, l.source, l.u) * l.k as f64;
                    for ax in 0..3 {
                        let c = l.u[ax] as f64;
                        ev[ax][usize::from(c < 0.0)] += x * c.abs();
                    }
                }
                ev
            })
            .collect();
        (e, dirs)
    }

    /// Indirect irradiance per leaf position from every node's gathered irradiance.
    fn push(&self, (got, got_dirs): &(Vec<DVec3>, Vec<Dirs>)) -> Vec<DVec3> {
        let h = self.h;
        const ZERO: Dirs = [[DVec3::ZERO; 2]; 3];
        let dirs_of = |ds: &[Dirs], i: usize| match self.cluster[i] {
            NONE => ZERO,
            c => ds[c as usize],
        };
        let mut acc = vec![DVec3::ZERO; h.nodes.len()];
        let mut acc_dirs = vec![ZERO; self.clusters];
        if !h.nodes.is_empty() {
            acc[0] = got[0];
            if h.nodes[0].is_planar() {
                acc[0] += self.along(0, &ZERO);
            } else {
                acc_dirs[0] = got_dirs[0];
            }
        }
        for i in 0..h.nodes.len() {
            let n = &h.nodes[i];
            if n.is_leaf() {
                continue;
            }
            let above = dirs_of(&acc_dirs, i);
            for k in n.kids {
                let k = k as usize;
                let mut a = acc[i] + got[k];
                if h.nodes[k].is_planar() {
                    // Where a face begins, the clusters' vectors above become irradiance.
                    if !n.is_planar() {
                        a += self.along(k, &above);
                    }
                } else {
                    let own = dirs_of(got_dirs, k);
                    let mut d = ZERO;
                    for ax in 0..3 {
                        for side in 0..2 {
                            d[ax][side] = above[ax][side] + own[ax][side];
                        }
                    }
                    acc_dirs[self.cluster[k] as usize] = d;
                }
                acc[k] = a;
            }
        }
        // Each leaf position takes its leaf's sum, on all threads.
        h.leaf_node
            .par_iter()
            .with_min_len(4096)
            .map(|&l| acc.get(l as usize).copied().unwrap_or(DVec3::ZERO))
            .collect()
    }

    /// The irradiance a planar node `k` takes from a cluster's directional sums: light that
    /// arrives travelling towards −n_axis meets a face whose normal has a positive n_axis
    /// (exact for faces along the axes, as for the source table).
    fn along(&self, k: usize, v: &Dirs) -> DVec3 {
        let nrm = self.faces[self.h.nodes[k].face as usize].plane.n;
        (0..3)
            .map(|ax| {
                let c = nrm[ax];
                // `u` points from the receiver to the source: a source on the +axis side
                // (u_ax > 0, bucket 0) lights faces with n_ax > 0.
                v[ax][usize::from(c < 0.0)] * c.abs()
            })
            .sum()
    }
}

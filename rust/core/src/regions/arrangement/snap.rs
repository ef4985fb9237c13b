//! Vertices with snapping: a point within `snap` of an existing vertex is that vertex.

use std::collections::HashMap;

use glam::DVec2;

pub(super) struct VertexPool {
    pts: Vec<DVec2>,
    snap: f64,
    /// Hash-grid cell side; at least `snap`, so the 3×3 cells around a point hold every
    /// vertex within `snap` of it.
    cell: f64,
    grid: HashMap<(i64, i64), Vec<u32>>,
}

impl VertexPool {
    /// `extent`: the largest coordinate magnitude expected; it bounds the cell side from
    /// below so that a tiny `snap` does not make cell indices overflow.
    pub(super) fn new(snap: f64, extent: f64) -> Self {
        let cell = snap
            .max(extent * f64::EPSILON * 1024.0)
            .max(f64::MIN_POSITIVE);
        Self {
            pts: Vec::new(),
            snap,
            cell,
            grid: HashMap::new(),
        }
    }

    pub(super) fn points(&self) -> &[DVec2] {
        &self.pts
    }

    pub(super) fn into_points(self) -> Vec<DVec2> {
        self.pts
    }

    fn key(&self, p: DVec2) -> (i64, i64) {
        // `as` saturates, so a point far outside the expected extent lands in an edge
        // cell: slower, never wrong.
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    /// The vertex at `p`: the nearest existing one within `snap`, else a new one.
    pub(super) fn insert(&mut self, p: DVec2) -> u32 {
        let (i, j) = self.key(p);
        let mut best: Option<(f64, u32)> = None;
        for di in -1..=1i64 {
            for dj in -1..=1i64 {
                let k = (i.saturating_add(di), j.saturating_add(dj));
                for &v in self.grid.get(&k).into_iter().flatten() {
                    let d = (self.pts[v as usize] - p).length();
                    if d <= self.snap && best.is_none_or(|(bd, _)| d < bd) {
                        best = Some((d, v));
                    }
                }
            }
        }
        if let Some((_, v)) = best {
            return v;
        }
        let v = self.pts.len() as u32;
        self.pts.push(p);
        self.grid.entry((i, j)).or_default().push(v);
        v
    }
}

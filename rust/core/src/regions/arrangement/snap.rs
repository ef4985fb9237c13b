//! Vertices with snapping: a point within `snap` of an existing vertex is that vertex.

use glam::DVec2;

use super::int_hash::IntMap;

pub(super) struct VertexPool {
    pts: Vec<DVec2>,
    snap: f64,
    /// Hash-grid cell side; at least `snap`, so the 3×3 cells around a point hold every
    /// vertex within `snap` of it.
    cell: f64,
    /// First and last vertex of each non-empty cell; `next` links a cell's vertices in the
    /// order they came (one allocation per cell cost more than the search).
    grid: IntMap<(i64, i64), (u32, u32)>,
    next: Vec<u32>,
}

const END: u32 = u32::MAX;

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
            grid: IntMap::default(),
            next: Vec::new(),
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
                let mut v = self.grid.get(&k).map_or(END, |c| c.0);
                while v != END {
                    let d = (self.pts[v as usize] - p).length();
                    if d <= self.snap && best.is_none_or(|(bd, _)| d < bd) {
                        best = Some((d, v));
                    }
                    v = self.next[v as usize];
                }
            }
        }
        if let Some((_, v)) = best {
            return v;
        }
        let v = self.pts.len() as u32;
        self.pts.push(p);
        self.next.push(END);
        match self.grid.get_mut(&(i, j)) {
            Some(cell) => {
                self.next[cell.1 as usize] = v;
                cell.1 = v;
            }
            None => {
                self.grid.insert((i, j), (v, v));
            }
        }
        v
    }
}

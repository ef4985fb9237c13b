//! A uniform grid over 2-D boxes, for "which boxes may hold this point / meet this box"
//! queries on one receiver. Lists keep the boxes' order, so a caller that walks candidates
//! sees them in the same order as a walk over all boxes would.

use glam::DVec2;

#[derive(Debug, Clone)]
pub struct BoxGrid {
    lo: DVec2,
    inv: DVec2,
    n: [usize; 2],
    cells: Vec<Vec<u32>>,
}

impl BoxGrid {
    /// About one cell per box, at most `1 << 16` cells in all, and coarser where large
    /// boxes would otherwise fill more than a few cells each on average (memory stays linear).
    pub fn new(boxes: &[(DVec2, DVec2)]) -> Self {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for (a, b) in boxes {
            lo = lo.min(*a);
            hi = hi.max(*b);
        }
        let size = hi - lo;
        let ok = size.is_finite() && size.x > 0.0 && size.y > 0.0;
        let mut side = (boxes.len() as f64).sqrt().ceil().clamp(1.0, 256.0) as usize;
        while ok && side > 1 {
            let per = DVec2::splat(side as f64) / size;
            let span = |a: f64, b: f64, n: usize| ((b - a).max(0.0) * n as f64) as usize + 2;
            let total: usize = boxes
                .iter()
                .map(|(a, b)| span(a.x * per.x, b.x * per.x, 1) * span(a.y * per.y, b.y * per.y, 1))
                .sum();
            if total <= 8 * boxes.len() + 1024 {
                break;
            }
            side /= 2;
        }
        let n = if ok { [side, side] } else { [1, 1] };
        let inv = if ok {
            DVec2::new(n[0] as f64 / size.x, n[1] as f64 / size.y)
        } else {
            DVec2::ZERO
        };
        let mut g = BoxGrid {
            lo: if ok { lo } else { DVec2::ZERO },
            inv,
            n,
            cells: vec![Vec::new(); n[0] * n[1]],
        };
        for (i, (a, b)) in boxes.iter().enumerate() {
            let (x0, y0) = g.cell(*a);
            let (x1, y1) = g.cell(*b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    g.cells[y * g.n[0] + x].push(i as u32);
                }
            }
        }
        g
    }

    fn cell(&self, p: DVec2) -> (usize, usize) {
        let c = (p - self.lo) * self.inv;
        let clamp = |v: f64, n: usize| {
            if v >= 0.0 {
                (v as usize).min(n - 1)
            } else {
                0
            }
        };
        (clamp(c.x, self.n[0]), clamp(c.y, self.n[1]))
    }

    /// Boxes whose cells hold `p` (a superset of the boxes that contain it), in order.
    pub fn at(&self, p: DVec2) -> &[u32] {
        let (x, y) = self.cell(p);
        &self.cells[y * self.n[0] + x]
    }

    /// Boxes whose cells meet the box `lo`–`hi`, each once, in no particular order.
    pub fn meeting(&self, lo: DVec2, hi: DVec2, out: &mut Vec<u32>) {
        out.clear();
        let (x0, y0) = self.cell(lo);
        let (x1, y1) = self.cell(hi);
        for y in y0..=y1 {
            for x in x0..=x1 {
                out.extend_from_slice(&self.cells[y * self.n[0] + x]);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// Bounding box of a point list (infinite-inverted when empty).
pub fn bounds(pts: &[DVec2]) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for q in pts {
        lo = lo.min(*q);
        hi = hi.max(*q);
    }
    (lo, hi)
}

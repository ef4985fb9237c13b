//! A bounding-box tree over receiver faces for convex-volume queries ("which receivers can a
//! shadow volume reach?"). obvhs serves ray casts; this query is a different traversal
//! (a box against a set of half-spaces), small enough to own.

use glam::DVec3;

use super::Plane;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub fn empty() -> Self {
        Aabb {
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
        }
    }
    pub fn from_points(pts: &[DVec3]) -> Self {
        let mut b = Self::empty();
        for p in pts {
            b.min = b.min.min(*p);
            b.max = b.max.max(*p);
        }
        b
    }
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }
    /// Conservative: false only when the whole box is strictly outside one of the planes
    /// (beyond `eps`).
    pub fn may_touch(&self, planes: &[Plane], eps: f64) -> bool {
        planes.iter().all(|h| {
            // The box corner furthest along the plane normal.
            let c = DVec3::new(
                if h.n.x >= 0.0 { self.max.x } else { self.min.x },
                if h.n.y >= 0.0 { self.max.y } else { self.min.y },
                if h.n.z >= 0.0 { self.max.z } else { self.min.z },
            );
            h.dist(c) >= -eps
        })
    }
}

#[derive(Debug, Clone)]
struct Node {
    bounds: Aabb,
    /// Leaf: items[start..start+count]; inner: children at `start` and `start + 1`.
    start: u32,
    count: u32,
}

/// Static tree over item boxes, median split on the longest axis.
#[derive(Debug, Clone)]
pub struct BoxTree {
    nodes: Vec<Node>,
    items: Vec<u32>,
    boxes: Vec<Aabb>,
}

const LEAF: usize = 4;

impl BoxTree {
    pub fn new(boxes: Vec<Aabb>) -> Self {
        let mut items: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF + 1);
        if !boxes.is_empty() {
            nodes.push(Node {
                bounds: Aabb::empty(),
                start: 0,
                count: 0,
            });
            build(&boxes, &mut items, &mut nodes, 0, 0, boxes.len());
        }
        BoxTree {
            nodes,
            items,
            boxes,
        }
    }

    /// Items whose box may touch the convex volume given by `planes` (all `dist >= 0`).
    pub fn query_volume(&self, planes: &[Plane], eps: f64, out: &mut Vec<u32>) {
        // The same walk as `any_in_volume`, never stopping early.
        self.any_in_volume(planes, eps, |it| {
            out.push(it);
            false
        });
    }

    /// Whether `keep` holds for some item whose box may touch the convex volume given by
    /// `planes` (as [`query_volume`](Self::query_volume)); stops at the first.
    pub fn any_in_volume(
        &self,
        planes: &[Plane],
        eps: f64,
        mut keep: impl FnMut(u32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i];
            if !n.bounds.may_touch(planes, eps) {
                continue;
            }
            if n.count > 0 {
                let items = &self.items[n.start as usize..(n.start + n.count) as usize];
                if items
                    .iter()
                    .any(|&it| self.boxes[it as usize].may_touch(planes, eps) && keep(it))
                {
                    return true;
                }
            } else {
                stack.push(n.start as usize);
                stack.push(n.start as usize + 1);
            }
        }
        false
    }
}

fn build(
    boxes: &[Aabb],
    items: &mut [u32],
    nodes: &mut Vec<Node>,
    node: usize,
    lo: usize,
    hi: usize,
) {
    let mut b = Aabb::empty();
    for &it in &items[lo..hi] {
        b = b.union(&boxes[it as usize]);
    }
    nodes[node].bounds = b;
    if hi - lo <= LEAF {
        nodes[node].start = lo as u32;
        nodes[node].count = (hi - lo) as u32;
        return;
    }
    let ext = b.max - b.min;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = (lo + hi) / 2;
    items[lo..hi].select_nth_unstable_by(mid - lo, |a, c| {
        boxes[*a as usize].center()[axis].total_cmp(&boxes[*c as usize].center()[axis])
    });
    let left = nodes.len();
    nodes.push(Node {
        bounds: Aabb::empty(),
        start: 0,
        count: 0,
    });
    nodes.push(Node {
        bounds: Aabb::empty(),
        start: 0,
        count: 0,
    });
    nodes[node].start = left as u32;
    nodes[node].count = 0;
    build(boxes, items, nodes, left, lo, mid);
    build(boxes, items, nodes, left + 1, mid, hi);
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn volume_query_matches_brute_force() {
        let mut s = 0x1234_5678_9abc_def0u64;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let boxes: Vec<Aabb> = (0..500)
            .map(|_| {
                let c = DVec3::new(rnd(), rnd(), rnd()) * 10.0;
                let h = DVec3::new(rnd(), rnd(), rnd()) * 0.5;
                Aabb {
                    min: c - h,
                    max: c + h,
                }
            })
            .collect();
        let tree = BoxTree::new(boxes.clone());
        let planes = [
            Plane::from_point_normal(DVec3::splat(3.0), DVec3::new(1., 0.3, 0.)),
            Plane::from_point_normal(DVec3::splat(6.0), DVec3::new(-1., 0., -0.2)),
        ];
        let mut got = Vec::new();
        tree.query_volume(&planes, 0.0, &mut got);
        got.sort();
        let want: Vec<u32> = (0..500)
            .filter(|&i| boxes[i as usize].may_touch(&planes, 0.0))
            .collect();
        assert_eq!(got, want);
        assert!(want.len() > 10 && want.len() < 400);
    }
}

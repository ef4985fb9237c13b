//! Where each corner of a triangle reads the light while refinement runs, on the
//! triangulation itself: the vertex's position, except on D0 rows (a hair into the sector of
//! triangles on the triangle's side) and at D0 corners (a hair into the triangle), exactly as
//! extraction will place the element vertices (`sides`), so that every value read here is the
//! element vertex's value afterwards.

use glam::DVec2;
use spade::handles::FixedVertexHandle;
use spade::Triangulation;

use super::sides::{nudge, sides, D0Test, Edge, Face};
use super::Cdt;
use crate::regions::Region;
use crate::scene::Tolerances;

/// What a vertex is to the D0 split.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Unknown,
    /// No D0 edge meets it: one value.
    Plain,
    /// On a straight D0 row: one value per side.
    Row,
    /// Where D0 rows end or turn: one value per triangle.
    Corner,
}

/// The triangulation with its faces' components (`Label`) and their regions.
pub(super) struct View<'a> {
    pub cdt: &'a Cdt,
    pub shift: DVec2,
    pub tol: &'a Tolerances,
    pub regions: &'a [Region],
    pub outside: &'a [bool],
    pub test: &'a D0Test<'a>,
}

impl View<'_> {
    pub fn label(&self, f: Face) -> u32 {
        self.cdt.face(f).data().0
    }

    /// In the receiver (not between its boundary and the frame).
    pub fn inside(&self, f: Face) -> bool {
        let l = self.label(f);
        l != u32::MAX && !self.outside[l as usize]
    }

    pub fn position(&self, v: FixedVertexHandle) -> DVec2 {
        let p = self.cdt.vertex(v).position();
        DVec2::new(p.x, p.y) - self.shift
    }

    pub fn vertices(&self, f: Face) -> [FixedVertexHandle; 3] {
        self.cdt.face(f).vertices().map(|v| v.fix())
    }

    pub fn triangle(&self, f: Face) -> [DVec2; 3] {
        self.vertices(f).map(|v| self.position(v))
    }

    pub fn is_d0(&self, e: Edge<'_>) -> bool {
        let (Some(fa), Some(fb)) = (e.face().as_inner(), e.rev().face().as_inner()) else {
            return false;
        };
        let (fa, fb) = (fa.fix(), fb.fix());
        if !self.inside(fa) || !self.inside(fb) {
            return false;
        }
        self.test
            .is_d0(e, self.label(fa), self.label(fb), self.regions)
    }

    pub fn kind(&self, v: FixedVertexHandle) -> Kind {
        match sides(self.cdt, v, self.shift, &|e| self.is_d0(e), &|f| {
            self.inside(f)
        }) {
            None => Kind::Plain,
            Some(s) if s.straight => Kind::Row,
            Some(_) => Kind::Corner,
        }
    }

    /// Faces across `f`'s edges in its own region: same component, not across a D0 edge.
    pub fn neighbours(&self, f: Face) -> impl Iterator<Item = Face> + '_ {
        let l = self.label(f);
        self.cdt
            .face(f)
            .adjacent_edges()
            .into_iter()
            .filter_map(move |e| {
                let n = e.rev().face().as_inner()?.fix();
                (self.label(n) == l && !(e.is_constraint_edge() && self.is_d0(e))).then_some(n)
            })
    }

    /// Where corner `k` of `f` (of kind `kind`) reads the light.
    pub fn reading(&self, f: Face, k: usize, kind: Kind) -> DVec2 {
        let v = self.vertices(f)[k];
        let p = self.position(v);
        match kind {
            Kind::Unknown | Kind::Plain => p,
            Kind::Row => self
                .sector(v, f)
                .and_then(|sector| nudge(p, sector.iter().map(|&g| self.triangle(g)), self.tol))
                .unwrap_or(p),
            Kind::Corner => nudge(p, std::iter::once(self.triangle(f)), self.tol).unwrap_or(p),
        }
    }

    /// The components whose regions the reading point of corner `k` of `f` lies in or
    /// borders: those of the faces on its side of the vertex.
    pub fn reading_labels(&self, f: Face, k: usize, kind: Kind) -> Vec<u32> {
        let v = self.vertices(f)[k];
        let mut labels: Vec<u32> = Vec::new();
        let mut add = |g: Face| {
            let l = self.label(g);
            if !labels.contains(&l) {
                labels.push(l);
            }
        };
        match kind {
            Kind::Unknown | Kind::Plain => {
                for e in self.cdt.vertex(v).out_edges() {
                    if let Some(g) = e.face().as_inner() {
                        if self.inside(g.fix()) {
                            add(g.fix());
                        }
                    }
                }
            }
            Kind::Row => match self.sector(v, f) {
                Some(sector) => sector.into_iter().for_each(add),
                None => add(f),
            },
            Kind::Corner => add(f),
        }
        labels
    }

    /// The faces on `f`'s side of the D0 row through `v`.
    fn sector(&self, v: FixedVertexHandle, f: Face) -> Option<Vec<Face>> {
        let s = sides(self.cdt, v, self.shift, &|e| self.is_d0(e), &|g| {
            self.inside(g)
        })?;
        s.sectors.into_iter().find(|sector| sector.contains(&f))
    }
}

//! Exact texel integration: convex UV pieces carrying a linear colour are cut along the texel
//! grid, and each cell's part is integrated in closed form.
//!
//! A linear field over a convex polygon integrates to the sum over a fan of triangles of
//! `area · mean of the three corner values`; clipping a polygon whose vertices carry a linear
//! attribute and interpolating the attribute at the cut points keeps it exact. So every texel
//! gets `∫ colour dA` and `∫ dA` over the surface its square covers, with no sampling.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::progress::Progress;
use crate::BakeError;

/// A polygon vertex carrying the (linear) colour field's value there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Attr {
    pub p: DVec2,
    pub c: DVec3,
}

/// Convex polygons with attributes, stored flat: piece `k` is
/// `verts[start[k] as usize..start[k + 1] as usize]`, in texel units (texel `(i, j)` is the
/// square `[i, i+1] × [j, j+1]`).
#[derive(Debug, Default)]
pub(crate) struct Pieces {
    pub verts: Vec<Attr>,
    pub start: Vec<u32>,
}

impl Pieces {
    pub fn new() -> Self {
        Pieces {
            verts: Vec::new(),
            start: vec![0],
        }
    }
    pub fn push(&mut self, poly: &[Attr]) {
        self.verts.extend_from_slice(poly);
        self.start.push(self.verts.len() as u32);
    }
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }
    pub fn get(&self, k: usize) -> &[Attr] {
        &self.verts[self.start[k] as usize..self.start[k + 1] as usize]
    }
    pub fn append(&mut self, other: Pieces) {
        let base = self.verts.len() as u32;
        self.verts.extend(other.verts);
        self.start.extend(other.start[1..].iter().map(|s| s + base));
    }
}

/// Keeps the part of convex `poly` where `f(p) ≥ 0` for an affine `f`; the colour is
/// interpolated at the cut, which is exact for a linear field.
pub(crate) fn clip(poly: &[Attr], f: impl Fn(DVec2) -> f64, out: &mut Vec<Attr>) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        let (da, db) = (f(a.p), f(b.p));
        if da >= 0.0 {
            out.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            out.push(lerp(a, b, da / (da - db)));
        }
    }
}

#[inline]
fn lerp(a: Attr, b: Attr, t: f64) -> Attr {
    Attr {
        p: a.p + (b.p - a.p) * t,
        c: a.c + (b.c - a.c) * t,
    }
}

/// Splits convex `poly` at the line `p[axis] = t` into the part below (`lo`) and above
/// (`hi`). The cut point is placed exactly on the line so neighbouring cells share it.
fn split(poly: &[Attr], axis: usize, t: f64, lo: &mut Vec<Attr>, hi: &mut Vec<Attr>) {
    lo.clear();
    hi.clear();
    let n = poly.len();
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        let (da, db) = (a.p[axis] - t, b.p[axis] - t);
        if da <= 0.0 {
            lo.push(a);
        }
        if da >= 0.0 {
            hi.push(a);
        }
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let mut m = lerp(a, b, da / (da - db));
            m.p[axis] = t;
            lo.push(m);
            hi.push(m);
        }
    }
}

/// `(∫ colour dA, ∫ dA)` over a convex polygon whose colour is linear. The area is returned
/// unsigned whatever the winding.
pub(crate) fn integrate(poly: &[Attr]) -> (DVec3, f64) {
    if poly.len() < 3 {
        return (DVec3::ZERO, 0.0);
    }
    let o = poly[0];
    let mut sum = DVec3::ZERO;
    let mut area = 0.0;
    for w in poly[1..].windows(2) {
        let a = 0.5 * (w[0].p - o.p).perp_dot(w[1].p - o.p);
        area += a;
        sum += (o.c + w[0].c + w[1].c) * (a / 3.0);
    }
    if area < 0.0 {
        (-sum, -area)
    } else {
        (sum, area)
    }
}

/// Rows of texels handled by one task: keeps each task's buffer small at any resolution.
const BAND: usize = 8;

/// Per texel `[∫r, ∫g, ∫b, ∫dA]` (row-major, row 0 at v = 0) over all pieces, clipped to
/// the `width × height` image. Bands of rows run in parallel, each owning its rows; each
/// band's sums go through `finish` at once, so the f64 sums of the whole image never exist
/// together (at 16384² they would take 8.6 GB).
pub(crate) fn accumulate<T: Send>(
    pieces: &Pieces,
    width: usize,
    height: usize,
    progress: &Progress,
    finish: impl Fn(Vec<[f64; 4]>) -> T + Sync,
) -> Result<Vec<T>, BakeError> {
    let n_bands = height.div_ceil(BAND);
    let mut in_band: Vec<Vec<u32>> = vec![Vec::new(); n_bands];
    for k in 0..pieces.len() {
        let (lo, hi) = y_range(pieces.get(k));
        if !(hi > 0.0 && lo < height as f64) {
            continue;
        }
        let b0 = (lo.max(0.0) as usize / BAND).min(n_bands - 1);
        let b1 = ((hi.min(height as f64) as usize) / BAND).min(n_bands - 1);
        for b in &mut in_band[b0..=b1] {
            b.push(k as u32);
        }
    }
    in_band
        .par_iter()
        .enumerate()
        .map(|(b, list)| {
            progress.check()?;
            let r0 = b * BAND;
            let r1 = (r0 + BAND).min(height);
            let mut acc = vec![[0.0; 4]; (r1 - r0) * width];
            let mut s = Scratch::default();
            for &k in list {
                band_piece(pieces.get(k as usize), r0, r1, width, &mut acc, &mut s);
            }
            Ok(finish(acc))
        })
        .collect()
}

#[derive(Default)]
struct Scratch {
    rest: Vec<Attr>,
    row: Vec<Attr>,
    lo: Vec<Attr>,
    hi: Vec<Attr>,
    cell: Vec<Attr>,
    tmp: Vec<Attr>,
}

fn y_range(poly: &[Attr]) -> (f64, f64) {
    poly.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
            (lo.min(a.p.y), hi.max(a.p.y))
        })
}

/// Adds one piece's share of rows `r0..r1` into the band buffer `acc`.
fn band_piece(
    poly: &[Attr],
    r0: usize,
    r1: usize,
    width: usize,
    acc: &mut [[f64; 4]],
    s: &mut Scratch,
) {
    // The part of the piece inside the band.
    s.split_keep(poly, 1, r0 as f64, true);
    let band_part = std::mem::take(&mut s.rest);
    s.split_keep(&band_part, 1, r1 as f64, false);
    let (ylo, yhi) = y_range(&s.rest);
    if s.rest.len() < 3 {
        return;
    }
    let j0 = (ylo.floor().max(r0 as f64) as usize).min(r1 - 1);
    let j1 = (yhi.ceil().min(r1 as f64) as usize).max(j0 + 1);
    for j in j0..j1 {
        // Cut off row j; what is above stays in `rest` for the next row.
        split(&s.rest, 1, (j + 1) as f64, &mut s.lo, &mut s.hi);
        std::mem::swap(&mut s.row, &mut s.lo);
        std::mem::swap(&mut s.rest, &mut s.hi);
        if s.row.len() < 3 {
            continue;
        }
        let (xlo, xhi) = s
            .row
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
                (lo.min(a.p.x), hi.max(a.p.x))
            });
        if !(xhi > 0.0 && xlo < width as f64) {
            continue;
        }
        split(&s.row, 0, 0.0, &mut s.lo, &mut s.hi);
        std::mem::swap(&mut s.tmp, &mut s.hi);
        let i0 = (xlo.floor().max(0.0) as usize).min(width - 1);
        let i1 = (xhi.ceil().min(width as f64) as usize).max(i0 + 1);
        for i in i0..i1 {
            split(&s.tmp, 0, (i + 1) as f64, &mut s.cell, &mut s.hi);
            std::mem::swap(&mut s.tmp, &mut s.hi);
            let (c, a) = integrate(&s.cell);
            if a > 0.0 {
                let t = &mut acc[(j - r0) * width + i];
                t[0] += c.x;
                t[1] += c.y;
                t[2] += c.z;
                t[3] += a;
            }
        }
    }
    s.rest = band_part;
}

impl Scratch {
    /// `rest` ← the part of `poly` above (`keep_hi`) or below the line `p[axis] = t`.
    fn split_keep(&mut self, poly: &[Attr], axis: usize, t: f64, keep_hi: bool) {
        split(poly, axis, t, &mut self.lo, &mut self.hi);
        self.rest.clear();
        self.rest
            .extend_from_slice(if keep_hi { &self.hi } else { &self.lo });
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn sums(p: &Pieces, w: usize, h: usize) -> Vec<[f64; 4]> {
        let bands = accumulate(p, w, h, &Progress::new(), |b| b).unwrap();
        bands.into_iter().flatten().collect()
    }

    fn attr(x: f64, y: f64, f: impl Fn(f64, f64) -> DVec3) -> Attr {
        Attr {
            p: DVec2::new(x, y),
            c: f(x, y),
        }
    }

    #[test]
    fn linear_field_over_covered_texels_is_its_centre_value() {
        let f = |x: f64, y: f64| DVec3::new(1.0 + 0.3 * x - 0.2 * y, 2.0 * y, 0.5);
        let mut p = Pieces::new();
        // A triangle covering many whole texels, partly outside the image.
        p.push(&[attr(-1.3, 0.2, f), attr(9.7, 1.1, f), attr(2.2, 11.4, f)]);
        let acc = sums(&p, 8, 8);
        let mut whole = 0;
        for j in 0..8 {
            for i in 0..8 {
                let t = acc[j * 8 + i];
                if (t[3] - 1.0).abs() < 1e-12 {
                    whole += 1;
                    let want = f(i as f64 + 0.5, j as f64 + 0.5);
                    let got = DVec3::new(t[0], t[1], t[2]);
                    assert!((got - want).length() < 1e-12, "{i},{j}: {got} vs {want}");
                }
            }
        }
        assert!(whole > 10);
    }

    #[test]
    fn areas_add_up_to_the_clipped_piece() {
        let f = |_: f64, _: f64| DVec3::ONE;
        let mut p = Pieces::new();
        // Wholly inside a 20×20 image, not aligned with the grid, spanning bands.
        let tri = [attr(0.3, 0.7, f), attr(17.9, 3.3, f), attr(5.5, 19.2, f)];
        p.push(&tri);
        let (_, want) = integrate(&tri);
        let acc = sums(&p, 20, 20);
        let got: f64 = acc.iter().map(|t| t[3]).sum();
        assert!((got - want).abs() < 1e-10 * want, "{got} vs {want}");
        // Every texel's colour integral equals its area for a field of ones.
        for t in &acc {
            assert!((t[0] - t[3]).abs() < 1e-12);
        }
    }

    #[test]
    fn a_piece_inside_one_texel_lands_there_whole() {
        let f = |x: f64, y: f64| DVec3::splat(x + y);
        let mut p = Pieces::new();
        let tri = [attr(3.1, 2.1, f), attr(3.9, 2.2, f), attr(3.5, 2.8, f)];
        p.push(&tri);
        let acc = sums(&p, 5, 5);
        let (c, a) = integrate(&tri);
        let t = acc[2 * 5 + 3];
        assert!((t[3] - a).abs() < 1e-15 && (t[0] - c.x).abs() < 1e-15);
        assert_eq!(acc.iter().filter(|t| t[3] > 0.0).count(), 1);
    }
}

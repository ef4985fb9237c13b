//! Margins: texels no surface touches take the mean of their filled neighbours, one ring a
//! pass, for `margin` passes (Cycles' "Extend" margin). Mip-mapping and bilinear filtering
//! in a game engine then read sensible colours just outside a UV island.

use rayon::prelude::*;

/// Fills up to `margin` rings of empty texels around the filled ones. `rgb` is row-major
/// `width × height`, `filled` says which texels hold a value; both are updated.
pub(crate) fn dilate(
    rgb: &mut [[f32; 3]],
    filled: &mut [bool],
    width: usize,
    height: usize,
    margin: u32,
) {
    for _ in 0..margin {
        let (src, was) = (rgb.to_vec(), filled.to_vec());
        let grown: Vec<Option<[f32; 3]>> = (0..width * height)
            .into_par_iter()
            .map(|t| {
                if was[t] {
                    return None;
                }
                let (i, j) = ((t % width) as isize, (t / width) as isize);
                let mut sum = [0.0f64; 3];
                let mut n = 0u32;
                for dj in -1..=1 {
                    for di in -1..=1 {
                        let (x, y) = (i + di, j + dj);
                        if x < 0 || y < 0 || x >= width as isize || y >= height as isize {
                            continue;
                        }
                        let u = y as usize * width + x as usize;
                        if was[u] {
                            for c in 0..3 {
                                sum[c] += src[u][c] as f64;
                            }
                            n += 1;
                        }
                    }
                }
                (n > 0).then(|| sum.map(|s| (s / n as f64) as f32))
            })
            .collect();
        let mut any = false;
        for (t, g) in grown.into_iter().enumerate() {
            if let Some(c) = g {
                rgb[t] = c;
                filled[t] = true;
                any = true;
            }
        }
        if !any {
            break;
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn grows_one_ring_a_pass_and_stops_at_the_margin() {
        let (w, h) = (9, 9);
        let mut rgb = vec![[0.0f32; 3]; w * h];
        let mut filled = vec![false; w * h];
        rgb[4 * w + 4] = [1.0, 2.0, 3.0];
        filled[4 * w + 4] = true;
        dilate(&mut rgb, &mut filled, w, h, 2);
        for j in 0..h {
            for i in 0..w {
                let ring = (i as isize - 4).abs().max((j as isize - 4).abs());
                assert_eq!(filled[j * w + i], ring <= 2, "{i},{j}");
                if ring <= 2 {
                    assert_eq!(rgb[j * w + i], [1.0, 2.0, 3.0]);
                }
            }
        }
    }

    #[test]
    fn an_empty_texel_takes_the_mean_of_its_filled_neighbours() {
        let (w, h) = (3, 1);
        let mut rgb = vec![[1.0, 0.0, 0.0], [0.0; 3], [3.0, 0.0, 0.0]];
        let mut filled = vec![true, false, true];
        dilate(&mut rgb, &mut filled, w, h, 1);
        assert_eq!(rgb[1], [2.0, 0.0, 0.0]);
        // Margin 0 leaves the image alone.
        let mut filled = vec![true, false, true];
        let mut rgb2 = vec![[1.0, 0.0, 0.0], [0.0; 3], [3.0, 0.0, 0.0]];
        dilate(&mut rgb2, &mut filled, w, h, 0);
        assert!(!filled[1]);
    }
}

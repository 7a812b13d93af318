//! Uniform-grid helpers shared by the spatial indexes (hatch ordering, boundary distances).

/// The cells (x, y) at Chebyshev distance exactly `r` from (cx, cy) that lie inside an
/// `nx` × `ny` grid: the ring searched in step `r` of a nearest-neighbour search.
pub fn ring_cells(cx: i64, cy: i64, r: i64, nx: i64, ny: i64) -> impl Iterator<Item = (i64, i64)> {
    ((cy - r)..=(cy + r))
        .filter(move |y| (0..ny).contains(y))
        .flat_map(move |y| {
            // Full rows at the ring's top and bottom, only the two ends in between.
            let step = if y == cy - r || y == cy + r {
                1
            } else {
                (2 * r).max(1)
            };
            (0..)
                .map(move |k| cx - r + k * step)
                .take_while(move |&x| x <= cx + r)
                .filter(move |x| (0..nx).contains(x))
                .map(move |x| (x, y))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_cover_the_grid_once() {
        let (nx, ny) = (7, 5);
        let mut seen = vec![0; (nx * ny) as usize];
        for r in 0..10 {
            for (x, y) in ring_cells(2, 3, r, nx, ny) {
                assert_eq!((x - 2).abs().max((y - 3).abs()), r);
                seen[(y * nx + x) as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
    }
}

//! Uniform grids over segments: which cells a segment passes within a margin of, and a bucket
//! grid of segment ids built from that.
//!
//! The traversal is the column-by-column form of Amanatides–Woo: rather than stepping cell to
//! cell along the segment, it walks the columns the segment spans and, per column, the rows
//! between the segment's lowest and highest point in that column. Widened by a margin `eps` on
//! every side it is conservative (every cell the segment passes within `eps` of, in the L∞
//! sense, is visited) and costs one step per visited cell plus one per column, with no
//! special cases for segments along grid lines or through corners.

use glam::DVec2;

/// Calls `visit(column, row)` for every cell of an `nx` × `ny` grid (cell `(c, r)` spans
/// `[c, c+1] × [r, r+1]` in grid coordinates) that the segment `a`–`b` (grid coordinates, finite)
/// passes within `eps` of; cells outside the grid are skipped.
pub(crate) fn for_each_cell(
    a: DVec2,
    b: DVec2,
    eps: f64,
    nx: usize,
    ny: usize,
    mut visit: impl FnMut(usize, usize),
) {
    let (lo, hi) = (a.min(b) - eps, a.max(b) + eps);
    if nx == 0 || ny == 0 || hi.x < 0.0 || hi.y < 0.0 || lo.x > nx as f64 || lo.y > ny as f64 {
        return;
    }
    let d = b - a;
    let (c0, c1) = (cell_index(lo.x, nx), cell_index(hi.x, nx));
    if c0 == c1 && cell_index(lo.y, ny) == cell_index(hi.y, ny) {
        // Most segments of a fine polyline: one cell, no walk.
        visit(c0, cell_index(lo.y, ny));
        return;
    }
    for c in c0..=c1 {
        // The part of the segment whose x lies in this column, widened by eps.
        let (x0, x1) = ((c as f64 - eps).max(lo.x), (c as f64 + 1.0 + eps).min(hi.x));
        let (y0, y1) = if d.x == 0.0 {
            (a.y.min(b.y), a.y.max(b.y))
        } else {
            let y_at = |x: f64| a.y + ((x - a.x) / d.x).clamp(0.0, 1.0) * d.y;
            let (ya, yb) = (y_at(x0), y_at(x1));
            (ya.min(yb), ya.max(yb))
        };
        if y1 + eps < 0.0 || y0 - eps > ny as f64 {
            continue;
        }
        for r in cell_index(y0 - eps, ny)..=cell_index(y1 + eps, ny) {
            visit(c, r);
        }
    }
}

/// `floor(x)` clamped to `0..n` (`n > 0`): clamping first makes the truncating cast a floor,
/// without the libm call `f64::floor` costs on baseline x86-64. Monotone in `x`.
#[must_use]
pub(crate) fn cell_index(x: f64, n: usize) -> usize {
    x.clamp(0.0, (n - 1) as f64) as usize
}

/// Segment ids bucketed by the cells of a uniform grid they pass within a margin of, in
/// compressed rows (`start[cell]..start[cell + 1]` indexes `items`), ids ascending per cell.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SegGrid {
    origin: DVec2,
    /// Cells per parameter unit (the same along both axes: the cells are square).
    scale: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl SegGrid {
    /// Buckets `segs` over the box `lo`..`hi` in at most about `2 * segs.len()` square cells,
    /// each segment into every cell it passes within `margin` (parameter units) of: so all
    /// segments within `margin` of a point are in that point's cell. Cells grow when the
    /// segments are long, so that the bucket entries stay about 5 per segment.
    #[must_use]
    pub(crate) fn new(segs: &[[DVec2; 2]], lo: DVec2, hi: DVec2, margin: f64) -> Self {
        let size = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
        let count = segs.len().max(1) as f64;
        let l1: f64 = segs.iter().map(|s| (s[1] - s[0]).abs().element_sum()).sum();
        let cell = (size.x * size.y / (2.0 * count))
            .sqrt()
            .max(l1 / (4.0 * count))
            .max(size.x.max(size.y) / 2048.0);
        let n = |extent: f64| ((extent / cell).ceil() as usize).clamp(1, 2048);
        let (nx, ny) = (n(size.x), n(size.y));
        let scale = 1.0 / cell;
        let mut grid = Self {
            origin: lo,
            scale,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: Vec::new(),
        };
        let eps = margin * scale;
        for s in segs {
            let (a, b) = (grid.to_grid(s[0]), grid.to_grid(s[1]));
            for_each_cell(a, b, eps, nx, ny, |c, r| grid.start[c * ny + r + 1] += 1);
        }
        for k in 1..grid.start.len() {
            grid.start[k] += grid.start[k - 1];
        }
        let mut fill = grid.start.clone();
        grid.items = vec![0; grid.start[nx * ny] as usize];
        for (id, s) in segs.iter().enumerate() {
            let (a, b) = (grid.to_grid(s[0]), grid.to_grid(s[1]));
            for_each_cell(a, b, eps, nx, ny, |c, r| {
                let slot = &mut fill[c * ny + r];
                grid.items[*slot as usize] = id as u32;
                *slot += 1;
            });
        }
        grid
    }

    #[must_use]
    fn to_grid(&self, p: DVec2) -> DVec2 {
        (p - self.origin) * self.scale
    }

    /// Number of cells.
    #[must_use]
    pub(crate) fn cell_count(&self) -> usize {
        self.nx * self.ny
    }

    /// The ids in cell number `cell` (column-major: `column * ny + row`).
    #[must_use]
    pub(crate) fn cell(&self, cell: usize) -> &[u32] {
        let (Some(&s), Some(&e)) = (self.start.get(cell), self.start.get(cell + 1)) else {
            return &[];
        };
        self.items.get(s as usize..e as usize).unwrap_or(&[])
    }

    /// The ids in the cell containing `p` (clamped into the grid).
    #[must_use]
    pub(crate) fn near(&self, p: DVec2) -> &[u32] {
        let g = self.to_grid(p);
        let (c, r) = (cell_index(g.x, self.nx), cell_index(g.y, self.ny));
        self.cell(c * self.ny + r)
    }
}

//! A trimmed surface's coverage of its sample grid packed for the fragment shader's inside
//! test (`shaders/trim.glsl`): a header, the cell words, the boundary-cell records and the
//! cell-local segments (`geom::trim::coverage` documents each), and the block classes of
//! every display level of detail, which let a triangle wholly inside skip the test and one
//! wholly outside be discarded at once.

use crate::geom::trim::{CellClass, Coverage};

/// Words before the cell words: the offsets of the cells, records, segments and level table,
/// the sample cell rows and columns, and the mask cells per sample cell and direction.
const HEADER: usize = 7;

/// Strides 1, 2, 4, 8, 16 per direction: the display level of detail's (`lod::MAX_STRIDE`).
pub const STRIDE_LEVELS: u32 = 5;

/// Block classes, 2 bits each: outside, inside, mixed (the cells of a block are not all
/// alike, or the boundary crosses one).
const OUTSIDE: u8 = 0;
const INSIDE: u8 = 1;
const MIXED: u8 = 2;

/// The mask words of `c`, a coverage of the sample grid with every cell cut `refine` times
/// per direction (a power of two; see `editor::TrimCoverage`).
#[must_use]
pub fn mask_words(c: &Coverage, refine: usize) -> Vec<u32> {
    let refine = refine.max(1);
    let (mu, mv) = c.samples();
    let (cells, records, segments) = (c.gpu_cells(), c.gpu_records(), c.gpu_segments());
    let at_records = HEADER + cells.len();
    let at_segments = at_records + 4 * records.len();
    let at_levels = at_segments + 4 * segments.len();
    let word = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let mut out = Vec::with_capacity(at_levels + 32);
    out.extend([
        word(HEADER),
        word(at_records),
        word(at_segments),
        word(at_levels),
        word(mu.saturating_sub(1) / refine),
        word(mv.saturating_sub(1) / refine),
        word(refine),
    ]);
    out.extend_from_slice(cells);
    out.extend(records.iter().flatten());
    out.extend(segments.iter().flatten().map(|x| x.to_bits()));
    append_levels(c, refine, &mut out);
    out
}

/// The level table (one word per (row level, column level): the offset of its packed
/// classes) and the packed classes of every level, 16 blocks a word, row-major: blocks of
/// sample cells, each a merge of its `refine`² mask cells.
fn append_levels(c: &Coverage, refine: usize, out: &mut Vec<u32>) {
    let (mu, mv) = c.samples();
    let (mut ncu, mut ncv) = (mu.saturating_sub(1), mv.saturating_sub(1));
    let mut fine: Vec<u8> = (0..ncu * ncv)
        .map(|k| match c.cell_class(k / ncv.max(1), k % ncv.max(1)) {
            CellClass::Outside => OUTSIDE,
            CellClass::Inside => INSIDE,
            CellClass::Boundary => MIXED,
        })
        .collect();
    let mut k = refine;
    while k > 1 {
        (fine, ncu) = halve_rows(&fine, ncu, ncv);
        (fine, ncv) = halve_cols(&fine, ncu, ncv);
        k /= 2;
    }
    let table = out.len();
    let n = STRIDE_LEVELS as usize;
    out.extend(std::iter::repeat_n(0, n * n));
    // Rows coarsened level by level, then each row level's columns.
    let mut rows = (fine, ncu);
    for lr in 0..n {
        if lr > 0 {
            rows = halve_rows(&rows.0, rows.1, ncv);
        }
        let mut level = (rows.0.clone(), ncv);
        for lc in 0..n {
            if lc > 0 {
                level = halve_cols(&level.0, rows.1, level.1);
            }
            out[table + lr * n + lc] = u32::try_from(out.len()).unwrap_or(u32::MAX);
            for chunk in level.0.chunks(16) {
                let w = chunk
                    .iter()
                    .enumerate()
                    .fold(0u32, |w, (k, &cls)| w | (u32::from(cls) << (2 * k)));
                out.push(w);
            }
        }
    }
}

/// The same class twice stays; two different ones are mixed.
fn merge(a: u8, b: u8) -> u8 {
    if a == b { a } else { MIXED }
}

/// `rows × cols` classes with pairs of rows merged (an odd last row stays alone).
fn halve_rows(classes: &[u8], rows: usize, cols: usize) -> (Vec<u8>, usize) {
    let half = rows.div_ceil(2);
    let mut out = Vec::with_capacity(half * cols);
    for r in 0..half {
        for j in 0..cols {
            let a = classes[2 * r * cols + j];
            let b = classes
                .get((2 * r + 1) * cols + j)
                .filter(|_| 2 * r + 1 < rows);
            out.push(b.map_or(a, |&b| merge(a, b)));
        }
    }
    (out, half)
}

/// `rows × cols` classes with pairs of columns merged.
fn halve_cols(classes: &[u8], rows: usize, cols: usize) -> (Vec<u8>, usize) {
    let half = cols.div_ceil(2);
    let mut out = Vec::with_capacity(rows * half);
    for r in 0..rows {
        for c in 0..half {
            let a = classes[r * cols + 2 * c];
            let b = (2 * c + 1 < cols).then(|| classes[r * cols + 2 * c + 1]);
            out.push(b.map_or(a, |b| merge(a, b)));
        }
    }
    (out, half)
}

/// The two words of a mask's table entries, one per level of detail in [`level_entry`]'s
/// order: the vertices per grid row with the row and column levels (bits 24 and 28 on), and
/// the surface's first vertex.
#[must_use]
pub fn mask_entries(cols: u32, first_vertex: u32) -> Vec<[u32; 2]> {
    (0..STRIDE_LEVELS)
        .flat_map(|lr| {
            (0..STRIDE_LEVELS).map(move |lc| [cols | (lr << 24) | (lc << 28), first_vertex])
        })
        .collect()
}

/// The table entry of a mask drawn at `stride` (rows, columns; powers of two up to 16).
#[must_use]
pub fn level_entry(mask: u32, stride: [u32; 2]) -> u32 {
    let level = |s: u32| s.max(1).trailing_zeros().min(STRIDE_LEVELS - 1);
    mask * STRIDE_LEVELS * STRIDE_LEVELS + level(stride[0]) * STRIDE_LEVELS + level(stride[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::trim::{LoopInput, Role, Tolerances, TrimRegions};
    use glam::DVec2;

    /// A disc with a square hole on [0, 1]², its coverage of an `n × m` sample grid.
    fn coverage(n: usize, m: usize) -> Coverage {
        let disc: Vec<DVec2> = (0..=64)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 64.0;
                DVec2::new(0.5 + 0.4 * a.cos(), 0.5 + 0.37 * a.sin())
            })
            .collect();
        let hole = vec![
            DVec2::new(0.4, 0.45),
            DVec2::new(0.6, 0.45),
            DVec2::new(0.6, 0.55),
            DVec2::new(0.4, 0.55),
            DVec2::new(0.4, 0.45),
        ];
        let inputs = [
            LoopInput {
                pieces: vec![disc],
                role: Some(Role::Outer),
            },
            LoopInput {
                pieces: vec![hole],
                role: Some(Role::Hole),
            },
        ];
        let regions =
            TrimRegions::new(&inputs, [(0.0, 1.0), (0.0, 1.0)], &Tolerances::default()).unwrap();
        let axis = |k: usize| {
            (0..k)
                .map(|i| i as f64 / (k - 1) as f64)
                .collect::<Vec<_>>()
        };
        Coverage::new(&regions, &axis(n), &axis(m)).unwrap()
    }

    /// The packed class of block (br, bc) at levels (lr, lc), read as the vertex shader does.
    fn packed(words: &[u32], lr: usize, lc: usize, br: usize, bc: usize) -> u8 {
        let ncv = words[5] as usize;
        let nbc = ncv.div_ceil(1 << lc);
        let level = words[words[3] as usize + lr * 5 + lc] as usize;
        let k = br * nbc + bc;
        ((words[level + k / 16] >> (2 * (k % 16))) & 3) as u8
    }

    /// Every block of every level says what its cells are: inside only if all are, outside
    /// only if all are, mixed otherwise; the shader's fast path relies on it. Also for masks
    /// whose cells cut each sample cell in 2 × 2 and 4 × 4 (a block of sample cells then
    /// merges all the mask cells under it).
    #[test]
    fn block_classes_of_every_level_agree_with_their_cells() {
        for (n, m, refine) in [(33, 29, 1), (40, 17, 1), (9, 9, 1), (9, 8, 2), (9, 9, 4)] {
            let (ncu, ncv) = (n - 1, m - 1);
            let c = coverage(ncu * refine + 1, ncv * refine + 1);
            let words = mask_words(&c, refine);
            assert_eq!(
                (words[4], words[5], words[6]),
                (ncu as u32, ncv as u32, refine as u32)
            );
            for lr in 0..5 {
                for lc in 0..5 {
                    let (sr, sc) = (1usize << lr, 1usize << lc);
                    for br in 0..ncu.div_ceil(sr) {
                        for bc in 0..ncv.div_ceil(sc) {
                            let rows = br * sr * refine..((br + 1) * sr).min(ncu) * refine;
                            let cols = bc * sc * refine..((bc + 1) * sc).min(ncv) * refine;
                            let cells: Vec<CellClass> = rows
                                .flat_map(|i| cols.clone().map(move |j| (i, j)))
                                .map(|(i, j)| c.cell_class(i, j))
                                .collect();
                            let want = if cells.iter().all(|&x| x == CellClass::Inside) {
                                INSIDE
                            } else if cells.iter().all(|&x| x == CellClass::Outside) {
                                OUTSIDE
                            } else {
                                MIXED
                            };
                            assert_eq!(
                                packed(&words, lr, lc, br, bc),
                                want,
                                "{n}x{m}/{refine} level ({lr}, {lc}) block ({br}, {bc})"
                            );
                        }
                    }
                }
            }
        }
    }

    /// Negative control: flipping one packed block's class is seen by the comparison.
    #[test]
    fn a_wrong_block_class_is_seen() {
        let c = coverage(33, 29);
        let mut words = mask_words(&c, 1);
        let level = words[words[3] as usize + 5 + 1] as usize;
        let before = packed(&words, 1, 1, 3, 3);
        words[level + (3 * 14 + 3) / 16] ^= 1 << (2 * ((3 * 14 + 3) % 16));
        assert_ne!(packed(&words, 1, 1, 3, 3), before);
    }
}

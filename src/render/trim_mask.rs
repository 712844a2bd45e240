//! A trimmed surface's coverage of its sample grid packed for the fragment shader's inside
//! test (`shaders/trim.glsl`): a header, the cell words, the boundary-cell records and the
//! cell-local segments (`geom::trim::coverage` documents each); and the blocks of every
//! display level of detail by class, so that only the blocks the boundary crosses pay for the
//! test ([`TrimBlocks`]).

use crate::geom::trim::{CellClass, Coverage};
use std::borrow::Cow;

/// Words before the cell words: the offsets of the cells, records and segments, the sample
/// cell rows and columns, and the mask cells per sample cell and direction.
const HEADER: usize = 6;

/// Strides 1, 2, 4, 8, 16 per direction: the display level of detail's.
const STRIDE_LEVELS: u32 = super::lod::MAX_STRIDE.trailing_zeros() + 1;

/// Block classes, 2 bits each: outside, inside, mixed (the cells of a block are not all
/// alike, or the boundary crosses one).
const OUTSIDE: u8 = 0;
const INSIDE: u8 = 1;
const MIXED: u8 = 2;

/// The mask words of `c`, a coverage of the sample grid with every cell cut `refine` times per
/// direction (a power of two; see `editor::TrimCoverage`), and the index ranges its blocks cut
/// every level of detail's triangle list into ([`TrimBlocks`]).
#[must_use]
pub fn mask_parts(c: &Coverage, refine: usize) -> (Vec<u32>, TrimBlocks) {
    let refine = refine.max(1);
    let (mu, mv) = c.samples();
    let (cells, records, segments) = (c.gpu_cells(), c.gpu_records(), c.gpu_segments());
    let at_records = HEADER + cells.len();
    let at_segments = at_records + 4 * records.len();
    let mut out = Vec::with_capacity(at_segments + 4 * segments.len());
    out.extend([
        word(HEADER),
        word(at_records),
        word(at_segments),
        word(mu.saturating_sub(1) / refine),
        word(mv.saturating_sub(1) / refine),
        word(refine),
    ]);
    out.extend_from_slice(cells);
    out.extend(records.iter().flatten());
    out.extend(segments.iter().flatten().map(|x| x.to_bits()));
    let blocks = TrimBlocks {
        levels: level_classes(c, refine)
            .iter()
            .map(BlockRanges::new)
            .collect(),
    };
    (out, blocks)
}

/// The block classes of one level of detail, row-major: `rows × cols` blocks of sample cells.
struct LevelClasses {
    classes: Vec<u8>,
    rows: usize,
    cols: usize,
}

/// Every level's block classes, row level major (`lr * STRIDE_LEVELS + lc`): blocks of sample
/// cells, each a merge of its `refine`² mask cells, merged again pairwise per level.
fn level_classes(c: &Coverage, refine: usize) -> Vec<LevelClasses> {
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
    let n = STRIDE_LEVELS as usize;
    let mut out = Vec::with_capacity(n * n);
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
            out.push(LevelClasses {
                classes: level.0.clone(),
                rows: rows.1,
                cols: level.1,
            });
        }
    }
    out
}

/// Index ranges (first index, count) of a trimmed surface's triangle list at every level of
/// detail, by block class. The blocks wholly inside the trim draw through the untrimmed
/// pipeline: no per-vertex grid coordinate, no per-fragment test and, without `discard`, the
/// early depth test. Only the boundary blocks pay for the mask, and the blocks wholly outside
/// are not drawn at all.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrimBlocks {
    levels: Vec<BlockRanges>,
}

impl TrimBlocks {
    /// The ranges of the triangle list drawn at `stride` (rows, columns: powers of two up to
    /// 16, the display level of detail's); `None` for any other stride, which then draws
    /// every block through the mask.
    #[must_use]
    pub fn at(&self, stride: [u32; 2]) -> Option<&BlockRanges> {
        let level = |s: u32| {
            (s.is_power_of_two() && s.trailing_zeros() < STRIDE_LEVELS)
                .then_some(s.trailing_zeros() as usize)
        };
        let k = level(stride[0])? * STRIDE_LEVELS as usize + level(stride[1])?;
        self.levels.get(k)
    }
}

/// One level's triangle list ([`crate::gpu::grid_triangles_strided`]: six indices per block,
/// blocks row-major) cut by class, in list order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BlockRanges {
    inside: Vec<(u32, u32)>,
    mixed: Vec<(u32, u32)>,
}

impl BlockRanges {
    fn new(level: &LevelClasses) -> Self {
        let mut out = Self::default();
        let mut k = 0;
        let classes = &level.classes[..(level.rows * level.cols).min(level.classes.len())];
        while k < classes.len() {
            let class = classes[k];
            let run = classes[k..].iter().take_while(|&&c| c == class).count();
            let range = (word(6 * k), word(6 * run));
            match class {
                INSIDE => out.inside.push(range),
                MIXED => out.mixed.push(range),
                _ => {}
            }
            k += run;
        }
        out
    }

    /// `cells` (index ranges of the same list, drawn in their order; `None`: all of it) cut
    /// into the parts inside the trim and the parts that test it; the parts outside are left
    /// out. A whole draw (`None`, every frame of a full redraw) borrows the ranges.
    #[must_use]
    pub fn split(&self, cells: Option<&[(u32, u32)]>) -> [Cow<'_, [(u32, u32)]>; 2] {
        let Some(cells) = cells else {
            return [Cow::Borrowed(&self.inside), Cow::Borrowed(&self.mixed)];
        };
        let cut = |ranges: &[(u32, u32)]| {
            let mut out = Vec::new();
            for &(first, count) in cells {
                let end = first.saturating_add(count);
                let from = ranges.partition_point(|&(f, n)| f + n <= first);
                for &(f, n) in ranges[from..].iter().take_while(|&&(f, _)| f < end) {
                    let (a, b) = (f.max(first), (f + n).min(end));
                    if a < b {
                        out.push((a, b - a));
                    }
                }
            }
            Cow::Owned(out)
        };
        [cut(&self.inside), cut(&self.mixed)]
    }
}

fn word(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
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

/// The two words of a mask's table entry: the vertices per grid row and the surface's first
/// vertex.
#[must_use]
pub fn mask_entry(cols: u32, first_vertex: u32) -> [u32; 2] {
    [cols, first_vertex]
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

    /// The class block `k` of `r` has by its ranges: inside, mixed or (in neither) outside.
    fn ranged(r: &BlockRanges, k: usize) -> u8 {
        let has = |ranges: &[(u32, u32)]| {
            let i = 6 * k as u32;
            ranges.iter().any(|&(f, n)| f <= i && i + 6 <= f + n)
        };
        if has(&r.inside) {
            INSIDE
        } else if has(&r.mixed) {
            MIXED
        } else {
            OUTSIDE
        }
    }

    /// What the blocks of every level of `blocks` should be, from `c`'s cells: the first block
    /// whose ranges say otherwise, or `None`.
    fn first_wrong_block(
        c: &Coverage,
        blocks: &TrimBlocks,
        (ncu, ncv, refine): (usize, usize, usize),
    ) -> Option<String> {
        for lr in 0..5 {
            for lc in 0..5 {
                let (sr, sc) = (1usize << lr, 1usize << lc);
                let r = blocks.at([sr as u32, sc as u32])?;
                let nbc = ncv.div_ceil(sc);
                for br in 0..ncu.div_ceil(sr) {
                    for bc in 0..nbc {
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
                        if ranged(r, br * nbc + bc) != want {
                            return Some(format!("level ({lr}, {lc}) block ({br}, {bc})"));
                        }
                    }
                }
            }
        }
        None
    }

    /// Every block of every level is drawn as what its cells are: untrimmed only if all are
    /// inside, not at all only if all are outside, through the mask otherwise. Also for masks
    /// whose cells cut each sample cell in 2 × 2 and 4 × 4 (a block of sample cells then
    /// merges all the mask cells under it).
    #[test]
    fn block_ranges_of_every_level_agree_with_their_cells() {
        for (n, m, refine) in [(33, 29, 1), (40, 17, 1), (9, 9, 1), (9, 8, 2), (9, 9, 4)] {
            let (ncu, ncv) = (n - 1, m - 1);
            let c = coverage(ncu * refine + 1, ncv * refine + 1);
            let (words, blocks) = mask_parts(&c, refine);
            assert_eq!(
                (words[3], words[4], words[5]),
                (ncu as u32, ncv as u32, refine as u32)
            );
            assert_eq!(
                first_wrong_block(&c, &blocks, (ncu, ncv, refine)),
                None,
                "{n}x{m}/{refine}"
            );
        }
    }

    /// Negative control: one block moved from the inside ranges to none is seen.
    #[test]
    fn a_wrong_block_range_is_seen() {
        let c = coverage(33, 29);
        let (_, mut blocks) = mask_parts(&c, 1);
        let level = &mut blocks.levels[0];
        let (f, n) = level.inside[0];
        level.inside[0] = (f + 6, n - 6);
        assert!(first_wrong_block(&c, &blocks, (32, 28, 1)).is_some());
    }

    /// Strides that are no level of detail have no blocks (their draws test every fragment).
    #[test]
    fn only_the_levels_of_detail_have_blocks() {
        let (_, blocks) = mask_parts(&coverage(33, 29), 1);
        assert!(blocks.at([1, 16]).is_some());
        for stride in [[3, 1], [1, 32], [0, 1], [6, 2]] {
            assert!(blocks.at(stride).is_none(), "{stride:?}");
        }
    }

    /// Cutting cell ranges by class keeps every index of them that is not outside, once, in
    /// the order given, and nothing else.
    #[test]
    fn split_keeps_the_cells_given_in_their_order() {
        let c = coverage(33, 29);
        let (_, blocks) = mask_parts(&c, 1);
        let r = blocks.at([1, 1]).unwrap();
        let total = 6 * 32 * 28;
        let class_of = |i: u32| ranged(r, i as usize / 6);
        // Ranges out of order, cutting blocks in halves (3 indices: one triangle).
        let cells = [(900, 1203), (3, 597), (2400, 2 * 3 * 28), (total - 9, 9)];
        let [inside, mixed] = r.split(Some(&cells));
        let expand = |ranges: &[(u32, u32)]| -> Vec<u32> {
            ranges.iter().flat_map(|&(f, n)| f..f + n).collect()
        };
        let want = |class: u8| -> Vec<u32> {
            expand(&cells)
                .into_iter()
                .filter(|&i| class_of(i) == class)
                .collect()
        };
        assert_eq!(expand(&inside), want(INSIDE));
        assert_eq!(expand(&mixed), want(MIXED));
        assert!(!inside.is_empty() && !mixed.is_empty());
        let [all_inside, all_mixed] = r.split(None);
        assert_eq!((&*all_inside, &*all_mixed), (&r.inside[..], &r.mixed[..]));
    }
}

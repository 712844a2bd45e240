//! A trimmed surface's coverage of its sample grid packed for the fragment shader's inside
//! test (`shaders/trim.glsl`): a header of five words, the cell words, the boundary-cell
//! records and the cell-local segments (`geom::trim::coverage` documents each).

use crate::geom::trim::Coverage;

/// Words before the cell words: the offsets of the cells, records and segments, and the cell
/// rows and columns.
const HEADER: usize = 5;

/// The mask words of `c`.
#[must_use]
pub fn mask_words(c: &Coverage) -> Vec<u32> {
    let (mu, mv) = c.samples();
    let (cells, records, segments) = (c.gpu_cells(), c.gpu_records(), c.gpu_segments());
    let at_records = HEADER + cells.len();
    let at_segments = at_records + 4 * records.len();
    let word = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let mut out = Vec::with_capacity(at_segments + 4 * segments.len());
    out.extend([
        word(HEADER),
        word(at_records),
        word(at_segments),
        word(mu.saturating_sub(1)),
        word(mv.saturating_sub(1)),
    ]);
    out.extend_from_slice(cells);
    out.extend(records.iter().flatten());
    out.extend(segments.iter().flatten().map(|x| x.to_bits()));
    out
}

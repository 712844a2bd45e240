//! Unit normals of surface samples, with the model's fallback where Su × Sv vanishes.

use super::curvature;
use super::fallback::{NormalSource, first_partial_slots, resolve_degenerate};
use super::grid::{PartialSet, SampleGrid};
use super::kernels::lanes;
use crate::geom::surface::regular_normal;
use std::ops::Range;

/// Recomputes normals, and [K, H] where the grid keeps them, of the samples in `rows × cols`
/// from the stored partials.
pub fn update(
    grid: &mut SampleGrid,
    rows: Range<usize>,
    cols: Range<usize>,
    params: [&[f64]; 2],
    model: &impl NormalSource,
) {
    if grid.partials == PartialSet::Shading {
        return update_shading(grid, rows, cols, params, model);
    }
    if grid.normals.is_none() {
        return;
    }
    let (stride, (iu, iv)) = (grid.partials.len(), first_partial_slots(grid));
    let Some(normals) = grid.normals.as_mut() else {
        return;
    };
    let mv = grid.dims[1];
    let mut degenerate = Vec::new();
    for i in rows.clone() {
        for j in cols.clone() {
            let base = (i * mv + j) * stride;
            match regular_normal(grid.data[base + iu], grid.data[base + iv]) {
                Some(n) => normals[i * mv + j] = n,
                None => degenerate.push((i, j)),
            }
        }
    }
    curvature::update(grid, rows, cols);
    resolve_degenerate(grid, &degenerate, params, model);
}

/// [`update`] for `Shading` grids (S, Su, Sv per sample), a row segment at a time through the
/// vectorised kernel; the degenerate samples take the same fallback afterwards.
fn update_shading(
    grid: &mut SampleGrid,
    rows: Range<usize>,
    cols: Range<usize>,
    params: [&[f64]; 2],
    model: &impl NormalSource,
) {
    let Some(normals) = grid.normals.as_mut() else {
        return;
    };
    let mv = grid.dims[1];
    let mut degenerate = Vec::new();
    for i in rows {
        let (a, b) = (i * mv + cols.start, i * mv + cols.end);
        let data = grid.data[a * 3..b * 3].as_chunks::<3>().0;
        lanes::normals_of(data, &mut normals[a..b], |jj| {
            degenerate.push((i, cols.start + jj))
        });
    }
    resolve_degenerate(grid, &degenerate, params, model);
}

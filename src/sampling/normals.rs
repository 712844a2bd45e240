//! Unit normals of surface samples, with the geometry layer's fallback where Su × Sv vanishes.

use super::grid::{PartialSet, SampleGrid};
use super::kernels::lanes;
use crate::geom::surface::{normal_with_fallback, regular_normal};
use glam::DVec3;
use std::ops::Range;

/// Exact first partials of the model, for the rare degenerate samples (collapsed edges, cusps).
pub trait NormalSource {
    /// (Su, Sv, Suv) at (u, v).
    fn first_partials(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3);
    fn domain(&self) -> [(f64, f64); 2];

    /// [K, H] next to (u, v) where the samples' Su × Sv vanishes (the limit from the inside of
    /// the domain), or `None` when the model cannot say (such samples show as undefined).
    fn curvature_near(&self, _u: f64, _v: f64) -> Option<[f64; 2]> {
        None
    }
}

/// Recomputes normals of the samples in `rows × cols` from the stored Su, Sv.
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
    resolve_degenerate(grid, &degenerate, params, model);
    super::curvature::update(grid, rows, cols, params, model);
}

/// Storage slots of Su and Sv.
fn first_partial_slots(grid: &SampleGrid) -> (usize, usize) {
    (
        grid.partials.index(1, 0).expect("normals need Su"),
        grid.partials.index(0, 1).expect("normals need Sv"),
    )
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

/// Normals of samples `(i, j)` whose Su × Sv the fast kernels found degenerate
/// (`regular_normal` is `None`): the same fallback [`update`] takes.
pub(crate) fn resolve_degenerate(
    grid: &mut SampleGrid,
    samples: &[(usize, usize)],
    params: [&[f64]; 2],
    model: &impl NormalSource,
) {
    if samples.is_empty() {
        return;
    }
    if grid.normals.is_none() {
        return;
    }
    let (stride, (iu, iv)) = (grid.partials.len(), first_partial_slots(grid));
    let Some(normals) = grid.normals.as_mut() else {
        return;
    };
    let mv = grid.dims[1];
    for &(i, j) in samples {
        let base = (i * mv + j) * stride;
        let (su, sv) = (grid.data[base + iu], grid.data[base + iv]);
        normals[i * mv + j] = fallback(su, sv, params[0][i], params[1][j], model);
    }
}

/// The model's one-sided limit where the sampled Su × Sv vanishes.
fn fallback(su: DVec3, sv: DVec3, u: f64, v: f64, model: &impl NormalSource) -> DVec3 {
    let (_, _, suv) = model.first_partials(u, v);
    normal_with_fallback(su, sv, suv, model.domain(), u, v, |u, v| {
        let (a, b, _) = model.first_partials(u, v);
        (a, b)
    })
}

//! Unit normals of surface samples, with the geometry layer's fallback where Su × Sv vanishes.

use super::grid::SampleGrid;
use crate::geom::surface::{normal_with_fallback, regular_normal};
use glam::DVec3;
use std::ops::Range;

/// Exact first partials of the model, for the rare degenerate samples (collapsed edges, cusps).
pub trait NormalSource {
    /// (Su, Sv, Suv) at (u, v).
    fn first_partials(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3);
    fn domain(&self) -> [(f64, f64); 2];
}

/// Recomputes normals of the samples in `rows × cols` from the stored Su, Sv.
pub fn update(
    grid: &mut SampleGrid,
    rows: Range<usize>,
    cols: Range<usize>,
    params: [&[f64]; 2],
    model: &impl NormalSource,
) {
    let Some(normals) = grid.normals.as_mut() else {
        return;
    };
    let stride = grid.partials.len();
    let (iu, iv) = (
        grid.partials.index(1, 0).expect("normals need Su"),
        grid.partials.index(0, 1).expect("normals need Sv"),
    );
    let mv = grid.dims[1];
    for i in rows {
        for j in cols.clone() {
            let base = (i * mv + j) * stride;
            let (su, sv) = (grid.data[base + iu], grid.data[base + iv]);
            normals[i * mv + j] = regular_normal(su, sv).unwrap_or_else(|| {
                let (u, v) = (params[0][i], params[1][j]);
                let (_, _, suv) = model.first_partials(u, v);
                normal_with_fallback(su, sv, suv, model.domain(), u, v, |u, v| {
                    let (a, b, _) = model.first_partials(u, v);
                    (a, b)
                })
            });
        }
    }
}

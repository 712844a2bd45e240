//! What a surface sample falls back on where its Su × Sv vanishes (collapsed edges, cusps,
//! poles): the model's one-sided limits of the normal and of the curvature. Kernels and generic
//! paths only find such samples; every caller resolves them here, the same way.

use super::grid::SampleGrid;
use crate::geom::surface::normal_with_fallback;
use glam::DVec3;

/// Exact first partials of the model, for the rare degenerate samples (collapsed edges, cusps).
pub trait NormalSource {
    /// (Su, Sv, Suv) at (u, v).
    #[must_use]
    fn first_partials(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3);
    #[must_use]
    fn domain(&self) -> [(f64, f64); 2];

    /// [K, H] next to (u, v) where the samples' Su × Sv vanishes (the limit from the inside of
    /// the domain), or `None` when the model cannot say (such samples show as undefined).
    #[must_use]
    fn curvature_near(&self, _u: f64, _v: f64) -> Option<[f64; 2]> {
        None
    }
}

/// Normals and, where the grid keeps them, [K, H] of samples `(i, j)` whose Su × Sv is
/// degenerate (`regular_normal` is `None`): the model's one-sided limit of the normal, and the
/// model's curvature next to the sample, or NaN (drawn as undefined) when it cannot give one.
pub(crate) fn resolve_degenerate(
    grid: &mut SampleGrid,
    samples: &[(usize, usize)],
    params: [&[f64]; 2],
    model: &impl NormalSource,
) {
    if samples.is_empty() {
        return;
    }
    resolve_normals(grid, samples, params, model);
    let mv = grid.dims[1];
    let Some(curv) = grid.curvatures.as_mut() else {
        return;
    };
    for &(i, j) in samples {
        curv[i * mv + j] = model
            .curvature_near(params[0][i], params[1][j])
            .unwrap_or([f64::NAN; 2]);
    }
}

fn resolve_normals(
    grid: &mut SampleGrid,
    samples: &[(usize, usize)],
    params: [&[f64]; 2],
    model: &impl NormalSource,
) {
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

/// Storage slots of Su and Sv.
#[must_use]
pub(crate) fn first_partial_slots(grid: &SampleGrid) -> (usize, usize) {
    (
        grid.partials.index(1, 0).expect("normals need Su"),
        grid.partials.index(0, 1).expect("normals need Sv"),
    )
}

/// The model's one-sided limit where the sampled Su × Sv vanishes.
#[must_use]
fn fallback(su: DVec3, sv: DVec3, u: f64, v: f64, model: &impl NormalSource) -> DVec3 {
    let (_, _, suv) = model.first_partials(u, v);
    normal_with_fallback(su, sv, suv, model.domain(), u, v, |u, v| {
        let (a, b, _) = model.first_partials(u, v);
        (a, b)
    })
}

//! Reference sampling by direct evaluation of the geometry at every parameter (no
//! pre-evaluation). Slow; used to check the engine.

use crate::geom::knots::uniform_params;
use crate::model::ModelRef;
use crate::sampling::{PartialSet, SampleGrid};

/// Samples `model` point by point through the geometry layer's own evaluators.
#[must_use]
pub fn exact_grid(model: ModelRef<'_>, set: &PartialSet) -> SampleGrid {
    // Catmull–Rom and Bézier splines: the de Boor evaluation of their Bézier chain.
    if let Some(chain) = model.to_bspline_curve() {
        return exact_grid(chain.as_ref(), set);
    }
    let domain = model.domain();
    let [mu, mv] = model.sample_dims();
    let g = set.max_order();
    let pu = uniform_params(domain[0].0, domain[0].1, mu);
    let pv = domain
        .get(1)
        .map_or_else(|| vec![0.0], |&(a, b)| uniform_params(a, b, mv));
    let set = if model.is_surface() {
        set.clone()
    } else {
        PartialSet::Curve(g)
    };
    let mut grid = SampleGrid::new([mu, mv], set.clone(), false);
    let list = set.list();
    for (i, &u) in pu.iter().enumerate() {
        for (j, &v) in pv.iter().enumerate() {
            let out = grid.sample_mut(i, j);
            model.kind().derivatives_at([u, v], g, &list, out);
        }
    }
    grid
}

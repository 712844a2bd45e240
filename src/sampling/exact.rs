//! Reference sampling by direct evaluation of the geometry at every parameter (no
//! pre-evaluation). Slow; used to check the engine.

use super::grid::{PartialSet, SampleGrid};
use crate::geom::knots::uniform_params;
use crate::scene::{Samples, Shape};

/// Samples `shape` point by point through the geometry layer's own evaluators.
pub fn exact_grid(shape: &Shape, samples: Samples, set: &PartialSet) -> SampleGrid {
    let domain = shape.domain();
    match samples {
        Samples::Curve(m) => {
            let g = set.max_order();
            let params = uniform_params(domain[0].0, domain[0].1, m);
            let mut grid = SampleGrid::new([m, 1], PartialSet::Curve(g), false);
            for (j, &t) in params.iter().enumerate() {
                let d = match shape {
                    Shape::BezierCurve(c) | Shape::BSplineCurve(c) => c.derivatives(t, g),
                    Shape::ErbsCurve(c) => c.derivatives(t, g),
                    _ => unreachable!("curve samples for a surface"),
                };
                grid.sample_mut(j, 0).copy_from_slice(&d);
            }
            grid
        }
        Samples::Surface([mu, mv]) => {
            let g = set.max_order();
            let pu = uniform_params(domain[0].0, domain[0].1, mu);
            let pv = uniform_params(domain[1].0, domain[1].1, mv);
            let mut grid = SampleGrid::new([mu, mv], set.clone(), false);
            let list = set.list();
            for (i, &u) in pu.iter().enumerate() {
                for (j, &v) in pv.iter().enumerate() {
                    let p = match shape {
                        Shape::BezierSurface(s) | Shape::BSplineSurface(s) => {
                            s.derivatives(u, v, g)
                        }
                        Shape::ErbsSurface(s) => s.derivatives(u, v, g),
                        _ => unreachable!("surface samples for a curve"),
                    };
                    for (slot, &(a, b)) in list.iter().enumerate() {
                        grid.sample_mut(i, j)[slot] = p.get(a, b);
                    }
                }
            }
            grid
        }
    }
}

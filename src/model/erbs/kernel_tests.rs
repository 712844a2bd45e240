//! The dense ERBS kernels through the ERBS surface sampler, against its generic code.

use crate::geom::{BFunctionKind, ErbsSurface, TensorSurface};
use crate::model::ErbsSurfaceSampler;
use crate::model::{ErbsSurfaceEdit, ErbsSurfaceModel, LocalEdit, LocalPath};
use crate::sampling::Sampler;
use crate::sampling::grid::PartialSet;
use crate::sampling::kernels::testing::{Rng, difference};
use glam::DMat4;

#[test]
fn erbs_shading_matches_the_generic_path() {
    // Local patches through the fast kernel (degrees 1..=3) or two_pass (4), the written-out
    // blend and the row-wise normals, against Square(1) grids that take none of them.
    let mut rng = Rng(0x5151_7e57);
    for case in 0..12 {
        let count = [2 + rng.below(3), 2 + rng.below(3)];
        let knots = count.map(|n| {
            let mut k = vec![0.0];
            let mut t = 0.0;
            for _ in 0..n {
                k.push(t);
                t += rng.range(0.3, 2.0);
            }
            k.push(k[n]);
            k
        });
        let patches = (0..count[0] * count[1])
            .map(|_| {
                let c = [2 + rng.below(4), 2 + rng.below(4)];
                let pts = (0..c[0] * c[1]).map(|_| rng.vec(5.0)).collect();
                TensorSurface::bezier(c, pts, None).unwrap()
            })
            .collect();
        let kind = if case % 2 == 0 {
            BFunctionKind::ExpoRational
        } else {
            BFunctionKind::Smoothstep
        };
        let e = ErbsSurface::new(knots, count, patches, kind).unwrap();
        let samples = [2 + rng.below(40), 2 + rng.below(40)];
        let m = ErbsSurfaceModel::new(e, samples).unwrap();
        let mut fast = ErbsSurfaceSampler::new(m.clone(), PartialSet::Shading, true);
        let mut generic = ErbsSurfaceSampler::new(m, PartialSet::Square(1), true);
        let d = difference(fast.grid(), generic.grid());
        assert!(d < 1e-13, "case {case}: {d:e}");
        for _ in 0..10 {
            let local = LocalPath::top([rng.below(count[0]), rng.below(count[1])]);
            let edit = if rng.below(2) == 0 {
                let matrix = DMat4::from_translation(rng.vec(1.0))
                    * DMat4::from_axis_angle(rng.vec(1.0).normalize(), rng.range(-1.0, 1.0));
                LocalEdit::Transform { local, matrix }
            } else {
                let [k, l] = local.steps()[0];
                let [da, db] = fast.model().surface().local_patch(k, l).degree();
                let point = [rng.below(da + 1), rng.below(db + 1)];
                let delta = rng.vec(1.0);
                LocalEdit::MovePoint {
                    local,
                    point,
                    delta,
                }
            };
            fast.apply(&ErbsSurfaceEdit::Local(edit.clone()));
            generic.apply(&ErbsSurfaceEdit::Local(edit));
            let d = difference(fast.grid(), generic.grid());
            assert!(d < 1e-12, "case {case}: {d:e}");
        }
    }
}

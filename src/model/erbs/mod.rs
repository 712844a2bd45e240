//! ERBS curves and surfaces: the models and their edits. Edits address local curves and patches
//! by a path descending through ERBS locals (hierarchical editing), and refine: a knot inserted
//! into the object or into an ERBS local, a polynomial local turned into an ERBS local of its own.
//! One generic edit type serves both kinds through [`ErbsNet`].

pub mod controls;
pub mod curve_sampler;
pub mod file;
#[cfg(test)]
mod kernel_tests;
pub mod surface_sampler;

mod curve;
mod edit;
mod kinds;
mod path;
mod surface;

pub use curve::ErbsCurveModel;
pub use edit::*;
pub use path::LocalPath;
pub use surface::ErbsSurfaceModel;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::BFunctionKind;
    use crate::geom::BezierCurve;
    use crate::geom::erbs::ErbsCurve;
    use crate::geom::erbs::ErbsKnots;
    use crate::geom::shape::erbs_knot_probes;
    use glam::{DMat4, DVec3};

    /// Four cubic locals on knots 0..3.
    fn curve() -> ErbsCurve {
        let local = (0..4)
            .map(|l| {
                let x = l as f64;
                BezierCurve::new(vec![
                    DVec3::new(x - 1.0, 0.3 * x, 0.0),
                    DVec3::new(x - 0.3, 1.0 + x.sin(), 0.5),
                    DVec3::new(x + 0.3, -0.5, 0.2 * x),
                    DVec3::new(x + 1.0, 0.1, 0.0),
                ])
                .unwrap()
            })
            .collect();
        ErbsCurve::new(
            vec![0., 0., 1., 2., 3., 3.],
            local,
            BFunctionKind::default(),
        )
        .unwrap()
    }

    /// Negative controls: refinement and construction keep the shape where they promise to,
    /// and a local moved there, by 1e-6 of the size, is caught.
    #[test]
    fn erbs_refinement_and_construction_are_compared_where_they_keep_the_shape() {
        let c = curve();
        let (refined, new) = c.insert_knot(1.5, None).unwrap();
        assert!(c.refinement_change(&refined, 1.5).is_kept());
        // The local beside the refined interval (its restriction), and the new local at t.
        for local in [0, new] {
            let mut moved = refined.clone();
            moved.transform_local(&[local], &DMat4::from_translation(DVec3::Y * 1e-5));
            let change = c.refinement_change(&moved, 1.5);
            assert!(!change.is_kept(), "local {local}: {change:?}");
        }
        let local = c.local_curves()[2].clone();
        let built = ErbsCurve::build(&local, 3, 3, BFunctionKind::default()).unwrap();
        assert!(ErbsCurve::build_change(&local, &built).is_kept());
        let mut moved = built.clone();
        moved.transform_local(&[1], &DMat4::from_translation(DVec3::X * 1e-5));
        assert!(!ErbsCurve::build_change(&local, &moved).is_kept());
        let knots = ErbsKnots::open(vec![0., 0., 1., 2., 3., 3.], 4).unwrap();
        assert_eq!(erbs_knot_probes(&knots), vec![0., 1., 2., 3.]);
    }

    /// The surface's guards: a refinement (u and v) and a construction keep the shape, and a
    /// local patch moved by 1e-5 where the comparison looks is caught.
    #[test]
    fn erbs_surface_refinement_and_construction_are_compared() {
        use crate::geom::TensorSurface;
        use crate::geom::erbs::ErbsSurface;
        let points = (0..16)
            .map(|k| DVec3::new((k / 4) as f64, (k % 4) as f64, ((k * 7) % 5) as f64 * 0.3))
            .collect();
        let source = TensorSurface::bezier([4, 4], points, None).unwrap();
        let s = ErbsSurface::from_surface(
            &source,
            [3, 3],
            [3, 3],
            BFunctionKind::default(),
            [false, false],
        )
        .unwrap();
        for dir in 0..2 {
            let t = s.knots()[dir].domain().0
                + 0.37 * (s.knots()[dir].domain().1 - s.knots()[dir].domain().0);
            let (refined, new) = s.insert_knot(dir, t, None).unwrap();
            assert!(
                s.refinement_change(&refined, (dir, t)).is_kept(),
                "dir {dir}"
            );
            let mut at = [1, 1];
            at[dir] = new;
            let mut moved = refined.clone();
            moved.transform_local(&[at], &DMat4::from_translation(DVec3::Z * 1e-5));
            let change = s.refinement_change(&moved, (dir, t));
            assert!(!change.is_kept(), "dir {dir}: {change:?}");
        }
        let local = s.local_patch(1, 1).clone();
        let built = ErbsSurface::build(&local, [2, 2], [2, 2], BFunctionKind::default()).unwrap();
        assert!(ErbsSurface::build_change(&local, &built).is_kept());
        let mut moved = built;
        moved.transform_local(&[[0, 1]], &DMat4::from_translation(DVec3::X * 1e-5));
        assert!(!ErbsSurface::build_change(&local, &moved).is_kept());
    }
}

//! ERBS curves and surfaces: the models and their edits, which act on local curves and patches.

use super::edit::{EditError, KindEdit, ObjectEdit, Target};
use super::points::{check_index, check_vector};
use super::{Index2, MAX_CURVE_SAMPLES, check_samples, check_surface_samples};
use crate::geom::{ErbsCurve, ErbsSurface};
use glam::{DMat4, DVec3, DVec4};

/// An ERBS curve with its sample count.
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsCurveModel {
    curve: ErbsCurve,
    samples: usize,
}

impl ErbsCurveModel {
    pub fn new(curve: ErbsCurve, samples: usize) -> Result<Self, EditError> {
        check_samples(samples, MAX_CURVE_SAMPLES)?;
        Ok(Self { curve, samples })
    }

    pub fn curve(&self) -> &ErbsCurve {
        &self.curve
    }

    pub fn samples(&self) -> usize {
        self.samples
    }
}

/// An ERBS surface with its sample counts [mu, mv].
#[derive(Debug, Clone, PartialEq)]
pub struct ErbsSurfaceModel {
    surface: ErbsSurface,
    samples: [usize; 2],
}

impl ErbsSurfaceModel {
    pub fn new(surface: ErbsSurface, samples: [usize; 2]) -> Result<Self, EditError> {
        check_surface_samples(samples)?;
        Ok(Self { surface, samples })
    }

    pub fn surface(&self) -> &ErbsSurface {
        &self.surface
    }

    pub fn samples(&self) -> [usize; 2] {
        self.samples
    }
}

/// Local curves (index `L`) whose control points (index `P`) can be edited.
pub trait LocalNet<L, P> {
    fn check_local(&self, l: L) -> Result<(), EditError>;
    fn check_local_point(&self, l: L, p: P) -> Result<(), EditError>;
    fn local_points(&self, l: L) -> &[DVec3];
    fn transform_local(&mut self, l: L, a: &DMat4);
    fn translate_local_point(&mut self, l: L, p: P, delta: DVec3);
    fn set_local_points(&mut self, l: L, points: &[DVec3]);
}

/// An edit of one local curve or patch.
#[derive(Debug, Clone, PartialEq)]
pub enum LocalEdit<L, P> {
    /// Map every control point by p ↦ (A·[p;1]).xyz, A affine.
    Transform { local: L, matrix: DMat4 },
    /// Translate one control point of the local.
    MovePoint { local: L, point: P, delta: DVec3 },
    /// Set every control point exactly (undo).
    SetPoints { local: L, points: Vec<DVec3> },
}

impl<L, P> LocalEdit<L, P>
where
    L: Copy + PartialEq + Into<Index2>,
    P: Copy + PartialEq,
{
    pub fn local(&self) -> L {
        match self {
            LocalEdit::Transform { local, .. }
            | LocalEdit::MovePoint { local, .. }
            | LocalEdit::SetPoints { local, .. } => *local,
        }
    }

    pub fn validate(&self, net: &impl LocalNet<L, P>) -> Result<(), EditError> {
        net.check_local(self.local())?;
        match self {
            LocalEdit::Transform { matrix, .. } => check_affine(matrix),
            LocalEdit::MovePoint {
                local,
                point,
                delta,
            } => {
                net.check_local_point(*local, *point)?;
                check_vector("delta", *delta)
            }
            LocalEdit::SetPoints { local, points } => {
                if points.len() != net.local_points(*local).len() {
                    return Err(EditError::new(
                        "points",
                        format!(
                            "{} points for a local with {}",
                            points.len(),
                            net.local_points(*local).len()
                        ),
                    ));
                }
                points.iter().try_for_each(|&p| check_vector("points", p))
            }
        }
    }

    pub fn apply(&self, net: &mut impl LocalNet<L, P>) {
        match self {
            LocalEdit::Transform { local, matrix } => net.transform_local(*local, matrix),
            LocalEdit::MovePoint {
                local,
                point,
                delta,
            } => net.translate_local_point(*local, *point, *delta),
            LocalEdit::SetPoints { local, points } => net.set_local_points(*local, points),
        }
    }

    #[must_use]
    pub fn inverse(&self, net: &impl LocalNet<L, P>) -> Self {
        LocalEdit::SetPoints {
            local: self.local(),
            points: net.local_points(self.local()).to_vec(),
        }
    }

    pub fn target(&self) -> Target {
        Target::Local(self.local().into())
    }

    /// Transforms compose (A2·A1), moves of one local point add up, the last set wins.
    #[must_use]
    pub fn merge(&self, next: &Self) -> Option<Self> {
        use LocalEdit::*;
        if self.local() != next.local() {
            return None;
        }
        match (self, next) {
            (Transform { local, matrix: a }, Transform { matrix: b, .. }) => Some(Transform {
                local: *local,
                matrix: *b * *a,
            }),
            (
                MovePoint {
                    local,
                    point,
                    delta: a,
                },
                MovePoint {
                    point: q, delta: b, ..
                },
            ) if point == q => Some(MovePoint {
                local: *local,
                point: *point,
                delta: *a + *b,
            }),
            (_, SetPoints { .. }) => Some(next.clone()),
            _ => None,
        }
    }
}

/// A finite affine matrix: last row (0, 0, 0, 1).
fn check_affine(m: &DMat4) -> Result<(), EditError> {
    if !m.is_finite() {
        return Err(EditError::new(
            "transform",
            "entries must be finite numbers",
        ));
    }
    if m.row(3) != DVec4::W {
        return Err(EditError::new(
            "transform",
            format!(
                "not affine: the last row must be [0, 0, 0, 1], found {:?}",
                m.row(3).to_array()
            ),
        ));
    }
    Ok(())
}

impl LocalNet<usize, usize> for ErbsCurve {
    fn check_local(&self, l: usize) -> Result<(), EditError> {
        check_index("local", l, self.local_curves().len())
    }

    fn check_local_point(&self, l: usize, p: usize) -> Result<(), EditError> {
        check_index("point", p, self.local_curves()[l].points().len())
    }

    fn local_points(&self, l: usize) -> &[DVec3] {
        self.local_curves()[l].points()
    }

    fn transform_local(&mut self, l: usize, a: &DMat4) {
        ErbsCurve::transform_local(self, l, a);
    }

    fn translate_local_point(&mut self, l: usize, p: usize, delta: DVec3) {
        ErbsCurve::translate_local_point(self, l, p, delta);
    }

    fn set_local_points(&mut self, l: usize, points: &[DVec3]) {
        ErbsCurve::set_local_points(self, l, points);
    }
}

impl LocalNet<[usize; 2], [usize; 2]> for ErbsSurface {
    fn check_local(&self, [k, l]: [usize; 2]) -> Result<(), EditError> {
        check_pair("local", [k, l], self.count())
    }

    fn check_local_point(&self, [k, l]: [usize; 2], p: [usize; 2]) -> Result<(), EditError> {
        check_pair("point", p, self.local_patch(k, l).count())
    }

    fn local_points(&self, [k, l]: [usize; 2]) -> &[DVec3] {
        self.local_patch(k, l).points()
    }

    fn transform_local(&mut self, [k, l]: [usize; 2], a: &DMat4) {
        ErbsSurface::transform_local(self, k, l, a);
    }

    fn translate_local_point(&mut self, [k, l]: [usize; 2], [a, b]: [usize; 2], delta: DVec3) {
        ErbsSurface::translate_local_point(self, k, l, a, b, delta);
    }

    fn set_local_points(&mut self, [k, l]: [usize; 2], points: &[DVec3]) {
        ErbsSurface::set_local_points(self, k, l, points);
    }
}

fn check_pair(
    field: &'static str,
    [i, j]: [usize; 2],
    [n, m]: [usize; 2],
) -> Result<(), EditError> {
    if i < n && j < m {
        return Ok(());
    }
    Err(EditError::new(
        field,
        format!(
            "index [{i}, {j}] out of range (valid: [0..={}, 0..={}])",
            n.saturating_sub(1),
            m.saturating_sub(1)
        ),
    ))
}

/// Edits of an [`ErbsCurveModel`].
#[derive(Debug, Clone, PartialEq)]
pub enum ErbsCurveEdit {
    Local(LocalEdit<usize, usize>),
}

/// Edits of an [`ErbsSurfaceModel`].
#[derive(Debug, Clone, PartialEq)]
pub enum ErbsSurfaceEdit {
    Local(LocalEdit<[usize; 2], [usize; 2]>),
}

/// The [`KindEdit`] of an ERBS kind whose edits are local edits.
macro_rules! erbs_kind_edit {
    ($edit:ident, $variant:ident, $model:ident, $geom:ident) => {
        impl KindEdit for $edit {
            type Model = $model;

            fn validate(&self, m: &$model) -> Result<(), EditError> {
                match self {
                    $edit::Local(e) => e.validate(&m.$geom),
                }
            }

            fn apply(&self, m: &mut $model) {
                match self {
                    $edit::Local(e) => e.apply(&mut m.$geom),
                }
            }

            fn inverse(&self, m: &$model) -> Self {
                match self {
                    $edit::Local(e) => $edit::Local(e.inverse(&m.$geom)),
                }
            }

            fn target(&self) -> Target {
                match self {
                    $edit::Local(e) => e.target(),
                }
            }

            fn merge(&self, next: &Self) -> Option<Self> {
                match (self, next) {
                    ($edit::Local(a), $edit::Local(b)) => a.merge(b).map($edit::Local),
                }
            }

            fn into_object(self) -> ObjectEdit {
                ObjectEdit::$variant(self)
            }

            fn from_object(e: &ObjectEdit) -> Option<&Self> {
                match e {
                    ObjectEdit::$variant(e) => Some(e),
                    _ => None,
                }
            }
        }
    };
}

erbs_kind_edit!(ErbsCurveEdit, ErbsCurve, ErbsCurveModel, curve);
erbs_kind_edit!(ErbsSurfaceEdit, ErbsSurface, ErbsSurfaceModel, surface);

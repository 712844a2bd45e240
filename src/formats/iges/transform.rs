//! Transformation matrices (entity 124) and the chain an entity's placement is made of: an
//! entity's DE field 7 points at a 124, whose own field 7 may point at another 124 that places
//! the first, and so on (IGES 5.3 §4.21). The chain is walked with a visited set, since a damaged
//! file can make it loop.

use std::collections::HashSet;

use super::IgesFile;
use super::directory::De;
use super::entity::Entity;
use super::error::IgesError;

/// An affine map `x ↦ R x + T`, stored as the three rows `[R | T]` the 124 lists
/// (R11 R12 R13 T1, R21 …).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    pub matrix: [[f64; 4]; 3],
}

impl Transform {
    pub const IDENTITY: Self = Self {
        matrix: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ],
    };

    /// The matrix of a 124 entity alone (without the 124s that place it).
    pub fn from_entity(entity: &Entity) -> Result<Self, IgesError> {
        if entity.entity_type() != 124 {
            return Err(entity.error("is not a transformation matrix (124)"));
        }
        let row = |first: usize| -> Result<[f64; 4], IgesError> {
            Ok([
                entity.real(first)?,
                entity.real(first + 1)?,
                entity.real(first + 2)?,
                entity.real(first + 3)?,
            ])
        };
        Ok(Self {
            matrix: [row(1)?, row(5)?, row(9)?],
        })
    }

    /// `self` followed by `outer`: the map `x ↦ outer(self(x))`.
    #[must_use]
    pub fn then(self, outer: Self) -> Self {
        let [a, b, c] = self.matrix;
        let row = |[r0, r1, r2, t]: [f64; 4]| {
            [
                r0 * a[0] + r1 * b[0] + r2 * c[0],
                r0 * a[1] + r1 * b[1] + r2 * c[1],
                r0 * a[2] + r1 * b[2] + r2 * c[2],
                r0 * a[3] + r1 * b[3] + r2 * c[3] + t,
            ]
        };
        Self {
            matrix: outer.matrix.map(row),
        }
    }

    /// The image of point `p`.
    #[must_use]
    pub fn apply_point(&self, p: [f64; 3]) -> [f64; 3] {
        self.matrix
            .map(|[r0, r1, r2, t]| r0 * p[0] + r1 * p[1] + r2 * p[2] + t)
    }

    /// The image of direction `v` (no translation).
    #[must_use]
    pub fn apply_vector(&self, v: [f64; 3]) -> [f64; 3] {
        self.matrix
            .map(|[r0, r1, r2, _]| r0 * v[0] + r1 * v[1] + r2 * v[2])
    }

    /// Whether this is the identity map exactly, so callers can skip transforming.
    #[must_use]
    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }
}

/// The placement of `entity`: its 124, then the 124 placing that, … up to one with no
/// transformation. Errors name the entity whose field 7 is wrong.
pub(super) fn placement(file: &IgesFile, entity: &Entity) -> Result<Transform, IgesError> {
    let mut result = Transform::IDENTITY;
    let mut holder = entity;
    let mut seen: HashSet<De> = HashSet::new();
    while let Some(next) = holder.directory().transform {
        if !seen.insert(next) {
            return Err(entity.error(format!(
                "its transformation chain loops: {next} is reached twice"
            )));
        }
        let Some(matrix) = file.entity(next) else {
            return Err(holder.error(format!(
                "its transformation matrix field points at {next}, which does not exist"
            )));
        };
        if matrix.entity_type() != 124 {
            return Err(holder.error(format!(
                "its transformation matrix field points at {next}, entity {} ({}), not a 124",
                matrix.entity_type(),
                matrix.type_name()
            )));
        }
        result = result.then(Transform::from_entity(matrix)?);
        holder = matrix;
    }
    Ok(result)
}

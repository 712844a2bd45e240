//! The two ways mapping an entity can fail: the file is malformed (the whole read stops with one
//! line naming the file line and DE, as the issue asks), or one face cannot be drawn for a
//! geometric reason (that face is skipped, counted and explained, the rest of the model is kept,
//! as OpenCASCADE does).

use crate::formats::iges::{Entity, IgesError};

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Fail {
    /// A structural or parameter error: wrong types, missing or dangling pointers, bad counts.
    Malformed(String),
    /// Well-formed data that this mapping cannot turn into a trimmed NURBS face.
    Skip(String),
}

impl From<IgesError> for Fail {
    fn from(e: IgesError) -> Self {
        Self::Malformed(e.to_string())
    }
}

/// A face-level failure with its reason.
#[must_use]
pub(crate) fn skip(reason: impl Into<String>) -> Fail {
    Fail::Skip(reason.into())
}

/// A malformed-file error about `entity`, at its directory entry.
#[must_use]
pub(crate) fn malformed(entity: &Entity, message: impl Into<String>) -> Fail {
    Fail::Malformed(entity.error(message.into()).to_string())
}

/// Wraps an analytic-crate error as a face-level failure naming `what` it was building.
pub(crate) fn geometry<T>(
    result: Result<T, crate::geom::analytic::AnalyticError>,
    what: &str,
) -> Result<T, Fail> {
    result.map_err(|e| skip(format!("{what}: {e}")))
}

pub(crate) type Mapped<T> = Result<T, Fail>;

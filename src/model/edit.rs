//! The edit vocabulary every kind shares: what an edit acts on, the trait per-kind edits
//! implement, and how a rejected edit is reported. The sum over kinds and the frame-merging of
//! edits are the registry's (model/object.rs).

use super::erbs::LocalPath;
use super::index::Index2;
use crate::geom::shape::{SHAPE_TOLERANCE, ShapeChange};
use std::fmt::Debug;

/// A rejected edit: which field of the edit is wrong and why (callers add the object and the
/// edit's position, so the whole message is one line).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("field '{field}': {message}")]
pub struct EditError {
    pub field: &'static str,
    pub message: String,
}

impl EditError {
    pub fn new(field: &'static str, message: impl Into<String>) -> Self {
        Self {
            field,
            message: message.into(),
        }
    }
}

/// Refuses a structural edit whose result would move the shape (`what`: "curve", "surface",
/// …) by more than [`ShapeChange::tolerance`]: one line with the field, how far, and against
/// what. Validation runs it, so nothing is applied.
pub(super) fn check_shape_kept(
    field: &'static str,
    what: &str,
    change: ShapeChange,
) -> Result<(), EditError> {
    if change.is_kept() {
        return Ok(());
    }
    Err(EditError::new(
        field,
        format!(
            "would move the {what} by {:.1e} (tolerance {SHAPE_TOLERANCE:e} of its size {}); refused, nothing changed",
            change.moved,
            significant(change.size)
        ),
    ))
}

/// `x` to three significant digits, without trailing zeros (4.1, 0.0123, 1.2e6).
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-3..1e5).contains(&x.abs()) {
        return format!("{x:.2e}");
    }
    let digits = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// What an edit will build: `what` in words ("3 local curves of degree 2") and about how many
/// bytes, for the field `field` of the edit; and, where the object it leaves grows with a count
/// (`locals`), the same edit with two small counts (`proxies`): the editor prepares those, reads
/// what the object would need with each, and extrapolates to `locals` to hold the whole object,
/// with the one it replaces, to the budget before the real edit builds anything.
#[derive(Debug, Clone, PartialEq)]
pub struct Build {
    pub field: &'static str,
    pub what: String,
    pub bytes: u128,
    pub locals: u128,
    pub proxies: Vec<(u128, super::ObjectEdit)>,
}

/// What an edit acts on. Edits on different targets commute; consecutive edits on one target
/// may merge. A structural edit acts on the whole object and orders everything around it. It
/// also says what the edit changes in the drawn control structures: one point, one local curve
/// or patch, nothing drawn (a weight), or their size and layout (structure).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Point(Index2),
    Weight(Index2),
    /// An ERBS local curve or patch (its transform and its control points), by path.
    Local(LocalPath<Index2>),
    Structure,
}

/// A kind's edit as one variant of the sum over kinds ([`ObjectEdit`](super::ObjectEdit)) and
/// back: the registry implements it for each registered kind's edit, so this trait names the
/// sum only through `Object`.
pub trait IntoObject: Sized {
    /// The sum over kinds.
    type Object;

    #[must_use]
    fn wrap(self) -> Self::Object;

    fn unwrap(e: &Self::Object) -> Option<&Self>;
}

/// An edit of one object kind. Implemented once per kind: this is the table of what each edit
/// means, written in one place per kind instead of one `match` per layer.
pub trait KindEdit: Clone + Debug + PartialEq + Sized + IntoObject {
    /// The model this kind of edit acts on.
    type Model;

    /// Checks the edit against the model it is about to be applied to, and computes what
    /// applying it takes: a structural edit hands back the model it leaves (a refinement is
    /// computed here once, since the shape guard needs it), so applying it computes nothing
    /// again; an edit applied in place hands back `None`.
    fn prepare(&self, model: &Self::Model) -> Result<Option<Self::Model>, EditError>;

    /// Checks the edit against the model it is about to be applied to.
    fn validate(&self, model: &Self::Model) -> Result<(), EditError> {
        self.prepare(model).map(|_| ())
    }

    /// Applies a validated edit to the model (a structural edit computes its result).
    fn apply(&self, model: &mut Self::Model);

    /// Applies an edit to the model it was prepared against, taking the prepared result where
    /// [`KindEdit::prepare`] computed one.
    fn apply_prepared(&self, model: &mut Self::Model, result: Option<Self::Model>) {
        match result {
            Some(after) => *model = after,
            None => self.apply(model),
        }
    }

    /// The edit that brings `model` (before this edit is applied) back bit for bit.
    #[must_use]
    fn inverse(&self, model: &Self::Model) -> Self;

    fn target(&self) -> Target;

    /// This edit followed by `next` as one edit, when both act on one target and combine.
    #[must_use]
    fn merge(&self, next: &Self) -> Option<Self>;

    /// What preparing the edit will allocate, known from the edit alone, so the editor holds
    /// it to the memory budget before anything is built (an ERBS local built from a count).
    fn builds(&self) -> Option<Build> {
        None
    }

    /// The edit as an edit of any kind.
    #[must_use]
    fn into_object(self) -> Self::Object {
        self.wrap()
    }

    /// The edit if `e` is of this kind.
    #[must_use]
    fn from_object(e: &Self::Object) -> Option<&Self> {
        Self::unwrap(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moving_refinement_is_refused_in_one_line() {
        let change = ShapeChange {
            moved: 3.2e-3,
            size: 4.1,
            magnitude: 3.0,
        };
        let e = check_shape_kept("elevate_degree", "curve", change).unwrap_err();
        assert_eq!(
            e.to_string(),
            "field 'elevate_degree': would move the curve by 3.2e-3 (tolerance 1e-9 of its size 4.1); refused, nothing changed"
        );
        let nan = ShapeChange {
            moved: f64::NAN,
            ..change
        };
        assert!(check_shape_kept("insert_knot", "surface", nan).is_err());
        let kept = ShapeChange {
            moved: 1e-15,
            ..change
        };
        assert_eq!(check_shape_kept("insert_knot", "surface", kept), Ok(()));
    }

    #[test]
    fn sizes_print_with_three_significant_digits() {
        for (x, s) in [
            (4.1, "4.1"),
            (4.123456, "4.12"),
            (123.4, "123"),
            (0.012345, "0.0123"),
            (0.0, "0"),
            (2.5e7, "2.50e7"),
        ] {
            assert_eq!(significant(x), s);
        }
    }
}

//! The commands that change an object's structure from the keyboard: X (a polynomial ERBS local
//! becomes an ERBS of its own), E (degree elevation) and B (a Catmull–Rom or Bézier spline
//! becomes its bspline_curve). Each is one undo step, refused on the status line when it does
//! not apply or would not fit the memory budget; I (knot insertion) is a mode of its own.

use super::stage::Stage;
use crate::model::{CurveEdit, Edit, KindEdit, ModelRef, SurfaceEdit};

/// Locals per direction of an ERBS local made from a polynomial local with X.
pub const DETAIL_LOCALS: usize = 3;

/// X: the selected polynomial local curve or patch becomes an ERBS local of its own, built by
/// Hermite interpolation (the same shape: its Taylor polynomials of its own degree are itself),
/// with [`DETAIL_LOCALS`] locals per direction.
pub fn local_to_erbs(s: &mut Stage) {
    s.editor.apply_queued();
    let Some((object, local)) = s.selection.selected_local else {
        return s.set_status(
            "select a local curve or patch of an ERBS object first (click one of its points), then X",
        );
    };
    let Some((edit, degree)) = s.doc().local_to_erbs_edit(object, local, DETAIL_LOCALS) else {
        return s.set_status("the selected local is not a polynomial local curve or patch");
    };
    if let Err(e) = edit.validate(s.doc().objects[object].sampled.model()) {
        return s.set_status(format!("cannot make an ERBS local: {e}"));
    }
    let name = s.doc().objects[object].name.clone();
    if !s.structural("make ERBS local", Edit { object, edit }) {
        return;
    }
    s.selection.selected_local = Some((object, local));
    let what = if s.doc().objects[object].sampled.model().is_surface() {
        format!("{DETAIL_LOCALS} x {DETAIL_LOCALS} patches")
    } else {
        format!("{DETAIL_LOCALS} curves")
    };
    s.set_status(format!(
        "{name} local {local} is an ERBS now: {what} of degree {degree}, same shape (I refines in it)"
    ));
}

/// E: degree elevation of the focused curve or surface by one (surfaces: in direction `dir`).
pub fn elevate(s: &mut Stage, dir: usize) {
    let Some(object) = s.selection.focused_object() else {
        return s.set_status("select a curve or surface first (click one of its points)");
    };
    let model = s.doc().objects[object].sampled.model();
    let edit = match model {
        ModelRef::Curve(_) => CurveEdit::ElevateDegree { by: 1 }.into_object(),
        ModelRef::Surface(_) => {
            let mut by = [0, 0];
            by[dir] = 1;
            SurfaceEdit::ElevateDegree { by }.into_object()
        }
        ModelRef::CatmullRom(_) | ModelRef::BezierSpline(_) => {
            let ty = model.type_name();
            return s.set_status(format!(
                "a {ty} keeps its segments: B converts it to a bspline_curve first"
            ));
        }
        _ => return s.set_status("ERBS objects are not refined by degree elevation"),
    };
    if let Err(e) = edit.validate(model) {
        return s.set_status(format!("cannot elevate the degree: {e}"));
    }
    let name = s.doc().objects[object].name.clone();
    if !s.structural("elevate degree", Edit { object, edit }) {
        return;
    }
    let degree = match s.doc().objects[object].sampled.model() {
        ModelRef::Curve(m) => m.curve().degree().to_string(),
        ModelRef::Surface(m) => format!("{:?}", m.surface().degree()),
        _ => String::new(),
    };
    s.set_status(format!("{name}: degree {degree} (Ctrl+Z undoes)"));
}

/// B: the focused Catmull–Rom or Bézier spline becomes its equivalent bspline_curve.
pub fn to_bspline(s: &mut Stage) {
    let Some(object) = s.selection.focused_object() else {
        return s
            .set_status("select a Catmull–Rom or Bézier spline first (click one of its points)");
    };
    match s.doc().to_bspline(object) {
        Ok(edit) => {
            let name = s.doc().objects[object].name.clone();
            if s.structural("convert to B-spline", edit) {
                s.set_status(format!("{name} is now a bspline_curve (Ctrl+Z undoes)"));
            }
        }
        Err(e) => s.set_status(e),
    }
}

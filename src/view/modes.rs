//! The gesture in progress and how input moves it along: orbiting, panning, dragging a control
//! point or its weight, grabbing, rotating or scaling with typed values, aiming a knot
//! insertion, typing a weight. Each mode takes the stage it acts on and returns the mode that
//! follows; what a key means when no gesture has claimed it is the key map's business.

use super::input::{Key, MouseButton};
use super::refine::Refine;
use super::stage::Stage;
use super::tools::{Axis, Drag, Transform, TransformKind};
use crate::editor::{Document, Handle};
use crate::gpu::LineVertex;
use crate::model::{Index2, LocalPath, Model, Target as EditTarget};
use crate::render::Gesture;
use glam::{DMat4, DVec3};

/// What a transform acts on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    Point(Handle),
    Local(usize, LocalPath<Index2>),
}

/// The gesture in progress.
#[derive(Debug, Clone, Default)]
pub enum Mode {
    #[default]
    Idle,
    /// Left drag on empty space; a click without motion clears the selection.
    Orbit {
        moved: bool,
    },
    Pan,
    /// A control point follows the cursor (X/Y/Z: along an axis).
    Drag {
        handle: Handle,
        drag: Drag,
    },
    /// G, R or S with the cursor or typed values; `origin` is the transformed object's model
    /// when the gesture began (a singular transform sets points from it exactly).
    Transform {
        target: Target,
        t: Box<Transform>,
        origin: Option<Box<Model>>,
    },
    /// Aiming a knot insertion (I).
    Refine(Refine),
    /// Alt+drag on a control point: its weight follows the vertical motion (up: heavier).
    Weight {
        handle: Handle,
        start_y: f64,
        from: f64,
    },
    /// Typing a weight for the selected control point (Shift+W).
    WeightEntry {
        handle: Handle,
        text: String,
    },
}

impl Mode {
    /// Whether the mode reads keys itself (typed values, U/V, Enter, Esc) instead of the key
    /// map.
    #[must_use]
    pub fn takes_keys(&self) -> bool {
        matches!(
            self,
            Mode::Transform { .. } | Mode::Refine(_) | Mode::WeightEntry { .. }
        )
    }

    /// What the gesture in progress moves, for the renderer's static layer: a dragged or
    /// transformed point (its weight with Alt), or a transformed ERBS local.
    #[must_use]
    pub fn gesture(&self) -> Option<Gesture> {
        let point = |h: &Handle, weight: bool| match *h {
            Handle::Point { object, point } => Gesture {
                object,
                target: if weight {
                    EditTarget::Weight(point)
                } else {
                    EditTarget::Point(point)
                },
            },
            Handle::LocalPoint { object, local, .. } => Gesture {
                object,
                target: EditTarget::Local(local),
            },
        };
        match self {
            Mode::Drag { handle, .. } => Some(point(handle, false)),
            Mode::Weight { handle, .. } => Some(point(handle, true)),
            Mode::Transform { target, .. } => Some(match target {
                Target::Point(h) => point(h, false),
                Target::Local(object, path) => Gesture {
                    object: *object,
                    target: EditTarget::Local(*path),
                },
            }),
            _ => None,
        }
    }

    /// Whether the osculating circle follows the cursor in this mode.
    #[must_use]
    pub fn shows_osculating(&self) -> bool {
        matches!(self, Mode::Idle | Mode::Drag { .. } | Mode::Weight { .. })
    }

    /// The cursor moved to (x, y).
    #[must_use]
    pub fn cursor_moved(self, s: &mut Stage, x: f64, y: f64) -> Mode {
        let (dx, dy) = (x - s.cursor.0, y - s.cursor.1);
        s.cursor = (x, y);
        match self {
            Mode::Idle => {
                s.hover();
                Mode::Idle
            }
            Mode::Orbit { .. } => {
                s.orbit(dx, dy);
                Mode::Orbit { moved: true }
            }
            Mode::Pan => {
                s.pan(dx, dy);
                Mode::Pan
            }
            Mode::Drag { handle, mut drag } => {
                if let Some(inc) = drag.update(&s.view(), s.cursor)
                    && let Some(edit) = s.doc().move_handle(handle, inc)
                {
                    s.submit(edit);
                }
                Mode::Drag { handle, drag }
            }
            Mode::Transform {
                target,
                mut t,
                origin,
            } => {
                t.set_cursor(s.cursor);
                let mut m = Mode::Transform { target, t, origin };
                m.update_transform(s);
                m
            }
            Mode::Weight {
                handle,
                start_y,
                from,
            } => {
                if let Ok(edit) = s.doc().set_weight(handle, weight_for(from, start_y, y)) {
                    s.submit(edit);
                }
                Mode::Weight {
                    handle,
                    start_y,
                    from,
                }
            }
            Mode::Refine(mut r) => {
                r.aim(s.doc(), &s.view(), s.cursor);
                Mode::Refine(r)
            }
            m @ Mode::WeightEntry { .. } => m,
        }
    }

    /// A mouse button went down or up.
    #[must_use]
    pub fn button(self, s: &mut Stage, button: MouseButton, pressed: bool) -> Mode {
        match (self, button, pressed) {
            (m @ Mode::Transform { .. }, MouseButton::Left, true) => m.confirm_transform(s),
            (Mode::Transform { .. }, MouseButton::Right, true) => cancel_transform(s),
            (Mode::Refine(r), MouseButton::Left, true) => {
                insert_knot(s, &r);
                Mode::Idle
            }
            (Mode::Refine(_), MouseButton::Right, true) => {
                s.set_status("knot insertion cancelled");
                Mode::Idle
            }
            (Mode::Idle, MouseButton::Left, true) if !s.mods.shift => press_left(s),
            (Mode::Idle, MouseButton::Left | MouseButton::Right, true) => Mode::Pan,
            (Mode::Idle, MouseButton::Middle, true) if s.mods.shift => Mode::Pan,
            (Mode::Idle, MouseButton::Middle, true) => Mode::Orbit { moved: false },
            (Mode::Drag { .. }, MouseButton::Left, false) => {
                s.editor.end();
                s.refresh_bounds();
                s.refit_map = true;
                Mode::Idle
            }
            (Mode::Weight { handle, .. }, MouseButton::Left, false) => {
                s.editor.end();
                s.refit_map = true;
                let w = s.doc().weight_of(handle).unwrap_or(1.0);
                s.set_status(format!(
                    "weight of {} is {w} (Ctrl+Z undoes)",
                    s.handle_name(handle)
                ));
                Mode::Idle
            }
            (Mode::Orbit { moved: false }, MouseButton::Left, false) => {
                // A click on empty space (no drag) clears the selection.
                s.selection.clear();
                Mode::Idle
            }
            (Mode::Orbit { .. } | Mode::Pan, _, false) => Mode::Idle,
            (m, _, _) => m,
        }
    }

    /// A key pressed while the mode [takes keys](Mode::takes_keys), or X/Y/Z during a drag.
    #[must_use]
    pub fn key(self, s: &mut Stage, key: Key) -> Mode {
        match self {
            Mode::Transform { .. } => self.transform_key(s, key),
            Mode::Refine(r) => refine_key(s, r, key),
            Mode::WeightEntry { handle, text } => weight_key(s, handle, text, key),
            Mode::Drag { handle, drag } => {
                let axis = match key {
                    Key::Char('x') => Axis::X,
                    Key::Char('y') => Axis::Y,
                    Key::Char('z') => Axis::Z,
                    _ => return Mode::Drag { handle, drag },
                };
                // A fresh drag from where the point is now, along (or freed from) the axis.
                let mut fresh = Drag::new(drag.anchor + drag.applied);
                fresh.axis = drag.axis.toggle(axis);
                fresh.grab(&s.view(), s.cursor);
                Mode::Drag {
                    handle,
                    drag: fresh,
                }
            }
            m => m,
        }
    }

    /// The status line while the mode runs (`None`: the stage's own message).
    #[must_use]
    pub fn status(&self, s: &Stage) -> Option<String> {
        Some(match self {
            Mode::Transform { t, .. } => t.describe(),
            Mode::Refine(r) => r.describe(s.doc()),
            Mode::WeightEntry { handle, text } => format!(
                "weight of {}: [{text}]  (type a positive number, Enter sets it, Esc cancels)",
                s.handle_name(*handle)
            ),
            Mode::Weight { handle, .. } => format!(
                "weight of {}: {}  (drag up/down, release to keep)",
                s.handle_name(*handle),
                s.doc().weight_of(*handle).unwrap_or(1.0)
            ),
            _ => return None,
        })
    }

    /// What the mode previews in the scene (the isoline or marker of a knot insertion).
    #[must_use]
    pub fn preview(&self, s: &Stage) -> Vec<LineVertex> {
        match self {
            Mode::Refine(r) => r.preview(s.doc(), s.bounds.radius()),
            _ => Vec::new(),
        }
    }

    fn transform_key(mut self, s: &mut Stage, key: Key) -> Mode {
        let Mode::Transform { t, .. } = &mut self else {
            return self;
        };
        let view = s.view();
        match key {
            Key::Char('x') => t.set_axis(Axis::X, &view),
            Key::Char('y') => t.set_axis(Axis::Y, &view),
            Key::Char('z') => t.set_axis(Axis::Z, &view),
            Key::Char(c @ ('0'..='9' | '.' | '-')) => t.numeric.push(c),
            Key::Backspace => {
                t.numeric.pop();
            }
            Key::Enter => return self.confirm_transform(s),
            Key::Escape => return cancel_transform(s),
            _ => return self,
        }
        self.update_transform(s);
        self
    }

    /// Submits the increment that brings the model from the transform applied so far to the
    /// transform the gesture stands for now.
    fn update_transform(&mut self, s: &mut Stage) {
        let Mode::Transform { target, t, origin } = self else {
            return;
        };
        let total = t.total(&s.view());
        if total == t.applied {
            return;
        }
        // A singular transform (a typed scale passes through 0 on the way to "0.5") has no
        // inverse to take the next increment from: the local's points are then set exactly
        // from where they were when the gesture began.
        let singular = |m: &DMat4| !(m.determinant().abs() > 0.0 && m.inverse().is_finite());
        let exact = singular(&total) || singular(&t.applied);
        let inc = total * t.applied.inverse();
        t.applied = total;
        let edit = match *target {
            Target::Local(object, local) if exact => origin
                .as_deref()
                .and_then(|o| Document::set_local_transformed(object, local, o, &total)),
            Target::Local(object, local) => s.doc().transform_local(object, local, inc),
            // A point only translates: the increment's translation part.
            Target::Point(h) => s.doc().move_handle(h, inc.w_axis.truncate()),
        };
        if let Some(edit) = edit {
            s.submit(edit);
        }
    }

    fn confirm_transform(mut self, s: &mut Stage) -> Mode {
        self.update_transform(s);
        s.editor.end();
        s.refresh_bounds();
        s.refit_map = true;
        s.set_status("transform applied (Ctrl+Z undoes)");
        Mode::Idle
    }
}

/// A factor of 2 per 80 pixels up, kept within [1e-4, 1e4].
fn weight_for(from: f64, start_y: f64, y: f64) -> f64 {
    (from * 2f64.powf((start_y - y) / 80.0)).clamp(1e-4, 1e4)
}

/// Left button down with nothing running: a point starts a drag (its weight with Alt), empty
/// space an orbit.
fn press_left(s: &mut Stage) -> Mode {
    let Some(p) = s.pick() else {
        return Mode::Orbit { moved: false };
    };
    s.select(p.handle);
    if !s.mods.alt {
        let mut drag = Drag::new(p.world);
        drag.grab(&s.view(), s.cursor);
        s.editor.begin("move point");
        return Mode::Drag {
            handle: p.handle,
            drag,
        };
    }
    match s.doc().weight_of(p.handle) {
        Some(from) => {
            s.editor.begin("weight");
            Mode::Weight {
                handle: p.handle,
                start_y: s.cursor.1,
                from,
            }
        }
        None => {
            let why = s.doc().set_weight(p.handle, 1.0).err().unwrap_or_default();
            s.set_status(why);
            Mode::Idle
        }
    }
}

fn cancel_transform(s: &mut Stage) -> Mode {
    s.editor.cancel_step();
    s.set_status("transform cancelled");
    Mode::Idle
}

/// G, R or S: a transform of the selected local (or, for G, the selected point).
#[must_use]
pub fn start_transform(s: &mut Stage, kind: TransformKind) -> Mode {
    // The pivot and the starting points come from the model with every queued edit in.
    s.editor.apply_queued();
    let target = match (s.selection.selected_local, s.selection.selected) {
        (Some((o, l)), _) => Target::Local(o, l),
        (None, Some(h)) if kind == TransformKind::Grab => Target::Point(h),
        (None, Some(_)) => {
            s.set_status(
                "rotate and scale act on ERBS local curves and patches: select a local control point",
            );
            return Mode::Idle;
        }
        (None, None) => {
            s.set_status("select a control point first");
            return Mode::Idle;
        }
    };
    let pivot = match target {
        Target::Point(h) => s.handle_world(h),
        Target::Local(o, l) => s
            .doc()
            .local_points(o, l)
            .map(|p| p.iter().sum::<DVec3>() / p.len() as f64),
    };
    let Some(pivot) = pivot else {
        return Mode::Idle;
    };
    let origin = match target {
        Target::Local(o, _) => Some(Box::new(s.doc().objects[o].sampled.model().to_model())),
        Target::Point(_) => None,
    };
    let t = Box::new(Transform::new(kind, pivot, &s.view(), s.cursor));
    s.editor.begin(kind.name());
    Mode::Transform { target, t, origin }
}

/// I: aim a knot insertion (a refinement on ERBS objects) on the focused object.
#[must_use]
pub fn start_refine(s: &mut Stage) -> Mode {
    let Some(object) = s.selection.focused_object() else {
        s.set_status("select a curve or surface first (click one of its points)");
        return Mode::Idle;
    };
    let mut r = match s.selection.selected_local {
        Some((o, local)) if o == object => Refine::for_local(object, local, s.doc()),
        _ => Refine::new(object),
    };
    // Refused at the key press, with the reason, where the object takes no knots.
    if let Err(e) = r.supported(s.doc()) {
        s.set_status(e);
        return Mode::Idle;
    }
    r.aim(s.doc(), &s.view(), s.cursor);
    Mode::Refine(r)
}

fn refine_key(s: &mut Stage, mut r: Refine, key: Key) -> Mode {
    match key {
        Key::Char(c @ ('u' | 'v')) => {
            let surface = s.doc().objects[r.object].sampled.model().is_surface();
            r.dir = usize::from(c == 'v' && surface);
            r.aim(s.doc(), &s.view(), s.cursor);
            Mode::Refine(r)
        }
        Key::Enter => {
            insert_knot(s, &r);
            Mode::Idle
        }
        Key::Escape => {
            s.set_status("knot insertion cancelled");
            Mode::Idle
        }
        _ => Mode::Refine(r),
    }
}

/// Inserts the aimed knot (CurveKnotIns), or on ERBS objects refines the aimed level with a new
/// Hermite local (a row or column of local patches on surfaces), as one undo step.
fn insert_knot(s: &mut Stage, r: &Refine) {
    let erbs = r.is_erbs(s.doc());
    let edit = match r.edit(s.doc()) {
        Ok(edit) => edit,
        Err(e) if erbs => return s.set_status(format!("cannot refine: {e}")),
        Err(e) => return s.set_status(format!("cannot insert a knot: {e}")),
    };
    let done = if erbs {
        let added = r.new_local(s.doc()).unwrap_or_else(|| "a local".into());
        let name = &s.doc().objects[r.object].name;
        let at = r.at.unwrap_or_default();
        let axis = r.axis_name(s.doc());
        format!("refined {name} at {axis} = {at:.4}: new {added} (Ctrl+Z undoes)")
    } else {
        let what = r.describe(s.doc());
        let at = what
            .split(" (")
            .next()
            .unwrap_or(&what)
            .replace("insert knot in", "inserted a knot in");
        format!("{at} (Ctrl+Z undoes)")
    };
    let label = if erbs { "refine" } else { "insert knot" };
    if s.structural(label, edit) {
        s.set_status(done);
    }
}

/// Shift+W: type a weight for the selected control point.
#[must_use]
pub fn start_weight_entry(s: &mut Stage) -> Mode {
    let Some(handle) = s.selection.selected else {
        s.set_status("select a control point first, then Shift+W types its weight");
        return Mode::Idle;
    };
    if let Err(e) = s.doc().set_weight(handle, 1.0) {
        s.set_status(e);
        return Mode::Idle;
    }
    Mode::WeightEntry {
        handle,
        text: String::new(),
    }
}

fn weight_key(s: &mut Stage, handle: Handle, mut text: String, key: Key) -> Mode {
    match key {
        Key::Char(c @ ('0'..='9' | '.' | 'e' | '-' | '+')) => text.push(c),
        Key::Backspace => {
            text.pop();
        }
        Key::Enter => {
            let edit = text
                .parse::<f64>()
                .map_err(|_| "not a number".to_string())
                .and_then(|w| s.doc().set_weight(handle, w));
            match edit {
                Ok(edit) => {
                    s.editor.begin("weight");
                    s.submit(edit);
                    s.editor.end();
                    s.editor.apply_queued();
                    s.refit_map = true;
                    let w = s.doc().weight_of(handle).unwrap_or(1.0);
                    s.set_status(format!(
                        "weight of {} is {w} (Ctrl+Z undoes)",
                        s.handle_name(handle)
                    ));
                }
                Err(e) => s.set_status(format!("weight not set: {e}")),
            }
            return Mode::Idle;
        }
        Key::Escape => {
            s.set_status("weight entry cancelled");
            return Mode::Idle;
        }
        _ => {}
    }
    Mode::WeightEntry { handle, text }
}

#[cfg(test)]
mod tests {
    use super::weight_for;

    #[test]
    fn weight_doubles_every_80_pixels_up_within_bounds() {
        assert_eq!(weight_for(1.0, 100.0, 20.0), 2.0);
        assert_eq!(weight_for(2.0, 100.0, 180.0), 1.0);
        assert_eq!(weight_for(1.0, 0.0, -1e6), 1e4);
        assert_eq!(weight_for(1.0, 0.0, 1e6), 1e-4);
    }
}

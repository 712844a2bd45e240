//! Reproducible benchmark sessions (`prespline bench --scenario`): input generated frame by
//! frame and fed through the same [`Session`] code paths as a user's mouse and keys.

use super::input::{InputEvent, Key, MouseButton};
use super::script::Action;
use super::session::Session;
use crate::editor::Handle;
use crate::model::{Index2, LocalPath, ModelRef};
use std::f64::consts::TAU;

/// What the scripted user does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scenario {
    /// Drag a surface control point in circles (one delta update per frame).
    Drag,
    /// Rotate an ERBS local patch (or local curve) continuously with R.
    ErbsRotate,
    /// Orbit the camera (no edits).
    Orbit,
    /// Nothing happens.
    Idle,
}

impl Scenario {
    pub const NAMES: [&'static str; 4] = ["drag", "erbs-rotate", "orbit", "idle"];

    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "drag" => Ok(Scenario::Drag),
            "erbs-rotate" => Ok(Scenario::ErbsRotate),
            "orbit" => Ok(Scenario::Orbit),
            "idle" => Ok(Scenario::Idle),
            _ => Err(format!(
                "unknown scenario '{s}' (expected one of: {})",
                Self::NAMES.join(", ")
            )),
        }
    }

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Scenario::Drag => "drag",
            Scenario::ErbsRotate => "erbs-rotate",
            Scenario::Orbit => "orbit",
            Scenario::Idle => "idle",
        }
    }
}

/// Frames per full circle of the scripted cursor.
const PERIOD: f64 = 90.0;
/// Radius of the cursor's circle in pixels.
const RADIUS: f64 = 40.0;

/// Generates the scenario's input, frame by frame. Frames before `warmup` set the scene up
/// (aim, select, press); measured frames `warmup..warmup+frames` carry the motion.
#[derive(Debug, Clone)]
pub struct ScenarioDriver {
    scenario: Scenario,
    warmup: usize,
    frames: usize,
    target: Option<Handle>,
    start: (f64, f64),
}

impl ScenarioDriver {
    pub fn new(
        scenario: Scenario,
        session: &Session,
        warmup: usize,
        frames: usize,
    ) -> Result<Self, String> {
        let target =
            match scenario {
                Scenario::Drag => Some(
                    drag_target(session)
                        .ok_or("the drag scenario needs an object with control points")?,
                ),
                Scenario::ErbsRotate => Some(erbs_target(session).ok_or(
                    "the erbs-rotate scenario needs an ERBS curve or surface in the scene",
                )?),
                Scenario::Orbit | Scenario::Idle => None,
            };
        if warmup < 4 && target.is_some() {
            return Err("this scenario needs at least 4 warm-up frames to aim and select".into());
        }
        Ok(Self {
            scenario,
            warmup,
            frames,
            target,
            start: (0.0, 0.0),
        })
    }

    /// The control point the scenario works on.
    #[must_use]
    pub fn target(&self) -> Option<Handle> {
        self.target
    }

    /// Input for frame `k` (0-based, warm-up included).
    pub fn actions(&mut self, k: usize, session: &Session) -> Vec<Action> {
        let w = self.warmup;
        let last = w + self.frames - 1;
        let button = |b, pressed| Action::Input(InputEvent::Button { button: b, pressed });
        let circle = |start: (f64, f64), k: usize, centre_offset: bool| {
            let t = TAU * (k - w + 1) as f64 / PERIOD;
            let (cx, cy) = if centre_offset {
                (start.0 - RADIUS, start.1)
            } else {
                start
            };
            Action::Input(InputEvent::CursorMoved {
                x: cx + RADIUS * t.cos(),
                y: cy + RADIUS * t.sin(),
            })
        };
        match self.scenario {
            Scenario::Idle => Vec::new(),
            Scenario::Orbit => {
                if k + 1 == w {
                    let [width, height] = session.size();
                    vec![
                        Action::Input(InputEvent::CursorMoved {
                            x: width * 0.5,
                            y: height * 0.5,
                        }),
                        button(MouseButton::Middle, true),
                    ]
                } else if k >= w && k < last {
                    vec![Action::MoveBy(4.0, 0.0)]
                } else if k == last {
                    vec![Action::MoveBy(4.0, 0.0), button(MouseButton::Middle, false)]
                } else {
                    Vec::new()
                }
            }
            Scenario::Drag => {
                let h = self.target.expect("drag has a target");
                if k + 2 == w {
                    self.start = session.handle_position(h).unwrap_or(self.start);
                    vec![Action::MoveTo(h)]
                } else if k + 1 == w {
                    vec![button(MouseButton::Left, true)]
                } else if k >= w && k < last {
                    // Circle through the grabbed point, so the drag starts without a jump.
                    vec![circle(self.start, k, true)]
                } else if k == last {
                    vec![
                        circle(self.start, k, true),
                        button(MouseButton::Left, false),
                    ]
                } else {
                    Vec::new()
                }
            }
            Scenario::ErbsRotate => {
                let h = self.target.expect("erbs-rotate has a target");
                if k + 4 == w {
                    vec![Action::MoveTo(h)]
                } else if k + 3 == w {
                    vec![
                        button(MouseButton::Left, true),
                        button(MouseButton::Left, false),
                    ]
                } else if k + 2 == w {
                    // Off the pivot, so the screen angle is well defined.
                    let (x, y) = session.handle_position(h).unwrap_or(session.cursor());
                    self.start = (x, y);
                    vec![Action::Input(InputEvent::CursorMoved { x: x + RADIUS, y })]
                } else if k + 1 == w {
                    vec![Action::Key {
                        key: Key::Char('r'),
                        mods: Default::default(),
                    }]
                } else if k >= w && k < last {
                    vec![circle(self.start, k, false)]
                } else if k == last {
                    vec![
                        circle(self.start, k, false),
                        Action::Key {
                            key: Key::Enter,
                            mods: Default::default(),
                        },
                    ]
                } else {
                    Vec::new()
                }
            }
        }
    }
}

/// An interior control point of the surface with the most control points (else of any object).
fn drag_target(session: &Session) -> Option<Handle> {
    let doc = session.doc();
    let best = (0..doc.objects.len())
        .filter(|&i| matches!(doc.objects[i].sampled.model(), ModelRef::Surface(_)))
        .max_by_key(|&i| doc.handles(i).len())
        .or_else(|| (0..doc.objects.len()).max_by_key(|&i| doc.handles(i).len()))?;
    let handles = doc.handles(best);
    match doc.objects[best].sampled.model() {
        ModelRef::Surface(s) => {
            let [nu, nv] = s.surface().count();
            Some(Handle::Point {
                object: best,
                point: Index2::Two(nu / 2, nv / 2),
            })
        }
        _ => handles.get(handles.len() / 2).map(|(h, _)| *h),
    }
}

/// The middle control point of the middle local patch (or curve) of the first ERBS object.
fn erbs_target(session: &Session) -> Option<Handle> {
    let doc = session.doc();
    for (object, o) in doc.objects.iter().enumerate() {
        match o.sampled.model() {
            ModelRef::ErbsSurface(s) => {
                let s = s.surface();
                let [nu, nv] = s.count();
                let (k, l) = (nu / 2, nv / 2);
                let ([a, b], _) = s.local_patch(k, l).net()?;
                return Some(Handle::LocalPoint {
                    object,
                    local: LocalPath::top(Index2::Two(k, l)),
                    point: Index2::Two(a / 2, b / 2),
                });
            }
            ModelRef::ErbsCurve(c) => {
                let c = c.curve();
                let l = c.local_curves().len() / 2;
                let q = c.local_curves()[l].points()?.len() / 2;
                return Some(Handle::LocalPoint {
                    object,
                    local: LocalPath::top(Index2::One(l)),
                    point: Index2::One(q),
                });
            }
            _ => {}
        }
    }
    None
}

//! `--script FILE`: timed input events replayed as if typed.
//!
//! A script is a JSON list; each entry has a time (`"frame": n` — the frame number, which makes
//! replays independent of speed — or `"t": seconds` since the first frame) and one action:
//!
//! ```json
//! [{"frame": 2, "move": [640, 360]},
//!  {"frame": 3, "move_to": {"object": "bspline_surface", "point": [3, 4]}},
//!  {"frame": 4, "press": "left"}, {"frame": 5, "move_by": [0, -40]}, {"frame": 6, "release": "left"},
//!  {"frame": 7, "key": "r"}, {"frame": 8, "type": "30"}, {"frame": 9, "key": "enter"},
//!  {"frame": 10, "key": "z", "ctrl": true}, {"frame": 11, "wheel": 2},
//!  {"frame": 12, "screenshot": "shot.png"}, {"frame": 13, "screenshot": "hud.png", "hud": true},
//!  {"frame": 14, "hold": ["alt"]}, {"frame": 15, "hold": []},
//!  {"frame": 16, "quit": true}]
//! ```
//!
//! `hold` keeps modifier keys down for the events that follow (an Alt+drag), `[]` releases.
//!
//! `move_to` aims the cursor at a control point (`"local"` too for ERBS objects), so scripts
//! keep working when the window size or framing changes. The point must exist when the event
//! runs (a refinement earlier in the script may have made it); a missing one ends the replay
//! with an error.

use super::input::{InputEvent, Key, Modifiers, MouseButton};
use crate::editor::{Document, Handle};
use crate::model::{Index2, LocalPath, ModelRef};
use crate::render::image_file::ImageFormat;
use serde_json::Value;
use std::path::PathBuf;

/// The latest time a script may name: a day. Later times are typos or fuzz, and a time past
/// what `Duration` and `Instant` hold would end the replay in a panic.
pub const MAX_SCRIPT_SECONDS: f64 = 86_400.0;
/// The last frame a script may name (about two days at 60 frames a second): frame-numbered
/// events keep frames coming until they run, so a larger number would draw until killed.
pub const MAX_SCRIPT_FRAME: u64 = 10_000_000;
/// Wheel steps per event at most: 0.85^1000 already zooms past any scene.
pub const MAX_WHEEL_STEPS: f64 = 1000.0;

/// When an action happens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum When {
    Frame(u64),
    Seconds(f64),
}

/// One scripted action.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    Input(InputEvent),
    /// Key press and release with modifiers held.
    Key {
        key: Key,
        mods: Modifiers,
    },
    MoveTo(Handle),
    /// The cursor onto object `object`'s drawn sample nearest the parameter `at` (a curve's t
    /// in `at[0]`, a surface's (u, v)), wherever the camera puts it.
    MoveOnto {
        object: usize,
        at: [f64; 2],
    },
    MoveBy(f64, f64),
    Type(String),
    /// A PNG or JPEG (by the extension) of the view (with the HUD when the flag is set).
    Screenshot(PathBuf, bool),
    Quit,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ScriptEvent {
    pub when: When,
    pub action: Action,
}

/// Parses a script against the document (object names and indices are checked up front).
pub fn parse_script(text: &str, doc: &Document) -> Result<Vec<ScriptEvent>, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("invalid JSON: {e}"))?;
    let list = v.as_array().ok_or("a script is a JSON list of events")?;
    list.iter()
        .enumerate()
        .map(|(i, e)| parse_event(e, doc).map_err(|m| format!("event {i}: {m}")))
        .collect()
}

fn parse_event(v: &Value, doc: &Document) -> Result<ScriptEvent, String> {
    let obj = v.as_object().ok_or("expected an object")?;
    let when = match (obj.get("frame"), obj.get("t")) {
        (Some(f), None) => {
            let f = f.as_u64().ok_or("'frame' must be a non-negative integer")?;
            if f > MAX_SCRIPT_FRAME {
                return Err(format!(
                    "'frame' {f} is beyond the last frame a script may name ({MAX_SCRIPT_FRAME}, about two days at 60 frames a second)"
                ));
            }
            When::Frame(f)
        }
        (None, Some(t)) => {
            let t = t
                .as_f64()
                .filter(|t| *t >= 0.0)
                .ok_or("'t' must be a non-negative number")?;
            if t > MAX_SCRIPT_SECONDS {
                return Err(format!(
                    "'t' {} s is beyond the longest a script may run ({MAX_SCRIPT_SECONDS} s, one day)",
                    crate::render::numbers::short(t)
                ));
            }
            When::Seconds(t)
        }
        _ => return Err("give exactly one of 'frame' and 't'".into()),
    };
    let flag = |k: &str| obj.get(k).and_then(Value::as_bool).unwrap_or(false);
    let mods = Modifiers {
        ctrl: flag("ctrl"),
        shift: flag("shift"),
        alt: flag("alt"),
    };
    let known = [
        "frame", "t", "ctrl", "shift", "alt", "object", "local", "point", "at", "hud",
    ];
    let actions: Vec<&String> = obj
        .keys()
        .filter(|k| !known.contains(&k.as_str()))
        .collect();
    let [name] = actions.as_slice() else {
        return Err(format!("expected exactly one action, found {:?}", actions));
    };
    let arg = &obj[name.as_str()];
    let pair = |a: &Value| -> Result<(f64, f64), String> {
        match a
            .as_array()
            .map(|x| x.iter().filter_map(Value::as_f64).collect::<Vec<_>>())
        {
            Some(p) if p.len() == 2 => Ok((p[0], p[1])),
            _ => Err(format!("'{name}' expects [x, y]")),
        }
    };
    let button = |a: &Value| -> Result<MouseButton, String> {
        serde_json::from_value(a.clone())
            .map_err(|_| format!("'{name}' expects \"left\", \"middle\" or \"right\""))
    };
    let action = match name.as_str() {
        "move" => {
            let (x, y) = pair(arg)?;
            Action::Input(InputEvent::CursorMoved { x, y })
        }
        "move_by" => {
            let (x, y) = pair(arg)?;
            Action::MoveBy(x, y)
        }
        "move_to" if arg.get("at").is_some() => onto(arg, doc)?,
        "move_to" => Action::MoveTo(handle(arg, doc)?),
        "press" => Action::Input(InputEvent::Button {
            button: button(arg)?,
            pressed: true,
        }),
        "release" => Action::Input(InputEvent::Button {
            button: button(arg)?,
            pressed: false,
        }),
        "wheel" => Action::Input(InputEvent::Wheel {
            delta: arg
                .as_f64()
                .filter(|d| d.abs() <= MAX_WHEEL_STEPS)
                .ok_or(format!(
                    "'wheel' expects a number of steps between -{MAX_WHEEL_STEPS} and {MAX_WHEEL_STEPS}"
                ))?,
        }),
        "key" => {
            let k = arg.as_str().and_then(Key::parse).ok_or(
                "'key' expects a key name (a character, enter, escape, backspace, home, f1)",
            )?;
            Action::Key { key: k, mods }
        }
        "type" => Action::Type(arg.as_str().ok_or("'type' expects a string")?.to_string()),
        "screenshot" => {
            let path = PathBuf::from(
                arg.as_str()
                    .filter(|p| !p.trim().is_empty())
                    .ok_or("'screenshot' expects a file name (a non-empty string)")?,
            );
            ImageFormat::of(&path).map_err(|e| format!("'screenshot': {e}"))?;
            Action::Screenshot(path, flag("hud"))
        }
        "hold" => {
            // {"hold": ["alt", "shift"]} keeps modifiers down for the following events
            // (an Alt+drag); {"hold": []} releases them.
            let names = arg
                .as_array()
                .ok_or("'hold' expects a list of modifier names")?;
            let mut m = Modifiers::default();
            for n in names {
                match n.as_str() {
                    Some("ctrl") => m.ctrl = true,
                    Some("shift") => m.shift = true,
                    Some("alt") => m.alt = true,
                    _ => return Err(format!("'hold': unknown modifier {n}")),
                }
            }
            Action::Input(InputEvent::Modifiers(m))
        }
        "quit" => Action::Quit,
        other => return Err(format!("unknown action '{other}'")),
    };
    Ok(ScriptEvent { when, action })
}

/// `{"object": name, "point": i | [i, j]}` or with `"local"` for ERBS objects.
/// The object a `move_to` names, by index, and its name.
fn target<'a>(v: &'a Value, doc: &Document) -> Result<(usize, &'a str), String> {
    let name = v
        .get("object")
        .and_then(Value::as_str)
        .ok_or("'move_to' needs \"object\"")?;
    let object = doc
        .objects
        .iter()
        .position(|o| o.name == name)
        .ok_or(format!("unknown object '{name}'"))?;
    Ok((object, name))
}

/// `{"object": NAME, "at": t}` (curves) or `"at": [u, v]` (surfaces): a parameter inside the
/// object's domain, which no edit changes, so it is checked here.
fn onto(v: &Value, doc: &Document) -> Result<Action, String> {
    let (object, name) = target(v, doc)?;
    if v.get("point").is_some() || v.get("local").is_some() {
        return Err("'move_to' takes either \"at\" or \"point\", not both".into());
    }
    let params = doc.objects[object].sampled.params();
    let at: Vec<f64> = match &v["at"] {
        Value::Number(n) => n.as_f64().into_iter().collect(),
        Value::Array(a) => a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect(),
        _ => Vec::new(),
    };
    if at.len() != params.len() {
        let want = if params.len() == 1 { "t" } else { "[u, v]" };
        return Err(format!("object '{name}': 'at' expects {want}"));
    }
    for (x, p) in at.iter().zip(&params) {
        let (lo, hi) = (p[0], p[p.len() - 1]);
        if !(lo..=hi).contains(x) {
            return Err(format!(
                "object '{name}': 'at' {x} is outside the domain [{lo}, {hi}]"
            ));
        }
    }
    Ok(Action::MoveOnto {
        object,
        at: [at[0], at.get(1).copied().unwrap_or(0.0)],
    })
}

fn handle(v: &Value, doc: &Document) -> Result<Handle, String> {
    let (object, name) = target(v, doc)?;
    let index = |k: &str| -> Result<Option<Index2>, String> {
        match v.get(k) {
            None => Ok(None),
            Some(Value::Number(n)) => Ok(Some(Index2::One(
                n.as_u64().ok_or(format!("bad '{k}'"))? as usize,
            ))),
            Some(Value::Array(a)) if a.len() == 2 => {
                let i = |x: &Value| x.as_u64().map(|u| u as usize).ok_or(format!("bad '{k}'"));
                Ok(Some(Index2::Two(i(&a[0])?, i(&a[1])?)))
            }
            Some(_) => Err(format!("bad '{k}'")),
        }
    };
    let point = index("point")?.ok_or("'move_to' needs \"point\"")?;
    let h = match v.get("local") {
        Some(l) => Handle::LocalPoint {
            object,
            local: local_path(l, doc.objects[object].sampled.model().is_surface())
                .ok_or("bad 'local': an index, [k, l], or a path of them")?,
            point,
        },
        None => Handle::Point { object, point },
    };
    // A point must fit its object's kind now; whether it exists is checked when the event
    // runs, since refinements earlier in the script add locals and control points.
    let model = doc.objects[object].sampled.model();
    let erbs = matches!(model, ModelRef::ErbsCurve(_) | ModelRef::ErbsSurface(_));
    let fits = match h {
        Handle::Point { point, .. } => {
            matches!(point, Index2::Two(..)) == model.is_surface() && !erbs
        }
        Handle::LocalPoint { point, .. } => {
            matches!(point, Index2::Two(..)) == model.is_surface() && erbs
        }
    };
    if !fits {
        return Err(format!("object '{name}' has no such control point"));
    }
    Ok(h)
}

/// Hands out script events as their time comes.
#[derive(Debug, Clone)]
pub struct ScriptPlayer {
    events: Vec<ScriptEvent>,
    next: usize,
}

impl ScriptPlayer {
    #[must_use]
    pub fn new(events: Vec<ScriptEvent>) -> Self {
        Self { events, next: 0 }
    }

    /// Events due at `frame` / `seconds`, in file order (an event waits for its predecessors).
    pub fn due(&mut self, frame: u64, seconds: f64) -> Vec<Action> {
        let mut out = Vec::new();
        while let Some(e) = self.events.get(self.next) {
            let ready = match e.when {
                When::Frame(f) => frame >= f,
                When::Seconds(t) => seconds >= t,
            };
            if !ready {
                break;
            }
            out.push(e.action.clone());
            self.next += 1;
        }
        out
    }

    #[must_use]
    pub fn finished(&self) -> bool {
        self.next >= self.events.len()
    }

    /// When the next event is due (`None` once all have run).
    #[must_use]
    pub fn next_when(&self) -> Option<When> {
        self.events.get(self.next).map(|e| e.when)
    }
}

/// An ERBS local: `l` or a path `[l, l2, …]` (curves); `[k, l]` or a path
/// `[[k, l], [k2, l2], …]` (surfaces).
fn local_path(v: &Value, surface: bool) -> Option<LocalPath<Index2>> {
    let one = |x: &Value| x.as_u64().map(|u| u as usize);
    let pair = |x: &Value| {
        let a = x.as_array().filter(|a| a.len() == 2)?;
        Some(Index2::Two(one(&a[0])?, one(&a[1])?))
    };
    let steps: Vec<Index2> = match (v, surface) {
        (Value::Array(a), true) if a.first().is_some_and(Value::is_array) => {
            a.iter().map(pair).collect::<Option<_>>()?
        }
        (_, true) => vec![pair(v)?],
        (Value::Array(a), false) => a
            .iter()
            .map(|x| one(x).map(Index2::One))
            .collect::<Option<_>>()?,
        (_, false) => vec![Index2::One(one(v)?)],
    };
    LocalPath::new(&steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::demo::demo_scene;

    fn parse(text: &str) -> Result<Vec<ScriptEvent>, String> {
        parse_script(text, &Document::new(&demo_scene()))
    }

    #[test]
    fn times_past_what_a_replay_can_reach_are_refused_in_one_line() {
        for (text, needle) in [
            (r#"[{"t": 1e300, "key": "a"}]"#, "'t'"),
            (r#"[{"t": 1e19, "key": "a"}]"#, "'t'"),
            (
                r#"[{"frame": 18446744073709551615, "key": "a"}]"#,
                "'frame'",
            ),
            (r#"[{"frame": 10000001, "quit": true}]"#, "'frame'"),
            (r#"[{"frame": 1, "wheel": 1e300}]"#, "'wheel'"),
            (r#"[{"frame": 1, "screenshot": ""}]"#, "'screenshot'"),
            (
                r#"[{"frame": 1, "screenshot": "x.gif"}]"#,
                "cannot write .gif",
            ),
        ] {
            let e = parse(text).expect_err(text);
            assert!(
                e.starts_with("event 0: ") && e.contains(needle),
                "{text}: {e}"
            );
            assert!(!e.contains('\n'), "{text}: one line, got {e:?}");
            // A huge number is written short, not digit by digit (1e300 has 301).
            assert!(e.len() < 200, "{text}: {} characters: {e}", e.len());
        }
    }

    #[test]
    fn move_to_a_parameter_is_checked_against_the_object() {
        let events =
            parse(r#"[{"frame": 1, "move_to": {"object": "bspline_surface", "at": [0.25, 0.5]}}]"#)
                .unwrap();
        assert!(matches!(
            events[0].action,
            Action::MoveOnto {
                at: [0.25, 0.5],
                ..
            }
        ));
        for (at, needle) in [
            ("0.5", "expects [u, v]"),
            ("[0.5]", "expects [u, v]"),
            ("[0.5, 7]", "outside the domain"),
            ("[0.5, \"x\"]", "outside the domain"),
            ("[0.5, 0.5], \"point\": [1, 1]", "not both"),
        ] {
            let text = format!(
                r#"[{{"frame": 1, "move_to": {{"object": "bspline_surface", "at": {at}}}}}]"#
            );
            let e = parse(&text).expect_err(&text);
            assert!(
                e.starts_with("event 0: ") && e.contains(needle),
                "{text}: {e}"
            );
        }
    }

    /// A screenshot's format comes from its extension, checked when the script is loaded:
    /// .png, .jpg and .jpeg (any case) are taken; .gif, .bmp and no extension are refused in
    /// one line naming the event and the path, before the window opens.
    #[test]
    fn screenshots_take_png_or_jpeg_and_refuse_other_extensions_at_load() {
        for ok in ["a.png", "b.jpg", "c.JPEG", "dir/d.Png"] {
            let text = format!(r#"[{{"frame": 1, "screenshot": "{ok}", "hud": true}}]"#);
            let events = parse(&text).unwrap_or_else(|e| panic!("{ok}: {e}"));
            assert_eq!(
                events[0].action,
                Action::Screenshot(PathBuf::from(ok), true)
            );
        }
        for (bad, needle) in [
            (
                "b.gif",
                "b.gif: cannot write .gif images (use .png, .jpg or .jpeg)",
            ),
            ("b.bmp", "cannot write .bmp images"),
            ("shot", "shot: the image needs an extension"),
        ] {
            let text =
                format!(r#"[{{"frame": 1, "key": "m"}}, {{"frame": 2, "screenshot": "{bad}"}}]"#);
            let e = parse(&text).expect_err(bad);
            assert!(e.starts_with("event 1: 'screenshot': "), "{bad}: {e}");
            assert!(e.contains(needle), "{bad}: {e}");
            assert!(!e.contains('\n'), "{bad}: one line, got {e:?}");
        }
    }

    /// The example script of docs/viewer.md ("Example") parses against the demo scene, so the
    /// documentation cannot drift from the format.
    #[test]
    fn the_example_in_the_viewer_docs_parses() {
        let doc = include_str!("../../docs/viewer.md");
        let example = doc
            .split_once("### Example")
            .expect("docs/viewer.md has an Example section")
            .1;
        let json = example
            .split_once("```json\n")
            .and_then(|(_, rest)| rest.split_once("```"))
            .expect("the Example section has a JSON block")
            .0;
        let events = parse(json).unwrap_or_else(|e| panic!("docs/viewer.md example: {e}"));
        assert_eq!(events.len(), 27);
        assert!(events.iter().any(|e| e.action == Action::Quit));
        let shots = events
            .iter()
            .filter(|e| matches!(e.action, Action::Screenshot(..)))
            .count();
        assert_eq!(shots, 2, "edited.png and undone.png");
        // Negative control: a misspelt action in the same block is refused.
        let bad = json.replacen("\"press\"", "\"pres\"", 1);
        assert!(parse(&bad).unwrap_err().contains("unknown action 'pres'"));
    }

    #[test]
    fn the_limits_themselves_are_accepted() {
        let text = format!(
            r#"[{{"t": {MAX_SCRIPT_SECONDS}, "key": "a"}}, {{"frame": {MAX_SCRIPT_FRAME}, "wheel": {MAX_WHEEL_STEPS}}}]"#
        );
        let events = parse(&text).unwrap();
        assert_eq!(events[0].when, When::Seconds(MAX_SCRIPT_SECONDS));
        assert_eq!(events[1].when, When::Frame(MAX_SCRIPT_FRAME));
    }
}

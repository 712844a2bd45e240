//! What a key means when no gesture has claimed it: one table from keys to commands, and the
//! help the overlay shows for them. Typed values, U/V, Enter and Esc inside a transform, a
//! knot insertion or a weight entry belong to those modes ([`super::modes`]).

use super::input::{Key, Modifiers};
use super::tools::TransformKind;

/// A command of the viewer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    Undo,
    Redo,
    Save,
    Quit,
    /// X, Y or Z during a drag: along an axis (the drag's own key).
    DragAxis,
    /// X: the selected polynomial ERBS local becomes an ERBS of its own.
    LocalToErbs,
    /// I: aim a knot insertion or an ERBS refinement.
    Refine,
    /// E: degree elevation in u (`0`) or v (`1`, with Shift).
    Elevate(usize),
    Transform(TransformKind),
    /// Shift+W: type the selected point's weight.
    WeightEntry,
    /// B: a Catmull–Rom or Bézier spline becomes its bspline_curve.
    ToBspline,
    CycleNets,
    ToggleLocals,
    CycleWire,
    ToggleNormals,
    ToggleFrenet,
    ToggleComb,
    ToggleBadges,
    ToggleOsculating,
    CycleMap,
    ToggleLod,
    ToggleHud,
    ToggleHelp,
    FrameSelection,
    FrameAll,
    Home,
    /// Esc: deselect, close the help.
    Escape,
}

/// The command a key press stands for (`dragging`: a control point drag is running).
#[must_use]
pub fn command(key: Key, mods: Modifiers, dragging: bool) -> Option<Command> {
    use Command::*;
    let c = match key {
        Key::Char(c) => c,
        Key::F1 => return Some(ToggleHelp),
        Key::Home => return Some(Home),
        Key::Escape => return Some(Escape),
        _ => return None,
    };
    if mods.ctrl {
        return match c {
            'z' if mods.shift => Some(Redo),
            'z' => Some(Undo),
            'y' => Some(Redo),
            's' => Some(Save),
            'q' => Some(Quit),
            _ => None,
        };
    }
    Some(match c {
        'x' | 'y' | 'z' if dragging => DragAxis,
        'x' => LocalToErbs,
        'i' => Refine,
        'e' => Elevate(usize::from(mods.shift)),
        'g' => Transform(TransformKind::Grab),
        'r' => Transform(TransformKind::Rotate),
        's' => Transform(TransformKind::Scale),
        'w' if mods.shift => WeightEntry,
        'w' => CycleWire,
        'b' => ToBspline,
        'c' => CycleNets,
        'l' => ToggleLocals,
        'n' => ToggleNormals,
        't' => ToggleFrenet,
        'k' => ToggleComb,
        'j' => ToggleBadges,
        'o' => ToggleOsculating,
        'm' => CycleMap,
        'd' => ToggleLod,
        'p' => ToggleHud,
        'h' => ToggleHelp,
        'f' => FrameSelection,
        'a' => FrameAll,
        _ => return None,
    })
}

/// Every key binding as the help overlay (H or F1) shows it, next to the map it describes;
/// docs/viewer.md and the README's key table describe the same keys.
pub const KEY_HELP: &[(&str, &str)] = &[
    (
        "left drag on a point",
        "move it in the view plane (X/Y/Z while dragging: along an axis)",
    ),
    ("left drag elsewhere", "orbit"),
    (
        "middle drag / right drag / shift+left drag",
        "orbit / pan / pan",
    ),
    ("wheel", "zoom to the cursor"),
    (
        "click a point",
        "select it (ERBS: selects its local curve/patch too)",
    ),
    (
        "G / R / S",
        "grab / rotate / scale the selected local curve or patch (G also a point)",
    ),
    (
        "  X / Y / Z, digits, Enter",
        "axis constraint, typed value (distance, degrees, factor), confirm",
    ),
    ("  Esc / right click", "cancel the transform"),
    (
        "I",
        "insert a knot at the cursor on the selected (or hovered) curve or surface (U/V direction)",
    ),
    (
        "  on ERBS",
        "refine at the cursor: a new local (row/column of patches) in the selected local's level",
    ),
    (
        "X",
        "turn the selected polynomial ERBS local into an ERBS of its own (3 locals per direction, same shape)",
    ),
    (
        "E / Shift+E",
        "elevate the degree of the selected (or hovered) curve or surface (in u / in v)",
    ),
    (
        "Alt+drag on a point / Shift+W",
        "change its weight (up: heavier) / type its weight; a polynomial object becomes rational",
    ),
    (
        "B",
        "convert the selected Catmull-Rom or Bezier spline to a bspline_curve",
    ),
    (
        "J / O",
        "continuity badges at joins / osculating circle, curvature, torsion at the cursor",
    ),
    (
        "M",
        "surface map: Gaussian, mean, max and min principal curvature, zebra, off",
    ),
    ("Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y)", "undo / redo"),
    ("Ctrl+S", "save the scene file"),
    ("F / A / Home", "frame selection / frame all / reset camera"),
    (
        "C / L / W",
        "control nets (all, focused, off) / local curves / wireframe (off, isolines, full)",
    ),
    ("N / T / K", "normals / Frenet frames / curvature combs"),
    (
        "D",
        "level of detail on/off (dense surfaces drawn from a strided subset)",
    ),
    ("P", "performance overlay"),
    ("H or F1", "this help"),
    ("Esc", "deselect, close this help"),
    ("Ctrl+Q or close the window", "quit"),
];

#[cfg(test)]
mod tests {
    use super::*;

    fn with(ctrl: bool, shift: bool) -> Modifiers {
        Modifiers {
            ctrl,
            shift,
            alt: false,
        }
    }

    #[test]
    fn modifiers_and_drags_change_what_a_key_means() {
        let plain = with(false, false);
        assert_eq!(
            command(Key::Char('z'), with(true, false), false),
            Some(Command::Undo)
        );
        assert_eq!(
            command(Key::Char('z'), with(true, true), false),
            Some(Command::Redo)
        );
        assert_eq!(
            command(Key::Char('s'), with(true, false), false),
            Some(Command::Save)
        );
        assert_eq!(
            command(Key::Char('s'), plain, false),
            Some(Command::Transform(TransformKind::Scale))
        );
        assert_eq!(
            command(Key::Char('x'), plain, false),
            Some(Command::LocalToErbs)
        );
        assert_eq!(
            command(Key::Char('x'), plain, true),
            Some(Command::DragAxis)
        );
        assert_eq!(
            command(Key::Char('e'), with(false, true), false),
            Some(Command::Elevate(1))
        );
        assert_eq!(
            command(Key::Char('w'), with(false, true), false),
            Some(Command::WeightEntry)
        );
        assert_eq!(
            command(Key::Char('w'), plain, false),
            Some(Command::CycleWire)
        );
        assert_eq!(command(Key::Char('?'), plain, false), None);
        assert_eq!(
            command(Key::Char('q'), plain, false),
            None,
            "quit needs Ctrl"
        );
    }

    #[test]
    fn every_letter_the_help_names_is_mapped() {
        // The single letters and F-keys of the help's key column (before any description).
        for (keys, _) in KEY_HELP {
            for word in keys.split(['/', ' ', ',']) {
                let word = word.trim();
                if word.len() == 1 && word.chars().all(|c| c.is_ascii_uppercase()) {
                    let c = word.chars().next().unwrap().to_ascii_lowercase();
                    let mapped = command(Key::Char(c), with(false, false), false).is_some()
                        || command(Key::Char(c), with(false, false), true).is_some();
                    assert!(
                        mapped,
                        "the help names {word} ({keys}) but no command has it"
                    );
                }
            }
        }
    }
}

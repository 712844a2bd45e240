//! Input events independent of the windowing system: the viewer translates winit events into
//! these, and `--script` files and benchmark scenarios produce them directly, so scripted
//! sessions go through exactly the code paths a user's input does.

use serde::Deserialize;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MouseButton {
    Left,
    Middle,
    Right,
}

/// A key, by what it means to the viewer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// A letter (lower case), digit or punctuation character.
    Char(char),
    Enter,
    Escape,
    Backspace,
    Home,
    F1,
    Other,
}

impl Key {
    /// Parses a key name as used in scripts: a single character, or one of `enter`, `escape`,
    /// `backspace`, `home`, `f1`.
    #[must_use]
    pub fn parse(name: &str) -> Option<Key> {
        let lower = name.to_ascii_lowercase();
        Some(match lower.as_str() {
            "enter" | "return" => Key::Enter,
            "escape" | "esc" => Key::Escape,
            "backspace" => Key::Backspace,
            "home" => Key::Home,
            "f1" => Key::F1,
            s if s.chars().count() == 1 => Key::Char(s.chars().next().expect("one char")),
            _ => return None,
        })
    }
}

/// Modifier state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Modifiers {
    pub ctrl: bool,
    pub shift: bool,
    pub alt: bool,
}

/// One input event in window pixel coordinates (origin top-left).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InputEvent {
    CursorMoved {
        x: f64,
        y: f64,
    },
    Button {
        button: MouseButton,
        pressed: bool,
    },
    /// Wheel notches; positive zooms in.
    Wheel {
        delta: f64,
    },
    Key {
        key: Key,
        pressed: bool,
    },
    Modifiers(Modifiers),
}

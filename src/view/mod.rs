//! The interactive viewer: a winit window over the [`session::Session`] core (camera, picking,
//! dragging, ERBS local transforms, undo/redo, save, overlays), scripted input for demos and
//! tests, and the HUD.

pub mod app;
pub mod autosave;
pub mod hud;
pub mod input;
pub mod keymap;
pub mod modes;
pub mod picking;
pub mod refine;
pub mod scenario;
pub mod script;
pub mod session;
pub mod stage;
pub mod structure;
pub mod tools;

pub use session::Session;

//! The JSON scene format (docs/scene-format.md, a contract): prespline's own, which holds every
//! kind exactly and is what the viewer's autosaves are written in.

mod read;
mod trim;
mod write;

pub use read::parse_scene;
pub use write::scene_to_json;

use super::context::{FileFormat, FormatError, Import, LoadContext, Written};
use crate::scene::Scene;

/// The JSON scene format.
#[derive(Debug, Clone, Copy)]
pub struct JsonScene;

impl FileFormat for JsonScene {
    fn name(&self) -> &'static str {
        "JSON scene"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["json"]
    }

    fn read(&self, bytes: &[u8], ctx: &LoadContext<'_>) -> Result<Import, FormatError> {
        let text = std::str::from_utf8(bytes)
            .map_err(|e| FormatError::new(format!("invalid JSON: not UTF-8 ({e})")))?;
        Ok(Import::plain(parse_scene(text, ctx)?))
    }

    fn write(&self, scene: &Scene) -> Result<Written, FormatError> {
        Ok(Written {
            bytes: scene_to_json(scene).into_bytes(),
            dropped: Vec::new(),
        })
    }

    fn writes(&self) -> bool {
        true
    }
}

//! The scene file's JSON vocabulary below every layer that reads or writes it: typed readers
//! whose errors name the object, field and index ([`json`]), and the writers ([`write`]). The
//! kinds in `model` read and write their own fields with these; `scene` frames the objects.

pub mod json;
pub mod write;

pub use json::{At, ReadCtx, SceneError};

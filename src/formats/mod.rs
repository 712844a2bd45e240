//! File formats: one folder per format behind one trait, [`FileFormat`] — read a file's bytes
//! to scene objects, write them back, carry what the program cannot use — listed once in
//! [`FORMATS`]. A new format is its folder, one entry in that list and its `mod` line here.
//!
//! This floor sits on `scene` (the objects) and `model` (the kinds, which read and write their
//! own fields); the command line and the viewer load and save through [`load`] and [`save`].

pub mod cad;
mod context;
pub mod demo;
pub mod iges;
pub mod json;
pub mod obj;
mod registry;
pub mod step;

pub use context::{
    FileFormat, FormatError, Import, LoadContext, Located, SampleDefaults, Skipped, Written,
};
pub use registry::{
    FORMATS, LoadOptions, check_save, format_of, known_extensions, load, load_json, parse_scene,
    read_json, save, save_json,
};

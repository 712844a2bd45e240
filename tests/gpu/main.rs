//! The headless GPU tests in one binary (lavapipe, Khronos validation on): the renderer API,
//! draws, mirrors, error paths, golden images, level of detail, and `prespline render` and
//! `bench` runs. Windowed tests (Xvfb) and the missing-driver test keep their own binaries.

#[path = "../common/mod.rs"]
mod common;

mod cli_bench;
mod cli_render;
mod gpu_api;
mod gpu_draws;
mod gpu_errors;
mod gpu_mirror;
mod gpu_scene;
mod obj_render;
mod render_analysis;
mod render_golden;
mod render_lod;
mod render_mirror;
mod retained;
mod trims;

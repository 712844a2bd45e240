//! The CPU-side integration tests in one binary: geometry, sampling, the oracle, scene files,
//! OBJ and the command line (run as a subprocess). One binary links the crate once instead of
//! once per file; the GPU and windowed tests keep their own binaries under `tests/`.

#[path = "../common/mod.rs"]
mod common;
#[path = "../oracle/mod.rs"]
mod oracle;

mod budget_counts;
mod cad_errors;
mod cad_reference;
mod cli_errors;
mod cli_help;
mod cli_spline_errors;
mod curvature_maps;
mod delta_vs_full;
mod erbs_hierarchy;
mod geom_properties;
mod large_surface_threads;
mod lints;
mod obj_blender;
mod obj_errors;
mod obj_kept;
mod obj_roundtrip;
mod oracle_agreement;
mod oracle_selfcheck;
mod oracle_trim_area;
mod profile_outputs;
mod splines;
mod structural_cli;
mod structural_edits;
mod structural_shape;
mod support;
mod trim_area;
mod trims;
mod undo_chains;

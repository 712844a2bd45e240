//! Editor → GPU: the orbit camera, per-object mirrors with per-slot dirty tracking fed by the
//! editor's [`Applied`](crate::editor::Applied) reports, display options and overlays. Used by `prespline render` (offscreen) and the
//! viewer (swapchain).

pub mod analysis;
pub mod camera;
mod control_pass;
pub mod gpu_scene;
mod grips;
pub mod image_file;
pub mod lod;
pub mod map_mirror;
pub mod maps;
pub mod numbers;
pub mod offscreen;
pub mod overlays;
pub mod retained;
pub mod style;
mod trim_mask;

pub use camera::{Bounds, OrbitCamera};
pub use gpu_scene::{DrawReport, GpuScene, UploadStats};
pub use lod::Lod;
pub use map_mirror::MapView;
pub use retained::{Gesture, Redraw};
pub use style::{Highlight, NetMode, Palette, ViewOptions, Wire};

use crate::gpu::ValidationMode;
use crate::sampling::budget::Uses;

/// What interactive drawing (`view`, `bench`) keeps per object besides the samples: GPU
/// mirrors in every frame slot, index buffers, a mirror of every control display (the nets
/// can be shown at any time).
pub const DRAW_USES: Uses = Uses {
    gpu_slots: crate::gpu::FRAMES_IN_FLIGHT as u8,
    control_displays: true,
    json_text: false,
};

/// What `render` keeps per object besides the samples: it draws one frame, so one slot of
/// the GPU mirrors is ever written, and control displays only with `--net`.
#[must_use]
pub const fn render_uses(nets: bool) -> Uses {
    Uses {
        gpu_slots: 1,
        control_displays: nets,
        ..DRAW_USES
    }
}

/// Validation layer policy for interactive commands: on in debug builds or with
/// `PRESPLINE_VALIDATION=1`, when the layer is installed; `PRESPLINE_VALIDATION=required`
/// refuses to run without it (tests must not pass unvalidated); `0` turns it off.
#[must_use]
pub fn validation_mode() -> ValidationMode {
    let env = std::env::var("PRESPLINE_VALIDATION").ok();
    match env.as_deref() {
        Some("required") => ValidationMode::Required,
        Some("1") => ValidationMode::IfAvailable,
        Some("0") => ValidationMode::Off,
        _ if cfg!(debug_assertions) => ValidationMode::IfAvailable,
        _ => ValidationMode::Off,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_budget_counts_the_run_length_the_renderer_draws() {
        // `sampling` does not depend on `gpu`, so the constant is written twice.
        assert_eq!(
            crate::sampling::budget::RUN_VERTICES,
            crate::gpu::RUN_VERTICES
        );
    }
}

//! GPU error paths with injected failures (lavapipe, validation and synchronization validation
//! on): a failed submission or a failed upload wait is reported as an error, never a hang, and
//! the renderer stays usable — both frame slots are reused afterwards, images are read back,
//! and the validation layer sees nothing wrong (no reset of pending work, no fence that can
//! never signal).

use crate::common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use prespline::gpu::{
    Fault, GpuError, GridShape, OffscreenDesc, OffscreenTarget, Pixels, Renderer, SurfaceGrid,
    SurfaceStyle, vk,
};

/// Fails the test (and the process) if `f` has not returned within a minute: a hang must
/// fail, not stall the suite.
fn within_a_minute<T>(name: &'static str, f: impl FnOnce() -> T) -> T {
    let done = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&done);
    std::thread::spawn(move || {
        for _ in 0..600 {
            std::thread::sleep(Duration::from_millis(100));
            if flag.load(Ordering::Relaxed) {
                return;
            }
        }
        eprintln!("{name}: hung for a minute");
        std::process::exit(1);
    });
    let out = f();
    done.store(true, Ordering::Relaxed);
    out
}

const SHAPE: GridShape = GridShape { rows: 12, cols: 10 };

struct Scene {
    target: OffscreenTarget,
    mirror: prespline::gpu::Mirror,
    grid: SurfaceGrid,
}

fn scene(r: &mut Renderer) -> Scene {
    let target = r
        .create_offscreen(&OffscreenDesc {
            width: 64,
            height: 48,
            samples: 1,
        })
        .expect("target");
    let grid = SurfaceGrid {
        offset: 0,
        shape: SHAPE,
    };
    let data = common::height_field(SHAPE, &[(0.0, 0.0, 0.6, 0.5)]);
    let mut mirror = r.create_mirror("surface", data.len()).expect("mirror");
    r.fill_mirror(&mut mirror, 0, &data).expect("fill");
    Scene {
        target,
        mirror,
        grid,
    }
}

/// One frame of the surface; `capture` copies it for read-back.
fn frame(r: &mut Renderer, s: &mut Scene, capture: bool) -> Result<u64, GpuError> {
    let mut frame = r.begin_offscreen(&mut s.target)?;
    frame.set_camera(common::camera(glam::Vec3::new(0.0, -2.5, 2.0), 64, 48));
    frame.draw_surface(&s.mirror, s.grid, &SurfaceStyle::default())?;
    if capture {
        frame.capture();
    }
    frame.finish()
}

fn finish(mut r: Renderer, s: Scene, sink: prespline::gpu::ValidationSink) {
    r.destroy_mirror(s.mirror);
    r.destroy_offscreen(s.target).expect("destroy target");
    common::teardown(r, sink);
}

fn not_blank(px: &Pixels) -> bool {
    let first = px.get(0, 0);
    (0..px.height).any(|y| (0..px.width).any(|x| px.get(x, y) != first))
}

#[test]
fn a_failed_submit_leaves_both_slots_usable() {
    within_a_minute("failed submit", || {
        let (mut r, sink) = common::renderer();
        let mut s = scene(&mut r);
        frame(&mut r, &mut s, true).expect("first frame");
        let before = r.frame_number();
        r.inject_fault(Fault::Submit(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY));
        let err = frame(&mut r, &mut s, true).expect_err("the injected failure");
        assert!(
            matches!(
                err,
                GpuError::Vk {
                    call: "vkQueueSubmit2",
                    result: vk::Result::ERROR_OUT_OF_DEVICE_MEMORY
                }
            ),
            "{err:?}"
        );
        assert_eq!(r.frame_number(), before, "a failed frame is not counted");
        // The failed frame's pixels were never produced.
        assert!(r.read_pixels(&s.target).is_err());
        // Several frames reuse both slots; the failed slot's fence must not be waited for.
        for k in 0..5 {
            frame(&mut r, &mut s, k == 4).expect("frames after the failure");
        }
        let px = r.read_pixels(&s.target).expect("read back");
        assert!(
            not_blank(&px),
            "the surface was not drawn after the failure"
        );
        finish(r, s, sink);
    });
}

#[test]
fn a_lost_device_is_reported_as_such() {
    within_a_minute("device lost", || {
        let (mut r, sink) = common::renderer();
        let mut s = scene(&mut r);
        r.inject_fault(Fault::Submit(vk::Result::ERROR_DEVICE_LOST));
        let err = frame(&mut r, &mut s, false).expect_err("the injected loss");
        assert!(err.is_device_lost(), "{err:?}");
        let text = err.to_string();
        assert!(
            !text.contains('\n') && text.contains("device was lost"),
            "{text}"
        );
        finish(r, s, sink);
    });
}

#[test]
fn a_failed_upload_wait_is_an_error_and_the_next_upload_works() {
    within_a_minute("failed upload wait", || {
        let (mut r, sink) = common::renderer();
        let mut s = scene(&mut r);
        // The surface's index buffer is uploaded on its first draw: make that wait fail
        // after the copy was submitted. The uploader must not reset a pool whose command
        // buffer may be pending (synchronization validation would object) nor hang.
        r.inject_fault(Fault::UploadWait(vk::Result::TIMEOUT));
        let mut f = r.begin_offscreen(&mut s.target).expect("begin");
        let err = f
            .draw_surface(&s.mirror, s.grid, &SurfaceStyle::default())
            .expect_err("the injected wait failure");
        assert!(matches!(err, GpuError::Timeout { .. }), "{err:?}");
        f.finish().expect("the frame itself still submits");
        // The same shape uploads again, and draws.
        frame(&mut r, &mut s, true).expect("frame after the failed upload");
        let px = r.read_pixels(&s.target).expect("read back");
        assert!(not_blank(&px));
        finish(r, s, sink);
    });
}

#[test]
fn the_injected_failures_are_real_negative_controls() {
    // Without injection the same frames succeed: the failures above come from the injection.
    within_a_minute("control", || {
        let (mut r, sink) = common::renderer();
        let mut s = scene(&mut r);
        for k in 0..3 {
            frame(&mut r, &mut s, k == 2).expect("plain frame");
        }
        assert!(not_blank(&r.read_pixels(&s.target).expect("read")));
        finish(r, s, sink);
    });
}

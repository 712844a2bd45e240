//! Swapchain smoke test: a real winit window (X11, e.g. under Xvfb), a few presented frames,
//! a resize, a switch away from vsync, a frame whose submission fails after its image was
//! acquired (the next frames must still present, validation-clean), and a leak-free teardown.
//! Skipped without `DISPLAY`, except under `make test` and CI, where that fails.
//! winit allows one event loop per process, so this binary holds exactly one windowed test
//! (the other only runs it again in child processes).
//!
//! `Xvfb :99 -screen 0 1280x1024x24 -noreset & DISPLAY=:99 cargo test --test gpu_window`

mod common;

use std::time::Duration;

use glam::Vec3;
use prespline::gpu::font::{TextSize, push_rect};
use prespline::gpu::{
    Fault, GpuError, GridShape, Mirror, PolylineStyle, Renderer, RendererDesc, SurfaceGrid,
    SurfaceStyle, Swapchain, SwapchainDesc, ValidationMode, ValidationSink, vk,
};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::platform::x11::EventLoopBuilderExtX11;
use winit::raw_window_handle::HasDisplayHandle;
use winit::window::{Window, WindowId};

const FRAMES: u32 = 12;
const MAX_REDRAWS: u32 = 400;

struct Gpu {
    renderer: Renderer,
    swapchain: Swapchain,
    mirror: Mirror,
    grid: SurfaceGrid,
    // The swapchain keeps its own reference to the window.
    window: std::sync::Arc<Window>,
}

#[derive(Default)]
struct App {
    gpu: Option<Gpu>,
    sink: Option<ValidationSink>,
    presented: u32,
    redraws: u32,
    skipped: u32,
    resized_to: Option<[u32; 2]>,
    last_extent: [u32; 2],
    minimised_once: bool,
    last_mode: Option<vk::PresentModeKHR>,
    /// Whether the injected submit failure was reported as the device-lost error.
    failed_submit_reported: bool,
    error: Option<String>,
    done: bool,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, message: String) {
        self.error = Some(message);
        self.shutdown(event_loop);
    }

    fn shutdown(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(mut gpu) = self.gpu.take() {
            let r = &mut gpu.renderer;
            r.destroy_mirror(gpu.mirror);
            if let Err(e) = r.destroy_swapchain(gpu.swapchain) {
                self.error.get_or_insert(format!("destroy swapchain: {e}"));
            }
            drop(gpu.renderer);
            drop(gpu.window);
        }
        self.done = true;
        event_loop.exit();
    }

    fn create(&mut self, event_loop: &ActiveEventLoop) -> Result<(), String> {
        let attrs = Window::default_attributes()
            .with_title("prespline gpu test")
            .with_inner_size(PhysicalSize::new(320, 240));
        let window =
            std::sync::Arc::new(event_loop.create_window(attrs).map_err(|e| e.to_string())?);
        let display = window.display_handle().map_err(|e| e.to_string())?.as_raw();
        let mut renderer = Renderer::new(&RendererDesc {
            app_name: "prespline-window-test".into(),
            validation: ValidationMode::Required,
            sync_validation: false,
            display: Some(display),
            always_flush: false,
            device: Some("llvmpipe".into()),
        })
        .map_err(|e| e.to_string())?;
        if renderer.caps().device_type != vk::PhysicalDeviceType::CPU {
            return Err(format!("not lavapipe: {}", renderer.caps().name));
        }
        self.sink = renderer.validation_sink();
        let size = window.inner_size();
        let swapchain = renderer
            .create_swapchain(
                std::sync::Arc::clone(&window),
                &SwapchainDesc {
                    width: size.width,
                    height: size.height,
                    vsync: true,
                    samples: 0,
                },
            )
            .map_err(|e| e.to_string())?;
        if swapchain.present_mode() != vk::PresentModeKHR::FIFO {
            return Err(format!("vsync gave {:?}", swapchain.present_mode()));
        }
        let shape = GridShape { rows: 20, cols: 20 };
        let grid = SurfaceGrid { offset: 0, shape };
        let data = common::height_field(shape, &[(0.0, 0.0, 0.5, 0.5)]);
        let mut mirror = renderer
            .create_mirror("window surface", data.len())
            .map_err(|e| e.to_string())?;
        renderer
            .fill_mirror(&mut mirror, 0, &data)
            .map_err(|e| e.to_string())?;
        window.request_redraw();
        self.gpu = Some(Gpu {
            renderer,
            swapchain,
            mirror,
            grid,
            window,
        });
        Ok(())
    }

    fn redraw(&mut self) -> Result<(), String> {
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        self.redraws += 1;
        if self.presented == 4 && self.resized_to.is_none() {
            // Resize mid-run: the swapchain must follow.
            let _ = gpu.window.request_inner_size(PhysicalSize::new(400, 300));
            self.resized_to = Some([400, 300]);
        }
        if self.presented == 8 {
            gpu.swapchain.set_vsync(false);
        }
        if self.presented == 6 && !self.minimised_once {
            // A minimised window reports 0x0: no frame, no error, until a real size returns.
            gpu.swapchain.resize(0, 0);
            self.minimised_once = true;
            if gpu
                .renderer
                .begin_swapchain(&mut gpu.swapchain)
                .map_err(|e| e.to_string())?
                .is_some()
            {
                return Err("a frame was begun on a zero-size swapchain".into());
            }
            self.skipped += 1;
            let size = gpu.window.inner_size();
            gpu.swapchain.resize(size.width, size.height);
        }
        let inject = self.presented == 10 && !self.failed_submit_reported;
        if inject {
            gpu.renderer
                .inject_fault(Fault::Submit(vk::Result::ERROR_DEVICE_LOST));
        }
        let Some(mut frame) = gpu
            .renderer
            .begin_swapchain(&mut gpu.swapchain)
            .map_err(|e| e.to_string())?
        else {
            self.skipped += 1;
            return Ok(());
        };
        let [w, h] = frame.extent();
        frame.set_clear_color([0.1, 0.1, 0.15, 1.0]);
        frame.set_camera(common::camera(Vec3::new(0.0, -2.5, 2.0), w, h));
        frame
            .draw_surface(&gpu.mirror, gpu.grid, &SurfaceStyle::default())
            .map_err(|e| e.to_string())?;
        frame
            .draw_wire(&gpu.mirror, gpu.grid, 4, [0.0, 0.0, 0.0, 1.0])
            .map_err(|e| e.to_string())?;
        frame
            .draw_polyline_immediate(
                &[[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]],
                &PolylineStyle::default(),
            )
            .map_err(|e| e.to_string())?;
        let mut hud = Vec::new();
        push_rect(&mut hud, 0.0, 0.0, w as f32, 20.0, [0, 0, 0, 128]);
        frame.font().push_text(
            &mut hud,
            &format!("frame {} {w}x{h}", frame.number()),
            4.0,
            2.0,
            TextSize::Small,
            [255, 255, 255, 255],
        );
        frame.draw_overlay(&hud).map_err(|e| e.to_string())?;
        if inject {
            // The image is acquired and its semaphore signalled; the submission fails. The
            // error must come back (no hang), and the slot must acquire again next frame
            // without a validation error about the semaphore.
            return match frame.finish() {
                Err(GpuError::DeviceLost { .. }) => {
                    self.failed_submit_reported = true;
                    self.skipped += 1;
                    Ok(())
                }
                other => Err(format!("injected submit failure gave {other:?}")),
            };
        }
        frame.finish().map_err(|e| e.to_string())?;
        self.presented += 1;
        self.last_extent = [w, h];
        self.last_mode = Some(gpu.swapchain.present_mode());
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_none()
            && !self.done
            && let Err(e) = self.create(event_loop)
        {
            self.fail(event_loop, format!("setup: {e}"));
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::Resized(size) => {
                if let Some(gpu) = self.gpu.as_mut() {
                    gpu.swapchain.resize(size.width, size.height);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.fail(event_loop, format!("frame {}: {e}", self.presented));
                } else if self.presented >= FRAMES {
                    self.shutdown(event_loop);
                } else if self.redraws >= MAX_REDRAWS {
                    let msg = format!("only {} frames presented", self.presented);
                    self.fail(event_loop, msg);
                }
            }
            WindowEvent::CloseRequested => self.shutdown(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(gpu) = self.gpu.as_ref() {
            gpu.window.request_redraw();
        }
    }
}

#[test]
fn swapchain_presents_resizes_and_tears_down() {
    if !common::display() {
        return;
    }
    // A hung window system must fail the test, not the CI job's time limit.
    std::thread::spawn(|| {
        std::thread::sleep(Duration::from_secs(120));
        eprintln!("swapchain test timed out");
        std::process::exit(1);
    });
    let event_loop = match EventLoop::builder().with_any_thread(true).build() {
        Ok(el) => el,
        Err(e) => {
            common::precondition(false, &format!("cannot open the display: {e}"));
            return;
        }
    };
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App::default();
    event_loop.run_app(&mut app).expect("event loop");
    if let Some(e) = app.error {
        panic!("{e}");
    }
    assert!(app.presented >= FRAMES, "presented {}", app.presented);
    assert!(
        app.minimised_once && app.skipped >= 1,
        "zero-size path not taken"
    );
    assert!(
        app.failed_submit_reported,
        "the injected submit failure was not reported"
    );
    let sink = app.sink.expect("validation sink");
    let errors = sink.errors();
    assert!(
        errors.is_empty(),
        "validation errors:\n{}",
        errors
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("\n")
    );
    eprintln!(
        "presented {} frames ({} skipped), last {:?} in {:?}",
        app.presented, app.skipped, app.last_extent, app.last_mode
    );
    // The window manager may refuse a resize; when it happened, the swapchain followed.
    assert!(
        app.last_extent == [400, 300] || app.last_extent == [320, 240],
        "swapchain extent {:?}",
        app.last_extent
    );
}

/// Under `make test` (PRESPLINE_STRICT=1) or CI, a missing display fails this binary's test
/// instead of skipping it: run again without DISPLAY in a child process (which opens no event
/// loop of its own here).
#[test]
fn without_a_display_strict_runs_fail() {
    if std::env::var_os("PRESPLINE_WINDOW_CHILD").is_some() {
        return;
    }
    for (var, value, fails) in [
        ("PRESPLINE_STRICT", "1", true),
        ("CI", "1", true),
        ("CI", "", false),
    ] {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "swapchain_presents_resizes_and_tears_down"])
            .env("PRESPLINE_WINDOW_CHILD", "1")
            .env_remove("DISPLAY")
            .env_remove("PRESPLINE_STRICT")
            .env_remove("CI")
            .env(var, value)
            .output()
            .unwrap();
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(!out.status.success(), fails, "{var}={value}:\n{text}");
    }
}

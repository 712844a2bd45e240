//! The winit 0.30 application: window, swapchain (resize, minimise, out-of-date), input
//! translation, the frame loop, scripted input and screenshots.
//!
//! `prespline view` draws on demand (`ControlFlow::Wait`): a frame follows input, window
//! events and scripted actions (frame-numbered script events count as an animation and keep
//! frames coming; timed ones wake the loop when due), and once activity stops, one more frame
//! a moment later lets the performance overlay show the last frames' figures. An idle viewer
//! draws nothing. `prespline bench --window` (a scenario or a frame limit) keeps drawing
//! continuously.

use super::autosave::Autosave;
use super::input::{InputEvent, Key, Modifiers, MouseButton};
use super::scenario::{Scenario, ScenarioDriver};
use super::script::{ScriptPlayer, When};
use super::session::Session;
use crate::gpu::{
    FRAMES_IN_FLIGHT, Fault, OffscreenDesc, Renderer, RendererDesc, Swapchain, SwapchainDesc,
    ValidationSink, vk,
};
use crate::profile::{FrameRecord, Phase, Recorder};
use crate::render::validation_mode;
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key as WKey, NamedKey};
use winit::raw_window_handle::HasDisplayHandle;
use winit::window::{Window, WindowId};

/// Options of `prespline view`.
#[derive(Debug, Clone)]
pub struct ViewArgs {
    pub scene: Scene,
    /// Shown in the title bar.
    pub title: String,
    pub save_path: PathBuf,
    pub size: (u32, u32),
    pub vsync: bool,
    pub script: Option<Vec<super::script::ScriptEvent>>,
    /// A benchmark scenario driving the input instead of (or besides) a script.
    pub scenario: Option<Scenario>,
    /// Frames excluded from statistics (shader compilation, first uploads).
    pub warmup: usize,
    /// Close the window after this many frames (warm-up included).
    pub max_frames: Option<usize>,
    /// Re-sample and upload edited objects in full (`--naive`).
    pub naive: bool,
    /// Where unsaved edits are kept (`None`: nowhere, as in benchmarks).
    pub autosave: Option<Autosave>,
    /// MSAA samples; 0 picks the device's default.
    pub msaa: u32,
    /// Display level of detail.
    pub lod: bool,
    /// A surface analysis map shown from the start.
    pub analysis: Option<crate::render::maps::SurfaceMap>,
    /// How the map's colour scale is chosen.
    pub map_range: crate::render::maps::MapRange,
    /// What pre-evaluation may take; structural edits and curvature maps that would need
    /// more are refused on the status line.
    pub memory: crate::sampling::budget::MemoryBudget,
    /// How gestures redraw (`--redraw`).
    pub redraw: crate::render::Redraw,
}

/// What a viewer run measured.
#[derive(Debug, Clone)]
pub struct ViewRun {
    pub frames: Vec<FrameRecord>,
    pub device: String,
}

struct Running {
    session: Session,
    swapchain: Swapchain,
    renderer: Renderer,
    // The swapchain holds the window too, so its handles outlive the surface.
    window: Arc<Window>,
}

struct App {
    args: ViewArgs,
    running: Option<Running>,
    sink: Option<ValidationSink>,
    script: Option<ScriptPlayer>,
    driver: Option<ScenarioDriver>,
    frame: u64,
    start: Option<Instant>,
    last: Option<Instant>,
    error: Option<String>,
    /// Continuous mode (benchmarks): frames run from the end of the previous one, so input
    /// handled between redraws counts as this frame's input phase. On demand, a frame's record
    /// starts with its redraw.
    rec: Recorder,
    device: String,
    /// The wake-up this app asked for on the autosave's behalf (so it clears only its own).
    autosave_wakeup: Option<Instant>,
    /// Draw every frame (a benchmark scenario or a frame limit) instead of on demand.
    continuous: bool,
    /// Something changed since the last frame: draw one.
    dirty: bool,
    /// When the performance overlay's one slow tick after activity is due.
    settle_at: Option<Instant>,
    /// Error-path testing: the frame at which the next submission is made to fail as if the
    /// device were lost (`PRESPLINE_FAULT=device-lost@N`).
    fault_at: Option<u64>,
}

/// Delay of the overlay's last tick after activity stops.
const SETTLE: Duration = Duration::from_millis(300);

/// `PRESPLINE_FAULT=device-lost@N`: the frame number whose submission reports a lost device.
fn fault_from_env() -> Option<u64> {
    let spec = std::env::var("PRESPLINE_FAULT").ok()?;
    spec.strip_prefix("device-lost@")?.parse().ok()
}

/// Whether an X11 display is reachable (this build's winit backend is X11; Wayland sessions
/// run it through XWayland).
#[must_use]
pub fn display_available() -> bool {
    std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty())
}

/// Opens the viewer and runs until the window closes (or the frame limit). Returns the frame
/// timings.
pub fn run(args: ViewArgs) -> Result<ViewRun, String> {
    if !display_available() {
        return Err("no display: DISPLAY is not set (prespline view needs X11 or XWayland; for headless use try `prespline render` or `prespline bench`)".into());
    }
    let event_loop = EventLoop::new().map_err(|e| format!("cannot open the display: {e}"))?;
    let continuous = args.scenario.is_some() || args.max_frames.is_some();
    event_loop.set_control_flow(if continuous {
        ControlFlow::Poll
    } else {
        ControlFlow::Wait
    });
    let script = args.script.clone().map(ScriptPlayer::new);
    let rec = Recorder::with_capacity(args.warmup, args.max_frames.unwrap_or(4096));
    let mut app = App {
        args,
        running: None,
        sink: None,
        script,
        driver: None,
        frame: 0,
        start: None,
        last: None,
        error: None,
        rec,
        device: String::new(),
        autosave_wakeup: None,
        continuous,
        dirty: true,
        settle_at: None,
        fault_at: fault_from_env(),
    };
    // A panic anywhere in the loop must not lose unsaved edits: write the autosave, then let
    // the panic go on.
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        event_loop.run_app(&mut app)
    }));
    let outcome = match outcome {
        Ok(outcome) => outcome,
        Err(panic) => {
            app.keep_unsaved_edits();
            if let Some(e) = &app.error {
                eprintln!("error: {e}");
            }
            std::panic::resume_unwind(panic)
        }
    };
    outcome.map_err(|e| format!("event loop failed: {e}"))?;
    if let Some(errors) = app
        .sink
        .as_ref()
        .map(|s| s.errors())
        .filter(|e| !e.is_empty())
    {
        let first = errors[0].to_string();
        app.error.get_or_insert(format!(
            "Vulkan validation reported {} error(s), first: {}",
            errors.len(),
            first.lines().next().unwrap_or("")
        ));
    }
    match app.error {
        Some(e) => Err(e),
        None => Ok(ViewRun {
            frames: app.rec.into_frames(),
            device: app.device,
        }),
    }
}

impl App {
    fn create(&mut self, event_loop: &ActiveEventLoop) -> Result<(), String> {
        let (w, h) = self.args.size;
        let attrs = Window::default_attributes()
            .with_title(format!("prespline — {}", self.args.title))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| format!("cannot create a window: {e}"))?,
        );
        let display = window.display_handle().map_err(|e| e.to_string())?.as_raw();
        let mut renderer = Renderer::new(&RendererDesc {
            app_name: "prespline view".into(),
            validation: validation_mode(),
            display: Some(display),
            ..RendererDesc::default()
        })
        .map_err(|e| e.to_string())?;
        self.sink = renderer.validation_sink();
        self.device = renderer.caps().name.clone();
        // Text is laid out in physical pixels at the window's scale factor.
        renderer
            .set_text_scale(window.scale_factor() as f32)
            .map_err(|e| e.to_string())?;
        let size = window.inner_size();
        let swapchain = renderer
            .create_swapchain(
                Arc::clone(&window),
                &SwapchainDesc {
                    width: size.width,
                    height: size.height,
                    vsync: self.args.vsync,
                    samples: self.args.msaa,
                },
            )
            .map_err(|e| e.to_string())?;
        let mut session = Session::open(
            &mut renderer,
            &self.args.scene,
            self.args.save_path.clone(),
            [size.width, size.height],
            self.args.memory,
        )?;
        session.set_autosave(self.args.autosave.clone());
        session.set_naive(self.args.naive);
        session.set_redraw(self.args.redraw);
        session.options.lod = self.args.lod;
        session.options.map_range = self.args.map_range;
        if self.args.analysis.is_some() {
            session.set_map(self.args.analysis);
        }
        if let Some(scenario) = self.args.scenario {
            let frames = self
                .args
                .max_frames
                .map_or(1, |m| m.saturating_sub(self.args.warmup).max(1));
            self.driver = Some(ScenarioDriver::new(
                scenario,
                &session,
                self.args.warmup,
                frames,
            )?);
        }
        window.request_redraw();
        self.running = Some(Running {
            session,
            swapchain,
            renderer,
            window,
        });
        Ok(())
    }

    /// Every way out: the unsaved edits go to the autosave first (CPU only). Where they are
    /// is printed, or joins the error line when the viewer fails; edits no place could take
    /// make the run fail with one line saying so.
    fn keep_unsaved_edits(&mut self) {
        let Some(r) = self.running.as_mut() else {
            return;
        };
        let line = match r.session.on_exit() {
            Ok(None) => return,
            Ok(Some(kept)) if self.error.is_none() => return eprintln!("{kept}"),
            Ok(Some(kept)) => kept.to_string(),
            Err(lost) => lost.to_string(),
        };
        self.error = Some(match self.error.take() {
            Some(e) => format!("{e}; {line}"),
            None => line,
        });
    }

    fn shutdown(&mut self, event_loop: &ActiveEventLoop) {
        self.keep_unsaved_edits();
        if let Some(r) = self.running.take() {
            let Running {
                session,
                swapchain,
                mut renderer,
                window,
            } = r;
            let _ = renderer.wait_idle();
            session.destroy(&mut renderer);
            if let Err(e) = renderer.destroy_swapchain(swapchain) {
                self.error.get_or_insert(e.to_string());
            }
            drop(renderer);
            drop(window);
        }
        event_loop.exit();
    }

    /// Ends the viewer with one error line. The session is first told to keep its unsaved
    /// work (a lost device cannot be recovered from, but the document is in main memory).
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: impl ToString) {
        if let Some(r) = self.running.as_mut() {
            // Written now; where it went joins the error line in shutdown.
            let _ = r.session.on_fatal_exit();
        }
        self.error.get_or_insert(e.to_string());
        self.shutdown(event_loop);
    }

    fn input(&mut self, e: InputEvent) {
        if let Some(r) = self.running.as_mut() {
            r.session.handle(e);
            self.dirty = true;
        }
    }

    /// When the next frame is due in on-demand mode: now, at an instant, or not until an
    /// event arrives.
    fn next_frame(&self) -> Option<Instant> {
        let now = Instant::now();
        if self.dirty {
            return Some(now);
        }
        let script =
            self.script
                .as_ref()
                .and_then(ScriptPlayer::next_when)
                .map(|when| match when {
                    // Frame-numbered events are an animation: frames keep coming until they run.
                    When::Frame(_) => now,
                    When::Seconds(t) => self.start.unwrap_or(now) + Duration::from_secs_f64(t),
                });
        match (script, self.settle_at) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    fn redraw(&mut self) -> Result<(), String> {
        let Some(r) = self.running.as_mut() else {
            return Ok(());
        };
        let began = Instant::now();
        let settling = self.settle_at.is_some_and(|t| t <= began);
        self.dirty = false;
        self.settle_at = None;
        if self.fault_at == Some(self.frame) {
            r.renderer
                .inject_fault(Fault::Submit(vk::Result::ERROR_DEVICE_LOST));
        }
        let rec = &mut self.rec;
        if rec.current_frame().is_none() {
            rec.begin_frame();
            rec.phase_start(Phase::Input);
        }
        let index = rec.current_frame().unwrap_or(0);
        let start = *self.start.get_or_insert_with(Instant::now);
        let mut shots = Vec::new();
        let mut actions = Vec::new();
        if let Some(script) = self.script.as_mut() {
            actions.extend(script.due(self.frame, start.elapsed().as_secs_f64()));
        }
        if let Some(driver) = self.driver.as_mut() {
            actions.extend(driver.actions(self.frame as usize, &r.session));
        }
        for action in actions {
            if let Some(shot) = r.session.perform(action) {
                shots.push(shot);
            }
            if let Some(e) = r.session.take_script_error() {
                return Err(format!("script: {e}"));
            }
        }
        rec.phase_start(Phase::Delta);
        let applied = r.session.apply_pending();
        rec.add_samples(applied.samples as u64);
        rec.phase_start(Phase::Present);
        let size = r.window.inner_size();
        match r
            .renderer
            .begin_swapchain(&mut r.swapchain)
            .map_err(|e| e.to_string())?
        {
            // Out of date (rebuilt next time) or minimised (a resize will come): try again
            // unless the window has no area.
            None => self.dirty = size.width > 0 && size.height > 0,
            Some(mut frame) => {
                if let Some(ms) = frame.gpu_time_ms() {
                    // The slot's previous use was FRAMES_IN_FLIGHT frames ago.
                    rec.set_gpu_ms(index.saturating_sub(FRAMES_IN_FLIGHT), ms);
                }
                rec.phase_start(Phase::Upload);
                let stats = r.session.upload(&mut frame).map_err(|e| e.to_string())?;
                rec.add_bytes(stats.bytes as u64);
                rec.phase_start(Phase::Record);
                r.session
                    .record(&mut frame, true)
                    .map_err(|e| e.to_string())?;
                let d = r.session.last_draw();
                rec.set_draw(d.retained, d.layer_built, d.triangles);
                rec.phase_start(Phase::Submit);
                frame.finish().map_err(|e| e.to_string())?;
            }
        }
        rec.phase_end();
        for (path, hud) in shots {
            screenshot(r, &path, hud)?;
            r.session
                .set_status(format!("screenshot {}", path.display()));
        }
        r.session.hud.gpu_ms = r.renderer.last_gpu_time_ms();
        let now = Instant::now();
        // The interval between frames is the frame time while they come back to back; after
        // an idle gap it would be the gap, so the frame's own duration stands in.
        let interval = self.last.map(|last| now - last);
        let ms = match interval {
            Some(d) if self.continuous || d < SETTLE => d,
            _ => now - began,
        };
        r.session.hud.push_frame(ms.as_secs_f64() * 1e3);
        self.last = Some(now);
        rec.end_frame();
        self.frame += 1;
        if self
            .args
            .max_frames
            .is_some_and(|m| self.frame as usize >= m)
        {
            r.session.quit = true;
        } else if self.continuous {
            rec.begin_frame();
            rec.phase_start(Phase::Input);
        } else if !settling {
            self.settle_at = Some(now + SETTLE);
        }
        Ok(())
    }
}

impl App {
    /// Writes the autosave when due, and keeps a loop that sleeps until input (redraw on
    /// demand) waking up for the next deadline. A polling loop wakes up anyway.
    fn schedule_autosave(&mut self, event_loop: &ActiveEventLoop) {
        let Some(r) = self.running.as_mut() else {
            return;
        };
        let now = Instant::now();
        let next = r.session.tick(now);
        let mine = std::mem::replace(&mut self.autosave_wakeup, next);
        let flow = match (event_loop.control_flow(), next) {
            (ControlFlow::Poll, _) => return,
            // Another timer of the loop's that is still ahead and comes first stays.
            (ControlFlow::WaitUntil(t), Some(d)) if t > now && Some(t) != mine => t.min(d),
            (_, Some(d)) => d,
            (ControlFlow::WaitUntil(t), None) if Some(t) == mine => {
                return event_loop.set_control_flow(ControlFlow::Wait);
            }
            (_, None) => return,
        };
        event_loop.set_control_flow(ControlFlow::WaitUntil(flow));
    }
}

/// Renders what the window shows offscreen at the window size into a PNG; without `hud` the
/// overlay (whose numbers change from run to run) is left out, as golden tests need.
fn screenshot(r: &mut Running, path: &Path, hud: bool) -> Result<(), String> {
    let [w, h] = r.session.size();
    let mut target = r
        .renderer
        .create_offscreen(&OffscreenDesc {
            width: w as u32,
            height: h as u32,
            samples: 0,
        })
        .map_err(|e| e.to_string())?;
    let result = (|| {
        let mut frame = r.renderer.begin_offscreen(&mut target)?;
        // The picture shows the figures of the window's last frame: this frame's upload only
        // brings its own slot up to date and is no edit of the user's (it used to reset the
        // HUD's "KB to GPU" to 0 before drawing).
        let shown = r.session.hud.bytes;
        r.session.upload(&mut frame)?;
        r.session.hud.bytes = shown;
        r.session.record(&mut frame, hud)?;
        frame.capture();
        frame.finish()?;
        r.renderer.read_pixels(&target)
    })();
    r.renderer
        .destroy_offscreen(target)
        .map_err(|e| e.to_string())?;
    let pixels = result.map_err(|e| e.to_string())?;
    crate::render::image_file::write_image(&pixels, path)
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_none()
            && let Err(e) = self.create(event_loop)
        {
            self.fail(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => self.shutdown(event_loop),
            WindowEvent::Resized(size) => {
                if let Some(r) = self.running.as_mut() {
                    r.swapchain.resize(size.width, size.height);
                    r.session.resize(size.width, size.height);
                }
                self.dirty = true;
            }
            WindowEvent::ScaleFactorChanged { scale_factor, .. } => {
                if let Some(r) = self.running.as_mut()
                    && let Err(e) = r.renderer.set_text_scale(scale_factor as f32)
                {
                    return self.fail(event_loop, e.to_string());
                }
                self.dirty = true;
            }
            WindowEvent::Focused(_)
            | WindowEvent::Occluded(false)
            | WindowEvent::ThemeChanged(_) => self.dirty = true,
            WindowEvent::ModifiersChanged(m) => {
                let s = m.state();
                self.input(InputEvent::Modifiers(Modifiers {
                    ctrl: s.control_key(),
                    shift: s.shift_key(),
                    alt: s.alt_key(),
                }));
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let key = match &event.logical_key {
                    WKey::Named(NamedKey::Enter) => Key::Enter,
                    WKey::Named(NamedKey::Escape) => Key::Escape,
                    WKey::Named(NamedKey::Backspace) => Key::Backspace,
                    WKey::Named(NamedKey::Home) => Key::Home,
                    WKey::Named(NamedKey::F1) => Key::F1,
                    WKey::Character(s) => match s.chars().next() {
                        // Ctrl+letter can arrive as a control character.
                        Some(c) if (c as u32) < 0x20 => {
                            Key::Char(char::from(b'a' + (c as u8).saturating_sub(1)))
                        }
                        Some(c) => Key::Char(c.to_ascii_lowercase()),
                        None => Key::Other,
                    },
                    _ => Key::Other,
                };
                self.input(InputEvent::Key {
                    key,
                    pressed: event.state == ElementState::Pressed,
                });
            }
            WindowEvent::CursorMoved { position, .. } => self.input(InputEvent::CursorMoved {
                x: position.x,
                y: position.y,
            }),
            WindowEvent::MouseInput { state, button, .. } => {
                let button = match button {
                    winit::event::MouseButton::Left => MouseButton::Left,
                    winit::event::MouseButton::Middle => MouseButton::Middle,
                    winit::event::MouseButton::Right => MouseButton::Right,
                    _ => return,
                };
                self.input(InputEvent::Button {
                    button,
                    pressed: state == ElementState::Pressed,
                });
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let d = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.input(InputEvent::Wheel { delta: d });
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    return self.fail(event_loop, e);
                }
                if self.running.as_ref().is_some_and(|r| r.session.quit) {
                    self.shutdown(event_loop);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(r) = self.running.as_ref() else {
            return;
        };
        if self.continuous {
            // Benchmarks want a steady stream of frames (paced by presentation).
            r.window.request_redraw();
        } else {
            match self.next_frame() {
                Some(t) if t <= Instant::now() => {
                    r.window.request_redraw();
                    event_loop.set_control_flow(ControlFlow::Wait);
                }
                Some(t) => event_loop.set_control_flow(ControlFlow::WaitUntil(t)),
                None => event_loop.set_control_flow(ControlFlow::Wait),
            }
        }
        // Unsaved edits are written about a second after the oldest one, also while idle: the
        // autosave's deadline joins the frame's.
        self.schedule_autosave(event_loop);
    }
}

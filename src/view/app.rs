//! The winit 0.30 application: window, swapchain (resize, minimise, out-of-date), input
//! translation, the frame loop, scripted input and screenshots.

use super::autosave::Autosave;
use super::input::{InputEvent, Key, Modifiers, MouseButton};
use super::scenario::{Scenario, ScenarioDriver};
use super::script::ScriptPlayer;
use super::session::Session;
use crate::cli::render::validation_mode;
use crate::gpu::{
    FRAMES_IN_FLIGHT, OffscreenDesc, Renderer, RendererDesc, Swapchain, SwapchainDesc,
    ValidationSink,
};
use crate::profile::{FrameRecord, Phase, Recorder};
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Instant;
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
    // Last: the swapchain and renderer must be destroyed before the window.
    window: Window,
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
    /// Frames run from the end of the previous one, so input handled between redraws counts
    /// as this frame's input phase.
    rec: Recorder,
    device: String,
    /// The wake-up this app asked for on the autosave's behalf (so it clears only its own).
    autosave_wakeup: Option<Instant>,
}

/// Whether an X11 display is reachable (this build's winit backend is X11; Wayland sessions
/// run it through XWayland).
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
    event_loop.set_control_flow(ControlFlow::Poll);
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
        let window = event_loop
            .create_window(attrs)
            .map_err(|e| format!("cannot create a window: {e}"))?;
        let display = window.display_handle().map_err(|e| e.to_string())?.as_raw();
        let mut renderer = Renderer::new(&RendererDesc {
            app_name: "prespline view".into(),
            validation: validation_mode(),
            display: Some(display),
            ..RendererDesc::default()
        })
        .map_err(|e| e.to_string())?;
        self.sink = renderer.validation_sink();
        let size = window.inner_size();
        let swapchain = renderer
            .create_swapchain(
                &window,
                &SwapchainDesc {
                    width: size.width,
                    height: size.height,
                    vsync: self.args.vsync,
                    samples: 0,
                },
            )
            .map_err(|e| e.to_string())?;
        let mut session = Session::new(
            &mut renderer,
            &self.args.scene,
            self.args.save_path.clone(),
            [size.width, size.height],
        )
        .map_err(|e| e.to_string())?;
        session.set_autosave(self.args.autosave.clone());
        window.request_redraw();
        self.running = Some(Running {
            session,
            swapchain,
            renderer,
            window,
        });
        Ok(())
    }

    /// Every way out: the unsaved edits go to the autosave first (CPU only), and its path is
    /// printed.
    fn keep_unsaved_edits(&mut self) {
        if let Some(path) = self.running.as_mut().and_then(|r| r.session.on_exit()) {
            eprintln!(
                "unsaved edits kept in {} (`prespline view SCENE --recover` opens them)",
                path.display()
            );
        }
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

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: impl ToString) {
        self.error.get_or_insert(e.to_string());
        self.shutdown(event_loop);
    }

    fn input(&mut self, e: InputEvent) {
        if let Some(r) = self.running.as_mut() {
            r.session.handle(e);
        }
    }

    fn redraw(&mut self) -> Result<(), String> {
        let Some(r) = self.running.as_mut() else {
            return Ok(());
        };
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
        }
        rec.phase_start(Phase::Delta);
        let applied = r.session.apply_pending();
        rec.add_samples(applied.samples as u64);
        rec.phase_start(Phase::Present);
        if let Some(mut frame) = r
            .renderer
            .begin_swapchain(&mut r.swapchain)
            .map_err(|e| e.to_string())?
        {
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
            rec.phase_start(Phase::Submit);
            frame.finish().map_err(|e| e.to_string())?;
        }
        rec.phase_end();
        for (path, hud) in shots {
            screenshot(r, &path, hud)?;
            r.session
                .set_status(format!("screenshot {}", path.display()));
        }
        r.session.hud.gpu_ms = r.renderer.last_gpu_time_ms();
        let now = Instant::now();
        if let Some(last) = self.last {
            r.session.hud.push_frame((now - last).as_secs_f64() * 1e3);
        }
        self.last = Some(now);
        rec.end_frame();
        self.frame += 1;
        if self
            .args
            .max_frames
            .is_some_and(|m| self.frame as usize >= m)
        {
            r.session.quit = true;
        } else {
            rec.begin_frame();
            rec.phase_start(Phase::Input);
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
        r.session.upload(&mut frame)?;
        r.session.record(&mut frame, hud)?;
        frame.finish()?;
        r.renderer.read_pixels(&target)
    })();
    r.renderer
        .destroy_offscreen(target)
        .map_err(|e| e.to_string())?;
    let pixels = result.map_err(|e| e.to_string())?;
    pixels
        .write_png(path)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
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
            }
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
        self.schedule_autosave(event_loop);
        // Continuous redraw: the frame-time graph and profiling want a steady stream of frames;
        // FIFO presentation paces it to the display.
        if let Some(r) = self.running.as_ref() {
            r.window.request_redraw();
        }
    }
}

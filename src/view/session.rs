//! An interactive editing session, independent of the window system: the document, its GPU
//! mirrors, camera, selection, tools, undo, and the per-frame work (apply edits through the
//! delta path, copy dirty rows, record draws and the overlay). The winit viewer, `--script`
//! replays and `prespline bench` all drive this same type.

use super::autosave::{Autosave, Kept, Lost};
use super::hud::{Hud, help_overlay, status_elided};
use super::input::{InputEvent, Key, Modifiers, MouseButton};
use super::picking::{PICK_RADIUS, Projected, pick, project_all};
use super::refine::{Refine, index_text, path_text};
use super::script::Action;
use super::tools::{Axis, Drag, Transform, TransformKind, View};
use crate::editor::{Applied, Document, Editor, Handle, Refused};
use crate::gpu::{Frame, GpuResult, Renderer};
use crate::model::{CurveEdit, Edit, Index2, KindEdit, LocalPath, Model, ModelRef, SurfaceEdit};
use crate::render::analysis::{
    CurveEval, Osculating, badge_overlay, osculating_lines, osculating_overlay,
};
use crate::render::lod::Lod;
use crate::render::map_mirror::MapView;
use crate::render::maps::{SurfaceMap, legend, map_range};
use crate::render::overlays::overlay_lines;
use crate::render::{
    Bounds, GpuScene, Highlight, NetMode, OrbitCamera, Palette, UploadStats, ViewOptions, Wire,
};
use crate::sampling::SampleMode;
use crate::sampling::budget::MemoryBudget;
use glam::{DMat4, DVec3};
use std::path::PathBuf;
use std::time::Instant;

/// Locals per direction of an ERBS local made from a polynomial local with X.
pub const DETAIL_LOCALS: usize = 3;

/// What a transform acts on.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    Point(Handle),
    Local(usize, LocalPath<Index2>),
}

#[derive(Debug, Clone)]
enum Mode {
    Idle,
    Orbit {
        moved: bool,
    },
    Pan,
    Drag {
        handle: Handle,
        drag: Drag,
    },
    Transform {
        target: Target,
        t: Box<Transform>,
    },
    /// Aiming a knot insertion (I).
    Refine(Refine),
    /// Alt+drag on a control point: its weight follows the vertical motion (up: heavier).
    Weight {
        handle: Handle,
        start_y: f64,
        from: f64,
    },
    /// Typing a weight for the selected control point (Shift+W).
    WeightEntry {
        handle: Handle,
        text: String,
    },
}

/// Cost of applying one frame's edits.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ApplyStats {
    pub edits: usize,
    pub samples: usize,
    pub micros: f64,
}

pub struct Session {
    editor: Editor,
    gpu: GpuScene,
    pub camera: OrbitCamera,
    home: OrbitCamera,
    pub options: ViewOptions,
    size: [f64; 2],
    bounds: Bounds,
    cursor: (f64, f64),
    mods: Modifiers,
    hovered: Option<Projected>,
    hovered_object: Option<usize>,
    selected: Option<Handle>,
    selected_local: Option<(usize, LocalPath<Index2>)>,
    mode: Mode,
    save_path: PathBuf,
    status: String,
    status_since: Option<Instant>,
    /// The last status message written to stderr because the window cut it.
    status_echoed: String,
    pub hud: Hud,
    pub show_help: bool,
    pub quit: bool,
    /// Projected handles, recomputed when the camera or the model changes.
    projected: Option<Vec<Projected>>,
    /// Unsaved edits kept beside the scene file (`None`: not kept, as in benchmarks).
    autosave: Option<Autosave>,
    /// The transformed object's model when the gesture began.
    transform_origin: Option<Model>,
    /// Osculating circle, curvature and torsion of the curve under the cursor (O).
    pub osculating: bool,
    /// Half range of the analysis map's colour scale (refitted when a map is chosen and after
    /// each drag).
    map_range: f64,
    /// A scripted action that could not run (see [`Session::take_script_error`]).
    script_error: Option<String>,
}

impl Session {
    /// Opens `scene` for drawing and editing: an editor held to `budget` (the scene refused
    /// in one line when it does not fit), uploaded and framed for a `size` image.
    pub fn open(
        renderer: &mut Renderer,
        scene: &crate::scene::Scene,
        save_path: PathBuf,
        size: [u32; 2],
        budget: MemoryBudget,
    ) -> Result<Self, String> {
        let options = crate::editor::EditorOptions {
            mode: SampleMode::Render,
            uses: crate::render::DRAW_USES,
            budget,
        };
        let editor = Editor::new(scene, options)?;
        Self::new(renderer, editor, save_path, size).map_err(|e| e.to_string())
    }

    /// Uploads the editor's document and frames it for a `size` image. Ctrl+S writes to
    /// `save_path`.
    pub fn new(
        renderer: &mut Renderer,
        editor: Editor,
        save_path: PathBuf,
        size: [u32; 2],
    ) -> GpuResult<Self> {
        let doc = editor.doc();
        let nets = default_nets(doc);
        let gpu = GpuScene::new(renderer, doc)?;
        let bounds = doc.bounds();
        let size = [size[0].max(1) as f64, size[1].max(1) as f64];
        let mut camera = OrbitCamera::default_for(&bounds);
        camera.frame(&bounds, size[0] / size[1]);
        Ok(Self {
            editor,
            gpu,
            camera,
            home: camera,
            options: ViewOptions {
                control_nets: nets,
                ..ViewOptions::default()
            },
            size,
            bounds,
            cursor: (size[0] * 0.5, size[1] * 0.5),
            mods: Modifiers::default(),
            hovered: None,
            hovered_object: None,
            selected: None,
            selected_local: None,
            mode: Mode::Idle,
            save_path,
            status: "H or F1: keys".into(),
            status_since: Some(Instant::now()),
            status_echoed: String::new(),
            hud: Hud::new(),
            show_help: false,
            quit: false,
            projected: None,
            autosave: None,
            transform_origin: None,
            osculating: false,
            map_range: 1.0,
            script_error: None,
        })
    }

    /// Keeps unsaved edits in an autosave file (see [`super::autosave`]); its start-up notes
    /// go to the status line and stderr.
    pub fn set_autosave(&mut self, autosave: Option<Autosave>) {
        self.autosave = autosave;
        self.show_autosave_notes();
    }

    pub fn autosave(&self) -> Option<&Autosave> {
        self.autosave.as_ref()
    }

    /// Writes the autosave when it is due at `now`; returns when it is due next, for an event
    /// loop that otherwise sleeps until input arrives.
    pub fn tick(&mut self, now: Instant) -> Option<Instant> {
        let due = self.autosave.as_ref()?.deadline()?;
        if due > now {
            return Some(due);
        }
        self.write_autosave(now);
        self.autosave.as_ref()?.deadline()
    }

    /// Every way out (window close, Ctrl+Q, a script's quit, an error): writes the autosave if
    /// edits are unsaved, and says where they are kept, or what no place could take.
    pub fn on_exit(&mut self) -> Result<Option<Kept>, Lost> {
        if self.autosave.is_none() {
            return Ok(None);
        }
        self.apply_pending();
        let scene = self.editor.doc().to_scene();
        let outcome = self
            .autosave
            .as_mut()
            .map_or(Ok(None), |a| a.finish(&scene));
        self.show_autosave_notes();
        outcome
    }

    /// The device was lost or the viewer is about to fail: write the autosave now, before
    /// anything else can go wrong (CPU only; touches no GPU object). Returns what
    /// [`Session::on_exit`] does.
    pub fn on_fatal_exit(&mut self) -> Result<Option<Kept>, Lost> {
        self.on_exit()
    }

    /// Brings the autosave up to date with every queued edit (no-op when nothing is unsaved).
    fn write_autosave(&mut self, now: Instant) {
        if self.autosave.is_none() {
            return;
        }
        self.apply_pending();
        let scene = self.editor.doc().to_scene();
        if let Some(a) = self.autosave.as_mut() {
            a.write(&scene, now);
        }
        self.show_autosave_notes();
    }

    /// What the autosave has to say goes to the status line and stderr.
    fn show_autosave_notes(&mut self) {
        let notes = self
            .autosave
            .as_mut()
            .map(Autosave::take_notes)
            .unwrap_or_default();
        for note in notes {
            eprintln!("{}", crate::scene::escape_controls(&note));
            self.set_status(note);
            // Already on stderr whole: not again when the window elides it.
            self.status_echoed.clone_from(&self.status);
        }
    }

    /// Gives the GPU resources back.
    pub fn destroy(self, renderer: &mut Renderer) {
        self.gpu.destroy(renderer);
    }

    pub fn size(&self) -> [f64; 2] {
        self.size
    }

    pub fn resize(&mut self, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.size = [width as f64, height as f64];
            self.projected = None;
        }
    }

    pub fn cursor(&self) -> (f64, f64) {
        self.cursor
    }

    pub fn bounds(&self) -> &Bounds {
        &self.bounds
    }

    pub fn selected(&self) -> Option<Handle> {
        self.selected
    }

    pub fn selected_local(&self) -> Option<(usize, LocalPath<Index2>)> {
        self.selected_local
    }

    pub fn undo_depth(&self) -> (usize, usize) {
        self.editor.undo_depth()
    }

    /// The document being edited.
    #[must_use]
    pub fn doc(&self) -> &Document {
        self.editor.doc()
    }

    /// The current scene, every queued edit in (what Ctrl+S writes).
    pub fn to_scene(&mut self) -> crate::scene::Scene {
        self.apply_pending();
        self.editor.doc().to_scene()
    }

    /// What pre-evaluation may take from now on (`--memory-limit`).
    pub fn set_memory_budget(&mut self, budget: MemoryBudget) {
        self.editor.set_budget(budget);
    }

    /// Re-samples and uploads edited objects in full on every edit (`bench --naive`).
    pub fn set_naive(&mut self, naive: bool) {
        self.editor.naive = naive;
    }

    /// Applies every edit as it comes instead of merging a frame's edits per target.
    pub fn set_merge(&mut self, merge: bool) {
        self.editor.merge = merge;
    }

    /// The status line's message (what the last action did or why it could not).
    pub fn status(&self) -> &str {
        &self.status
    }

    pub fn set_status(&mut self, s: impl Into<String>) {
        let s: String = s.into();
        self.status = crate::scene::escape_controls(&s).into_owned();
        self.status_since = Some(Instant::now());
    }

    fn view(&self) -> View<'_> {
        View {
            camera: &self.camera,
            bounds: &self.bounds,
            size: self.size,
        }
    }

    /// Screen position of a handle (for scripts that aim at a control point).
    pub fn handle_position(&self, handle: Handle) -> Option<(f64, f64)> {
        let (_, world) = self
            .editor
            .doc()
            .handles(handle.object())
            .into_iter()
            .find(|(h, _)| *h == handle)?;
        self.view().project(world)
    }

    /// Submits an edit for this frame (validated, budgeted, recorded for undo); a refusal goes
    /// to the status line. Structural edits apply at once (see [`Editor::submit`]).
    fn queue(&mut self, edit: Edit) -> bool {
        let object = edit.object;
        match self.editor.submit(edit) {
            Ok(()) => true,
            Err(e) => {
                let name = &self.editor.doc().objects[object].name;
                self.set_status(format!("{name}: edit refused: {e}"));
                false
            }
        }
    }

    /// Applies this frame's queued edits through the delta path and hands the editor's report
    /// to the GPU scene, which marks what it rewrote dirty for every frame slot's mirrors.
    pub fn apply_pending(&mut self) -> ApplyStats {
        let applied = self.editor.apply_pending();
        self.take_applied(&applied);
        ApplyStats {
            edits: applied.edits,
            samples: applied.samples,
            micros: applied.micros,
        }
    }

    fn take_applied(&mut self, applied: &Applied) {
        if applied.is_empty() && applied.edits == 0 {
            return;
        }
        self.gpu.consume(applied);
        if applied.edits > 0
            && let Some(a) = self.autosave.as_mut()
        {
            a.edited(Instant::now());
        }
        self.projected = None;
        self.hud.edit_us = applied.micros;
        self.hud.samples_touched = applied.samples;
    }

    /// Copies this slot's dirty rows into the mirrors.
    pub fn upload(&mut self, frame: &mut Frame<'_>) -> GpuResult<UploadStats> {
        let stats = self.gpu.upload(frame, self.editor.doc())?;
        self.hud.bytes = stats.bytes;
        Ok(stats)
    }

    /// Why the last scripted action could not run (a `move_to` a point that does not exist),
    /// once: the replay ends with this error.
    pub fn take_script_error(&mut self) -> Option<String> {
        self.script_error.take()
    }

    /// Performs a scripted action as if typed; returns a requested screenshot (path, with HUD).
    pub fn perform(&mut self, action: Action) -> Option<(PathBuf, bool)> {
        match action {
            Action::Input(e) => self.handle(e),
            Action::Key { key, mods } => {
                let before = self.mods;
                self.handle(InputEvent::Modifiers(mods));
                self.handle(InputEvent::Key { key, pressed: true });
                self.handle(InputEvent::Key {
                    key,
                    pressed: false,
                });
                self.handle(InputEvent::Modifiers(before));
            }
            Action::MoveTo(h) => {
                if let Some((x, y)) = self.handle_position(h) {
                    self.handle(InputEvent::CursorMoved { x, y });
                } else if !self
                    .editor
                    .doc()
                    .handles(h.object())
                    .iter()
                    .any(|(x, _)| *x == h)
                {
                    self.script_error =
                        Some(format!("move_to: there is no {} now", self.handle_name(h)));
                }
            }
            Action::MoveBy(dx, dy) => {
                let (x, y) = self.cursor;
                self.handle(InputEvent::CursorMoved {
                    x: x + dx,
                    y: y + dy,
                });
            }
            Action::Type(text) => {
                for c in text.chars() {
                    self.handle(InputEvent::Key {
                        key: Key::Char(c),
                        pressed: true,
                    });
                }
            }
            Action::Screenshot(path, hud) => return Some((path, hud)),
            Action::Quit => self.quit = true,
        }
        None
    }

    /// Records the scene, overlays and (with `hud`) the overlay text and graph into the frame.
    pub fn record(&mut self, frame: &mut Frame<'_>, hud: bool) -> GpuResult<()> {
        let aspect = self.size[0] / self.size[1];
        frame.set_clear_color(Palette::default().background);
        frame.set_camera(self.camera.gpu(aspect, &self.bounds));
        let hl = Highlight {
            hovered: self.hovered.map(|p| p.handle),
            selected: self.selected,
            selected_local: self.selected_local,
            hovered_object: self.hovered_object,
        };
        let view_proj = self.camera.view_proj(aspect, &self.bounds);
        let lod = Lod::new(view_proj, self.size, frame.samples());
        let report = self
            .gpu
            .draw(frame, self.editor.doc(), &self.options, &hl, &lod)?;
        self.hud.triangles = (report.triangles, report.full_triangles);
        let mut lines = overlay_lines(self.editor.doc(), &self.options, self.bounds.radius());
        let font = frame.font();
        let (width, height) = (self.size[0] as f32, self.size[1] as f32);
        // Back to front: badges, legend, the osculating readout (never under a badge), the
        // HUD and status line, and the help above everything.
        let mut overlay = Vec::new();
        let mut readout = Vec::new();
        if self.osculating
            && matches!(
                self.mode,
                Mode::Idle | Mode::Drag { .. } | Mode::Weight { .. }
            )
            && let Some((object, o)) = self.osculating_at_cursor()
        {
            lines.extend(osculating_lines(&o));
            if let Some(at) = self.view().project(o.point) {
                let name = &self.editor.doc().objects[object].name;
                readout = osculating_overlay(name, &o, font, at, [width, height]);
            }
        }
        if !lines.is_empty() {
            frame.draw_lines3d(&lines)?;
        }
        if self.options.badges {
            let view = self.view();
            overlay.extend(badge_overlay(self.editor.doc(), font, |p| view.project(p)));
        }
        if let Some(map) = self.options.analysis {
            overlay.extend(legend(map, self.map_range, font, width, height));
        }
        overlay.extend(readout);
        if let Some(t) = self.status_since
            && t.elapsed().as_secs_f64() > 6.0
            && !matches!(self.mode, Mode::Transform { .. })
        {
            self.status.clear();
            self.status_since = None;
        }
        let status = match &self.mode {
            Mode::Transform { t, .. } => t.describe(),
            Mode::Refine(r) => {
                let preview = r.preview(self.editor.doc(), self.bounds.radius());
                if !preview.is_empty() {
                    frame.draw_lines3d(&preview)?;
                }
                r.describe(self.editor.doc())
            }
            Mode::WeightEntry { handle, text } => format!(
                "weight of {}: [{text}]  (type a positive number, Enter sets it, Esc cancels)",
                self.handle_name(*handle)
            ),
            Mode::Weight { handle, .. } => format!(
                "weight of {}: {}  (drag up/down, release to keep)",
                self.handle_name(*handle),
                self.editor.doc().weight_of(*handle).unwrap_or(1.0)
            ),
            _ => self.status.clone(),
        };
        if hud {
            // A message the window can only show with its middle elided goes to stderr whole,
            // once, so its advice is never lost.
            if status_elided(font, width, &status) && self.status_echoed != status {
                eprintln!("prespline: {status}");
                self.status_echoed.clone_from(&status);
            }
            overlay.extend(self.hud.build(font, width, height, &status, self.show_help));
            if self.show_help {
                overlay.extend(help_overlay(font, width, height));
            }
        }
        if !overlay.is_empty() {
            frame.draw_overlay(&overlay)?;
        }
        Ok(())
    }

    /// Handles one input event.
    pub fn handle(&mut self, event: InputEvent) {
        match event {
            InputEvent::Modifiers(m) => self.mods = m,
            InputEvent::CursorMoved { x, y } => self.cursor_moved(x, y),
            InputEvent::Button { button, pressed } => self.button(button, pressed),
            InputEvent::Wheel { delta } => self.zoom(delta),
            InputEvent::Key { key, pressed: true } => self.key(key),
            InputEvent::Key { .. } => {}
        }
    }

    fn projected(&mut self) -> &[Projected] {
        if self.projected.is_none() {
            let handles = self.editor.doc().all_handles();
            self.projected = Some(project_all(&handles, &self.camera, &self.bounds, self.size));
        }
        self.projected.as_deref().unwrap_or(&[])
    }

    fn cursor_moved(&mut self, x: f64, y: f64) {
        let (dx, dy) = (x - self.cursor.0, y - self.cursor.1);
        self.cursor = (x, y);
        match std::mem::replace(&mut self.mode, Mode::Idle) {
            Mode::Idle => {
                let cursor = self.cursor;
                self.hovered = pick(self.projected(), cursor, PICK_RADIUS);
                self.hovered_object = self
                    .hovered
                    .map(|p| p.handle.object())
                    .or_else(|| self.object_near_cursor());
            }
            Mode::Orbit { .. } => {
                self.camera.orbit(-dx * 0.008, dy * 0.008);
                self.projected = None;
                self.mode = Mode::Orbit { moved: true };
            }
            Mode::Pan => {
                let per_pixel =
                    2.0 * self.camera.distance * (0.5 * self.camera.fov_y).tan() / self.size[1];
                let (right, up) = self.camera.basis();
                self.camera.pan((-right * dx + up * dy) * per_pixel);
                self.projected = None;
                self.mode = Mode::Pan;
            }
            Mode::Drag { handle, mut drag } => {
                if let Some(inc) = drag.update(&self.view(), self.cursor)
                    && let Some(edit) = self.editor.doc().move_handle(handle, inc)
                {
                    self.queue(edit);
                }
                self.mode = Mode::Drag { handle, drag };
            }
            Mode::Transform { target, mut t } => {
                t.set_cursor(self.cursor);
                self.mode = Mode::Transform { target, t };
                self.update_transform();
            }
            Mode::Weight {
                handle,
                start_y,
                from,
            } => {
                // A factor of 2 per 80 pixels, kept within [1e-4, 1e4].
                let w = (from * 2f64.powf((start_y - y) / 80.0)).clamp(1e-4, 1e4);
                if let Ok(edit) = self.editor.doc().set_weight(handle, w) {
                    self.queue(edit);
                }
                self.mode = Mode::Weight {
                    handle,
                    start_y,
                    from,
                };
            }
            m @ Mode::WeightEntry { .. } => self.mode = m,
            Mode::Refine(mut r) => {
                r.aim(self.editor.doc(), &self.view(), self.cursor);
                self.mode = Mode::Refine(r);
            }
        }
    }

    fn button(&mut self, button: MouseButton, pressed: bool) {
        let mode = std::mem::replace(&mut self.mode, Mode::Idle);
        self.mode = match (mode, button, pressed) {
            (Mode::Transform { target, t }, MouseButton::Left, true) => {
                self.mode = Mode::Transform { target, t };
                self.confirm_transform();
                return;
            }
            (Mode::Transform { target, t }, MouseButton::Right, true) => {
                self.mode = Mode::Transform { target, t };
                self.cancel_transform();
                return;
            }
            (m @ Mode::Transform { .. }, _, _) => m,
            (Mode::Refine(r), MouseButton::Left, true) => {
                self.insert_knot(&r);
                Mode::Idle
            }
            (Mode::Refine(_), MouseButton::Right, true) => {
                self.set_status("knot insertion cancelled");
                Mode::Idle
            }
            (m @ Mode::Refine(_), _, _) => m,
            (Mode::Idle, MouseButton::Left, true) if !self.mods.shift => {
                let cursor = self.cursor;
                match pick(self.projected(), cursor, PICK_RADIUS) {
                    Some(p) if self.mods.alt => {
                        self.select(p.handle);
                        match self.editor.doc().weight_of(p.handle) {
                            Some(from) => {
                                self.editor.begin("weight");
                                Mode::Weight {
                                    handle: p.handle,
                                    start_y: self.cursor.1,
                                    from,
                                }
                            }
                            None => {
                                let why = self
                                    .editor
                                    .doc()
                                    .set_weight(p.handle, 1.0)
                                    .err()
                                    .unwrap_or_default();
                                self.set_status(why);
                                Mode::Idle
                            }
                        }
                    }
                    Some(p) => {
                        self.select(p.handle);
                        let mut drag = Drag::new(p.world);
                        drag.grab(&self.view(), self.cursor);
                        self.editor.begin("move point");
                        Mode::Drag {
                            handle: p.handle,
                            drag,
                        }
                    }
                    None => Mode::Orbit { moved: false },
                }
            }
            (Mode::Idle, MouseButton::Left, true) | (Mode::Idle, MouseButton::Right, true) => {
                Mode::Pan
            }
            (Mode::Idle, MouseButton::Middle, true) => {
                if self.mods.shift {
                    Mode::Pan
                } else {
                    Mode::Orbit { moved: false }
                }
            }
            (Mode::Drag { .. }, MouseButton::Left, false) => {
                self.editor.end();
                self.refresh_bounds();
                self.refit_map();
                Mode::Idle
            }
            (Mode::Weight { handle, .. }, MouseButton::Left, false) => {
                self.editor.end();
                self.refit_map();
                let w = self.editor.doc().weight_of(handle).unwrap_or(1.0);
                self.set_status(format!(
                    "weight of {} is {w} (Ctrl+Z undoes)",
                    self.handle_name(handle)
                ));
                Mode::Idle
            }
            (m @ (Mode::Weight { .. } | Mode::WeightEntry { .. }), _, _) => m,
            (Mode::Orbit { moved: false }, MouseButton::Left, false) => {
                // A click on empty space (no drag) clears the selection.
                self.selected = None;
                self.selected_local = None;
                Mode::Idle
            }
            (Mode::Orbit { .. } | Mode::Pan, _, false) => Mode::Idle,
            (m, _, _) => m,
        };
    }

    /// The object with a sample projecting within 24 pixels of the cursor (every 4th sample per
    /// direction is enough to find an object), nearest in depth.
    fn object_near_cursor(&self) -> Option<usize> {
        let view = self.view();
        let mut best: Option<(f64, usize)> = None;
        for (i, o) in self.editor.doc().objects.iter().enumerate() {
            let g = o.sampled.grid();
            let [rows, cols] = g.dims;
            for r in (0..rows).step_by(4) {
                for c in (0..cols).step_by(4) {
                    let p = g.position(r, c);
                    let Some((x, y, depth)) =
                        view.camera
                            .project(p, view.size[0], view.size[1], view.bounds)
                    else {
                        continue;
                    };
                    if (x - self.cursor.0).hypot(y - self.cursor.1) <= 24.0
                        && best.is_none_or(|(d, _)| depth < d)
                    {
                        best = Some((depth, i));
                    }
                }
            }
        }
        best.map(|(_, i)| i)
    }

    fn select(&mut self, handle: Handle) {
        self.selected = Some(handle);
        self.selected_local = match handle {
            Handle::LocalPoint { object, local, .. } => Some((object, local)),
            Handle::Point { .. } => None,
        };
        let name = &self.editor.doc().objects[handle.object()].name;
        let what = match handle {
            Handle::Point { point, .. } => format!("{name}: point {}", index_text(point)),
            Handle::LocalPoint { local, point, .. } => {
                format!(
                    "{name}: local {} point {} (G/R/S transform the local)",
                    path_text(local),
                    index_text(point)
                )
            }
        };
        self.set_status(what);
    }

    /// Zoom towards the point under the cursor (on the plane through the target).
    fn zoom(&mut self, delta: f64) {
        let f = 0.85f64.powf(delta);
        let (o, d) = self.view().ray(self.cursor);
        let n = self.camera.direction();
        let denom = d.dot(n);
        let p = if denom.abs() > 1e-9 {
            o + d * ((self.camera.target - o).dot(n) / denom)
        } else {
            self.camera.target
        };
        self.camera.target += (p - self.camera.target) * (1.0 - f);
        self.camera.distance *= f;
        self.projected = None;
    }

    fn key(&mut self, key: Key) {
        let ctrl = self.mods.ctrl;
        if let Mode::Transform { .. } = self.mode {
            return self.transform_key(key);
        }
        if let Mode::Refine(_) = self.mode {
            return self.refine_key(key);
        }
        if let Mode::WeightEntry { .. } = self.mode {
            return self.weight_key(key);
        }
        match (key, ctrl) {
            (Key::Char('z'), true) if self.mods.shift => self.redo(),
            (Key::Char('z'), true) => self.undo(),
            (Key::Char('y'), true) => self.redo(),
            (Key::Char('s'), true) => self.save(),
            (Key::Char('q'), true) => self.quit = true,
            (Key::Char(c @ ('x' | 'y' | 'z')), false) if matches!(self.mode, Mode::Drag { .. }) => {
                if let Mode::Drag { drag, .. } = &mut self.mode {
                    let axis = match c {
                        'x' => Axis::X,
                        'y' => Axis::Y,
                        _ => Axis::Z,
                    };
                    let mut fresh = Drag::new(drag.anchor + drag.applied);
                    fresh.axis = drag.axis.toggle(axis);
                    fresh.grab(
                        &View {
                            camera: &self.camera,
                            bounds: &self.bounds,
                            size: self.size,
                        },
                        self.cursor,
                    );
                    *drag = fresh;
                }
            }
            (Key::Char('x'), false) => self.local_to_erbs(),
            (Key::Char('i'), false) => self.start_refine(),
            (Key::Char('e'), false) => self.elevate(),
            (Key::Char('g'), false) => self.start_transform(TransformKind::Grab),
            (Key::Char('r'), false) => self.start_transform(TransformKind::Rotate),
            (Key::Char('s'), false) => self.start_transform(TransformKind::Scale),
            (Key::Char('c'), false) => {
                self.options.control_nets = self.options.control_nets.next();
                let what = match self.options.control_nets {
                    NetMode::All => "control nets: all objects",
                    NetMode::Focused => {
                        "control nets: selected object and the one under the cursor"
                    }
                    NetMode::Off => "control nets: off",
                };
                self.set_status(what);
            }
            (Key::Char('l'), false) => self.options.local_curves = !self.options.local_curves,
            (Key::Char('w'), false) if self.mods.shift => self.start_weight_entry(),
            (Key::Char('j'), false) => {
                self.options.badges = !self.options.badges;
                self.set_status(if self.options.badges {
                    "continuity badges at junctions and multiple knots"
                } else {
                    "continuity badges off"
                });
            }
            (Key::Char('o'), false) => {
                self.osculating = !self.osculating;
                self.set_status(if self.osculating {
                    "osculating circle, curvature and torsion at the cursor"
                } else {
                    "osculating circle off"
                });
            }
            (Key::Char('m'), false) => self.cycle_map(),
            (Key::Char('b'), false) => self.convert_to_bspline(),
            (Key::Char('w'), false) => {
                self.options.wire = match self.options.wire {
                    Wire::Off => Wire::Isolines(8),
                    Wire::Isolines(_) => Wire::Full,
                    Wire::Full => Wire::Off,
                }
            }
            (Key::Char('n'), false) => self.options.normals = !self.options.normals,
            (Key::Char('t'), false) => self.options.frenet = !self.options.frenet,
            (Key::Char('k'), false) => self.options.curvature_comb = !self.options.curvature_comb,
            (Key::Char('p'), false) => self.hud.visible = !self.hud.visible,
            (Key::Char('d'), false) => {
                self.options.lod = !self.options.lod;
                self.set_status(if self.options.lod {
                    "level of detail: on (dense surfaces drawn from a strided subset)"
                } else {
                    "level of detail: off (every sample drawn)"
                });
            }
            (Key::Char('h'), false) | (Key::F1, _) => self.show_help = !self.show_help,
            (Key::Char('f'), false) => self.frame_selection(),
            (Key::Char('a'), false) => self.frame_all(),
            (Key::Home, _) => {
                self.camera = self.home;
                self.projected = None;
            }
            (Key::Escape, _) => {
                self.selected = None;
                self.selected_local = None;
                self.show_help = false;
            }
            _ => {}
        }
    }

    /// The object the refinement tools act on: the selected one, else the one under the cursor.
    fn focused_object(&self) -> Option<usize> {
        self.selected
            .map(|h| h.object())
            .or(self.selected_local.map(|(o, _)| o))
            .or(self.hovered_object)
    }

    fn start_refine(&mut self) {
        let Some(object) = self.focused_object() else {
            return self.set_status("select a curve or surface first (click one of its points)");
        };
        let mut r = match self.selected_local {
            Some((o, local)) if o == object => Refine::for_local(object, local, self.editor.doc()),
            _ => Refine::new(object),
        };
        r.aim(self.editor.doc(), &self.view(), self.cursor);
        self.mode = Mode::Refine(r);
    }

    fn refine_key(&mut self, key: Key) {
        let Mode::Refine(r) = &mut self.mode else {
            return;
        };
        match key {
            Key::Char(c @ ('u' | 'v')) => {
                r.dir = usize::from(c == 'v')
                    * usize::from(
                        self.editor.doc().objects[r.object]
                            .sampled
                            .model()
                            .is_surface(),
                    );
                let mut r = r.clone();
                r.aim(self.editor.doc(), &self.view(), self.cursor);
                self.mode = Mode::Refine(r);
            }
            Key::Enter => {
                let r = r.clone();
                self.mode = Mode::Idle;
                self.insert_knot(&r);
            }
            Key::Escape => {
                self.mode = Mode::Idle;
                self.set_status("knot insertion cancelled");
            }
            _ => {}
        }
    }

    fn insert_knot(&mut self, r: &Refine) {
        if r.is_erbs(self.editor.doc()) {
            return self.refine_erbs(r);
        }
        match r.edit(self.editor.doc()) {
            Ok(edit) => {
                let what = r.describe(self.editor.doc());
                if !self.structural("insert knot", edit) {
                    return;
                }
                let at = what
                    .split(" (")
                    .next()
                    .unwrap_or(&what)
                    .replace("insert knot in", "inserted a knot in");
                self.set_status(format!("{at} (Ctrl+Z undoes)"));
            }
            Err(e) => self.set_status(format!("cannot insert a knot: {e}")),
        }
    }

    /// ERBS refinement at the aimed parameter: a new Hermite local (a row or column of local
    /// patches on surfaces) in the refined level, one undo step.
    fn refine_erbs(&mut self, r: &Refine) {
        match r.edit(self.editor.doc()) {
            Ok(edit) => {
                let added = r
                    .new_local(self.editor.doc())
                    .unwrap_or_else(|| "a local".into());
                let name = self.editor.doc().objects[r.object].name.clone();
                let at = r.at.unwrap_or_default();
                let axis = r.axis_name(self.editor.doc());
                if !self.structural("refine", edit) {
                    return;
                }
                self.set_status(format!(
                    "refined {name} at {axis} = {at:.4}: new {added} (Ctrl+Z undoes)"
                ));
            }
            Err(e) => self.set_status(format!("cannot refine: {e}")),
        }
    }

    /// X: the selected polynomial local curve or patch becomes an ERBS local of its own, built
    /// by Hermite interpolation (the same shape: its Taylor polynomials of its own degree are
    /// itself), with [`DETAIL_LOCALS`] locals per direction. One undo step.
    fn local_to_erbs(&mut self) {
        self.apply_pending();
        let Some((object, local)) = self.selected_local else {
            return self.set_status(
                "select a local curve or patch of an ERBS object first (click one of its points), then X",
            );
        };
        let Some((edit, degree)) =
            self.editor
                .doc()
                .local_to_erbs_edit(object, local, DETAIL_LOCALS)
        else {
            return self.set_status("the selected local is not a polynomial local curve or patch");
        };
        if let Err(e) = edit.validate(self.editor.doc().objects[object].sampled.model()) {
            return self.set_status(format!("cannot make an ERBS local: {e}"));
        }
        let name = self.editor.doc().objects[object].name.clone();
        if !self.structural(
            "make ERBS local",
            Edit {
                object,
                edit: edit.clone(),
            },
        ) {
            return;
        }
        self.selected_local = Some((object, local));
        let what = if self.editor.doc().objects[object]
            .sampled
            .model()
            .is_surface()
        {
            format!("{DETAIL_LOCALS} x {DETAIL_LOCALS} patches")
        } else {
            format!("{DETAIL_LOCALS} curves")
        };
        self.set_status(format!(
            "{name} local {} is an ERBS now: {what} of degree {degree}, same shape (I refines in it)",
            path_text(local)
        ));
    }

    /// Degree elevation of the focused curve or surface by one (surfaces: in u, with Shift in v).
    fn elevate(&mut self) {
        let Some(object) = self.focused_object() else {
            return self.set_status("select a curve or surface first (click one of its points)");
        };
        let model = self.editor.doc().objects[object].sampled.model();
        let dir = usize::from(self.mods.shift);
        let edit = match model {
            ModelRef::Curve(_) => CurveEdit::ElevateDegree { by: 1 }.into_object(),
            ModelRef::Surface(_) => {
                let mut by = [0, 0];
                by[dir] = 1;
                SurfaceEdit::ElevateDegree { by }.into_object()
            }
            ModelRef::CatmullRom(_) | ModelRef::BezierSpline(_) => {
                let ty = model.type_name();
                return self.set_status(format!(
                    "a {ty} keeps its segments: B converts it to a bspline_curve first"
                ));
            }
            _ => return self.set_status("ERBS objects are not refined by degree elevation"),
        };
        if let Err(e) = edit.validate(model) {
            return self.set_status(format!("cannot elevate the degree: {e}"));
        }
        let name = self.editor.doc().objects[object].name.clone();
        if !self.structural("elevate degree", Edit { object, edit }) {
            return;
        }
        let degree = match self.editor.doc().objects[object].sampled.model() {
            ModelRef::Curve(m) => m.curve().degree().to_string(),
            ModelRef::Surface(m) => format!("{:?}", m.surface().degree()),
            _ => String::new(),
        };
        self.set_status(format!("{name}: degree {degree} (Ctrl+Z undoes)"));
    }

    /// Applies a structural edit as one undo step. Control point indices of that object change,
    /// so its selection and the projected handles are dropped.
    /// Refused (false, the reason on the status line) where the edit does not fit its object or
    /// the result would not fit the memory budget.
    #[must_use]
    fn structural(&mut self, label: &str, edit: Edit) -> bool {
        let object = edit.object;
        self.editor.begin(label);
        let result = self.editor.submit(edit);
        self.editor.end();
        match result {
            Ok(()) => {}
            Err(Refused::OverBudget(e)) => {
                self.set_status(format!("no {label}: {e}"));
                return false;
            }
            Err(Refused::Invalid(e)) => {
                self.set_status(format!("cannot {label}: {e}"));
                return false;
            }
        }
        self.apply_pending();
        if self.selected.is_some_and(|h| h.object() == object) {
            self.selected = None;
        }
        self.hovered = None;
        self.projected = None;
        self.refresh_bounds();
        true
    }

    fn transform_key(&mut self, key: Key) {
        let Mode::Transform { t, .. } = &mut self.mode else {
            return;
        };
        let view = View {
            camera: &self.camera,
            bounds: &self.bounds,
            size: self.size,
        };
        match key {
            Key::Char('x') => t.set_axis(Axis::X, &view),
            Key::Char('y') => t.set_axis(Axis::Y, &view),
            Key::Char('z') => t.set_axis(Axis::Z, &view),
            Key::Char(c @ ('0'..='9' | '.' | '-')) => t.numeric.push(c),
            Key::Backspace => {
                t.numeric.pop();
            }
            Key::Enter => return self.confirm_transform(),
            Key::Escape => return self.cancel_transform(),
            _ => return,
        }
        self.update_transform();
    }

    fn start_transform(&mut self, kind: TransformKind) {
        // The pivot and the starting points come from the model with every queued edit in.
        self.apply_pending();
        let target = match (self.selected_local, self.selected) {
            (Some((o, l)), _) => Target::Local(o, l),
            (None, Some(h)) if kind == TransformKind::Grab => Target::Point(h),
            (None, Some(_)) => {
                return self.set_status("rotate and scale act on ERBS local curves and patches: select a local control point");
            }
            (None, None) => return self.set_status("select a control point first"),
        };
        let pivot = match target {
            Target::Point(h) => self
                .editor
                .doc()
                .handles(h.object())
                .into_iter()
                .find(|(x, _)| *x == h)
                .map(|(_, p)| p),
            Target::Local(o, l) => self
                .editor
                .doc()
                .local_points(o, l)
                .map(|p| p.iter().sum::<DVec3>() / p.len() as f64),
        };
        let Some(pivot) = pivot else { return };
        self.transform_origin = match target {
            Target::Local(o, _) => Some(self.editor.doc().objects[o].sampled.model().to_model()),
            Target::Point(_) => None,
        };
        let t = Box::new(Transform::new(kind, pivot, &self.view(), self.cursor));
        self.editor.begin(kind.name());
        self.mode = Mode::Transform { target, t };
    }

    /// Queues the increment that brings the model from the transform applied so far to the
    /// transform the gesture stands for now.
    fn update_transform(&mut self) {
        let view = View {
            camera: &self.camera,
            bounds: &self.bounds,
            size: self.size,
        };
        let Mode::Transform { target, t } = &mut self.mode else {
            return;
        };
        let total = t.total(&view);
        if total == t.applied {
            return;
        }
        // A singular transform (a typed scale passes through 0 on the way to "0.5") has no
        // inverse to take the next increment from: the local's points are then set exactly
        // from where they were when the gesture began.
        let singular = |m: &DMat4| !(m.determinant().abs() > 0.0 && m.inverse().is_finite());
        let exact = singular(&total) || singular(&t.applied);
        let inc = total * t.applied.inverse();
        t.applied = total;
        let edit = match *target {
            Target::Local(object, local) if exact => self
                .transform_origin
                .as_ref()
                .and_then(|origin| Document::set_local_transformed(object, local, origin, &total)),
            Target::Local(object, local) => self.editor.doc().transform_local(object, local, inc),
            // A point only translates: the increment's translation part.
            Target::Point(h) => self.editor.doc().move_handle(h, inc.w_axis.truncate()),
        };
        if let Some(edit) = edit {
            self.queue(edit);
        }
    }

    fn confirm_transform(&mut self) {
        self.update_transform();
        self.mode = Mode::Idle;
        self.editor.end();
        self.refresh_bounds();
        self.set_status("transform applied (Ctrl+Z undoes)");
    }

    fn cancel_transform(&mut self) {
        self.mode = Mode::Idle;
        self.editor.cancel_step();
        self.set_status("transform cancelled");
    }

    pub fn undo(&mut self) {
        match self.editor.undo() {
            Some(label) => {
                self.set_status(format!("undo: {label}"));
                self.refresh_bounds_later();
            }
            None => self.set_status("nothing to undo"),
        }
    }

    pub fn redo(&mut self) {
        match self.editor.redo() {
            Some(label) => {
                self.set_status(format!("redo: {label}"));
                self.refresh_bounds_later();
            }
            None => self.set_status("nothing to redo"),
        }
    }

    /// Writes the scene (exact control data) to the save path, as OBJ when it ends in `.obj`.
    pub fn save(&mut self) {
        let scene = self.to_scene();
        match crate::scene::obj::save_scene_file(&scene, &self.save_path) {
            Ok(dropped) => {
                if let Some(a) = self.autosave.as_mut() {
                    a.saved();
                }
                let mut status = format!("saved {}", self.save_path.display());
                if !dropped.is_empty() {
                    status.push_str(&format!(" without: {}", dropped.join("; ")));
                }
                self.set_status(status)
            }
            Err(e) => self.set_status(format!("save failed: {e}")),
        }
    }

    fn refresh_bounds(&mut self) {
        self.bounds = self.editor.doc().bounds();
        self.projected = None;
        // An undone or redone refinement changes control point indices.
        let exists =
            |doc: &Document, h: Handle| doc.handles(h.object()).iter().any(|(x, _)| *x == h);
        if self.selected.is_some_and(|h| !exists(self.editor.doc(), h)) {
            self.selected = None;
        }
        if self
            .selected_local
            .is_some_and(|(o, l)| self.editor.doc().local_points(o, l).is_none())
        {
            self.selected_local = None;
        }
        self.hovered = None;
    }

    fn refresh_bounds_later(&mut self) {
        // Undo edits are applied next frame; the bounds follow then.
        self.apply_pending();
        self.refresh_bounds();
    }

    /// Shows the next surface analysis map (M): Gaussian, mean, max and min principal
    /// curvature, zebra stripes, off. Curvature maps re-sample surfaces with second partials.
    pub fn cycle_map(&mut self) {
        self.set_map(SurfaceMap::next(self.options.analysis));
    }

    /// Shows `map` (or none) on every surface.
    pub fn set_map(&mut self, map: Option<SurfaceMap>) {
        let mode = match map {
            Some(m) if m.needs_curvature() => SampleMode::Analysis,
            _ => SampleMode::Render,
        };
        if let Err(e) = self.editor.set_surface_mode(mode) {
            return self.set_status(format!("no curvature map: {e}"));
        }
        self.apply_pending();
        self.options.analysis = map;
        self.refit_map();
        match map {
            Some(m) => self.set_status(format!("analysis: {} (M: next map)", m.title())),
            None => self.set_status("analysis maps off"),
        }
    }

    /// Refits the colour scale to the current surfaces.
    fn refit_map(&mut self) {
        if let Some(map) = self.options.analysis.filter(|m| m.needs_curvature()) {
            self.map_range = map_range(self.editor.doc(), map);
        }
        self.gpu.set_map(self.options.analysis.map(|map| MapView {
            map,
            range: self.map_range,
        }));
    }

    /// B: the focused Catmull–Rom or Bézier spline becomes its equivalent bspline_curve (one
    /// undo step).
    fn convert_to_bspline(&mut self) {
        let Some(object) = self.focused_object() else {
            return self.set_status(
                "select a Catmull–Rom or Bézier spline first (click one of its points)",
            );
        };
        match self.editor.doc().to_bspline(object) {
            Ok(edit) => {
                let name = self.editor.doc().objects[object].name.clone();
                if !self.structural("convert to B-spline", edit) {
                    return;
                }
                self.set_status(format!("{name} is now a bspline_curve (Ctrl+Z undoes)"));
            }
            Err(e) => self.set_status(e),
        }
    }

    /// Shift+W: type a weight for the selected control point.
    fn start_weight_entry(&mut self) {
        let Some(handle) = self.selected else {
            return self.set_status("select a control point first, then Shift+W types its weight");
        };
        if let Err(e) = self.editor.doc().set_weight(handle, 1.0) {
            return self.set_status(e);
        }
        self.mode = Mode::WeightEntry {
            handle,
            text: String::new(),
        };
    }

    fn weight_key(&mut self, key: Key) {
        let Mode::WeightEntry { handle, text } = &mut self.mode else {
            return;
        };
        let handle = *handle;
        match key {
            Key::Char(c @ ('0'..='9' | '.' | 'e' | '-' | '+')) => text.push(c),
            Key::Backspace => {
                text.pop();
            }
            Key::Enter => {
                let typed = text.parse::<f64>();
                self.mode = Mode::Idle;
                let edit = typed
                    .map_err(|_| "not a number".to_string())
                    .and_then(|w| self.editor.doc().set_weight(handle, w));
                match edit {
                    Ok(edit) => {
                        self.editor.begin("weight");
                        self.queue(edit);
                        self.editor.end();
                        self.apply_pending();
                        self.refit_map();
                        let w = self.editor.doc().weight_of(handle).unwrap_or(1.0);
                        self.set_status(format!(
                            "weight of {} is {w} (Ctrl+Z undoes)",
                            self.handle_name(handle)
                        ));
                    }
                    Err(e) => self.set_status(format!("weight not set: {e}")),
                }
            }
            Key::Escape => {
                self.mode = Mode::Idle;
                self.set_status("weight entry cancelled");
            }
            _ => {}
        }
    }

    /// "name point 3" for messages.
    fn handle_name(&self, h: Handle) -> String {
        let name = &self.editor.doc().objects[h.object()].name;
        match h {
            Handle::Point { point, .. } => format!("{name} point {}", index_text(point)),
            Handle::LocalPoint { local, point, .. } => format!(
                "{name} local {} point {}",
                path_text(local),
                index_text(point)
            ),
        }
    }

    /// The curve sample nearest the cursor (within 40 pixels) and its osculating circle.
    fn osculating_at_cursor(&self) -> Option<(usize, Osculating)> {
        let view = self.view();
        let mut best: Option<(f64, usize, f64)> = None;
        for (i, o) in self.editor.doc().objects.iter().enumerate() {
            if o.sampled.model().is_surface() {
                continue;
            }
            let g = o.sampled.grid();
            let params = o.sampled.params()[0];
            let step = (g.dims[0] / 2000).max(1);
            for j in (0..g.dims[0]).step_by(step) {
                let Some((x, y)) = view.project(g.position(j, 0)) else {
                    continue;
                };
                let d = (x - self.cursor.0).hypot(y - self.cursor.1);
                if d <= 40.0 && best.is_none_or(|(b, _, _)| d < b) {
                    best = Some((d, i, params[j]));
                }
            }
        }
        let (_, i, t) = best?;
        let curve = CurveEval::of(self.editor.doc().objects[i].sampled.model())?;
        Osculating::at(&curve, t).map(|o| (i, o))
    }

    pub fn frame_all(&mut self) {
        self.refresh_bounds();
        self.camera.frame(&self.bounds, self.size[0] / self.size[1]);
        self.projected = None;
    }

    fn frame_selection(&mut self) {
        let points: Vec<DVec3> = match (self.selected_local, self.selected) {
            (Some((o, l)), _) => self.editor.doc().local_points(o, l).unwrap_or_default(),
            (None, Some(h)) => self
                .editor
                .doc()
                .handles(h.object())
                .into_iter()
                .map(|(_, p)| p)
                .collect(),
            (None, None) => return self.frame_all(),
        };
        let mut b = Bounds::EMPTY;
        points.iter().for_each(|&p| b.include(p));
        self.camera.frame(&b, self.size[0] / self.size[1]);
        self.projected = None;
    }
}

/// All control nets for small scenes; for scenes with many control points (the demo with the
/// teapot's 512) only the focused object's, so the picture is not buried under points.
fn default_nets(doc: &Document) -> NetMode {
    if doc.all_handles().len() <= 400 {
        NetMode::All
    } else {
        NetMode::Focused
    }
}

//! An interactive editing session, independent of the window system: the stage (the editor's
//! document, camera, selection, status), the gesture in progress, the GPU mirrors, the HUD and
//! the per-frame work (apply edits through the delta path, copy dirty rows, record draws and
//! the overlay). The winit viewer, `--script` replays and `prespline bench` all drive this
//! same type.

use super::autosave::{Autosave, Kept, Lost};
use super::hud::{Hud, free_rect, help_overlay, status_band, status_elided};
use super::input::{InputEvent, Key};
use super::keymap::{Command, command};
use super::modes::{self, Mode};
use super::script::Action;
use super::stage::Stage;
use super::structure;
use crate::editor::{Applied, Document, Editor, Handle};
use crate::gpu::{Frame, GpuResult, Renderer};
use crate::model::{Index2, LocalPath};
use crate::render::analysis::{
    CurveEval, Osculating, badge_overlay, osculating_lines, osculating_overlay,
};
use crate::render::lod::Lod;
use crate::render::map_mirror::MapView;
use crate::render::maps::{
    LegendPlace, MapRange, MapScale, SurfaceMap, legend, map_scales_of, surface_families,
};
use crate::render::overlays::overlay_lines;
use crate::render::{
    Bounds, DrawReport, GpuScene, Highlight, NetMode, OrbitCamera, Palette, UploadStats,
    ViewOptions, Wire,
};
use crate::sampling::SampleMode;
use crate::sampling::budget::MemoryBudget;
use std::path::PathBuf;
use std::time::Instant;

pub use super::structure::DETAIL_LOCALS;

/// Cost of applying one frame's edits.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ApplyStats {
    pub edits: usize,
    pub samples: usize,
    pub micros: f64,
}

pub struct Session {
    stage: Stage,
    mode: Mode,
    gpu: GpuScene,
    pub options: ViewOptions,
    save_path: PathBuf,
    /// The last status message written to stderr because the window cut it.
    status_echoed: String,
    pub hud: Hud,
    pub show_help: bool,
    pub quit: bool,
    /// Unsaved edits kept beside the scene file (`None`: not kept, as in benchmarks).
    autosave: Option<Autosave>,
    /// Osculating circle, curvature and torsion of the curve under the cursor (O).
    pub osculating: bool,
    /// Each object's colour scale of the analysis map (refitted when a map is chosen and after
    /// each gesture that changed samples).
    map_scales: Vec<MapScale>,
    /// The surface families the scales were fitted to ([`surface_families`]), kept with them:
    /// finding them walks every sample, too much for every frame.
    map_families: Vec<(String, Vec<usize>)>,
    /// A scripted action that could not run (see [`Session::take_script_error`]).
    script_error: Option<String>,
    /// Where the performance panel and the status line stand, for framing.
    overlays: OverlayPlaces,
    /// What the last recorded frame's draw of the document did.
    last_draw: DrawReport,
    /// An edit was applied since the last upload (the HUD's bytes are then that upload's).
    edited_this_frame: bool,
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
        let nets = default_nets(editor.doc());
        let gpu = GpuScene::new(renderer, editor.doc())?;
        let hud = Hud::new();
        let overlays = OverlayPlaces {
            panel: hud.panel_rect(renderer.font()),
            status: status_band(renderer.font()),
        };
        let free = free_ndc(
            [f64::from(size[0].max(1)), f64::from(size[1].max(1))],
            overlays.panel,
            overlays.status,
        );
        Ok(Self {
            stage: Stage::new(editor, size, nets, free),
            mode: Mode::Idle,
            gpu,
            options: ViewOptions {
                control_nets: nets,
                ..ViewOptions::default()
            },
            save_path,
            status_echoed: String::new(),
            hud,
            overlays,
            last_draw: DrawReport::default(),
            edited_this_frame: false,
            show_help: false,
            quit: false,
            autosave: None,
            osculating: false,
            map_scales: Vec::new(),
            map_families: Vec::new(),
            script_error: None,
        })
    }

    /// The window region the overlays leave free (NDC `[x0, x1, y0, y1]`): above the status
    /// line, and of the parts beside and below the performance panel (while it is shown) the
    /// larger. Framing (open, F, A) fills it, so no model starts under the panel.
    fn update_free_region(&mut self) {
        let panel = self.overlays.panel.filter(|_| self.hud.visible);
        let free = free_ndc(self.stage.size, panel, self.overlays.status);
        self.stage.set_free(free);
    }

    /// Keeps unsaved edits in an autosave file (see [`super::autosave`]); its start-up notes
    /// go to the status line and stderr.
    pub fn set_autosave(&mut self, autosave: Option<Autosave>) {
        self.autosave = autosave;
        self.show_autosave_notes();
    }

    #[must_use]
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
        let scene = self.stage.doc().to_scene();
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
        let scene = self.stage.doc().to_scene();
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
            self.status_echoed.clone_from(&self.stage.status.text);
        }
    }

    /// Gives the GPU resources back.
    pub fn destroy(self, renderer: &mut Renderer) {
        self.gpu.destroy(renderer);
    }

    #[must_use]
    pub fn size(&self) -> [f64; 2] {
        self.stage.size
    }

    pub fn resize(&mut self, width: u32, height: u32) {
        self.stage.resize(width, height);
        self.update_free_region();
    }

    #[must_use]
    pub fn cursor(&self) -> (f64, f64) {
        self.stage.cursor
    }

    #[must_use]
    pub fn bounds(&self) -> &Bounds {
        &self.stage.bounds
    }

    #[must_use]
    pub fn camera(&self) -> &OrbitCamera {
        &self.stage.camera
    }

    #[must_use]
    pub fn selected(&self) -> Option<Handle> {
        self.stage.selection.selected
    }

    #[must_use]
    pub fn selected_local(&self) -> Option<(usize, LocalPath<Index2>)> {
        self.stage.selection.selected_local
    }

    #[must_use]
    pub fn undo_depth(&self) -> (usize, usize) {
        self.stage.editor.undo_depth()
    }

    /// The document being edited.
    #[must_use]
    pub fn doc(&self) -> &Document {
        self.stage.doc()
    }

    /// The current scene, every queued edit in (what Ctrl+S writes).
    pub fn to_scene(&mut self) -> crate::scene::Scene {
        self.apply_pending();
        self.stage.doc().to_scene()
    }

    /// What pre-evaluation may take from now on (`--memory-limit`).
    pub fn set_memory_budget(&mut self, budget: MemoryBudget) {
        self.stage.editor.set_budget(budget);
    }

    /// How gestures redraw (`--redraw`).
    pub fn set_redraw(&mut self, redraw: crate::render::Redraw) {
        self.gpu.set_redraw(redraw);
    }

    /// Test hook: the retained redraw's dynamic set misses one chunk (a negative control).
    #[doc(hidden)]
    pub fn set_drop_chunk(&mut self, drop: bool) {
        self.gpu.set_drop_chunk(drop);
    }

    /// Test hook: retained frames leave the lines through moved control points out of what
    /// they redraw (a negative control).
    #[doc(hidden)]
    pub fn set_drop_lines(&mut self, drop: bool) {
        self.gpu.set_drop_lines(drop);
    }

    /// Test hook: every gesture builds a static layer, even one whose dynamic set is most of
    /// the frame (where the layer does not pay and frames are drawn in full otherwise), so
    /// exactness tests reach the retained path on small scenes.
    #[doc(hidden)]
    pub fn set_layer_always(&mut self, always: bool) {
        self.gpu.set_layer_always(always);
    }

    /// Re-samples and uploads edited objects in full on every edit (`bench --naive`).
    pub fn set_naive(&mut self, naive: bool) {
        self.stage.editor.naive = naive;
    }

    /// Applies every edit as it comes instead of merging a frame's edits per target.
    pub fn set_merge(&mut self, merge: bool) {
        self.stage.editor.merge = merge;
    }

    /// What the last recorded frame's draw of the document did (for profiles).
    #[must_use]
    pub fn last_draw(&self) -> DrawReport {
        self.last_draw
    }

    /// The status line's message (what the last action did or why it could not).
    #[must_use]
    pub fn status(&self) -> &str {
        &self.stage.status.text
    }

    pub fn set_status(&mut self, s: impl Into<String>) {
        self.stage.set_status(s);
    }

    /// Screen position of a handle (for scripts that aim at a control point).
    #[must_use]
    pub fn handle_position(&self, handle: Handle) -> Option<(f64, f64)> {
        self.stage.view().project(self.stage.handle_world(handle)?)
    }

    /// Applies this frame's queued edits through the delta path and hands the editor's report
    /// to the GPU scene, which marks what it rewrote dirty for every frame slot's mirrors.
    pub fn apply_pending(&mut self) -> ApplyStats {
        let applied = self.stage.editor.apply_pending();
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
        self.stage.moved();
        self.hud.edit_us = applied.micros;
        self.hud.samples_touched = applied.samples;
        self.edited_this_frame = true;
    }

    /// Copies this slot's dirty rows into the mirrors, and makes the control mirrors this
    /// frame will draw for the first time (counted with the bytes copied).
    pub fn upload(&mut self, frame: &mut Frame<'_>) -> GpuResult<UploadStats> {
        let mut stats = self.gpu.upload(frame, self.stage.doc())?;
        let hl = self.highlight();
        stats.bytes += self
            .gpu
            .make_controls(frame, self.stage.doc(), &self.options, &hl)?;
        // The edit line's bytes are its edit's upload: frames without an edit (whose uploads
        // bring the other frame slots up to date, or are empty) keep them.
        if std::mem::take(&mut self.edited_this_frame) || stats.bytes > 0 {
            self.hud.bytes = stats.bytes;
        }
        Ok(stats)
    }

    /// The hovered and selected handles, local and object, as the draw marks them.
    fn highlight(&self) -> Highlight {
        let s = &self.stage.selection;
        Highlight {
            hovered: s.hovered.map(|p| p.handle),
            selected: s.selected,
            selected_local: s.selected_local,
            hovered_object: s.hovered_object,
        }
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
                let before = self.stage.mods;
                self.handle(InputEvent::Modifiers(mods));
                self.handle(InputEvent::Key { key, pressed: true });
                self.handle(InputEvent::Key {
                    key,
                    pressed: false,
                });
                self.handle(InputEvent::Modifiers(before));
            }
            Action::MoveTo(h) => match self.handle_position(h) {
                Some((x, y)) => self.handle(InputEvent::CursorMoved { x, y }),
                None if self.stage.handle_world(h).is_none() => {
                    self.script_error = Some(format!(
                        "move_to: there is no {} now",
                        self.stage.handle_name(h)
                    ));
                }
                None => {}
            },
            Action::MoveOnto { object, at } => {
                let p = self.stage.sample_near(object, at);
                if let Some((x, y)) = p.and_then(|p| self.stage.view().project(p)) {
                    self.handle(InputEvent::CursorMoved { x, y });
                }
            }
            Action::MoveBy(dx, dy) => {
                let (x, y) = self.stage.cursor;
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
        let s = &self.stage;
        let aspect = s.size[0] / s.size[1];
        frame.set_clear_color(Palette::default().background);
        frame.set_camera(s.camera.gpu(aspect, &s.bounds));
        let hl = self.highlight();
        let lod = Lod::new(
            s.camera.view_proj(aspect, &s.bounds),
            s.size,
            frame.samples(),
        );
        self.gpu.set_gesture(self.mode.gesture());
        let report = self.gpu.draw(frame, s.doc(), &self.options, &hl, &lod)?;
        self.last_draw = report;
        self.hud.layer_built = report.layer_built;
        if report.retained {
            self.hud.triangles = (report.retained_of, report.full_triangles);
            self.hud.retained = Some((report.triangles, report.retained_of));
        } else {
            self.hud.triangles = (report.triangles, report.full_triangles);
            self.hud.retained = None;
        }
        let mut lines = overlay_lines(s.doc(), &self.options, s.bounds.radius());
        lines.extend(self.mode.preview(s));
        let font = frame.font();
        let (width, height) = (s.size[0] as f32, s.size[1] as f32);
        // Back to front: badges, legend, the osculating readout (never under a badge), the
        // HUD and status line, and the help above everything.
        let mut overlay = Vec::new();
        let mut readout = Vec::new();
        if self.osculating
            && self.mode.shows_osculating()
            && let Some((object, o)) = self.osculating_at_cursor()
        {
            lines.extend(osculating_lines(&o));
            if let Some(at) = s.view().project(o.point) {
                let name = &s.doc().objects[object].name;
                readout = osculating_overlay(name, &o, font, at, [width, height]);
            }
        }
        if !lines.is_empty() {
            frame.draw_lines3d(&lines)?;
        }
        if self.options.badges {
            let view = s.view();
            overlay.extend(badge_overlay(s.doc(), font, |p| view.project(p)));
        }
        if let Some(map) = self.options.analysis {
            overlay.extend(self.map_legend(map, font, width, height));
        }
        overlay.extend(readout);
        if hud {
            let status = self.status_text();
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

    /// The status line now: the gesture's own (a transform's values, …) or the last message,
    /// which expires after a while.
    fn status_text(&mut self) -> String {
        if let Some(text) = self.mode.status(&self.stage) {
            return text;
        }
        self.stage.status.expire();
        self.stage.status.text.clone()
    }

    /// Handles one input event.
    pub fn handle(&mut self, event: InputEvent) {
        let s = &mut self.stage;
        match event {
            InputEvent::Modifiers(m) => s.mods = m,
            InputEvent::CursorMoved { x, y } => {
                self.mode = std::mem::take(&mut self.mode).cursor_moved(s, x, y);
            }
            InputEvent::Button { button, pressed } => {
                self.mode = std::mem::take(&mut self.mode).button(s, button, pressed);
            }
            InputEvent::Wheel { delta } => s.zoom(delta),
            InputEvent::Key { key, pressed: true } => self.key(key),
            InputEvent::Key { .. } => {}
        }
        if std::mem::take(&mut self.stage.refit_map) {
            self.refit_map();
        }
    }

    fn key(&mut self, key: Key) {
        if self.mode.takes_keys() {
            self.mode = std::mem::take(&mut self.mode).key(&mut self.stage, key);
            return;
        }
        let dragging = matches!(self.mode, Mode::Drag { .. });
        if let Some(c) = command(key, self.stage.mods, dragging) {
            self.run(c, key);
        }
    }

    /// Carries out a command of the key map.
    fn run(&mut self, c: Command, key: Key) {
        let s = &mut self.stage;
        match c {
            Command::Undo => s.undo(),
            Command::Redo => s.redo(),
            Command::Save => self.save(),
            Command::Quit => self.quit = true,
            Command::DragAxis => self.mode = std::mem::take(&mut self.mode).key(s, key),
            Command::LocalToErbs => structure::local_to_erbs(s),
            Command::Refine => self.mode = modes::start_refine(s),
            Command::Elevate(dir) => structure::elevate(s, dir),
            Command::Transform(kind) => self.mode = modes::start_transform(s, kind),
            Command::WeightEntry => self.mode = modes::start_weight_entry(s),
            Command::ToBspline => structure::to_bspline(s),
            Command::CycleNets => {
                self.options.control_nets = self.options.control_nets.next();
                s.set_status(match self.options.control_nets {
                    NetMode::All => "control nets: all objects",
                    NetMode::Focused => {
                        "control nets: selected object and the one under the cursor"
                    }
                    NetMode::Off => "control nets: off",
                });
            }
            Command::ToggleLocals => toggle(&mut self.options.local_curves),
            Command::CycleWire => {
                self.options.wire = match self.options.wire {
                    Wire::Off => Wire::Isolines(8),
                    Wire::Isolines(_) => Wire::Full,
                    Wire::Full => Wire::Off,
                }
            }
            Command::ToggleNormals => toggle(&mut self.options.normals),
            Command::ToggleFrenet => toggle(&mut self.options.frenet),
            Command::ToggleComb => toggle(&mut self.options.curvature_comb),
            Command::ToggleBadges => {
                toggle(&mut self.options.badges);
                s.set_status(if self.options.badges {
                    "continuity badges at junctions and multiple knots"
                } else {
                    "continuity badges off"
                });
            }
            Command::ToggleOsculating => {
                toggle(&mut self.osculating);
                s.set_status(if self.osculating {
                    "osculating circle, curvature and torsion at the cursor"
                } else {
                    "osculating circle off"
                });
            }
            Command::CycleMap => self.cycle_map(),
            Command::ToggleLod => {
                toggle(&mut self.options.lod);
                s.set_status(if self.options.lod {
                    "level of detail: on (dense surfaces drawn from a strided subset)"
                } else {
                    "level of detail: off (every sample drawn)"
                });
            }
            Command::ToggleHud => {
                toggle(&mut self.hud.visible);
                self.update_free_region();
            }
            Command::ToggleHelp => toggle(&mut self.show_help),
            Command::FrameSelection => s.frame_selection(self.options.control_nets),
            Command::FrameAll => s.frame_all(self.options.control_nets),
            Command::Home => s.go_home(),
            Command::Escape => {
                s.selection.clear();
                self.show_help = false;
            }
        }
    }

    pub fn undo(&mut self) {
        self.stage.undo();
    }

    pub fn redo(&mut self) {
        self.stage.redo();
    }

    /// Writes the scene (exact control data) to the save path, as OBJ when it ends in `.obj`.
    pub fn save(&mut self) {
        let scene = self.to_scene();
        match crate::formats::save(&scene, &self.save_path) {
            Ok(dropped) => {
                if let Some(a) = self.autosave.as_mut() {
                    a.saved();
                }
                let mut msg = format!("saved {}", self.save_path.display());
                if !dropped.is_empty() {
                    msg.push_str(&format!(" without: {}", dropped.join("; ")));
                }
                self.set_status(msg)
            }
            Err(e) => self.set_status(format!("save failed: {e}")),
        }
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
        if let Err(e) = self.stage.editor.set_surface_mode(mode) {
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
            self.stage.editor.apply_queued();
            self.map_families = surface_families(self.stage.doc());
            let doc = self.stage.doc();
            self.map_scales = map_scales_of(doc, map, self.options.map_range, &self.map_families);
        }
        self.gpu.set_map(self.options.analysis.map(|map| MapView {
            map,
            scales: self.map_scales.clone(),
        }));
    }

    /// How the analysis map's colour scale is chosen (`--map-range`); refits it.
    pub fn set_map_range(&mut self, range: MapRange) {
        self.options.map_range = range;
        self.refit_map();
    }

    /// The legend of the map: the selected surface's scale under per-object ranges (the first
    /// surface's while no surface is selected), named by its family; the one scale otherwise.
    fn map_legend(
        &self,
        map: SurfaceMap,
        font: &crate::gpu::font::Font,
        width: f32,
        height: f32,
    ) -> Vec<crate::gpu::OverlayVertex> {
        let families = &self.map_families;
        let selected = self.selected().map(|h| h.object());
        let family = families
            .iter()
            .find(|(_, m)| selected.is_some_and(|i| m.contains(&i)))
            .or(families.first());
        let own = self.options.map_range == MapRange::PerObject && families.len() > 1;
        let name = family.filter(|_| own).map(|(name, _)| name.as_str());
        let scale = family
            .and_then(|(_, m)| self.map_scales.get(m[0]))
            .copied()
            .unwrap_or(MapScale::symmetric(1.0));
        let place = LegendPlace {
            name,
            slot: 0,
            width,
            height,
        };
        legend(map, scale, font, place)
    }

    /// The curve sample nearest the cursor (within 40 pixels) and its osculating circle.
    fn osculating_at_cursor(&self) -> Option<(usize, Osculating)> {
        let s = &self.stage;
        let view = s.view();
        let mut best: Option<(f64, usize, f64)> = None;
        for (i, o) in s.doc().objects.iter().enumerate() {
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
                let d = (x - s.cursor.0).hypot(y - s.cursor.1);
                if d <= 40.0 && best.is_none_or(|(b, _, _)| d < b) {
                    best = Some((d, i, params[j]));
                }
            }
        }
        let (_, i, t) = best?;
        let curve = CurveEval::of(s.doc().objects[i].sampled.model())?;
        Osculating::at(&curve, t).map(|o| (i, o))
    }

    pub fn frame_all(&mut self) {
        self.stage.frame_all(self.options.control_nets);
    }
}

/// The overlays framing keeps the model out of: the performance panel's rectangle as it opened
/// (`[x, y, width, height]` pixels, top-left origin; `None` when hidden) and the status line's
/// band height at the bottom.
#[derive(Debug, Clone, Copy)]
struct OverlayPlaces {
    panel: Option<[f32; 4]>,
    status: f64,
}

/// [`free_rect`] of a `size` window as an NDC region `[x0, x1, y0, y1]` (y up), which framing
/// fills.
fn free_ndc(size: [f64; 2], panel: Option<[f32; 4]>, status: f64) -> [f64; 4] {
    let [w, h] = size;
    let px = free_rect(size, panel, status);
    [
        2.0 * px[0] / w - 1.0,
        2.0 * px[1] / w - 1.0,
        1.0 - 2.0 * px[3] / h,
        1.0 - 2.0 * px[2] / h,
    ]
}

fn toggle(flag: &mut bool) {
    *flag = !*flag;
}

/// All control nets for small scenes; for scenes with many control points (the demo with the
/// teapot's 512) only the focused object's, so the picture is not buried under points.
fn default_nets(doc: &Document) -> NetMode {
    let handles: usize = doc
        .objects
        .iter()
        .map(|o| o.controls.grip_points().take(401).count())
        .sum();
    if handles <= 400 {
        NetMode::All
    } else {
        NetMode::Focused
    }
}

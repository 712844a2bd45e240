//! What the viewer's gestures and commands act on: the document through its editor, the
//! camera over it, the selection, the cursor and the status line. The session owns one stage
//! and hands it to the gesture in progress ([`super::modes`]) and to the commands of the key
//! map ([`super::keymap`]), so none of them needs the GPU or the window.

use super::input::Modifiers;
use super::picking::{PICK_RADIUS, Projected, pick, project_all};
use super::tools::View;
use crate::editor::{Document, Editor, Handle, Refused};
use crate::model::{Edit, Index2, LocalPath};
use crate::render::offscreen::framing_points;
use crate::render::style::NetMode;
use crate::render::{Bounds, OrbitCamera};
use glam::DVec3;
use std::time::Instant;

/// What is selected and what is under the cursor.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Selection {
    pub selected: Option<Handle>,
    /// The ERBS local curve or patch the selected local control point belongs to.
    pub selected_local: Option<(usize, LocalPath<Index2>)>,
    pub hovered: Option<Projected>,
    /// The object under the cursor (a handle's, or one with a sample near it).
    pub hovered_object: Option<usize>,
}

impl Selection {
    /// The object the refinement tools act on: the selected one, else the one under the cursor.
    #[must_use]
    pub fn focused_object(&self) -> Option<usize> {
        self.selected
            .map(|h| h.object())
            .or(self.selected_local.map(|(o, _)| o))
            .or(self.hovered_object)
    }

    pub fn clear(&mut self) {
        self.selected = None;
        self.selected_local = None;
    }
}

/// The status line: the last message and when it was set.
#[derive(Debug, Clone)]
pub struct Status {
    pub text: String,
    pub since: Option<Instant>,
}

/// How long a status message stays (a transform in progress keeps its own).
const STATUS_SECONDS: f64 = 6.0;

impl Status {
    fn new(text: &str) -> Self {
        Self {
            text: text.into(),
            since: Some(Instant::now()),
        }
    }

    /// Clears a message shown long enough.
    pub fn expire(&mut self) {
        if self
            .since
            .is_some_and(|t| t.elapsed().as_secs_f64() > STATUS_SECONDS)
        {
            self.text.clear();
            self.since = None;
        }
    }
}

/// The viewer's state below the window and the GPU.
pub struct Stage {
    pub editor: Editor,
    pub camera: OrbitCamera,
    /// Where Home takes the camera back to.
    pub home: OrbitCamera,
    pub size: [f64; 2],
    pub bounds: Bounds,
    pub cursor: (f64, f64),
    pub mods: Modifiers,
    pub selection: Selection,
    pub status: Status,
    /// A gesture changed the samples a curvature map colours: its scale is refitted.
    pub refit_map: bool,
    /// Projected handles, recomputed when the camera or the model changes.
    projected: Option<Vec<Projected>>,
    /// The NDC region `[x0, x1, y0, y1]` the overlays leave free, which framing fills.
    free: [f64; 4],
}

impl Stage {
    /// The editor's document framed for a `size` image as [`Stage::frame_all`] frames it,
    /// into `free` (the NDC region the overlays leave free, [`Stage::set_free`]); that view is
    /// the home view.
    #[must_use]
    pub fn new(editor: Editor, size: [u32; 2], nets: NetMode, free: [f64; 4]) -> Self {
        let bounds = editor.doc().bounds();
        let size = [size[0].max(1) as f64, size[1].max(1) as f64];
        let mut camera = OrbitCamera::default_for(&bounds);
        camera.frame_points_in(
            &framing_points(editor.doc(), |_| nets == NetMode::All),
            &bounds,
            size[0] / size[1],
            free,
        );
        Self {
            editor,
            camera,
            home: camera,
            size,
            bounds,
            cursor: (size[0] * 0.5, size[1] * 0.5),
            mods: Modifiers::default(),
            selection: Selection::default(),
            status: Status::new("H or F1: keys"),
            refit_map: false,
            projected: None,
            free,
        }
    }

    #[must_use]
    pub fn doc(&self) -> &Document {
        self.editor.doc()
    }

    /// Camera, bounds and image size for projections.
    #[must_use]
    pub fn view(&self) -> View<'_> {
        View {
            camera: &self.camera,
            bounds: &self.bounds,
            size: self.size,
        }
    }

    /// Control characters in the message are escaped (object names are user text).
    pub fn set_status(&mut self, s: impl Into<String>) {
        let s: String = s.into();
        self.status.text = crate::scene::escape_controls(&s).into_owned();
        self.status.since = Some(Instant::now());
    }

    /// The camera or the model moved: handles project anew.
    pub fn moved(&mut self) {
        self.projected = None;
    }

    pub fn resize(&mut self, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.size = [width as f64, height as f64];
            self.moved();
        }
    }

    fn projected(&mut self) -> &[Projected] {
        if self.projected.is_none() {
            let handles = self.editor.doc().all_handles();
            self.projected = Some(project_all(&handles, &self.camera, &self.bounds, self.size));
        }
        self.projected.as_deref().unwrap_or(&[])
    }

    /// The control point under the cursor.
    pub fn pick(&mut self) -> Option<Projected> {
        let cursor = self.cursor;
        pick(self.projected(), cursor, PICK_RADIUS)
    }

    /// What the cursor is over now (while no gesture runs).
    pub fn hover(&mut self) {
        self.selection.hovered = self.pick();
        self.selection.hovered_object = self
            .selection
            .hovered
            .map(|p| p.handle.object())
            .or_else(|| self.object_near_cursor());
    }

    /// The object with a drawn sample projecting within 24 pixels of the cursor (every 4th
    /// sample per direction is enough to find an object; outside a trim nothing is drawn, so
    /// nothing is picked), nearest in depth.
    fn object_near_cursor(&self) -> Option<usize> {
        let view = self.view();
        let mut best: Option<(f64, usize)> = None;
        for (i, o) in self.doc().objects.iter().enumerate() {
            let g = o.sampled.grid();
            let [rows, cols] = g.dims;
            for r in (0..rows).step_by(4) {
                for c in (0..cols).step_by(4).filter(|&c| o.drawn(r, c)) {
                    let Some((x, y, depth)) = view.project_depth(g.position(r, c)) else {
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

    /// Selects a handle (and, for a local control point, its local curve or patch).
    pub fn select(&mut self, handle: Handle) {
        self.selection.selected = Some(handle);
        self.selection.selected_local = match handle {
            Handle::LocalPoint { object, local, .. } => Some((object, local)),
            Handle::Point { .. } => None,
        };
        let what = match handle {
            Handle::Point { .. } => self.handle_name(handle),
            Handle::LocalPoint { .. } => {
                format!("{} (G/R/S transform the local)", self.handle_name(handle))
            }
        };
        self.set_status(what);
    }

    /// "name point 3", "name local 1 → [0, 2] point [1, 1]" for messages.
    #[must_use]
    pub fn handle_name(&self, h: Handle) -> String {
        let name = &self.doc().objects[h.object()].name;
        match h {
            Handle::Point { point, .. } => format!("{name} point {point}"),
            Handle::LocalPoint { local, point, .. } => {
                format!("{name} local {local} point {point}")
            }
        }
    }

    /// Where a handle is in the world now, if it exists.
    #[must_use]
    pub fn handle_world(&self, handle: Handle) -> Option<DVec3> {
        self.doc()
            .handles(handle.object())
            .into_iter()
            .find(|(h, _)| *h == handle)
            .map(|(_, p)| p)
    }

    /// Submits an edit for this frame; a refusal goes to the status line.
    pub fn submit(&mut self, edit: Edit) {
        let object = edit.object;
        if let Err(e) = self.editor.submit(edit) {
            let name = &self.doc().objects[object].name;
            self.set_status(format!("{name}: edit refused: {e}"));
        }
    }

    /// Applies a structural edit as one undo step. Control point indices of that object change,
    /// so its selection and the projected handles are dropped. Refused (false, the reason on the
    /// status line) where the edit does not fit its object or the result would not fit the
    /// memory budget.
    #[must_use]
    pub fn structural(&mut self, label: &str, edit: Edit) -> bool {
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
        if self
            .selection
            .selected
            .is_some_and(|h| h.object() == object)
        {
            self.selection.selected = None;
        }
        self.refresh_bounds();
        true
    }

    /// New bounds after the model changed; a selection whose point an undone or redone
    /// refinement took away is dropped.
    pub fn refresh_bounds(&mut self) {
        self.bounds = self.editor.doc().bounds();
        self.moved();
        let doc = self.editor.doc();
        let exists = |h: Handle| doc.handles(h.object()).iter().any(|(x, _)| *x == h);
        if self.selection.selected.is_some_and(|h| !exists(h)) {
            self.selection.selected = None;
        }
        if self
            .selection
            .selected_local
            .is_some_and(|(o, l)| doc.local_points(o, l).is_none())
        {
            self.selection.selected_local = None;
        }
        self.selection.hovered = None;
    }

    pub fn undo(&mut self) {
        match self.editor.undo() {
            Some(label) => {
                self.set_status(format!("undo: {label}"));
                self.refresh_bounds();
                self.refit_map = true;
            }
            None => self.set_status("nothing to undo"),
        }
    }

    pub fn redo(&mut self) {
        match self.editor.redo() {
            Some(label) => {
                self.set_status(format!("redo: {label}"));
                self.refresh_bounds();
                self.refit_map = true;
            }
            None => self.set_status("nothing to redo"),
        }
    }

    /// Zoom towards the point under the cursor (on the plane through the target).
    pub fn zoom(&mut self, delta: f64) {
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
        self.moved();
    }

    /// Turns the camera by a cursor motion in pixels.
    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.camera.orbit(-dx * 0.008, dy * 0.008);
        self.moved();
    }

    /// Moves the camera with the cursor: what was under it stays under it.
    pub fn pan(&mut self, dx: f64, dy: f64) {
        let per_pixel = 2.0 * self.camera.distance * (0.5 * self.camera.fov_y).tan() / self.size[1];
        let (right, up) = self.camera.basis();
        self.camera.pan((-right * dx + up * dy) * per_pixel);
        self.moved();
    }

    /// Frames what is drawn, as `prespline render` does: the projected samples, and the
    /// control points of the objects whose nets `nets` shows (all, or the selected object's),
    /// centred with balanced margins (fitting the bounding box left a flat object seen from
    /// above crowded at the bottom and empty on top).
    pub fn frame_all(&mut self, nets: NetMode) {
        self.refresh_bounds();
        let focused = self.selection.focused_object();
        let shown = |i: usize| match nets {
            NetMode::All => true,
            NetMode::Focused => focused == Some(i),
            NetMode::Off => false,
        };
        let points = framing_points(self.editor.doc(), shown);
        self.camera.frame_points_in(
            &points,
            &self.bounds,
            self.size[0] / self.size[1],
            self.free,
        );
        self.moved();
    }

    /// Sets the NDC region `[x0, x1, y0, y1]` the overlays leave free: framing fills it.
    pub fn set_free(&mut self, region: [f64; 4]) {
        self.free = region;
    }

    /// Frames the selected local, or the selected point's object, or everything.
    pub fn frame_selection(&mut self, nets: NetMode) {
        let doc = self.editor.doc();
        let points: Vec<DVec3> = match (self.selection.selected_local, self.selection.selected) {
            (Some((o, l)), _) => doc.local_points(o, l).unwrap_or_default(),
            (None, Some(h)) => doc
                .handles(h.object())
                .into_iter()
                .map(|(_, p)| p)
                .collect(),
            (None, None) => return self.frame_all(nets),
        };
        let mut b = Bounds::EMPTY;
        points.iter().for_each(|&p| b.include(p));
        self.camera
            .frame_points_in(&points, &b, self.size[0] / self.size[1], self.free);
        self.moved();
    }

    /// Object `object`'s sample nearest the parameter `at` (t in `at[0]` on curves): a point
    /// of the object as drawn.
    #[must_use]
    pub fn sample_near(&self, object: usize, at: [f64; 2]) -> Option<DVec3> {
        let o = self.doc().objects.get(object)?;
        let nearest = |params: &[f64], x: f64| {
            (0..params.len())
                .min_by(|&a, &b| (params[a] - x).abs().total_cmp(&(params[b] - x).abs()))
        };
        let params = o.sampled.params();
        let i = nearest(params[0], at[0])?;
        let j = match params.get(1) {
            Some(v) => nearest(v, at[1])?,
            None => 0,
        };
        Some(o.sampled.grid().position(i, j))
    }

    /// Back to the camera the session opened with.
    pub fn go_home(&mut self) {
        self.camera = self.home;
        self.moved();
    }
}

//! The document on the GPU: the objects' samples in arena mirrors and a mirror per drawn
//! control structure, with per-frame-slot dirty tracking so each slot receives exactly the rows
//! changed since it was last written.

use super::analysis::{CurvePiece, curve_pieces};
use super::control_pass::{
    ControlPass, NetClip, clipped_net, control_drawn, is_local_display, line_margin, net_shown,
    polyline,
};
use super::grips::grip_every;
use super::lod::{GridMetrics, Lod};
use super::map_mirror::{MapScalars, MapView, SurfaceSlot};
use super::retained::{
    Gesture, LayerKey, Redraw, SplitCells, covers, moving_vertices, overlaps, sample_bounds,
    screen_rect, screen_rect_with, split_cells, touched_vertices, union_rect, vertex_bounds,
};
use super::style::{Highlight, NetMode, Palette, ViewOptions, Wire};
use super::trim_mask::{BlockRanges, TrimBlocks, mask_entry, mask_parts};
use crate::editor::{Applied, ControlLayout, ControlsChange, Document};
use crate::gpu::{
    FRAMES_IN_FLIGHT, Frame, GpuError, GpuResult, GridShape, GridStride, LayerPart, MapStyle,
    MaskRef, MaskSet, MaskWords, Mirror, PointRun, PolylineStyle, Renderer, Restore, SurfaceBatch,
    SurfaceGrid, SurfaceStyle,
};
use crate::sampling::{DirtyRegion, DirtySet};
use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet};

/// Where an object's samples sit: an arena mirror and a float offset in it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Place {
    arena: usize,
    offset: usize,
}

struct ObjectGpu {
    name: String,
    samples: Place,
    /// Sample rows (surfaces) or samples (curves) each slot has not seen yet.
    dirty: [DirtySet; FRAMES_IN_FLIGHT],
    /// The control display's mirror, made when a frame first draws the display: a scene of
    /// many patches drawn without their nets (`render`) never pays a Vulkan buffer per patch.
    controls: Option<Mirror>,
    /// Control display vertices each slot has not seen yet (while `controls` exists).
    controls_dirty: [DirtySet; FRAMES_IN_FLIGHT],
    /// The control display changed layout: the next upload replaces the control mirror.
    controls_resized: bool,
    /// Every how many rows and columns its control grips are drawn ([`super::grips`]), for the
    /// view in `GpuScene::lod_view` (kept while the view stands, also through edits).
    grips: Option<u32>,
    /// Stride chosen for the view in `GpuScene::lod_view`, until the view or the samples change.
    lod: Option<GridStride>,
    /// World-space measures of the samples for choosing strides; `None` until measured after
    /// the samples last changed (the inner `None`: not measurable, drawn in full).
    metrics: Option<Option<GridMetrics>>,
    /// World-space bounds of the samples, measured when a static layer needs them.
    bounds: Option<Option<[DVec3; 2]>>,
}

/// Surfaces of one grid shape and colour in one arena: drawn with one multi-draw per stride.
/// A trimmed surface is a group of its own, drawn through its coverage mask.
#[derive(Debug, Clone, PartialEq)]
struct SurfaceGroup {
    /// Object indices, in document order.
    members: Vec<usize>,
    shape: GridShape,
    arena: usize,
    /// The trimmed member's entry in the scene's [`MaskSet`].
    mask: Option<u32>,
}

/// Surfaces of one group drawn at one stride: one multi-draw in a full redraw.
#[derive(Debug, Clone, PartialEq)]
struct Batch {
    group: usize,
    stride: GridStride,
    members: Vec<usize>,
}

/// Floats per arena mirror at most (256 MiB); a larger object gets an arena of its own.
const ARENA_FLOATS: usize = 64 << 20;

/// What one frame's upload copied.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UploadStats {
    /// Bytes written into mapped memory.
    pub bytes: usize,
    /// Sample rows (surfaces) and samples (curves) copied.
    pub rows: usize,
}

/// What one frame's draw of the document cost in surface triangles.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DrawReport {
    /// Triangles of the surfaces as drawn (after level of detail).
    pub triangles: u64,
    /// Triangles the surfaces would have at full resolution.
    pub full_triangles: u64,
    /// The frame started from the static layer: `triangles` of `retained_of` (the triangles
    /// of a full redraw at the same levels of detail) were drawn.
    pub retained: bool,
    pub retained_of: u64,
    /// The frame built the gesture's static layer (a full redraw and the layer's saves).
    pub layer_built: bool,
}

/// The document's GPU side. Samples of all objects live in a few large *arena* mirrors
/// (surfaces first, in document order, then curves), so a group of same-shaped surfaces is
/// drawn with one multi-draw per level of detail; a control structure has a mirror of its own
/// from the first frame that draws it.
pub struct GpuScene {
    arenas: Vec<Mirror>,
    objects: Vec<ObjectGpu>,
    groups: Vec<SurfaceGroup>,
    /// The view the objects' cached strides were chosen for.
    lod_view: Option<Lod>,
    /// The analysis map on surfaces ([`GpuScene::set_map`]).
    map: Option<MapView>,
    /// The curvature map's scalars, built by the first upload after the map changed.
    scalars: Option<MapScalars>,
    scratch: Vec<f32>,
    /// Some surface's LOD metrics were dropped since [`GpuScene::measure_grids`] last ran.
    unmeasured: bool,
    /// Per arena, the frame slots not yet written since the arena was created.
    unfilled: Vec<[bool; FRAMES_IN_FLIGHT]>,
    /// `--redraw`: whether gestures draw from a static layer.
    redraw: Redraw,
    /// The gesture in progress ([`GpuScene::set_gesture`]).
    gesture: Option<Gesture>,
    /// The static layer of the gesture, once built.
    layer: Option<Layer>,
    /// The last gesture whose dynamic set was too much of the frame for a static layer to
    /// pay (see [`worth_a_layer`]): its frames draw in full without trying again.
    unworthy: Option<LayerKey>,
    /// Test hook: build a layer for every gesture ([`GpuScene::set_layer_always`]).
    layer_always: bool,
    /// Test hook: the dynamic set misses one chunk (a negative control).
    drop_chunk: bool,
    /// Test hook: the lines through moved control points are left out of the redrawn
    /// rectangle (a negative control).
    drop_lines: bool,
    /// Control vertices of the gesture's object its edits rewrote so far (the next layer
    /// redraws the lines through them every frame).
    moved_controls: DirtySet,
    /// Objects whose control display is an ERBS local display (drawn wherever local curves
    /// are shown), kept current when a display changes layout: the frames that make control
    /// mirrors look at these and the focused objects, not at every object of the scene.
    local_displays: BTreeSet<usize>,
    /// Every object has its control mirror: nothing is left to make.
    controls_complete: bool,
    /// The trimmed surfaces' coverage masks, made by the first frame that draws.
    masks: Option<MaskSet>,
    /// Per mask, its blocks by class at every level of detail (made with the masks).
    blocks: Vec<TrimBlocks>,
    /// Static layers built so far (a frame that builds one reports it).
    layers_built: u64,
}

/// A static layer in the target and what it was built for.
struct Layer {
    key: LayerKey,
    /// The saves of the static surfaces ([`LayerPart::Surfaces`]) and of the surfaces with
    /// every line and point over them ([`LayerPart::Lines`]).
    surfaces: u64,
    lines: u64,
    /// The support of the gesture's target when the layer was built.
    support: Vec<DirtyRegion>,
    /// Control vertices of the gesture's object that may move, and the vertices of every
    /// line and point drawn through them.
    moving: DirtySet,
    touched: DirtySet,
    /// Screen rectangle of those lines and points as the layer holds them.
    lines_then: [u32; 4],
    /// Screen rectangle of each other object's lines and points (`None`: nothing drawn).
    line_rects: Vec<Option<[u32; 4]>>,
    /// The dragged surface's cells (`None`: the gesture moves a curve).
    cells: Option<SplitCells>,
    /// Surfaces after the dragged one in draw order, with their screen rectangles.
    later: Vec<(usize, [u32; 4])>,
    /// Something drawn in the layer changed: the next frame draws in full.
    stale: bool,
}

/// Reflection-line bands of the zebra map over the height of the reflected view ray.
const ZEBRA_STRIPES: f32 = 16.0;

impl GpuScene {
    /// Creates the sample arenas, which the first upload into each frame slot writes; control
    /// mirrors are made by the first frame that draws them.
    pub fn new(renderer: &mut Renderer, doc: &Document) -> GpuResult<Self> {
        let (places, sizes) = arena_layout(doc);
        let mut scene = Self {
            arenas: Vec::with_capacity(sizes.len()),
            objects: Vec::with_capacity(doc.objects.len()),
            groups: surface_groups(doc, &places),
            lod_view: None,
            map: None,
            scalars: None,
            scratch: Vec::new(),
            unfilled: Vec::with_capacity(sizes.len()),
            unmeasured: true,
            redraw: Redraw::default(),
            gesture: None,
            layer: None,
            unworthy: None,
            layer_always: false,
            drop_chunk: false,
            drop_lines: false,
            moved_controls: DirtySet::default(),
            local_displays: (0..doc.objects.len())
                .filter(|&i| is_local_display(&doc.objects[i].controls.layout))
                .collect(),
            controls_complete: doc.objects.is_empty(),
            masks: None,
            blocks: Vec::new(),
            layers_built: 0,
        };
        // On failure, give back what was created.
        match scene.fill(renderer, doc, &places, &sizes) {
            Ok(()) => Ok(scene),
            Err(e) => {
                scene.destroy(renderer);
                Err(e)
            }
        }
    }

    fn fill(
        &mut self,
        renderer: &mut Renderer,
        doc: &Document,
        places: &[Place],
        sizes: &[usize],
    ) -> GpuResult<()> {
        // Arenas are written by the first upload into each slot (`unfilled`), so a slot that
        // is never drawn (`render` draws one frame) is never touched, nor its pages resident.
        for (a, &len) in sizes.iter().enumerate() {
            self.arenas
                .push(renderer.create_mirror(&format!("samples {a}"), len.max(3))?);
            self.unfilled.push([true; FRAMES_IN_FLIGHT]);
        }
        for (i, o) in doc.objects.iter().enumerate() {
            self.objects.push(ObjectGpu {
                name: o.name.clone(),
                samples: places[i],
                dirty: Default::default(),
                controls: None,
                controls_dirty: Default::default(),
                controls_resized: false,
                grips: None,
                lod: None,
                metrics: None,
                bounds: None,
            });
        }
        Ok(())
    }

    /// Takes in what an apply changed: its sample rows and control vertices become dirty for
    /// every frame slot; a control display with a new layout replaces its mirror at the next
    /// upload. The report is all it reads: what the edits were does not matter here.
    pub fn consume(&mut self, applied: &Applied) {
        if let Some(layer) = &mut self.layer {
            let moved = |c: &crate::editor::ObjectChange| {
                c.object == layer.key.gesture.object
                    && c.samples
                        .iter()
                        .all(|r| layer.support.iter().any(|s| s.contains(r)))
            };
            // Controls drawn in the layer changed: a resize, or vertices it did not expect.
            let controls_moved = |c: &crate::editor::ObjectChange| match &c.controls {
                ControlsChange::Unchanged => true,
                ControlsChange::Vertices(set) => {
                    set.ranges().iter().all(|r| covers(&layer.moving, r))
                }
                ControlsChange::Resized => false,
            };
            // Samples drawn in the layer changed (an undo, another object, a structural edit).
            if applied.structure_changed()
                || !applied
                    .changes
                    .iter()
                    .all(|c| moved(c) && controls_moved(c))
            {
                layer.stale = true;
            }
        }
        if let Some(g) = self.gesture {
            for c in applied.changes.iter().filter(|c| c.object == g.object) {
                if let ControlsChange::Vertices(set) = &c.controls {
                    set.ranges()
                        .iter()
                        .for_each(|r| self.moved_controls.insert(r.clone()));
                }
            }
        }
        for c in &applied.changes {
            let o = &mut self.objects[c.object];
            for region in &c.samples {
                for d in &mut o.dirty {
                    d.insert(region.rows.clone());
                }
            }
            match &c.controls {
                ControlsChange::Unchanged => {}
                ControlsChange::Vertices(set) => {
                    for d in &mut o.controls_dirty {
                        set.ranges().iter().for_each(|r| d.insert(r.clone()));
                    }
                }
                ControlsChange::Resized => {
                    o.controls_resized = true;
                    o.grips = None;
                    o.controls_dirty = Default::default();
                }
            }
        }
    }

    /// Colours the surfaces by `map` from the next frame on (`None`: plain shading). A new
    /// curvature map or new scales compute the scalars at the next [`GpuScene::upload`] (they
    /// are stored on each surface's scale).
    pub fn set_map(&mut self, map: Option<MapView>) {
        self.map = map;
    }

    /// The map colouring the surfaces.
    #[must_use]
    pub fn map(&self) -> Option<&MapView> {
        self.map.as_ref()
    }

    /// Builds the scalar mirrors when the curvature map changed, drops them when none is
    /// shown; returns the bytes written.
    fn sync_scalars(&mut self, frame: &mut Frame<'_>, doc: &Document) -> GpuResult<usize> {
        let wanted = self.map.as_ref().filter(|m| m.map.needs_curvature());
        if self.scalars.as_ref().map(|s| &s.view) == wanted {
            return Ok(0);
        }
        if let Some(old) = self.scalars.take() {
            old.destroy_with(|m| frame.destroy_mirror(m));
        }
        let Some(view) = wanted else { return Ok(0) };
        let slots: Vec<Option<SurfaceSlot>> = (0..self.objects.len())
            .map(|i| {
                doc.objects[i].sampled.grid().normals.as_ref().map(|_| {
                    let p = self.objects[i].samples;
                    SurfaceSlot {
                        arena: p.arena,
                        offset: p.offset,
                    }
                })
            })
            .collect();
        let scalars = MapScalars::build(frame, doc, &slots, self.arenas.len(), view)?;
        let bytes = scalars.mirrors.iter().map(|m| m.len() * 4).sum::<usize>();
        self.scalars = Some(scalars);
        Ok(bytes * FRAMES_IN_FLIGHT)
    }

    /// Copies into this frame's slot exactly what changed since the slot was last written:
    /// whole sample rows of touched rectangles (surfaces), touched spans (curves), and the control
    /// structures of edited objects.
    pub fn upload(&mut self, frame: &mut Frame<'_>, doc: &Document) -> GpuResult<UploadStats> {
        let slot = frame.slot();
        let mut stats = UploadStats::default();
        stats.bytes += self.sync_scalars(frame, doc)?;
        stats.bytes += self.fill_arenas(frame, doc)?;
        for (i, o) in self.objects.iter_mut().enumerate() {
            let ranges = o.dirty[slot].take();
            if !ranges.is_empty() {
                // New samples may project differently: measure and choose the stride again,
                // except for the object a gesture moves (its level of detail is frozen
                // until the gesture ends).
                if self.gesture.is_none_or(|g| g.object != i) {
                    o.lod = None;
                    o.metrics = None;
                    self.unmeasured = true;
                }
                o.bounds = None;
                let cols = doc.objects[i].sampled.grid().dims[1];
                let per = floats_per_sample(doc, i);
                let mut w = frame.write_mirror(&mut self.arenas[o.samples.arena]);
                for r in &ranges {
                    stats.rows += r.len();
                    sample_floats(doc, i, r.clone(), &mut self.scratch);
                    w.write(o.samples.offset + r.start * cols * per, &self.scratch)?;
                    stats.bytes += self.scratch.len() * 4;
                }
                drop(w);
                // The map's scalars of the same rows (surfaces only).
                if let Some(scalars) = &mut self.scalars
                    && per == 6
                {
                    let place = SurfaceSlot {
                        arena: o.samples.arena,
                        offset: o.samples.offset,
                    };
                    for r in ranges {
                        stats.bytes +=
                            scalars.write_rows(frame, doc, i, place, r, &mut self.scratch)?;
                    }
                }
            }
            let vertices = &doc.objects[i].controls.vertices;
            let resized = std::mem::take(&mut o.controls_resized);
            if resized {
                // A conversion can turn a polygon into ERBS locals or back.
                if is_local_display(&doc.objects[i].controls.layout) {
                    self.local_displays.insert(i);
                } else {
                    self.local_displays.remove(&i);
                }
            }
            let ranges = o.controls_dirty[slot].take();
            // Without a mirror there is nothing to keep current: the first frame that draws
            // the display makes it from the vertices of that time.
            let Some(controls) = &mut o.controls else {
                continue;
            };
            if resized {
                let name = format!("{} controls", o.name);
                let data = vertex_floats(vertices);
                frame.replace_mirror(controls, &name, &data)?;
                stats.bytes += data.len() * 4 * FRAMES_IN_FLIGHT;
            }
            if !ranges.is_empty() {
                let mut w = frame.write_mirror(controls);
                for r in ranges {
                    let data = vertex_floats(&vertices[r.clone()]);
                    w.write(r.start * 3, &data)?;
                    stats.bytes += data.len() * 4;
                }
            }
        }
        Ok(stats)
    }

    /// Writes every object's samples into this frame's slot of each arena not yet written
    /// there (objects lie back to back, so that fills the arena), on every core: runs of
    /// consecutive objects each go to a disjoint range of the slot. Returns the bytes written.
    fn fill_arenas(&mut self, frame: &mut Frame<'_>, doc: &Document) -> GpuResult<usize> {
        let slot = frame.slot();
        let mut bytes = 0;
        for (a, unfilled) in self.unfilled.iter_mut().enumerate() {
            if !std::mem::take(&mut unfilled[slot]) {
                continue;
            }
            // (object, float offset, floats) of the arena's objects, in order of offset.
            let mut members: Vec<(usize, usize, usize)> = (0..self.objects.len())
                .filter(|&i| self.objects[i].samples.arena == a)
                .map(|i| {
                    let [rows, cols] = doc.objects[i].sampled.grid().dims;
                    let floats = rows * cols * floats_per_sample(doc, i);
                    (i, self.objects[i].samples.offset, floats)
                })
                .collect();
            members.sort_by_key(|m| m.1);
            let runs = fill_runs(&members, crate::parallel::threads());
            let ranges: Vec<std::ops::Range<usize>> = runs
                .iter()
                .map(|r| {
                    let (first, last) = (members[r.start], members[r.end - 1]);
                    first.1..last.1 + last.2
                })
                .collect();
            bytes += ranges.iter().map(|r| r.len() * 4).sum::<usize>();
            let mut w = frame.write_mirror(&mut self.arenas[a]);
            let mut jobs: Vec<_> = w
                .split(&ranges)?
                .into_iter()
                .zip(&runs)
                .map(|(writer, run)| (writer, &members[run.clone()], Ok(())))
                .collect();
            crate::parallel::for_each_mut(&mut jobs, |(writer, run, result)| {
                let mut scratch = Vec::new();
                *result = run.iter().try_for_each(|&(i, offset, _)| {
                    let rows = doc.objects[i].sampled.grid().dims[0];
                    sample_floats(doc, i, 0..rows, &mut scratch);
                    writer.write(offset, &scratch)
                });
            });
            jobs.into_iter().try_for_each(|(_, _, result)| result)?;
        }
        Ok(bytes)
    }

    /// How gestures redraw (`--redraw`); `Full` drops any static layer.
    pub fn set_redraw(&mut self, redraw: Redraw) {
        self.redraw = redraw;
        if redraw == Redraw::Full {
            self.layer = None;
        }
    }

    /// How gestures redraw.
    #[must_use]
    pub fn redraw(&self) -> Redraw {
        self.redraw
    }

    /// The gesture in progress (`None`: none). Its object's level of detail stays as it is
    /// until the gesture ends, then is chosen again; a new gesture builds a new static layer.
    pub fn set_gesture(&mut self, gesture: Option<Gesture>) {
        if self.gesture == gesture {
            return;
        }
        if let Some(o) = self.gesture.and_then(|g| self.objects.get_mut(g.object)) {
            o.lod = None;
            o.metrics = None;
            self.unmeasured = true;
        }
        self.gesture = gesture;
        self.layer = None;
        self.moved_controls = DirtySet::default();
    }

    /// Test hook, a negative control: the dynamic set of the next static layers misses one
    /// chunk, whose old pixels then stay in the layer.
    #[doc(hidden)]
    pub fn set_drop_chunk(&mut self, drop: bool) {
        self.drop_chunk = drop;
        self.layer = None;
    }

    /// Test hook: every gesture builds a static layer, whether it pays or not (see
    /// [`worth_a_layer`]), so exactness tests reach the retained path on small scenes.
    #[doc(hidden)]
    pub fn set_layer_always(&mut self, always: bool) {
        self.layer_always = always;
        self.unworthy = None;
    }

    /// Test hook, a negative control: retained frames leave the lines through moved control
    /// points out of the rectangle they redraw, so their old pixels stay in the layer.
    #[doc(hidden)]
    pub fn set_drop_lines(&mut self, drop: bool) {
        self.drop_lines = drop;
        self.layer = None;
    }

    /// Records the draws of every object. Each surface is drawn at the stride `lod` picks for
    /// it (strided index buffers over the full-resolution mirrors; choosing a stride copies
    /// nothing); surfaces of one group sharing a stride are one multi-draw. During a gesture
    /// with [`Redraw::Retained`] the surfaces come from the static layer where it is valid
    /// (see [`super::retained`]).
    pub fn draw(
        &mut self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
        lod: &Lod,
    ) -> GpuResult<DrawReport> {
        let mut report = DrawReport::default();
        self.make_masks(frame, doc)?;
        self.make_controls(frame, doc, opts, hl)?;
        if self.lod_view != Some(*lod) {
            self.lod_view = Some(*lod);
            self.objects.iter_mut().for_each(|o| {
                o.lod = None;
                o.grips = None;
            });
        }
        self.measure_grips(frame, doc, opts, hl);
        let order = self.surface_order(doc, opts, lod);
        for b in &order {
            let shape = self.groups[b.group].shape;
            let n = b.members.len() as u64;
            report.triangles += 2 * b.stride.cells(shape) * n;
            report.full_triangles += 2 * GridStride::FULL.cells(shape) * n;
        }
        let before = frame.stats().surface_triangles;
        let layers_before = self.layers_built;
        let retained = self.draw_retained(frame, doc, opts, hl, &order, report.triangles)?;
        report.layer_built = self.layers_built > layers_before;
        if retained {
            report.retained = true;
            report.retained_of = report.triangles;
            report.triangles = frame.stats().surface_triangles - before;
        } else {
            for b in &order {
                self.draw_batch(frame, doc, opts, b, &b.members)?;
            }
            self.draw_lines(frame, doc, opts, hl, &|_| true, None)?;
        }
        Ok(report)
    }

    /// Makes the coverage masks of the trimmed surfaces, once: trims never move in parameter
    /// space, so a mask outlives every edit.
    fn make_masks(&mut self, frame: &mut Frame<'_>, doc: &Document) -> GpuResult<()> {
        if self.masks.is_some() || self.groups.iter().all(|g| g.mask.is_none()) {
            return Ok(());
        }
        let mut masked: Vec<(usize, Vec<u32>)> = Vec::new();
        let mut blocks = Vec::new();
        for g in self.groups.iter().filter(|g| g.mask.is_some()) {
            let i = g.members[0];
            let Some(trim) = doc.objects[i].trim.as_ref() else {
                continue;
            };
            let (words, b) = mask_parts(&trim.coverage, trim.refine);
            masked.push((i, words));
            blocks.push(b);
        }
        let words: Vec<MaskWords<'_>> = masked
            .iter()
            .map(|(i, w)| {
                let cols = doc.objects[*i].sampled.grid().dims[1] as u32;
                let first =
                    (self.objects[*i].samples.offset / SurfaceGrid::FLOATS_PER_VERTEX) as u32;
                MaskWords {
                    words: w,
                    entries: vec![mask_entry(cols, first)],
                }
            })
            .collect();
        self.masks = Some(frame.create_mask_set(&words)?);
        self.blocks = blocks;
        Ok(())
    }

    /// The blocks of group `g`'s trim at `stride`: what its draws cut by class.
    fn group_blocks(&self, g: usize, stride: GridStride) -> Option<&BlockRanges> {
        let mask = self.groups[g].mask?;
        self.blocks
            .get(mask as usize)?
            .at([stride.rows, stride.cols])
    }

    /// The coverage mask group `g` is drawn through.
    fn group_mask(&self, g: usize) -> Option<MaskRef<'_>> {
        let mask = self.groups[g].mask?;
        Some(self.masks.as_ref()?.entry(mask))
    }

    /// Makes the control mirrors a frame drawn with `opts` and `hl` needs and does not have
    /// yet, from the vertices of now (in every slot, so nothing of them is dirty). Returns the
    /// bytes written. [`GpuScene::draw`] calls it; a caller that reports upload figures calls
    /// it after [`GpuScene::upload`] so they include these bytes.
    pub fn make_controls(
        &mut self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
    ) -> GpuResult<usize> {
        if self.controls_complete {
            return Ok(0);
        }
        // Only these can be drawn: every object's display where the nets are all shown;
        // otherwise the focused objects' and, where local curves are shown, ERBS objects'.
        // An object met twice already has its mirror the second time.
        let all = opts.control_nets == NetMode::All;
        let focused = [
            hl.hovered.map(|h| h.object()),
            hl.selected.map(|h| h.object()),
            hl.selected_local.map(|(o, _)| o),
            hl.hovered_object,
        ];
        let locals = opts.local_curves.then_some(&self.local_displays);
        let candidates: Box<dyn Iterator<Item = usize>> = if all {
            Box::new(0..self.objects.len())
        } else {
            Box::new(
                focused
                    .into_iter()
                    .flatten()
                    .chain(locals.into_iter().flatten().copied()),
            )
        };
        let mut bytes = 0;
        for i in candidates {
            let Some(o) = self.objects.get_mut(i) else {
                continue;
            };
            let controls = &doc.objects[i].controls;
            if o.controls.is_some() || !control_drawn(opts, hl, i, &controls.layout) {
                continue;
            }
            let data = vertex_floats(&controls.vertices);
            o.controls = Some(frame.create_mirror(&format!("{} controls", o.name), &data)?);
            o.controls_dirty = Default::default();
            o.controls_resized = false;
            bytes += data.len() * 4 * FRAMES_IN_FLIGHT;
        }
        if all {
            self.controls_complete = self.objects.iter().all(|o| o.controls.is_some());
        }
        Ok(bytes)
    }

    /// The curves' samples and every object's control display (of the objects `only`
    /// admits), in document order.
    fn draw_lines(
        &self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
        only: &dyn Fn(usize) -> bool,
        clip: Option<&NetClip>,
    ) -> GpuResult<()> {
        let palette = Palette::default();
        for (i, o) in self.objects.iter().enumerate().filter(|(i, _)| only(*i)) {
            let grid = doc.objects[i].sampled.grid();
            if grid.normals.is_none() && grid.dims[0] >= 2 {
                let color = palette.object(i, doc.objects[i].color);
                let style = PolylineStyle {
                    color,
                    width: opts.curve_width,
                    depth_test: true,
                };
                let sampled = &doc.objects[i].sampled;
                for piece in curve_pieces(sampled.model(), sampled.params()[0]) {
                    let run = PointRun {
                        offset: o.samples.offset + 3 * piece.samples.start,
                        stride: 3,
                        count: piece.samples.len(),
                    };
                    polyline(frame, &self.arenas[o.samples.arena], run, &style)?;
                    piece_ends(frame, grid, &piece, &style)?;
                }
            }
            let controls = &doc.objects[i].controls;
            // No mirror: nothing of the display is drawn (`make_controls` made every other).
            let Some(mirror) = &o.controls else {
                continue;
            };
            if let (Some(c), ControlLayout::Net { rows, cols }) = (clip, &controls.layout)
                && c.object == i
                && net_shown(opts, hl, i)
            {
                clipped_net(
                    frame,
                    mirror,
                    &controls.vertices,
                    ([*rows, *cols], o.grips.unwrap_or(1)),
                    opts,
                    hl,
                    c,
                )?;
                continue;
            }
            ControlPass::new(i, mirror, opts, hl, &palette)
                .with_grips(o.grips.unwrap_or(1))
                .draw(frame, &controls.layout)?;
        }
        Ok(())
    }

    /// Chooses how densely the shown control nets and polygons draw their grips for this view,
    /// where not chosen since the view changed.
    fn measure_grips(
        &mut self,
        frame: &Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
    ) {
        let (camera, viewport) = (frame.camera(), frame.viewport());
        // Every frame calls this: with focused nets only the few focused objects are looked
        // at, not every object of a large scene.
        let focused = [
            hl.hovered.map(|h| h.object()),
            hl.selected.map(|h| h.object()),
            hl.selected_local.map(|(o, _)| o),
            hl.hovered_object,
        ];
        let candidates: Box<dyn Iterator<Item = usize>> = match opts.control_nets {
            NetMode::Off => return,
            NetMode::All => Box::new(0..self.objects.len()),
            NetMode::Focused => Box::new(focused.into_iter().flatten()),
        };
        for i in candidates {
            let Some(o) = self.objects.get_mut(i) else {
                continue;
            };
            if o.grips.is_some() || !net_shown(opts, hl, i) {
                continue;
            }
            let controls = &doc.objects[i].controls;
            let shape = match controls.layout {
                ControlLayout::Net { rows, cols } => [rows, cols],
                ControlLayout::Polygon { count } => [1, count],
                _ => continue,
            };
            o.grips = Some(grip_every(
                &controls.vertices,
                shape,
                &camera,
                viewport,
                opts.point_size,
            ));
        }
    }

    /// The surfaces in draw order: per group, per stride (ascending), the members sharing it.
    fn surface_order(&mut self, doc: &Document, opts: &ViewOptions, lod: &Lod) -> Vec<Batch> {
        if opts.lod {
            self.measure_grids(doc);
        }
        let mut order = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            let mut by_stride: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
            // Trimmed faces meet other faces at seams: a quarter of the deviation (Lod).
            let factor = if group.mask.is_some() { 0.25 } else { 1.0 };
            for &i in &group.members {
                let o = &mut self.objects[i];
                let stride = if opts.lod {
                    let grid = doc.objects[i].sampled.grid();
                    let metrics = o.metrics.get_or_insert_with(|| GridMetrics::new(grid));
                    *o.lod
                        .get_or_insert_with(|| lod.stride_within(metrics.as_ref(), factor))
                } else {
                    GridStride::FULL
                };
                by_stride
                    .entry((stride.rows, stride.cols))
                    .or_default()
                    .push(i);
            }
            for ((rows, cols), members) in by_stride {
                order.push(Batch {
                    group: g,
                    stride: GridStride { rows, cols },
                    members,
                });
            }
        }
        order
    }

    /// Measures every surface not measured since its samples last changed, on every core:
    /// after a load that is one pass over all the samples of the scene.
    fn measure_grids(&mut self, doc: &Document) {
        // Most frames change no samples: skip the pass over every object then.
        if !std::mem::take(&mut self.unmeasured) {
            return;
        }
        let stale: Vec<usize> = self
            .groups
            .iter()
            .flat_map(|g| g.members.iter().copied())
            .filter(|&i| self.objects[i].metrics.is_none())
            .collect();
        let measured =
            crate::parallel::map(&stale, |&i| GridMetrics::new(doc.objects[i].sampled.grid()));
        for (i, m) in stale.into_iter().zip(measured) {
            self.objects[i].metrics = Some(m);
        }
    }

    /// The surfaces `members` of batch `b` (shaded or mapped, then their isolines).
    fn draw_batch(
        &self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        b: &Batch,
        members: &[usize],
    ) -> GpuResult<()> {
        if members.is_empty() {
            return Ok(());
        }
        let palette = Palette::default();
        let group = &self.groups[b.group];
        let offsets: Vec<usize> = members
            .iter()
            .map(|&i| self.objects[i].samples.offset)
            .collect();
        let batch = SurfaceBatch {
            shape: group.shape,
            stride: b.stride,
            offsets: &offsets,
            mask: self.group_mask(b.group),
        };
        self.draw_surfaces(
            frame,
            group.arena,
            &batch,
            None,
            self.group_blocks(b.group, b.stride),
            &self.group_style(doc, b.group),
        )?;
        let every = match opts.wire {
            Wire::Off => return Ok(()),
            Wire::Isolines(every) => every.max(1),
            Wire::Full => 1,
        };
        frame.draw_wire_batch(&self.arenas[group.arena], &batch, every, palette.wire)
    }

    /// Cell ranges of surface `i` of batch `b` (no isolines: retained redraw needs them off).
    fn draw_cells(
        &self,
        frame: &mut Frame<'_>,
        doc: &Document,
        b: &Batch,
        i: usize,
        cells: &[(u32, u32)],
    ) -> GpuResult<()> {
        if cells.is_empty() {
            return Ok(());
        }
        let group = &self.groups[b.group];
        let offsets = [self.objects[i].samples.offset];
        let batch = SurfaceBatch {
            shape: group.shape,
            stride: b.stride,
            offsets: &offsets,
            mask: self.group_mask(b.group),
        };
        let style = self.group_style(doc, b.group);
        let blocks = self.group_blocks(b.group, b.stride);
        self.draw_surfaces(frame, group.arena, &batch, Some(cells), blocks, &style)
    }

    fn group_style(&self, doc: &Document, g: usize) -> SurfaceStyle {
        let palette = Palette::default();
        let color = palette.surface(doc.objects[self.groups[g].members[0]].color);
        SurfaceStyle {
            front: color,
            back: palette.back_of(color),
            ..SurfaceStyle::default()
        }
    }

    /// Draws the frame's surfaces and lines from the static layer when a gesture allows it:
    /// restores a valid layer or builds one, then draws the dynamic set. `false`: nothing was
    /// drawn, draw everything (no gesture, `--redraw full`, isolines on, or a target without
    /// a layer). `triangles`: the surface triangles of a full redraw of `order`.
    #[allow(clippy::too_many_arguments)]
    fn draw_retained(
        &mut self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
        order: &[Batch],
        triangles: u64,
    ) -> GpuResult<bool> {
        let Some(g) = self.gesture.filter(|_| self.redraw == Redraw::Retained) else {
            self.layer = None;
            return Ok(false);
        };
        if opts.wire != Wire::Off || g.object >= self.objects.len() || !frame.has_static_layer() {
            self.layer = None;
            return Ok(false);
        }
        let place = order.iter().enumerate().find_map(|(bi, b)| {
            let m = b.members.iter().position(|&i| i == g.object)?;
            Some((bi, m))
        });
        let key = LayerKey {
            camera: frame.camera(),
            clear: frame.clear_color(),
            viewport: frame.viewport(),
            extent: frame.extent(),
            opts: *opts,
            lod: self.lod_view,
            map: self.map.clone(),
            scalars: self.scalars.is_some(),
            objects: self.objects.len(),
            gesture: g,
            highlight: *hl,
            stride: place.map(|(bi, _)| order[bi].stride),
        };
        let valid = self
            .layer
            .as_ref()
            .is_some_and(|l| !l.stale && l.key == key);
        let restored = match &self.layer {
            // Depth only inside the redrawn rectangle (restored with the surfaces' save
            // there): every depth-tested draw of a retained frame stays inside it.
            Some(l) if valid => {
                frame.restore_static_layer(LayerPart::Lines, l.lines, None, Restore::Color)?
            }
            _ => false,
        };
        if !restored {
            self.layer = None;
            if self.unworthy.as_ref() == Some(&key) {
                return Ok(false);
            }
            let support = doc.objects[g.object].sampled.support(g.target);
            let cells = place.map(|(bi, _)| {
                let shape = self.groups[order[bi].group].shape;
                split_cells(shape, order[bi].stride, &support, self.drop_chunk)
            });
            let [w, h] = key.extent.map(u64::from);
            let trimmed = order.iter().any(|b| self.groups[b.group].mask.is_some());
            if !self.layer_always && !worth_a_layer(cells.as_ref(), triangles, w * h, trimmed) {
                self.unworthy = Some(key);
                return Ok(false);
            }
            self.unworthy = None;
            frame.keep_depth();
            self.build_layer(frame, doc, opts, hl, order, place, key, (support, cells))?;
            self.layers_built += 1;
            if self.layer.is_none() {
                return Ok(true);
            }
        }
        self.draw_dynamic(frame, doc, opts, hl, order, place)?;
        Ok(true)
    }

    /// Draws everything but the dynamic chunks in full order, saving the surfaces and then
    /// the surfaces with the lines as the static layer, and notes what later frames need.
    #[allow(clippy::too_many_arguments)]
    fn build_layer(
        &mut self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
        order: &[Batch],
        place: Option<(usize, usize)>,
        key: LayerKey,
        (support, cells): (Vec<DirtyRegion>, Option<SplitCells>),
    ) -> GpuResult<()> {
        let g = key.gesture;
        for (bi, b) in order.iter().enumerate() {
            match (place, &cells) {
                (Some((pb, m)), Some(c)) if pb == bi => {
                    self.draw_batch(frame, doc, opts, b, &b.members[..m])?;
                    self.draw_cells(frame, doc, b, g.object, &c.fixed)?;
                    self.draw_batch(frame, doc, opts, b, &b.members[m + 1..])?;
                }
                _ => self.draw_batch(frame, doc, opts, b, &b.members)?,
            }
        }
        let Some(surfaces) = frame.save_static_layer(LayerPart::Surfaces)? else {
            // The target lost its layer: finish this frame without one.
            if let (Some((pb, _)), Some(c)) = (place, &cells) {
                self.draw_cells(frame, doc, &order[pb], g.object, &c.dynamic)?;
            }
            return self.draw_lines(frame, doc, opts, hl, &|_| true, None);
        };
        self.draw_lines(frame, doc, opts, hl, &|_| true, None)?;
        // Saves need the same as the first one did: this one cannot fail where it succeeded.
        let lines = frame
            .save_static_layer(LayerPart::Lines)?
            .ok_or_else(|| GpuError::InvalidArgument("static layer lost between saves".into()))?;
        let (camera, viewport) = (frame.camera(), frame.viewport());
        let mut later = Vec::new();
        if let Some((pb, m)) = place {
            let after = order[pb].members[m + 1..]
                .iter()
                .chain(order[pb + 1..].iter().flat_map(|b| &b.members));
            for &i in after {
                if let Some(b) = self.sample_bounds_of(doc, i) {
                    later.push((i, screen_rect(&camera, b, viewport)));
                }
            }
        }
        let controls = &doc.objects[g.object].controls;
        let mut moving = moving_vertices(&controls.layout, g.target);
        for r in self.moved_controls.ranges() {
            moving.insert(r.clone());
        }
        let touched = touched_vertices(&controls.layout, &moving);
        let line_rects = (0..self.objects.len())
            .map(|i| {
                let curve = (doc.objects[i].sampled.grid().normals.is_none())
                    .then(|| self.sample_bounds_of(doc, i))
                    .flatten();
                let all = DirtySet::all(doc.objects[i].controls.vertices.len());
                let b = join_bounds(
                    vertex_bounds(&doc.objects[i].controls.vertices, &all),
                    curve,
                );
                b.map(|b| screen_rect_with(&camera, b, viewport, line_margin(opts)))
            })
            .collect();
        let mut layer = Layer {
            key,
            surfaces,
            lines,
            support,
            moving,
            touched,
            lines_then: [0; 4],
            line_rects,
            cells,
            later,
            stale: false,
        };
        layer.lines_then = moving_rect(doc, &layer, &camera, viewport, opts);
        self.layer = Some(layer);
        Ok(())
    }

    /// World-space bounds of object `i`'s samples, measured once per change of them.
    fn sample_bounds_of(&mut self, doc: &Document, i: usize) -> Option<[DVec3; 2]> {
        *self.objects[i]
            .bounds
            .get_or_insert_with(|| sample_bounds(doc.objects[i].sampled.grid(), None))
    }

    /// Inside the rectangle R of what moves (the dynamic chunks, and the lines and points
    /// through moving control points as drawn now and as the layer holds them), the frame
    /// is drawn again from the static surfaces: the dynamic chunks, then, clipped to their
    /// screen rectangle, the surfaces after them in draw order that reach it (so ties in
    /// depth go as in a full redraw), then every line and point that reaches R in full
    /// order, clipped to R. Outside R the layer of surfaces and lines is the full redraw.
    fn draw_dynamic(
        &self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        hl: &Highlight,
        order: &[Batch],
        place: Option<(usize, usize)>,
    ) -> GpuResult<()> {
        let Some(layer) = &self.layer else {
            return Ok(());
        };
        let g = layer.key.gesture;
        let (camera, viewport) = (frame.camera(), frame.viewport());
        let chunks = match (place, &layer.cells) {
            (Some(_), Some(cells)) => {
                let grid = doc.objects[g.object].sampled.grid();
                sample_bounds(grid, Some(&cells.chunks))
                    .map_or([0; 4], |b| screen_rect(&camera, b, viewport))
            }
            _ => [0; 4],
        };
        let lines = if self.drop_lines {
            [0; 4]
        } else {
            union_rect(
                layer.lines_then,
                moving_rect(doc, layer, &camera, viewport, opts),
            )
        };
        let r = union_rect(chunks, lines);
        if r[2] == 0 || r[3] == 0 {
            return Ok(());
        }
        let what = Restore::ColorAndDepth;
        if !frame.restore_static_layer(LayerPart::Surfaces, layer.surfaces, Some(r), what)? {
            return Err(GpuError::InvalidArgument(
                "static layer lost within a frame".into(),
            ));
        }
        if let (Some((pb, _)), Some(cells)) = (place, &layer.cells) {
            self.draw_cells(frame, doc, &order[pb], g.object, &cells.dynamic)?;
            self.draw_later(frame, doc, opts, order, chunks)?;
        }
        frame.set_scissor(Some(r));
        let reaches =
            |i: usize| i == g.object || layer.line_rects[i].is_some_and(|lr| overlaps(lr, r));
        let clip = NetClip {
            object: g.object,
            rect: r,
            camera,
            viewport,
        };
        self.draw_lines(frame, doc, opts, hl, &reaches, Some(&clip))?;
        frame.set_scissor(None);
        Ok(())
    }

    /// Clipped to `rect`, the surfaces after the dragged one in draw order that reach it.
    fn draw_later(
        &self,
        frame: &mut Frame<'_>,
        doc: &Document,
        opts: &ViewOptions,
        order: &[Batch],
        rect: [u32; 4],
    ) -> GpuResult<()> {
        let Some(layer) = &self.layer else {
            return Ok(());
        };
        if rect[2] == 0 || rect[3] == 0 {
            return Ok(());
        }
        let reached: Vec<usize> = layer
            .later
            .iter()
            .filter(|(_, r)| overlaps(*r, rect))
            .map(|&(i, _)| i)
            .collect();
        if reached.is_empty() {
            return Ok(());
        }
        frame.set_scissor(Some(rect));
        for b in order {
            let members: Vec<usize> = b
                .members
                .iter()
                .copied()
                .filter(|i| reached.contains(i))
                .collect();
            self.draw_batch(frame, doc, opts, b, &members)?;
        }
        frame.set_scissor(None);
        Ok(())
    }

    /// A batch of surfaces (with `cells`, those cells of its one surface), shaded or coloured
    /// by the map. A trimmed surface (`blocks`, its blocks at the batch's stride) draws its
    /// blocks wholly inside the trim as an untrimmed surface and only the boundary blocks
    /// through its mask.
    fn draw_surfaces(
        &self,
        frame: &mut Frame<'_>,
        arena: usize,
        batch: &SurfaceBatch,
        cells: Option<&[(u32, u32)]>,
        blocks: Option<&BlockRanges>,
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        let Some(blocks) = blocks else {
            return self.draw_surfaces_as(frame, arena, batch, cells, style);
        };
        let [inside, mixed] = blocks.split(cells);
        let whole = SurfaceBatch {
            mask: None,
            ..*batch
        };
        for (batch, cells) in [(&whole, inside), (batch, mixed)] {
            if !cells.is_empty() {
                self.draw_surfaces_as(frame, arena, batch, Some(&cells), style)?;
            }
        }
        Ok(())
    }

    /// [`GpuScene::draw_surfaces`] through the batch's own pipeline. Until the first upload
    /// after a map change has built its scalars, curvature maps draw plain shading.
    fn draw_surfaces_as(
        &self,
        frame: &mut Frame<'_>,
        arena: usize,
        batch: &SurfaceBatch,
        cells: Option<&[(u32, u32)]>,
        style: &SurfaceStyle,
    ) -> GpuResult<()> {
        let mirror = &self.arenas[arena];
        let plain = |frame: &mut Frame<'_>| match cells {
            Some(c) => frame.draw_surface_cells(mirror, batch, c, style),
            None => frame.draw_surface_batch(mirror, batch, style),
        };
        let mapped = |frame: &mut Frame<'_>, scalars: Option<&Mirror>, map| match cells {
            Some(c) => frame.draw_surface_map_cells(mirror, scalars, batch, c, map),
            None => frame.draw_surface_map_batch(mirror, scalars, batch, map),
        };
        let Some(view) = &self.map else {
            return plain(frame);
        };
        if !view.map.needs_curvature() {
            let zebra = MapStyle::Zebra {
                stripes: ZEBRA_STRIPES,
            };
            return mapped(frame, None, zebra);
        }
        match &self.scalars {
            // The scalars are on each surface's scale already (−1 … 1).
            Some(s) if s.view.map == view.map => {
                let scale = MapStyle::Scale { range: 1.0 };
                mapped(frame, Some(&s.mirrors[arena]), scale)
            }
            _ => plain(frame),
        }
    }

    /// Gives every mirror back to the renderer.
    pub fn destroy(self, renderer: &mut Renderer) {
        if let Some(s) = self.scalars {
            s.destroy_with(|m| renderer.destroy_mirror(m));
        }
        for a in self.arenas {
            renderer.destroy_mirror(a);
        }
        for m in self.objects.into_iter().filter_map(|o| o.controls) {
            renderer.destroy_mirror(m);
        }
        if let Some(m) = self.masks {
            m.destroy_with(|b| renderer.destroy_mirror(b));
        }
    }
}

/// The box holding both.
fn join_bounds(a: Option<[DVec3; 2]>, b: Option<[DVec3; 2]>) -> Option<[DVec3; 2]> {
    match (a, b) {
        (Some([l0, h0]), Some([l1, h1])) => Some([l0.min(l1), h0.max(h1)]),
        (x, None) | (None, x) => x,
    }
}

/// Screen rectangle of the lines and points of `layer`'s gesture that move, as the document
/// holds them now: those through its moving control points, and for a curve the sample
/// polyline's segments through its support.
fn moving_rect(
    doc: &Document,
    layer: &Layer,
    camera: &crate::gpu::Camera,
    viewport: [u32; 4],
    opts: &ViewOptions,
) -> [u32; 4] {
    let object = &doc.objects[layer.key.gesture.object];
    let controls = vertex_bounds(&object.controls.vertices, &layer.touched);
    let grid = object.sampled.grid();
    let curve = if grid.normals.is_none() {
        let spans: Vec<[std::ops::Range<usize>; 2]> = layer
            .support
            .iter()
            .filter(|r| !r.is_empty())
            .map(|r| {
                [
                    r.rows.start.saturating_sub(1)..r.rows.end + 1,
                    0..grid.dims[1],
                ]
            })
            .collect();
        sample_bounds(grid, Some(&spans))
    } else {
        None
    };
    join_bounds(controls, curve).map_or([0; 4], |b| {
        screen_rect_with(camera, b, viewport, line_margin(opts))
    })
}

/// Floats per sample on the GPU: position and normal for surfaces, position for curves.
fn floats_per_sample(doc: &Document, i: usize) -> usize {
    if doc.objects[i].sampled.grid().normals.is_some() {
        6
    } else {
        3
    }
}

/// Where every object's samples go, and the length of each arena: surfaces first in document
/// order (so same-shaped neighbours are contiguous), then curves. An arena is closed when the
/// next object would take it past `ARENA_FLOATS`.
fn arena_layout(doc: &Document) -> (Vec<Place>, Vec<usize>) {
    let n = doc.objects.len();
    let mut places = vec![
        Place {
            arena: 0,
            offset: 0
        };
        n
    ];
    let mut sizes = vec![0usize];
    let is_surface = |i: &usize| doc.objects[*i].sampled.grid().normals.is_some();
    let surfaces = (0..n).filter(is_surface);
    let curves = (0..n).filter(|i| !is_surface(i));
    for i in surfaces.chain(curves) {
        let [rows, cols] = doc.objects[i].sampled.grid().dims;
        let len = rows * cols * floats_per_sample(doc, i);
        let last = sizes.len() - 1;
        if sizes[last] > 0 && sizes[last] + len > ARENA_FLOATS {
            sizes.push(0);
        }
        let arena = sizes.len() - 1;
        places[i] = Place {
            arena,
            offset: sizes[arena],
        };
        sizes[arena] += len;
    }
    (places, sizes)
}

/// Whether a static layer pays for a gesture whose dragged surface splits into `cells`
/// (`None`: the gesture moves a curve, and every surface stays in the layer) in a frame of
/// `all` surface triangles on a target of `pixels`. Restoring the layer copies every pixel each frame (about 0.7 ms at 1280 × 720 on
/// lavapipe, as much as drawing a few thousand surface triangles: docs/performance.md), so
/// what stays in it must be a surface triangle per [`PIXELS_PER_KEPT_TRIANGLE`] pixels at
/// least, and a quarter of the frame's triangles. Otherwise the frame is drawn in full: a
/// scene of curves only, or an ERBS local patch whose support is the whole surface. With
/// `trimmed` surfaces in the frame triangles do not measure the cost: a trimmed face's
/// fragments test its mask (and discard, so depth is tested late), and a CAD plane of two
/// triangles can fill the screen (a 160-face assembly: 32 ms a frame in full), so there the
/// quarter alone decides.
fn worth_a_layer(cells: Option<&SplitCells>, all: u64, pixels: u64, trimmed: bool) -> bool {
    let dynamic: u64 = cells.map_or(0, |c| {
        c.dynamic.iter().map(|&(_, n)| u64::from(n) / 3).sum()
    });
    let kept = all.saturating_sub(dynamic);
    (trimmed || kept * PIXELS_PER_KEPT_TRIANGLE >= pixels) && 4 * dynamic < 3 * all
}

/// A static layer must keep a surface triangle per this many pixels of its target to pay for
/// its copy (see [`worth_a_layer`]): 3,600 triangles at 1280 × 720.
const PIXELS_PER_KEPT_TRIANGLE: u64 = 256;

/// Runs of consecutive `members` (object, offset, floats) for a parallel fill: about four
/// per thread of similar float counts, so a thread that finishes early takes another.
fn fill_runs(members: &[(usize, usize, usize)], threads: usize) -> Vec<std::ops::Range<usize>> {
    let total: usize = members.iter().map(|m| m.2).sum();
    let per = total.div_ceil((threads.max(1) * 4).max(1)).max(1);
    let mut runs = Vec::new();
    let (mut start, mut floats) = (0, 0);
    for (k, m) in members.iter().enumerate() {
        floats += m.2;
        if floats >= per {
            runs.push(start..k + 1);
            (start, floats) = (k + 1, 0);
        }
    }
    if start < members.len() {
        runs.push(start..members.len());
    }
    runs
}

/// Surfaces grouped by arena, grid shape and colour (in order of first appearance).
fn surface_groups(doc: &Document, places: &[Place]) -> Vec<SurfaceGroup> {
    let mut groups: Vec<SurfaceGroup> = Vec::new();
    let mut masks = 0;
    for (i, o) in doc.objects.iter().enumerate() {
        let grid = o.sampled.grid();
        if grid.normals.is_none() {
            continue;
        }
        let shape = GridShape {
            rows: grid.dims[0] as u32,
            cols: grid.dims[1] as u32,
        };
        let arena = places[i].arena;
        if o.trim.is_some() {
            groups.push(SurfaceGroup {
                members: vec![i],
                shape,
                arena,
                mask: Some(masks),
            });
            masks += 1;
            continue;
        }
        let same = |g: &&mut SurfaceGroup| {
            g.mask.is_none()
                && g.shape == shape
                && g.arena == arena
                && doc.objects[g.members[0]].color == o.color
        };
        match groups.iter_mut().find(same) {
            Some(g) => g.members.push(i),
            None => groups.push(SurfaceGroup {
                members: vec![i],
                shape,
                arena,
                mask: None,
            }),
        }
    }
    groups
}

/// The segments from a curve piece's end points that no sample reaches (the one-sided limits
/// at a gap) to its first and last samples, or between them when it has no sample.
fn piece_ends(
    frame: &mut Frame<'_>,
    grid: &crate::sampling::SampleGrid,
    piece: &CurvePiece,
    style: &PolylineStyle,
) -> GpuResult<()> {
    // The samples as the mirror holds them (f32 of the f64), so each segment meets its run.
    let f = |p: DVec3| [p.x as f32, p.y as f32, p.z as f32];
    let sample = |j: usize| f(grid.data[j * grid.stride()]);
    let first = piece.start.map(f);
    let last = piece.end.map(f);
    let samples = &piece.samples;
    let segments: [Option<[[f32; 3]; 2]>; 2] = if samples.is_empty() {
        [first.zip(last).map(|(a, b)| [a, b]), None]
    } else {
        [
            first.map(|a| [a, sample(samples.start)]),
            last.map(|b| [sample(samples.end - 1), b]),
        ]
    };
    for segment in segments.into_iter().flatten() {
        frame.draw_polyline_immediate(&segment, style)?;
    }
    Ok(())
}

/// f32 vertices of sample rows `rows` of object `i`: (position, normal) for surfaces, position
/// for curves — the only place canonical f64 samples become GPU data.
fn sample_floats(doc: &Document, i: usize, rows: std::ops::Range<usize>, out: &mut Vec<f32>) {
    let grid = doc.objects[i].sampled.grid();
    let [_, cols] = grid.dims;
    let stride = grid.stride();
    out.clear();
    match &grid.normals {
        Some(n) => {
            out.reserve(rows.len() * cols * 6);
            for idx in rows.start * cols..rows.end * cols {
                let p = grid.data[idx * stride];
                let q = n[idx];
                out.extend_from_slice(&[
                    p.x as f32, p.y as f32, p.z as f32, q.x as f32, q.y as f32, q.z as f32,
                ]);
            }
        }
        None => {
            out.reserve(rows.len() * 3);
            for j in rows {
                let p = grid.data[j * stride];
                out.extend_from_slice(&[p.x as f32, p.y as f32, p.z as f32]);
            }
        }
    }
}

/// Display vertices as the f32 triples of a control mirror.
fn vertex_floats(vertices: &[DVec3]) -> Vec<f32> {
    vertices
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{SplitCells, fill_runs, worth_a_layer};

    /// Split cells whose dynamic part is `triangles` triangles.
    fn dynamic(triangles: u32) -> SplitCells {
        SplitCells {
            dynamic: vec![(0, 3 * triangles)],
            fixed: Vec::new(),
            chunks: Vec::new(),
        }
    }

    #[test]
    fn a_layer_pays_only_for_enough_kept_triangles_and_a_small_dynamic_set() {
        let pixels = 1280 * 720;
        // Plenty kept, a tenth dynamic: a layer.
        assert!(worth_a_layer(
            Some(&dynamic(10_000)),
            100_000,
            pixels,
            false
        ));
        // A curve moving over many surface triangles: a layer.
        assert!(worth_a_layer(None, 100_000, pixels, false));
        // Curves only: nothing would stay in the layer.
        assert!(!worth_a_layer(None, 0, pixels, false));
        // A small dynamic set, but too few triangles kept for the copy.
        assert!(!worth_a_layer(Some(&dynamic(100)), 1_000, pixels, false));
        // Enough kept, but the dynamic set is most of the frame.
        assert!(!worth_a_layer(
            Some(&dynamic(80_000)),
            100_000,
            pixels,
            false
        ));
        assert!(!worth_a_layer(
            Some(&dynamic(100_000)),
            100_000,
            pixels,
            false
        ));
        // Trimmed faces: few triangles, costly fragments; the quarter still holds.
        assert!(!worth_a_layer(Some(&dynamic(100)), 1_000, pixels, false));
        assert!(worth_a_layer(Some(&dynamic(100)), 1_000, pixels, true));
        assert!(!worth_a_layer(Some(&dynamic(800)), 1_000, pixels, true));
        assert!(!worth_a_layer(None, 0, pixels, true));
    }

    #[test]
    fn fill_runs_cover_the_members_in_order() {
        let members: Vec<(usize, usize, usize)> = (0..10).map(|i| (i, i * 100, 100)).collect();
        for threads in [1, 2, 3, 16] {
            let runs = fill_runs(&members, threads);
            assert_eq!(runs.first().map(|r| r.start), Some(0));
            assert_eq!(runs.last().map(|r| r.end), Some(10));
            assert!(runs.windows(2).all(|w| w[0].end == w[1].start));
            assert!(runs.iter().all(|r| !r.is_empty()));
        }
        // One thread: four runs of similar size.
        assert_eq!(fill_runs(&members, 1).len(), 4);
        assert!(fill_runs(&[], 2).is_empty());
    }
}

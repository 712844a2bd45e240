//! One object's control display drawn over the scene: its control polygon or net with the
//! grips (thinned where dense, `super::grips`), or its ERBS locals (display samples, polygons
//! and nets), the hovered and selected points marked; and, for the retained redraw, only the
//! rows and columns of the dragged net that reach the redrawn rectangle.

use super::retained::{overlaps, screen_rect_with};
use super::style::{Highlight, NetMode, Palette, ViewOptions};
use crate::editor::{ControlLayout, Handle, LOCAL_CURVE_SAMPLES, LOCAL_PATCH_SAMPLES, LocalEntry};
use crate::gpu::{
    Frame, GpuResult, GridShape, GridStride, GripGrid, Mirror, PointRun, PointStyle, PolylineStyle,
    SurfaceBatch,
};
use crate::model::Index2;
use glam::DVec3;

/// Drawing one object's control display: its polygon or net, or its ERBS locals (display
/// samples, control polygons and nets), with the hovered and selected points marked.
pub(super) struct ControlPass<'a> {
    object: usize,
    controls: &'a Mirror,
    opts: &'a ViewOptions,
    hl: &'a Highlight,
    palette: &'a Palette,
    /// The line style of control polygons and nets.
    net: PolylineStyle,
    /// Whether the object's polygon or net is shown (a chosen local's always is).
    nets: bool,
    /// Every how many rows and columns of its polygon or net grips are drawn.
    grips: u32,
}

impl<'a> ControlPass<'a> {
    pub(super) fn new(
        object: usize,
        controls: &'a Mirror,
        opts: &'a ViewOptions,
        hl: &'a Highlight,
        palette: &'a Palette,
    ) -> Self {
        let net = PolylineStyle {
            color: palette.net,
            width: 1.0,
            depth_test: true,
        };
        Self {
            object,
            controls,
            opts,
            hl,
            palette,
            net,
            nets: net_shown(opts, hl, object),
            grips: 1,
        }
    }

    pub(super) fn with_grips(self, grips: u32) -> Self {
        Self { grips, ..self }
    }

    pub(super) fn draw(&self, frame: &mut Frame<'_>, layout: &ControlLayout) -> GpuResult<()> {
        match layout {
            ControlLayout::Polygon { count } if self.nets => self.polygon(frame, *count),
            ControlLayout::Net { rows, cols } if self.nets => self.net(frame, *rows, *cols),
            ControlLayout::LocalCurves(entries) => self.local_curves(frame, entries),
            ControlLayout::LocalPatches(entries) => self.local_patches(frame, entries),
            _ => Ok(()),
        }
    }

    /// The control points in `run`, the hovered and the selected one marked: `pick` is a
    /// handle's index in the run, where the handle is one of these points.
    fn points(
        &self,
        frame: &mut Frame<'_>,
        run: PointRun,
        grid: Option<GripGrid>,
        pick: impl Fn(Handle) -> Option<u32>,
    ) -> GpuResult<()> {
        let index_in = |h: Option<Handle>| h.filter(|h| h.object() == self.object).and_then(&pick);
        let style = PointStyle {
            color: self.palette.point,
            size: self.opts.point_size,
            hovered: index_in(self.hl.hovered),
            selected: index_in(self.hl.selected),
            grid,
            ..PointStyle::default()
        };
        frame.draw_points(self.controls, run, &style)
    }

    /// A curve's control polygon and its points.
    fn polygon(&self, frame: &mut Frame<'_>, count: usize) -> GpuResult<()> {
        let run = PointRun::packed(0, count);
        polyline(frame, self.controls, run, &self.net)?;
        let grid = self.grip_grid(1, count);
        self.points(frame, run, grid, |h| match h {
            Handle::Point {
                point: Index2::One(k),
                ..
            } => Some(k as u32),
            _ => None,
        })
    }

    /// A surface's control net and its points.
    fn net(&self, frame: &mut Frame<'_>, rows: usize, cols: usize) -> GpuResult<()> {
        control_net(frame, self.controls, 0, rows, cols, &self.net)?;
        let grid = self.grip_grid(rows, cols);
        self.points(frame, PointRun::packed(0, rows * cols), grid, |h| match h {
            Handle::Point {
                point: Index2::Two(a, b),
                ..
            } => Some((a * cols + b) as u32),
            _ => None,
        })
    }

    /// The thinning of a `rows × cols` polygon or net's grips ([`super::grips`]).
    fn grip_grid(&self, rows: usize, cols: usize) -> Option<GripGrid> {
        (self.grips > 1).then(|| GripGrid {
            rows: u32::try_from(rows).unwrap_or(u32::MAX),
            cols: u32::try_from(cols).unwrap_or(u32::MAX),
            first_row: 0,
            every: self.grips,
        })
    }

    /// Whether a local is the selected local or lies inside it.
    fn chosen(&self, e: &LocalEntry) -> bool {
        self.hl
            .selected_local
            .is_some_and(|(o, p)| o == self.object && e.path.starts_with(&p))
    }

    /// An ERBS curve's polynomial locals: each one's display samples (where local curves are
    /// shown, or it is chosen) and its control polygon.
    fn local_curves(&self, frame: &mut Frame<'_>, entries: &[LocalEntry]) -> GpuResult<()> {
        for e in entries {
            let chosen = self.chosen(e);
            if self.opts.local_curves || chosen {
                self.local_curve(frame, e, chosen)?;
            }
            if self.nets || chosen {
                self.local_polygon(frame, e)?;
            }
        }
        Ok(())
    }

    /// A local curve's display samples, wider and in the selection colour when chosen.
    fn local_curve(&self, frame: &mut Frame<'_>, e: &LocalEntry, chosen: bool) -> GpuResult<()> {
        let style = PolylineStyle {
            color: if chosen {
                self.palette.selected_local
            } else {
                self.palette.local
            },
            width: if chosen { 2.5 } else { 1.5 },
            depth_test: true,
        };
        let run = PointRun {
            offset: e.samples * 3,
            stride: 3,
            count: LOCAL_CURVE_SAMPLES,
        };
        polyline(frame, self.controls, run, &style)
    }

    /// A local curve's control polygon and its points.
    fn local_polygon(&self, frame: &mut Frame<'_>, e: &LocalEntry) -> GpuResult<()> {
        let run = PointRun {
            offset: e.points * 3,
            stride: 3,
            count: e.rows,
        };
        polyline(frame, self.controls, run, &self.net)?;
        self.points(frame, run, None, |h| match h {
            Handle::LocalPoint {
                local,
                point: Index2::One(q),
                ..
            } if local == e.path => Some(q as u32),
            _ => None,
        })
    }

    /// An ERBS surface's polynomial local patches: their wires, then each shown one's control
    /// net.
    fn local_patches(&self, frame: &mut Frame<'_>, entries: &[LocalEntry]) -> GpuResult<()> {
        self.patch_wires(frame, entries)?;
        for e in entries {
            if self.nets || self.chosen(e) {
                self.local_net(frame, e)?;
            }
        }
        Ok(())
    }

    /// Outline and centre lines only: full wire grids of every patch bury the surface. All
    /// patches in one call (where local patches are shown), the chosen ones on top in their
    /// colour.
    fn patch_wires(&self, frame: &mut Frame<'_>, entries: &[LocalEntry]) -> GpuResult<()> {
        let k = LOCAL_PATCH_SAMPLES as u32;
        let wire = |frame: &mut Frame<'_>, offsets: &[usize], color| {
            let batch = SurfaceBatch {
                shape: GridShape { rows: k, cols: k },
                stride: GridStride::FULL,
                offsets,
                mask: None,
            };
            frame.draw_wire_batch(self.controls, &batch, (k - 1) / 2, color)
        };
        let offsets = |chosen: bool| -> Vec<usize> {
            entries
                .iter()
                .filter(|e| self.chosen(e) == chosen)
                .map(|e| e.samples * 3)
                .collect()
        };
        if self.opts.local_curves {
            wire(frame, &offsets(false), self.palette.local)?;
        }
        let selected = offsets(true);
        if !selected.is_empty() {
            wire(frame, &selected, self.palette.selected_local)?;
        }
        Ok(())
    }

    /// A local patch's control net and its points.
    fn local_net(&self, frame: &mut Frame<'_>, e: &LocalEntry) -> GpuResult<()> {
        control_net(
            frame,
            self.controls,
            e.points * 3,
            e.rows,
            e.cols,
            &self.net,
        )?;
        let run = PointRun {
            offset: e.points * 3,
            stride: 3,
            count: e.rows * e.cols,
        };
        self.points(frame, run, None, |h| match h {
            Handle::LocalPoint {
                local,
                point: Index2::Two(a, b),
                ..
            } if local == e.path => Some((a * e.cols + b) as u32),
            _ => None,
        })
    }
}

/// Whether object `i`'s control net or polygon is shown.
pub(super) fn net_shown(opts: &ViewOptions, hl: &Highlight, i: usize) -> bool {
    match opts.control_nets {
        NetMode::All => true,
        NetMode::Focused => hl.focuses(i),
        NetMode::Off => false,
    }
}

/// An ERBS object's display of its locals (drawn wherever local curves are shown).
pub(super) fn is_local_display(layout: &ControlLayout) -> bool {
    matches!(
        layout,
        ControlLayout::LocalCurves(_) | ControlLayout::LocalPatches(_)
    )
}

/// Whether [`ControlPass::draw`] may draw something of object `i`'s control display: a
/// polygon or net where the nets are shown; an ERBS object's locals where local curves and
/// patches are shown, or its nets, or one of its locals is chosen.
pub(super) fn control_drawn(
    opts: &ViewOptions,
    hl: &Highlight,
    i: usize,
    layout: &ControlLayout,
) -> bool {
    match layout {
        ControlLayout::Polygon { .. } | ControlLayout::Net { .. } => net_shown(opts, hl, i),
        ControlLayout::LocalCurves(_) | ControlLayout::LocalPatches(_) => {
            opts.local_curves
                || net_shown(opts, hl, i)
                || hl.selected_local.is_some_and(|(o, _)| o == i)
        }
    }
}

/// A pixel rectangle that draws are clipped to, so the gesture's control net need only draw
/// its rows and columns that reach it.
pub(super) struct NetClip {
    pub(super) object: usize,
    pub(super) rect: [u32; 4],
    pub(super) camera: crate::gpu::Camera,
    pub(super) viewport: [u32; 4],
}

/// The rows, then the columns, then the points (row by row) of a `rows × cols` control net
/// whose screen rectangles reach `clip`'s. Within the clip this is the full net's image: net
/// lines are one colour, so their order among themselves changes no pixel, points follow all
/// lines as in the full draw and keep their order, and what is left out has no pixel there.
pub(super) fn clipped_net(
    frame: &mut Frame<'_>,
    controls: &Mirror,
    vertices: &[DVec3],
    ([rows, cols], grips): ([usize; 2], u32),
    opts: &ViewOptions,
    hl: &Highlight,
    clip: &NetClip,
) -> GpuResult<()> {
    let palette = Palette::default();
    let margin = line_margin(opts);
    let reaches = |points: &mut dyn Iterator<Item = DVec3>| {
        let b = points.fold(None, |b: Option<[DVec3; 2]>, p| {
            Some(b.map_or([p, p], |[lo, hi]| [lo.min(p), hi.max(p)]))
        });
        b.is_some_and(|b| {
            overlaps(
                screen_rect_with(&clip.camera, b, clip.viewport, margin),
                clip.rect,
            )
        })
    };
    let row_hit: Vec<bool> = (0..rows)
        .map(|r| reaches(&mut vertices[r * cols..(r + 1) * cols].iter().copied()))
        .collect();
    let col_hit: Vec<bool> = (0..cols)
        .map(|c| reaches(&mut (0..rows).map(|r| vertices[r * cols + c])))
        .collect();
    let net = PolylineStyle {
        color: palette.net,
        width: 1.0,
        depth_test: true,
    };
    let run = |offset: usize, stride: usize, count: usize| PointRun {
        offset: offset * 3,
        stride: stride * 3,
        count,
    };
    for r in (0..rows).filter(|&r| row_hit[r]) {
        polyline(frame, controls, run(r * cols, 1, cols), &net)?;
    }
    for c in (0..cols).filter(|&c| col_hit[c]) {
        polyline(frame, controls, run(c, cols, rows), &net)?;
    }
    let index_of = |h: Option<Handle>, r: usize| match h {
        Some(Handle::Point {
            object,
            point: Index2::Two(a, b),
        }) if object == clip.object && a == r => Some(b as u32),
        _ => None,
    };
    for r in (0..rows).filter(|&r| row_hit[r]) {
        let style = PointStyle {
            color: palette.point,
            size: opts.point_size,
            hovered: index_of(hl.hovered, r),
            selected: index_of(hl.selected, r),
            grid: (grips > 1).then(|| GripGrid {
                rows: u32::try_from(rows).unwrap_or(u32::MAX),
                cols: u32::try_from(cols).unwrap_or(u32::MAX),
                first_row: u32::try_from(r).unwrap_or(u32::MAX),
                every: grips,
            }),
            ..PointStyle::default()
        };
        frame.draw_points(controls, run(r * cols, 1, cols), &style)?;
    }
    Ok(())
}

/// Pixels that lines and points reach beyond their vertices' projections: half the largest
/// point (a selected one is 1.5 times the size) and the widest line.
pub(super) fn line_margin(opts: &ViewOptions) -> f32 {
    0.75 * opts.point_size + opts.curve_width.max(2.5) + 2.0
}

/// A `rows × cols` control net stored row-major from float `base`: every row and column, in
/// one draw.
pub(super) fn control_net(
    frame: &mut Frame<'_>,
    m: &Mirror,
    base: usize,
    rows: usize,
    cols: usize,
    style: &PolylineStyle,
) -> GpuResult<()> {
    if rows * cols < 2 {
        return Ok(());
    }
    let run = PointRun {
        offset: base,
        stride: 3,
        count: rows * cols,
    };
    frame.draw_net(m, run, cols, style)
}

/// Polylines need two points; degree-0 local curves have one.
pub(super) fn polyline(
    frame: &mut Frame<'_>,
    m: &Mirror,
    run: PointRun,
    style: &PolylineStyle,
) -> GpuResult<()> {
    if run.count >= 2 {
        frame.draw_polyline(m, run, style)
    } else {
        Ok(())
    }
}

//! Memory budget for pre-evaluation: how many bytes an object's Hermite tables, sample grids and
//! GPU mirrors will take, estimated from its shape and sample counts *before* anything is
//! allocated, so that a request too large for the machine is refused with one line naming the
//! object instead of aborting in the allocator.
//!
//! [`estimate`] is a pure function of an object's [`Extent`] (degrees, sample counts, rational
//! or not, ERBS local counts), the [`SampleMode`] and what the command does with the samples
//! ([`Uses`]). [`check_extents`] applies it to every object of a scene against a
//! [`MemoryBudget`] (by default half of physical memory; `--memory-limit` overrides).

use super::object::SampleMode;
use crate::geom::erbs::{ErbsCurve, ErbsSurface, LocalCurve, LocalPatch};
use std::fmt::Write;

/// Bytes of one f64 / `DVec3` / `DVec4` / f32.
const F64: u128 = 8;
const VEC3: u128 = 24;
const VEC4: u128 = 32;
const F32: u128 = 4;
/// A point: three f64.
const DVEC3: u128 = 24;
/// A span index.
const USIZE: u128 = std::mem::size_of::<usize>() as u128;
/// Frames in flight, each with its own mirror (see `gpu::FRAMES_IN_FLIGHT`; `sampling` does not
/// depend on `gpu`): control mirrors are written in every one.
const GPU_SLOTS_ALWAYS: u128 = 2;
/// Per object and frame slot, its control structure's mirror: the Vulkan buffer, its
/// allocation's bookkeeping and contents (lavapipe, measured on 32 × 32 teapots: 4 KiB an
/// object over two slots).
const CONTROL_MIRROR: u128 = 2048;
/// Per object besides its samples and tables: the model, the sampler's structure, the control
/// display and the name. Measured on bicubic Bézier patches: 2.5 KiB requested, 4 KiB resident
/// with the allocator's headers. Small beside any object's samples, it is what a scene of many
/// small objects adds up.
const OBJECT_BYTES: u128 = 4096;
/// Of [`OBJECT_BYTES`], what does not grow with the control points (those are
/// [`Extent::control_bytes`]): an object costs at least `OBJECT_BYTES`, and its structure
/// plus its control bytes where those are more.
const OBJECT_STRUCTURE: u128 = 3072;
/// What lavapipe keeps per shaded vertex of a draw until the frame is rasterised (measured
/// with heaptrack on `render` of 50,000 curves: 411.6 MB for 9.6 M polyline vertices).
const DRIVER_VERTEX_BYTES: u128 = 43;
/// What the driver allocates, once per process, when it first draws a scene: lavapipe's
/// compiled pipelines and draw state (measured after `render` of one-object scenes and of one
/// teapot: 27–30 MiB over the resident size once the device was made; 17–24 MiB on 8 × 8 to
/// 64 × 64 teapots, where the rest of the estimate runs slightly high).
const DRIVER_DRAW_STATE: u128 = 26 << 20;
/// Vertices one entry of a surface batch's multi-draw covers at most (`gpu::RUN_VERTICES`).
pub const RUN_VERTICES: u64 = 1 << 16;
/// Budget when physical memory cannot be read.
pub const FALLBACK_BUDGET: u64 = 4 << 30;

/// What the estimate needs to know about one object, independent of the scene model's types.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Extent {
    /// Samples per direction: one entry for curves, two for surfaces.
    pub samples: Vec<usize>,
    /// Polynomial degree per direction; for ERBS objects the highest local degree.
    pub degree: Vec<usize>,
    /// Rational objects keep homogeneous samples besides the projected ones.
    pub rational: bool,
    /// ERBS objects: local curves (patches) per direction; `None` for Bézier/B-spline/NURBS.
    pub erbs_locals: Option<Vec<usize>>,
    /// ERBS locals that are ERBS themselves: each a level of its own, pre-evaluated at the
    /// parent's samples inside its support (its `samples`).
    pub nested: Vec<Extent>,
    /// Vertices of the object's control display (a net's points; an ERBS object's local
    /// display samples and points), each mirrored to the GPU in every frame slot.
    pub control_vertices: usize,
    /// Host bytes that grow with the object's control points: the model's points, weights and
    /// knots, the sampler's per-point ranges and the control display, as the kind counts them
    /// (a curve read from a file can have millions of points).
    pub control_bytes: u128,
    /// Identifies the object's Hermite tables where objects with equal knots and sample
    /// counts share them (`HermiteTable::shared`): a scene counts each such key's tables once.
    pub shared_tables: Option<u64>,
}

impl Extent {
    /// A Bézier, B-spline or NURBS object (or one evaluated as such) of these degrees.
    #[must_use]
    pub fn polynomial(samples: &[usize], degree: &[usize], rational: bool) -> Self {
        Extent {
            samples: samples.to_vec(),
            degree: degree.to_vec(),
            rational,
            erbs_locals: None,
            nested: Vec::new(),
            control_vertices: 0,
            control_bytes: 0,
            shared_tables: None,
        }
    }

    /// This extent with its control display's `vertices` and the host `bytes` that grow with
    /// the control points ([`Extent::control_bytes`]).
    #[must_use]
    pub fn with_controls(mut self, vertices: usize, bytes: u128) -> Self {
        self.control_vertices = vertices;
        self.control_bytes = bytes;
        self
    }

    /// This extent with tables shared under `key` (a hash of what the tables are built from,
    /// equal exactly when the tables are).
    #[must_use]
    pub fn with_shared_tables(mut self, key: u64) -> Self {
        self.shared_tables = Some(key);
        self
    }

    /// [`Extent::with_controls`] for a B-spline net of `points` control points with `knots`
    /// knots in all and `directions` Hermite tables: the model's points (and weights), the
    /// display's copy of them, the knots and each table's per-point influence range.
    #[must_use]
    pub fn with_net(self, points: usize, knots: usize, directions: usize, rational: bool) -> Self {
        let per_point = 2 * DVEC3 + if rational { F64 } else { 0 };
        let per_range = 2 * USIZE;
        // A surface's tables hold one range per row and per column; bounded by the points.
        let ranges = if directions == 1 {
            points as u128
        } else {
            (points as u128).min(2 * (points as f64).sqrt().ceil() as u128 + 2)
        };
        // The knots twice: the model's and the copy each table keeps to tell a refinement.
        let bytes = points as u128 * per_point + 2 * knots as u128 * F64 + ranges * per_range;
        self.with_controls(points, bytes)
    }

    /// An ERBS curve sampled `m` times.
    #[must_use]
    pub fn erbs_curve(c: &ErbsCurve, m: usize) -> Self {
        erbs_curve_extent(c, m)
    }

    /// An ERBS surface sampled `dims`.
    #[must_use]
    pub fn erbs_surface(s: &ErbsSurface, dims: [usize; 2]) -> Self {
        erbs_surface_extent(s, dims)
    }

    fn is_surface(&self) -> bool {
        self.samples.len() == 2
    }

    /// Samples in the grid (product over the directions).
    fn sample_count(&self) -> u128 {
        self.samples.iter().map(|&m| m as u128).product()
    }
}

/// Samples of a parent's `m` over `domain` that fall in `support` (both ends counted).
fn samples_in(m: usize, domain: (f64, f64), support: (f64, f64)) -> usize {
    let width = domain.1 - domain.0;
    let part = if width > 0.0 {
        ((support.1 - support.0) / width).clamp(0.0, 1.0)
    } else {
        1.0
    };
    ((part * (m.saturating_sub(1)) as f64).ceil() as usize + 1).min(m)
}

/// An ERBS curve's extent at `m` samples, its ERBS locals (to any depth) at the samples in
/// their supports.
fn erbs_curve_extent(c: &ErbsCurve, m: usize) -> Extent {
    let locals = c.local_curves();
    let nested = locals
        .iter()
        .enumerate()
        .filter_map(|(l, local)| match local {
            LocalCurve::Erbs(inner) => Some(erbs_curve_extent(
                inner,
                samples_in(m, c.domain(), c.knots().support(l)),
            )),
            LocalCurve::Spline { .. } => None,
        })
        .collect();
    Extent {
        samples: vec![m],
        degree: vec![locals.iter().map(LocalCurve::degree).max().unwrap_or(0)],
        rational: false,
        erbs_locals: Some(vec![locals.len()]),
        nested,
        control_vertices: 0,
        control_bytes: 0,
        shared_tables: None,
    }
}

/// As [`erbs_curve_extent`] for a surface at `dims` samples.
fn erbs_surface_extent(s: &ErbsSurface, dims: [usize; 2]) -> Extent {
    let [_, nv] = s.count();
    let domain = s.domain();
    let nested = s
        .local_patches()
        .iter()
        .enumerate()
        .filter_map(|(idx, p)| match p {
            LocalPatch::Erbs(inner) => {
                let (k, l) = (idx / nv.max(1), idx % nv.max(1));
                let support = [s.knots()[0].support(k), s.knots()[1].support(l)];
                let sub = [0, 1].map(|d| samples_in(dims[d], domain[d], support[d]));
                Some(erbs_surface_extent(inner, sub))
            }
            LocalPatch::Spline { .. } => None,
        })
        .collect();
    let degree = s.local_patches().iter().fold(vec![0, 0], |d, p| {
        let [a, b] = p.degree();
        vec![d[0].max(a), d[1].max(b)]
    });
    Extent {
        samples: dims.to_vec(),
        degree,
        rational: false,
        erbs_locals: Some(s.count().to_vec()),
        nested,
        control_vertices: 0,
        control_bytes: 0,
        shared_tables: None,
    }
}

/// What a command does with the samples besides keeping them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Uses {
    /// Frame slots whose GPU mirrors get written: 0 without a GPU (`sample`), 1 for `render`
    /// (one frame), every slot for `view` and `bench`. A slot's mirror is written by the
    /// first frame that uses it, so only those slots' pages become resident.
    pub gpu_slots: u8,
    /// Every object's control display is drawn (`view` and `bench`, where the nets can be
    /// shown at any time; `render --net`). Otherwise only the displays drawn whatever the nets
    /// (ERBS objects' locals) get a GPU mirror, made when first drawn.
    pub control_displays: bool,
    /// The whole `prespline sample` JSON text, built in memory so a failure prints nothing.
    pub json_text: bool,
}

/// One kind of allocation and its size.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Part {
    /// What it is ("Hermite tables", "samples", …).
    pub what: &'static str,
    pub bytes: u64,
    /// How it is computed, e.g. "5000000 samples × 21 derivative orders × 61 basis functions".
    pub formula: String,
}

/// Estimated memory of one object.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Estimate {
    /// The parts, largest first.
    pub parts: Vec<Part>,
}

impl Estimate {
    /// Total bytes.
    #[must_use]
    pub fn bytes(&self) -> u64 {
        self.parts
            .iter()
            .fold(0u64, |s, p| s.saturating_add(p.bytes))
    }

    /// Bytes of the part named `what` (0 when there is none).
    #[must_use]
    pub fn part_bytes(&self, what: &str) -> u64 {
        self.parts
            .iter()
            .filter(|p| p.what == what)
            .fold(0u64, |s, p| s.saturating_add(p.bytes))
    }

    /// The two largest parts with their formulas, for the refusal message.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut s = String::new();
        for (i, p) in self.parts.iter().take(2).enumerate() {
            if i > 0 {
                s.push_str("; ");
            }
            let _ = write!(s, "{} {}: {}", p.what, format_bytes(p.bytes), p.formula);
        }
        if self.parts.len() > 2 {
            let rest = self.parts[2..]
                .iter()
                .fold(0u64, |s, p| s.saturating_add(p.bytes));
            let _ = write!(s, "; other {}", format_bytes(rest));
        }
        s
    }

    fn add(&mut self, what: &'static str, bytes: u128, formula: String) {
        if bytes > 0 {
            self.parts.push(Part {
                what,
                bytes: u64::try_from(bytes).unwrap_or(u64::MAX),
                formula,
            });
        }
    }
}

/// Estimates the bytes pre-evaluating one object takes: per direction the Hermite tables
/// (samples × derivative rows kept × (degree + 1) f64), the canonical grid (samples × partials
/// × 24 B), homogeneous copies of rational objects, unit normals, ERBS blend weights and local
/// sample buffers, and with `uses` its GPU mirrors and the JSON text. What objects share (index
/// buffers by grid shape) is [`shared_estimate`]'s.
#[must_use]
pub fn estimate(extent: &Extent, mode: SampleMode, uses: Uses) -> Estimate {
    let mut e = Estimate::default();
    let at = Layout::of(extent, mode);
    e.add(
        "object",
        OBJECT_BYTES.max(OBJECT_STRUCTURE + extent.control_bytes),
        format!(
            "model, sampler, control display ({} vertices) and name",
            extent.control_vertices
        ),
    );
    add_tables(&mut e, extent, &at);
    add_samples(&mut e, extent, mode, &at);
    if let Some(locals) = &extent.erbs_locals {
        add_erbs(&mut e, extent, locals, &at);
    }
    if !extent.nested.is_empty() {
        add_nested(&mut e, extent, mode, &at);
    }
    add_gpu(&mut e, extent, mode, uses, &at);
    if uses.json_text {
        // "[x, y, z]" with up to 24 characters a number.
        e.add(
            "output text",
            at.vectors * 80,
            format!("{} × {} × ~80 characters", at.samples_text, at.orders),
        );
    }
    e.parts.sort_by_key(|p| std::cmp::Reverse(p.bytes));
    e
}

/// What an object's terms are counted in: the highest derivative order kept, the vectors per
/// sample, the samples, and their wording for the refusal message.
struct Layout {
    surface: bool,
    g: u128,
    stride: u128,
    n: u128,
    vectors: u128,
    orders: String,
    samples_text: String,
}

impl Layout {
    fn of(extent: &Extent, mode: SampleMode) -> Self {
        let surface = extent.is_surface();
        let (g, stride) = match (mode, surface) {
            (SampleMode::Derivatives(g), false) => (g, g + 1),
            (SampleMode::Derivatives(g), true) => (g, (g + 1) * (g + 1)),
            (SampleMode::Render, false) => (1, 2),
            (SampleMode::Render, true) => (1, 3),
            (SampleMode::Analysis, false) => (1, 2),
            (SampleMode::Analysis, true) => (2, 6),
        };
        let (g, stride) = (g as u128, stride as u128);
        let n = extent.sample_count();
        Layout {
            surface,
            g,
            stride,
            n,
            vectors: n * stride,
            orders: if surface {
                format!("{stride} partials")
            } else {
                format!("{stride} derivative orders")
            },
            samples_text: samples_text(&extent.samples),
        }
    }
}

/// Hermite tables: per direction m × rows × (d+1) f64; an ERBS local's table covers its
/// support, and every sample lies in the supports of two locals per direction. Counted per
/// object: B-spline objects with equal knots and sample counts share one table
/// (`HermiteTable::shared`), which the extent cannot see, so for them this is an upper bound.
fn add_tables(e: &mut Estimate, extent: &Extent, at: &Layout) {
    let mut table_bytes = 0u128;
    let mut table_formula = Vec::new();
    for (dir, (&m, &d)) in extent.samples.iter().zip(&extent.degree).enumerate() {
        let (m, d) = (m as u128, d as u128);
        let rows = at.g.min(d) + 1;
        let copies = match &extent.erbs_locals {
            // A surface's local patch (k, l) has its own u table over its support rows: each
            // u support is repeated for every l.
            Some(locals) if at.surface => 2 * locals[1 - dir] as u128,
            Some(_) => 2,
            None => 1,
        };
        // Besides the basis values, every table keeps each sample's parameter and span.
        table_bytes += copies * m * (rows * (d + 1) * F64 + F64 + USIZE);
        table_formula.push(format!(
            "{}{m} samples × {rows} derivative orders × {} basis functions",
            if copies > 1 {
                format!("{copies} × ")
            } else {
                String::new()
            },
            d + 1
        ));
    }
    e.add("Hermite tables", table_bytes, table_formula.join(" + "));
}

/// The canonical grid, homogeneous copies, unit normals and curvatures.
fn add_samples(e: &mut Estimate, extent: &Extent, mode: SampleMode, at: &Layout) {
    let (n, text) = (at.n, &at.samples_text);
    e.add(
        "samples",
        at.vectors * VEC3,
        format!("{text} × {} × 24 B", at.orders),
    );
    if extent.rational {
        e.add(
            "homogeneous samples",
            at.vectors * VEC4,
            format!("{text} × {} × 32 B", at.orders),
        );
    }
    if at.surface && matches!(mode, SampleMode::Render | SampleMode::Analysis) {
        e.add("normals", n * VEC3, format!("{text} × 24 B"));
    }
    if at.surface && mode == SampleMode::Analysis {
        e.add("curvatures", n * 2 * F64, format!("{text} × [K, H] × 16 B"));
    }
}

/// ERBS blend weights and local samples (curves) or blended bases (surfaces).
fn add_erbs(e: &mut Estimate, extent: &Extent, locals: &[usize], at: &Layout) {
    // Blend weights: per direction m × 2 × (g+1) f64. Local samples: every parent sample
    // lies in two supports per direction, so 2 (curves) or 4 (surfaces) local copies.
    let blend: u128 = extent
        .samples
        .iter()
        .map(|&m| m as u128 * 2 * (at.g + 1) * F64)
        .sum();
    e.add(
        "ERBS blend weights",
        blend,
        format!("{} × 2 × {} orders × 8 B", at.samples_text, at.g + 1),
    );
    if at.surface {
        // Polynomial local patches keep no samples, only their blended bases: per
        // direction each support row once per patch in the other direction, rows 0 and 1
        // padded to 4 functions (ERBS locals of locals are levels of their own, sized as
        // deep as the scene makes them, and not counted here).
        let dense: u128 = extent
            .samples
            .iter()
            .enumerate()
            .map(|(dir, &m)| 2 * locals[1 - dir] as u128 * m as u128 * 2 * 4 * F64)
            .sum();
        e.add(
            "ERBS blended bases",
            dense,
            "per direction: 2 × samples × patches across × 2 orders × 4 functions × 8 B".into(),
        );
        // Each polynomial patch's own structure, whatever its samples: its two tables' headers
        // and knots, its net and the dense kernels' padded copy of it (what a scene of many
        // patches with few samples each is made of).
        use super::tables::axis::HermiteTable;
        use super::tables::erbs_patch::{DensePatch, SplinePatch};
        let size = |bytes: usize| bytes as u128;
        let (du, dv) = (extent.degree[0] as u128 + 1, extent.degree[1] as u128 + 1);
        let per_patch = size(std::mem::size_of::<SplinePatch>())
            + 2 * size(std::mem::size_of::<HermiteTable>())
            + size(std::mem::size_of::<DensePatch>())
            + du * dv * VEC3
            + 2 * (du + dv) * F64;
        let patches = locals[0] as u128 * locals[1] as u128;
        e.add(
            "ERBS local patch structure",
            patches * per_patch,
            format!("{patches} patches × {per_patch} B"),
        );
    } else {
        e.add(
            "ERBS local samples",
            2 * at.vectors * VEC3,
            format!(
                "2 × {} × {} × 24 B over {} locals",
                at.samples_text,
                at.orders,
                locals.iter().map(|&l| l as u128).product::<u128>()
            ),
        );
        // Each polynomial local's own structure, whatever its samples: its table's header,
        // knots and per-point ranges, and its samples' list.
        use super::tables::axis::HermiteTable;
        let d1 = extent.degree[0] as u128 + 1;
        let per_local = std::mem::size_of::<HermiteTable>() as u128
            + 2 * std::mem::size_of::<Vec<f64>>() as u128
            + 2 * d1 * F64
            + d1 * 2 * USIZE;
        e.add(
            "ERBS local curve structure",
            locals[0] as u128 * per_local,
            format!("{} locals × {per_local} B", locals[0]),
        );
    }
}

/// ERBS locals that are ERBS themselves: a level each.
fn add_nested(e: &mut Estimate, extent: &Extent, mode: SampleMode, at: &Layout) {
    // A nested level keeps what an ERBS object of its own would, less the normals and
    // curvatures (only the top level has them).
    let nested: u128 = extent
        .nested
        .iter()
        .map(|x| {
            let e = estimate(x, mode, Uses::default());
            e.parts
                .iter()
                .filter(|p| !matches!(p.what, "normals" | "curvatures" | "object"))
                .map(|p| u128::from(p.bytes))
                .sum::<u128>()
        })
        .sum();
    // A curve's nested local has no Hermite table nor local samples in its parent (its
    // level holds them), which the parent's terms above counted for every local.
    let replaced: u128 = if at.surface {
        0
    } else {
        let (rows, d1) = (
            at.g.min(extent.degree[0] as u128) + 1,
            extent.degree[0] as u128 + 1,
        );
        extent
            .nested
            .iter()
            .map(|x| x.sample_count() * (rows * d1 * F64 + F64 + USIZE + at.stride * VEC3))
            .sum()
    };
    e.add(
        "nested ERBS levels",
        nested.saturating_sub(replaced),
        format!(
            "{} ERBS locals at the samples in their supports",
            extent.nested.len()
        ),
    );
}

/// The object's own GPU parts: per frame slot written a mirror of f32 vertices (surfaces:
/// position + normal), and the curvature map's scalar per vertex likewise; the control
/// structure's mirror.
fn add_gpu(e: &mut Estimate, extent: &Extent, mode: SampleMode, uses: Uses, at: &Layout) {
    if uses.gpu_slots == 0 {
        return;
    }
    let slots = u128::from(uses.gpu_slots);
    let floats: u128 = if at.surface { 6 } else { 3 };
    let text = &at.samples_text;
    e.add(
        "GPU mirrors",
        slots * at.n * floats * F32,
        format!("{slots} × {text} × {} B", floats * F32),
    );
    if !at.surface {
        // lavapipe shades a draw's vertices when it is recorded and keeps them until the
        // render pass is rasterised: a wide curve is a quad (6 vertices) per segment.
        let vertices = 6 * at.n.saturating_sub(1);
        e.add(
            "GPU driver vertices",
            vertices * DRIVER_VERTEX_BYTES,
            format!("{vertices} drawn vertices × {DRIVER_VERTEX_BYTES} B (lavapipe)"),
        );
    }
    if at.surface && mode == SampleMode::Analysis {
        e.add(
            "GPU map mirrors",
            slots * at.n * F32,
            format!("{slots} × {text} × 4 B"),
        );
    }
    // The control structure's mirror is written in every slot: at least a small buffer's
    // cost, and three f32 per vertex where a display has many. It is made when the display is
    // first drawn, and an ERBS object's locals are drawn without the nets.
    if !uses.control_displays && extent.erbs_locals.is_none() {
        return;
    }
    let mirror = CONTROL_MIRROR.max(extent.control_vertices as u128 * 3 * F32);
    e.add(
        "GPU control mirrors",
        GPU_SLOTS_ALWAYS * mirror,
        format!("{GPU_SLOTS_ALWAYS} × {mirror} B"),
    );
}

/// Surfaces of one grid shape share their index buffers: triangles and isolines, six and
/// about four u32 per vertex, in copies for runs of up to [`RUN_VERTICES`] vertices (the next
/// power of two of the grids in such a run; one copy for a grid larger than that), and their
/// staging copies while uploading. Counted once per shape of the scene's surfaces.
#[must_use]
pub fn shared_estimate(objects: &[(&str, Extent)], uses: Uses) -> Estimate {
    let mut e = Estimate::default();
    if uses.gpu_slots == 0 {
        return e;
    }
    let mut shapes: std::collections::HashMap<(usize, usize), u128> = Default::default();
    for (_, x) in objects.iter().filter(|(_, x)| x.is_surface()) {
        *shapes.entry((x.samples[0], x.samples[1])).or_default() += 1;
    }
    let bytes: u128 = shapes
        .iter()
        .map(|(&(rows, cols), &count)| {
            let vertices = (rows as u128 * cols as u128).max(1);
            let cap = (u128::from(RUN_VERTICES) / vertices).max(1);
            let copies = count.min(cap).next_power_of_two();
            2 * copies * vertices * 10 * F32
        })
        .sum();
    e.add(
        "GPU index buffers",
        bytes,
        format!("{} grid shapes × 2 × copies × samples × 40 B", shapes.len()),
    );
    e.add(
        "GPU driver draw state",
        DRIVER_DRAW_STATE,
        "compiled pipelines and draw state, once (lavapipe)".to_string(),
    );
    e
}

fn samples_text(samples: &[usize]) -> String {
    match samples {
        [m] => format!("{m} samples"),
        [mu, mv] => format!("{mu}×{mv} samples"),
        _ => format!("{samples:?} samples"),
    }
}

/// Where a budget came from (said in the refusal so the user knows what to change).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BudgetSource {
    /// Half of the machine's physical memory.
    HalfOfPhysical,
    /// Half of the process's memory limit (cgroup `memory.max` or `ulimit -v`), lower than
    /// physical memory.
    HalfOfLimit,
    /// Physical memory could not be read: [`FALLBACK_BUDGET`].
    Fallback,
    /// `--memory-limit`.
    Flag,
}

/// The bytes pre-evaluation may take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryBudget {
    pub bytes: u64,
    pub source: BudgetSource,
}

impl MemoryBudget {
    /// `--memory-limit` when given, else half of physical memory.
    #[must_use]
    pub fn from_flag(limit: Option<u64>) -> Self {
        match limit {
            Some(bytes) => MemoryBudget {
                bytes,
                source: BudgetSource::Flag,
            },
            None => Self::machine_default(),
        }
    }

    /// Half of physical memory (`MemTotal` in /proc/meminfo, lowered to a cgroup v2 limit or
    /// an address-space limit when there is one), or [`FALLBACK_BUDGET`] where none can be
    /// read.
    #[must_use]
    pub fn machine_default() -> Self {
        let physical = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|t| mem_total(&t));
        let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
            .ok()
            .and_then(|t| t.trim().parse::<u64>().ok());
        // An address-space limit (`ulimit -v`) is a ceiling too: allocating past it aborts.
        let address_space = std::fs::read_to_string("/proc/self/limits")
            .ok()
            .and_then(|t| address_space_limit(&t));
        let cgroup = match (cgroup, address_space) {
            (Some(c), Some(a)) => Some(c.min(a)),
            (c, a) => c.or(a),
        };
        match (physical, cgroup) {
            (None, None) => MemoryBudget {
                bytes: FALLBACK_BUDGET,
                source: BudgetSource::Fallback,
            },
            (p, Some(c)) if p.is_none_or(|p| c < p) => MemoryBudget {
                bytes: c / 2,
                source: BudgetSource::HalfOfLimit,
            },
            (p, _) => MemoryBudget {
                bytes: p.unwrap_or(u64::MAX) / 2,
                source: BudgetSource::HalfOfPhysical,
            },
        }
    }

    fn describe(&self) -> String {
        let why = match self.source {
            BudgetSource::HalfOfPhysical => "half of physical memory; --memory-limit overrides",
            BudgetSource::HalfOfLimit => {
                "half of the process's memory limit (cgroup or ulimit -v); --memory-limit overrides"
            }
            BudgetSource::Fallback => {
                "physical memory unknown, fixed default; --memory-limit overrides"
            }
            BudgetSource::Flag => "--memory-limit",
        };
        format!("{} ({why})", format_bytes(self.bytes))
    }
}

impl MemoryBudget {
    /// Refuses, as one line, building `what` (e.g. "1000000000000 local curves of degree 3")
    /// when its `bytes` exceed the budget. Called with counts from a file, an edit, a script
    /// or the command line before anything is allocated for them.
    pub fn check_build(&self, what: impl std::fmt::Display, bytes: u128) -> Result<(), String> {
        if bytes > u128::from(self.bytes) {
            return Err(format!(
                "{what} need about {} to build, over the memory budget of {}",
                format_bytes(u64::try_from(bytes).unwrap_or(u64::MAX)),
                self.describe()
            ));
        }
        Ok(())
    }
}

/// The soft "Max address space" limit in bytes from /proc/self/limits text; `None` when
/// unlimited or unreadable.
fn address_space_limit(limits: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// `MemTotal` in bytes from /proc/meminfo text.
fn mem_total(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Refuses, as one line naming the object, objects given by name and extent that do not fit
/// `budget` together (a scene's, or a document's with one object about to change, without
/// copying any model); returns the estimated total otherwise.
///
/// Objects given by name and extent (a document with one object about
/// to change, say, without copying any model).
pub fn check_extents(
    objects: &[(&str, Extent)],
    mode: SampleMode,
    uses: Uses,
    budget: &MemoryBudget,
) -> Result<u64, String> {
    let shared_parts = shared_estimate(objects, uses);
    let mut total = shared_parts.bytes();
    let mut largest: Option<(usize, u64)> = None;
    let mut tables_seen = std::collections::HashSet::new();
    for (i, (name, extent)) in objects.iter().enumerate() {
        let e = estimate(extent, mode, uses);
        let bytes = e.bytes();
        // Tables another object already holds are not allocated again.
        let shared = match extent.shared_tables {
            Some(key) if !tables_seen.insert(key) => e.part_bytes("Hermite tables"),
            _ => 0,
        };
        if bytes > budget.bytes {
            return Err(format!(
                "object '{name}' (objects[{i}]): needs about {} to pre-evaluate ({}), over the memory budget of {}",
                format_bytes(bytes),
                e.describe(),
                budget.describe()
            ));
        }
        total = total.saturating_add(bytes - shared);
        if largest.is_none_or(|(_, b)| bytes > b) {
            largest = Some((i, bytes));
        }
    }
    match largest {
        Some((i, bytes)) if total > budget.bytes => Err(format!(
            "{} need{} about {} in all to pre-evaluate and draw (the largest, object '{}' (objects[{i}]), about {}{}), over the memory budget of {}",
            match objects.len() {
                1 => "1 object".to_string(),
                n => format!("{n} objects"),
            },
            if objects.len() == 1 { "s" } else { "" },
            format_bytes(total),
            objects[i].0,
            format_bytes(bytes),
            match shared_parts.bytes() {
                0 => String::new(),
                b => format!(
                    "; what the GPU shares between objects, about {}",
                    format_bytes(b)
                ),
            },
            budget.describe()
        )),
        _ => Ok(total),
    }
}

/// Bytes in binary units with one decimal: "512 B", "1.5 KiB", "47.7 GiB".
#[must_use]
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if bytes < 1024 {
        return format!("{bytes} B");
    }
    let mut v = bytes as f64 / 1024.0;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    format!("{v:.1} {}", UNITS[unit])
}

/// Parses a `--memory-limit` value: a number of bytes with an optional binary suffix
/// (K, M, G, T, optionally followed by "iB" or "B"), e.g. `512M`, `4G`, `1.5GiB`, `1000000`.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let unit = unit.trim();
    let shift = match unit.to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        "T" | "TB" | "TIB" => 40,
        _ => {
            return Err(format!(
                "'{s}': unknown unit '{unit}' (use a byte count or K, M, G, T, e.g. 512M, 4G)"
            ));
        }
    };
    let value: f64 = number
        .parse()
        .map_err(|_| format!("'{s}' is not a size (e.g. 512M, 4G)"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes >= u64::MAX as f64 {
        return Err(format!("'{s}': the limit must be at least 1 byte"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(degree: usize, samples: usize) -> Extent {
        Extent {
            samples: vec![samples],
            degree: vec![degree],
            rational: false,
            erbs_locals: None,
            nested: Vec::new(),
            control_vertices: 0,
            control_bytes: 0,
            shared_tables: None,
        }
    }

    #[test]
    fn issue_example_is_dominated_by_the_hermite_tables() {
        // Degree 60, 5 000 000 samples, 20 derivatives: 5e6 × 21 × 61 f64 = 51.24e9 B of
        // tables (plus each sample's parameter and span) and 5e6 × 21 × 24 B of samples.
        let e = estimate(
            &curve(60, 5_000_000),
            SampleMode::Derivatives(20),
            Uses::default(),
        );
        assert_eq!(e.parts[0].what, "Hermite tables");
        assert_eq!(e.parts[0].bytes, 5_000_000 * (21 * 61 * 8 + 16));
        assert_eq!(e.parts[1].bytes, 5_000_000 * 21 * 24);
        assert_eq!(
            e.bytes(),
            5_000_000 * (21 * 61 * 8 + 16) + 5_000_000 * 21 * 24 + OBJECT_BYTES as u64
        );
        assert!(
            e.describe()
                .contains("5000000 samples × 21 derivative orders × 61 basis functions"),
            "{}",
            e.describe()
        );
    }

    #[test]
    fn derivative_rows_above_the_degree_are_not_kept() {
        let e = estimate(
            &curve(3, 1000),
            SampleMode::Derivatives(20),
            Uses::default(),
        );
        let tables = e.parts.iter().find(|p| p.what == "Hermite tables").unwrap();
        assert_eq!(tables.bytes, 1000 * (4 * 4 * 8 + 16));
    }

    #[test]
    fn render_mode_surfaces_count_normals_and_gpu_mirrors() {
        let s = Extent {
            samples: vec![512, 512],
            degree: vec![3, 3],
            rational: true,
            erbs_locals: None,
            nested: Vec::new(),
            control_vertices: 0,
            control_bytes: 0,
            shared_tables: None,
        };
        let e = estimate(
            &s,
            SampleMode::Render,
            Uses {
                gpu_slots: 3,
                control_displays: true,
                json_text: false,
            },
        );
        let part = |w: &str| e.parts.iter().find(|p| p.what == w).unwrap().bytes;
        let n = 512 * 512;
        assert_eq!(part("samples"), n * 3 * 24);
        assert_eq!(part("homogeneous samples"), n * 3 * 32);
        assert_eq!(part("normals"), n * 24);
        assert_eq!(part("GPU mirrors"), 3 * n * 24);
    }

    /// A control display's mirror is counted where it is drawn: every one when the nets can
    /// show, otherwise only an ERBS object's (its locals are drawn without the nets).
    #[test]
    fn control_mirrors_are_counted_where_control_displays_are_drawn() {
        let spline = Extent::polynomial(&[17, 17], &[3, 3], false).with_controls(16, 0);
        let erbs = Extent {
            erbs_locals: Some(vec![3, 3]),
            control_vertices: 3 * 3 * (81 + 16),
            ..spline.clone()
        };
        let mirrors = |x: &Extent, control_displays: bool| {
            let uses = Uses {
                gpu_slots: 1,
                control_displays,
                json_text: false,
            };
            estimate(x, SampleMode::Render, uses)
                .parts
                .iter()
                .find(|p| p.what == "GPU control mirrors")
                .map(|p| p.bytes)
        };
        let small = (GPU_SLOTS_ALWAYS * CONTROL_MIRROR) as u64;
        assert_eq!(mirrors(&spline, true), Some(small));
        assert_eq!(mirrors(&spline, false), None);
        let big = (GPU_SLOTS_ALWAYS * 3 * 3 * (81 + 16) * 3 * F32) as u64;
        assert_eq!(mirrors(&erbs, true), Some(big));
        assert_eq!(mirrors(&erbs, false), Some(big));
    }

    #[test]
    fn analysis_mode_surfaces_count_the_map_mirror() {
        let s = Extent {
            samples: vec![512, 512],
            degree: vec![3, 3],
            rational: false,
            erbs_locals: None,
            nested: Vec::new(),
            control_vertices: 0,
            control_bytes: 0,
            shared_tables: None,
        };
        let uses = Uses {
            gpu_slots: 3,
            control_displays: true,
            json_text: false,
        };
        let n = 512 * 512;
        let part = |mode, w: &str| {
            estimate(&s, mode, uses)
                .parts
                .iter()
                .find(|p| p.what == w)
                .map(|p| p.bytes)
        };
        assert_eq!(
            part(SampleMode::Analysis, "GPU map mirrors"),
            Some(3 * n * 4)
        );
        assert_eq!(part(SampleMode::Analysis, "curvatures"), Some(n * 16));
        assert_eq!(part(SampleMode::Render, "GPU map mirrors"), None);
    }

    #[test]
    fn sizes_parse_with_binary_units() {
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("4GiB"), Ok(4 << 30));
        assert_eq!(parse_size("1.5k"), Ok(1536));
        assert_eq!(parse_size("1000"), Ok(1000));
        assert!(parse_size("4X").is_err());
        assert!(parse_size("G").is_err());
        assert!(parse_size("0").is_err());
        assert!(parse_size("-1G").is_err());
    }

    #[test]
    fn address_space_limit_is_read_from_proc_limits() {
        let limited = "Limit                     Soft Limit           Hard Limit           Units     \nMax address space         2147483648           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limited), Some(2 << 30));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes     \n";
        assert_eq!(address_space_limit(unlimited), None);
    }

    /// A scene drawn on the GPU counts the driver's draw state once, whatever its objects, and
    /// a refusal of the whole names what the objects share; without a GPU neither appears.
    #[test]
    fn the_driver_draw_state_is_counted_once_per_drawn_scene() {
        let patch = Extent::polynomial(&[17, 17], &[3, 3], false).with_controls(16, 0);
        let objects = [("a", patch.clone()), ("b", patch.clone())];
        let uses = |gpu_slots| Uses {
            gpu_slots,
            control_displays: false,
            json_text: false,
        };
        let each = estimate(&patch, SampleMode::Render, uses(1)).bytes();
        let shared = shared_estimate(&objects, uses(1));
        assert_eq!(
            shared.part_bytes("GPU driver draw state"),
            DRIVER_DRAW_STATE as u64
        );
        let roomy = MemoryBudget::from_flag(Some(1 << 40));
        let total = check_extents(&objects, SampleMode::Render, uses(1), &roomy).unwrap();
        assert_eq!(total, 2 * each + shared.bytes());
        let tight = MemoryBudget::from_flag(Some(total - 1));
        let e = check_extents(&objects, SampleMode::Render, uses(1), &tight).unwrap_err();
        assert!(e.starts_with("2 objects need about"), "{e}");
        assert!(
            e.contains("; what the GPU shares between objects, about 26."),
            "{e}"
        );
        let alone = check_extents(&objects[..1], SampleMode::Render, uses(1), &roomy).unwrap();
        let tight_alone = MemoryBudget::from_flag(Some(alone - 1));
        let one =
            check_extents(&objects[..1], SampleMode::Render, uses(1), &tight_alone).unwrap_err();
        assert!(e.contains(" in all to pre-evaluate and draw "), "{e}");
        assert!(one.starts_with("1 object needs about"), "{one}");
        let on_cpu = check_extents(&objects, SampleMode::Render, uses(0), &roomy).unwrap();
        assert_eq!(
            on_cpu,
            2 * estimate(&patch, SampleMode::Render, uses(0)).bytes()
        );
        let tight = MemoryBudget::from_flag(Some(on_cpu - 1));
        let e = check_extents(&objects, SampleMode::Render, uses(0), &tight).unwrap_err();
        assert!(!e.contains("the GPU shares"), "{e}");
    }

    #[test]
    fn builds_over_the_build_budget_are_refused_in_one_line() {
        let budget = MemoryBudget::from_flag(Some(1 << 20));
        let refused = budget.check_build("3 things", 2 << 20);
        let fits = budget.check_build("3 things", 1 << 20);
        let e = refused.unwrap_err();
        assert!(e.starts_with("3 things need about 2.0 MiB"), "{e}");
        assert!(!e.contains('\n'));
        assert_eq!(fits, Ok(()));
    }

    #[test]
    fn physical_memory_is_read_from_meminfo() {
        assert_eq!(
            mem_total("MemTotal:       24683656 kB\nMemFree: 1 kB\n"),
            Some(24683656 * 1024)
        );
        assert_eq!(mem_total("nothing"), None);
    }

    #[test]
    fn bytes_are_printed_in_binary_units() {
        assert_eq!(format_bytes(512), "512 B");
        assert_eq!(format_bytes(1536), "1.5 KiB");
        assert_eq!(format_bytes(12 << 30), "12.0 GiB");
    }
}

//! Surface analysis maps: which quantity colours a surface (Gaussian, mean or a principal
//! curvature, or zebra stripes), its colour scale, and the legend that explains it.
//!
//! The scale is diverging — blue for negative, white for zero, red for positive — over a
//! symmetric range ±R, R the 90th percentile of |value| (so the most curved tenth — a cusp, a
//! collapsed edge, a spout — does not wash the rest of the map out). By default each surface gets its own R, so a gently
//! curved surface next to a strongly curved one keeps its colours ([`MapRange`]). Values are
//! mapped onto [−1, 1] per surface on the CPU and the shader applies the scale ([`SCALE`] is
//! its table), so the legend shows exactly what the surface does.

use crate::editor::Document;
use crate::geom::bounds::Bounds;
use crate::gpu::OverlayVertex;
use crate::gpu::font::{Font, TextSize, push_rect};
use crate::sampling::curvature::principal;
use glam::DVec3;
use std::collections::HashMap;

/// What an analysis view shows on surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SurfaceMap {
    /// K = κ1 κ2.
    Gaussian,
    /// H = (κ1 + κ2)/2 (sign with the normal Su × Sv).
    Mean,
    /// κ_max = H + √(H² − K).
    MaxPrincipal,
    /// κ_min = H − √(H² − K).
    MinPrincipal,
    /// Reflection lines: stripes of a striped environment reflected in the surface, which
    /// bend smoothly across G2 joins and kink at G1 ones.
    Zebra,
}

impl SurfaceMap {
    pub const ALL: [SurfaceMap; 5] = [
        SurfaceMap::Gaussian,
        SurfaceMap::Mean,
        SurfaceMap::MaxPrincipal,
        SurfaceMap::MinPrincipal,
        SurfaceMap::Zebra,
    ];

    /// The `render --analysis` name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            SurfaceMap::Gaussian => "gaussian",
            SurfaceMap::Mean => "mean",
            SurfaceMap::MaxPrincipal => "kmax",
            SurfaceMap::MinPrincipal => "kmin",
            SurfaceMap::Zebra => "zebra",
        }
    }

    /// What the legend calls it.
    #[must_use]
    pub fn title(self) -> &'static str {
        match self {
            SurfaceMap::Gaussian => "Gaussian curvature K",
            SurfaceMap::Mean => "mean curvature H",
            SurfaceMap::MaxPrincipal => "max principal curvature",
            SurfaceMap::MinPrincipal => "min principal curvature",
            SurfaceMap::Zebra => "zebra stripes (reflection lines)",
        }
    }

    /// Parses a `--analysis` value.
    pub fn parse(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|m| m.name()).collect();
                format!(
                    "unknown analysis '{s}' (expected one of: {})",
                    names.join(", ")
                )
            })
    }

    /// The next map for the viewer's key: Gaussian → mean → κ_max → κ_min → zebra → off.
    #[must_use]
    pub fn next(current: Option<Self>) -> Option<Self> {
        match current {
            None => Some(SurfaceMap::Gaussian),
            Some(m) => {
                let i = Self::ALL.iter().position(|&x| x == m).unwrap_or(0);
                Self::ALL.get(i + 1).copied()
            }
        }
    }

    /// Whether the map needs second partials (all but zebra, which needs only normals).
    #[must_use]
    pub fn needs_curvature(self) -> bool {
        self != SurfaceMap::Zebra
    }

    /// The mapped value of a sample's [K, H] (NaN where undefined).
    #[inline]
    #[must_use]
    pub fn value(self, kh: [f64; 2]) -> f64 {
        match self {
            SurfaceMap::Gaussian => kh[0],
            SurfaceMap::Mean => kh[1],
            SurfaceMap::MaxPrincipal => principal(kh)[0],
            SurfaceMap::MinPrincipal => principal(kh)[1],
            SurfaceMap::Zebra => 0.0,
        }
    }
}

/// Which percentile of |value| sets a colour scale's half range.
pub const RANGE_PERCENTILE: f64 = 0.90;

/// How the colour scale of a curvature map is chosen (`--map-range`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MapRange {
    /// One symmetric range over every surface: the most curved surface sets it.
    Shared,
    /// Each surface its own symmetric range (the default).
    PerObject,
    /// `low` is the blue end and `high` the red end on every surface, white halfway.
    Fixed { low: f64, high: f64 },
}

impl MapRange {
    /// Parses `shared`, `per-object` or `MIN,MAX` (finite, MIN < MAX).
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "shared" => return Ok(MapRange::Shared),
            "per-object" => return Ok(MapRange::PerObject),
            _ => {}
        }
        let bad = || format!("'{s}' is not shared, per-object or MIN,MAX (for example -0.5,0.5)");
        let (a, b) = s.split_once(',').ok_or_else(bad)?;
        let (low, high): (f64, f64) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if !(low.is_finite() && high.is_finite() && low < high) {
            return Err(format!(
                "'{s}': MIN and MAX must be finite numbers with MIN < MAX"
            ));
        }
        Ok(MapRange::Fixed { low, high })
    }
}

/// The values a surface's colour scale spans: `low` is the blue end, `high` the red end, the
/// middle white.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapScale {
    pub low: f64,
    pub high: f64,
}

impl MapScale {
    /// ±r.
    #[must_use]
    pub fn symmetric(r: f64) -> Self {
        Self { low: -r, high: r }
    }

    /// Where `v` falls on the scale, −1 (low) … 1 (high); NaN stays NaN.
    #[must_use]
    pub fn unit(&self, v: f64) -> f64 {
        (2.0 * v - (self.low + self.high)) / (self.high - self.low)
    }
}

/// How far apart two surfaces' bounding boxes may be and still touch, relative to the larger
/// box's diagonal: room for rounding along a shared edge (and for an exporter's few digits),
/// far less than any gap a user would place between separate objects.
pub const TOUCH_TOLERANCE: f64 = 1e-3;

/// The surfaces of `doc` in families that share a colour scale under [`MapRange::PerObject`]:
/// the patches of one model. A family is the surfaces whose names differ only in a trailing
/// number (`teapot_00` … `teapot_31`) and whose bounding boxes touch or overlap, directly or
/// through other members ([`TOUCH_TOLERANCE`]): numbered names alone would also join separate
/// objects (Blender's `Surface.001`, `Surface.002`, …; unnamed OBJ objects `surface`,
/// `surface.2`, …), which seldom touch, while a model's patches share their edges. A family is
/// named by the common stem (by its first and last member's names where the stem has several
/// families; by the surface's own name when it is alone). In scene order of first members.
#[must_use]
pub fn surface_families(doc: &Document) -> Vec<(String, Vec<usize>)> {
    let mut stems: HashMap<&str, Vec<usize>> = HashMap::new();
    for (i, o) in doc.objects.iter().enumerate() {
        if o.sampled.model().is_surface() {
            stems.entry(name_stem(&o.name)).or_default().push(i);
        }
    }
    let mut families: Vec<(String, Vec<usize>)> = Vec::new();
    for (stem, members) in stems {
        if members.len() == 1 {
            families.push((doc.objects[members[0]].name.clone(), members));
            continue;
        }
        let boxes = crate::parallel::map(&members, |&i| {
            let mut b = Bounds::EMPTY;
            let g = doc.objects[i].sampled.grid();
            for p in g.data.iter().step_by(g.stride()) {
                b.include(*p);
            }
            b
        });
        let parts = touching_parts(&boxes);
        let whole = parts.len() == 1;
        for part in parts {
            let part: Vec<usize> = part.into_iter().map(|k| members[k]).collect();
            let name = match part.as_slice() {
                _ if whole => stem.to_string(),
                [one] => doc.objects[*one].name.clone(),
                [first, .., last] => {
                    format!("{}…{}", doc.objects[*first].name, doc.objects[*last].name)
                }
                [] => unreachable!("a part has a member"),
            };
            families.push((name, part));
        }
    }
    families.sort_unstable_by_key(|(_, members)| members[0]);
    families
}

/// A surface name without its trailing number and the separator before it (`teapot_07` →
/// `teapot`, `Surface.001` → `Surface`); the whole name when that leaves nothing or nothing
/// was removed.
fn name_stem(name: &str) -> &str {
    let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
    let stem = stem.trim_end_matches(['_', '-', '.', ' ']);
    if stem.is_empty() || stem.len() == name.len() {
        name
    } else {
        stem
    }
}

/// `boxes` split into the groups connected by touching or overlapping boxes (each grown by
/// [`TOUCH_TOLERANCE`] of its diagonal), each group in index order, the groups by their
/// first index. A box that is empty or not finite is a group of its own.
///
/// Candidate pairs come from a hierarchical grid rather than all n² pairs: level L has cells
/// `base·2^L` wide (`base` the median box size) and holds the boxes no larger than its cells,
/// so a box lies in at most 8 cells of its level, and finds every box it may touch in at most
/// 8 cells of its own and each coarser level. Work is O(n · levels + touching pairs).
fn touching_parts(boxes: &[Bounds]) -> Vec<Vec<usize>> {
    let grown: Vec<Option<Bounds>> = boxes
        .iter()
        .map(|b| {
            let finite = !b.is_empty() && b.min.is_finite() && b.max.is_finite();
            finite.then(|| {
                let pad = DVec3::splat(TOUCH_TOLERANCE * (b.max - b.min).length());
                Bounds {
                    min: b.min - pad,
                    max: b.max + pad,
                }
            })
        })
        .collect();
    let extent = |b: &Bounds| (b.max - b.min).max_element();
    let mut sizes: Vec<f64> = grown.iter().flatten().map(extent).collect();
    let base = if sizes.is_empty() {
        1.0
    } else {
        let mid = sizes.len() / 2;
        let (_, m, _) = sizes.select_nth_unstable_by(mid, f64::total_cmp);
        if *m > 0.0 { *m } else { 1.0 }
    };
    // The level whose cells are at least as wide as the box.
    let level_of = |b: &Bounds| (extent(b) / base).max(1.0).log2().ceil() as i32;
    let cells = |b: &Bounds, level: i32| {
        let size = base * 2f64.powi(level);
        let lo = (b.min / size).floor().as_i64vec3();
        let hi = (b.max / size).floor().as_i64vec3();
        (lo.x..=hi.x).flat_map(move |x| {
            (lo.y..=hi.y).flat_map(move |y| (lo.z..=hi.z).map(move |z| [x, y, z]))
        })
    };
    let mut grid: HashMap<(i32, [i64; 3]), Vec<usize>> = HashMap::new();
    let mut levels: Vec<i32> = Vec::new();
    for (i, b) in grown.iter().enumerate() {
        let Some(b) = b else { continue };
        let level = level_of(b);
        levels.push(level);
        for cell in cells(b, level) {
            grid.entry((level, cell)).or_default().push(i);
        }
    }
    levels.sort_unstable();
    levels.dedup();
    let mut parent: Vec<usize> = (0..boxes.len()).collect();
    for (i, b) in grown.iter().enumerate() {
        let Some(b) = b else { continue };
        let own = level_of(b);
        for &level in levels.iter().filter(|&&l| l >= own) {
            for cell in cells(b, level) {
                for &j in grid.get(&(level, cell)).into_iter().flatten() {
                    let other = grown[j]
                        .as_ref()
                        .expect("only finite boxes are in the grid");
                    let touch = b.min.cmple(other.max).all() && other.min.cmple(b.max).all();
                    if j != i && touch {
                        union(&mut parent, i, j);
                    }
                }
            }
        }
    }
    let mut parts: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..boxes.len() {
        let root = find(&mut parent, i);
        parts.entry(root).or_default().push(i);
    }
    let mut parts: Vec<Vec<usize>> = parts.into_values().collect();
    parts.sort_unstable_by_key(|p| p[0]);
    parts
}

/// The representative of `i`'s set (union-find, with path halving).
fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the sets of `a` and `b`, keeping the smaller representative.
fn union(parent: &mut [usize], a: usize, b: usize) {
    let (a, b) = (find(parent, a), find(parent, b));
    parent[a.max(b)] = a.min(b);
}

/// The colour scale of every object of `doc` for `map`, by object index (curves get one too,
/// unused).
#[must_use]
pub fn map_scales(doc: &Document, map: SurfaceMap, range: MapRange) -> Vec<MapScale> {
    let families = match range {
        MapRange::PerObject => surface_families(doc),
        _ => Vec::new(),
    };
    map_scales_of(doc, map, range, &families)
}

/// [`map_scales`] with the surface families already found (`families`, from
/// [`surface_families`]; used by [`MapRange::PerObject`] only).
#[must_use]
pub fn map_scales_of(
    doc: &Document,
    map: SurfaceMap,
    range: MapRange,
    families: &[(String, Vec<usize>)],
) -> Vec<MapScale> {
    let values = |i: usize| {
        doc.objects[i]
            .sampled
            .grid()
            .curvatures
            .iter()
            .flatten()
            .map(move |&kh| map.value(kh))
    };
    let n = doc.objects.len();
    match range {
        MapRange::Fixed { low, high } => vec![MapScale { low, high }; n],
        MapRange::Shared => vec![MapScale::symmetric(symmetric_range((0..n).flat_map(values))); n],
        MapRange::PerObject => {
            let mut scales = vec![MapScale::symmetric(1.0); n];
            for (_, members) in families {
                let r = symmetric_range(members.iter().flat_map(|&i| values(i)));
                for &i in members {
                    scales[i] = MapScale::symmetric(r);
                }
            }
            scales
        }
    }
}

/// The colour scale's half range R (values map to ±R): the 90th percentile of |value| over
/// `values` (NaN ignored); 1 when nothing is finite or everything is 0. Curvature is heavy
/// tailed (the teapot's |K|: median 1.5, 90th percentile 21, 98th 79), so a higher percentile
/// leaves most of a surface white.
pub fn symmetric_range(values: impl Iterator<Item = f64>) -> f64 {
    let mut mags: Vec<f64> = values.filter(|v| v.is_finite()).map(f64::abs).collect();
    if mags.is_empty() {
        return 1.0;
    }
    let k = ((mags.len() - 1) as f64 * RANGE_PERCENTILE).round() as usize;
    let (_, r, _) = mags.select_nth_unstable_by(k, f64::total_cmp);
    let r = *r;
    if r > 0.0 { r } else { 1.0 }
}

/// The diverging scale at s ∈ [−1, 1] (clamped): (position, linear RGB) stops, interpolated
/// linearly. Shared with the shader (shaders/map.frag).
pub const SCALE: [(f32, [f32; 3]); 5] = [
    (-1.0, [0.02, 0.10, 0.60]),
    (-0.5, [0.25, 0.50, 0.95]),
    (0.0, [0.92, 0.92, 0.92]),
    (0.5, [0.95, 0.45, 0.25]),
    (1.0, [0.60, 0.02, 0.02]),
];

/// Linear RGB of the scale at s; NaN (undefined) is mid grey.
#[must_use]
pub fn scale_color(s: f32) -> [f32; 3] {
    if s.is_nan() {
        return [0.3, 0.3, 0.3];
    }
    let s = s.clamp(-1.0, 1.0);
    for w in SCALE.windows(2) {
        let ((a, ca), (b, cb)) = (w[0], w[1]);
        if s <= b {
            let t = (s - a) / (b - a);
            return [0, 1, 2].map(|i| ca[i] + (cb[i] - ca[i]) * t);
        }
    }
    SCALE[SCALE.len() - 1].1
}

/// sRGB bytes of a linear colour (the overlay takes sRGB).
fn srgb(c: [f32; 3]) -> [u8; 4] {
    let enc = |x: f32| {
        let x = x.clamp(0.0, 1.0);
        let v = if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (v * 255.0 + 0.5) as u8
    };
    [enc(c[0]), enc(c[1]), enc(c[2]), 255]
}

const PANEL: [u8; 4] = super::analysis::PANEL;
/// The colour of a legend's text (sRGB).
pub const LEGEND_TEXT: [u8; 4] = [230, 232, 238, 255];

/// The height of a legend slot: a colour-scale legend and the gap above it.
pub const LEGEND_STEP: f32 = 96.0;

/// Where a legend goes and what it names: `slot` 0 is the lowest, bottom right of a
/// `width × height` image, each further slot stacked above it; `name` (a surface's) is added to
/// the title when the scales differ per surface.
#[derive(Debug, Clone, Copy)]
pub struct LegendPlace<'a> {
    pub name: Option<&'a str>,
    pub slot: usize,
    pub width: f32,
    pub height: f32,
}

/// Where the parts of a legend go (top-left corners, in pixels), so that tests can read back
/// what [`legend`] draws.
#[derive(Debug, Clone, PartialEq)]
pub struct LegendLayout {
    /// x, y, width, height.
    pub panel: [f32; 4],
    pub title: (String, [f32; 2]),
    /// The colour bar's top-left corner (none for zebra).
    pub bar: Option<[f32; 2]>,
    /// The low, middle and high values under the bar (none for zebra).
    pub labels: Vec<(String, [f32; 2])>,
}

/// Width and height of a legend's colour bar.
const BAR: [f32; 2] = [280.0, 16.0];

/// The layout of the legend of `map` with colour scale `scale` at `place`.
#[must_use]
pub fn legend_layout(
    map: SurfaceMap,
    scale: MapScale,
    font: &Font,
    place: LegendPlace<'_>,
) -> LegendLayout {
    let size = TextSize::Normal;
    let title = match place.name {
        Some(name) if map != SurfaceMap::Zebra => format!("{}: {name}", map.title()),
        _ => map.title().to_string(),
    };
    let [tw, th] = font.text_size(&title, size);
    let [bar_w, bar_h] = BAR;
    let panel_w = tw.max(bar_w) + 24.0;
    let panel_h = if map == SurfaceMap::Zebra {
        th + 16.0
    } else {
        th + bar_h + th + 28.0
    };
    let x = place.width - panel_w - 12.0;
    let y = place.height - panel_h - 64.0 - place.slot as f32 * LEGEND_STEP;
    let mut layout = LegendLayout {
        panel: [x, y, panel_w, panel_h],
        title: (title, [x + 12.0, y + 8.0]),
        bar: None,
        labels: Vec::new(),
    };
    if map == SurfaceMap::Zebra {
        return layout;
    }
    let (bx, by) = (x + 12.0, y + th + 12.0);
    layout.bar = Some([bx, by]);
    let ly = by + bar_h + 4.0;
    let number = |x: f64| {
        let t = super::numbers::short(x.abs());
        if x < 0.0 { format!("-{t}") } else { t }
    };
    let lo = number(scale.low);
    let mid = number(0.5 * (scale.low + scale.high));
    let hi = number(scale.high);
    let [zw, _] = font.text_size(&mid, size);
    let [hw, _] = font.text_size(&hi, size);
    layout.labels = vec![
        (lo, [bx, ly]),
        (mid, [bx + 0.5 * (bar_w - zw), ly]),
        (hi, [bx + bar_w - hw, ly]),
    ];
    layout
}

/// The legend of `map` with colour scale `scale`: the title, a colour bar from its low to its
/// high end with the end and middle values (zebra: a note instead).
#[must_use]
pub fn legend(
    map: SurfaceMap,
    scale: MapScale,
    font: &Font,
    place: LegendPlace<'_>,
) -> Vec<OverlayVertex> {
    let layout = legend_layout(map, scale, font, place);
    let mut v = Vec::new();
    let size = TextSize::Normal;
    let [x, y, w, h] = layout.panel;
    push_rect(&mut v, x, y, w, h, PANEL);
    let (title, [tx, ty]) = &layout.title;
    font.push_text(&mut v, title, *tx, *ty, size, LEGEND_TEXT);
    if let Some([bx, by]) = layout.bar {
        let [bar_w, bar_h] = BAR;
        let steps = 56;
        let w = bar_w / steps as f32;
        for k in 0..steps {
            let s = -1.0 + 2.0 * (k as f32 + 0.5) / steps as f32;
            push_rect(
                &mut v,
                bx + k as f32 * w,
                by,
                w + 0.5,
                bar_h,
                srgb(scale_color(s)),
            );
        }
    }
    for (text, [lx, ly]) in &layout.labels {
        font.push_text(&mut v, text, *lx, *ly, size, LEGEND_TEXT);
    }
    v
}

/// What the line above a stack of legends says when `families` more families (`surfaces`
/// surfaces in all) had no room for a legend.
#[must_use]
pub fn legend_note_text(families: usize, surfaces: usize) -> String {
    let s = if surfaces == 1 { "" } else { "s" };
    format!("+{families} more: {surfaces} surface{s} without a legend")
}

/// The layout of a one-line note on a panel, bottom-aligned in `place`'s slot like a legend:
/// the panel (x, y, width, height) and the text's top-left corner.
#[must_use]
pub fn legend_note_layout(text: &str, font: &Font, place: LegendPlace<'_>) -> ([f32; 4], [f32; 2]) {
    let [tw, th] = font.text_size(text, TextSize::Normal);
    let (w, h) = (tw + 24.0, th + 16.0);
    let x = place.width - w - 12.0;
    let y = place.height - h - 64.0 - place.slot as f32 * LEGEND_STEP;
    ([x, y, w, h], [x + 12.0, y + 8.0])
}

/// The height [`legend_note`] takes.
#[must_use]
pub fn legend_note_height(font: &Font) -> f32 {
    font.text_size("+", TextSize::Normal)[1] + 16.0
}

/// A one-line note on a panel, bottom-aligned in `place`'s slot like a legend.
#[must_use]
pub fn legend_note(text: &str, font: &Font, place: LegendPlace<'_>) -> Vec<OverlayVertex> {
    let ([x, y, w, h], [tx, ty]) = legend_note_layout(text, font, place);
    let mut v = Vec::new();
    push_rect(&mut v, x, y, w, h, PANEL);
    font.push_text(&mut v, text, tx, ty, TextSize::Normal, LEGEND_TEXT);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_ends_and_middle() {
        let near = |a: [f32; 3], b: [f32; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-6);
        assert!(near(scale_color(-1.0), SCALE[0].1));
        assert!(near(scale_color(0.0), SCALE[2].1));
        assert!(near(scale_color(7.0), SCALE[4].1));
        assert!(!near(scale_color(0.1), SCALE[2].1));
        let c = scale_color(0.25);
        for i in 0..3 {
            let mid = 0.5 * (SCALE[2].1[i] + SCALE[3].1[i]);
            assert!((c[i] - mid).abs() < 1e-6);
        }
    }

    #[test]
    fn range_ignores_the_worst_tenth_and_nan() {
        let mut v: Vec<f64> = (0..100).map(|i| i as f64 / 100.0).collect();
        v.push(f64::NAN);
        v.extend([1e9; 10]);
        let r = symmetric_range(v.into_iter());
        assert!((0.97..=1.0).contains(&r), "{r}");
        assert_eq!(symmetric_range([0.0, 0.0].into_iter()), 1.0);
        assert_eq!(symmetric_range([f64::NAN].into_iter()), 1.0);
    }

    #[test]
    fn map_ranges_parse_and_scales_map_to_the_unit_range() {
        assert_eq!(MapRange::parse("shared"), Ok(MapRange::Shared));
        assert_eq!(MapRange::parse("per-object"), Ok(MapRange::PerObject));
        assert_eq!(
            MapRange::parse("-0.5, 2"),
            Ok(MapRange::Fixed {
                low: -0.5,
                high: 2.0
            })
        );
        for bad in ["", "own", "1", "2,1", "0,0", "nan,1", "0,inf", "a,b"] {
            assert!(MapRange::parse(bad).is_err(), "{bad}");
        }
        let s = MapScale {
            low: -0.5,
            high: 2.0,
        };
        assert_eq!([s.unit(-0.5), s.unit(0.75), s.unit(2.0)], [-1.0, 0.0, 1.0]);
        assert!(s.unit(f64::NAN).is_nan());
        assert_eq!(MapScale::symmetric(4.0).unit(-1.0), -0.25);
    }

    fn cube(at: [f64; 3], size: f64) -> Bounds {
        let min = DVec3::from(at);
        Bounds {
            min,
            max: min + DVec3::splat(size),
        }
    }

    #[test]
    fn boxes_join_when_they_touch_directly_or_through_others() {
        // A chain of unit boxes sharing faces (one face apart by rounding), two boxes a
        // clear gap away, one box inside a large one, a NaN box, and the large box touching
        // the chain's end.
        let mut boxes: Vec<Bounds> = (0..5).map(|k| cube([k as f64, 0.0, 0.0], 1.0)).collect();
        boxes[3].min.x += 1e-12;
        boxes.push(cube([0.0, 3.0, 0.0], 1.0)); // 5: alone, 2 above the chain
        boxes.push(cube([0.0, 4.5, 0.0], 1.0)); // 6: alone, 0.5 above box 5
        boxes.push(cube([5.0 + 1e-4, 0.0, 0.0], 100.0)); // 7: within the tolerance of box 4
        boxes.push(cube([50.0, 50.0, 50.0], 0.1)); // 8: inside box 7
        boxes.push(Bounds {
            min: DVec3::splat(f64::NAN),
            max: DVec3::splat(f64::NAN),
        }); // 9
        boxes.push(Bounds::EMPTY); // 10
        let parts = touching_parts(&boxes);
        assert_eq!(
            parts,
            vec![
                vec![0, 1, 2, 3, 4, 7, 8],
                vec![5],
                vec![6],
                vec![9],
                vec![10]
            ]
        );
        // Negative control: a gap of 1 % of the size keeps boxes apart.
        let apart = [cube([0.0; 3], 1.0), cube([1.01, 0.0, 0.0], 1.0)];
        assert_eq!(touching_parts(&apart), vec![vec![0], vec![1]]);
    }

    #[test]
    fn a_grid_of_touching_tiles_is_one_part_and_spaced_tiles_are_many() {
        let tiles = |step: f64| -> Vec<Bounds> {
            (0..40 * 40)
                .map(|k| cube([(k % 40) as f64 * step, (k / 40) as f64 * step, 0.0], 1.0))
                .collect()
        };
        assert_eq!(touching_parts(&tiles(1.0)).len(), 1);
        assert_eq!(touching_parts(&tiles(1.5)).len(), 1600);
    }

    #[test]
    fn stems_drop_a_trailing_number_and_its_separator() {
        assert_eq!(name_stem("teapot_07"), "teapot");
        assert_eq!(name_stem("Surface.001"), "Surface");
        assert_eq!(name_stem("surface"), "surface");
        assert_eq!(name_stem("42"), "42");
        assert_eq!(name_stem("t3_teapot_12"), "t3_teapot");
    }

    #[test]
    fn map_names_round_trip() {
        for m in SurfaceMap::ALL {
            assert_eq!(SurfaceMap::parse(m.name()), Ok(m));
        }
        assert!(SurfaceMap::parse("gauss").unwrap_err().contains("gaussian"));
        let mut m = None;
        let mut seen = Vec::new();
        loop {
            m = SurfaceMap::next(m);
            match m {
                Some(x) => seen.push(x),
                None => break,
            }
        }
        assert_eq!(seen, SurfaceMap::ALL);
    }
}

//! Surface analysis maps: which quantity colours a surface (Gaussian, mean or a principal
//! curvature, or zebra stripes), its colour scale, and the legend that explains it.
//!
//! The scale is diverging — blue for negative, white for zero, red for positive — over a
//! symmetric range ±R, R the 98th percentile of |value| over the analysed surfaces (so a few
//! extreme samples near a singular point do not wash the map out). The shader applies the
//! same scale ([`SCALE`] is its table), so the legend shows exactly what the surface does.

use crate::editor::Document;
use crate::gpu::OverlayVertex;
use crate::gpu::font::{Font, TextSize, push_rect};
use crate::sampling::curvature::principal;

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
    pub fn needs_curvature(self) -> bool {
        self != SurfaceMap::Zebra
    }

    /// The mapped value of a sample's [K, H] (NaN where undefined).
    #[inline]
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

/// The half range of `map`'s colour scale over every surface of `doc` (see
/// [`symmetric_range`]).
#[must_use]
pub fn map_range(doc: &Document, map: SurfaceMap) -> f64 {
    symmetric_range(doc.objects.iter().flat_map(|o| {
        o.sampled
            .grid()
            .curvatures
            .iter()
            .flatten()
            .map(move |&kh| map.value(kh))
    }))
}

/// The colour scale's half range R (values map to ±R): the 98th percentile of |value| over
/// `values` (NaN ignored); 1 when nothing is finite or everything is 0.
pub fn symmetric_range(values: impl Iterator<Item = f64>) -> f64 {
    let mut mags: Vec<f64> = values.filter(|v| v.is_finite()).map(f64::abs).collect();
    if mags.is_empty() {
        return 1.0;
    }
    let k = ((mags.len() - 1) as f64 * 0.98).round() as usize;
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
const TEXT: [u8; 4] = [230, 232, 238, 255];

/// The legend of `map` with half range `r`, bottom right of a `width × height` image: the title,
/// a colour bar from −R to +R with its end and middle values (zebra: a note instead).
pub fn legend(map: SurfaceMap, r: f64, font: &Font, width: f32, height: f32) -> Vec<OverlayVertex> {
    let mut v = Vec::new();
    let size = TextSize::Normal;
    let title = map.title();
    let [tw, th] = font.text_size(title, size);
    let (bar_w, bar_h) = (280.0f32, 16.0f32);
    let panel_w = tw.max(bar_w) + 24.0;
    let panel_h = if map == SurfaceMap::Zebra {
        th + 16.0
    } else {
        th + bar_h + th + 28.0
    };
    let (x, y) = (width - panel_w - 12.0, height - panel_h - 64.0);
    push_rect(&mut v, x, y, panel_w, panel_h, PANEL);
    font.push_text(&mut v, title, x + 12.0, y + 8.0, size, TEXT);
    if map == SurfaceMap::Zebra {
        return v;
    }
    let (bx, by) = (x + 12.0, y + th + 12.0);
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
    let ly = by + bar_h + 4.0;
    let lo = format!("-{}", super::style::short(r));
    let hi = super::style::short(r);
    font.push_text(&mut v, &lo, bx, ly, size, TEXT);
    let [zw, _] = font.text_size("0", size);
    font.push_text(&mut v, "0", bx + 0.5 * (bar_w - zw), ly, size, TEXT);
    let [hw, _] = font.text_size(&hi, size);
    font.push_text(&mut v, &hi, bx + bar_w - hw, ly, size, TEXT);
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
    fn range_ignores_the_worst_two_percent_and_nan() {
        let mut v: Vec<f64> = (0..100).map(|i| i as f64 / 100.0).collect();
        v.push(f64::NAN);
        v.push(1e9);
        let r = symmetric_range(v.into_iter());
        assert!((0.97..=1.0).contains(&r), "{r}");
        assert_eq!(symmetric_range([0.0, 0.0].into_iter()), 1.0);
        assert_eq!(symmetric_range([f64::NAN].into_iter()), 1.0);
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

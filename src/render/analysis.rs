//! Curve analysis shown in the viewer and `prespline render`: what a curve is at its joins
//! (continuity badges) and the osculating circle with curvature and torsion at a parameter.
//! Pure f64 computations from the model; drawing them is the overlays' business.

pub use super::numbers::short;
use crate::editor::Document;
use crate::geom::continuity::{JoinClass, classify};
use crate::geom::differential::frenet_frame;
use crate::geom::{BSplineCurve, ErbsCurve};
use crate::gpu::font::{Font, TextSize, push_rect};
use crate::gpu::{LineVertex, OverlayVertex};
use crate::model::{Model, ModelRef};
use glam::DVec3;

/// A curve of any kind, evaluable with one-sided limits.
pub enum CurveEval<'a> {
    /// B-spline, Bézier and NURBS curves, and the Bézier chains of Catmull–Rom and Bézier
    /// splines (with the chain's segment boundaries).
    BSpline {
        curve: std::borrow::Cow<'a, BSplineCurve>,
        junctions: Option<Vec<f64>>,
        /// A closed chain (closed Catmull–Rom): its end meets its start, one more junction.
        closed: bool,
    },
    Erbs(&'a ErbsCurve),
}

impl<'a> CurveEval<'a> {
    /// The curve of a curve model; `None` for surfaces.
    #[must_use]
    pub fn of(model: ModelRef<'a>) -> Option<Self> {
        use std::borrow::Cow;
        Some(match model {
            ModelRef::Curve(c) => CurveEval::BSpline {
                curve: Cow::Borrowed(c.curve()),
                junctions: None,
                closed: false,
            },
            ModelRef::ErbsCurve(c) => CurveEval::Erbs(c.curve()),
            _ if model.is_surface() => return None,
            // Chains of Bézier segments: the de Boor form of the chain, with its junctions.
            other => {
                let (junctions, closed) = other.kind().junctions()?;
                let Some(Model::Curve(chain)) = other.to_bspline_curve() else {
                    return None;
                };
                CurveEval::BSpline {
                    curve: Cow::Owned(chain.curve().clone()),
                    junctions: Some(junctions),
                    closed,
                }
            }
        })
    }

    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        match self {
            CurveEval::BSpline { curve, .. } => curve.domain(),
            CurveEval::Erbs(c) => c.domain(),
        }
    }

    /// c, c', …, c^(n) at t (the right limit at a knot).
    #[must_use]
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<DVec3> {
        match self {
            CurveEval::BSpline { curve, .. } => curve.derivatives(t, n),
            CurveEval::Erbs(c) => c.derivatives(t, n),
        }
    }

    /// The parameters a badge goes to: the segment junctions of Catmull–Rom and Bézier
    /// splines (a closed chain's seam too, as the domain's start), the interior knots of
    /// multiplicity > 1 of B-spline curves (where their guaranteed continuity drops below
    /// C^(d−1)); none for ERBS curves (C^∞ blends).
    #[must_use]
    pub fn join_params(&self) -> Vec<f64> {
        match self {
            CurveEval::BSpline {
                junctions: Some(j),
                closed,
                ..
            } => {
                let seam = if *closed { &j[..1] } else { &[] };
                seam.iter().chain(&j[1..j.len() - 1]).copied().collect()
            }
            CurveEval::BSpline { curve, .. } => {
                let (a, b) = curve.domain();
                // Runs of equal knots in one pass (millions of knots are possible).
                curve
                    .knots()
                    .chunk_by(|x, y| x == y)
                    .filter(|run| run.len() > 1 && run[0] > a && run[0] < b)
                    .map(|run| run[0])
                    .collect()
            }
            CurveEval::Erbs(_) => Vec::new(),
        }
    }

    /// Left and right limits of c, c', c'' at t. At a closed chain's seam (the domain's start)
    /// the left limit is the one at the domain's end.
    #[must_use]
    pub fn limits(&self, t: f64) -> Option<([DVec3; 3], [DVec3; 3])> {
        let CurveEval::BSpline { curve, closed, .. } = self else {
            return None;
        };
        let (a, b) = curve.domain();
        let left_at = if *closed && t == a { b } else { t };
        let arr = |v: Vec<DVec3>| [v[0], v[1], v[2]];
        Some((
            arr(curve.one_sided_derivatives(left_at, 2, true)),
            arr(curve.one_sided_derivatives(t, 2, false)),
        ))
    }
}

/// One continuity badge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Join {
    pub t: f64,
    pub position: DVec3,
    pub class: JoinClass,
}

/// The badges of one curve model (none for surfaces and ERBS curves).
#[must_use]
pub fn curve_joins(model: ModelRef<'_>) -> Vec<Join> {
    let Some(curve) = CurveEval::of(model) else {
        return Vec::new();
    };
    let params = curve.join_params();
    if params.is_empty() {
        return Vec::new();
    }
    let size = extent(&curve);
    params
        .into_iter()
        .filter_map(|t| {
            let (l, r) = curve.limits(t)?;
            Some(Join {
                t,
                position: r[0],
                class: classify(l, r, size),
            })
        })
        .collect()
}

/// One connected piece of a drawn curve: a run of its samples and, where the piece meets a gap,
/// the end points the samples miss.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePiece {
    /// The samples drawn as one polyline.
    pub samples: std::ops::Range<usize>,
    /// The right limit c(t+) at the gap the piece starts at, where no sample lies exactly on
    /// that knot (the first sample comes later).
    pub start: Option<DVec3>,
    /// The left limit c(t−) at the gap the piece ends at: no sample reaches it, since a sample
    /// at the knot is the right limit and belongs to the next piece.
    pub end: Option<DVec3>,
}

impl CurvePiece {
    /// The piece of every sample, with nothing to add.
    fn whole(samples: usize) -> Self {
        Self {
            samples: 0..samples,
            start: None,
            end: None,
        }
    }
}

/// The pieces a curve is drawn as: one, or for a B-spline curve whose interior knot of
/// multiplicity ≥ degree + 1 leaves a gap (C⁻¹, the "gap" badge), one per connected piece, so
/// no line bridges the gap and each piece still reaches its ends. `params` are the curve's
/// sample parameters; a sample at the gap's knot belongs to the piece on its right (the
/// evaluator's right limit).
#[must_use]
pub fn curve_pieces(model: ModelRef<'_>, params: &[f64]) -> Vec<CurvePiece> {
    let whole = vec![CurvePiece::whole(params.len())];
    // Only B-spline, Bézier and NURBS curves can tear: chains share their junction points and
    // ERBS curves blend smoothly.
    let ModelRef::Curve(c) = model else {
        return whole;
    };
    let curve = c.curve();
    let d = curve.degree();
    let (a, b) = curve.domain();
    // One pass over the runs of equal knots: a curve read from a file can have millions, and
    // asking each breakpoint for its multiplicity would scan them all per breakpoint.
    let tears = curve
        .knots()
        .chunk_by(|x, y| x == y)
        .any(|run| run.len() > d && run[0] > a && run[0] < b);
    if !tears {
        return whole;
    }
    let mut gaps: Vec<f64> = curve_joins(model)
        .iter()
        .filter(|j| !j.class.connected)
        .map(|j| j.t)
        .collect();
    gaps.dedup();
    let mut pieces = Vec::with_capacity(gaps.len() + 1);
    let mut piece = CurvePiece::whole(0);
    for t in gaps {
        let cut = params.partition_point(|&p| p < t);
        piece.samples.end = cut;
        piece.end = Some(curve.one_sided_derivatives(t, 0, true)[0]);
        pieces.push(piece);
        let on_knot = params.get(cut) == Some(&t);
        piece = CurvePiece {
            samples: cut..cut,
            start: (!on_knot).then(|| curve.one_sided_derivatives(t, 0, false)[0]),
            end: None,
        };
    }
    piece.samples.end = params.len();
    pieces.push(piece);
    pieces
}

/// A length scale of the curve: the largest coordinate magnitude of a coarse sampling.
fn extent(curve: &CurveEval<'_>) -> f64 {
    let (a, b) = curve.domain();
    (0..=16)
        .map(|k| curve.derivatives(a + (b - a) * k as f64 / 16.0, 0)[0])
        .fold(1e-300f64, |m, p| m.max(p.abs().max_element()))
}

/// The osculating circle and the Frenet quantities at one curve point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Osculating {
    pub t: f64,
    pub point: DVec3,
    pub tangent: DVec3,
    pub normal: DVec3,
    pub binormal: DVec3,
    /// κ = |c' × c''| / |c'|³; the circle's radius is 1/κ.
    pub curvature: f64,
    /// τ = (c' × c'')·c''' / |c' × c''|².
    pub torsion: f64,
}

impl Osculating {
    /// At parameter t of `curve`; `None` where there is no osculating plane (straight pieces,
    /// inflections, a vanishing derivative).
    #[must_use]
    pub fn at(curve: &CurveEval<'_>, t: f64) -> Option<Self> {
        let d = curve.derivatives(t, 3);
        let f = frenet_frame(d[1], d[2], d[3])?;
        Some(Self {
            t,
            point: d[0],
            tangent: f.tangent,
            normal: f.normal,
            binormal: f.binormal,
            curvature: f.curvature,
            torsion: f.torsion,
        })
    }

    #[must_use]
    pub fn radius(&self) -> f64 {
        1.0 / self.curvature
    }

    #[must_use]
    pub fn center(&self) -> DVec3 {
        self.point + self.normal * self.radius()
    }

    /// `segments` + 1 points around the circle in the osculating plane, starting at the curve
    /// point.
    #[must_use]
    pub fn circle(&self, segments: usize) -> Vec<DVec3> {
        let (c, r) = (self.center(), self.radius());
        (0..=segments)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / segments as f64;
                c - self.normal * (r * a.cos()) + self.tangent * (r * a.sin())
            })
            .collect()
    }

    /// "t 1.250  curvature 0.8123  radius 1.231  torsion -0.04120" (plain ASCII).
    #[must_use]
    pub fn describe(&self) -> String {
        format!(
            "t {}  curvature {}  radius {}  torsion {}",
            short(self.t),
            short(self.curvature),
            short(self.radius()),
            short(self.torsion)
        )
    }
}

/// The parameter of the sample of a curve object nearest to `target` among `samples` (the
/// canonical grid), for aiming the osculating circle with the cursor.
pub fn nearest_sample(
    params: &[f64],
    positions: impl Iterator<Item = DVec3>,
    target: DVec3,
) -> f64 {
    let mut best = (f64::INFINITY, params[0]);
    for (t, p) in params.iter().zip(positions) {
        let d = (p - target).length_squared();
        if d < best.0 {
            best = (d, *t);
        }
    }
    best.1
}

/// Badge colours (sRGB): C2 green, C1 / G2 teal, G1 yellow, G0 orange, a gap red.
#[must_use]
pub fn badge_color(class: JoinClass) -> [u8; 4] {
    match class.label() {
        "C2" => [70, 200, 110, 255],
        "C1 G2" | "G2" => [60, 190, 200, 255],
        "C1" => [120, 170, 240, 255],
        "G1" => [235, 200, 60, 255],
        "G0" => [240, 140, 50, 255],
        _ => [235, 70, 60, 255],
    }
}

/// Every continuity badge of the document as overlay quads: a dot on the join and its label
/// beside it on an opaque tag, placed by `project` (world → pixel, `None` behind the camera).
pub fn badge_overlay(
    doc: &Document,
    font: &Font,
    project: impl Fn(DVec3) -> Option<(f64, f64)>,
) -> Vec<OverlayVertex> {
    let mut v = Vec::new();
    let size = TextSize::Normal;
    for o in &doc.objects {
        for j in curve_joins(o.sampled.model()) {
            let Some((x, y)) = project(j.position) else {
                continue;
            };
            let (x, y) = (x as f32, y as f32);
            let color = badge_color(j.class);
            push_rect(&mut v, x - 4.0, y - 4.0, 8.0, 8.0, PANEL);
            push_rect(&mut v, x - 3.0, y - 3.0, 6.0, 6.0, color);
            let label = j.class.label();
            let [w, h] = font.text_size(label, size);
            let (bx, by) = (x + 8.0, y - h - 10.0);
            push_rect(&mut v, bx, by, w + 8.0, h + 4.0, PANEL);
            push_rect(&mut v, bx, by + h + 2.0, w + 8.0, 2.0, color);
            font.push_text(&mut v, label, bx + 4.0, by + 1.0, size, color);
        }
    }
    v
}

/// The osculating circle (magenta), the radius to its centre and the tangent (thin), as lines.
#[must_use]
pub fn osculating_lines(o: &Osculating) -> Vec<LineVertex> {
    let mut out = Vec::new();
    let mut line = |a: DVec3, b: DVec3, color: [u8; 4]| {
        out.push(LineVertex {
            pos: a.as_vec3().to_array(),
            color,
        });
        out.push(LineVertex {
            pos: b.as_vec3().to_array(),
            color,
        });
    };
    let ring = o.circle(96);
    for w in ring.windows(2) {
        line(w[0], w[1], [230, 70, 230, 255]);
    }
    line(o.point, o.center(), [170, 90, 170, 255]);
    let r = o.radius();
    line(
        o.center() - o.tangent * (0.04 * r),
        o.center() + o.tangent * (0.04 * r),
        [230, 70, 230, 255],
    );
    line(
        o.center() - o.normal * (0.04 * r),
        o.center() + o.normal * (0.04 * r),
        [230, 70, 230, 255],
    );
    out
}

/// The osculating readout (curvature, radius, torsion) as a label next to the curve point,
/// kept inside a `size` image, on an opaque panel: draw it after the badges, so none covers
/// it.
#[must_use]
pub fn osculating_overlay(
    name: &str,
    o: &Osculating,
    font: &Font,
    at: (f64, f64),
    size: [f32; 2],
) -> Vec<OverlayVertex> {
    let mut v = Vec::new();
    let text = osculating_text(name, o);
    let [w, h] = font.text_size(&text, TextSize::Normal);
    let [x, y] = osculating_panel_origin([w, h], at, size);
    push_rect(&mut v, x, y, w + 10.0, h + 8.0, PANEL);
    let magenta = [240, 150, 240, 255];
    font.push_text(&mut v, &text, x + 5.0, y + 4.0, TextSize::Normal, magenta);
    v
}

/// The readout's lines: curve name and parameter, curvature and radius, torsion.
#[must_use]
pub fn osculating_text(name: &str, o: &Osculating) -> String {
    format!(
        "{name}  t = {}\ncurvature {}  radius {}\ntorsion {}",
        short(o.t),
        short(o.curvature),
        short(o.radius()),
        short(o.torsion)
    )
}

/// Top-left corner of the readout panel for text of `[w, h]` pixels next to the curve point
/// `at`: right of it, or left where the image ends, inside the image.
#[must_use]
pub fn osculating_panel_origin([w, h]: [f32; 2], at: (f64, f64), size: [f32; 2]) -> [f32; 2] {
    let (px, py) = (at.0 as f32, at.1 as f32);
    let x = if px + 14.0 + w + 10.0 <= size[0] {
        px + 14.0
    } else {
        (px - 14.0 - w - 10.0).max(0.0)
    };
    let y = (py + 10.0).min(size[1] - h - 8.0).max(0.0);
    [x.round(), y.round()]
}

/// Colour of the opaque panels under overlay text (sRGB).
pub const PANEL: [u8; 4] = [10, 12, 16, 255];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_numbers_include_zero() {
        // A planar curve's torsion is exactly 0 (this overflowed the digit count once).
        assert_eq!(short(0.0), "0");
        assert_eq!(short(-0.0), "0");
        assert_eq!(short(1.25), "1.250");
        assert_eq!(short(-0.04120), "-0.04120");
        assert_eq!(short(1e-7), "1.000e-7");
    }
    use crate::formats::parse_scene;

    fn model(text: &str) -> Model {
        parse_scene(text).unwrap().objects.remove(0).model
    }

    #[test]
    fn badges_on_constructed_junctions() {
        // A cubic B-spline whose interior knots have multiplicity 1, 2 and 3: C2, C1, C0.
        let m = model(
            r#"{"objects": [{"name": "c", "type": "bspline_curve", "degree": 3,
            "knots": [0,0,0,0, 1, 2,2, 3,3,3, 4,4,4,4],
            "points": [[0,0,0],[1,2,0],[2,3,1],[3,1,0],[4,2,2],[5,0,1],[6,1,0],[7,3,1],[8,0,0],[9,1,1]],
            "samples": 50}]}"#,
        );
        let j = curve_joins(m.as_ref());
        let labels: Vec<(f64, &str)> = j.iter().map(|j| (j.t, j.class.label())).collect();
        assert_eq!(labels, vec![(2.0, "C1"), (3.0, "G0")]);
        // A C1 cubic Bézier spline on unequal intervals is C1 (and not G2 by accident).
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bezier_spline.json"),
        )
        .unwrap();
        let scene = parse_scene(&text).unwrap();
        let expect = ["C1", "C2", "G1"];
        for (o, want) in scene.objects.iter().zip(expect) {
            for j in curve_joins(o.model.as_ref()) {
                assert_eq!(j.class.label(), want, "{} at {}", o.name, j.t);
            }
        }
    }

    #[test]
    fn osculating_circle_of_a_circle_is_the_circle() {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let m = model(&format!(
            r#"{{"objects": [{{"name": "q", "type": "bezier_curve", "points": [[2,0,0],[2,2,0],[0,2,0]],
            "weights": [1, {w}, 1], "samples": 9}}]}}"#
        ));
        let c = CurveEval::of(m.as_ref()).unwrap();
        for t in [0.1, 0.5, 0.9] {
            let o = Osculating::at(&c, t).unwrap();
            assert!((o.radius() - 2.0).abs() < 1e-12, "{}", o.radius());
            assert!(o.center().length() < 1e-12);
            assert!(o.torsion.abs() < 1e-12);
            for p in o.circle(12) {
                assert!((p.length() - 2.0).abs() < 1e-12);
            }
        }
    }
}

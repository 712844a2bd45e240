//! CAD faces as scene objects: each face's exact NURBS becomes a `bspline_surface` with sample
//! counts that fit it, its loops a trim; what cannot be drawn is reported, not dropped.
//!
//! **Sample counts** (`--samples` overrides them): along each direction, a face gets as many
//! samples as its most curved piece asks for, so that a chord between neighbouring samples
//! departs from the surface by at most [`CHORD`] of the model's diagonal (about a quarter of a
//! pixel when the model fills a 1280-pixel view, which is what keeps two faces that share an
//! edge from showing a crack): per piece between breakpoints, the departure of one chord
//! `d = |S(mid) − (S(a) + S(b)) / 2|` at five probes across the other direction, `k = ⌈√(d /
//! tol)⌉` chords, since a chord's departure falls with the square of the step. A plane gets 2
//! × 2 samples, a quarter cylinder of a tenth of the model about 9 around.

use super::model::{CadCurve2, CadFace, CadModel};
use crate::formats::context::{Import, Located, Skipped};
use crate::geom::TensorSurface;
use crate::geom::trim::{LoopSpec, Trim, TrimCurve, TrimPiece, Trimmed};
use crate::model::{Model, SplineForm, SurfaceModel};
use crate::scene::{Scene, SceneObject};
use glam::{DVec2, DVec3};

/// The largest departure of a drawn chord from the surface, as a fraction of the model's
/// diagonal.
pub const CHORD: f64 = 5e-5;
/// Samples per direction: at least 2, at most this.
const MAX_SAMPLES: usize = 257;

/// The scene of a mapped CAD file, with its warnings (one line each), what was skipped and
/// the unit. A face whose surface or trim prespline refuses is skipped with the reason.
#[must_use]
pub fn to_import(model: CadModel) -> Import {
    let diagonal = model_diagonal(&model);
    let mut objects = Vec::with_capacity(model.faces.len());
    let mut skipped = model
        .skipped
        .into_iter()
        .map(|s| Skipped {
            what: s.what,
            count: s.count,
            reason: s.reason,
        })
        .collect::<Vec<_>>();
    let mut warnings: Vec<Located> = model
        .warnings
        .into_iter()
        .map(|w| Located {
            line: None,
            message: format!("warning: {w}"),
        })
        .collect();
    for face in model.faces {
        match face_object(&face, diagonal) {
            Ok(o) => objects.push(o),
            Err(why) => {
                warnings.push(Located {
                    line: None,
                    message: format!("warning: face {} not drawn: {why}", face.name),
                });
                match skipped.iter_mut().find(|s| s.what == face.surface_type) {
                    Some(s) if s.reason == "not drawn: its surface or trim was refused" => {
                        s.count += 1;
                    }
                    _ => skipped.push(Skipped {
                        what: face.surface_type.clone(),
                        count: 1,
                        reason: "not drawn: its surface or trim was refused".into(),
                    }),
                }
            }
        }
    }
    Import {
        scene: Scene { objects },
        warnings,
        skipped,
        unit: Some(model.unit),
    }
}

/// The diagonal of the box of every face's control net (the model's size, for the sample
/// counts).
fn model_diagonal(model: &CadModel) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in model.faces.iter().flat_map(|f| &f.surface.points) {
        if p.is_finite() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
    }
    let d = (hi - lo).length();
    if d.is_finite() && d > 0.0 { d } else { 1.0 }
}

/// One face as a trimmed `bspline_surface`.
fn face_object(face: &CadFace, diagonal: f64) -> Result<SceneObject, String> {
    let s = &face.surface;
    let nu = s.knots[0].len().saturating_sub(s.degree[0] + 1);
    let nv = s.knots[1].len().saturating_sub(s.degree[1] + 1);
    let rational = s.weights.iter().any(|&w| w != 1.0);
    let surface = TensorSurface::bspline(
        s.degree,
        s.knots.clone(),
        [nu, nv],
        s.points.clone(),
        rational.then(|| s.weights.clone()),
    )
    .map_err(|e| e.to_string())?;
    let samples = face_samples(&surface, CHORD * diagonal);
    let model =
        SurfaceModel::new(SplineForm::BSpline, surface, samples).map_err(|e| e.to_string())?;
    let model = Model::Surface(model);
    let d = model.domain();
    let trim = Trimmed::new(trim_of(face)?, [d[0], d[1]]).map_err(|e| format!("trim: {e}"))?;
    Ok(SceneObject {
        name: face.name.clone(),
        model,
        color: face.color,
        kept: Default::default(),
        trim: Some(trim),
    })
}

/// The face's loops as a trim, classified by nesting (periodic surfaces make "outer" a
/// matter of where the seam was cut, so the file's outer flags are not trusted).
fn trim_of(face: &CadFace) -> Result<Trim, String> {
    let mut loops = Vec::with_capacity(face.loops.len());
    for (k, l) in face.loops.iter().enumerate() {
        let pieces = l
            .pieces
            .iter()
            .enumerate()
            .map(|(c, p)| {
                let curve = match &p.curve {
                    CadCurve2::Polyline(v) => {
                        TrimCurve::polyline(v.iter().map(|q| DVec2::from_array(*q)).collect())
                    }
                    CadCurve2::Nurbs {
                        degree,
                        knots,
                        points,
                        weights,
                    } => {
                        let pts: Vec<DVec2> =
                            points.iter().map(|q| DVec2::from_array(*q)).collect();
                        TrimCurve::bspline(*degree, knots.clone(), &pts, weights.clone())
                    }
                }
                .map_err(|e| format!("loop {k}, curve {c}: {e}"))?;
                Ok(TrimPiece {
                    curve,
                    range: p.range,
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        loops.push(LoopSpec { pieces, role: None });
    }
    Ok(Trim { loops })
}

/// Samples per direction of `surface` such that chords depart from it by at most `tol` (see
/// the module doc).
#[must_use]
pub fn face_samples(surface: &TensorSurface, tol: f64) -> [usize; 2] {
    let domain = surface.domain();
    let mut out = [2usize; 2];
    for (dir, slot) in out.iter_mut().enumerate() {
        let (a, b) = domain[dir];
        let (oa, ob) = domain[1 - dir];
        let knots = surface.knots()[dir].as_slice();
        let mut breaks: Vec<f64> = vec![a];
        breaks.extend(knots.iter().copied().filter(|&k| k > a && k < b));
        breaks.push(b);
        breaks.dedup();
        let mut density: f64 = 0.0;
        for w in breaks.windows(2) {
            let (s0, s1) = (w[0], w[1]);
            let mut worst: f64 = 0.0;
            for probe in 0..5 {
                let o = oa + (ob - oa) * f64::from(probe) / 4.0;
                let at = |s: f64| {
                    // The allocation-free evaluator (this runs for every span of every face).
                    if dir == 0 {
                        surface.first_partials(s, o)[0]
                    } else {
                        surface.first_partials(o, s)[0]
                    }
                };
                let mid = at(0.5 * (s0 + s1));
                worst = worst.max(mid.distance(0.5 * (at(s0) + at(s1))));
            }
            let k = if tol > 0.0 && worst.is_finite() {
                (worst / tol).sqrt().ceil().max(1.0)
            } else {
                1.0
            };
            density = density.max(k / (s1 - s0));
        }
        let n = (density * (b - a)).ceil();
        *slot = if n.is_finite() {
            (n as usize + 1).clamp(2, MAX_SAMPLES)
        } else {
            MAX_SAMPLES
        };
    }
    out
}

//! The one bridge between OBJ elements and scene objects, one function each way
//! ([`element_to_object`], [`object_to_element`]); the mapping rules are in docs/obj.md.

use super::ObjError;
use super::erbs;
use super::kept::ObjKept;
use super::model::{Basis, Direction, FreeForm};
use super::trims;
use crate::geom::error::GeomResult;
use crate::geom::trim::Trimmed;
use crate::geom::{BSplineCurve, GeomError, TensorSurface};
use crate::model::{CurveModel, EditError, Model, ModelRef, SplineForm, SurfaceModel};
use crate::scene::{Carried, SceneError, SceneObject};
use glam::DVec3;

/// An OBJ element as a scene object. A single Bézier segment on [0, 1] stays a Bézier object;
/// everything else becomes a B-spline with the same control data, and a range that is a proper
/// part of the domain is cut out by knot insertion.
pub fn element_to_object(e: &FreeForm, name: String) -> Result<SceneObject, ObjError> {
    let weights = e.rational.then(|| e.weights.clone());
    let err = |g: GeomError| ObjError::new(e.line, format!("{}: {}", e.keyword(), g.message));
    let invalid = |m: EditError| ObjError::new(e.line, format!("{}: {}", e.keyword(), m.message));
    let form = if is_unit_bezier(e) {
        SplineForm::Bezier
    } else {
        SplineForm::BSpline
    };
    let model = if let [u] = e.dirs.as_slice() {
        let c = BSplineCurve::new(u.degree, u.knots(e.basis), e.points.clone(), weights)
            .map_err(err)?;
        let c = restrict_curve(c, u.range).map_err(err)?;
        let m = e
            .samples
            .as_ref()
            .map_or_else(|| default_curve_samples(&c), |m| m[0]);
        Model::Curve(CurveModel::new(form, c, m).map_err(invalid)?)
    } else {
        let (u, v) = (&e.dirs[0], &e.dirs[1]);
        let (nu, nv) = (u.count, v.count);
        // OBJ lists u fastest; scene nets are row-major with i along u.
        let ours = |i: usize| (i % nv) * nu + i / nv;
        let points = (0..nu * nv).map(|i| e.points[ours(i)]).collect();
        let weights = weights.map(|w| (0..nu * nv).map(|i| w[ours(i)]).collect());
        let knots = [u.knots(e.basis), v.knots(e.basis)];
        let s = TensorSurface::bspline([u.degree, v.degree], knots, [nu, nv], points, weights)
            .map_err(err)?;
        let s = restrict_surface(s, 0, u.range).map_err(err)?;
        let s = restrict_surface(s, 1, v.range).map_err(err)?;
        let m = e
            .samples
            .as_ref()
            .map_or_else(|| default_surface_samples(&s), |m| [m[0], m[1]]);
        Model::Surface(SurfaceModel::new(form, s, m).map_err(invalid)?)
    };
    let trim = match trims::trim_of(&e.carried) {
        Ok(Some(spec)) if model.is_surface() => {
            let d = model.domain();
            Some(
                Trimmed::new(spec, [d[0], d[1]])
                    .map_err(|t| ObjError::new(e.line, format!("{}: trim: {t}", e.keyword())))?,
            )
        }
        Ok(_) => None,
        Err(t) => return Err(ObjError::new(e.line, format!("{}: {t}", e.keyword()))),
    };
    Ok(SceneObject {
        name,
        model,
        color: e.color,
        kept: if e.carried.is_empty() {
            Carried::default()
        } else {
            Carried::of(Box::new(e.carried.clone()))
        },
        trim,
    })
}

/// A scene object as an OBJ element. ERBS objects go through their exact B-spline form where
/// the B-function allows one, and are refused otherwise.
pub fn object_to_element(o: &SceneObject) -> Result<FreeForm, SceneError> {
    let at = |msg: String| SceneError(format!("object '{}': {msg}", o.name));
    check_name(&o.name).map_err(at)?;
    let basis = |form| match form {
        SplineForm::Bezier => Basis::Bezier,
        SplineForm::BSpline => Basis::BSpline,
    };
    let mut e = match o.model.as_ref() {
        ModelRef::Curve(m) => curve_element(m.curve(), basis(m.form())),
        ModelRef::Surface(m) => surface_element(m.surface(), basis(m.form())),
        ModelRef::ErbsCurve(m) => curve_element(
            &erbs::curve_to_bspline(m.curve()).map_err(at)?,
            Basis::BSpline,
        ),
        ModelRef::ErbsSurface(m) => surface_element(
            &erbs::surface_to_bspline(m.surface()).map_err(at)?,
            Basis::BSpline,
        ),
        // Catmull–Rom and Bézier splines as the B-spline of their Bézier chain; any other
        // kind through its B-spline form where it has one.
        other => match other.to_bspline_curve() {
            Some(crate::model::Model::Curve(c)) => curve_element(c.curve(), Basis::BSpline),
            _ => return Err(at(format!("a {} has no OBJ form", other.type_name()))),
        },
    };
    let dims = o.model.sample_dims();
    e.name = Some(o.name.clone());
    e.samples = Some(if o.model.is_surface() {
        dims.to_vec()
    } else {
        vec![dims[0]]
    });
    e.color = o.color;
    // The statements an OBJ file gave are written back as they were; a trim from anywhere
    // else is written as vp, curv2 and trim/hole statements.
    e.carried = match (o.kept.get::<ObjKept>(), &o.trim) {
        (Some(kept), _) => kept.clone(),
        (None, Some(t)) if o.model.is_surface() => trims::kept_of(t),
        (None, _) => ObjKept::default(),
    };
    Ok(e)
}

/// Samples of an imported curve without `# prespline samples`: 32 per knot span, 129 to 4097
/// in all.
#[must_use]
pub fn default_curve_samples(c: &BSplineCurve) -> usize {
    (32 * spans(c.knots(), c.domain()) + 1).clamp(129, 4097)
}

/// Samples of an imported surface without `# prespline samples`: 8 per knot span in each
/// direction, 17 to 257, so a Bézier patch gets 17 × 17 and dense nets stay responsive.
#[must_use]
pub fn default_surface_samples(s: &TensorSurface) -> [usize; 2] {
    let dom = s.domain();
    [0, 1].map(|d| (8 * spans(&s.knots()[d], dom[d]) + 1).clamp(17, 257))
}

/// Non-empty knot spans in [a, b].
fn spans(knots: &[f64], (a, b): (f64, f64)) -> usize {
    let mut n = 0usize;
    let mut last = a;
    for &t in knots.iter().filter(|&&t| t > a && t <= b) {
        if t > last {
            n += 1;
            last = t;
        }
    }
    n.max(1)
}

/// One Bézier segment per direction on [0, 1]: a `bezier_curve` / `bezier_surface`.
fn is_unit_bezier(e: &FreeForm) -> bool {
    e.basis == Basis::Bezier
        && e.dirs
            .iter()
            .all(|d| d.parm == [0.0, 1.0] && d.range == [0.0, 1.0])
}

/// The part of `c` on [a, b] ⊆ its domain, by splitting (CurveKnotIns) at a and b; `c` itself
/// when [a, b] is the domain.
fn restrict_curve(c: BSplineCurve, [a, b]: [f64; 2]) -> GeomResult<BSplineCurve> {
    let (lo, hi) = c.domain();
    let c = if a > lo { c.split(a)?.1 } else { c };
    if b < hi { Ok(c.split(b)?.0) } else { Ok(c) }
}

/// The part of `s` on [a, b] in direction `dir`: every row (or column) of the net is cut like a
/// curve; they share the knot vector, so they are refined alike.
fn restrict_surface(s: TensorSurface, dir: usize, range: [f64; 2]) -> GeomResult<TensorSurface> {
    let dom = s.domain()[dir];
    if range == [dom.0, dom.1] {
        return Ok(s);
    }
    let [nu, nv] = s.count();
    let (lines, len) = if dir == 0 { (nv, nu) } else { (nu, nv) };
    let at = |line: usize, k: usize| {
        if dir == 0 {
            k * nv + line
        } else {
            line * nv + k
        }
    };
    let knots = s.knots()[dir].to_vec();
    let cut = (0..lines)
        .map(|line| {
            let points = (0..len).map(|k| s.points()[at(line, k)]).collect();
            let weights = s
                .weights()
                .map(|w| (0..len).map(|k| w[at(line, k)]).collect());
            let c = BSplineCurve::new(s.degree()[dir], knots.clone(), points, weights)?;
            restrict_curve(c, range)
        })
        .collect::<GeomResult<Vec<_>>>()?;
    let new_len = cut[0].points().len();
    let mut count = [nu, nv];
    count[dir] = new_len;
    let index = |line: usize, k: usize| if dir == 0 { (k, line) } else { (line, k) };
    let mut points = vec![DVec3::ZERO; count[0] * count[1]];
    let mut weights = s.weights().map(|_| vec![1.0; count[0] * count[1]]);
    for (line, c) in cut.iter().enumerate() {
        for k in 0..new_len {
            let (i, j) = index(line, k);
            points[i * count[1] + j] = c.points()[k];
            if let (Some(w), Some(cw)) = (&mut weights, c.weights()) {
                w[i * count[1] + j] = cw[k];
            }
        }
    }
    let mut knots = [s.knots()[0].to_vec(), s.knots()[1].to_vec()];
    knots[dir] = cut[0].knots().to_vec();
    TensorSurface::bspline(s.degree(), knots, count, points, weights)
}

fn curve_element(c: &BSplineCurve, basis: Basis) -> FreeForm {
    let (a, b) = c.domain();
    let parm = match basis {
        Basis::Bezier => vec![a, b],
        Basis::BSpline => c.knots().to_vec(),
    };
    let n = c.points().len();
    FreeForm {
        basis,
        rational: c.is_rational(),
        dirs: vec![Direction {
            degree: c.degree(),
            range: [a, b],
            parm,
            count: n,
            parm_line: 0,
        }],
        points: c.points().to_vec(),
        weights: c.weights().map_or_else(|| vec![1.0; n], <[f64]>::to_vec),
        name: None,
        samples: None,
        color: None,
        line: 0,
        carried: ObjKept::default(),
    }
}

fn surface_element(s: &TensorSurface, basis: Basis) -> FreeForm {
    let [nu, nv] = s.count();
    let dirs = (0..2)
        .map(|d| {
            let (a, b) = s.domain()[d];
            Direction {
                degree: s.degree()[d],
                range: [a, b],
                parm: match basis {
                    Basis::Bezier => vec![a, b],
                    Basis::BSpline => s.knots()[d].to_vec(),
                },
                count: s.count()[d],
                parm_line: 0,
            }
        })
        .collect();
    // OBJ lists u fastest: element k is control point (k mod nu, k div nu).
    let net = |k: usize| (k % nu) * nv + k / nu;
    FreeForm {
        basis,
        rational: s.is_rational(),
        dirs,
        points: (0..nu * nv).map(|k| s.points()[net(k)]).collect(),
        weights: (0..nu * nv)
            .map(|k| s.weights().map_or(1.0, |w| w[net(k)]))
            .collect(),
        name: None,
        samples: None,
        color: None,
        line: 0,
        carried: ObjKept::default(),
    }
}

/// A name survives an OBJ `o` statement when it has no control characters, no trailing
/// backslash and single spaces between words (the reader joins words with one space). A `#`
/// would start a comment, so names are written through [`encode_name`].
fn check_name(name: &str) -> Result<(), String> {
    let why = if name.chars().any(char::is_control) {
        Some("it contains a control character")
    } else if name.ends_with('\\') {
        Some("a trailing '\\' would continue the line")
    } else if name.split_whitespace().collect::<Vec<_>>().join(" ") != name {
        Some("OBJ keeps only single spaces between words")
    } else {
        None
    };
    match why {
        Some(why) => Err(format!("the name cannot be written to OBJ: {why}")),
        None => Ok(()),
    }
}

/// A name as an `o` statement writes it: `#` (which would start a comment) as `%23` and `%` as
/// `%25`, so that CAD face names such as `bracket#1234` survive and [`decode_name`] restores
/// every name exactly. Other programs show the encoded name, which stays legible.
#[must_use]
pub(crate) fn encode_name(name: &str) -> String {
    name.replace('%', "%25").replace('#', "%23")
}

/// The name an `o` or `g` statement gives: [`encode_name`] undone (`%23` is `#`, `%25` is `%`;
/// any other `%` stays as written).
#[must_use]
pub(crate) fn decode_name(written: &str) -> String {
    let mut out = String::with_capacity(written.len());
    let mut rest = written;
    while let Some(at) = rest.find('%') {
        out.push_str(&rest[..at]);
        let tail = &rest[at..];
        if let Some(t) = tail.strip_prefix("%23") {
            out.push('#');
            rest = t;
        } else if let Some(t) = tail.strip_prefix("%25") {
            out.push('%');
            rest = t;
        } else {
            out.push('%');
            rest = &tail[1..];
        }
    }
    out.push_str(rest);
    out
}

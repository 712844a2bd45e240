//! The checks of one element at its `end`: per direction the degree against the control
//! vertices and the `parm` vector (B-spline knots: control vertices + degree + 1, non-decreasing,
//! multiplicity at most degree + 1, non-empty domain; Bézier: K·d + 1 control vertices and K + 1
//! increasing breakpoints), and the `curv`/`surf` range against the domain.

use super::model::{Basis, Direction};
use super::{ObjError, Warnings};

/// What the reader collected for one supported element up to its `end`.
pub struct Body<'a> {
    /// `curv` or `surf`.
    pub keyword: &'static str,
    /// Line of the `curv`/`surf` statement.
    pub line: usize,
    pub basis: Basis,
    /// The `deg` values in effect (at least one per direction).
    pub degrees: &'a [usize],
    /// One range per direction.
    pub ranges: &'a [[f64; 2]],
    /// `parm u` (and `parm v`) with their lines, one entry per direction.
    pub parm: &'a [Option<(Vec<f64>, usize)>],
    /// Number of control vertices listed.
    pub vertices: usize,
}

/// The element's checked directions; a range that is part of the domain is warned about.
pub fn directions(b: &Body, warnings: &mut Warnings) -> Result<Vec<Direction>, ObjError> {
    let (word, line, basis) = (b.keyword, b.line, b.basis);
    let mut dirs = Vec::with_capacity(b.parm.len());
    for (d, parm) in b.parm.iter().enumerate() {
        let uv = ["u", "v"][d];
        let (parm, parm_line) = parm.clone().ok_or_else(|| {
            ObjError::new(line, format!("{word} has no parm {uv} before its end"))
        })?;
        dirs.push(Direction {
            degree: b.degrees[d],
            range: b.ranges[d],
            parm,
            count: 0,
            parm_line,
        });
    }
    let n = b.vertices;
    if let [u, v] = dirs.as_mut_slice() {
        u.count = surface_count(basis, u, "u")?;
        v.count = surface_count(basis, v, "v")?;
        if n != u.count * v.count {
            return Err(ObjError::new(
                line,
                format!(
                    "surf lists {n} control vertices, but parm u and parm v with deg {} {} describe {} × {} = {}",
                    u.degree,
                    v.degree,
                    u.count,
                    v.count,
                    u.count * v.count
                ),
            ));
        }
    } else {
        dirs[0].count = n;
        curve_count(basis, &dirs[0], line)?;
    }
    for (d, dir) in dirs.iter_mut().enumerate() {
        check_parm(basis, dir, ["u", "v"][d])?;
        check_range(warnings, basis, dir, word, line, ["u", "v"][d])?;
    }
    Ok(dirs)
}

/// The range must overlap the domain. A range reaching outside it is clamped to it (warned
/// once per file): Blender 2.7x–2.9x writes `curv 0.0 1.0` over an unclamped knot vector whose
/// domain [t_d, t_n] is narrower, meaning the whole curve. A proper part of the domain is cut
/// out on import (warned).
fn check_range(
    warnings: &mut Warnings,
    basis: Basis,
    dir: &mut Direction,
    word: &str,
    line: usize,
    uv: &str,
) -> Result<(), ObjError> {
    let [a, b] = dir.range;
    let [lo, hi] = dir.domain(basis);
    let what = if uv == "u" && word == "curv" {
        "range".to_string()
    } else {
        format!("{uv} range")
    };
    if a >= b {
        return Err(ObjError::new(
            line,
            format!("{word} {what} [{a}, {b}] is empty or reversed"),
        ));
    }
    let clamped = [a.max(lo), b.min(hi)];
    if clamped[0] >= clamped[1] {
        return Err(ObjError::new(
            line,
            format!(
                "{word} {what} [{a}, {b}] lies outside the domain [{lo}, {hi}] of parm {uv} (line {})",
                dir.parm_line
            ),
        ));
    }
    if clamped != dir.range {
        let [ca, cb] = clamped;
        warnings.add("range clamped", line, || {
            format!(
                "{word} {what} [{a}, {b}] reaches outside the domain [{lo}, {hi}] of parm {uv} (line {}): clamped to [{ca}, {cb}] (Blender 2.7x–2.9x writes 'curv 0.0 1.0' over unclamped knots)",
                dir.parm_line
            )
        });
        dir.range = clamped;
    }
    let [a, b] = dir.range;
    if dir.is_restricted(basis) {
        warnings.add(&format!("range {line} {uv}"), line, || {
            format!(
                "{word} {what} [{a}, {b}] is part of the domain [{lo}, {hi}] of parm {uv}: the {} is cut to it by knot insertion (control points recomputed)",
                if word == "curv" { "curve" } else { "surface" }
            )
        });
    }
    Ok(())
}

/// Control vertices along a surface direction, from its `parm` vector.
fn surface_count(basis: Basis, dir: &Direction, uv: &str) -> Result<usize, ObjError> {
    let (k, d) = (dir.parm.len(), dir.degree);
    match basis {
        Basis::BSpline if k < 2 * d + 2 => Err(ObjError::new(
            dir.parm_line,
            format!(
                "parm {uv} has {k} knots; degree {d} needs at least {} (control vertices + degree + 1, with at least degree + 1 control vertices)",
                2 * d + 2
            ),
        )),
        Basis::BSpline => Ok(k - d - 1),
        Basis::Bezier => Ok((k - 1) * d + 1),
    }
}

/// A curve's control vertex count must fit its degree and `parm` vector.
fn curve_count(basis: Basis, dir: &Direction, line: usize) -> Result<(), ObjError> {
    let (n, d, k) = (dir.count, dir.degree, dir.parm.len());
    match basis {
        Basis::BSpline => {
            if n <= d {
                return Err(ObjError::new(
                    line,
                    format!(
                        "curv lists {n} control vertices; degree {d} needs at least {}",
                        d + 1
                    ),
                ));
            }
            if k != n + d + 1 {
                return Err(ObjError::new(
                    dir.parm_line,
                    format!(
                        "parm u has {k} knots; a degree-{d} B-spline with {n} control vertices needs {} (control vertices + degree + 1)",
                        n + d + 1
                    ),
                ));
            }
        }
        Basis::Bezier => {
            if n <= d || (n - 1) % d != 0 {
                return Err(ObjError::new(
                    line,
                    format!(
                        "curv lists {n} control vertices; a Bézier curve of degree {d} needs k·{d} + 1 ({}, {}, …)",
                        d + 1,
                        2 * d + 1
                    ),
                ));
            }
            let segments = (n - 1) / d;
            if k != segments + 1 {
                return Err(ObjError::new(
                    dir.parm_line,
                    format!(
                        "parm u has {k} values; {segments} Bézier segment(s) need {} breakpoints",
                        segments + 1
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Knots non-decreasing with multiplicity ≤ degree + 1 and a non-empty domain; Bézier
/// breakpoints strictly increasing.
fn check_parm(basis: Basis, dir: &Direction, uv: &str) -> Result<(), ObjError> {
    let p = &dir.parm;
    let line = dir.parm_line;
    for i in 1..p.len() {
        let bad = match basis {
            Basis::BSpline => p[i] < p[i - 1],
            Basis::Bezier => p[i] <= p[i - 1],
        };
        if bad {
            let rule = match basis {
                Basis::BSpline => "knots must be non-decreasing",
                Basis::Bezier => "Bézier breakpoints must increase strictly",
            };
            return Err(ObjError::new(
                line,
                format!(
                    "parm {uv}: value {} ({}) follows value {i} ({}): {rule}",
                    i + 1,
                    p[i],
                    p[i - 1]
                ),
            ));
        }
    }
    if basis == Basis::BSpline {
        let d = dir.degree;
        let mut start = 0;
        while start < p.len() {
            let end = start + p[start..].iter().take_while(|&&t| t == p[start]).count();
            if end - start > d + 1 {
                return Err(ObjError::new(
                    line,
                    format!(
                        "parm {uv}: knot {} appears {} times, more than degree + 1 = {}",
                        p[start],
                        end - start,
                        d + 1
                    ),
                ));
            }
            start = end;
        }
        if p[d] >= p[dir.count] {
            return Err(ObjError::new(
                line,
                format!(
                    "parm {uv}: empty domain: knot {} ({}) must be smaller than knot {} ({})",
                    d + 1,
                    p[d],
                    dir.count + 1,
                    p[dir.count]
                ),
            ));
        }
    }
    Ok(())
}

//! Length and plane-angle units of a representation context (ISO 10303-41 §4.2 measure schema).
//!
//! A representation's `context_of_items` is usually a complex GEOMETRIC_REPRESENTATION_CONTEXT
//! with a GLOBAL_UNIT_ASSIGNED_CONTEXT listing its units: SI_UNIT (with a prefix: `.MILLI.`,
//! `.CENTI.`, …) or CONVERSION_BASED_UNIT (`'INCH'` = 25.4 mm, `'DEGREE'` = π/180 rad) through a
//! MEASURE_WITH_UNIT. Lengths are converted to millimetres, angles to radians: the mapping keeps
//! geometry in the file's length unit and scales it at the end, but converts every angle (cone
//! semi-angles, trimmed-conic parameters, angular parameter limits) when it reads it.

use crate::formats::step::EntityRef;

use super::attrs::{P, Res, bad, is, part};

/// How many CONVERSION_BASED_UNITs may refer to each other in a chain.
const MAX_CHAIN: usize = 8;

/// The units of one representation context.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Units {
    /// Millimetres per length unit.
    pub mm: f64,
    /// Radians per plane-angle unit.
    pub rad: f64,
}

impl Default for Units {
    /// Millimetres and radians: what a file without units is read as (OpenCASCADE's default).
    fn default() -> Self {
        Self { mm: 1.0, rad: 1.0 }
    }
}

/// The units of the representation `rep` (its third attribute, `context_of_items`).
pub(crate) fn of_representation(rep: EntityRef<'_>) -> Res<Units> {
    let own = part(rep, "REPRESENTATION", 0)?;
    let ctx = own.p(2, "context_of_items")?.ent()?;
    of_context(ctx)
}

/// The units a context assigns; defaults where it assigns none.
pub(crate) fn of_context(ctx: EntityRef<'_>) -> Res<Units> {
    let mut units = Units::default();
    if !is(&ctx, "GLOBAL_UNIT_ASSIGNED_CONTEXT") {
        return Ok(units);
    }
    let list = part(ctx, "GLOBAL_UNIT_ASSIGNED_CONTEXT", 2)?
        .p(0, "units")?
        .ents()?;
    for u in list {
        match kind(&u) {
            Some(Kind::Length) => units.mm = factor(u, Kind::Length, 0)?,
            Some(Kind::Angle) => units.rad = factor(u, Kind::Angle, 0)?,
            None => {}
        }
    }
    Ok(units)
}

/// The two kinds of unit the mapping needs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Length,
    Angle,
}

/// Which kind a unit is, from its records (LENGTH_UNIT, PLANE_ANGLE_UNIT) or its SI name.
#[must_use]
fn kind(u: &EntityRef<'_>) -> Option<Kind> {
    if is(u, "LENGTH_UNIT") {
        return Some(Kind::Length);
    }
    if is(u, "PLANE_ANGLE_UNIT") {
        return Some(Kind::Angle);
    }
    let si = part(*u, "SI_UNIT", 1).ok()?;
    match si.p(1, "name").ok()?.enm().ok()? {
        "METRE" => Some(Kind::Length),
        "RADIAN" => Some(Kind::Angle),
        _ => None,
    }
}

/// Millimetres (length) or radians (angle) per unit `u`.
fn factor(u: EntityRef<'_>, want: Kind, depth: usize) -> Res<f64> {
    if depth > MAX_CHAIN {
        return Err(bad(
            &u,
            "conversion-based units refer to each other in a cycle",
        ));
    }
    if is(&u, "SI_UNIT") {
        let si = part(u, "SI_UNIT", 1)?;
        let prefix = match si.p(0, "prefix")?.optional() {
            Some(p) => prefix(p.enm()?).ok_or_else(|| bad(&u, "unknown SI prefix"))?,
            None => 1.0,
        };
        let base = match (want, si.p(1, "name")?.enm()?) {
            (Kind::Length, "METRE") => 1000.0,
            (Kind::Angle, "RADIAN") => 1.0,
            (_, other) => return Err(bad(&u, format!("unit .{other}. is not a length or angle"))),
        };
        return Ok(prefix * base);
    }
    if is(&u, "CONVERSION_BASED_UNIT") {
        let own = part(u, "CONVERSION_BASED_UNIT", 1)?;
        let name = own.p(0, "name")?.text()?.to_ascii_uppercase();
        let measured = own
            .p(1, "conversion_factor")
            .and_then(|p| p.ent())
            .and_then(|m| measure(m, want, depth));
        return match (measured, known(&name, want)) {
            (Ok(f), _) => Ok(f),
            (Err(_), Some(f)) => Ok(f),
            (Err(e), None) => Err(e),
        };
    }
    Err(bad(&u, "unit is neither SI_UNIT nor CONVERSION_BASED_UNIT"))
}

/// MEASURE_WITH_UNIT (or LENGTH_/PLANE_ANGLE_MEASURE_WITH_UNIT): value × its unit's factor.
fn measure(m: EntityRef<'_>, want: Kind, depth: usize) -> Res<f64> {
    let own = part(m, "MEASURE_WITH_UNIT", 0)?;
    let value = own.p(0, "value_component")?.f()?;
    let unit = own.p(1, "unit_component")?.ent()?;
    let f = value * factor(unit, want, depth + 1)?;
    if f.is_finite() && f > 0.0 {
        Ok(f)
    } else {
        Err(bad(&m, "conversion factor is not a positive number"))
    }
}

/// Factors of the common conversion-based units by name, for files whose factor is unreadable.
#[must_use]
fn known(name: &str, want: Kind) -> Option<f64> {
    match (want, name) {
        (Kind::Length, "INCH") => Some(25.4),
        (Kind::Length, "FOOT") => Some(304.8),
        (Kind::Length, "YARD") => Some(914.4),
        (Kind::Length, "MILE") => Some(1_609_344.0),
        (Kind::Angle, "DEGREE") => Some(std::f64::consts::PI / 180.0),
        (Kind::Angle, "GRAD") => Some(std::f64::consts::PI / 200.0),
        _ => None,
    }
}

/// ISO 10303-41 si_prefix values.
#[must_use]
fn prefix(p: &str) -> Option<f64> {
    Some(match p {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    })
}

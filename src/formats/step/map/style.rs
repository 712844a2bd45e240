//! Colours (ISO 10303-46 presentation appearance): STYLED_ITEM / OVER_RIDING_STYLED_ITEM →
//! PRESENTATION_STYLE_ASSIGNMENT → SURFACE_STYLE_USAGE → SURFACE_SIDE_STYLE →
//! SURFACE_STYLE_FILL_AREA → FILL_AREA_STYLE → FILL_AREA_STYLE_COLOUR → COLOUR_RGB or
//! DRAUGHTING_PRE_DEFINED_COLOUR (also SURFACE_STYLE_RENDERING's surface colour, which AP242
//! writers use). AP214 files keep the styled items in a
//! MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION; they are found wherever they are.
//!
//! The result maps a styled item (a face, shell, solid, mapped item) to its colour; the walk
//! over the shapes passes colours down, so the innermost styled item wins. Over-riding styles
//! replace plain ones on the same item. A style that cannot be read is reported as a warning
//! and ignored: colours never stop a file from being drawn.

use std::collections::HashMap;

use crate::formats::step::{EntityRef, StepFile};

use super::attrs::{P, Res, is, part};

/// How deeply styles may nest (select lists of selects).
const MAX_DEPTH: usize = 8;

/// Styled item → linear RGB in [0, 1], and warnings for unreadable styles.
#[must_use]
pub(crate) fn colours(file: &StepFile) -> (HashMap<u64, [f64; 3]>, Vec<String>) {
    let mut plain = HashMap::new();
    let mut over = HashMap::new();
    let mut warnings = Vec::new();
    for e in file.entities() {
        if !is(&e, "STYLED_ITEM") {
            continue;
        }
        match styled(e) {
            Ok(Some((item, rgb))) => {
                let map = if is(&e, "OVER_RIDING_STYLED_ITEM") {
                    &mut over
                } else {
                    &mut plain
                };
                map.insert(item, rgb);
            }
            Ok(None) => {}
            Err(err) => warnings.push(format!("{} (colour ignored)", err.text)),
        }
    }
    plain.extend(over);
    (plain, warnings)
}

/// The item and colour of one styled item, if it carries a surface colour.
fn styled(e: EntityRef<'_>) -> Res<Option<(u64, [f64; 3])>> {
    let own = part(e, "STYLED_ITEM", 1)?;
    let styles = own.p(0, "styles")?.ents()?;
    let item = own.p(1, "item")?.reference().map_err(super::attrs::msg)?;
    for s in styles {
        if let Some(rgb) = find(s, 0)? {
            return Ok(Some((item, rgb)));
        }
    }
    Ok(None)
}

/// The first surface colour below a style entity.
fn find(e: EntityRef<'_>, depth: usize) -> Res<Option<[f64; 3]>> {
    if depth > MAX_DEPTH {
        return Ok(None);
    }
    let below = |rec: &str, inherited, index, name| -> Res<Vec<EntityRef<'_>>> {
        let p = part(e, rec, inherited)?.p(index, name)?;
        match p.list() {
            Ok(_) => p.ents(),
            Err(_) => Ok(vec![p.ent()?]),
        }
    };
    let next: Vec<EntityRef<'_>> = if is(&e, "PRESENTATION_STYLE_ASSIGNMENT") {
        below("PRESENTATION_STYLE_ASSIGNMENT", 0, 0, "styles")?
    } else if is(&e, "SURFACE_STYLE_USAGE") {
        below("SURFACE_STYLE_USAGE", 0, 1, "style")?
    } else if is(&e, "SURFACE_SIDE_STYLE") {
        below("SURFACE_SIDE_STYLE", 0, 1, "styles")?
    } else if is(&e, "SURFACE_STYLE_FILL_AREA") {
        below("SURFACE_STYLE_FILL_AREA", 0, 0, "fill_area")?
    } else if is(&e, "FILL_AREA_STYLE") {
        below("FILL_AREA_STYLE", 0, 1, "fill_styles")?
    } else if is(&e, "FILL_AREA_STYLE_COLOUR") {
        below("FILL_AREA_STYLE_COLOUR", 0, 1, "fill_colour")?
    } else if is(&e, "SURFACE_STYLE_RENDERING") {
        below("SURFACE_STYLE_RENDERING", 0, 1, "surface_colour")?
    } else if is(&e, "COLOUR_RGB") {
        return rgb(e).map(Some);
    } else if is(&e, "DRAUGHTING_PRE_DEFINED_COLOUR") || is(&e, "PRE_DEFINED_COLOUR") {
        let name = part(e, "PRE_DEFINED_ITEM", 0)?.p(0, "name")?.text()?;
        return Ok(predefined(name));
    } else {
        return Ok(None);
    };
    for n in next {
        if let Some(c) = find(n, depth + 1)? {
            return Ok(Some(c));
        }
    }
    Ok(None)
}

/// COLOUR_RGB(name, red, green, blue), clamped into [0, 1].
fn rgb(e: EntityRef<'_>) -> Res<[f64; 3]> {
    let own = part(e, "COLOUR_RGB", 1)?;
    let c = |i, name| {
        own.p(i, name)
            .and_then(|p| p.f())
            .map(|x| x.clamp(0.0, 1.0))
    };
    Ok([c(0, "red")?, c(1, "green")?, c(2, "blue")?])
}

/// The pre-defined colours of ISO 10303-46 §4.4.39 (DRAUGHTING_PRE_DEFINED_COLOUR names).
#[must_use]
fn predefined(name: &str) -> Option<[f64; 3]> {
    Some(match name.trim().to_ascii_lowercase().as_str() {
        "red" => [1.0, 0.0, 0.0],
        "green" => [0.0, 1.0, 0.0],
        "blue" => [0.0, 0.0, 1.0],
        "yellow" => [1.0, 1.0, 0.0],
        "magenta" => [1.0, 0.0, 1.0],
        "cyan" => [0.0, 1.0, 1.0],
        "black" => [0.0, 0.0, 0.0],
        "white" => [1.0, 1.0, 1.0],
        _ => return None,
    })
}

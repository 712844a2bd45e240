//! What was read but not drawn: faces that could not be built (with their reasons) and every
//! entity no drawn face used, counted per type with the reason its kind is not drawn; one
//! warning line per kind, plus one line each for the trim repairs made.

use std::collections::BTreeMap;

use crate::formats::iges::type_name;

use super::loops::SNAP;
use super::reader::Reader;
use crate::formats::cad::Skipped;

/// Why an entity of this type that no face used is not drawn.
fn reason(entity_type: i32, form: i32) -> &'static str {
    match entity_type {
        0 => "null entity",
        100..=112 | 116 | 123 | 125..=126 | 130 => {
            "wireframe geometry (not part of a face) is not drawn"
        }
        142 => "curve on a surface outside a face is wireframe, not drawn",
        114 | 118..=122 | 128 | 140 | 143 | 144 | 190..=198 => "surface not reached as a face",
        124 => "transformation matrix used by nothing drawn",
        150..=184 => "CSG solid primitives and trees are not supported",
        202..=230 => "annotation is not drawn",
        308 => "subfigure definition without an instance",
        314 => "colour used by nothing drawn",
        402 if form == 9 => "single-parent associativity (planes with holes) is not supported",
        402..=430 => "structure or property entity without geometry",
        502..=514 => "B-rep part not reached from a solid or face",
        _ => "entity type not drawn",
    }
}

/// The skipped list and the warnings of a finished mapping run.
pub(crate) fn account(
    reader: &Reader<'_>,
    failed: &[(i32, String)],
) -> (Vec<Skipped>, Vec<String>) {
    let mut by_kind: BTreeMap<(i32, String), usize> = BTreeMap::new();
    for (t, why) in failed {
        *by_kind.entry((*t, why.clone())).or_insert(0) += 1;
    }
    for e in reader.file.entities() {
        let t = e.entity_type();
        // Groups only list faces; they are read, not drawn, and need no mention.
        let group = t == 402 && e.form() != 9;
        if group || reader.used.contains(&e.de()) {
            continue;
        }
        *by_kind
            .entry((t, reason(t, e.form()).to_owned()))
            .or_insert(0) += 1;
    }
    let skipped: Vec<Skipped> = by_kind
        .into_iter()
        .map(|((t, reason), count)| Skipped {
            what: format!("entity {t}"),
            count,
            reason,
        })
        .collect();
    let mut per_type: BTreeMap<&str, (usize, &str)> = BTreeMap::new();
    for s in &skipped {
        let slot = per_type.entry(&s.what).or_insert((0, &s.reason));
        slot.0 += s.count;
    }
    let mut warnings: Vec<String> = per_type
        .into_iter()
        .map(|(what, (count, why))| {
            let t: i32 = what.trim_start_matches("entity ").parse().unwrap_or(-1);
            format!("{what} ({}): {count} not drawn: {why}", type_name(t))
        })
        .collect();
    let r = reader.repairs;
    if r.snapped > 0 {
        warnings.push(format!(
            "trim gaps closed: {} (at most {:.3e} in parameter units, on {}; limit {SNAP:e} of the domain diagonal)",
            r.snapped, r.largest, reader.largest_gap_face
        ));
    }
    if r.bridged > 0 {
        warnings.push(format!(
            "trim loops bridged across {} degenerate edge(s) (poles or apexes)",
            r.bridged
        ));
    }
    let (relative, mm) = reader.off_surface;
    if relative > 1e-4 {
        warnings.push(format!(
            "model-space trim curves lie up to {mm:.3e} mm ({relative:.1e} of the surface size) off their surfaces"
        ));
    }
    (skipped, warnings)
}

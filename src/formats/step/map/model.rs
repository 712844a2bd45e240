//! The whole file: product structure → face instances → mapped faces, and the account of what
//! was not drawn.
//!
//! Each face entity is mapped once (in its representation's units) and every instance gets a
//! copy of the result with its control points moved by the instance's transformation (affine
//! maps keep a rational B-spline exact: the same weights, the moved points). A face that cannot
//! be mapped is skipped with its reason unless the file itself is malformed, which fails the
//! whole read.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::formats::step::StepFile;
use glam::DAffine3;

use super::assembly::{self, Instance};
use super::attrs::{Error, Kind, is};
use super::trims::{self, Mapped};
use super::{CadFace, CadModel, Skipped, products, style, surface, topology};

/// A face mapped once, shared by its instances.
struct Done {
    mapped: Mapped,
    surface_type: String,
    /// same_sense = .F. or a flipped rectangular trim.
    flip: bool,
}

/// What was not drawn: `(type, reason)` → (count, first line/id message).
#[derive(Default)]
struct Account {
    entries: BTreeMap<(String, String), (usize, String)>,
}

impl Account {
    fn add(&mut self, what: &str, reason: &str, first: impl FnOnce() -> String) {
        let slot = self
            .entries
            .entry((what.to_owned(), reason.to_owned()))
            .or_insert_with(|| (0, first()));
        slot.0 += 1;
    }
}

/// Builds the model of a parsed file.
pub(crate) fn build(file: &StepFile) -> Result<CadModel, String> {
    let fatal = |e: Error| e.text;
    let products = products::index(file).map_err(fatal)?;
    let (colours, mut warnings) = style::colours(file);
    let walk = assembly::walk(file, &products, &colours).map_err(fatal)?;
    warnings.extend(walk.warnings.iter().cloned());
    let mut account = Account::default();
    for (what, &(count, line, id)) in &walk.not_drawn {
        for _ in 0..count {
            account.add(what, "not a face or solid: not drawn", || {
                format!("line {line}: #{id} {what}")
            });
        }
    }
    let mut mapped = map_all(file, &walk.instances);
    let mut done: HashMap<u64, Result<Done, (String, String, String)>> = HashMap::new();
    let mut faces = Vec::with_capacity(walk.instances.len());
    let mut names: HashMap<String, usize> = HashMap::new();
    for inst in &walk.instances {
        let entry = match done.get(&inst.face) {
            Some(d) => d,
            None => {
                let result = mapped
                    .remove(&inst.face)
                    .unwrap_or_else(|| map_one(file, inst));
                let d = match result {
                    Ok(d) => Ok(d),
                    Err(e) if e.kind == Kind::Malformed => return Err(e.text),
                    Err(e) => Err(failure(&e)),
                };
                done.entry(inst.face).or_insert(d)
            }
        };
        match entry {
            Ok(d) => faces.push(place(d, inst, &mut names)),
            Err((what, reason, text)) => account.add(what, reason, || text.clone()),
        }
    }
    unreached(file, &walk.instances, &mut account);
    let mut skipped = Vec::new();
    for ((what, reason), (count, first)) in account.entries {
        warnings.push(format!("{first}: {count} × {what} not drawn: {reason}"));
        skipped.push(Skipped {
            what,
            count,
            reason,
        });
    }
    Ok(CadModel {
        faces,
        skipped,
        warnings,
        unit: "mm".to_owned(),
    })
}

/// Most threads that map faces.
const MAX_THREADS: usize = 8;

/// Maps every distinct face once, spread over threads (faces are independent: each reads the
/// shared, immutable file and builds its own surface). A face a thread did not deliver is
/// mapped again by the caller, so the result never depends on the threads.
fn map_all(file: &StepFile, instances: &[Instance]) -> HashMap<u64, Result<Done, Error>> {
    let mut seen = HashSet::new();
    let firsts: Vec<&Instance> = instances.iter().filter(|i| seen.insert(i.face)).collect();
    let next = AtomicUsize::new(0);
    let work = || {
        let mut out = Vec::new();
        while let Some(inst) = firsts.get(next.fetch_add(1, Ordering::Relaxed)) {
            out.push((inst.face, map_one(file, inst)));
        }
        out
    };
    let threads = crate::parallel::threads()
        .min(MAX_THREADS)
        .min(firsts.len());
    std::thread::scope(|s| {
        let helpers: Vec<_> = (1..threads)
            .filter_map(|_| std::thread::Builder::new().spawn_scoped(s, work).ok())
            .collect();
        let mut all: HashMap<u64, Result<Done, Error>> = work().into_iter().collect();
        for h in helpers {
            if let Ok(part) = h.join() {
                all.extend(part);
            }
        }
        all
    })
}

/// Reads and maps one face entity.
fn map_one(file: &StepFile, inst: &Instance) -> Result<Done, Error> {
    let e = file.get(inst.face).map_err(super::attrs::msg)?;
    let face = topology::read_face(e, inst.rad)?;
    let surf = surface::read(face.surface, inst.rad, face.extent)?;
    let mapped = trims::map_face(&face, &surf)?;
    Ok(Done {
        mapped,
        surface_type: surf.type_name.clone(),
        flip: !face.same_sense ^ surf.flip,
    })
}

/// What, why, and the first line of a face that failed.
#[must_use]
fn failure(e: &Error) -> (String, String, String) {
    let (place, why) = e
        .parts
        .clone()
        .unwrap_or_else(|| (e.text.clone(), String::new()));
    match &e.kind {
        Kind::Unsupported(t) => (t.clone(), why, place),
        _ => (
            "ADVANCED_FACE".to_owned(),
            format!("trim not mapped: {why}"),
            place,
        ),
    }
}

/// One instance of a mapped face.
#[must_use]
fn place(d: &Done, inst: &Instance, names: &mut HashMap<String, usize>) -> CadFace {
    let m: DAffine3 = inst.to_mm;
    let mut surface = d.mapped.surface.clone();
    for p in &mut surface.points {
        *p = m.transform_point3(*p);
    }
    let mirrored = m.matrix3.determinant() < 0.0;
    let base = format!("{}#{}", inst.product, inst.face);
    let n = names.entry(base.clone()).or_insert(0);
    *n += 1;
    let name = if *n == 1 { base } else { format!("{base}@{n}") };
    CadFace {
        name,
        surface_type: d.surface_type.clone(),
        surface,
        loops: d.mapped.loops.clone(),
        color: inst.colour,
        reversed: d.flip ^ inst.flip ^ mirrored,
    }
}

/// Faces that no walk reached (in a GEOMETRIC_CURVE_SET, an unreferenced shell, …).
fn unreached(file: &StepFile, instances: &[Instance], account: &mut Account) {
    let reached: HashSet<u64> = instances.iter().map(|i| i.face).collect();
    for e in file.entities() {
        if is(&e, "FACE_SURFACE") && !reached.contains(&e.id()) {
            let first = || format!("line {}: #{} {}", e.line(), e.id(), e.name());
            account.add(
                e.name(),
                "not in any shape reached from a product or representation",
                first,
            );
        }
    }
}

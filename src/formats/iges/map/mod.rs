//! IGES 5.3 entities → trimmed NURBS faces ([`CadModel`]).
//!
//! The route: the `iges` crate parses the file; `roots` finds the faces to draw by following
//! pointers (trimmed 144, bounded 143, B-rep solids 186 → shells 514 → faces 510, subfigure
//! instances 408 → definitions 308, and surfaces on their own); `surfaces` makes each surface
//! an exact NURBS (128/114 directly, analytic ones through the analytic crate, cut to the face's
//! parameter box); `boundary` reads the loops with their preference flags; `trace` puts them
//! in the NURBS parameter space (exactly where a closed form exists, else as polylines within
//! [`FLATTEN`] of the domain diagonal); `loops` closes gaps up to [`SNAP`] of it; the trim crate
//! validates and classifies the loops ([`check`]). Everything not drawn is counted in
//! [`CadModel::skipped`] with a reason, one warning per kind.
//!
//! Errors: a malformed file (broken layout, bad parameters, dangling or mistyped pointers) is one
//! line naming the file line and DE; a face that is well-formed but cannot be drawn is skipped
//! with its reason, and the rest of the model is kept.

mod boundary;
pub mod check;
mod curves;
pub mod eval;
mod faces;
mod fail;
mod invert;
mod loops;
mod reader;
mod roots;
mod segment;
mod skipped;
mod surfaces;
mod trace;

#[cfg(test)]
mod tests;

pub use crate::formats::cad::{CadCurve2, CadFace, CadLoop, CadModel, CadPiece, Skipped};
pub use crate::geom::analytic::NurbsSurface;
pub use loops::SNAP;
pub use trace::{FLATTEN, PIECES_PER_SPAN};

use crate::formats::iges::IgesFile;

use fail::Fail;
use reader::Reader;
use roots::Outcome;

/// Reads an IGES file into trimmed NURBS faces; faces are named after the Global section's
/// product id (or file name) and their DE number.
pub fn read_iges(bytes: &[u8]) -> Result<CadModel, String> {
    read_iges_named(bytes, None)
}

/// [`read_iges`] for a file named `stem` (its name without directory and extension): faces
/// are named after the Global section's product id, else after `stem` (`hammer#341`), else
/// the receiving system's id or the file name the Global section gives.
pub fn read_iges_with_stem(bytes: &[u8], stem: Option<&str>) -> Result<CadModel, String> {
    let file = IgesFile::parse(bytes).map_err(|e| e.to_string())?;
    let own = file.global.product_id.trim();
    let name = if own.is_empty() { stem } else { Some(own) };
    read_parsed(&file, name.map(str::to_owned))
}

/// [`read_iges`] with the face-name stem given by the caller (normally the file stem:
/// `hammer#341`).
pub fn read_iges_named(bytes: &[u8], stem: Option<&str>) -> Result<CadModel, String> {
    let file = IgesFile::parse(bytes).map_err(|e| e.to_string())?;
    read_parsed(&file, stem.map(str::to_owned))
}

/// Maps a parsed file, faces named after `stem` or [`default_stem`].
fn read_parsed(file: &IgesFile, stem: Option<String>) -> Result<CadModel, String> {
    let stem = stem.unwrap_or_else(|| default_stem(file));
    let refs = roots::referenced(file).map_err(|e| e.to_string())?;
    let mut reader = Reader::new(file, stem);
    let unit = reader.unit();
    let mut outcomes = Vec::new();
    for e in file.entities() {
        if refs.contains(&e.de()) {
            continue;
        }
        match reader.root(e, &unit, 0, &mut outcomes) {
            Ok(()) => {}
            Err(Fail::Malformed(m) | Fail::Skip(m)) => return Err(m),
        }
    }
    let mut faces = Vec::new();
    let mut failed = Vec::new();
    for o in outcomes {
        match o {
            Outcome::Face(f) => faces.push(f),
            Outcome::Skipped {
                entity_type,
                reason,
            } => failed.push((entity_type, reason)),
        }
    }
    unique_names(&mut faces);
    let (skipped, warnings) = skipped::account(&reader, &failed);
    Ok(CadModel {
        faces,
        skipped,
        warnings,
        unit: "mm".to_owned(),
    })
}

/// Second and later instances of the same face (subfigure instances) get `@2`, `@3`, …
fn unique_names(faces: &mut [CadFace]) {
    let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for f in faces {
        let n = seen.entry(f.name.clone()).or_insert(0);
        *n += 1;
        if *n > 1 {
            f.name = format!("{}@{n}", f.name);
        }
    }
}

/// The product id, else the file name's stem from the Global section, else "iges".
fn default_stem(file: &IgesFile) -> String {
    let g = &file.global;
    let name = [g.product_id.trim(), g.receiver_product_id.trim()]
        .into_iter()
        .find(|s| !s.is_empty())
        .map(str::to_owned)
        .or_else(|| {
            let f = g.file_name.trim();
            let base = f.rsplit(['/', '\\']).next().unwrap_or(f);
            let stem = base.split('.').next().unwrap_or(base);
            (!stem.is_empty()).then(|| stem.to_owned())
        });
    name.unwrap_or_else(|| "iges".to_owned())
}

//! `prespline info FILE [--json]`: what a file holds, for every format — one line per object
//! (name, kind, degrees, control net, trimmed or not, the area of what is drawn) and the
//! totals, or one JSON object (docs/info.md).

use super::CliError;
use super::args::{MemoryArgs, SamplesArgs};
use super::load::load_import;
use crate::fields::write::{json_string, number};
use crate::formats::Import;
use crate::model::ControlLayout;
use crate::scene::{Measure, SceneObject, escape_controls};
use clap::Args;
use glam::DVec3;
use std::fmt::Write;
use std::path::PathBuf;

/// Describe a scene file: every object, its area and the bounds of what is drawn.
///
/// One line per object (name, kind, degrees, control net, trim loops, area of what is drawn:
/// a trimmed surface's trimmed part) and the totals: objects, faces (surfaces drawn), total
/// area, bounding box and unit. Areas are ∫∫|S_u × S_v| over the drawn domain, computed from
/// the exact geometry (docs/info.md says how, and how accurately).
#[derive(Args, Debug, Clone)]
pub struct InfoArgs {
    /// Scene file (any format prespline reads).
    pub file: PathBuf,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub samples: SamplesArgs,
    #[command(flatten)]
    pub memory: MemoryArgs,
}

/// One object as `info` reports it.
struct Row<'a> {
    object: &'a SceneObject,
    measure: Measure,
}

/// Loads, measures and prints.
pub fn run(args: InfoArgs) -> Result<(), CliError> {
    let (import, notes) = load_import(&args.file, &args.samples.counts(), &args.memory.budget())?;
    let measured = crate::parallel::map(&import.scene.objects, SceneObject::measure);
    let mut rows = Vec::with_capacity(measured.len());
    for (o, m) in import.scene.objects.iter().zip(measured) {
        let measure =
            m.map_err(|e| CliError::in_file(&args.file, format!("object '{}': {e}", o.name)))?;
        rows.push(Row { object: o, measure });
    }
    let text = if args.json {
        json(&import, &rows)
    } else {
        table(&args.file.display().to_string(), &import, &rows)
    };
    notes.print();
    super::print_stdout(&text)
}

fn faces(rows: &[Row<'_>]) -> usize {
    rows.iter().filter(|r| r.object.model.is_surface()).count()
}

fn total_area(rows: &[Row<'_>]) -> f64 {
    rows.iter().map(|r| r.measure.area).sum()
}

fn total_bounds(rows: &[Row<'_>]) -> Option<[DVec3; 2]> {
    rows.iter()
        .filter_map(|r| r.measure.bounds)
        .reduce(|a, b| [a[0].min(b[0]), a[1].max(b[1])])
}

/// `3x3`, `3`, or `-`.
fn degrees(o: &SceneObject) -> String {
    let d = o.model.kind().degrees();
    if d.is_empty() {
        return "-".into();
    }
    let parts: Vec<String> = d.iter().map(ToString::to_string).collect();
    parts.join("x")
}

/// The control net's size: `7x7`, `12`, or the number of ERBS locals.
fn net(o: &SceneObject) -> String {
    match o.model.kind().controls().layout {
        ControlLayout::Polygon { count } => count.to_string(),
        ControlLayout::Net { rows, cols } => format!("{rows}x{cols}"),
        ControlLayout::LocalCurves(l) | ControlLayout::LocalPatches(l) => {
            format!("{} locals", l.len())
        }
    }
}

fn loops(o: &SceneObject) -> usize {
    o.trim.as_ref().map_or(0, |t| t.spec().loops.len())
}

fn table(file: &str, import: &Import, rows: &[Row<'_>]) -> String {
    let mut s = String::new();
    let name_w = rows
        .iter()
        .map(|r| r.object.name.chars().count())
        .max()
        .unwrap_or(4)
        .clamp(4, 40);
    let _ = writeln!(
        s,
        "{:<name_w$}  {:<16} {:>7} {:>10} {:>9} {:>14}",
        "name", "kind", "degrees", "net", "trim", "area"
    );
    for r in rows {
        let o = r.object;
        let trim = match loops(o) {
            0 => "-".to_string(),
            1 => "1 loop".to_string(),
            n => format!("{n} loops"),
        };
        let area = if o.model.is_surface() {
            format!("{:.6}", r.measure.area)
        } else {
            "-".into()
        };
        let _ = writeln!(
            s,
            "{:<name_w$}  {:<16} {:>7} {:>10} {:>9} {:>14}",
            escape_controls(&o.name),
            o.model.type_name(),
            degrees(o),
            net(o),
            trim,
            area
        );
    }
    let unit = import.unit.as_deref().unwrap_or("not given");
    let _ = writeln!(
        s,
        "{}: {} objects, {} faces, area {:.6}, unit {unit}",
        escape_controls(file),
        rows.len(),
        faces(rows),
        total_area(rows)
    );
    match total_bounds(rows) {
        Some([lo, hi]) => {
            let _ = writeln!(
                s,
                "bounds [{:.6}, {:.6}, {:.6}] .. [{:.6}, {:.6}, {:.6}]",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            );
        }
        None => s.push_str("bounds: nothing drawn\n"),
    }
    for k in &import.skipped {
        let _ = writeln!(
            s,
            "skipped: {} × {} ({})",
            k.count,
            escape_controls(&k.what),
            escape_controls(&k.reason)
        );
    }
    s
}

fn point(p: DVec3) -> String {
    format!("[{}, {}, {}]", number(p.x), number(p.y), number(p.z))
}

fn bounds_json(b: Option<[DVec3; 2]>) -> String {
    b.map_or_else(
        || "null".into(),
        |[lo, hi]| format!("[{}, {}]", point(lo), point(hi)),
    )
}

fn json(import: &Import, rows: &[Row<'_>]) -> String {
    let objects: Vec<String> = rows
        .iter()
        .map(|r| {
            let o = r.object;
            let d = o.model.kind().degrees();
            let degrees: Vec<String> = d.iter().map(ToString::to_string).collect();
            format!(
                "{{\"name\": {}, \"kind\": \"{}\", \"surface\": {}, \"degrees\": [{}], \"net\": {}, \"trimmed\": {}, \"loops\": {}, \"area\": {}, \"bounds\": {}}}",
                json_string(&o.name),
                o.model.type_name(),
                o.model.is_surface(),
                degrees.join(", "),
                json_string(&net(o)),
                o.trim.is_some(),
                loops(o),
                number(r.measure.area),
                bounds_json(r.measure.bounds)
            )
        })
        .collect();
    let skipped: Vec<String> = import
        .skipped
        .iter()
        .map(|k| {
            format!(
                "{{\"what\": {}, \"count\": {}, \"reason\": {}}}",
                json_string(&k.what),
                k.count,
                json_string(&k.reason)
            )
        })
        .collect();
    let unit = import
        .unit
        .as_deref()
        .map_or_else(|| "null".into(), json_string);
    format!(
        "{{\"unit\": {unit}, \"objects\": [\n  {}\n], \"faces\": {}, \"area\": {}, \"bounds\": {}, \"skipped\": [{}]}}\n",
        objects.join(",\n  "),
        faces(rows),
        number(total_area(rows)),
        bounds_json(total_bounds(rows)),
        skipped.join(", ")
    )
}

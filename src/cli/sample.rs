//! `prespline sample`: samples every object of a scene (optionally after edits) and prints the
//! JSON contract of docs/scene-format.md on stdout.

use super::CliError;
use super::args::{MemoryArgs, SamplesArgs};
use super::load::{Notes, load_scene};
use crate::editor::{Editor, EditorOptions, ListRefused, TrimCoverage};
use crate::model::SampledObject;
use crate::sampling::SampleMode;
use crate::sampling::budget::Uses;
use crate::scene::EditList;
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;

/// Highest derivative order `--derivatives` accepts.
pub const MAX_DERIVATIVES: usize = 20;

/// Sample every object of a scene and print positions and derivatives as JSON on stdout.
#[derive(Args, Debug, Clone)]
pub struct SampleArgs {
    /// Scene file: JSON (docs/scene-format.md), Wavefront OBJ (docs/obj.md), STEP or IGES (docs/cad.md).
    pub scene: PathBuf,
    /// Highest derivative order N: curves get c..c^(N), surfaces every ∂^{a+b}S with a, b ≤ N.
    #[arg(long, short = 'd', default_value_t = 1, value_name = "N")]
    pub derivatives: usize,
    /// Edits (JSON list) applied in order through the incremental (delta) path.
    #[arg(long, value_name = "EDITS.json")]
    pub edits: Option<PathBuf>,
    /// Apply the edits to the model and re-sample from scratch instead of the delta path.
    #[arg(long)]
    pub full: bool,
    #[command(flatten)]
    pub samples: SamplesArgs,
    #[command(flatten)]
    pub memory: MemoryArgs,
}

/// Runs the command and prints the output; nothing is printed on error, so a failure never
/// leaves partial output.
pub fn run(args: SampleArgs) -> Result<(), CliError> {
    let (text, notes) = sample_text(&args)?;
    notes.print();
    super::print_stdout(&text)
}

/// The complete output text.
fn sample_text(args: &SampleArgs) -> Result<(String, Notes), CliError> {
    if args.derivatives > MAX_DERIVATIVES {
        return Err(CliError(format!(
            "--derivatives {} exceeds the supported maximum {MAX_DERIVATIVES}",
            args.derivatives
        )));
    }
    let budget = args.memory.budget();
    let (scene, notes) = load_scene(&args.scene, &args.samples.counts(), &budget)?;
    let edits = match &args.edits {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError(format!("cannot read {}: {e}", path.display())))?;
            Some((
                path,
                EditList::parse(&text).map_err(|e| CliError::in_file(path, e))?,
            ))
        }
        None => None,
    };
    let options = EditorOptions {
        mode: SampleMode::Derivatives(args.derivatives),
        uses: Uses {
            gpu_slots: 0,
            control_displays: false,
            json_text: true,
        },
        budget,
    };
    let mut editor = Editor::new(&scene, options).map_err(|e| CliError::in_file(&args.scene, e))?;
    if let Some((path, list)) = &edits {
        // Through the delta path; edits that grow an object are budgeted as they come.
        editor.submit_list(list).map_err(|r| match r {
            ListRefused::Edit(e) => CliError::in_file(path, e),
            ListRefused::OverBudget(e) => CliError::in_file(&args.scene, e),
        })?;
    }
    if args.full {
        editor.resample_all();
    }
    let doc = editor.into_document();
    let objects: Vec<&SampledObject> = doc.objects.iter().map(|o| &o.sampled).collect();
    let mut out = String::with_capacity(1 << 16);
    out.push_str("{\"objects\": [\n");
    for (i, (meta, obj)) in doc.objects.iter().zip(&objects).enumerate() {
        write_object(&mut out, &meta.name, obj, meta.trim.as_deref())
            .map_err(|e| CliError::in_file(&args.scene, e.0))?;
        out.push_str(if i + 1 < objects.len() { ",\n" } else { "\n" });
    }
    out.push_str("]}\n");
    Ok((out, notes))
}

/// Why sampling can overflow: a rational object whose weights lie far apart (its derivatives
/// divide by the weighted sum, which a tiny weight makes tiny near its point), else
/// coordinates too large for their powers.
fn overflow_cause(weights: Option<&[f64]>) -> String {
    let range = weights.and_then(|w| {
        let lo = w.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = w.iter().copied().fold(0.0f64, f64::max);
        (lo > 0.0 && hi / lo > 1e12).then_some((lo, hi))
    });
    match range {
        Some((lo, hi)) => format!(
            "its weights range from {lo:e} to {hi:e}, and rational derivatives divide by the \
             weighted sum: bring the weights within 1e12 of each other"
        ),
        None => "scale the coordinates down".into(),
    }
}

fn write_object(
    out: &mut String,
    name: &str,
    obj: &SampledObject,
    trim: Option<&TrimCoverage>,
) -> Result<(), CliError> {
    let grid = obj.grid();
    if let Some(bad) = grid.data.iter().position(|v| !v.is_finite()) {
        let sample = bad / grid.stride();
        return Err(CliError(format!(
            "object '{name}': evaluation overflowed (non-finite value in sample {sample}); {}",
            overflow_cause(obj.model().kind().weights())
        )));
    }
    let name_json = serde_json::to_string(name).expect("strings serialise");
    let _ = write!(
        out,
        "  {{\"name\": {name_json}, \"type\": \"{}\", \"params\": ",
        obj.type_name()
    );
    let params = obj.params();
    let g = grid.partials.max_order() + 1;
    if obj.model().is_surface() {
        out.push('[');
        numbers(out, params[0]);
        out.push_str(", ");
        numbers(out, params[1]);
        out.push_str("], \"samples\": [");
        let [mu, mv] = grid.dims;
        for i in 0..mu {
            out.push_str(if i == 0 { "[" } else { ", [" });
            for j in 0..mv {
                out.push_str(if j == 0 { "[" } else { ", [" });
                let s = grid.sample(i, j);
                for a in 0..g {
                    out.push_str(if a == 0 { "[" } else { ", [" });
                    for b in 0..g {
                        if b > 0 {
                            out.push_str(", ");
                        }
                        vec3(out, s[a * g + b].to_array());
                    }
                    out.push(']');
                }
                out.push(']');
            }
            out.push(']');
        }
        out.push(']');
        if let Some(t) = trim {
            // Which samples lie inside the trim (docs/scene-format.md, "Trims").
            out.push_str(", \"inside\": [");
            for i in 0..mu {
                out.push_str(if i == 0 { "[" } else { ", [" });
                for j in 0..mv {
                    if j > 0 {
                        out.push_str(", ");
                    }
                    out.push_str(if t.sample_inside(i, j) {
                        "true"
                    } else {
                        "false"
                    });
                }
                out.push(']');
            }
            out.push(']');
        }
        out.push('}');
    } else {
        numbers(out, params[0]);
        out.push_str(", \"samples\": [");
        for j in 0..grid.dims[0] {
            out.push_str(if j == 0 { "[" } else { ", [" });
            for (r, v) in grid.sample(j, 0).iter().enumerate() {
                if r > 0 {
                    out.push_str(", ");
                }
                vec3(out, v.to_array());
            }
            out.push(']');
        }
        out.push_str("]}");
    }
    Ok(())
}

/// Shortest round-trip decimal; Rust's `{:?}` for f64 prints exactly that, with exponents for
/// very large and small magnitudes (valid JSON).
fn number(out: &mut String, x: f64) {
    let _ = write!(out, "{x:?}");
}

fn numbers(out: &mut String, v: &[f64]) {
    out.push('[');
    for (i, &x) in v.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        number(out, x);
    }
    out.push(']');
}

fn vec3(out: &mut String, v: [f64; 3]) {
    numbers(out, &v);
}

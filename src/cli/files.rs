//! Scene files by extension (`.obj` Wavefront OBJ, anything else the JSON scene format), the
//! `--samples` override, and `prespline convert`.

use super::CliError;
use crate::model::{
    BezierSplineModel, CatmullRomModel, CurveModel, ErbsCurveModel, ErbsSurfaceModel, Model,
    SurfaceModel,
};
use crate::scene::obj::{Format, load_obj, save_scene_file};
use crate::scene::{MAX_CURVE_SAMPLES, MAX_SURFACE_SAMPLES, Scene};
use std::path::Path;

/// `--samples N` (every curve) and `--samples NxM` (every surface); the flag may be repeated.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SampleOverride {
    pub curve: Option<usize>,
    pub surface: Option<[usize; 2]>,
}

/// One `--samples` value: `N` for curves or `NxM` for surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SamplesArg {
    Curve(usize),
    Surface([usize; 2]),
}

impl SamplesArg {
    /// Parses `N` or `NxM` within the scene format's limits.
    pub fn parse(s: &str) -> Result<SamplesArg, String> {
        let count = |t: &str, max: usize| -> Result<usize, String> {
            let m: usize = t
                .trim()
                .parse()
                .map_err(|_| format!("'{t}' is not a sample count"))?;
            if m < 2 || m > max {
                return Err(format!("{m} samples: expected 2..={max}"));
            }
            Ok(m)
        };
        match s.split_once(['x', 'X']) {
            None => Ok(SamplesArg::Curve(count(s, MAX_CURVE_SAMPLES)?)),
            Some((a, b)) => {
                let (mu, mv) = (
                    count(a, MAX_SURFACE_SAMPLES)?,
                    count(b, MAX_SURFACE_SAMPLES)?,
                );
                if mu * mv > MAX_SURFACE_SAMPLES {
                    return Err(format!(
                        "{mu}x{mv} samples exceed the limit of {MAX_SURFACE_SAMPLES}"
                    ));
                }
                Ok(SamplesArg::Surface([mu, mv]))
            }
        }
    }
}

impl SampleOverride {
    /// The last `N` and the last `NxM` win.
    #[must_use]
    pub fn from_args(args: &[SamplesArg]) -> Self {
        let mut o = Self::default();
        for a in args {
            match *a {
                SamplesArg::Curve(m) => o.curve = Some(m),
                SamplesArg::Surface(m) => o.surface = Some(m),
            }
        }
        o
    }

    /// Gives every curve and surface of the scene the overriding counts (checked on parsing).
    pub fn apply(&self, scene: &mut Scene) -> Result<(), CliError> {
        for o in &mut scene.objects {
            let model = match (&o.model, self.curve, self.surface) {
                (Model::Curve(m), Some(n), _) => {
                    CurveModel::new(m.form(), m.curve().clone(), n).map(Model::Curve)
                }
                (Model::ErbsCurve(m), Some(n), _) => {
                    ErbsCurveModel::new(m.curve().clone(), n).map(Model::ErbsCurve)
                }
                (Model::CatmullRom(m), Some(n), _) => {
                    CatmullRomModel::new(m.spline().clone(), n).map(Model::CatmullRom)
                }
                (Model::BezierSpline(m), Some(n), _) => {
                    BezierSplineModel::new(m.spline().clone(), n).map(Model::BezierSpline)
                }
                (Model::Surface(m), _, Some(n)) => {
                    SurfaceModel::new(m.form(), m.surface().clone(), n).map(Model::Surface)
                }
                (Model::ErbsSurface(m), _, Some(n)) => {
                    ErbsSurfaceModel::new(m.surface().clone(), n).map(Model::ErbsSurface)
                }
                _ => continue,
            };
            o.model = model.map_err(|e| CliError(format!("--samples: {e}")))?;
        }
        Ok(())
    }
}

impl SampleOverride {
    /// The counts as defaults for scene-file objects that give none.
    #[must_use]
    pub fn defaults(&self) -> crate::scene::SampleDefaults {
        crate::scene::SampleDefaults {
            curve: self.curve,
            surface: self.surface,
        }
    }

    /// A note for each given count that no object of `scene` (loaded from `file`) takes:
    /// `--samples N` sets curves only and `NxM` surfaces only, so `--samples 5` on a scene of
    /// surfaces would otherwise change nothing without a word.
    #[must_use]
    pub fn unused_notes(&self, scene: &Scene, file: &str) -> Vec<String> {
        let surfaces = scene
            .objects
            .iter()
            .filter(|o| o.model.is_surface())
            .count();
        let curves = scene.objects.len() - surfaces;
        let mut notes = Vec::new();
        if let Some(n) = self.curve.filter(|_| curves == 0) {
            notes.push(format!(
                "note: --samples {n} sets the sample count of curves, and {file} has none \
                 (surfaces take NxM: --samples {n}x{n})"
            ));
        }
        if let Some([u, v]) = self.surface.filter(|_| surfaces == 0) {
            notes.push(format!(
                "note: --samples {u}x{v} sets the sample count of surfaces, and {file} has none \
                 (curves take N: --samples {u})"
            ));
        }
        notes
    }
}

/// Loads a scene file of either format; OBJ warnings go to stderr as `FILE:LINE: warning: …`,
/// then a note for a `--samples` count the scene has no object for.
pub fn load_scene(path: &Path, samples: &SampleOverride) -> Result<Scene, CliError> {
    let mut scene = match Format::of(path) {
        Some(Format::Obj) => {
            let import = load_obj(path).map_err(|e| CliError(e.0))?;
            for w in &import.warnings {
                eprintln!("{}", crate::scene::escape_controls(&w.in_file(path)));
            }
            import.scene
        }
        _ => Scene::load_with(path, samples.defaults()).map_err(|e| CliError::in_file(path, e))?,
    };
    samples.apply(&mut scene)?;
    let shown = path.display().to_string();
    for note in samples.unused_notes(&scene, &crate::scene::escape_controls(&shown)) {
        eprintln!("{note}");
    }
    Ok(scene)
}

/// `prespline convert IN OUT`: JSON ↔ OBJ by the extensions; returns the closing line.
pub fn convert(input: &Path, output: &Path, samples: &SampleOverride) -> Result<String, CliError> {
    for p in [input, output] {
        if Format::of(p).is_none() {
            return Err(CliError(format!(
                "{}: cannot tell the format from the extension (use .json or .obj)",
                p.display()
            )));
        }
    }
    let scene = load_scene(input, samples)?;
    let dropped = save_scene_file(&scene, output).map_err(|e| CliError::in_file(input, e))?;
    if !dropped.is_empty() {
        eprintln!(
            "warning: {}: written without: {}",
            output.display(),
            dropped.join("; ")
        );
    }
    Ok(format!(
        "wrote {} ({} objects)",
        output.display(),
        scene.objects.len()
    ))
}

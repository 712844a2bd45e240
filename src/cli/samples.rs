//! `--samples N` (every curve) and `--samples NxM` (every surface), in every command that
//! loads a scene.

use super::CliError;
use crate::formats::SampleDefaults;
use crate::scene::{MAX_CURVE_SAMPLES, MAX_SURFACE_SAMPLES, Scene};

/// The counts of the `--samples` flags of one command; the flag may be repeated.
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

    /// Gives every curve and surface of the scene the overriding counts (checked on parsing),
    /// each through its kind ([`crate::model::Kind::with_samples`]).
    pub fn apply(&self, scene: &mut Scene) -> Result<(), CliError> {
        for o in &mut scene.objects {
            let counts = if o.model.is_surface() {
                self.surface
            } else {
                self.curve.map(|n| [n, 1])
            };
            if let Some(counts) = counts {
                o.model = o
                    .model
                    .kind()
                    .with_samples(counts)
                    .map_err(|e| CliError(format!("--samples: {e}")))?;
            }
        }
        Ok(())
    }

    /// The counts as defaults for scene-file objects that give none.
    #[must_use]
    pub fn defaults(&self) -> SampleDefaults {
        SampleDefaults {
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

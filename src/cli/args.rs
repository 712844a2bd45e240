//! Argument groups several commands share (`#[command(flatten)]`), and the parsers of their
//! values.

use super::samples::{SampleOverride, SamplesArg};
use crate::render::maps::{MapRange, SurfaceMap};
use crate::render::{NetMode, ViewOptions, Wire};
use crate::sampling::budget::{self, MemoryBudget};
use clap::Args;

/// Sample counts that replace the file's (or, for files without them, the default).
#[derive(Args, Debug, Clone)]
pub struct SamplesArgs {
    /// Sample counts: N for every curve, NxM for every surface; repeat for both
    /// (e.g. --samples 400 --samples 64x64). A count the scene has no object for is noted.
    #[arg(long, value_name = "N|NxM", value_parser = SamplesArg::parse)]
    pub samples: Vec<SamplesArg>,
}

impl SamplesArgs {
    #[must_use]
    pub fn counts(&self) -> SampleOverride {
        SampleOverride::from_args(&self.samples)
    }
}

/// How much memory pre-evaluation may take.
#[derive(Args, Debug, Clone, Copy)]
pub struct MemoryArgs {
    /// Refuse scenes whose pre-evaluated tables, samples and GPU mirrors would need more than
    /// this (bytes, or with K, M, G, T: 512M, 4G). Default: half of physical memory.
    #[arg(long, value_name = "SIZE", value_parser = budget::parse_size)]
    pub memory_limit: Option<u64>,
}

impl MemoryArgs {
    /// The command's budget: every count read from its files, edits and flags is held to it
    /// before anything is built from it.
    #[must_use]
    pub fn budget(self) -> MemoryBudget {
        MemoryBudget::from_flag(self.memory_limit)
    }
}

/// The colour scale of curvature maps.
#[derive(Args, Debug, Clone, Copy)]
pub struct MapRangeArgs {
    /// Colour scale of curvature maps: per-object (each surface its own symmetric range from
    /// the 90th percentile of |value|; the patches of one model share one: surfaces named
    /// NAME_0, NAME_1, … whose bounding boxes touch, directly or through each other; see
    /// docs/viewer.md, "Analysis"), shared (one range over every surface) or MIN,MAX (fixed:
    /// MIN blue, MAX red, white halfway).
    #[arg(long, value_name = "shared|per-object|MIN,MAX", default_value = "per-object", value_parser = MapRange::parse, allow_hyphen_values = true)]
    pub map_range: MapRange,
}

/// What to draw besides curves and shaded surfaces.
#[derive(Args, Debug, Clone, Copy)]
pub struct DisplayArgs {
    /// Draw control polygons, control nets and control points.
    #[arg(long)]
    pub net: bool,
    /// Hide ERBS local curves and patches.
    #[arg(long)]
    pub no_local: bool,
    /// Isoparametric lines every N samples on surfaces (1 = full wireframe; N ≥ 1).
    #[arg(long, value_name = "N", value_parser = parse_wire)]
    pub wire: Option<u32>,
    /// Draw surface normals.
    #[arg(long)]
    pub normals: bool,
    /// Draw Frenet frames along curves.
    #[arg(long)]
    pub frenet: bool,
    /// Draw curvature combs along curves.
    #[arg(long)]
    pub comb: bool,
    /// Draw continuity badges (G0/G1/G2, C1/C2 from left and right derivatives) at curve
    /// junctions and at knots of multiplicity > 1.
    #[arg(long)]
    pub badges: bool,
    /// Colour surfaces by an analysis map, with a legend: gaussian, mean, kmax, kmin
    /// (principal curvatures) or zebra (reflection lines).
    #[arg(long, value_name = "MAP", value_parser = SurfaceMap::parse)]
    pub analysis: Option<SurfaceMap>,
    #[command(flatten)]
    pub map_range: MapRangeArgs,
    /// Draw every sample of every surface (no display level of detail).
    #[arg(long)]
    pub no_lod: bool,
}

/// `--wire N`: a whole number of samples between isolines, at least 1.
fn parse_wire(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(0) => {
            Err("0 draws no isolines: give N ≥ 1 (1 = full wireframe), or leave --wire out".into())
        }
        Ok(n) => Ok(n),
        Err(_) => Err(format!("'{s}' is not a whole number of samples ≥ 1")),
    }
}

impl DisplayArgs {
    #[must_use]
    pub fn options(self) -> ViewOptions {
        ViewOptions {
            control_nets: if self.net { NetMode::All } else { NetMode::Off },
            local_curves: !self.no_local,
            wire: match self.wire {
                None | Some(0) => Wire::Off,
                Some(1) => Wire::Full,
                Some(n) => Wire::Isolines(n),
            },
            normals: self.normals,
            frenet: self.frenet,
            curvature_comb: self.comb,
            badges: self.badges,
            analysis: self.analysis,
            map_range: self.map_range.map_range,
            lod: !self.no_lod,
            ..ViewOptions::default()
        }
    }
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("'{w}' is not a width"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("'{h}' is not a height"))?;
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(format!("{w}x{h}: width and height must be within 1..16384"));
    }
    Ok((w, h))
}

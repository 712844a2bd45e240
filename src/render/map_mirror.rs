//! The analysis map on the GPU: one f32 per surface vertex, in mirrors parallel to the sample
//! arenas, so a batch of surfaces drawn with one multi-draw reads its scalars with the same
//! vertex indices as its positions and normals (scalar `v` belongs to the vertex at floats
//! `6v` of the arena). Only curvature maps have scalars; zebra stripes need normals alone.
//!
//! The scalars follow the samples: the sample rows an edit dirtied are the scalar rows it
//! dirtied, so a drag copies only the touched rows of the map, like the vertex mirrors.

use super::maps::{MapScale, SurfaceMap};
use crate::editor::Document;
use crate::gpu::{Frame, GpuResult, Mirror};
use std::ops::Range;

/// What colours the surfaces: a map and each object's colour scale (by object index; ignored
/// by zebra stripes).
#[derive(Debug, Clone, PartialEq)]
pub struct MapView {
    pub map: SurfaceMap,
    pub scales: Vec<MapScale>,
}

/// A surface's place in its arena, for its scalars.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SurfaceSlot {
    pub arena: usize,
    /// Float offset of the surface's vertex (0, 0) in the arena (a multiple of 6).
    pub offset: usize,
}

/// The scalars of one curvature map, one mirror per arena: each value already placed on its
/// surface's scale (−1 … 1), so surfaces drawn in one batch keep their own scales.
pub(crate) struct MapScalars {
    /// The map and scales the values belong to.
    pub view: MapView,
    /// Per arena; arenas without surfaces hold a single unused float.
    pub mirrors: Vec<Mirror>,
}

/// Floats per surface vertex in the arenas (position, normal).
const VERTEX_FLOATS: usize = 6;

impl MapScalars {
    /// Computes every scalar of `map` and creates the mirrors (all slots written, no wait).
    /// `slots[i]` is object `i`'s place when it is a surface.
    pub fn build(
        frame: &mut Frame<'_>,
        doc: &Document,
        slots: &[Option<SurfaceSlot>],
        arenas: usize,
        view: &MapView,
    ) -> GpuResult<Self> {
        let mut data = vec![Vec::<f32>::new(); arenas];
        let mut row = Vec::new();
        for (i, slot) in slots.iter().enumerate() {
            let Some(slot) = slot else { continue };
            let rows = doc.objects[i].sampled.grid().dims[0];
            scalar_floats(doc, i, 0..rows, view, &mut row);
            let start = slot.offset / VERTEX_FLOATS;
            let a = &mut data[slot.arena];
            if a.len() < start + row.len() {
                a.resize(start + row.len(), 0.0);
            }
            a[start..start + row.len()].copy_from_slice(&row);
        }
        let mut mirrors = Vec::with_capacity(arenas);
        for (a, floats) in data.iter().enumerate() {
            match frame.create_mirror(&format!("map scalars {a}"), floats) {
                Ok(m) => mirrors.push(m),
                Err(e) => {
                    mirrors.into_iter().for_each(|m| frame.destroy_mirror(m));
                    return Err(e);
                }
            }
        }
        Ok(Self {
            view: view.clone(),
            mirrors,
        })
    }

    /// Copies the scalars of sample rows `rows` of surface `i` into this frame's slot; returns
    /// the bytes written.
    pub fn write_rows(
        &mut self,
        frame: &mut Frame<'_>,
        doc: &Document,
        i: usize,
        slot: SurfaceSlot,
        rows: Range<usize>,
        scratch: &mut Vec<f32>,
    ) -> GpuResult<usize> {
        let cols = doc.objects[i].sampled.grid().dims[1];
        scalar_floats(doc, i, rows.clone(), &self.view, scratch);
        let at = slot.offset / VERTEX_FLOATS + rows.start * cols;
        frame
            .write_mirror(&mut self.mirrors[slot.arena])
            .write(at, scratch)?;
        Ok(scratch.len() * 4)
    }

    /// Gives the mirrors back (released when their slots' fences signal).
    pub fn destroy_with(self, mut destroy: impl FnMut(Mirror)) {
        self.mirrors.into_iter().for_each(&mut destroy);
    }
}

/// The map's value at each sample of rows `rows` of surface `i` on the surface's scale, as f32;
/// NaN (drawn as undefined) where the object carries no curvature or the curvature is undefined.
pub(crate) fn scalar_floats(
    doc: &Document,
    i: usize,
    rows: Range<usize>,
    view: &MapView,
    out: &mut Vec<f32>,
) {
    let (map, scale) = (view.map, view.scales.get(i).copied());
    let scale = scale.unwrap_or(MapScale::symmetric(1.0));
    let grid = doc.objects[i].sampled.grid();
    let cols = grid.dims[1];
    let samples = rows.start * cols..rows.end * cols;
    out.clear();
    match &grid.curvatures {
        Some(kh) => out.extend(
            kh[samples]
                .iter()
                .map(|&kh| scale.unit(map.value(kh)) as f32),
        ),
        None => out.resize(samples.len(), f32::NAN),
    }
}

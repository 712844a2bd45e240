//! Coverage masks: per-fragment inside tests in grid coordinates for surfaces drawn from a
//! grid of vertices (trimmed surfaces). The words of every mask of a scene sit in one mirror;
//! a table mirror holds `uvec4` entries — the device address of a mask's words in that slot
//! and two words the caller chooses (the shaders read the vertices per grid row and the
//! surface's first vertex there) — which the trimmed pipelines read as
//! an instance-rate attribute, so a masked draw needs no descriptor set and no push constants
//! beyond the untrimmed one's (`shaders/trim.glsl` reads the words).

use super::FRAMES_IN_FLIGHT;
use super::error::{GpuError, GpuResult};
use super::frame::Frame;
use super::mirror::Mirror;
use super::region::MaskRef;

/// One surface's mask as the caller packed it (the layout `shaders/trim.glsl` documents), and
/// its table entries: each the mask's address followed by these two words.
#[derive(Debug, Clone)]
pub struct MaskWords<'a> {
    pub words: &'a [u32],
    pub entries: Vec<[u32; 2]>,
}

/// Every mask of a scene: their words and the table the draws index.
pub struct MaskSet {
    words: Mirror,
    table: Mirror,
    count: u32,
}

impl MaskSet {
    /// Table entry `k` (the masks' entries in order), for a [`super::SurfaceBatch`] of its
    /// surface.
    #[must_use]
    pub fn entry(&self, k: u32) -> MaskRef<'_> {
        MaskRef {
            table: &self.table,
            entry: k,
        }
    }

    /// How many table entries the set holds.
    #[must_use]
    pub fn len(&self) -> u32 {
        self.count
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Gives both mirrors to `release` (a frame's or the renderer's).
    pub fn destroy_with(self, mut release: impl FnMut(Mirror)) {
        release(self.words);
        release(self.table);
    }
}

impl Frame<'_> {
    /// Makes the set of `masks`, entry `k` for `masks[k]`. Never waits: the new buffers have
    /// never been used by the GPU, so every slot is written now, each slot's table pointing
    /// at that slot's words.
    pub fn create_mask_set(&mut self, masks: &[MaskWords<'_>]) -> GpuResult<MaskSet> {
        let total: usize = masks.iter().map(|m| m.words.len()).sum();
        let mut words = Vec::with_capacity(total.max(1));
        let mut starts = Vec::with_capacity(masks.len());
        for m in masks {
            starts.push(words.len());
            words.extend(m.words.iter().map(|&w| f32::from_bits(w)));
        }
        let words = self.create_mirror("coverage masks", &words)?;
        let count: usize = masks.iter().map(|m| m.entries.len()).sum();
        let mut table = match self.create_mirror("coverage mask table", &vec![0.0; count * 4]) {
            Ok(t) => t,
            Err(e) => {
                self.destroy_mirror(words);
                return Err(e);
            }
        };
        let entries = |slot: usize| -> Result<Vec<f32>, GpuError> {
            let base = words.slot(slot).address();
            let mut out = Vec::with_capacity(count * 4);
            for (m, &start) in masks.iter().zip(&starts) {
                let address = base + 4 * start as u64;
                for &[z, w] in &m.entries {
                    out.extend([
                        f32::from_bits(address as u32),
                        f32::from_bits((address >> 32) as u32),
                        f32::from_bits(z),
                        f32::from_bits(w),
                    ]);
                }
            }
            Ok(out)
        };
        let filled = (0..FRAMES_IN_FLIGHT).try_for_each(|slot| {
            let data = entries(slot)?;
            self.write_new_mirror_slot(&mut table, slot, &data)
        });
        if let Err(e) = filled {
            self.destroy_mirror(words);
            self.destroy_mirror(table);
            return Err(e);
        }
        let count = u32::try_from(count)
            .map_err(|_| GpuError::InvalidArgument("too many coverage masks".into()))?;
        Ok(MaskSet {
            words,
            table,
            count,
        })
    }
}

//! The one report an apply gives back: what changed, so that whoever mirrors the document (the
//! GPU scene, a test's reference copy) copies exactly that and never looks at the edits.

pub use crate::model::controls::ControlsChange;
use crate::sampling::{DirtyRegion, DirtySet};

/// What an apply changed in one object.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObjectChange {
    pub object: usize,
    /// The sample rectangles rewritten (each edit's own, the periodic exact rebuild's included),
    /// in the order they were written.
    pub samples: Vec<DirtyRegion>,
    pub controls: ControlsChange,
}

impl ObjectChange {
    /// Sample rows (surfaces) or samples (curves) touched, as one set of ranges.
    #[must_use]
    pub fn rows(&self) -> DirtySet {
        let mut set = DirtySet::default();
        for r in &self.samples {
            set.insert(r.rows.clone());
        }
        set
    }
}

/// The report of one apply: per touched object what changed, in first-touch order, and what it
/// cost.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Applied {
    pub changes: Vec<ObjectChange>,
    /// Edits applied (after merging a frame's edits per target).
    pub edits: usize,
    /// Samples rewritten.
    pub samples: usize,
    /// Time the apply took, in µs.
    pub micros: f64,
}

impl Applied {
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.changes.is_empty()
    }

    /// Whether any object's structure changed: its handles are numbered anew and its control
    /// display has another layout.
    #[must_use]
    pub fn structure_changed(&self) -> bool {
        self.changes
            .iter()
            .any(|c| c.controls == ControlsChange::Resized)
    }

    /// Records that `object`'s samples in `region` and its controls as `controls` changed.
    pub fn record(&mut self, object: usize, region: DirtyRegion, controls: ControlsChange) {
        self.samples += region.samples();
        let i = match self.changes.iter().position(|c| c.object == object) {
            Some(i) => i,
            None => {
                self.changes.push(ObjectChange {
                    object,
                    ..ObjectChange::default()
                });
                self.changes.len() - 1
            }
        };
        let c = &mut self.changes[i];
        if !region.is_empty() {
            c.samples.push(region);
        }
        c.controls.join(controls);
    }

    /// Another report folded into this one (the apply that follows in the same frame).
    pub fn extend(&mut self, other: Applied) {
        self.edits += other.edits;
        self.micros += other.micros;
        for c in other.changes {
            let object = c.object;
            for r in c.samples {
                self.record(object, r, ControlsChange::Unchanged);
            }
            self.record(object, DirtyRegion::NOTHING, c.controls);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changes_join_per_object_and_resizing_wins() {
        let mut a = Applied::default();
        let mut v = DirtySet::default();
        v.insert(3..4);
        a.record(2, DirtyRegion::curve(0..5), ControlsChange::Vertices(v));
        a.record(
            0,
            DirtyRegion::surface(1..3, 0..4),
            ControlsChange::Unchanged,
        );
        let mut w = DirtySet::default();
        w.insert(7..9);
        a.record(2, DirtyRegion::curve(10..12), ControlsChange::Vertices(w));
        assert_eq!(a.changes.len(), 2);
        assert_eq!(a.changes[0].object, 2);
        assert_eq!(a.samples, 5 + 8 + 2);
        assert_eq!(a.changes[0].rows().ranges(), &[0..5, 10..12]);
        let ControlsChange::Vertices(set) = &a.changes[0].controls else {
            panic!("vertices expected");
        };
        assert_eq!(set.ranges(), &[3..4, 7..9]);
        assert!(!a.structure_changed());
        a.record(0, DirtyRegion::NOTHING, ControlsChange::Resized);
        a.record(0, DirtyRegion::NOTHING, ControlsChange::Unchanged);
        assert!(a.structure_changed());
    }
}

//! Interactive tools: dragging a control point in the view plane or along an axis, and the
//! modal grab/rotate/scale of a control point or an ERBS local curve/patch, with axis
//! constraints and numeric entry.

use crate::render::{Bounds, OrbitCamera};
use glam::{DMat4, DVec3};

/// Axis constraint of a drag or transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Axis {
    /// View plane (drags, grab), view axis (rotate), uniform (scale).
    #[default]
    Free,
    X,
    Y,
    Z,
}

impl Axis {
    #[must_use]
    pub fn vector(self) -> Option<DVec3> {
        match self {
            Axis::Free => None,
            Axis::X => Some(DVec3::X),
            Axis::Y => Some(DVec3::Y),
            Axis::Z => Some(DVec3::Z),
        }
    }

    /// Pressing the same axis key twice returns to free movement.
    #[must_use]
    pub fn toggle(self, other: Axis) -> Axis {
        if self == other { Axis::Free } else { other }
    }

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Axis::Free => "",
            Axis::X => " X",
            Axis::Y => " Y",
            Axis::Z => " Z",
        }
    }
}

/// What a camera and image size say about the cursor.
#[derive(Debug, Clone, Copy)]
pub struct View<'a> {
    pub camera: &'a OrbitCamera,
    pub bounds: &'a Bounds,
    pub size: [f64; 2],
}

impl View<'_> {
    #[must_use]
    pub fn ray(&self, cursor: (f64, f64)) -> (DVec3, DVec3) {
        self.camera
            .ray(cursor.0, cursor.1, self.size[0], self.size[1], self.bounds)
    }

    #[must_use]
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        self.project_depth(p).map(|(x, y, _)| (x, y))
    }

    /// Pixel position and depth in [0, 1] of a world point; `None` behind the eye.
    #[must_use]
    pub fn project_depth(&self, p: DVec3) -> Option<(f64, f64, f64)> {
        self.camera
            .project(p, self.size[0], self.size[1], self.bounds)
    }
}

/// Where the cursor ray meets the plane through `anchor` facing the camera, or the point of
/// the axis line through `anchor` closest to the ray.
#[must_use]
pub fn cursor_point(view: &View, cursor: (f64, f64), anchor: DVec3, axis: Axis) -> Option<DVec3> {
    let (o, d) = view.ray(cursor);
    match axis.vector() {
        None => {
            let n = view.camera.direction();
            let denom = d.dot(n);
            if denom.abs() < 1e-12 {
                return None;
            }
            let t = (anchor - o).dot(n) / denom;
            Some(o + d * t)
        }
        Some(a) => {
            // Closest points of the line anchor + s·a and the ray o + t·d.
            let w = o - anchor;
            let b = a.dot(d);
            let denom = 1.0 - b * b;
            if denom.abs() < 1e-9 {
                return None;
            }
            let s = (a.dot(w) - b * d.dot(w)) / denom;
            Some(anchor + a * s)
        }
    }
}

/// Translation of a dragged point: the total offset from where the drag grabbed the plane (or
/// axis), so clicking slightly off the point does not make it jump.
#[derive(Debug, Clone)]
pub struct Drag {
    pub anchor: DVec3,
    grab: Option<DVec3>,
    pub axis: Axis,
    pub applied: DVec3,
}

impl Drag {
    #[must_use]
    pub fn new(anchor: DVec3) -> Self {
        Self {
            anchor,
            grab: None,
            axis: Axis::Free,
            applied: DVec3::ZERO,
        }
    }

    /// Sets the grab point from the cursor (at the start, or again after an axis change).
    pub fn grab(&mut self, view: &View, cursor: (f64, f64)) {
        self.grab = cursor_point(view, cursor, self.anchor + self.applied, self.axis)
            .map(|p| p - self.applied);
    }

    /// The increment to apply now so the total offset follows the cursor.
    pub fn update(&mut self, view: &View, cursor: (f64, f64)) -> Option<DVec3> {
        let grab = self.grab?;
        let p = cursor_point(view, cursor, self.anchor, self.axis)?;
        let mut total = p - grab;
        if let Some(a) = self.axis.vector() {
            total = a * total.dot(a);
        }
        let inc = total - self.applied;
        self.applied = total;
        (inc != DVec3::ZERO).then_some(inc)
    }
}

/// Grab, rotate or scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransformKind {
    Grab,
    Rotate,
    Scale,
}

impl TransformKind {
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            TransformKind::Grab => "Grab",
            TransformKind::Rotate => "Rotate",
            TransformKind::Scale => "Scale",
        }
    }
}

/// A modal transform about `pivot`, driven by the cursor or by a typed number (distance along
/// the axis, degrees, or a scale factor).
#[derive(Debug, Clone)]
pub struct Transform {
    pub kind: TransformKind,
    pub pivot: DVec3,
    pub axis: Axis,
    pub numeric: String,
    start_cursor: (f64, f64),
    cursor: (f64, f64),
    drag: Drag,
    /// The total transform already applied to the model during this gesture.
    pub applied: DMat4,
}

impl Transform {
    #[must_use]
    pub fn new(kind: TransformKind, pivot: DVec3, view: &View, cursor: (f64, f64)) -> Self {
        let mut drag = Drag::new(pivot);
        drag.grab(view, cursor);
        Self {
            kind,
            pivot,
            axis: Axis::Free,
            numeric: String::new(),
            start_cursor: cursor,
            cursor,
            drag,
            applied: DMat4::IDENTITY,
        }
    }

    pub fn set_axis(&mut self, axis: Axis, view: &View) {
        self.axis = self.axis.toggle(axis);
        self.drag = Drag::new(self.pivot);
        self.drag.axis = self.axis;
        self.drag.grab(view, self.start_cursor);
    }

    pub fn set_cursor(&mut self, cursor: (f64, f64)) {
        self.cursor = cursor;
    }

    /// The value typed so far, if it parses.
    #[must_use]
    pub fn typed(&self) -> Option<f64> {
        self.numeric.parse::<f64>().ok().filter(|v| v.is_finite())
    }

    /// The whole transform the gesture stands for now.
    pub fn total(&mut self, view: &View) -> DMat4 {
        let around = |m: DMat4| {
            DMat4::from_translation(self.pivot) * m * DMat4::from_translation(-self.pivot)
        };
        match self.kind {
            TransformKind::Grab => {
                let t = match (self.typed(), self.axis.vector()) {
                    (Some(v), Some(a)) => a * v,
                    _ => {
                        self.drag.update(view, self.cursor);
                        self.drag.applied
                    }
                };
                DMat4::from_translation(t)
            }
            TransformKind::Rotate => {
                let axis = self
                    .axis
                    .vector()
                    .unwrap_or_else(|| view.camera.direction());
                let angle = match self.typed() {
                    Some(deg) => deg.to_radians(),
                    None => self.screen_angle(view),
                };
                around(DMat4::from_axis_angle(axis, angle))
            }
            TransformKind::Scale => {
                let f = self.typed().unwrap_or_else(|| self.screen_ratio(view));
                let s = match self.axis.vector() {
                    None => DVec3::splat(f),
                    Some(a) => DVec3::ONE + a * (f - 1.0),
                };
                around(DMat4::from_scale(s))
            }
        }
    }

    /// Counter-clockwise screen angle swept around the pivot since the start (positive about
    /// the axis towards the viewer).
    fn screen_angle(&self, view: &View) -> f64 {
        let Some(c) = view.project(self.pivot) else {
            return 0.0;
        };
        let a0 = (self.start_cursor.1 - c.1).atan2(self.start_cursor.0 - c.0);
        let a1 = (self.cursor.1 - c.1).atan2(self.cursor.0 - c.0);
        // Screen y points down, so a clockwise-looking change in atan2 is counter-clockwise on
        // screen.
        let d = a0 - a1;
        let sign = match self.axis.vector() {
            Some(axis) if axis.dot(view.camera.direction()) < 0.0 => -1.0,
            _ => 1.0,
        };
        sign * d
    }

    fn screen_ratio(&self, view: &View) -> f64 {
        let Some(c) = view.project(self.pivot) else {
            return 1.0;
        };
        let r0 = (self.start_cursor.0 - c.0)
            .hypot(self.start_cursor.1 - c.1)
            .max(1.0);
        let r1 = (self.cursor.0 - c.0).hypot(self.cursor.1 - c.1);
        r1 / r0
    }

    /// HUD text: "Rotate Z 30°" and the like.
    #[must_use]
    pub fn describe(&self) -> String {
        let value = if self.numeric.is_empty() {
            String::new()
        } else {
            format!(" [{}]", self.numeric)
        };
        format!(
            "{}{}{}  (X/Y/Z axis, type a value, Enter/click confirm, Esc/right click cancel)",
            self.kind.name(),
            self.axis.name(),
            value
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> (OrbitCamera, Bounds) {
        let mut b = Bounds::EMPTY;
        b.include(DVec3::splat(-1.0));
        b.include(DVec3::splat(1.0));
        let mut c = OrbitCamera::default();
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
                DVec3::new(s(1), s(2), s(4))
            })
            .collect();
        c.frame_points(&corners, &b, 4.0 / 3.0);
        (c, b)
    }

    #[test]
    fn drag_follows_the_cursor_in_the_view_plane_and_along_axes() {
        let (cam, b) = view();
        let v = View {
            camera: &cam,
            bounds: &b,
            size: [800.0, 600.0],
        };
        let anchor = DVec3::new(0.2, 0.1, 0.3);
        let (x, y) = v.project(anchor).unwrap();
        let mut d = Drag::new(anchor);
        d.grab(&v, (x, y));
        d.update(&v, (x + 40.0, y - 25.0)).unwrap();
        let (nx, ny) = v.project(anchor + d.applied).unwrap();
        assert!((nx - x - 40.0).abs() < 1e-6 && (ny - y + 25.0).abs() < 1e-6);
        assert!(
            d.applied.dot(cam.direction()).abs() < 1e-9,
            "stays in the view plane"
        );
        let mut z = Drag::new(anchor);
        z.axis = Axis::Z;
        z.grab(&v, (x, y));
        z.update(&v, (x + 10.0, y - 60.0)).unwrap();
        assert_eq!((z.applied.x, z.applied.y), (0.0, 0.0));
        assert!(z.applied.z > 0.0);
    }

    #[test]
    fn typed_values_are_exact() {
        let (cam, b) = view();
        let v = View {
            camera: &cam,
            bounds: &b,
            size: [800.0, 600.0],
        };
        let mut t = Transform::new(
            TransformKind::Rotate,
            DVec3::new(1.0, 2.0, 0.0),
            &v,
            (100.0, 100.0),
        );
        t.set_axis(Axis::Z, &v);
        t.numeric = "90".into();
        let m = t.total(&v);
        let p = m.transform_point3(DVec3::new(2.0, 2.0, 0.5));
        assert!((p - DVec3::new(1.0, 3.0, 0.5)).length() < 1e-12, "{p:?}");
        let mut g = Transform::new(TransformKind::Grab, DVec3::ZERO, &v, (100.0, 100.0));
        g.set_axis(Axis::Z, &v);
        g.numeric = "1.5".into();
        assert_eq!(
            g.total(&v).transform_point3(DVec3::new(1.0, 2.0, 3.0)),
            DVec3::new(1.0, 2.0, 4.5)
        );
        let mut s = Transform::new(TransformKind::Scale, DVec3::ONE, &v, (100.0, 100.0));
        s.numeric = "2".into();
        assert_eq!(
            s.total(&v).transform_point3(DVec3::new(2.0, 1.0, 1.0)),
            DVec3::new(3.0, 1.0, 1.0)
        );
    }
}

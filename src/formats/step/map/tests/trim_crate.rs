//! A limitation of the trim crate found on real data, kept as a reproduction for its owner.

use crate::geom::trim::{LoopInput, Tolerances, TrimRegions};
use glam::DVec2;

/// Two curves leaving one vertex 0.009 rad apart (a cusp, trj5_k1-ug-214 #119 before the
/// mapping spread vertex offsets along its polylines): no two segments cross (checked exactly
/// below), yet the trim crate reports a self-crossing. Its contact runs around the vertex are
/// split by the pair of adjacent segments it skips, and `interleave` is then asked about an
/// arm of zero length. Expected to pass once the trim crate joins runs across a shared vertex.
#[test]
#[ignore = "trim crate: false self-crossing at a tangent cusp"]
fn cusp_is_not_a_crossing() {
    let p = |x: f64, y: f64| DVec2::new(x, y);
    let a = vec![
        p(4.931658394494, 1.080000000000),
        p(4.932258955022, 1.078814895467),
        p(4.932849991782, 1.077626724464),
        p(4.933431507930, 1.076435535670),
        p(4.934003506566, 1.075241377763),
    ];
    let b = vec![
        p(4.932791309491, 1.077916892969),
        p(4.932555730108, 1.078330016683),
        p(4.932324615666, 1.078744941090),
        p(4.932097999419, 1.079161614343),
        p(4.931875914613, 1.079579984596),
        p(4.931658394494, 1.080000000000),
    ];
    let pieces = vec![a.clone(), vec![a[4], b[0]], b.clone()];
    let poly: Vec<DVec2> = a.iter().chain(b.iter().take(5)).copied().collect();
    assert!(!crosses(&poly), "the polygon is simple");
    let r = TrimRegions::new(
        &[LoopInput { pieces, role: None }],
        [(4.9, 11.0), (0.9, 1.1)],
        &Tolerances::default(),
    );
    assert!(r.is_ok(), "{:?}", r.err());
}

/// Whether two non-adjacent edges of the closed polygon properly cross.
fn crosses(poly: &[DVec2]) -> bool {
    let n = poly.len();
    let seg = |i: usize| (poly[i], poly[(i + 1) % n]);
    (0..n).any(|i| {
        (i + 2..n).any(|j| {
            if i == 0 && j == n - 1 {
                return false;
            }
            let ((a, b), (c, d)) = (seg(i), seg(j));
            let side = |o: DVec2, p: DVec2, q: DVec2| (p - o).perp_dot(q - o);
            (side(a, b, c) > 0.0) != (side(a, b, d) > 0.0)
                && (side(c, d, a) > 0.0) != (side(c, d, b) > 0.0)
        })
    })
}

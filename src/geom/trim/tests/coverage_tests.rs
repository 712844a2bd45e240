//! Grid coverage: samples, cell classes, blocks and the shader's reference test.

use glam::DVec2;

use super::super::coverage::clip;
use super::super::{CellClass, Coverage, LoopInput, Tolerances, TrimError, TrimRegions};
use super::{Circle, Rng, UNIT, boundary_distance, curve_loop, ok, one_piece, rect};

pub(super) fn axis(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

fn cover(t: &TrimRegions, u: &[f64], v: &[f64]) -> Coverage {
    match Coverage::new(t, u, v) {
        Ok(c) => c,
        Err(e) => panic!("coverage failed: {e}"),
    }
}

/// Outer rectangle with a circular hole (centre `c`) holding a square island, on `domain`.
fn holed(domain: [(f64, f64); 2], c: DVec2, tol: f64) -> TrimRegions {
    let [(u0, u1), (v0, v1)] = domain;
    let at = |x: f64, y: f64| DVec2::new(u0 + (u1 - u0) * x, v0 + (v1 - v0) * y);
    let outer = rect(
        at(0.1, 0.1).x,
        at(0.1, 0.1).y,
        at(0.9, 0.9).x,
        at(0.9, 0.9).y,
    );
    let r = 0.25 * (u1 - u0).min(v1 - v0);
    let circle = Circle { c: at(c.x, c.y), r };
    let island = vec![
        at(c.x, c.y - 0.1),
        at(c.x + 0.1, c.y),
        at(c.x, c.y + 0.1),
        at(c.x - 0.1, c.y),
    ];
    let loops = [
        one_piece(outer, None),
        curve_loop(&circle, tol, None),
        one_piece(island, None),
    ];
    ok(TrimRegions::new(&loops, domain, &Tolerances::default()))
}

fn polygons(t: &TrimRegions) -> Vec<Vec<DVec2>> {
    t.loops().iter().map(|l| l.points().to_vec()).collect()
}

#[test]
fn samples_agree_exactly_with_contains() {
    // Edges on grid lines and vertices on samples: the hard cases for a separate sweep.
    let loops = [
        one_piece(rect(0.125, 0.125, 0.875, 0.875), None),
        one_piece(rect(0.25, 0.25, 0.5, 0.625), None),
        one_piece(
            vec![
                DVec2::new(0.625, 0.25),
                DVec2::new(0.75, 0.5),
                DVec2::new(0.625, 0.75),
            ],
            None,
        ),
    ];
    let t = ok(super::build(&loops));
    let moved = holed(UNIT, DVec2::new(0.45, 0.5), 1e-4);
    let t2 = holed(UNIT, DVec2::new(0.5, 0.5), 1e-4);
    for (mu, mv) in [(17, 17), (33, 9), (2, 2), (101, 77)] {
        let (u, v) = (axis(0.0, 1.0, mu), axis(0.0, 1.0, mv));
        for regions in [&t, &t2] {
            let c = cover(regions, &u, &v);
            for i in 0..mu {
                for j in 0..mv {
                    assert_eq!(
                        c.sample_inside(i, j),
                        regions.contains(DVec2::new(u[i], v[j]))
                    );
                    assert_eq!(c.inside()[i * mv + j], c.sample_inside(i, j));
                }
            }
        }
        // Negative control: another trim's samples disagree somewhere (on a grid fine enough).
        if mu > 30 {
            let c = cover(&moved, &u, &v);
            let differ = (0..mu * mv)
                .any(|k| c.inside()[k] != t2.contains(DVec2::new(u[k / mv], v[k % mv])));
            assert!(differ);
        }
    }
}

/// Checks every cell's class against brute force; returns the number of violations.
fn class_violations(c: &Coverage, t: &TrimRegions, u: &[f64], v: &[f64], rng: &mut Rng) -> usize {
    let polys = polygons(t);
    let mut bad = 0;
    for i in 0..u.len() - 1 {
        for j in 0..v.len() - 1 {
            let (lo, hi) = (DVec2::new(u[i], v[j]), DVec2::new(u[i + 1], v[j + 1]));
            let to_cell = |p: DVec2| (p - lo) / (hi - lo);
            let touches = |m: f64| {
                (0..t.segment_count())
                    .filter_map(|id| t.segment(id))
                    .any(|[a, b]| clip(to_cell(a), to_cell(b), -m, 1.0 + m).is_some())
            };
            let class = c.cell_class(i, j);
            let consistent = match class {
                CellClass::Boundary => touches(2e-6) && !c.cell_segments(i, j).is_empty(),
                inside_or_out => {
                    let want = inside_or_out == CellClass::Inside;
                    !touches(0.0)
                        && (0..20).all(|_| t.contains(rng.point(lo, hi)) == want)
                        && super::brute_inside(&polys, rng.point(lo, hi)) == want
                }
            };
            bad += usize::from(!consistent);
        }
    }
    bad
}

#[test]
fn cell_classes_agree_with_brute_force() {
    let t = holed(UNIT, DVec2::new(0.45, 0.5), 1e-4);
    let (u, v) = (axis(0.0, 1.0, 23), axis(0.0, 1.0, 15));
    let c = cover(&t, &u, &v);
    let mut rng = Rng(5);
    assert_eq!(class_violations(&c, &t, &u, &v, &mut rng), 0);
    let count = |k: CellClass| {
        (0..22 * 14)
            .filter(|&n| c.cell_class(n / 14, n % 14) == k)
            .count()
    };
    assert!(
        count(CellClass::Inside) > 20
            && count(CellClass::Outside) > 20
            && count(CellClass::Boundary) > 20
    );
    // Negative control: classes of a moved hole fail against this trim.
    let moved = cover(&holed(UNIT, DVec2::new(0.5, 0.5), 1e-4), &u, &v);
    assert!(class_violations(&moved, &t, &u, &v, &mut rng) > 0);
}

#[test]
fn blocks_aggregate_cell_classes() {
    let t = holed(UNIT, DVec2::new(0.45, 0.5), 1e-4);
    let (u, v) = (axis(0.0, 1.0, 40), axis(0.0, 1.0, 29));
    let c = cover(&t, &u, &v);
    let other = cover(&holed(UNIT, DVec2::new(0.55, 0.5), 1e-4), &u, &v);
    let brute = |c: &Coverage, i0: usize, j0: usize, s: usize| {
        let cells: Vec<CellClass> = (i0..(i0 + s).min(39))
            .flat_map(|i| (j0..(j0 + s).min(28)).map(move |j| (i, j)))
            .map(|(i, j)| c.cell_class(i, j))
            .collect();
        if cells.iter().all(|&k| k == CellClass::Inside) {
            CellClass::Inside
        } else if cells.iter().all(|&k| k == CellClass::Outside) {
            CellClass::Outside
        } else {
            CellClass::Boundary
        }
    };
    for s in [1, 2, 4, 5, 8] {
        let (nu, nv, classes) = c.block_classes(s);
        assert_eq!((nu, nv), (39usize.div_ceil(s), 28usize.div_ceil(s)));
        let mut differs_from_other = false;
        for k in 0..nu * nv {
            let (bi, bj) = (k / nv, k % nv);
            assert_eq!(classes[k], brute(&c, bi * s, bj * s, s));
            differs_from_other |= classes[k] != brute(&other, bi * s, bj * s, s);
        }
        // Negative control: another trim's blocks differ somewhere (while blocks are small
        // enough to resolve the 0.1 shift).
        assert!(differs_from_other || s > 4, "block size {s}");
    }
}

/// Fraction of random grid points where the shader's test disagrees with `contains`, ignoring
/// points within 1e-5 grid units of the boundary.
fn fragment_mismatches(c: &Coverage, t: &TrimRegions, u: &[f64], v: &[f64], n: usize) -> usize {
    let (du, dv) = (u[1] - u[0], v[1] - v[0]);
    let grid_polys: Vec<Vec<DVec2>> = polygons(t)
        .iter()
        .map(|p| {
            p.iter()
                .map(|q| DVec2::new((q.x - u[0]) / du, (q.y - v[0]) / dv))
                .collect()
        })
        .collect();
    let extent = DVec2::new((u.len() - 1) as f64, (v.len() - 1) as f64);
    let mut rng = Rng(99);
    let mut bad = 0;
    for _ in 0..n {
        let g = rng.point(DVec2::ZERO, extent).as_vec2();
        let gd = g.as_dvec2();
        if boundary_distance(&grid_polys, gd) < 1e-5 {
            continue;
        }
        let p = DVec2::new(u[0] + gd.x * du, v[0] + gd.y * dv);
        bad += usize::from(c.fragment_inside([g.x, g.y]) != t.contains(p));
    }
    bad
}

#[test]
fn fragment_test_agrees_with_contains() {
    // Far from the origin, non-square cells: cell-local f32 keeps the precision.
    let domain = [(1000.0, 1020.0), (-5.0, 5.0)];
    let t = holed(domain, DVec2::new(0.45, 0.5), 1e-6);
    let (u, v) = (axis(1000.0, 1020.0, 65), axis(-5.0, 5.0, 49));
    let c = cover(&t, &u, &v);
    assert_eq!(fragment_mismatches(&c, &t, &u, &v, 20_000), 0);
    // Samples and the grid's far edges.
    for (i, j) in [(0, 0), (64, 48), (64, 0), (0, 48), (30, 20)] {
        let g = [i as f32, j as f32];
        let inside = t.contains(DVec2::new(u[i], v[j]));
        let near = boundary_distance(&polygons(&t), DVec2::new(u[i], v[j])) < 1e-4;
        assert!(near || c.fragment_inside(g) == inside);
    }
    // Negative control: another trim's packed cells disagree.
    let moved = cover(&holed(domain, DVec2::new(0.5, 0.5), 1e-6), &u, &v);
    assert!(fragment_mismatches(&moved, &t, &u, &v, 20_000) > 0);
}

#[test]
fn fragment_test_handles_many_segments_per_cell() {
    // A circle flattened to 1e-9 over an 8 x 8 grid: thousands of segments per boundary cell.
    let circle = Circle {
        c: DVec2::new(0.5, 0.5),
        r: 0.35,
    };
    let loops: Vec<LoopInput> = vec![curve_loop(&circle, 1e-9, None)];
    let t = ok(super::build(&loops));
    let (u, v) = (axis(0.0, 1.0, 9), axis(0.0, 1.0, 9));
    let c = cover(&t, &u, &v);
    assert!(c.gpu_segments().len() > 20_000);
    assert!(c.gpu_records().iter().any(|r| (r[1] >> 1) > 1000));
    assert_eq!(fragment_mismatches(&c, &t, &u, &v, 3000), 0);
}

#[test]
fn bad_grids_are_refused() {
    let t = holed(UNIT, DVec2::new(0.5, 0.5), 1e-3);
    let good = axis(0.0, 1.0, 5);
    let mut uneven = good.clone();
    uneven[2] += 1e-3;
    let cases = [
        vec![0.5],
        vec![0.0, f64::NAN, 1.0],
        vec![1.0, 0.5, 0.0],
        uneven,
    ];
    for bad in &cases {
        assert!(matches!(
            Coverage::new(&t, bad, &good),
            Err(TrimError::BadGrid { .. })
        ));
        assert!(matches!(
            Coverage::new(&t, &good, bad),
            Err(TrimError::BadGrid { .. })
        ));
    }
    // Negative control: the good axis is accepted.
    assert!(Coverage::new(&t, &good, &good).is_ok());
}

/// The drawn region grows by half a pixel at the boundary, measured on screen through the
/// pixels-per-grid-unit matrix (anisotropic: a grazing view squeezes one direction), never
/// more; a zero matrix (a triangle seen edge-on) grows nothing.
#[test]
fn the_drawn_region_grows_by_half_a_pixel_on_screen() {
    // The unit square [0.25, 0.75]² inside [0, 1]², on 4 × 4 cells: its right edge is the
    // grid line g.x = 3 (u = 0.75 → 0.75 · 4).
    let domain = [(0.0, 1.0), (0.0, 1.0)];
    let square = vec![
        DVec2::new(0.25, 0.25),
        DVec2::new(0.75, 0.25),
        DVec2::new(0.75, 0.75),
        DVec2::new(0.25, 0.75),
        DVec2::new(0.25, 0.25),
    ];
    let input = LoopInput {
        pieces: vec![square],
        role: None,
    };
    let t = TrimRegions::new(&[input], domain, &Tolerances::default()).unwrap();
    let (u, v) = (axis(0.0, 1.0, 5), axis(0.0, 1.0, 5));
    let c = cover(&t, &u, &v);
    // 10 pixels per grid unit along g.x, 2 along g.y (column-major, as GLSL's mat2).
    let reach = [[10.0, 0.0], [0.0, 2.0]];
    let right = |dx: f32| [3.0 + dx, 2.0];
    assert!(!c.fragment_inside(right(0.03)), "outside without growth");
    assert!(
        c.fragment_inside_within(right(0.03), reach),
        "0.3 px out: grown over"
    );
    assert!(
        !c.fragment_inside_within(right(0.07), reach),
        "0.7 px out: not"
    );
    // Along g.y a grid unit is 2 pixels: 0.2 grid units is 0.4 px, 0.3 is 0.6 px.
    let top = |dy: f32| [2.0, 3.0 + dy];
    assert!(c.fragment_inside_within(top(0.2), reach));
    assert!(!c.fragment_inside_within(top(0.3), reach));
    assert!(
        !c.fragment_inside_within(right(0.03), [[0.0; 2]; 2]),
        "edge-on: no growth"
    );
}

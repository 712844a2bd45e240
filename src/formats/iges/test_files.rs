//! The real files (OpenCASCADE's test data, see SOURCES.md next to them): every one parses, its
//! entity counts agree with a separate scanner that only reads column 73 and the type field,
//! and a few entities read by hand from the files come out as written there.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::{De, IgesFile, Transform, Unit};

/// Where the real files are; `PRESPLINE_CAD_DIR` overrides it (the main repository keeps its own copy).
fn cad_dir() -> PathBuf {
    std::env::var_os("PRESPLINE_CAD_DIR").map_or_else(
        || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/cad")),
        PathBuf::from,
    )
}

fn iges_files() -> Vec<PathBuf> {
    let dir = cad_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e} (set PRESPLINE_CAD_DIR)", dir.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|p| {
            let name = p.to_string_lossy().to_ascii_lowercase();
            name.ends_with(".igs") || name.ends_with(".iges")
        })
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no IGES files in {}", dir.display());
    files
}

fn read(name: &str) -> IgesFile {
    let path = cad_dir().join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    IgesFile::parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// An independent count: D lines are those with `D` in column 73; each pair's first line
/// carries the type in columns 1–8. Knows nothing of the parser.
fn scan_types(text: &str) -> BTreeMap<i32, usize> {
    let d_lines: Vec<&str> = text
        .lines()
        .filter(|l| l.as_bytes().get(72) == Some(&b'D'))
        .collect();
    assert_eq!(d_lines.len() % 2, 0, "odd D line count");
    let mut counts = BTreeMap::new();
    for pair in d_lines.chunks(2) {
        let first: i32 = pair[0][..8].trim().parse().unwrap();
        let second: i32 = pair[1][..8].trim().parse().unwrap();
        assert_eq!(first, second);
        *counts.entry(first).or_insert(0) += 1;
    }
    counts
}

#[test]
fn every_real_file_parses_and_matches_an_independent_count() {
    for path in iges_files() {
        let bytes = std::fs::read(&path).unwrap();
        let file = IgesFile::parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let expected = scan_types(&String::from_utf8_lossy(&bytes));
        assert_eq!(
            file.entities().len(),
            expected.values().sum::<usize>(),
            "{}",
            path.display()
        );
        assert_eq!(file.count_by_type(), expected, "{}", path.display());
        for (index, entity) in file.entities().iter().enumerate() {
            assert_eq!(entity.de(), De(2 * index as u32 + 1));
            assert_eq!(file.entity(entity.de()), Some(entity));
            file.transform(entity).unwrap();
        }
        assert_eq!(file.global.unit, Unit::Millimetre, "{}", path.display());
    }
}

/// Negative control for the test above: the scanner sees a change the parser must see too.
#[test]
fn the_independent_count_notices_a_changed_type() {
    let path = cad_dir().join("BIGES.igs");
    let text = std::fs::read_to_string(&path).unwrap();
    let file = IgesFile::parse(text.as_bytes()).unwrap();
    // D 13 is a line (110); relabel both its D lines and its parameters as a point (116).
    let changed = text
        .replace("     110       9       0", "     116       9       0")
        .replacen(
            "     110       0       0       1       0                               0D0000014",
            "     116       0       0       1       0                               0D0000014",
            1,
        )
        .replacen(
            "110,100.,0.,0.,0.,0.,0.;                                         0000013P0000009",
            "116,100.,0.,0.,0.,0.,0.;                                         0000013P0000009",
            1,
        );
    let changed_file = IgesFile::parse(changed.as_bytes()).unwrap();
    assert_ne!(changed_file.count_by_type(), file.count_by_type());
    assert_eq!(scan_types(&changed), changed_file.count_by_type());
    assert_ne!(scan_types(&changed), file.count_by_type());
    assert_eq!(scan_types(&text), file.count_by_type());
}

#[test]
fn biges_trimmed_bilinear_patch_reads_as_written() {
    let file = read("BIGES.igs");
    assert_eq!(file.global.native_system, "MATRA-DATAVISION CASCADE OL 3.0");
    assert_eq!(file.global.unit, Unit::Millimetre);
    assert_eq!(file.global.model_scale, 1.0);
    assert_eq!(file.global.min_resolution, 1e-7);
    assert_eq!(file.global.max_coordinate, 300.0);
    // P 3: "144,7,1,0,9;"
    let face = file.entity(De(5)).unwrap();
    assert_eq!(face.entity_type(), 144);
    assert_eq!(face.param_count(), 4);
    assert_eq!(face.pointer(1).unwrap(), De(7));
    assert_eq!(face.int(2).unwrap(), 1);
    assert_eq!(face.count(3).unwrap(), 0);
    assert_eq!(face.pointer(4).unwrap(), De(9));
    // P 4-6: "128,1,1,1,1,0,0,1,0,0,0.,0.,100.,100.,-100.,-100.,0.,0.,1.,1.,1.,1.,0.,100.,0., …"
    let surface = file.follow(face, 1).unwrap();
    assert_eq!(surface.entity_type(), 128);
    assert_eq!(surface.param_count(), 37);
    assert_eq!(surface.ints(1, 9).unwrap(), [1, 1, 1, 1, 0, 0, 1, 0, 0]);
    assert_eq!(surface.reals(10, 4).unwrap(), [0.0, 0.0, 100.0, 100.0]);
    assert_eq!(surface.reals(14, 4).unwrap(), [-100.0, -100.0, 0.0, 0.0]);
    assert_eq!(surface.reals(18, 4).unwrap(), [1.0; 4]);
    assert_eq!(
        surface.reals(22, 6).unwrap(),
        [0.0, 100.0, 0.0, 0.0, 100.0, 100.0]
    );
    assert_eq!(surface.reals(34, 4).unwrap(), [0.0, 100.0, -100.0, 0.0]);
    assert!(surface.value(38).is_none());
    // P 7: "142,0,7,11,21,3;"
    let boundary = file.follow(face, 4).unwrap();
    assert_eq!(boundary.entity_type(), 142);
    assert_eq!(boundary.ints(1, 1).unwrap(), [0]);
    assert_eq!(boundary.pointers(2, 3).unwrap(), [De(7), De(11), De(21)]);
    assert_eq!(boundary.int(5).unwrap(), 3);
    assert_eq!(boundary.directory().status.entity_use, 5);
    // D 1 line 1: "     402       1       0       0       0       0       0       000000000"
    // D 1 line 2: "     402       0       0       1       1                ASSEMBLY        "
    let group = file.entity(De(1)).unwrap();
    assert_eq!((group.entity_type(), group.form()), (402, 1));
    assert_eq!(group.directory().label, "ASSEMBLY");
    assert_eq!(group.ints(1, 3).unwrap(), [3, 3, 161]);
    assert_eq!(group.pointer(4).unwrap(), De(319));
}

#[test]
fn pro20359_degree_5_surface_reads_as_written() {
    let file = read("PRO20359-L1.igs");
    assert_eq!(
        file.global.native_system,
        "IBM CATIA IGES - CATIA SOLUTIONS V4RELEASE 1.9 REFRESH 01"
    );
    // P 1: "144,3,1,0,7,0,1,45;" — two trailing pointer groups: 0 associativities, 1 property.
    let face = file.entity(De(1)).unwrap();
    assert_eq!(face.param_count(), 7);
    assert_eq!(face.pointer(7).unwrap(), De(45));
    let surface = file.follow(face, 1).unwrap();
    // D 3 line 2: "     128     200       7     486       0                  SUR121     374"
    let directory = surface.directory();
    assert_eq!(directory.parameter_lines, 486);
    assert_eq!(directory.line_weight, 200);
    assert_eq!(directory.colour, super::Attr::Value(7));
    assert_eq!(directory.label, "SUR121");
    assert_eq!(directory.subscript, 374);
    assert_eq!(directory.status.blank, 1);
    // P 2: "128,40,24,5,5,0,0,1,0,0,0.,0.,0.,0.,0.,0.,1.,1.,1.,1.,1.,2.,2.,"
    assert_eq!(surface.ints(1, 4).unwrap(), [40, 24, 5, 5]);
    let u_knots = surface.reals(10, 40 + 5 + 2).unwrap();
    assert_eq!(&u_knots[..8], &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0]);
    assert_eq!(u_knots[46], 8.0);
    let v_knots = surface.reals(57, 24 + 5 + 2).unwrap();
    assert_eq!(&v_knots[..7], &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    let weights = 41 * 25;
    let total = 9 + 47 + 31 + weights + 3 * weights + 4;
    // P 487: "…,0.,8.,0.,4.00036,0,1,5;": the parameter ranges, then the two trailing pointer
    // groups, no associativities and one property (D 5, a 406).
    assert_eq!(
        surface.reals(total - 3, 4).unwrap(),
        [0.0, 8.0, 0.0, 4.00036]
    );
    assert_eq!(surface.param_count(), total + 3);
    assert_eq!(surface.ints(total + 1, 2).unwrap(), [0, 1]);
    assert_eq!(file.follow(surface, total + 3).unwrap().entity_type(), 406);
    assert_eq!(surface.count(1).unwrap(), 40);
}

#[test]
fn catia_cylinder_hollerith_across_lines_and_transforms() {
    let file = read("OCC8842_cylinder_CATIA.igs");
    // "44HIBM CATIA IGES " ends G line 1 at column 72 and continues on G line 2.
    assert_eq!(
        file.global.native_system,
        "IBM CATIA IGES - CATIA Version 5 Release 14 "
    );
    assert_eq!(file.global.author, "Administrator");
    assert_eq!(file.global.organisation, "VCAD-23B");
    assert_eq!(file.global.units_flag, 2);
    assert_eq!(file.start, "START RECORD GO HERE.");
    // P 4: "124,0.0,0.0,1.0,100.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0,0;"
    let matrix = file.entity(De(7)).unwrap();
    let expected = Transform {
        matrix: [
            [0.0, 0.0, 1.0, 100.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
        ],
    };
    assert_eq!(Transform::from_entity(matrix).unwrap(), expected);
    // D 9: circular arc with transformation matrix D 7.
    let arc = file.entity(De(9)).unwrap();
    assert_eq!(arc.entity_type(), 100);
    assert_eq!(arc.directory().transform, Some(De(7)));
    assert_eq!(file.transform(arc).unwrap(), expected);
    assert_eq!(
        file.transform(arc).unwrap().apply_point([0.0, 50.0, 0.0]),
        [100.0, 0.0, 50.0]
    );
    // P 5: "100,0.0,0.0,0.0,50.0,0.0,-50.0,6.123031769E-015,0,0;"
    assert_eq!(arc.real(7).unwrap(), 6.123031769e-15);
    // The last entity, D 79, P 44: "144,65,1,0,77,0,0;"
    let face = file.entity(De(79)).unwrap();
    assert_eq!(face.ints(1, 6).unwrap(), [65, 1, 0, 77, 0, 0]);
}

#[test]
fn hammer_face_with_a_hole() {
    let file = read("hammer.iges");
    // Line 4472: "144,343,1,1,345,359;" with back pointer 341.
    let face = file.entity(De(341)).unwrap();
    assert_eq!(face.count(3).unwrap(), 1);
    assert_eq!(face.pointers(1, 1).unwrap(), [De(343)]);
    assert_eq!(face.pointer(4).unwrap(), De(345));
    assert_eq!(face.pointer(5).unwrap(), De(359));
    assert_eq!(file.follow(face, 5).unwrap().entity_type(), 142);
    let faces_with_holes = file
        .entities()
        .iter()
        .filter(|e| e.entity_type() == 144 && e.int(3).unwrap() > 0)
        .count();
    assert_eq!(faces_with_holes, 3);
}

#[test]
fn bearing_top_group_lists_every_face() {
    let file = read("bearing.iges");
    // P 1: "402,213,3,29,55,…"
    let group = file.entity(De(1)).unwrap();
    let n = group.count(1).unwrap();
    assert_eq!(n, 213);
    let members = group.pointers(2, n).unwrap();
    assert_eq!(&members[..3], &[De(3), De(29), De(55)]);
    assert!(
        members
            .iter()
            .all(|&de| file.entity(de).unwrap().entity_type() == 144)
    );
    assert_eq!(file.count_by_type()[&144], 213);
}

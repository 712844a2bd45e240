//! The real CAD files of the project's shared test data (OpenCASCADE's and CAx-IF's; see
//! SOURCES.md there). Set `PRESPLINE_CAD_DIR` to read them from elsewhere.

use std::path::PathBuf;
use std::time::Instant;

use super::super::{EntityRef, StepFile};
use super::{all_close, close, count_instances, ok, touch_all};

fn cad_dir() -> PathBuf {
    std::env::var_os("PRESPLINE_CAD_DIR").map_or_else(
        || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/cad")),
        PathBuf::from,
    )
}

/// Every `.stp`/`.step` file in the CAD folder, sorted; fails if there is none, so that a moved
/// folder cannot make these tests pass vacuously.
fn step_files() -> Vec<(String, Vec<u8>)> {
    let dir = cad_dir();
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut files: Vec<(String, Vec<u8>)> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            let ext = p
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or("")
                .to_ascii_lowercase();
            ext == "stp" || ext == "step"
        })
        .map(|p| {
            let name = p
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("")
                .to_owned();
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (name, bytes)
        })
        .collect();
    files.sort();
    assert!(
        files.len() >= 9,
        "expected the 9 STEP files of {}",
        dir.display()
    );
    files
}

/// One file by name, parsed.
fn load(name: &str) -> StepFile {
    let path = cad_dir().join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    StepFile::parse(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Parameter `index` of record `record` of `#id`, for spot checks.
fn param<'a>(
    file: &'a StepFile,
    id: u64,
    record: &str,
    index: usize,
) -> super::super::ParamRef<'a> {
    ok(ok(ok(file.get(id)).record(record)).param(index, ""))
}

#[test]
fn every_step_file_parses_completely() {
    for (name, bytes) in step_files() {
        let file = StepFile::parse(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(
            file.len(),
            count_instances(&bytes),
            "{name}: instance count"
        );
        file.check_references()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!file.header.schemas.is_empty(), "{name}: schema");
        assert!(
            !file.header.originating_system.is_empty(),
            "{name}: originating system"
        );
        let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
        let last = file
            .entities()
            .map(|e| e.line() as usize)
            .max()
            .unwrap_or(0);
        assert!(
            last > 0 && last <= lines,
            "{name}: entity lines within the file"
        );
        assert!(
            touch_all(&file) > file.len(),
            "{name}: every value reachable"
        );
    }
}

#[test]
fn iges_files_are_not_step() {
    let path = cad_dir().join("BIGES.igs");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let err = StepFile::parse(&bytes)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.starts_with("line 1: not a STEP file: expected ISO-10303-21, found"),
        "{err}"
    );
}

#[test]
fn headers_of_real_files() {
    let h = load("trj6_as1-pe-203.stp").header;
    assert_eq!(
        h.schemas,
        [
            "CONFIG_CONTROL_DESIGN",
            "GEOMETRIC_VALIDATION_PROPERTIES_MIM"
        ]
    );
    assert_eq!(h.name, "AS1-PE_ASM");
    assert_eq!(h.author, ["csmetana"]);
    assert_eq!(
        h.originating_system,
        "PRO/ENGINEER BY PARAMETRIC TECHNOLOGY CORPORATION, 2000510"
    );
    // Header full of comments.
    let h = load("bug24595_281390.stp").header;
    assert_eq!(
        (h.description.as_slice(), h.implementation_level.as_str()),
        (&[String::new()][..], "2;1")
    );
    assert_eq!(h.name, "F4AW1200AWX38E240_GTM.stp");
    assert_eq!(h.time_stamp, "2013-12-17T09:51:44+00:00");
    assert_eq!(h.preprocessor_version, "ST-DEVELOPER v15");
    assert_eq!(h.originating_system, "SIEMENS PLM Software NX 9.0");
    assert_eq!(
        h.schema_identifiers,
        ["AUTOMOTIVE_DESIGN { 1 0 10303 214 3 1 1 1 }"]
    );
    assert_eq!(h.schemas, ["AUTOMOTIVE_DESIGN"]);
    let h = load("xr1-tu-rod.stp").header;
    assert_eq!(
        h.description,
        [
            "CAx Round 4 testing - External References XR1",
            "Rod Piece Part"
        ]
    );
    assert_eq!(
        h.schema_identifiers,
        ["AUTOMOTIVE_DESIGN { 1 2 10303 214 0 1 1 1 } "]
    );
    let h = load("linkrods.step").header;
    assert_eq!(
        (h.name.as_str(), h.originating_system.as_str()),
        ("Euclid  Shape Model", "EUCLID")
    );
    assert_eq!(h.schemas, ["AUTOMOTIVE_DESIGN_CC1"]);
}

#[test]
fn rational_b_spline_surface_in_as1() {
    // as1-oc-214-mat.stp line 293: a complex instance of seven records.
    let file = load("as1-oc-214-mat.stp");
    let e = ok(file.get(248));
    assert_eq!(e.line(), 293);
    assert_eq!(
        e.type_names(),
        "(BOUNDED_SURFACE B_SPLINE_SURFACE B_SPLINE_SURFACE_WITH_KNOTS \
         GEOMETRIC_REPRESENTATION_ITEM RATIONAL_B_SPLINE_SURFACE REPRESENTATION_ITEM SURFACE)"
    );
    assert_eq!(
        (
            ok(param(&file, 248, "B_SPLINE_SURFACE", 0).int()),
            ok(param(&file, 248, "B_SPLINE_SURFACE", 1).int())
        ),
        (1, 3)
    );
    let rows = ok(param(&file, 248, "B_SPLINE_SURFACE", 2).list());
    let ids: Vec<Vec<u64>> = rows.iter().map(|r| ok(r.references())).collect();
    assert_eq!(ids, [vec![249, 250, 251, 252], vec![253, 254, 255, 256]]);
    assert_eq!(
        ok(param(&file, 248, "B_SPLINE_SURFACE", 3).enumeration()),
        "UNSPECIFIED"
    );
    assert_eq!(
        ok(param(&file, 248, "B_SPLINE_SURFACE_WITH_KNOTS", 0).ints()),
        [2, 2]
    );
    assert_eq!(
        ok(param(&file, 248, "B_SPLINE_SURFACE_WITH_KNOTS", 1).ints()),
        [4, 4]
    );
    let u_knots = ok(param(&file, 248, "B_SPLINE_SURFACE_WITH_KNOTS", 2).reals());
    assert!(all_close(&u_knots, &[9.9800399E-004, 3.00099800399]));
    assert!(
        !all_close(&u_knots, &[9.98E-004, 3.00099800399]),
        "negative control"
    );
    assert_eq!(
        ok(param(&file, 248, "B_SPLINE_SURFACE_WITH_KNOTS", 4).enumeration()),
        "PIECEWISE_BEZIER_KNOTS"
    );
    let weights = ok(param(&file, 248, "RATIONAL_B_SPLINE_SURFACE", 0).list());
    for row in weights.iter() {
        assert!(all_close(
            &ok(row.reals()),
            &[1.0, 0.33333333333, 0.33333333333, 1.0]
        ));
    }
    let corner = ok(ok(ok(rows.get(1)).list()).get(3));
    let point = ok(corner.entity());
    assert_eq!(
        ok(param(&file, point.id(), "CARTESIAN_POINT", 1).reals()),
        [15.0, 7.5, 0.0]
    );
}

#[test]
fn units_and_measures_in_as1() {
    let file = load("as1-oc-214-mat.stp");
    let names = |id| ok(file.get(id)).type_names();
    assert_eq!(names(32), "(LENGTH_UNIT NAMED_UNIT SI_UNIT)");
    assert_eq!(names(33), "(NAMED_UNIT PLANE_ANGLE_UNIT SI_UNIT)");
    assert!(param(&file, 32, "NAMED_UNIT", 0).is_derived());
    assert_eq!(ok(param(&file, 32, "SI_UNIT", 0).enumeration()), "MILLI");
    assert_eq!(ok(param(&file, 32, "SI_UNIT", 1).enumeration()), "METRE");
    assert!(param(&file, 33, "SI_UNIT", 0).is_unset());
    assert_eq!(
        ok(param(&file, 35, "UNCERTAINTY_MEASURE_WITH_UNIT", 0).typed()).0,
        "LENGTH_MEASURE"
    );
    assert!(close(
        ok(param(&file, 35, "UNCERTAINTY_MEASURE_WITH_UNIT", 0).real()),
        5e-6
    ));
    let unit: EntityRef<'_> = ok(param(&file, 35, "UNCERTAINTY_MEASURE_WITH_UNIT", 1).entity());
    assert_eq!(unit.id(), 32);
    assert_eq!(
        ok(param(&file, 35, "UNCERTAINTY_MEASURE_WITH_UNIT", 3).string()),
        "confusion accuracy"
    );
    let rational = ok(file.get(634));
    assert!(
        rational.has_record("RATIONAL_B_SPLINE_CURVE")
            && rational.has_record("B_SPLINE_CURVE_WITH_KNOTS")
    );
    assert_eq!(
        ok(param(&file, 634, "B_SPLINE_CURVE", 1).references()),
        [635, 636, 637, 638]
    );
}

#[test]
fn wrapped_strings_and_sparse_ids() {
    let file = load("linkrods.step");
    let category = param(&file, 1, "PRODUCT_RELATED_PRODUCT_CATEGORY", 1);
    assert_eq!(
        ok(category.string()),
        "Undefined Description",
        "line break inside a string dropped"
    );
    assert_eq!(
        ok(param(&file, 5, "APPLICATION_PROTOCOL_DEFINITION", 1).string()),
        "automotive_design"
    );
    assert_eq!(
        ok(param(&file, 5, "APPLICATION_PROTOCOL_DEFINITION", 2).int()),
        1997
    );
    let file = load("trj6_as1-pe-203.stp");
    assert_eq!(
        ok(param(&file, 7, "CARTESIAN_POINT", 1).reals()),
        [40.0, -20.0, -75.0]
    );
    assert_eq!(ok(file.get(30)).line(), 38);
    assert_eq!(ok(file.get(29)).line(), 1932, "#29 is written after #2209");
    let file = load("bug24595_281390.stp");
    assert!(
        file.find(9).is_none() && file.find(10).is_some(),
        "ids start at #10"
    );
    let text = ok(param(&file, 12, "SHAPE_REPRESENTATION_RELATIONSHIP", 1).string());
    assert_eq!(
        text,
        "relationship between F4AW1200AWX38E240_GTM-None and F4AW1200AWX38E240_GTM-None"
    );
    let file = load("xr1-tu-rod.stp");
    assert_eq!(
        ok(file.get(3)).type_names(),
        "(NAMED_UNIT SI_UNIT SOLID_ANGLE_UNIT)"
    );
    assert_eq!(ok(param(&file, 3, "SI_UNIT", 1).enumeration()), "STERADIAN");
    assert_eq!(ok(param(&file, 1, "DIMENSIONAL_EXPONENTS", 0).real()), 1.0);
    assert_eq!(
        ok(param(&file, 6, "CARTESIAN_POINT", 0).string()),
        "#6",
        "'#6' inside a string"
    );
}

/// Release parse time of each file: `cargo test --release -- --ignored --nocapture timings`.
#[test]
#[ignore = "timing report, run in release with --nocapture"]
fn timings() {
    for (name, bytes) in step_files() {
        let mut best = f64::MAX;
        for _ in 0..20 {
            let start = Instant::now();
            let file = StepFile::parse(&bytes);
            best = best.min(start.elapsed().as_secs_f64());
            assert!(file.is_ok());
        }
        println!("{name:24} {:>9} bytes {:>8.2} ms", bytes.len(), best * 1e3);
    }
}

/// Entity type names with counts over all files, and the complex-instance patterns:
/// `cargo test -- --ignored --nocapture census`.
#[test]
#[ignore = "report for the geometry mapping, run with --nocapture"]
fn census() {
    let mut totals = std::collections::BTreeMap::<String, usize>::new();
    let mut complex = std::collections::BTreeMap::<String, usize>::new();
    let mut values = std::collections::BTreeMap::<String, usize>::new();
    for (name, bytes) in step_files() {
        let file = StepFile::parse(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        for (type_name, count) in file.type_counts() {
            *totals.entry(type_name.to_owned()).or_default() += count;
        }
        for e in file.entities().filter(|e| e.is_complex()) {
            *complex.entry(e.type_names()).or_default() += 1;
        }
        for p in file
            .entities()
            .flat_map(|e| e.records())
            .flat_map(|r| r.params())
        {
            census_values(p, &mut values);
        }
    }
    for (name, count) in &totals {
        println!("{count:7} {name}");
    }
    println!("typed parameters and enumeration values:");
    for (name, count) in &values {
        println!("{count:7} {name}");
    }
    println!("complex instances:");
    for (names, count) in &complex {
        println!("{count:7} {names}");
    }
}

/// Counts typed-parameter names and enumeration values under `p`, for [`census`].
fn census_values(
    p: super::super::ParamRef<'_>,
    out: &mut std::collections::BTreeMap<String, usize>,
) {
    match p.value() {
        super::super::Value::Typed(name, inner) => {
            *out.entry(format!("{name}(…)")).or_default() += 1;
            census_values(inner, out);
        }
        super::super::Value::Enum(e) => *out.entry(format!(".{e}.")).or_default() += 1,
        super::super::Value::List(list) => list.iter().for_each(|item| census_values(item, out)),
        _ => {}
    }
}

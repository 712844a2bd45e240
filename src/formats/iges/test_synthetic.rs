//! Synthetic files for what the real ones do not show: Hollerith strings holding delimiters,
//! declared delimiters, the number forms, defaults, long parameter lists, units, the forms that
//! must be refused, lenient line endings, and each structural check (with its negative control:
//! the same file without the fault parses).

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use super::test_support::{GLOBAL, build, ent, error_line, line_of, lines, small_file, unlines};
use super::{Attr, De, IgesError, IgesFile, Transform, Unit, Value};

fn parse(text: &str) -> IgesFile {
    IgesFile::parse(text.as_bytes()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn fails(text: &str) -> IgesError {
    match IgesFile::parse(text.as_bytes()) {
        Ok(_) => panic!("parsed, but should not have:\n{text}"),
        Err(e) => {
            error_line(&e);
            e
        }
    }
}

#[test]
fn hollerith_strings_may_hold_both_delimiters() {
    let global = GLOBAL.replace("4Htest,8Htest.igs", "7Ha,b;c,d,8Htest.igs");
    let file = parse(&build(&global, &[ent(406, "406,2,12Hname,;with;,,3H;;;;")]));
    assert_eq!(file.global.product_id, "a,b;c,d");
    assert_eq!(file.global.file_name, "test.igs");
    let property = file.entity(De(1)).unwrap();
    assert_eq!(property.string(2).unwrap(), "name,;with;,");
    assert_eq!(property.string(3).unwrap(), ";;;");
    assert_eq!(property.param_count(), 3);
}

#[test]
fn declared_delimiters_are_used_everywhere() {
    // Parameter '/', record '#'.
    let global = GLOBAL.replace(',', "/").replace(';', "#");
    assert!(global.starts_with("1H//1H#/"));
    let file = parse(&build(&global, &[ent(110, "110/1./2./3./4/5/6.#")]));
    assert_eq!(file.global.parameter_delimiter, b'/');
    assert_eq!(file.global.record_delimiter, b'#');
    assert_eq!(file.global.units_name, "MM");
    let line = file.entity(De(1)).unwrap();
    assert_eq!(line.reals(1, 6).unwrap(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);

    // The defaults swapped: parameter ';', record ','.
    let swapped: String = GLOBAL
        .chars()
        .map(|c| match c {
            ',' => ';',
            ';' => ',',
            c => c,
        })
        .collect();
    assert!(swapped.starts_with("1H;;1H,;"));
    let file = parse(&build(&swapped, &[ent(406, "406;1;3Ha,b,")]));
    assert_eq!(file.global.parameter_delimiter, b';');
    assert_eq!(file.global.record_delimiter, b',');
    assert_eq!(file.entity(De(1)).unwrap().string(2).unwrap(), "a,b");

    // Only the record delimiter declared, the parameter delimiter defaulted (empty field 1).
    let global = GLOBAL.replacen("1H,,1H;,", ",1H|,", 1).replace(';', "|");
    let file = parse(&build(&global, &[ent(116, "116,1.,2.,3.|")]));
    assert_eq!(
        (
            file.global.parameter_delimiter,
            file.global.record_delimiter
        ),
        (b',', b'|')
    );

    // Both defaulted.
    let global = GLOBAL.replacen("1H,,1H;,", ",,", 1);
    let file = parse(&build(&global, &[ent(116, "116,1.,2.,3.;")]));
    assert_eq!(file.global.file_name, "test.igs");
}

#[test]
fn forbidden_or_equal_delimiters_are_refused() {
    for (bad, field) in [
        ("1HE,1H;,", 1),
        ("1H,,1H,,", 2),
        ("1H ,1H;,", 1),
        ("2H,,", 1),
    ] {
        let global = GLOBAL.replacen("1H,,1H;,", bad, 1);
        let error = fails(&build(&global, &[]));
        assert!(
            matches!(error, IgesError::Global { index, .. } if index == field),
            "{bad}: {error}"
        );
    }
}

#[test]
fn number_forms() {
    let file = parse(&build(
        GLOBAL,
        &[ent(
            406,
            "406,1.5D-3,+2.D+1,.5,5.,-1.E2,1e3,+7,-0,1.5d2,0.25E+01,  3 ,12345678901;",
        )],
    ));
    let e = file.entity(De(1)).unwrap();
    let expected = [
        1.5e-3,
        20.0,
        0.5,
        5.0,
        -100.0,
        1000.0,
        7.0,
        0.0,
        150.0,
        2.5,
        3.0,
        12_345_678_901.0,
    ];
    assert_eq!(e.reals(1, expected.len()).unwrap(), expected);
    assert_eq!(e.value(7), Some(&Value::Int(7)));
    assert_eq!(e.value(6), Some(&Value::Real(1000.0)));
    assert_eq!(e.int(11).unwrap(), 3);
    assert!(e.int(1).is_err(), "a real is not an integer");
}

#[test]
fn malformed_numbers_fail_when_read() {
    let text = build(
        GLOBAL,
        &[ent(
            128,
            "128,1,1,1,1,0,0,1,0,0,0.,0.,1.0.0,.,1E,E5,1.5X,1 2,--1,1E999,99999999999999999999;",
        )],
    );
    let file = parse(&text);
    let e = file.entity(De(1)).unwrap();
    let error = e.real(12).unwrap_err();
    assert_eq!(
        error.to_string(),
        format!(
            "line {}: D 1 (entity 128, rational B-spline surface): parameter 12 should be a real, found '1.0.0'",
            line_of(&text, 'P', 1)
        )
    );
    assert_eq!(e.param_count(), 20);
    for k in 13..=20 {
        let error = e.real(k).unwrap_err();
        error_line(&error);
        assert!(
            error
                .to_string()
                .contains(&format!("parameter {k} should be a real"))
        );
    }
    assert_eq!(
        e.real(11).unwrap(),
        0.0,
        "control: the field before is fine"
    );
}

#[test]
fn blank_fields_take_defaults() {
    let file = parse(&build(GLOBAL, &[ent(406, "406,,1.,,  ,2Hab,;")]));
    let e = file.entity(De(1)).unwrap();
    assert_eq!(e.param_count(), 6);
    assert_eq!(e.value(1), Some(&Value::Empty));
    assert_eq!(e.int(1).unwrap(), 0);
    assert_eq!(e.real(3).unwrap(), 0.0);
    assert_eq!(e.real_or(4, 7.5).unwrap(), 7.5);
    assert_eq!(e.string(6).unwrap(), "");
    assert_eq!(e.optional_pointer(1).unwrap(), None);
    assert_eq!(e.int_or(9, 42).unwrap(), 42, "omitted at the end");
    let missing = e.int(9).unwrap_err().to_string();
    assert!(
        missing.contains("parameter 9 is missing (the entity has 6)"),
        "{missing}"
    );
    assert!(e.pointer(1).is_err(), "a required pointer may not be null");
    // Blank directory fields are 0 (the builder writes the reserved fields blank).
    let d = e.directory();
    assert_eq!((d.level, d.view, d.transform), (Attr::Value(0), None, None));
}

#[test]
fn parameters_spanning_many_lines() {
    let knots: Vec<String> = (0..300).map(|i| format!("{}.{}", i, i % 7)).collect();
    let params = format!("126,{};", knots.join(","));
    let file = parse(&build(
        GLOBAL,
        &[ent(116, "116,0.,0.,0.;"), ent(126, &params)],
    ));
    let e = file.entity(De(3)).unwrap();
    assert!(e.directory().parameter_lines > 20);
    assert_eq!(e.param_count(), 300);
    let values = e.reals(1, 300).unwrap();
    for (i, v) in values.iter().enumerate() {
        assert_eq!(*v, format!("{}.{}", i, i % 7).parse::<f64>().unwrap());
    }
    // A string across four P lines (cut at column 64 by the builder).
    let text: String = (0..200)
        .map(|i| char::from(b'a' + (i % 26) as u8))
        .collect();
    let file = parse(&build(GLOBAL, &[ent(406, &format!("406,1,200H{text};"))]));
    assert_eq!(file.entity(De(1)).unwrap().string(2).unwrap(), text);
}

#[test]
fn trailing_text_after_the_record_delimiter_is_ignored() {
    let file = parse(&build(
        GLOBAL,
        &[ent(116, "116,1.,2.,3.; a comment, 5H;;;;;")],
    ));
    assert_eq!(file.entity(De(1)).unwrap().param_count(), 3);
}

#[test]
fn back_pointer_and_type_mismatches_are_errors() {
    let good = build(
        GLOBAL,
        &[
            ent(116, "116,1.,2.,3.;"),
            ent(110, "110,0.,0.,0.,1.,1.,1.;"),
        ],
    );
    parse(&good);
    let mut broken = lines(&good);
    let p2 = broken.iter().position(|l| l.ends_with("P0000002")).unwrap();
    broken[p2].replace_range(64..72, "       1");
    let error = fails(&unlines(&broken));
    assert_eq!(error_line(&error), p2 + 1);
    assert!(
        error.to_string().contains("point back at '1', not 3"),
        "{error}"
    );

    let error = fails(&good.replace("110,0.,0.", "111,0.,0."));
    assert!(
        error.to_string().contains("start with the integer 111"),
        "{error}"
    );
}

#[test]
fn pointer_checks_name_the_entity_and_parameter() {
    let text = build(
        GLOBAL,
        &[
            ent(110, "110,0.,0.,0.,1.,1.,1.;"),
            ent(102, "102,7,1,4,9,-1,1.;"),
            ent(116, "116,0.,0.,0.;"),
        ],
    );
    let file = parse(&text);
    let composite = file.entity(De(3)).unwrap();
    assert_eq!(composite.pointer(2).unwrap(), De(1));
    assert_eq!(file.follow(composite, 2).unwrap().entity_type(), 110);
    let error = composite.pointer(3).unwrap_err();
    assert_eq!(
        error.to_string(),
        format!(
            "line {}: D 3 (entity 102, composite curve): parameter 3 points at D 4, which is not a directory entry (odd, at most 5)",
            line_of(&text, 'P', 2)
        )
    );
    for k in [4, 5] {
        assert!(composite.pointer(k).is_err(), "parameter {k}");
    }
    assert!(
        composite
            .pointer(6)
            .unwrap_err()
            .to_string()
            .contains("should be a pointer, found the real 1.0")
    );
    assert!(
        composite
            .count(1)
            .unwrap_err()
            .to_string()
            .contains("count of 7, more than")
    );
}

#[test]
fn units_flags_and_names() {
    let cases = [
        (1, "4HINCH", Unit::Inch, 25.4),
        (2, "2HMM", Unit::Millimetre, 1.0),
        (3, "2HFT", Unit::Foot, 304.8),
        (3, "3HUIN", Unit::Microinch, 0.000_025_4),
        (4, "2HFT", Unit::Foot, 304.8),
        (5, "2HMI", Unit::Mile, 1_609_344.0),
        (6, "1HM", Unit::Metre, 1000.0),
        (7, "2HKM", Unit::Kilometre, 1e6),
        (8, "3HMIL", Unit::Mil, 0.0254),
        (9, "2HUM", Unit::Micron, 0.001),
        (10, "2HCM", Unit::Centimetre, 10.0),
        (11, "3HUIN", Unit::Microinch, 0.000_025_4),
        (2, "", Unit::Millimetre, 1.0),
    ];
    for (flag, name, unit, mm) in cases {
        let global = GLOBAL.replacen("1.,2,2HMM,", &format!("0.5,{flag},{name},"), 1);
        let file = parse(&build(&global, &[]));
        assert_eq!(
            (file.global.unit, file.mm_per_unit()),
            (unit, mm),
            "{flag} {name}"
        );
        assert_eq!(file.global.model_scale, 0.5);
    }
    let defaulted = parse(&build(&GLOBAL.replacen("1.,2,2HMM,", ",,,", 1), &[]));
    assert_eq!(
        (defaulted.global.unit, defaulted.global.model_scale),
        (Unit::Inch, 1.0)
    );
    for (bad, index) in [
        ("1.,12,2HMM,", 14),
        ("1.,3,7HFURLONG,", 15),
        ("0.,2,2HMM,", 13),
        ("1.,1H2,2HMM,", 14),
    ] {
        let error = fails(&build(&GLOBAL.replacen("1.,2,2HMM,", bad, 1), &[]));
        assert!(
            matches!(error, IgesError::Global { index: i, .. } if i == index),
            "{bad}: {error}"
        );
    }
}

#[test]
fn compressed_and_binary_forms_are_refused_by_name() {
    let compressed = format!("{:<72}C{:07}\n{}", "", 1, small_file());
    let error = fails(&compressed);
    assert!(matches!(
        error,
        IgesError::UnsupportedForm {
            form: "compressed ASCII",
            ..
        }
    ));
    let mut binary = b"B\x00\x01\x02IGES".to_vec();
    binary.extend_from_slice(&[0x80; 200]);
    let error = IgesFile::parse(&binary).unwrap_err();
    error_line(&error);
    assert!(
        matches!(error, IgesError::UnsupportedForm { form: "binary", .. }),
        "{error}"
    );
}

#[test]
fn line_ending_variants_read_the_same() {
    let text = small_file();
    let reference = parse(&text);
    let crlf = text.replace('\n', "\r\n");
    // Sequence numbers left-aligned, then trailing blanks stripped: lines shorter than 80.
    let stripped: String = text
        .lines()
        .map(|l| format!("{}{}\n", &l[..73], l[73..].trim_start_matches('0')))
        .collect();
    assert!(stripped.lines().all(|l| l.len() < 80));
    let no_breaks: String = text.lines().collect();
    let old_mac = text.replace('\n', "\r");
    let no_final_break = text.trim_end().to_owned();
    for variant in [crlf, stripped, no_breaks, old_mac, no_final_break] {
        assert_eq!(parse(&variant), reference);
    }
    // Sequence numbers right-aligned in blanks, as CATIA writes them.
    let blanks: String = text
        .lines()
        .map(|l| format!("{}{:>7}\n", &l[..73], l[73..].trim_start_matches('0')))
        .collect();
    assert_eq!(parse(&blanks), reference);
}

#[test]
fn structural_faults_are_errors_with_their_line() {
    let text = small_file();
    parse(&text);
    let original = lines(&text);
    let d3 = original
        .iter()
        .position(|l| l.ends_with("D0000003"))
        .unwrap();
    let cases: Vec<(Vec<String>, usize, &str)> = vec![
        {
            let mut l = original.clone();
            l[d3].replace_range(73..80, "0000004");
            (l, d3 + 1, "sequence number 4, expected 3")
        },
        {
            let mut l = original.clone();
            let t = l.len() - 1;
            l[t].replace_range(25..32, "0000009");
            (l, original.len(), "counts 9 P lines")
        },
        {
            let mut l = original.clone();
            l.remove(d3);
            l.remove(d3);
            (l, d3 + 1, "sequence number 5, expected 3")
        },
        {
            let mut l = original.clone();
            let globals = l.iter().filter(|l| l.as_bytes()[72] == b'G').count();
            let start = l.remove(0);
            l.insert(globals, start);
            (
                l,
                globals + 1,
                "a Start (S) line after the Global (G) section",
            )
        },
        {
            let mut l = original.clone();
            l.pop();
            (l, original.len() - 1, "without a Terminate")
        },
        {
            let mut l = original.clone();
            l[d3].replace_range(48..56, "       4");
            (l, d3 + 1, "field 7 (transformation matrix) points at D 4")
        },
        {
            let mut l = original.clone();
            l[d3 + 1].replace_range(24..32, "      99");
            (l, d3 + 1, "claims P lines")
        },
        {
            let mut l = original.clone();
            l[d3 + 1].replace_range(0..8, "     117");
            (l, d3 + 2, "second line gives entity type 117")
        },
        {
            let mut l = original.clone();
            l[d3].replace_range(8..16, "     1.0");
            (l, d3 + 1, "should be an integer, found '     1.0'")
        },
        {
            let mut l = original.clone();
            l[d3].replace_range(8..16, "  1\r\x01\u{7f}\t2");
            (l, d3 + 1, r"found '  1\x0D\x01\x7F\x092'")
        },
    ];
    for (variant, line, words) in cases {
        let error = fails(&unlines(&variant));
        assert_eq!(error_line(&error), line, "{error}");
        assert!(error.to_string().contains(words), "{error} lacks {words:?}");
    }
}

#[test]
fn transform_chains_compose_and_loops_are_caught() {
    // D 1 translates by +10 in x and is itself placed by D 3, a quarter turn about z.
    let mut translate = ent(124, "124,1.,0.,0.,10.,0.,1.,0.,0.,0.,0.,1.,0.;");
    translate.transform = 3;
    let rotate = ent(124, "124,0.,-1.,0.,0.,1.,0.,0.,0.,0.,0.,1.,0.;");
    let mut point = ent(116, "116,1.,0.,0.;");
    point.transform = 1;
    let entities = [translate.clone(), rotate, point.clone()];
    let file = parse(&build(GLOBAL, &entities));
    let placement = file.transform(file.entity(De(5)).unwrap()).unwrap();
    assert_eq!(placement.apply_point([1.0, 0.0, 0.0]), [0.0, 11.0, 0.0]);
    assert_eq!(placement.apply_vector([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    assert!(
        file.transform(file.entity(De(3)).unwrap())
            .unwrap()
            .is_identity()
    );

    let mut looping = ent(124, "124,1.,0.,0.,0.,0.,1.,0.,0.,0.,0.,1.,0.;");
    looping.transform = 1;
    let file = parse(&build(GLOBAL, &[translate.clone(), looping, point.clone()]));
    let error = file.transform(file.entity(De(5)).unwrap()).unwrap_err();
    assert!(error.to_string().contains("loops"), "{error}");

    let mut wrong = translate;
    wrong.transform = 5;
    let file = parse(&build(
        GLOBAL,
        &[
            wrong,
            ent(110, "110,0,0,0,1,1,1;"),
            ent(110, "110,0,0,0,1,1,1;"),
        ],
    ));
    let error = file.transform(file.entity(De(1)).unwrap()).unwrap_err();
    assert!(
        error.to_string().contains("entity 110 (line), not a 124"),
        "{error}"
    );
    assert_eq!(
        Transform::IDENTITY.then(Transform::IDENTITY),
        Transform::IDENTITY
    );
}

#[test]
fn directory_fields_are_typed() {
    let mut e = ent(128, "128,0,0,1,1,0,0,1,0,0,0.,0.,1.,1.;");
    e.status = "01010502".to_owned();
    e.colour = -3;
    e.form = 9;
    e.label = "SURF 12".to_owned();
    let file = parse(&build(GLOBAL, &[e, ent(314, "314,100.,0.,0.;")]));
    let d = file.entity(De(1)).unwrap().directory();
    assert_eq!(
        (
            d.status.blank,
            d.status.subordinate,
            d.status.entity_use,
            d.status.hierarchy
        ),
        (1, 1, 5, 2)
    );
    assert!(!d.status.is_independent());
    assert_eq!(d.colour, Attr::Pointer(De(3)));
    assert_eq!((d.form, d.label.as_str()), (9, "SURF 12"));
    assert_eq!(super::type_name(128), "rational B-spline surface");
    assert_eq!(super::type_name(1), "unknown entity type");
}

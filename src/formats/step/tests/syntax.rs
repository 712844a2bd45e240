//! Synthetic files covering the grammar: instances, parameters, strings, comments, sections.

use super::super::{StepFile, Value};
use super::{HEAD, all_close, error, ok, parse, wrap};

#[test]
fn complex_instance_with_forward_references() {
    let file = parse(&wrap(
        "#1=ADVANCED_FACE('',(),#3,.T.);\n\
         #3=(BOUNDED_SURFACE()B_SPLINE_SURFACE(1,1,((#4,#5),(#5,#4)),.UNSPECIFIED.,.F.,.F.,.F.)\n\
         B_SPLINE_SURFACE_WITH_KNOTS((2),(2),(0.,1.),(0.,1.),.UNSPECIFIED.)\n\
         RATIONAL_B_SPLINE_SURFACE(((1.,2.),(3.,4.))));\n\
         #4=CARTESIAN_POINT('',(1.,2.,3.));#5=CARTESIAN_POINT('',(4,5,6));",
    ));
    assert_eq!(file.len(), 4);
    let face = ok(file.get(1));
    assert!(!face.is_complex());
    assert_eq!(face.name(), "ADVANCED_FACE");
    let surface = ok(ok(ok(face.record("ADVANCED_FACE")).param(2, "face_geometry")).entity());
    assert_eq!(surface.id(), 3);
    assert_eq!(surface.line(), 9);
    assert!(surface.is_complex());
    let names: Vec<&str> = surface.records().map(|r| r.name()).collect();
    assert_eq!(
        names,
        [
            "BOUNDED_SURFACE",
            "B_SPLINE_SURFACE",
            "B_SPLINE_SURFACE_WITH_KNOTS",
            "RATIONAL_B_SPLINE_SURFACE"
        ]
    );
    assert!(ok(surface.record("BOUNDED_SURFACE")).is_empty());
    let bspline = ok(surface.record("B_SPLINE_SURFACE"));
    assert_eq!(ok(ok(bspline.param(0, "u_degree")).int()), 1);
    let rows = ok(ok(bspline.param(2, "control_points_list")).list());
    assert_eq!(rows.len(), 2);
    let second_row = ok(ok(rows.get(1)).references());
    assert_eq!(second_row, [5, 4]);
    let corner = ok(ok(ok(ok(rows.get(1)).list()).get(0)).entity());
    assert_eq!(
        ok(ok(ok(corner.record("CARTESIAN_POINT")).param(1, "")).reals()),
        [4.0, 5.0, 6.0]
    );
    assert_eq!(
        ok(ok(bspline.param(3, "surface_form")).enumeration()),
        "UNSPECIFIED"
    );
    assert!(!ok(ok(bspline.param(4, "u_closed")).boolean()));
    let weights = ok(ok(ok(surface.record("RATIONAL_B_SPLINE_SURFACE")).param(0, "")).list());
    let flat: Vec<f64> = weights.iter().flat_map(|row| ok(row.reals())).collect();
    assert_eq!(flat, [1.0, 2.0, 3.0, 4.0]);
    let knots = ok(surface.record("B_SPLINE_SURFACE_WITH_KNOTS"));
    assert_eq!(ok(ok(knots.param(0, "")).ints()), [2]);
    ok(file.check_references());
}

#[test]
fn numbers_in_every_form() {
    let file = parse(&wrap(
        "#1=N(1,-2,+3,1.,1.E-5,-.5,2.5E+003,.5,0.E+000,1e3,-0.0,\
         9223372036854775807,-9223372036854775808);",
    ));
    let r = ok(ok(file.get(1)).record("N"));
    let p = |i| ok(r.param(i, ""));
    assert_eq!(ok(p(0).int()), 1);
    assert_eq!(ok(p(1).int()), -2);
    assert_eq!(ok(p(2).int()), 3);
    let reals: Vec<f64> = (3..11).map(|i| ok(p(i).real())).collect();
    assert!(all_close(
        &reals,
        &[1.0, 1e-5, -0.5, 2500.0, 0.5, 0.0, 1000.0, 0.0]
    ));
    assert!(matches!(p(3).value(), Value::Real(_)), "1. is a real");
    assert!(matches!(p(0).value(), Value::Int(_)), "1 is an integer");
    assert_eq!(ok(p(11).int()), i64::MAX);
    assert_eq!(ok(p(12).int()), i64::MIN);
    assert_eq!(ok(p(0).real()), 1.0, "integers read as reals");
}

/// Decodes the one string parameter of `#1=S(<literal>);`.
fn string_of(literal: &[u8]) -> String {
    let mut text = HEAD.as_bytes().to_vec();
    text.extend_from_slice(b"#1=S(");
    text.extend_from_slice(literal);
    text.extend_from_slice(b");\nENDSEC;END-ISO-10303-21;");
    let file = ok(StepFile::parse(&text));
    ok(ok(ok(ok(file.get(1)).record("S")).param(0, "")).string()).to_owned()
}

#[test]
fn every_string_escape() {
    assert_eq!(string_of(b"'It''s'"), "It's");
    assert_eq!(string_of(b"''''"), "'");
    assert_eq!(string_of(b"''"), "");
    assert_eq!(string_of(b"'\\X\\E9t\\X\\E9'"), "été");
    assert_eq!(string_of(b"'\\X2\\00E9\\X0\\'"), "é");
    assert_eq!(string_of(b"'\\X2\\00410042\\X0\\C'"), "ABC");
    assert_eq!(string_of(b"'\\X4\\0001F600\\X0\\'"), "\u{1F600}");
    assert_eq!(
        string_of(b"'\\X2\\D83DDE00\\X0\\'"),
        "\u{1F600}",
        "surrogate pair"
    );
    assert_eq!(
        string_of(b"'\\X2\\D83D\\X0\\'"),
        "\u{FFFD}",
        "lone surrogate"
    );
    assert_eq!(
        string_of(b"'\\X4\\00110000\\X0\\'"),
        "\u{FFFD}",
        "beyond Unicode"
    );
    assert_eq!(string_of(b"'\\S\\i'"), "é", "\\S\\ adds 128");
    assert_eq!(string_of(b"'\\PA\\x\\S\\i'"), "xé", "page select ignored");
    assert_eq!(string_of(b"'a\\\\b'"), "a\\b");
    assert_eq!(
        string_of(b"'C:\\parts\\a.stp'"),
        "C:\\parts\\a.stp",
        "lone backslashes kept"
    );
    assert_eq!(
        string_of(b"'\\X\\G1'"),
        "\\X\\G1",
        "bad hex kept as written"
    );
    assert_eq!(
        string_of(b"'\\X2\\00E9'"),
        "é",
        "unclosed \\X2\\ ends with the string"
    );
    assert_eq!(
        string_of(b"'Undefined De\nscription'"),
        "Undefined Description"
    );
    assert_eq!(string_of(b"'a\r\nb'"), "ab");
    assert_eq!(string_of(b"'caf\xe9'"), "café", "ISO 8859-1 byte");
    assert_eq!(string_of("'café'".as_bytes()), "café", "valid UTF-8");
    assert_eq!(string_of(b"'/* not a comment */'"), "/* not a comment */");
    // Negative control: escapes are decoded, not copied.
    assert_ne!(string_of(b"'\\X\\E9'"), "\\X\\E9");
}

#[test]
fn comments_anywhere() {
    let text = "/* leading */ISO-10303-21;\nHEADER;/* in\nheader */\n\
        FILE_DESCRIPTION(/* description */ ('d1', /* between */ 'd2'),'2;1');\n\
        FILE_NAME('n','t',(''),(''),'pre',/* originating_system */ 'sys','');\n\
        FILE_SCHEMA((/*x*/'AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF { 1 0 10303 442 1 1 4 }'));\n\
        ENDSEC;\nDATA;\n\
        #1 /* a */ = /* b */ A /* c */ ( /* d */ 1 /* e */ , ( 2 /* f */ , /* '#9=' */ 3 ) /* g */ ) /* h */ ;\n\
        /* multi\n\nline */ #2=B('/*');\nENDSEC;\nEND-ISO-10303-21;";
    let file = parse(text);
    assert_eq!(file.len(), 2);
    assert_eq!(file.header.description, ["d1", "d2"]);
    assert_eq!(file.header.originating_system, "sys");
    assert_eq!(
        file.header.schemas,
        ["AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF"]
    );
    let a = ok(ok(file.get(1)).record("A"));
    assert_eq!(ok(ok(a.param(0, "")).int()), 1);
    assert_eq!(ok(ok(a.param(1, "")).ints()), [2, 3]);
    assert_eq!(
        ok(file.get(2)).line(),
        12,
        "lines inside comments are counted"
    );
    assert_eq!(
        ok(ok(ok(ok(file.get(2)).record("B")).param(0, "")).string()),
        "/*"
    );
}

#[test]
fn lowercase_keywords_are_normalised() {
    let file = parse(
        "iso-10303-21;\r\nheader;\r\nfile_schema(('config_control_design'));\r\nendsec;\r\n\
         data;\r\n#1=cartesian_point('',(1.,2.));\r\n#2=Foo(.t.,.unspecified.,length_measure(1.));\r\n\
         endsec;\r\nend-iso-10303-21;\r\n",
    );
    assert_eq!(file.header.schemas, ["CONFIG_CONTROL_DESIGN"]);
    assert_eq!(ok(file.get(1)).name(), "CARTESIAN_POINT");
    let foo = ok(ok(file.get(2)).record("FOO"));
    assert!(ok(ok(foo.param(0, "")).boolean()));
    assert_eq!(ok(ok(foo.param(1, "")).enumeration()), "UNSPECIFIED");
    assert_eq!(ok(ok(foo.param(2, "")).typed()).0, "LENGTH_MEASURE");
    assert_eq!(ok(file.get(2)).line(), 7, "CRLF counts one line");
    assert!(
        file.find(2).is_some_and(|e| e.record("Foo").is_err()),
        "lookup is upper-case"
    );
}

#[test]
fn unset_derived_nested_typed_and_binary() {
    let file = parse(&wrap(
        "#1=A($,*,($,*),((1,(2,(3))),()),LENGTH_MEASURE(5.),\
         POSITIVE_LENGTH_MEASURE(LENGTH_MEASURE(2)),(PARAMETER_VALUE(1.),ANGLE( 2 )),\
         \"0123AB\",\"3F\",\"0\");",
    ));
    let a = ok(ok(file.get(1)).record("A"));
    let p = |i| ok(a.param(i, ""));
    assert!(p(0).is_unset() && p(0).optional().is_none());
    assert!(p(1).is_derived() && p(1).optional().is_some());
    let inner = ok(p(2).list());
    assert!(ok(inner.get(0)).is_unset() && ok(inner.get(1)).is_derived());
    let nested = ok(p(3).list());
    let deep = ok(ok(ok(ok(ok(nested.get(0)).list()).get(1)).list()).get(1));
    assert_eq!(ok(ok(deep.list()).get(0)).int().ok(), Some(3));
    assert!(ok(ok(nested.get(1)).list()).is_empty());
    assert_eq!(
        ok(p(4).real()),
        5.0,
        "scalar accessors look through typed parameters"
    );
    let (name, value) = ok(p(4).typed());
    assert_eq!((name, ok(value.real())), ("LENGTH_MEASURE", 5.0));
    let (outer, inner) = ok(p(5).typed());
    assert_eq!(
        (outer, ok(inner.typed()).0, ok(p(5).int())),
        ("POSITIVE_LENGTH_MEASURE", "LENGTH_MEASURE", 2)
    );
    assert!(all_close(&ok(p(6).reals()), &[1.0, 2.0]));
    assert_eq!(ok(p(7).binary()), "0123AB");
    assert_eq!(ok(p(8).binary()), "3F");
    assert_eq!(ok(p(9).binary()), "0");
    assert!(p(0).typed().is_err(), "negative control: $ is not typed");
}

#[test]
fn sections_and_header() {
    let text = "\u{feff}ISO-10303-21;\nHEADER;\n\
        FILE_DESCRIPTION(('A','B'),'2;1');\n\
        FILE_NAME('part.stp','2024-01-01T00:00:00',('me'),('org'),'pre 1.0','CAD 9','auth');\n\
        FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }','X_MIM'));\n\
        FILE_POPULATION('s','g',$);\nENDSEC;\n\
        ANCHOR;\n<a> = #1; /* ENDSEC; */ <b> = 'ENDSEC;';\nENDSEC;\n\
        DATA('one',('AUTOMOTIVE_DESIGN'));\n#1=A(#2);\nENDSEC;\n\
        DATA;\n#2=B(#1);\nENDSEC;\n\
        SIGNATURE;\nabc;\nENDSEC;\nEND-ISO-10303-21;\ntrailing junk \x00 ignored";
    let file = parse(text);
    let h = &file.header;
    assert_eq!(h.description, ["A", "B"]);
    assert_eq!(h.implementation_level, "2;1");
    assert_eq!(h.name, "part.stp");
    assert_eq!(h.time_stamp, "2024-01-01T00:00:00");
    assert_eq!(
        (h.author.as_slice(), h.organization.as_slice()),
        (&["me".to_owned()][..], &["org".to_owned()][..])
    );
    assert_eq!(h.preprocessor_version, "pre 1.0");
    assert_eq!(h.originating_system, "CAD 9");
    assert_eq!(h.authorization, "auth");
    assert_eq!(h.schemas, ["AUTOMOTIVE_DESIGN", "X_MIM"]);
    assert_eq!(
        h.schema_identifiers[0],
        "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }"
    );
    assert_eq!(file.len(), 2, "instances from both DATA sections");
    assert_eq!(ok(file.get(2)).line(), 15);
    assert!(file.check_references().is_ok());
}

#[test]
fn header_is_lenient() {
    let file = parse("ISO-10303-21;HEADER;FILE_NAME($,1,'x');ENDSEC;DATA;ENDSEC;END-ISO-10303-21;");
    assert_eq!(file.header.name, "");
    assert!(file.header.author.is_empty() && file.header.schemas.is_empty());
    assert!(file.is_empty());
}

#[test]
fn sparse_and_huge_ids() {
    let file = parse(&wrap(
        "#18446744073709551615=A(#7);#7=B(#2147483648);#2147483648=C();",
    ));
    assert_eq!(file.len(), 3);
    assert_eq!(ok(file.get(u64::MAX)).name(), "A");
    assert_eq!(ok(file.get(2_147_483_648)).name(), "C");
    assert!(file.find(8).is_none() && file.find(2_147_483_647).is_none());
    assert!(file.check_references().is_ok());
    let order: Vec<u64> = file.entities().map(|e| e.id()).collect();
    assert_eq!(order, [u64::MAX, 7, 2_147_483_648], "file order is kept");
}

#[test]
fn nesting_up_to_the_limit() {
    let depth = super::super::MAX_DEPTH;
    let ok_text = wrap(&format!(
        "#1=A({}1{});",
        "(".repeat(depth),
        ")".repeat(depth)
    ));
    let file = parse(&ok_text);
    let mut p = ok(ok(ok(file.get(1)).record("A")).param(0, ""));
    for _ in 1..depth {
        p = ok(ok(p.list()).get(0));
    }
    assert_eq!(ok(ok(p.list()).get(0)).int().ok(), Some(1));
    let too_deep = wrap(&format!(
        "#1=A({}1{});",
        "(".repeat(depth + 1),
        ")".repeat(depth + 1)
    ));
    assert_eq!(
        error(&too_deep),
        "line 8: parameters nested deeper than 64 levels inside #1 (started at line 8)"
    );
}

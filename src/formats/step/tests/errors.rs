//! The exact message of every syntax error, with its line and instance.

use super::super::{StepError, StepFile};
use super::{HEAD, error, wrap};

#[test]
fn not_a_step_file() {
    let msg = "line 1: not a STEP file: expected ISO-10303-21, found";
    assert_eq!(error("hello world"), format!("{msg} keyword hello"));
    assert_eq!(error(""), format!("{msg} an empty file"));
    assert_eq!(error("<?xml"), format!("{msg} '<'"));
    assert_eq!(
        error("\n\nISO-10303-22;"),
        "line 3: not a STEP file: expected ISO-10303-21, found keyword ISO-10303-22"
    );
    let gzip = StepFile::parse(b"\x1f\x8b\x08\x00")
        .err()
        .map(|e| e.to_string());
    assert_eq!(gzip.as_deref(), Some(format!("{msg} byte 0x1f").as_str()));
    assert_eq!(
        error("ISO-10303-21;\nDATA;"),
        "line 2: unexpected keyword DATA between sections, expected HEADER"
    );
}

#[test]
fn truncated_files() {
    assert_eq!(
        error(&format!("{HEAD}#123=A(1,\n2")),
        "line 9: unexpected end of file inside #123 (started at line 8), expected ',' or ')'"
    );
    assert_eq!(
        error(&format!("{HEAD}#123=A(1,")),
        "line 8: unexpected end of file inside #123 (started at line 8), expected a parameter"
    );
    assert_eq!(
        error(&format!("{HEAD}#1=A()")),
        "line 8: unexpected end of file inside #1 (started at line 8), expected ';'"
    );
    assert_eq!(
        error(&format!("{HEAD}#1=A();\n")),
        "line 9: unexpected end of file in a DATA section, expected an entity instance '#…' or ENDSEC"
    );
    assert_eq!(
        error(&format!("{HEAD}ENDSEC;\n")),
        "line 9: unexpected end of file between sections, expected DATA or END-ISO-10303-21"
    );
    assert_eq!(
        error(&format!("{HEAD}ENDSEC;\nEND-ISO-10303-21")),
        "line 9: unexpected end of file between sections, expected ';' after END-ISO-10303-21"
    );
    assert_eq!(
        error("ISO-10303-21;\nHEADER;\nFILE_NAME('x',"),
        "line 3: unexpected end of file inside a HEADER entry (started at line 3), expected a parameter"
    );
}

#[test]
fn unterminated_string_and_comment() {
    assert_eq!(
        error(&format!("{HEAD}#5=A('abc);\nENDSEC;\nEND-ISO-10303-21;\n")),
        "line 8: unterminated string inside #5 (started at line 8)"
    );
    assert_eq!(
        error(&format!(
            "{HEAD}#5=A(1);\n/* oops\nENDSEC;\nEND-ISO-10303-21;"
        )),
        "line 9: unterminated comment in a DATA section"
    );
    assert_eq!(
        error("ISO-10303-21;\nHEADER;\nFILE_NAME(/* x"),
        "line 3: unterminated comment inside a HEADER entry (started at line 3)"
    );
}

#[test]
fn bad_tokens_are_shown_escaped() {
    let at = "inside #5 (started at line 8)";
    assert_eq!(
        error(&wrap("#5=A(1,@);")),
        format!("line 8: unexpected '@' {at}, expected a parameter")
    );
    assert_eq!(
        error(&wrap("#5=A(1,);")),
        format!("line 8: unexpected ')' {at}, expected a parameter")
    );
    assert_eq!(
        error(&wrap("#5=A(1 2);")),
        format!("line 8: unexpected '2' {at}, expected ',' or ')'")
    );
    assert_eq!(
        error(&wrap("#5=A(.T);")),
        format!("line 8: unexpected ')' {at}, expected '.' closing an enumeration")
    );
    assert_eq!(
        error(&wrap("#5=A(\"4F\");")),
        format!(
            "line 8: unexpected '4' {at}, expected a binary literal starting with 0, 1, 2 or 3"
        )
    );
    assert_eq!(
        error(&wrap("#5=A(\"0Z\");")),
        format!("line 8: unexpected keyword Z {at}, expected '\"' closing a binary literal")
    );
    assert_eq!(
        error(&wrap("#5=A(1.E);")),
        format!("line 8: unexpected ')' {at}, expected the digits of an exponent")
    );
    assert_eq!(
        error(&wrap("#5=A(-);")),
        format!("line 8: unexpected '-' {at}, expected a number")
    );
    assert_eq!(
        error(&wrap("#5=A;")),
        format!("line 8: unexpected ';' {at}, expected '(' after the entity type name")
    );
    assert_eq!(
        error(&wrap("#5 A();")),
        format!("line 8: unexpected keyword A {at}, expected '=' after the entity name")
    );
    assert_eq!(
        error(&wrap("#5=();")),
        format!("line 8: unexpected ')' {at}, expected a record name in a complex instance")
    );
    assert_eq!(
        error(&wrap("#5=1;")),
        format!("line 8: unexpected '1' {at}, expected an entity type name or '('")
    );
    assert_eq!(
        error(&wrap("#5=A(B);")),
        format!("line 8: unexpected ')' {at}, expected '(' after a typed parameter's type name")
    );
    assert_eq!(
        error(&wrap("#5=A(LENGTH_MEASURE(1.,2.));")),
        format!(
            "line 8: unexpected 2 values {at}, expected exactly one value in a typed parameter"
        )
    );
    assert_eq!(
        error(&wrap("#=A();")),
        "line 8: unexpected '=' in a DATA section, expected digits of an entity name after '#'"
    );
    assert_eq!(
        error(&wrap("A();")),
        "line 8: unexpected keyword A in a DATA section, expected an entity instance '#…' or ENDSEC"
    );
    assert_eq!(
        error(&format!("{HEAD}ENDSEC;\nFOO;\n")),
        "line 9: unexpected keyword FOO between sections, expected DATA or END-ISO-10303-21"
    );
}

#[test]
fn binary_junk() {
    assert_eq!(
        error(&wrap("#5=A(1,\x01);")),
        "line 8: binary byte 0x01 inside #5 (started at line 8): not STEP text"
    );
    assert_eq!(
        error(&wrap("#5=A(1é);")),
        "line 8: binary byte 0xc3 inside #5 (started at line 8): not STEP text"
    );
    assert_eq!(
        error(&wrap("\x00\x00")),
        "line 8: binary byte 0x00 in a DATA section: not STEP text"
    );
}

#[test]
fn duplicates_missing_semicolons_and_ranges() {
    assert_eq!(
        error(&wrap("#1=A();\n#1=B();")),
        "line 9: duplicate entity #1 (first defined at line 8)"
    );
    assert_eq!(
        error(&wrap(
            "#1000000000=A();\n#5=B();\n#5=C();\n#1000000000=C();"
        )),
        "line 10: duplicate entity #5 (first defined at line 9)",
        "sorted index reports the first duplicate in file order"
    );
    assert_eq!(
        error(&wrap("#1=A()\n#2=B();")),
        "line 9: missing ';' after #1 (started at line 8), found '#'"
    );
    assert_eq!(
        error(&wrap("#1=A(99999999999999999999);")),
        "line 8: number 99999999999999999999 out of range inside #1 (started at line 8)"
    );
    assert_eq!(
        error(&wrap("#1=A(1.E999);")),
        "line 8: number 1.E999 out of range inside #1 (started at line 8)"
    );
    assert_eq!(
        error(&wrap("#99999999999999999999=A();")),
        "line 8: number 99999999999999999999 out of range in a DATA section"
    );
}

#[test]
fn error_line_and_id_accessors() {
    let err = StepFile::parse_str(&wrap("#5=A(1,@);")).err();
    assert_eq!(err.as_ref().and_then(StepError::line), Some(8));
    assert_eq!(err.as_ref().and_then(StepError::entity_id), Some(5));
    let err = StepFile::parse_str(&wrap("#1=A();\n#1=B();")).err();
    assert_eq!(err.as_ref().and_then(StepError::entity_id), Some(1));
    let err = StepFile::parse_str("x").err();
    assert_eq!(
        (
            err.as_ref().and_then(StepError::line),
            err.as_ref().and_then(StepError::entity_id)
        ),
        (Some(1), None)
    );
}

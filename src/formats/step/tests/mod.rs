//! Tests of the STEP reader, and the helpers they share (each helper has a negative control).

mod access;
mod errors;
mod real_files;
mod robustness;
mod syntax;

use super::{ParamRef, StepError, StepFile, Value};

/// A header that puts the first DATA line at line 8.
const HEAD: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n\
FILE_NAME('t','',(''),(''),'','','');\nFILE_SCHEMA(('CONFIG_CONTROL_DESIGN'));\nENDSEC;\nDATA;\n";

/// A complete file whose DATA section holds `data`, starting at line 8.
fn wrap(data: &str) -> String {
    format!("{HEAD}{data}\nENDSEC;\nEND-ISO-10303-21;\n")
}

/// Parses a file that must be valid.
fn parse(text: &str) -> StepFile {
    match StepFile::parse_str(text) {
        Ok(file) => file,
        Err(e) => panic!("should parse: {e}\n{text}"),
    }
}

/// The error message of a file that must be invalid.
fn error(text: &str) -> String {
    match StepFile::parse_str(text) {
        Ok(_) => panic!("should fail:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// Unwraps an access result in a test, showing the error.
fn ok<T>(result: Result<T, StepError>) -> T {
    result.unwrap_or_else(|e| panic!("{e}"))
}

/// Relative closeness of reals, for values written with 11–15 significant digits.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
}

/// Whether two real lists are element-wise [`close`].
fn all_close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| close(*x, *y))
}

/// Counts entity instances `#id =` in STEP text independently of the parser: a tiny state
/// machine that skips strings (with `''`) and comments and accepts whitespace and comments
/// between `#id` and `=`, so that references (`#id` not followed by `=`) are not counted.
fn count_instances(text: &[u8]) -> usize {
    let mut count = 0;
    let mut i = 0;
    let skip_gap = |mut j: usize| loop {
        match text.get(j..) {
            Some([b' ' | b'\t' | b'\r' | b'\n', ..]) => j += 1,
            Some([b'/', b'*', rest @ ..]) => {
                let end = rest
                    .windows(2)
                    .position(|w| w == b"*/")
                    .unwrap_or(rest.len());
                j += 2 + end + 2;
            }
            _ => return j,
        }
    };
    while let Some(&b) = text.get(i) {
        match b {
            b'\'' => {
                i += 1;
                loop {
                    match text.get(i..) {
                        Some([b'\'', b'\'', ..]) => i += 2,
                        Some([b'\'', ..]) | None | Some([]) => break,
                        Some(_) => i += 1,
                    }
                }
                i += 1;
            }
            b'/' if text.get(i + 1) == Some(&b'*') => i = skip_gap(i),
            b'#' => {
                let digits = text
                    .iter()
                    .skip(i + 1)
                    .take_while(|b| b.is_ascii_digit())
                    .count();
                i += 1 + digits;
                if digits > 0 && text.get(skip_gap(i)) == Some(&b'=') {
                    count += 1;
                }
            }
            _ => i += 1,
        }
    }
    count
}

/// Calls every accessor on every value of the file, recursively, ignoring the results: used
/// on damaged input to show that access never panics either.
fn touch_all(file: &StepFile) -> usize {
    fn touch(p: ParamRef<'_>) -> usize {
        let _ = (
            p.int(),
            p.real(),
            p.string(),
            p.enumeration(),
            p.boolean(),
            p.logical(),
        );
        let _ = (
            p.reference(),
            p.entity(),
            p.binary(),
            p.typed(),
            p.reals(),
            p.references(),
        );
        let _ = p.context();
        match p.value() {
            Value::List(list) => {
                let _ = list.get(list.len());
                1 + list.iter().map(touch).sum::<usize>()
            }
            Value::Typed(_, inner) => 1 + touch(inner),
            _ => 1,
        }
    }
    let _ = file.check_references();
    let mut n = 0;
    for e in file.entities() {
        let _ = (e.record("X"), e.type_names(), e.invalid("x"));
        for r in e.records() {
            let _ = r.param(r.len(), "missing");
            n += r.params().map(touch).sum::<usize>();
        }
    }
    n
}

#[test]
fn close_rejects_different_values() {
    assert!(close(1.0, 1.0 + 1e-14));
    assert!(!close(1.0, 1.0001), "negative control");
    assert!(!close(0.0, 1e-9), "negative control near zero");
    assert!(all_close(&[1.0, 2.0], &[1.0, 2.0]));
    assert!(
        !all_close(&[1.0, 2.0], &[1.0, 2.5]),
        "negative control: value"
    );
    assert!(!all_close(&[1.0, 2.0], &[1.0]), "negative control: length");
}

#[test]
fn count_instances_ignores_references_strings_and_comments() {
    let text = b"#1=A(#2,'#3=x',''); /* #4=B(); */ #5 /*c*/ = C('it''s #6=');\n#7\n=D(#8);";
    assert_eq!(count_instances(text), 3);
    // Negative control: a naive count of "#digits=" patterns is fooled by the string.
    let naive = text
        .windows(3)
        .filter(|w| w[0] == b'#' && w[2] == b'=')
        .count();
    assert_ne!(naive, 3);
    assert_eq!(count_instances(b"#1=A();#2=B();"), 2);
    assert_ne!(
        count_instances(b"#1=A(#2);"),
        2,
        "negative control: references not counted"
    );
}

#[test]
fn touch_all_visits_every_value() {
    let file = parse(&wrap("#1=A(1,(2,(3,T(4))),#1);"));
    // 1, the outer list, 2, the inner list, 3, the typed value and its inner 4, #1.
    assert_eq!(touch_all(&file), 8);
    assert_ne!(touch_all(&parse(&wrap("#1=A(1);"))), 8, "negative control");
}

#[test]
fn doc_example() -> Result<(), StepError> {
    let file = StepFile::parse_str(
        "ISO-10303-21;HEADER;FILE_SCHEMA(('CONFIG_CONTROL_DESIGN'));ENDSEC;\
         DATA;#1=CARTESIAN_POINT('',(0.,1.,2.));ENDSEC;END-ISO-10303-21;",
    )?;
    let point = file.get(1)?.record("CARTESIAN_POINT")?;
    assert_eq!(point.param(1, "coordinates")?.reals()?, [0.0, 1.0, 2.0]);
    Ok(())
}

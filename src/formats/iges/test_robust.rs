//! Damaged input: truncations, byte flips, shifted columns and absurd counts must all end in a
//! one-line error that names a line, never in a panic or a huge allocation. A file that still
//! parses after damage (a changed digit is undetectable) must survive every accessor.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use super::test_support::{GLOBAL, build, ent, error_line, lines, small_file, unlines};
use super::{De, IgesFile};

fn real_file(name: &str) -> Vec<u8> {
    let dir = std::env::var_os("PRESPLINE_CAD_DIR").map_or_else(
        || concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/cad").into(),
        std::path::PathBuf::from,
    );
    std::fs::read(dir.join(name)).unwrap()
}

/// Calls every accessor on every parameter (and one past the end), so that damage that parses
/// is also shown not to panic later.
fn exercise(file: &IgesFile) {
    for e in file.entities() {
        let n = e.param_count();
        for k in 0..=n + 1 {
            let _ = (e.int(k), e.real(k), e.string(k), e.optional_pointer(k));
            let _ = (e.count(k), e.int_or(k, 1), e.real_or(k, 1.0), e.value(k));
            let _ = file.follow_optional(e, k);
        }
        let _ = (e.reals(1, n), e.ints(n, 2), e.pointers(1, usize::MAX));
        let _ = file.transform(e);
        let _ = super::Transform::from_entity(e);
        let _ = e.type_name();
    }
}

/// Parses `bytes`; an error must be one line naming a line of the input; a success is exercised.
fn survive(bytes: &[u8]) -> bool {
    match IgesFile::parse(bytes) {
        Ok(file) => {
            exercise(&file);
            true
        }
        Err(error) => {
            let line = error_line(&error);
            let count = bytes
                .split(|&b| b == b'\n')
                .count()
                .max(bytes.len() / 80 + 1);
            assert!(line <= count, "line {line} of {count}: {error}");
            false
        }
    }
}

/// xorshift64*: deterministic, so a failure reproduces.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn every_truncation_of_real_files_is_an_error() {
    for name in ["OCC8842_cylinder_CATIA.igs", "BIGES.igs"] {
        let bytes = real_file(name);
        assert!(survive(&bytes), "control: {name} whole");
        // Dropping only the final line break leaves the file whole.
        assert!(survive(&bytes[..bytes.len() - 1]));
        let positions = 200;
        for i in 0..positions {
            let cut = i * (bytes.len() - 1) / positions;
            assert!(!survive(&bytes[..cut]), "{name} cut at {cut} parsed");
        }
        // The last few cuts (inside the Terminate line) are the subtle ones.
        for cut in bytes.len() - 12..bytes.len() - 1 {
            assert!(!survive(&bytes[..cut]), "{name} cut at {cut} parsed");
        }
    }
}

#[test]
fn every_truncation_of_a_small_file_is_an_error() {
    let text = small_file();
    let bytes = text.as_bytes();
    assert!(survive(bytes));
    for cut in 0..bytes.len() - 1 {
        assert!(!survive(&bytes[..cut]), "cut at {cut} parsed");
    }
}

#[test]
fn random_damage_never_panics() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let sources = [
        small_file().into_bytes(),
        real_file("BIGES.igs"),
        real_file("OCC131-2.igs"),
    ];
    let (mut parsed, mut refused) = (0, 0);
    for trial in 0..600 {
        let mut bytes = sources[trial % sources.len()].clone();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(bytes.len());
            match rng.below(4) {
                0 => bytes[at] ^= 1 << rng.below(8),
                1 => bytes[at] = rng.next() as u8,
                2 => {
                    bytes.remove(at);
                }
                _ => bytes.insert(at, b"0123456789.,;HDEP -+\r\n"[rng.below(22)]),
            }
        }
        if survive(&bytes) {
            parsed += 1;
        } else {
            refused += 1;
        }
    }
    // Most damage is caught; some (a changed digit) cannot be.
    assert!(refused > parsed, "{refused} refused, {parsed} parsed");
    assert!(
        parsed > 0,
        "no damage went unnoticed: the test is not reaching the accessors"
    );
}

#[test]
fn a_line_shifted_by_one_column_is_refused_at_that_line() {
    let texts = [
        small_file(),
        String::from_utf8(real_file("OCC8842_cylinder_CATIA.igs")).unwrap(),
    ];
    for text in texts {
        let original = lines(&text);
        for index in 0..original.len() {
            for right in [true, false] {
                let mut shifted = original.clone();
                if right {
                    shifted[index].insert(0, ' ');
                } else {
                    shifted[index].remove(0);
                }
                let error = IgesFile::parse(unlines(&shifted).as_bytes()).unwrap_err();
                assert_eq!(error_line(&error), index + 1, "{error}");
            }
        }
    }
}

#[test]
fn a_shifted_directory_line_names_the_letter_it_found() {
    let original = lines(&small_file());
    let d = original
        .iter()
        .position(|l| l.ends_with("D0000003"))
        .unwrap();
    let mut shifted = original.clone();
    shifted[d].remove(0);
    let error = IgesFile::parse(unlines(&shifted).as_bytes()).unwrap_err();
    assert_eq!(
        error.to_string(),
        format!(
            "line {}: column 73 holds '0', not a section letter (S, G, D, P or T) ('D' is in column 72: the columns are shifted)",
            d + 1
        )
    );
}

#[test]
fn absurd_counts_are_errors_not_allocations() {
    let huge = 2_000_000_000;
    let file = IgesFile::parse(
        build(
            GLOBAL,
            &[
                ent(102, &format!("102,{huge},3;")),
                ent(110, "110,0.,0.,0.,1.,1.,1.;"),
                ent(128, &format!("128,{huge},1,3,3,0,0,1,0,0;")),
            ],
        )
        .as_bytes(),
    )
    .unwrap();
    let composite = file.entity(De(1)).unwrap();
    let error = composite.count(1).unwrap_err();
    error_line(&error);
    assert!(
        error
            .to_string()
            .contains("count of 2000000000, more than the entity's 2"),
        "{error}"
    );
    assert!(composite.pointers(2, huge).is_err());
    assert!(composite.reals(1, usize::MAX).is_err());
    let surface = file.entity(De(5)).unwrap();
    assert!(surface.count(1).is_err());
    assert!(surface.reals(10, huge + 5).is_err());

    let cases = [
        build(GLOBAL, &[ent(406, &format!("406,1,{huge}Habc;"))]),
        build(&GLOBAL.replacen("4Htest", &format!("{huge}Htest"), 1), &[]),
        build(GLOBAL, &[ent(406, "406,1,99999999999999999999999999Habc;")]),
    ];
    for text in cases {
        let error = IgesFile::parse(text.as_bytes()).unwrap_err();
        error_line(&error);
        assert!(error.to_string().contains("Hollerith string of"), "{error}");
    }
    // The widest a DE field can hold: 99,999,999 parameter lines, or a pointer that far.
    let text = small_file();
    let original = lines(&text);
    let d = original
        .iter()
        .position(|l| l.ends_with("D0000004"))
        .unwrap();
    for (range, what) in [(24..32, "claims P lines"), (8..16, "entity 116")] {
        let mut changed = original.clone();
        let row = if what == "claims P lines" { d } else { d - 1 };
        changed[row].replace_range(range, "99999999");
        let error = IgesFile::parse(unlines(&changed).as_bytes()).unwrap_err();
        assert_eq!(error_line(&error), d, "{error}");
        assert!(error.to_string().contains("P section has"), "{error}");
    }
    let mut changed = original;
    let t = changed.len() - 1;
    changed[t].replace_range(17..24, "9999999");
    assert!(IgesFile::parse(unlines(&changed).as_bytes()).is_err());
}

//! Damaged input: truncations, byte flips, deep nesting, huge numbers. The reader must return
//! an error with a plausible line, never panic, never overflow the stack, never allocate from
//! a number in the file.

use super::super::model::Index;
use super::super::{StepError, StepFile};
use super::{touch_all, wrap};

/// A small file using every feature, for exhaustive truncation.
fn feature_file() -> String {
    "ISO-10303-21;\nHEADER;/* c */FILE_DESCRIPTION(('d'),'2;1');\n\
     FILE_NAME('n','t',('a'),('o'),'p','s','z');FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 }'));\n\
     ENDSEC;\nDATA;\n#1=(A(1,-2.5E+003,.T.)B('It''s \\X2\\00E9\\X0\\',\"0F\",$,*));\n\
     #2 = C ( ( #1 , ( 1. , -.5 ) ) , LENGTH_MEASURE ( 5. ) /* x */ ) ;\nENDSEC;\n\
     END-ISO-10303-21;\n"
        .to_owned()
}

/// The number of lines in `bytes` (a final line without a newline counts).
fn lines(bytes: &[u8]) -> u32 {
    u32::try_from(bytes.iter().filter(|&&b| b == b'\n').count() + 1).unwrap_or(u32::MAX)
}

/// Checks one parse of possibly damaged `bytes`: an error must carry a line within the
/// input; a success must survive every accessor. Returns whether it parsed.
fn check(bytes: &[u8]) -> bool {
    match StepFile::parse(bytes) {
        Ok(file) => {
            touch_all(&file);
            true
        }
        Err(e) => {
            let line = e.line().unwrap_or(0);
            assert!(
                line >= 1 && line <= lines(bytes),
                "line {line} of {}: {e}",
                lines(bytes)
            );
            assert!(!e.to_string().contains('\n'), "one-line message: {e}");
            false
        }
    }
}

/// End of the `END-ISO-10303-21;` terminator: a prefix at least this long is a complete file.
fn complete_length(bytes: &[u8]) -> usize {
    let key = b"END-ISO-10303-21;";
    let at = bytes
        .windows(key.len())
        .rposition(|w| w == key)
        .unwrap_or(usize::MAX - key.len());
    at + key.len()
}

/// Truncates `bytes` at each position in `positions`: incomplete prefixes fail, complete ones
/// parse to the same number of instances.
fn truncations(bytes: &[u8], positions: impl Iterator<Item = usize>) {
    let complete = complete_length(bytes);
    let full = StepFile::parse(bytes).map(|f| f.len());
    assert!(full.is_ok(), "the untruncated file parses");
    for at in positions {
        let prefix = bytes.get(..at).unwrap_or(bytes);
        let parsed = check(prefix);
        if at < complete {
            assert!(!parsed, "prefix of {at} bytes should fail");
        } else {
            assert_eq!(
                StepFile::parse(prefix).map(|f| f.len()).ok(),
                full.clone().ok()
            );
        }
    }
}

#[test]
fn every_truncation_of_a_small_file_fails_with_a_line() {
    let text = feature_file();
    let bytes = text.as_bytes();
    assert_eq!(StepFile::parse(bytes).map(|f| f.len()).ok(), Some(2));
    truncations(bytes, 0..=bytes.len());
    // Negative control: the check does notice a prefix that parses although it should not.
    let complete = complete_length(bytes);
    assert!(check(&bytes[..complete]), "the complete prefix parses");
}

#[test]
fn truncations_of_real_files() {
    let dir = std::env::var_os("PRESPLINE_CAD_DIR").map_or_else(
        || std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/cad")),
        std::path::PathBuf::from,
    );
    // About 200 evenly spread cuts of a 62 kB file (its header is full of comments), and
    // fewer of the others to keep the debug-build test fast.
    for (name, cuts) in [
        ("trj5_k1-ug-214.stp", 200),
        ("bug24595_281390.stp", 20),
        ("linkrods.step", 10),
    ] {
        let bytes = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let step = bytes.len() / cuts;
        truncations(&bytes, (0..cuts).map(|k| k * step + k % 7));
    }
    // Every cut at the interesting end of a small file: inside ENDSEC / END-ISO-10303-21.
    let bytes = std::fs::read(dir.join("xr1-tu-rod.stp")).unwrap_or_default();
    let complete = complete_length(&bytes);
    truncations(&bytes, complete.saturating_sub(40)..=bytes.len());
}

/// Deterministic xorshift64*, so that failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        usize::try_from(self.next() % (n.max(1) as u64)).unwrap_or(0)
    }
}

/// Applies `rounds` random damages of 1–4 edits to `original` and checks each.
fn flips(original: &[u8], seed: u64, rounds: usize) -> (usize, usize) {
    const SPECIAL: &[u8] = b"()',;#=$*.\"/\\\n\0\xff EX0123456789-+";
    let mut rng = Rng(seed);
    let (mut parsed, mut failed) = (0, 0);
    for _ in 0..rounds {
        let mut bytes = original.to_vec();
        for _ in 0..=rng.below(4) {
            let at = rng.below(bytes.len());
            let byte = match rng.below(3) {
                0 => SPECIAL[rng.below(SPECIAL.len())],
                1 => bytes[at] ^ (1 << rng.below(8)),
                _ => (rng.next() & 0xff) as u8,
            };
            if rng.below(4) == 0 {
                bytes.insert(at, byte);
            } else {
                bytes[at] = byte;
            }
        }
        if check(&bytes) {
            parsed += 1
        } else {
            failed += 1
        }
    }
    (parsed, failed)
}

#[test]
fn random_damage_never_panics() {
    let (parsed, failed) = flips(feature_file().as_bytes(), 0x5eed_1234, 3000);
    // Both outcomes occur, so the damage is neither always fatal nor always harmless.
    assert!(
        parsed > 100 && failed > 100,
        "parsed {parsed}, failed {failed}"
    );
    let dir = std::env::var_os("PRESPLINE_CAD_DIR").map_or_else(
        || std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/cad")),
        std::path::PathBuf::from,
    );
    let bytes = std::fs::read(dir.join("xr1-tu-rod.stp")).unwrap_or_default();
    assert!(!bytes.is_empty(), "xr1-tu-rod.stp is there");
    let (parsed, failed) = flips(&bytes, 42, 1000);
    assert!(parsed > 0 && failed > 0, "parsed {parsed}, failed {failed}");
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    let limit = "parameters nested deeper than 64 levels";
    for (open, close) in [("(", ")"), ("T(", ")")] {
        let unclosed = wrap(&format!("#1=A({});", open.repeat(10_000)));
        let closed = wrap(&format!(
            "#1=A({}1{});",
            open.repeat(10_000),
            close.repeat(10_000)
        ));
        for text in [unclosed, closed] {
            let err = StepFile::parse_str(&text).err();
            assert!(
                matches!(
                    err,
                    Some(StepError::TooDeep {
                        line: 8,
                        limit: 64,
                        ..
                    })
                ),
                "{err:?}"
            );
            assert!(err.is_some_and(|e| e.to_string().contains(limit)));
        }
    }
    let header = format!("ISO-10303-21;HEADER;FILE_NAME({}", "(".repeat(10_000));
    assert!(matches!(
        StepFile::parse_str(&header),
        Err(StepError::TooDeep { line: 1, .. })
    ));
}

#[test]
fn huge_numbers_size_nothing() {
    // A dense id table is only built when it is at most 4 slots per instance (plus 1024).
    let file = StepFile::parse_str(&wrap("#2147483648=A(2147483648,(#2147483648));"));
    let file = file.unwrap_or_else(|e| panic!("{e}"));
    assert!(
        matches!(file.index, Index::Sorted(_)),
        "a 2 G id must not size a table"
    );
    assert_eq!(
        file.find(2_147_483_648).map(|e| e.id()),
        Some(2_147_483_648)
    );
    let ids: String = (1..=100).map(|i| format!("#{}=A();", i * 3)).collect();
    let dense = StepFile::parse_str(&wrap(&ids)).unwrap_or_else(|e| panic!("{e}"));
    match &dense.index {
        Index::Dense(table) => assert!(table.len() <= 4 * 100 + 1024),
        Index::Sorted(_) => panic!("ids 3..300 should use the direct table"),
    }
    // Negative control of the first check: many instances with a big id still get the table.
    let many: String = (0..2000).map(|i| format!("#{}=A();", i + 5000)).collect();
    let many = StepFile::parse_str(&wrap(&many)).unwrap_or_else(|e| panic!("{e}"));
    assert!(matches!(many.index, Index::Dense(_)));
}

/// A longer run of [`random_damage_never_panics`]: `cargo test --release -- --ignored long_`.
#[test]
#[ignore = "slow; run in release"]
fn long_random_damage() {
    let (parsed, failed) = flips(feature_file().as_bytes(), 7, 300_000);
    assert!(parsed > 0 && failed > 0);
    let dir = std::env::var_os("PRESPLINE_CAD_DIR").map_or_else(
        || std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/cad")),
        std::path::PathBuf::from,
    );
    let bytes = std::fs::read(dir.join("trj9_io1-ug-214.stp")).unwrap_or_default();
    let (parsed, failed) = flips(&bytes, 9, 20_000);
    assert!(parsed > 0 && failed > 0);
}

//! Scene-file JSON written by hand, one object per line, numbers in Rust's shortest round-trip
//! form so a saved scene loads back bit for bit.

use glam::DVec3;
use std::fmt::Write;

pub fn field(s: &mut String, name: &str, value: &str) {
    let _ = write!(s, ", \"{name}\": {value}");
}

/// Shortest round-trip decimal (Rust's `{:?}` for f64 never loses bits; exponents for extremes).
#[must_use]
pub fn number(x: f64) -> String {
    format!("{x:?}")
}

#[must_use]
pub fn numbers(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| number(x)).collect();
    format!("[{}]", items.join(", "))
}

#[must_use]
pub fn points(p: &[DVec3]) -> String {
    let items: Vec<String> = p.iter().map(|q| numbers(&q.to_array())).collect();
    format!("[{}]", items.join(", "))
}

#[must_use]
pub fn json_string(s: &str) -> String {
    serde_json::to_string(s).expect("strings always serialise")
}

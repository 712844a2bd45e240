//! [`FreeForm`] elements → OBJ text. Every element gets its own `o` name, `# prespline`
//! settings and `v` statements right before it; numbers are written in Rust's shortest
//! round-trip form, so reading the file back reproduces every value bit for bit.

use super::model::FreeForm;
use crate::scene::write::number;
use std::fmt::Write;

/// Statement lines longer than this are continued with `\`.
const WIDTH: usize = 100;

/// Serialises elements; vertex numbers count up from 1 through the file.
pub fn write(elements: &[FreeForm]) -> String {
    let mut s = format!(
        "# Wavefront OBJ free-form geometry written by prespline {}\n\
         # Rational elements carry their weights as the fourth v coordinate; see docs/obj.md.\n",
        env!("CARGO_PKG_VERSION")
    );
    let mut next = 1usize;
    for e in elements {
        s.push('\n');
        if let Some(name) = &e.name {
            let _ = writeln!(s, "o {name}");
        }
        if let Some(m) = &e.samples {
            let counts: Vec<String> = m.iter().map(ToString::to_string).collect();
            let _ = writeln!(s, "# prespline samples {}", counts.join(" "));
        }
        if let Some(c) = e.color {
            let _ = writeln!(s, "# prespline color {}", join(&c));
        }
        for (p, &w) in e.points.iter().zip(&e.weights) {
            let _ = write!(s, "v {}", join(&p.to_array()));
            if e.rational {
                let _ = write!(s, " {}", number(w));
            }
            s.push('\n');
        }
        let _ = writeln!(
            s,
            "cstype {}{}",
            if e.rational { "rat " } else { "" },
            e.basis.word()
        );
        let degrees: Vec<String> = e.dirs.iter().map(|d| d.degree.to_string()).collect();
        let _ = writeln!(s, "deg {}", degrees.join(" "));
        let mut words: Vec<String> = vec![e.keyword().to_string()];
        for d in &e.dirs {
            words.extend(d.range.iter().map(|&x| number(x)));
        }
        words.extend((next..next + e.points.len()).map(|i| i.to_string()));
        next += e.points.len();
        statement(&mut s, &words);
        for (d, uv) in e.dirs.iter().zip(["u", "v"]) {
            let mut words = vec!["parm".to_string(), uv.to_string()];
            words.extend(d.parm.iter().map(|&x| number(x)));
            statement(&mut s, &words);
        }
        s.push_str("end\n");
    }
    s
}

/// One statement, wrapped with `\` continuation lines.
fn statement(s: &mut String, words: &[String]) {
    let mut width = 0;
    for (i, w) in words.iter().enumerate() {
        if i > 0 {
            if width + 1 + w.len() > WIDTH {
                s.push_str(" \\\n   ");
                width = 3;
            }
            s.push(' ');
            width += 1;
        }
        s.push_str(w);
        width += w.len();
    }
    s.push('\n');
}

fn join(v: &[f64]) -> String {
    v.iter().map(|&x| number(x)).collect::<Vec<_>>().join(" ")
}

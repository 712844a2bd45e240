//! OBJ text → statements: `#` comments removed, `\` continuation lines joined, every token
//! tagged with the physical line it came from so messages can point at it.

use super::ObjError;

/// A whitespace-separated word and the (1-based) line it is on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Token<'a> {
    pub text: &'a str,
    pub line: usize,
}

/// One logical statement: a keyword and its arguments.
#[derive(Debug, Clone, PartialEq)]
pub struct Statement<'a> {
    /// Line of the keyword.
    pub line: usize,
    pub keyword: &'a str,
    pub args: Vec<Token<'a>>,
    /// A `# prespline KEY …` comment (prespline's own extension, invisible to other readers);
    /// `keyword` is then KEY.
    pub extension: bool,
}

/// Splits OBJ text into statements; judging them is the reader's job.
pub fn statements(text: &str) -> Vec<Statement<'_>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out = Vec::new();
    let mut pending: Option<Vec<Token>> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let trimmed = raw.trim();
        if pending.is_none()
            && let Some(words) = extension(trimmed)
        {
            let mut words = words.split_whitespace();
            if let Some(keyword) = words.next() {
                out.push(Statement {
                    line,
                    keyword,
                    args: words.map(|text| Token { text, line }).collect(),
                    extension: true,
                });
            }
            continue;
        }
        let code = trimmed.split('#').next().unwrap_or("").trim_end();
        let (code, continued) = match code.strip_suffix('\\') {
            Some(c) => (c, true),
            None => (code, false),
        };
        let tokens = pending.get_or_insert_with(Vec::new);
        tokens.extend(code.split_whitespace().map(|text| Token { text, line }));
        if !continued {
            flush(&mut pending, &mut out);
        }
    }
    flush(&mut pending, &mut out);
    out
}

/// The words after `# prespline` (or `#prespline`), if this comment is one of ours.
fn extension(line: &str) -> Option<&str> {
    let rest = line.strip_prefix('#')?.trim_start();
    let rest = rest.strip_prefix("prespline")?;
    (rest.is_empty() || rest.starts_with(char::is_whitespace)).then_some(rest)
}

fn flush<'a>(pending: &mut Option<Vec<Token<'a>>>, out: &mut Vec<Statement<'a>>) {
    if let Some(tokens) = pending.take()
        && let Some((first, rest)) = tokens.split_first()
    {
        out.push(Statement {
            line: first.line,
            keyword: first.text,
            args: rest.to_vec(),
            extension: false,
        });
    }
}

/// Decodes file bytes, naming the first line that is not UTF-8.
pub fn decode(bytes: &[u8]) -> Result<&str, ObjError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        ObjError::new(line, "the line is not valid UTF-8 text")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuation_comments_and_lines() {
        let s = statements(
            "v 1 2 3 # a vertex\r\ncurv 0 1 \\\n 1 2 \\\n\n# x\nend\n# prespline samples 9\n",
        );
        assert_eq!(s.len(), 4);
        assert_eq!((s[0].keyword, s[0].args.len()), ("v", 3));
        assert_eq!(s[1].keyword, "curv");
        let lines: Vec<usize> = s[1].args.iter().map(|t| t.line).collect();
        assert_eq!(lines, [2, 2, 3, 3]);
        assert_eq!((s[2].keyword, s[2].line), ("end", 6));
        assert!(s[3].extension);
        assert_eq!((s[3].keyword, s[3].args[0].text), ("samples", "9"));
    }

    #[test]
    fn invalid_utf8_names_the_line() {
        let e = decode(b"v 1 2 3\nv 1 2 \xff\n").unwrap_err();
        assert_eq!(e.line, 2);
    }
}

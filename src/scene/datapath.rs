//! Blender RNA data paths, as F-curves name the property they animate and as
//! "Copy Full Data Path" gives them: `location`, `constraints["Follow Path"].offset`,
//! `splines[0].bezier_points[2].co`, `["my prop"]`, `nodes["Math"].inputs[1].default_value`.

#[derive(Debug, Clone, PartialEq)]
pub enum Token {
    /// An attribute: `.name`.
    Prop(String),
    /// A string subscript: `["name"]` (collection lookup by name, or ID property).
    Key(String),
    /// An integer subscript: `[3]`.
    Index(usize),
}

/// Parses a data path into tokens. Errors name the offending path.
pub fn parse(path: &str) -> Result<Vec<Token>, String> {
    let bad = |why: &str| format!("data path {path:?}: {why}");
    let b = path.as_bytes();
    let mut i = 0;
    let mut out = Vec::new();
    while i < b.len() {
        match b[i] {
            b'.' if !out.is_empty() => i += 1,
            b'[' => {
                i += 1;
                if i < b.len() && (b[i] == b'"' || b[i] == b'\'') {
                    let quote = b[i];
                    i += 1;
                    let mut s = Vec::new();
                    loop {
                        if i >= b.len() {
                            return Err(bad("unterminated string"));
                        }
                        match b[i] {
                            b'\\' if i + 1 < b.len() => {
                                s.push(b[i + 1]);
                                i += 2;
                            }
                            c if c == quote => {
                                i += 1;
                                break;
                            }
                            c => {
                                s.push(c);
                                i += 1;
                            }
                        }
                    }
                    if i >= b.len() || b[i] != b']' {
                        return Err(bad("expected ']' after a string subscript"));
                    }
                    i += 1;
                    out.push(Token::Key(
                        String::from_utf8(s).map_err(|_| bad("not UTF-8"))?,
                    ));
                } else {
                    let start = i;
                    while i < b.len() && b[i].is_ascii_digit() {
                        i += 1;
                    }
                    if start == i || i >= b.len() || b[i] != b']' {
                        return Err(bad("expected an integer or a quoted name in []"));
                    }
                    out.push(Token::Index(
                        path[start..i].parse().map_err(|_| bad("index too large"))?,
                    ));
                    i += 1;
                }
            }
            c if c == b'_' || c.is_ascii_alphanumeric() => {
                let start = i;
                while i < b.len() && (b[i] == b'_' || b[i].is_ascii_alphanumeric()) {
                    i += 1;
                }
                out.push(Token::Prop(path[start..i].to_string()));
            }
            _ => return Err(bad("unexpected character")),
        }
    }
    if out.is_empty() {
        return Err(bad("empty"));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use Token::*;

    #[test]
    fn parses_common_paths() {
        assert_eq!(parse("location").unwrap(), vec![Prop("location".into())]);
        assert_eq!(
            parse("constraints[\"Follow \\\"Path\\\"\"].offset").unwrap(),
            vec![
                Prop("constraints".into()),
                Key("Follow \"Path\"".into()),
                Prop("offset".into())
            ]
        );
        assert_eq!(
            parse("splines[0].bezier_points[12].co").unwrap(),
            vec![
                Prop("splines".into()),
                Index(0),
                Prop("bezier_points".into()),
                Index(12),
                Prop("co".into())
            ]
        );
        assert_eq!(parse("[\"prop\"]").unwrap(), vec![Key("prop".into())]);
        assert!(parse("a[").is_err());
        assert!(parse("").is_err());
    }
}

//! What the Import nodes (STL, PLY, OBJ) share: the Path input turned into the bytes of
//! the export's copy of that file (`Scene::import_file`), and the float and integer
//! prefixes Blender's importers parse text with.

use super::super::error::GeometryError;
use super::super::eval::NodeCtx;

/// Largest file an Import node reads (the exporter copies no larger one).
const MAX_IMPORT_BYTES: u64 = 1 << 30;

/// The file the node's Path names: None when Blender's node gives empty geometry (an
/// empty path: no output; no file there when exported: an error on the node, which is
/// printed as a warning here). A path the export has no copy of is an error naming it.
pub fn read_path(ctx: &NodeCtx) -> Result<Option<(String, Vec<u8>)>, GeometryError> {
    let path = ctx.string("Path")?;
    if path.is_empty() {
        return Ok(None);
    }
    let scene = ctx.session().scene;
    match scene.import_file(&path).map_err(|e| ctx.err(e))? {
        None => {
            eprintln!(
                "warning: {}",
                ctx.err(format!(
                    "file {path:?} did not exist when exported: empty geometry, as Blender's node gives"
                ))
            );
            Ok(None)
        }
        Some(file) => {
            let bytes = crate::scene::file::read_regular(&file, MAX_IMPORT_BYTES)
                .map_err(|e| ctx.err(format!("file {path:?}: {e}")))?;
            Ok(Some((path, bytes)))
        }
    }
}

/// Blender's `<= ' '` whitespace test (control characters count).
pub fn is_space(b: u8) -> bool {
    b <= b' '
}

/// The first byte at or after `p` in `s` that is not whitespace (`s.len()` if none).
pub fn skip_space(s: &[u8], mut p: usize) -> usize {
    while p < s.len() && is_space(s[p]) {
        p += 1;
    }
    p
}

/// The first whitespace byte at or after `p` in `s` (`s.len()` if none).
pub fn skip_word(s: &[u8], mut p: usize) -> usize {
    while p < s.len() && !is_space(s[p]) {
        p += 1;
    }
    p
}

/// The integer after the whitespace at `p` (`parse_int` with fallback 0); `p` moves past it.
pub fn next_int(s: &[u8], p: &mut usize) -> i32 {
    *p = skip_space(s, *p);
    let (v, n) = parse_int(&s[*p..], 0);
    *p += n;
    v
}

/// The length of the longest prefix of `s` that `fast_float::from_chars` reads as a
/// float (sign, digits with an optional point, exponent; or inf/infinity/nan), 0 if none.
pub fn float_prefix(s: &[u8]) -> usize {
    let mut i = 0;
    if i < s.len() && s[i] == b'-' {
        i += 1;
    }
    let lower =
        |k: usize, w: &[u8]| s.len() >= k + w.len() && s[k..k + w.len()].eq_ignore_ascii_case(w);
    if lower(i, b"infinity") {
        return i + 8;
    }
    if lower(i, b"inf") || lower(i, b"nan") {
        return i + 3;
    }
    let digits = |mut k: usize| {
        while k < s.len() && s[k].is_ascii_digit() {
            k += 1;
        }
        k
    };
    let int_end = digits(i);
    let mut end = int_end;
    let mut any = int_end > i;
    if end < s.len() && s[end] == b'.' {
        let frac_end = digits(end + 1);
        any |= frac_end > end + 1;
        end = frac_end;
    }
    if !any {
        return 0;
    }
    if end < s.len() && (s[end] == b'e' || s[end] == b'E') {
        let mut k = end + 1;
        if k < s.len() && (s[k] == b'+' || s[k] == b'-') {
            k += 1;
        }
        let exp_end = digits(k);
        if exp_end > k {
            end = exp_end;
        }
    }
    end
}

/// Parses a float at the start of `s` as Blender's importers do (a leading '+' skipped,
/// `fast_float`, `fallback` when nothing parses or the value is out of float range);
/// returns the value and the bytes consumed.
pub fn parse_float(s: &[u8], fallback: f32) -> (f32, usize) {
    let skip = usize::from(s.first() == Some(&b'+'));
    let t = &s[skip..];
    let n = float_prefix(t);
    if n == 0 {
        return (fallback, skip);
    }
    let text = std::str::from_utf8(&t[..n]).unwrap_or("0");
    (float_of_text(text).unwrap_or(fallback), skip + n)
}

/// A float's text read as `fast_float::from_chars` reads it: None when it does not parse
/// or when a finite-looking number overflows to infinity ("inf" and "nan" stay).
pub fn float_of_text(text: &str) -> Option<f32> {
    let v: f32 = text.parse().ok()?;
    let finite_text = !text
        .trim_start_matches('-')
        .bytes()
        .next()
        .is_some_and(|b| b.is_ascii_alphabetic());
    if v.is_infinite() && finite_text {
        return None;
    }
    Some(v)
}

/// Parses an integer as `std::from_chars` does after Blender skips a '+': optional '-',
/// decimal digits; `fallback` when none or out of `i32` range. Returns the bytes consumed.
pub fn parse_int(s: &[u8], fallback: i32) -> (i32, usize) {
    let skip = usize::from(s.first() == Some(&b'+'));
    let t = &s[skip..];
    let mut i = usize::from(t.first() == Some(&b'-'));
    let start = i;
    while i < t.len() && t[i].is_ascii_digit() {
        i += 1;
    }
    if i == start {
        return (fallback, skip);
    }
    let text = std::str::from_utf8(&t[..i]).unwrap_or("0");
    (text.parse().unwrap_or(fallback), skip + i)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_parse_as_fast_float_does() {
        assert_eq!(parse_float(b"1.5e2 x", 0.0), (150.0, 5));
        assert_eq!(parse_float(b"+.25", 0.0), (0.25, 4));
        assert_eq!(parse_float(b"-3.", 0.0), (-3.0, 3));
        assert_eq!(parse_float(b"abc", 7.0), (7.0, 0));
        assert_eq!(parse_float(b"1e", 0.0), (1.0, 1));
        assert_eq!(parse_float(b"1e99", 0.0), (0.0, 4));
        assert_eq!(parse_int(b"-12/3", 0), (-12, 3));
        assert_eq!(parse_int(b"/3", 5), (5, 0));
    }
}

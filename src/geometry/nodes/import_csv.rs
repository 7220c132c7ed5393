//! Import CSV (Blender 4.5, `node_geo_import_csv.cc` reading with `io/csv` and
//! `BLI_csv_parse`): a point cloud with one point per data row, every position zero,
//! and one point attribute per header column whose every value parses: 32-bit integer
//! when all are integers, float when some have a fraction or exponent; a column with an
//! empty, missing or non-numeric value, an empty name, or a name Blender keeps from
//! procedural access (`.`-prefixed) is left out. Fields are split at ',' with '"'
//! quotes ('""' and '\"' inside them stand for a quote); '\r' is ignored outside quotes.
//! An empty file or an unclosed quote is Blender's import error: an error naming the
//! node and the file here.

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::pointcloud::PointCloud;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::value::SocketValue;
use super::import_file::{float_of_text, float_prefix, read_path};

const DELIMITER: u8 = b',';
const QUOTE: u8 = b'"';

pub fn import_csv(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let set = match read_path(ctx)? {
        None => GeometrySet::default(),
        Some((path, bytes)) => {
            let pc = read_csv(&bytes).map_err(|e| ctx.err(format!("CSV file {path:?}: {e}")))?;
            GeometrySet::from_points(pc)
        }
    };
    Ok(outputs([("Point Cloud", SocketValue::Geometry(set))]))
}

/// The point cloud Blender's CSV importer makes of `bytes`, or its error.
pub fn read_csv(bytes: &[u8]) -> Result<PointCloud, String> {
    if bytes.is_empty() {
        return Err("the file is empty (Blender: \"CSV Import: empty file\")".into());
    }
    let mut header = Vec::new();
    let data_start = parse_record(bytes, 0, &mut header).ok_or_else(unclosed)?;
    // Records as ranges into `fields`; one pass, no per-record allocation.
    let mut fields: Vec<(usize, usize)> = Vec::new();
    let mut offsets = vec![0usize];
    let mut start = data_start;
    while start < bytes.len() {
        start = parse_record(bytes, start, &mut fields).ok_or_else(unclosed)?;
        offsets.push(fields.len());
    }
    let rows = offsets.len() - 1;
    let mut pc = PointCloud {
        positions: vec![[0.0; 3]; rows],
        ..PointCloud::default()
    };
    for (c, &(a, b)) in header.iter().enumerate() {
        let name = unescape(&bytes[a..b]);
        if name.is_empty() || name.starts_with('.') {
            continue;
        }
        let field = |r: usize| -> &[u8] {
            let k = offsets[r] + c;
            if k < offsets[r + 1] {
                let (a, b) = fields[k];
                &bytes[a..b]
            } else {
                &[]
            }
        };
        let Some(data) = parse_column(rows, field) else {
            continue;
        };
        // Blender's add fails for a repeated name (the first column stays) and for the
        // point cloud's built-in attributes of another type: position (a vector) and
        // radius (a float; an integer column of that name is left out).
        let builtin_clash =
            name == "position" || (name == "radius" && !matches!(data, Array::Float(_)));
        let id = AttrId::Named(name);
        if pc.attributes.get(&id).is_some() || builtin_clash {
            continue;
        }
        pc.attributes.set(id, Domain::Point, data);
    }
    Ok(pc)
}

fn unclosed() -> String {
    "a quoted field is not closed (Blender: \"CSV import: failed to parse file\")".into()
}

/// The column as integers, else as floats; None when a value is neither.
fn parse_column<'b>(rows: usize, field: impl Fn(usize) -> &'b [u8]) -> Option<Array> {
    let mut ints = Vec::with_capacity(rows);
    let mut as_float = false;
    for r in 0..rows {
        match parse_int(field(r)) {
            Int::Value(v) => ints.push(v),
            Int::Float => {
                as_float = true;
                break;
            }
            Int::Invalid => return None,
        }
    }
    if !as_float {
        return Some(Array::Int(ints));
    }
    let mut floats = Vec::with_capacity(rows);
    for r in 0..rows {
        floats.push(parse_float(field(r))?);
    }
    Some(Array::Float(floats))
}

enum Int {
    Value(i32),
    Float,
    Invalid,
}

/// Leading spaces and '+' skipped.
fn trim_start(s: &[u8]) -> &[u8] {
    let k = s.iter().take_while(|&&c| c == b' ' || c == b'+').count();
    &s[k..]
}

fn only_spaces(s: &[u8]) -> bool {
    s.iter().all(|&c| c == b' ')
}

/// `std::from_chars` for int: optional '-', digits, in range; a '.' right after the
/// digits makes the column a float column; trailing spaces are allowed.
fn parse_int(s: &[u8]) -> Int {
    let s = trim_start(s);
    let neg = usize::from(s.first() == Some(&b'-'));
    let n = s[neg..].iter().take_while(|c| c.is_ascii_digit()).count();
    if n == 0 {
        return Int::Invalid;
    }
    let end = neg + n;
    let Ok(v) = std::str::from_utf8(&s[..end]).unwrap_or("x").parse::<i32>() else {
        return Int::Invalid;
    };
    match s.get(end) {
        None => Int::Value(v),
        Some(b'.') => Int::Float,
        Some(_) if only_spaces(&s[end..]) => Int::Value(v),
        Some(_) => Int::Invalid,
    }
}

/// `fast_float::from_chars` for float (out-of-range values are an error there), then
/// only spaces.
fn parse_float(s: &[u8]) -> Option<f32> {
    let s = trim_start(s);
    let n = float_prefix(s);
    if n == 0 || !only_spaces(&s[n..]) {
        return None;
    }
    float_of_text(std::str::from_utf8(&s[..n]).ok()?)
}

/// `'""'` and `'\"'` as one quote; the name as text (invalid UTF-8 replaced, as an
/// attribute name must be text).
fn unescape(s: &[u8]) -> String {
    let mut out = Vec::with_capacity(s.len());
    let mut i = 0;
    while i < s.len() {
        if (s[i] == QUOTE || s[i] == b'\\') && i + 1 < s.len() && s[i + 1] == QUOTE {
            out.push(QUOTE);
            i += 2;
            continue;
        }
        out.push(s[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `parse_record_fields`: the fields of the record at `start` appended to `out` as
/// byte ranges; the start of the next record, or None for an unclosed quote.
fn parse_record(b: &[u8], start: usize, out: &mut Vec<(usize, usize)>) -> Option<usize> {
    // A delimiter that ends the line or the file leaves an empty last field.
    let trailing = |i: usize, out: &mut Vec<(usize, usize)>| {
        if i == b.len() || (i < b.len() && (b[i] == b'\n' || b[i] == b'\r')) {
            out.push((i, i));
        }
    };
    let mut i = start;
    while i < b.len() {
        let c = b[i];
        if c == b'\n' {
            return Some(i + 1);
        }
        if c == b'\r' {
            i += 1;
            continue;
        }
        if c == DELIMITER {
            out.push((i, i));
            i += 1;
            trailing(i, out);
            continue;
        }
        if c == QUOTE {
            i += 1;
            let mut e = i;
            loop {
                if e >= b.len() {
                    return None;
                }
                if (b[e] == QUOTE || b[e] == b'\\') && e + 1 < b.len() && b[e + 1] == QUOTE {
                    e += 2;
                    continue;
                }
                if b[e] == QUOTE {
                    break;
                }
                e += 1;
            }
            out.push((i, e));
            i = e;
            // Up to the delimiter or line end; anything after the closing quote is dropped.
            while i < b.len() {
                match b[i] {
                    QUOTE => i += 1,
                    DELIMITER => {
                        i += 1;
                        trailing(i, out);
                        break;
                    }
                    b'\n' | b'\r' => break,
                    _ => i += 1,
                }
            }
            continue;
        }
        let mut e = i;
        while e < b.len() && !matches!(b[e], DELIMITER | b'\n' | b'\r') {
            e += 1;
        }
        out.push((i, e));
        i = e;
        if i < b.len() && b[i] == DELIMITER {
            i += 1;
            trailing(i, out);
        }
    }
    Some(b.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attr(pc: &PointCloud, name: &str) -> Option<Array> {
        pc.attributes
            .get(&AttrId::Named(name.into()))
            .map(|a| a.data.clone())
    }

    #[test]
    fn columns_are_typed_as_blender_types_them() {
        let pc = read_csv(b"a,b,c,,.d,e\n1, 2.5,x,1,1,+3 \r\n-4,3,y,2,2,\"7\"\n").unwrap();
        assert_eq!(pc.len(), 2);
        assert_eq!(attr(&pc, "a"), Some(Array::Int(vec![1, -4])));
        assert_eq!(attr(&pc, "b"), Some(Array::Float(vec![2.5, 3.0])));
        assert_eq!(attr(&pc, "c"), None);
        assert_eq!(attr(&pc, ".d"), None);
        assert_eq!(attr(&pc, "e"), Some(Array::Int(vec![3, 7])));
        assert!(read_csv(b"").is_err());
        assert!(read_csv(b"a\n\"1\n").is_err());
        // A short row leaves its column out.
        let pc = read_csv(b"a,b\n1,2\n3\n").unwrap();
        assert_eq!(attr(&pc, "a"), Some(Array::Int(vec![1, 3])));
        assert_eq!(attr(&pc, "b"), None);
        // Names as Blender 4.5 keeps them (checked with bpy on the point cloud): an integer
        // radius and a position column are left out, other names kept.
        let pc = read_csv(b"radius,__x,x y,position,material_index\n1,2,3,4,5\n").unwrap();
        assert_eq!(attr(&pc, "radius"), None);
        assert_eq!(attr(&pc, "position"), None);
        for n in ["__x", "x y", "material_index"] {
            assert!(attr(&pc, n).is_some(), "{n}");
        }
        let pc = read_csv(b"radius\n0.5\n").unwrap();
        assert_eq!(attr(&pc, "radius"), Some(Array::Float(vec![0.5])));
    }
}

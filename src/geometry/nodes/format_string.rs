//! Format String (Blender 4.5, `node_fn_format_string.cc`): the Format text with each
//! `{...}` replaced by one of the node's items (float, integer or string inputs), as
//! Blender does it: `{}` takes the next item, `{name}` or `{0}` a named or numbered one;
//! after a colon either the `fmt` library's specification (fill and align, sign, `0`,
//! width, precision, type; width and precision may be `{item}`), restricted to what
//! Blender's pattern for the item's type accepts, or a path-template `#` pattern
//! (`{:##.###}`). What Blender reports as a node error (an unknown item, a bad pattern,
//! an unclosed brace) is an error naming the node; Blender then outputs an empty string.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::DataType;
use super::super::value::SocketValue;

/// Largest width or precision formatted: Blender would build the string, but a pattern
/// asking for more is taken as a mistake rather than a reason to allocate gigabytes.
const MAX_WIDTH: u64 = 1 << 16;

#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Float(f32),
    Int(i32),
    Str(String),
}

pub fn format_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let format = ctx.string("Format")?;
    let mut names = Vec::new();
    let mut items = Vec::new();
    for s in &ctx.node().inputs {
        if s.identifier == "Format" || s.identifier == "__extend__" {
            continue;
        }
        // One string is made: an item fed by a field (Blender 4.5 has no string fields
        // and its node gives no text then) is refused naming the item.
        let single = |ty: DataType| match ctx.field(&s.identifier, ty)? {
            Field::Constant(v) => Ok(v),
            _ => Err(ctx.err(format!(
                "item {:?} is fed by a field; Format String makes a single string",
                s.name
            ))),
        };
        let item = match s.kind.as_str() {
            "VALUE" => Item::Float(single(DataType::Float)?.as_float()),
            "INT" => Item::Int(single(DataType::Int)?.as_int()),
            "STRING" => Item::Str(ctx.string(&s.identifier)?),
            other => {
                return Err(ctx.err(format!(
                    "item {:?} is a {other} socket, which Format String cannot format",
                    s.name
                )))
            }
        };
        names.push(s.name.clone());
        items.push(item);
    }
    let s = format_items(&format, &items, &names).map_err(|e| ctx.err(e))?;
    Ok(outputs([("String", SocketValue::String(s))]))
}

/// Blender's `format_strings` for single values: the formatted text or the message
/// Blender shows on the node.
pub fn format_items(format: &str, items: &[Item], names: &[String]) -> Result<String, String> {
    let b = format.as_bytes();
    let mut out: Vec<u8> = Vec::new();
    let mut lookup = Lookup {
        items,
        names,
        next_auto: 0,
        explicit_used: false,
    };
    let mut i = 0;
    while i < b.len() {
        // Literal text; doubled braces stand for one.
        while i < b.len() {
            let c = b[i];
            if c == b'{' || c == b'}' {
                if i + 1 < b.len() && b[i + 1] == c {
                    out.push(c);
                    i += 2;
                    continue;
                }
                break;
            }
            out.push(c);
            i += 1;
        }
        if i == b.len() {
            break;
        }
        // The replacement field: up to the brace that balances the opening one (a lone
        // '}' opens one too, as in Blender).
        let mut depth = 1;
        let mut end = None;
        for (k, &c) in b[i + 1..].iter().enumerate() {
            if c == b'{' {
                depth += 1;
            } else if c == b'}' {
                depth -= 1;
            }
            if depth == 0 {
                end = Some(i + 1 + k + 1);
                break;
            }
        }
        let Some(end) = end else {
            return Err(format!(
                "Format specifier is not closed: \"{}\"",
                String::from_utf8_lossy(&b[i..])
            ));
        };
        let outer = &format[i..end];
        let inner = &outer[1..outer.len() - 1];
        let (identifier, pattern) = match inner.find(':') {
            Some(c) => (&inner[..c], &inner[c + 1..]),
            None => (inner, ""),
        };
        let item = &items[lookup.find(identifier)?];
        if pattern.is_empty() {
            plain(item, &mut out);
        } else if pattern.contains('#') {
            let s = hash_pattern(pattern, item)?;
            out.extend_from_slice(s.as_bytes());
        } else {
            let s = python_pattern(pattern, outer, item, &mut lookup)?;
            out.extend_from_slice(s.as_bytes());
        }
        i = end;
    }
    // Only whole UTF-8 sequences are copied or written.
    String::from_utf8(out).map_err(|_| "the formatted text is not valid UTF-8".to_string())
}

struct Lookup<'a> {
    items: &'a [Item],
    names: &'a [String],
    next_auto: usize,
    explicit_used: bool,
}

impl Lookup<'_> {
    /// `FormatInputsLookup::find_next_input_index`, with Blender's messages.
    fn find(&mut self, identifier: &str) -> Result<usize, String> {
        if identifier.is_empty() {
            if self.explicit_used {
                return Err("Empty identifier can't be used when explicit identifier was used before. For example, \"{} {x}\" is ok but \"{x} {}\" is not.".into());
            }
            if self.next_auto == self.items.len() {
                return Err("Format uses more inputs than provided.".into());
            }
            self.next_auto += 1;
            return Ok(self.next_auto - 1);
        }
        self.explicit_used = true;
        let b = identifier.as_bytes();
        if b[0].is_ascii_digit() {
            let n = b.iter().take_while(|c| c.is_ascii_digit()).count();
            let Ok(index) = identifier[..n].parse::<i64>() else {
                return Err(format!("Invalid identifier: \"{identifier}\""));
            };
            if n < b.len() {
                return Err(format!(
                    "An input name can't start with a digit: \"{identifier}\""
                ));
            }
            if index as u64 >= self.items.len() as u64 {
                if self.items.is_empty() {
                    return Err("There are no inputs.".into());
                }
                return Err(format!("Input with index {identifier} does not exist. Currently, the maximum possible index is {}. Did you mean to use {{:{identifier}}}?", self.items.len() - 1));
            }
            return Ok(index as usize);
        }
        self.names
            .iter()
            .position(|n| n == identifier)
            .ok_or_else(|| format!("Input does not exist: \"{identifier}\""))
    }
}

/// `{}` and `{name}`: `fmt`'s default form; whole floats get Python's ".0".
fn plain(item: &Item, out: &mut Vec<u8>) {
    match item {
        Item::Float(v) => {
            let s = shortest(*v, false);
            out.extend_from_slice(s.as_bytes());
            if s.bytes().all(|c| c == b'-' || c.is_ascii_digit()) {
                out.extend_from_slice(b".0");
            }
        }
        Item::Int(v) => out.extend_from_slice(v.to_string().as_bytes()),
        Item::Str(s) => out.extend_from_slice(s.as_bytes()),
    }
}

// ------------------------------------------------------------ path-template patterns

/// A `#` pattern (`BKE_path_template_format_int/float`): all `#` is a zero-padded
/// integer of that many digits (floats rounded half away from zero); `#`s, one dot and
/// at least one `#` after it a fixed-point number, zero-padded to the whole width when
/// there are `#`s before the dot.
fn hash_pattern(pattern: &str, item: &Item) -> Result<String, String> {
    let bad = || format!("Invalid format specifier: \"{pattern}\"");
    if let Item::Str(_) = item {
        return Err(format!(
            "Invalid format specifier for string: \"{pattern}\""
        ));
    }
    let int_digits;
    let mut frac_digits = None;
    if pattern.bytes().all(|c| c == b'#') {
        int_digits = pattern.len();
    } else {
        let dots = pattern.bytes().filter(|&c| c == b'.').count();
        if dots != 1 || !pattern.bytes().all(|c| c == b'#' || c == b'.') {
            return Err(bad());
        }
        let (l, r) = pattern.split_once('.').unwrap();
        if r.is_empty() {
            return Err(bad());
        }
        int_digits = l.len();
        frac_digits = Some(r.len());
    }
    let zero_int = |v: i64, width: usize| {
        let mut s = String::new();
        if v < 0 {
            s.push('-');
        }
        let digits = v.unsigned_abs().to_string();
        for _ in digits.len() + s.len()..width {
            s.push('0');
        }
        s + &digits
    };
    Ok(match (item, frac_digits) {
        (Item::Int(v), None) => zero_int(*v as i64, int_digits),
        (Item::Int(v), Some(f)) => {
            format!("{}.{}", zero_int(*v as i64, int_digits), "0".repeat(f))
        }
        (Item::Float(v), None) => {
            let r = (*v as f64).round();
            if !r.is_finite() || r.abs() >= 9.2e18 {
                return Err(format!(
                    "{v} cannot be formatted as an integer by \"{pattern}\""
                ));
            }
            zero_int(r as i64, int_digits)
        }
        (Item::Float(v), Some(f)) => {
            let body = fixed_digits(*v, f);
            let width = if int_digits > 0 {
                int_digits + f + 1
            } else {
                0
            };
            let spec = Spec {
                zero: true,
                width: width as u64,
                ..Spec::default()
            };
            pad_number(&spec, sign_of(*v, &spec), &body)
        }
        (Item::Str(_), _) => unreachable!(),
    })
}

// ------------------------------------------------------------ fmt specifications

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Float,
    Int,
    Str,
}

impl Kind {
    fn of(item: &Item) -> Kind {
        match item {
            Item::Float(_) => Kind::Float,
            Item::Int(_) => Kind::Int,
            Item::Str(_) => Kind::Str,
        }
    }
    /// The text of Blender's regular expression for the type: its characters decide
    /// which one the "unsupported character" message names.
    fn pattern_text(self) -> &'static str {
        match self {
            Kind::Float => {
                r"^([^{}]?[<>^])?[+\- ]?0?(\d+|(\{.*\}))?(\.(\d+|(\{.*\})))?[aAeEfFgG]?$"
            }
            Kind::Int => r"^([^{}]?[<>^])?[+\- ]?0?(\d+|(\{.*\}))?[bBcdoxX]?$",
            Kind::Str => r"^([^{}]?[<>^])?(\d+|(\{.*\}))?(\.(\d+|(\{.*\})))?[s\?]?$",
        }
    }
    fn types(self) -> &'static [u8] {
        match self {
            Kind::Float => b"aAeEfFgG",
            Kind::Int => b"bBcdoxX",
            Kind::Str => b"s?",
        }
    }
}

/// A width or precision: digits, or `{item}` (the text between the braces).
#[derive(Clone, Debug, PartialEq)]
enum Count<'a> {
    Digits(&'a str),
    Item(&'a str),
}

#[derive(Debug, Default, PartialEq)]
struct Parsed<'a> {
    fill: Option<u8>,
    align: Option<u8>,
    sign: Option<u8>,
    zero: bool,
    width: Option<Count<'a>>,
    precision: Option<Count<'a>>,
    ty: Option<u8>,
}

/// Matches `p` against Blender's pattern for `kind` the way `std::regex` (ECMAScript,
/// greedy with backtracking) does.
fn match_pattern(p: &str, kind: Kind) -> Option<Parsed<'_>> {
    let b = p.as_bytes();
    let is_align = |c: u8| matches!(c, b'<' | b'>' | b'^');
    // Fill and align first as two characters, then as the align alone, then absent.
    let mut starts: Vec<(Option<u8>, Option<u8>, usize)> = Vec::new();
    if b.len() >= 2 && b[0] != b'{' && b[0] != b'}' && is_align(b[1]) {
        starts.push((Some(b[0]), Some(b[1]), 2));
    }
    if !b.is_empty() && is_align(b[0]) {
        starts.push((None, Some(b[0]), 1));
    }
    starts.push((None, None, 0));
    for (fill, align, mut i) in starts {
        let mut sign = None;
        let mut zero = false;
        if kind != Kind::Str {
            if i < b.len() && matches!(b[i], b'+' | b'-' | b' ') {
                sign = Some(b[i]);
                i += 1;
            }
            if i < b.len() && b[i] == b'0' {
                zero = true;
                i += 1;
            }
        }
        for (width, i) in counts(p, i) {
            let tails: Vec<(Option<Count>, usize)> = if kind == Kind::Int {
                vec![(None, i)]
            } else if i < b.len() && b[i] == b'.' {
                let mut t: Vec<_> = counts(p, i + 1)
                    .into_iter()
                    .filter_map(|(c, k)| c.map(|c| (Some(c), k)))
                    .collect();
                t.push((None, i));
                t
            } else {
                vec![(None, i)]
            };
            for (precision, k) in tails {
                let rest = &b[k..];
                let ty = match rest {
                    [] => None,
                    [c] if kind.types().contains(c) => Some(*c),
                    _ => continue,
                };
                return Some(Parsed {
                    fill,
                    align,
                    sign,
                    zero,
                    width,
                    precision,
                    ty,
                });
            }
        }
    }
    None
}

/// The ways `(\d+|(\{.*\}))?` can match at `i`, greediest first.
fn counts(p: &str, i: usize) -> Vec<(Option<Count<'_>>, usize)> {
    let b = p.as_bytes();
    let mut out = Vec::new();
    if i < b.len() && b[i].is_ascii_digit() {
        let n = b[i..].iter().take_while(|c| c.is_ascii_digit()).count();
        out.push((Some(Count::Digits(&p[i..i + n])), i + n));
    } else if i < b.len() && b[i] == b'{' {
        // `.` does not match line terminators.
        let stop = b[i + 1..]
            .iter()
            .position(|&c| c == b'\n' || c == b'\r')
            .map_or(b.len(), |k| i + 1 + k);
        for k in (i + 1..stop).rev() {
            if b[k] == b'}' {
                out.push((Some(Count::Item(&p[i + 1..k])), k + 1));
            }
        }
    }
    out.push((None, i));
    out
}

/// The resolved specification `fmt` formats with.
#[derive(Default)]
struct Spec {
    fill: Option<u8>,
    align: Option<u8>,
    sign: Option<u8>,
    zero: bool,
    width: u64,
    precision: Option<u64>,
    ty: Option<u8>,
}

fn python_pattern(
    pattern: &str,
    outer: &str,
    item: &Item,
    lookup: &mut Lookup,
) -> Result<String, String> {
    let kind = Kind::of(item);
    let Some(m) = match_pattern(pattern, kind) else {
        let text = kind.pattern_text();
        for c in pattern.bytes() {
            if !text.as_bytes().contains(&c) && (0x20..0x7f).contains(&c) && !c.is_ascii_digit() {
                return Err(format!(
                    "Format contains unsupported \"{}\" character: \"{outer}\"",
                    c as char
                ));
            }
        }
        return Err(format!("Invalid format: \"{outer}\""));
    };
    let mut resolve = |c: &Option<Count>, what: &str| -> Result<Option<u64>, String> {
        Ok(match c {
            None => None,
            Some(Count::Digits(d)) => Some(d.parse::<u64>().unwrap_or(u64::MAX)),
            Some(Count::Item(name)) => match &lookup.items[lookup.find(name)?] {
                Item::Int(v) => Some((*v).max(0) as u64),
                _ => {
                    return Err(format!(
                        "Only integer inputs can be used as dynamic {what}: \"{outer}\""
                    ))
                }
            },
        })
    };
    let width = resolve(&m.width, "width")?;
    let precision = resolve(&m.precision, "precision")?;
    for v in [width, precision].into_iter().flatten() {
        if v > MAX_WIDTH {
            return Err(format!(
                "width or precision {v} in \"{outer}\" is larger than blendsynth formats ({MAX_WIDTH})"
            ));
        }
    }
    let spec = Spec {
        fill: m.fill,
        align: m.align,
        sign: m.sign,
        zero: m.zero,
        width: width.unwrap_or(0),
        precision,
        ty: m.ty,
    };
    if let (Item::Int(v), Some(b'c')) = (item, spec.ty) {
        if v.unsigned_abs() & 0x80 != 0 {
            return Err(format!(
                "{v} in \"{outer}\" is not an ASCII character (Blender writes its low byte, which is not UTF-8 text)"
            ));
        }
    }
    Ok(match item {
        Item::Int(v) => format_int(*v, &spec),
        Item::Float(v) => format_float(*v, &spec),
        Item::Str(s) => format_str(s, &spec),
    })
}

/// `fmt`'s display width of text: East Asian wide and some emoji ranges count 2.
fn display_width(s: &str) -> u64 {
    s.chars()
        .map(|c| {
            let cp = c as u32;
            let wide = cp >= 0x1100
                && (cp <= 0x115f
                    || cp == 0x2329
                    || cp == 0x232a
                    || (0x2e80..=0xa4cf).contains(&cp) && cp != 0x303f
                    || (0xac00..=0xd7a3).contains(&cp)
                    || (0xf900..=0xfaff).contains(&cp)
                    || (0xfe10..=0xfe19).contains(&cp)
                    || (0xfe30..=0xfe6f).contains(&cp)
                    || (0xff00..=0xff60).contains(&cp)
                    || (0xffe0..=0xffe6).contains(&cp)
                    || (0x20000..=0x2fffd).contains(&cp)
                    || (0x30000..=0x3fffd).contains(&cp)
                    || (0x1f300..=0x1f64f).contains(&cp)
                    || (0x1f900..=0x1f9ff).contains(&cp));
            1 + u64::from(wide)
        })
        .sum()
}

/// Pads `body` to the width with the fill, where the alignment (or `default`) puts it.
fn pad(spec: &Spec, body: &str, default: u8) -> String {
    let w = display_width(body);
    if spec.width <= w {
        return body.to_string();
    }
    let n = (spec.width - w) as usize;
    let fill = spec.fill.unwrap_or(b' ') as char;
    let left = match spec.align.unwrap_or(default) {
        b'<' => 0,
        b'^' => n / 2,
        _ => n,
    };
    let mut s = String::with_capacity(body.len() + n);
    s.extend(std::iter::repeat_n(fill, left));
    s.push_str(body);
    s.extend(std::iter::repeat_n(fill, n - left));
    s
}

/// A number: sign (and prefix) then digits; `0` without an explicit alignment pads
/// with zeros between them (`fmt` ignores it when an alignment is given).
fn pad_number(spec: &Spec, sign: &str, digits: &str) -> String {
    if spec.zero && spec.align.is_none() {
        let len = (sign.len() + digits.len()) as u64;
        let zeros = spec.width.saturating_sub(len) as usize;
        return format!("{sign}{}{digits}", "0".repeat(zeros));
    }
    pad(spec, &format!("{sign}{digits}"), b'>')
}

fn sign_of(v: f32, spec: &Spec) -> &'static str {
    if v.is_sign_negative() {
        "-"
    } else {
        match spec.sign {
            Some(b'+') => "+",
            Some(b' ') => " ",
            _ => "",
        }
    }
}

fn format_int(v: i32, spec: &Spec) -> String {
    let a = v.unsigned_abs();
    if spec.ty == Some(b'c') {
        // A character: the value's low byte; sign options do not apply.
        let c = (a & 0xff) as u8 as char;
        if spec.zero && spec.align.is_none() {
            return pad_number(spec, "", &c.to_string());
        }
        return pad(spec, &c.to_string(), b'<');
    }
    let digits = match spec.ty {
        Some(b'x') => format!("{a:x}"),
        Some(b'X') => format!("{a:X}"),
        Some(b'o') => format!("{a:o}"),
        Some(b'b') | Some(b'B') => format!("{a:b}"),
        _ => a.to_string(),
    };
    let sign = if v < 0 {
        "-"
    } else {
        match spec.sign {
            Some(b'+') => "+",
            Some(b' ') => " ",
            _ => "",
        }
    };
    pad_number(spec, sign, &digits)
}

fn format_str(s: &str, spec: &Spec) -> String {
    let cut: &str = match spec.precision {
        Some(p) => match s.char_indices().nth(p as usize) {
            Some((k, _)) => &s[..k],
            None => s,
        },
        None => s,
    };
    let body = if spec.ty == Some(b'?') {
        debug_string(cut)
    } else {
        cut.to_string()
    };
    pad(spec, &body, b'<')
}

/// `fmt`'s `?` form: quoted, with `\n \r \t \" \\` and other ASCII control characters
/// escaped.
fn debug_string(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '\n' => o.push_str("\\n"),
            '\r' => o.push_str("\\r"),
            '\t' => o.push_str("\\t"),
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            c if (c as u32) < 0x20 || c as u32 == 0x7f => {
                o.push_str(&format!("\\x{:02x}", c as u32))
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

/// The significant digits and decimal exponent of `v` (finite, any sign) rounded to
/// `digits` significant digits, or shortest round-trip digits for None.
fn sci_digits(v: f32, digits: Option<u64>) -> (String, i32) {
    let s = match digits {
        None => format!("{:e}", v.abs()),
        Some(d) => format!("{:.*e}", d.saturating_sub(1) as usize, v.abs() as f64),
    };
    let (m, e) = s.split_once('e').unwrap();
    (m.replace('.', ""), e.parse().unwrap())
}

/// Digits laid out in `fmt`'s fixed form (`exp` is the first digit's power of ten).
fn fixed_layout(digits: &str, exp: i32) -> String {
    let n = digits.len() as i32;
    if exp >= n - 1 {
        format!("{digits}{}", "0".repeat((exp - (n - 1)) as usize))
    } else if exp >= 0 {
        let k = (exp + 1) as usize;
        format!("{}.{}", &digits[..k], &digits[k..])
    } else {
        format!("0.{}{digits}", "0".repeat((-exp - 1) as usize))
    }
}

fn exp_layout(digits: &str, exp: i32, e: char) -> String {
    let mut s = digits[..1].to_string();
    if digits.len() > 1 {
        s.push('.');
        s.push_str(&digits[1..]);
    }
    s.push(e);
    s.push(if exp < 0 { '-' } else { '+' });
    s.push_str(&format!("{:02}", exp.unsigned_abs()));
    s
}

/// `fmt`'s default float form: shortest digits, fixed for exponents -4..16, else
/// exponent form.
fn shortest(v: f32, upper: bool) -> String {
    if !v.is_finite() {
        return format!(
            "{}{}",
            if v.is_sign_negative() { "-" } else { "" },
            nonfinite(v, upper)
        );
    }
    let (d, e) = sci_digits(v, None);
    let d = if v == 0.0 { "0".to_string() } else { d };
    let e = if v == 0.0 { 0 } else { e };
    let body = if (-4..16).contains(&e) {
        fixed_layout(&d, e)
    } else {
        exp_layout(&d, e, if upper { 'E' } else { 'e' })
    };
    format!("{}{body}", if v.is_sign_negative() { "-" } else { "" })
}

fn nonfinite(v: f32, upper: bool) -> &'static str {
    match (v.is_nan(), upper) {
        (true, false) => "nan",
        (true, true) => "NAN",
        (false, false) => "inf",
        (false, true) => "INF",
    }
}

/// Fixed-point text of |v| with `f` decimals: the exact value rounded half to even, as
/// both `fmt` and Rust print it.
fn fixed_digits(v: f32, f: usize) -> String {
    format!("{:.*}", f, (v as f64).abs())
}

fn format_float(v: f32, spec: &Spec) -> String {
    let upper = matches!(spec.ty, Some(b'A' | b'E' | b'F' | b'G'));
    let sign = sign_of(v, spec);
    if !v.is_finite() {
        // `fmt` pads infinities and NaN with spaces even under `0`.
        let s = Spec {
            zero: false,
            ..*spec
        };
        return pad_number(&s, sign, nonfinite(v, upper));
    }
    let e_char = if upper { 'E' } else { 'e' };
    let body = match (spec.ty, spec.precision) {
        (None, None) => shortest(v.abs(), false),
        (Some(b'f' | b'F'), p) => fixed_digits(v, p.unwrap_or(6) as usize),
        (Some(b'e' | b'E'), p) => {
            let (d, e) = sci_digits(v, Some(p.unwrap_or(6) + 1));
            let d = if v == 0.0 { "0".repeat(d.len()) } else { d };
            exp_layout(&d, if v == 0.0 { 0 } else { e }, e_char)
        }
        (Some(b'a' | b'A'), p) => hex_float(v.abs() as f64, p, upper),
        (_, p) => {
            // General: `p` significant digits (6 for g, at least 1), trailing zeros
            // dropped; fixed when the exponent is in -4..p.
            let p = p.unwrap_or(6).max(1);
            if v == 0.0 {
                "0".to_string()
            } else {
                let (d, e) = sci_digits(v, Some(p));
                let d = d.trim_end_matches('0');
                let d = if d.is_empty() { "0" } else { d };
                if e >= -4 && (e as i64) < p as i64 {
                    fixed_layout(d, e)
                } else {
                    exp_layout(d, e, e_char)
                }
            }
        }
    };
    pad_number(spec, sign, &body)
}

/// `fmt`'s hexadecimal form of the value as a double: `0x1.<hex>p<exp>`, trailing
/// zero digits dropped without a precision; with one, the digits rounded up when the
/// first dropped one is 8 or more (zero prints with exponent -1022, as `fmt` does).
fn hex_float(v: f64, precision: Option<u64>, upper: bool) -> String {
    let bits = v.to_bits();
    let mut mant = bits & ((1u64 << 52) - 1);
    let biased = ((bits >> 52) & 0x7ff) as i64;
    let (mut lead, exp) = if biased == 0 {
        (0u64, -1022)
    } else {
        (1u64, biased - 1023)
    };
    let mut n = 13usize;
    if let Some(p) = precision {
        if (p as usize) < 13 {
            let shift = 4 * (13 - p as usize);
            let next = (mant >> (shift - 4)) & 0xf;
            mant >>= shift;
            if next >= 8 {
                mant += 1;
                if mant >> (4 * p) != 0 {
                    mant &= (1u64 << (4 * p)) - 1;
                    lead += 1;
                }
            }
            n = p as usize;
        }
    }
    let mut digits = if n == 0 {
        String::new()
    } else {
        format!("{:0w$x}", mant, w = n)
    };
    match precision {
        None => {
            while digits.ends_with('0') {
                digits.pop();
            }
        }
        Some(p) => {
            for _ in n..p as usize {
                digits.push('0');
            }
        }
    }
    let mut s = format!("0x{lead}");
    if !digits.is_empty() {
        s.push('.');
        s.push_str(&digits);
    }
    s.push_str(&format!(
        "p{}{}",
        if exp < 0 { '-' } else { '+' },
        exp.abs()
    ));
    if upper {
        s = s.to_uppercase();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(format: &str, items: &[Item]) -> Result<String, String> {
        let names: Vec<String> = (0..items.len())
            .map(|i| ["x", "n", "w", "s"][i].to_string())
            .collect();
        format_items(format, items, &names)
    }

    /// Blender 4.5's results for these (printed by bpy, see gn_misc_nodes.py).
    // 3.14159 is the value Blender was given, not an approximation of pi.
    #[allow(clippy::approx_constant)]
    #[test]
    fn formats_as_blender() {
        use Item::*;
        let cases: &[(&str, Item, &str)] = &[
            ("a{}b", Float(1.0), "a1.0b"),
            ("{}", Float(0.1), "0.1"),
            ("{}", Float(1e20), "1e+20"),
            ("{}", Float(1e-5), "1e-05"),
            ("{:.3}", Float(1.0), "1"),
            ("{:.3}", Float(1234.5), "1.23e+03"),
            ("{:+08.2f}", Float(-3.14159), "-0003.14"),
            ("{:*^9}", Int(42), "***42****"),
            ("{:x}", Int(-255), "-ff"),
            ("{:e}", Float(0.5), "5.000000e-01"),
            ("{:g}", Float(1e-7), "1e-07"),
            ("{:10}", Str("ab".into()), "ab        "),
            ("{:.1s}", Str("xyz".into()), "x"),
            ("{:?}", Str("a\"b".into()), "\"a\\\"b\""),
            ("{:c}", Int(65), "A"),
            ("{:###.##}", Float(3.14159), "003.14"),
            ("{:##}", Int(7), "07"),
            ("{}", Float(16777216.0), "16777216.0"),
            ("{}", Float(-0.0), "-0.0"),
            ("{:a}", Float(1.5), "0x1.8p+0"),
            ("{:<08}", Int(5), "5       "),
            ("{:08}", Int(-5), "-0000005"),
            ("{:.2f}", Float(0.125), "0.12"),
            ("{:.0f}", Float(2.5), "2"),
            ("{:.0}", Float(1.5), "2"),
            ("{:?}", Str("a\n\u{1}é\\".into()), "\"a\\n\\x01é\\\\\""),
            ("{:08}", Float(1e30), "0001e+30"),
            ("{:>6}", Str("中".into()), "    中"),
            ("{:.2}", Str("ééé".into()), "éé"),
            ("{:+}", Float(2.0), "+2"),
            ("{: }", Int(2), " 2"),
            ("{:g}", Float(123456789.0), "1.23457e+08"),
            ("{:G}", Float(1e-20), "1E-20"),
            ("{:E}", Float(12345.678), "1.234568E+04"),
            ("{:.3a}", Float(0.1), "0x1.99ap-4"),
            ("{:a}", Float(0.1), "0x1.99999ap-4"),
            ("{:b}", Int(10), "1010"),
            ("{:o}", Int(-8), "-10"),
            ("{:+c}", Int(65), "A"),
            ("{:10.3}", Float(3.14159), "      3.14"),
            ("{:.1}", Float(0.0001234), "0.0001"),
            ("{:}", Float(1e16), "1e+16"),
            ("{}", Float(1e15), "1000000000000000.0"),
            ("{:f}", Float(1e10), "10000000000.000000"),
            ("{:05c}", Int(65), "0000A"),
            ("{:c}", Int(-65), "A"),
            ("{:c}", Int(321), "A"),
            ("{:+}", Float(-0.0), "-0"),
            ("{:##.#}", Int(-5), "-5.0"),
            ("{:###}", Float(-2.5), "-03"),
            ("{:.#}", Float(2.25), "2.2"),
            ("{:06X}", Int(-255), "-000FF"),
            ("{:^7.2e}", Float(1234.5), "1.23e+03"),
            ("{:.3g}", Float(0.00001234), "1.23e-05"),
            ("{:g}", Float(100000.0), "100000"),
            ("{:g}", Float(1000000.0), "1e+06"),
            ("{:.0e}", Float(2.5), "2e+00"),
            ("{:a}", Float(0.0), "0x0p-1022"),
            ("{:a}", Float(-2.0), "-0x1p+1"),
            ("{:.1a}", Float(1.97), "0x2.0p+0"),
            ("{:?}", Str("中\t\u{7f}".into()), "\"中\\t\\x7f\""),
            ("{:X}", Int(i32::MIN), "-80000000"),
            ("{}", Float(3.4028235e38), "3.4028235e+38"),
            ("{}", Float(1.17549435e-38), "1.1754944e-38"),
            ("{:.30f}", Float(0.1), "0.100000001490116119384765625000"),
        ];
        for (fmt, item, want) in cases {
            assert_eq!(
                f(fmt, std::slice::from_ref(item)).as_deref(),
                Ok(*want),
                "{fmt} {item:?}"
            );
        }
        assert_eq!(f("x{{}}y", &[]).as_deref(), Ok("x{}y"));
        assert_eq!(
            f("{:>{w}}", &[Int(6), Int(0), Int(6)]).as_deref(),
            Ok("     6")
        );
    }

    #[test]
    fn errors_are_blenders() {
        use Item::*;
        let e = |fmt: &str, items: &[Item]| f(fmt, items).unwrap_err();
        assert_eq!(e("{y}", &[Int(7)]), "Input does not exist: \"y\"");
        assert_eq!(e("{", &[Int(7)]), "Format specifier is not closed: \"{\"");
        assert_eq!(e("{:#x}", &[Int(7)]), "Invalid format specifier: \"#x\"");
        assert_eq!(
            e("{:%}", &[Float(1.0)]),
            "Format contains unsupported \"%\" character: \"{:%}\""
        );
        assert_eq!(
            e("{0}{}", &[Float(1.0)]),
            "Empty identifier can't be used when explicit identifier was used before. For example, \"{} {x}\" is ok but \"{x} {}\" is not."
        );
        assert_eq!(
            e("{1}", &[Float(1.0)]),
            "Input with index 1 does not exist. Currently, the maximum possible index is 0. Did you mean to use {:1}?"
        );
        assert_eq!(
            e("{1a}", &[Float(1.0)]),
            "An input name can't start with a digit: \"1a\""
        );
        assert_eq!(
            e("{:{}}", &[Int(6)]),
            "Format uses more inputs than provided."
        );
        assert_eq!(
            e("{x:{x}}", &[Float(6.0)]),
            "Only integer inputs can be used as dynamic width: \"{x:{x}}\""
        );
        assert_eq!(
            e("{:##}", &[Str("a".into())]),
            "Invalid format specifier for string: \"##\""
        );
        // Blender's pattern takes "{}.{}" greedily as one dynamic width.
        assert_eq!(
            e("{:{}.{}}", &[Float(0.5), Int(9), Int(3)]),
            "Input does not exist: \"}.{\""
        );
        assert!(e("{:>99999999}", &[Int(1)]).contains("larger than blendsynth formats"));
    }
}

//! Import PLY (`node_geo_import_ply.cc`, reading with `io/ply` with attributes imported):
//! the file's vertices (ASCII, binary little or big endian), faces (`vertex_indices` or
//! `vertex_index` lists, or `tristrips`) and `edge` elements as a mesh, as Blender 4.5
//! builds it: colours `red`/`green`/`blue`(/`alpha`) as the point colour attribute "Col"
//! (integers divided by their type's maximum, RGB decoded from sRGB), `s`/`t` as the
//! corner UV map "UVMap", every other vertex property as a float point attribute of its
//! name; vertex normals `nx`/`ny`/`nz` as custom normals (faces smooth) when there are
//! faces, else as a point attribute "normal"; without normals every face is flat.
//! Blender stores those custom normals relative to each corner's fan, so they follow a
//! later deformation; blendsynth keeps them fixed and refuses a deformed mesh by name
//! (`Mesh::relative_normals_moved`).
//! Edges are the file's then the faces' (`mesh_calc_edges`). Blender's read errors (no
//! header, a short row or file) give empty geometry; an index out of range is refused.

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::math::normalize;
use super::super::mesh::{Mesh, RELATIVE_NORMALS_REST};
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::value::SocketValue;
use super::import_file::{is_space, next_int, parse_float, read_path, skip_space, skip_word};
use crate::nodes::image::srgb_to_linear;

pub fn import_ply(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let set = match read_path(ctx)? {
        None => GeometrySet::default(),
        Some((path, bytes)) => match read_ply(&bytes) {
            Ok(mesh) => GeometrySet::from_mesh(mesh),
            Err(PlyError::Blender(why)) => {
                eprintln!(
                    "warning: {}",
                    ctx.err(format!(
                        "PLY file {path:?}: {why}: empty geometry, as Blender gives"
                    ))
                );
                GeometrySet::default()
            }
            Err(PlyError::Refused(why)) => return Err(ctx.err(format!("PLY file {path:?}: {why}"))),
        },
    };
    Ok(outputs([("Mesh", SocketValue::Geometry(set))]))
}

#[derive(Debug)]
pub enum PlyError {
    /// Blender's importer fails too (its node then outputs nothing).
    Blender(String),
    /// Blender makes something of it that blendsynth does not reproduce.
    Refused(String),
}

fn blender(m: impl Into<String>) -> PlyError {
    PlyError::Blender(m.into())
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Ty {
    Char,
    UChar,
    Short,
    UShort,
    Int,
    UInt,
    Float,
    Double,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::Char,
            "uchar" | "uint8" => Ty::UChar,
            "short" | "int16" => Ty::Short,
            "ushort" | "uint16" => Ty::UShort,
            "int" | "int32" => Ty::Int,
            "uint" | "uint32" => Ty::UInt,
            "float" | "float32" => Ty::Float,
            "double" | "float64" => Ty::Double,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Ty::Char | Ty::UChar => 1,
            Ty::Short | Ty::UShort => 2,
            Ty::Int | Ty::UInt | Ty::Float => 4,
            Ty::Double => 8,
        }
    }
    /// What a colour channel of this type is divided by.
    fn normalizer(self) -> f32 {
        match self {
            Ty::Char => 127.0,
            Ty::UChar => 255.0,
            Ty::Short => 32767.0,
            Ty::UShort => 65535.0,
            Ty::Int => i32::MAX as f32,
            Ty::UInt => u32::MAX as f32,
            Ty::Float | Ty::Double => 1.0,
        }
    }
}

struct Property {
    name: String,
    ty: Ty,
    /// The count's type for a list property.
    list: Option<Ty>,
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// The file after its header: rows of text, or bytes.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
}

impl<'a> Body<'a> {
    fn line(&mut self) -> &'a [u8] {
        let rest = &self.bytes[self.pos..];
        let n = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (n + 1).min(rest.len());
        &rest[..n]
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], PlyError> {
        if self.bytes.len() - self.pos < n {
            return Err(blender("the file ends inside its data"));
        }
        self.pos += n;
        Ok(&self.bytes[self.pos - n..self.pos])
    }
    /// One binary value converted to f32 as Blender's `get_binary_value<float>` does
    /// (`uint` read as a signed int).
    fn value(&mut self, ty: Ty) -> Result<f64, PlyError> {
        let b = self.take(ty.size())?;
        let mut a = [0u8; 8];
        a[..b.len()].copy_from_slice(b);
        if self.format == Format::Big {
            a[..b.len()].reverse();
        }
        Ok(match ty {
            Ty::Char => a[0] as i8 as f64,
            Ty::UChar => a[0] as f64,
            Ty::Short => i16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::UShort => u16::from_le_bytes([a[0], a[1]]) as f64,
            Ty::Int | Ty::UInt => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::Float => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Ty::Double => f64::from_le_bytes(a),
        })
    }
    /// A list count or index as `get_binary_value<uint32_t>` gives it.
    fn index(&mut self, ty: Ty) -> Result<u32, PlyError> {
        let v = self.value(ty)?;
        Ok(match ty {
            Ty::Char | Ty::Short | Ty::Int | Ty::UInt => v as i64 as u32,
            _ => v as u32,
        })
    }
}

fn parse_header(bytes: &[u8]) -> Result<(Format, Vec<Element>, usize), PlyError> {
    let mut pos = 0;
    let mut next_line = || -> Option<&[u8]> {
        if pos >= bytes.len() {
            return None;
        }
        let rest = &bytes[pos..];
        let n = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        pos += (n + 1).min(rest.len());
        Some(&rest[..n])
    };
    let words = |l: &[u8]| -> Vec<String> {
        String::from_utf8_lossy(l)
            .split(|c: char| (c as u32) <= 32)
            .filter(|w| !w.is_empty())
            .map(str::to_string)
            .collect()
    };
    match next_line() {
        Some(l) if words(l).first().map(String::as_str) == Some("ply") => {}
        _ => return Err(blender("not a PLY file (no \"ply\" line)")),
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(l) = next_line() else {
            return Err(blender("the header has no end_header"));
        };
        let w = words(l);
        match w.first().map(String::as_str) {
            Some("end_header") => break,
            Some("format") => {
                format = Some(match w.get(1).map(String::as_str) {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::Little,
                    Some("binary_big_endian") => Format::Big,
                    other => return Err(blender(format!("unknown format {other:?}"))),
                })
            }
            Some("element") => {
                let count = w
                    .get(2)
                    .and_then(|c| c.parse::<usize>().ok())
                    .ok_or_else(|| blender(format!("bad element line {:?}", w.join(" "))))?;
                elements.push(Element {
                    name: w.get(1).cloned().unwrap_or_default(),
                    count,
                    properties: Vec::new(),
                });
            }
            Some("property") => {
                let bad = || blender(format!("bad property line {:?}", w.join(" ")));
                let e = elements.last_mut().ok_or_else(bad)?;
                let p = if w.get(1).map(String::as_str) == Some("list") {
                    Property {
                        list: Some(w.get(2).and_then(|t| Ty::parse(t)).ok_or_else(bad)?),
                        ty: w.get(3).and_then(|t| Ty::parse(t)).ok_or_else(bad)?,
                        name: w.get(4).cloned().ok_or_else(bad)?,
                    }
                } else {
                    Property {
                        list: None,
                        ty: w.get(1).and_then(|t| Ty::parse(t)).ok_or_else(bad)?,
                        name: w.get(2).cloned().ok_or_else(bad)?,
                    }
                };
                e.properties.push(p);
            }
            _ => {} // comment, obj_info
        }
    }
    let format = format.ok_or_else(|| blender("the header has no format line"))?;
    Ok((format, elements, pos))
}

#[derive(Default)]
struct Data {
    vertices: Vec<[f32; 3]>,
    colors: Vec<[f32; 4]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    custom: Vec<(String, Vec<f32>)>,
    face_sizes: Vec<u32>,
    face_vertices: Vec<u32>,
    edges: Vec<[i64; 2]>,
}

/// One row of a list-free element as floats (`parse_row_ascii` / `parse_row_binary`):
/// an ASCII row shorter than the properties keeps the previous row's trailing values.
fn row(body: &mut Body, e: &Element, values: &mut [f32]) -> Result<(), PlyError> {
    if body.format == Format::Ascii {
        let line = body.line();
        if line.is_empty() {
            return Err(blender(format!(
                "could not read a row of element {:?}",
                e.name
            )));
        }
        let mut p = 0;
        let mut k = 0;
        while p < line.len() && k < values.len() {
            p = skip_space(line, p);
            let (v, n) = parse_float(&line[p..], 0.0);
            values[k] = v;
            k += 1;
            p += n;
            if n == 0 {
                // fast_float consumed nothing: Blender's next read starts at the same byte.
                p = line.len().min(p);
                if p < line.len() && !is_space(line[p]) {
                    // Every further value of the row parses as 0 from this byte.
                    while k < values.len() {
                        values[k] = 0.0;
                        k += 1;
                    }
                }
            }
        }
        return Ok(());
    }
    if e.properties.iter().any(|p| p.list.is_some()) {
        return Err(blender(format!("element {:?} has list properties", e.name)));
    }
    for (k, p) in e.properties.iter().enumerate() {
        values[k] = body.value(p.ty)? as f32;
    }
    Ok(())
}

fn index_of(e: &Element, name: &str) -> Option<usize> {
    e.properties.iter().position(|p| p.name == name)
}

fn load_vertices(body: &mut Body, e: &Element, d: &mut Data) -> Result<(), PlyError> {
    let at = |n: &str| index_of(e, n);
    let (Some(x), Some(y), Some(z)) = (at("x"), at("y"), at("z")) else {
        return Err(blender("vertex positions are not present in the file"));
    };
    let color = match (at("red"), at("green"), at("blue")) {
        (Some(r), Some(g), Some(b)) => Some([r, g, b]),
        _ => None,
    };
    let normal = match (at("nx"), at("ny"), at("nz")) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let uv = at("s").zip(at("t"));
    let alpha = at("alpha");
    const STANDARD: &[&str] = &[
        "x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha", "s", "t",
    ];
    let custom: Vec<usize> = (0..e.properties.len())
        .filter(|&i| !STANDARD.contains(&e.properties[i].name.as_str()))
        .collect();
    d.custom = custom
        .iter()
        // The header's count is the file's claim: reserve no more than its bytes can hold.
        .map(|&i| {
            (
                e.properties[i].name.clone(),
                Vec::with_capacity(e.count.min(body.bytes.len())),
            )
        })
        .collect();
    let norm = |i: usize| e.properties[i].ty.normalizer();
    let mut values = vec![0.0f32; e.properties.len()];
    for _ in 0..e.count {
        row(body, e, &mut values)?;
        d.vertices.push([values[x], values[y], values[z]]);
        if let Some([r, g, b]) = color {
            let a = alpha.map_or(1.0, |a| values[a] / norm(a));
            d.colors.push([
                values[r] / norm(r),
                values[g] / norm(g),
                values[b] / norm(b),
                a,
            ]);
        }
        if let Some([a, b, c]) = normal {
            d.normals.push([values[a], values[b], values[c]]);
        }
        if let Some((s, t)) = uv {
            d.uvs.push([values[s], values[t]]);
        }
        for (k, &i) in custom.iter().enumerate() {
            d.custom[k].1.push(values[i]);
        }
    }
    Ok(())
}

fn load_faces(body: &mut Body, e: &Element, d: &mut Data) -> Result<(), PlyError> {
    let pi = index_of(e, "vertex_indices")
        .or_else(|| index_of(e, "vertex_index"))
        .or_else(|| (e.properties.len() == 1).then_some(0))
        .ok_or_else(|| blender("face element does not contain vertex indices property"))?;
    let prop = &e.properties[pi];
    let Some(count_ty) = prop.list else {
        return Err(blender(
            "face element vertex indices property must be a list",
        ));
    };
    for _ in 0..e.count {
        if body.format == Format::Ascii {
            let line = body.line();
            let mut p = 0;
            let int = |p: &mut usize| next_int(line, p);
            for q in &e.properties[..pi] {
                if q.list.is_none() {
                    p = skip_word(line, skip_space(line, p));
                } else {
                    let n = int(&mut p);
                    for _ in 0..n.max(0) {
                        p = skip_word(line, skip_space(line, p));
                    }
                }
            }
            let n = int(&mut p);
            if !(1..=255).contains(&n) {
                return Err(blender("invalid face size, must be between 1 and 255"));
            }
            for _ in 0..n {
                d.face_vertices.push(int(&mut p) as u32);
            }
            d.face_sizes.push(n as u32);
        } else {
            for q in &e.properties[..pi] {
                skip(body, q)?;
            }
            let n = body.index(count_ty)?;
            if !(1..=255).contains(&n) {
                return Err(blender("invalid face size, must be between 1 and 255"));
            }
            for _ in 0..n {
                let v = body.index(prop.ty)?;
                d.face_vertices.push(v);
            }
            d.face_sizes.push(n);
            for q in &e.properties[pi + 1..] {
                skip(body, q)?;
            }
        }
    }
    Ok(())
}

fn skip(body: &mut Body, p: &Property) -> Result<(), PlyError> {
    match p.list {
        None => body.take(p.ty.size()).map(|_| ()),
        Some(ct) => {
            let n = body.index(ct)? as usize;
            body.take(n.saturating_mul(p.ty.size())).map(|_| ())
        }
    }
}

fn load_tristrips(body: &mut Body, e: &Element, d: &mut Data) -> Result<(), PlyError> {
    if e.count != 1 || e.properties.len() != 1 || e.properties[0].list.is_none() {
        return Err(blender("tristrips must be one row of one list property"));
    }
    let mut strip: Vec<i32> = Vec::new();
    if body.format == Format::Ascii {
        let line = body.line();
        let mut p = 0;
        let int = |p: &mut usize| next_int(line, p);
        let n = int(&mut p);
        for _ in 0..n.max(0) {
            strip.push(int(&mut p));
        }
    } else {
        let prop = &e.properties[0];
        let n = body.index(prop.list.unwrap())?;
        for _ in 0..n {
            strip.push(body.value(prop.ty)? as i64 as i32);
        }
    }
    let mut start = 0usize;
    for i in 0..strip.len() {
        if strip[i] == -1 {
            start = i + 1;
        } else if i - start >= 2 {
            let (mut a, mut b, c) = (strip[i - 2], strip[i - 1], strip[i]);
            if (i - start) & 1 == 1 {
                std::mem::swap(&mut a, &mut b);
            }
            if a != b && a != c && b != c {
                d.face_vertices.extend([a as u32, b as u32, c as u32]);
                d.face_sizes.push(3);
            }
        }
    }
    Ok(())
}

fn load_edges(body: &mut Body, e: &Element, d: &mut Data) -> Result<(), PlyError> {
    let (Some(a), Some(b)) = (index_of(e, "vertex1"), index_of(e, "vertex2")) else {
        return Err(blender(
            "edge element does not contain vertex1 and vertex2 properties",
        ));
    };
    let mut values = vec![0.0f32; e.properties.len()];
    for _ in 0..e.count {
        row(body, e, &mut values)?;
        d.edges.push([values[a] as i64, values[b] as i64]);
    }
    Ok(())
}

fn skip_element(body: &mut Body, e: &Element) -> Result<(), PlyError> {
    for _ in 0..e.count {
        if body.format == Format::Ascii {
            body.line();
        } else {
            for p in &e.properties {
                skip(body, p)?;
            }
        }
    }
    Ok(())
}

/// The mesh Blender's PLY importer makes of `bytes`.
pub fn read_ply(bytes: &[u8]) -> Result<Mesh, PlyError> {
    let (format, elements, start) = parse_header(bytes)?;
    let mut body = Body {
        bytes,
        pos: start,
        format,
    };
    let mut d = Data::default();
    let mut got = [false; 4];
    for e in &elements {
        match e.name.as_str() {
            "vertex" => {
                load_vertices(&mut body, e, &mut d)?;
                got[0] = true;
            }
            "face" => {
                load_faces(&mut body, e, &mut d)?;
                got[1] = true;
            }
            "tristrips" => {
                load_tristrips(&mut body, e, &mut d)?;
                got[2] = true;
            }
            "edge" => {
                load_edges(&mut body, e, &mut d)?;
                got[3] = true;
            }
            _ => skip_element(&mut body, e)?,
        }
        if got.iter().all(|&g| g) {
            break;
        }
    }
    to_mesh(d)
}

/// `convert_ply_to_mesh` (no vertex merging: the node leaves Merge Vertices off).
fn to_mesh(d: Data) -> Result<Mesh, PlyError> {
    let nv = d.vertices.len();
    if d.face_vertices.iter().any(|&v| v as usize >= nv) {
        return Err(PlyError::Refused(
            "a face names a vertex index past the vertex count (Blender's mesh validation \
             then rewrites the faces, which blendsynth does not reproduce)"
                .into(),
        ));
    }
    let mut m = Mesh::new();
    m.positions = d.vertices;
    m.edges = d
        .edges
        .iter()
        .map(|e| {
            e.map(|v| {
                if v < 0 || v as usize >= nv {
                    0
                } else {
                    v as u32
                }
            })
        })
        .collect();
    let mut offset = 0u32;
    for &s in &d.face_sizes {
        offset += s;
        m.face_offsets.push(offset);
    }
    m.corner_verts = d.face_vertices;
    let nf = m.face_count();
    let set = |m: &mut Mesh, name: &str, domain, data| {
        m.attributes.set(AttrId::Named(name.into()), domain, data)
    };
    if !d.colors.is_empty() {
        let c = d
            .colors
            .iter()
            .map(|c| {
                [
                    srgb_to_linear(c[0]),
                    srgb_to_linear(c[1]),
                    srgb_to_linear(c[2]),
                    c[3],
                ]
            })
            .collect();
        set(&mut m, "Col", Domain::Point, Array::Color(c));
    }
    if !d.uvs.is_empty() {
        let uv = m.corner_verts.iter().map(|&v| d.uvs[v as usize]).collect();
        set(&mut m, "UVMap", Domain::Corner, Array::Float2(uv));
    }
    let custom_normals = !d.normals.is_empty() && nf > 0;
    if !d.normals.is_empty() && nf == 0 {
        set(
            &mut m,
            "normal",
            Domain::Point,
            Array::Vector(d.normals.clone()),
        );
    } else if d.normals.is_empty() {
        set(
            &mut m,
            "sharp_face",
            Domain::Face,
            Array::Bool(vec![true; nf]),
        );
    }
    for (name, values) in d.custom {
        set(&mut m, &name, Domain::Point, Array::Float(values));
    }
    // The file's edges are kept, in order, before the faces' (`mesh_calc_edges(true)`).
    m.calc_edges(true);
    if custom_normals {
        // Blender stores them relative to each corner's fan; with one normal per vertex
        // every corner of a vertex gets that normal (normalized), and no edge turns sharp.
        let n: Vec<[f32; 3]> = d.normals.iter().map(|&v| normalize(v)).collect();
        set(&mut m, "custom_normal", Domain::Point, Array::Vector(n));
        // Blender's are relative to the corner fans and follow a later deformation: the
        // rest positions let a deformed mesh be refused (`Mesh::relative_normals_moved`).
        let rest = Array::Vector(m.positions.clone());
        set(&mut m, RELATIVE_NORMALS_REST, Domain::Point, rest);
        let ne = m.edge_count();
        set(
            &mut m,
            "sharp_edge",
            Domain::Edge,
            Array::Bool(vec![false; ne]),
        );
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header claiming billions of elements over a few bytes is an error naming the
    /// file's shortfall, not an allocation the machine cannot make.
    #[test]
    fn a_header_count_beyond_the_data_is_an_error() {
        for format in ["ascii", "binary_little_endian"] {
            let ply = format!("ply\nformat {format} 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nproperty float foo\nend_header\n0 0 0 1\n");
            assert!(read_ply(ply.as_bytes()).is_err(), "{format}");
        }
    }

    #[test]
    fn ascii_and_binary_read_alike() {
        let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n";
        let a = read_ply(ascii).unwrap();
        let mut bin = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
        for (p, c) in [
            ([0f32, 0., 0.], [255u8, 0, 0]),
            ([1., 0., 0.], [0, 255, 0]),
            ([0., 1., 0.], [0, 0, 255]),
        ] {
            for x in p {
                bin.extend(x.to_be_bytes());
            }
            bin.extend(c);
        }
        bin.push(3);
        for i in [0i32, 1, 2] {
            bin.extend(i.to_be_bytes());
        }
        let b = read_ply(&bin).unwrap();
        assert_eq!(a, b);
        assert_eq!(
            (a.vertex_count(), a.face_count(), a.edge_count()),
            (3, 1, 3)
        );
        assert!(matches!(
            read_ply(b"ply\nformat ascii 1.0\n"),
            Err(PlyError::Blender(_))
        ));
        assert!(matches!(
            read_ply(&bin[..bin.len() - 2]),
            Err(PlyError::Blender(_))
        ));
    }
}

//! Mesh attributes a material reads (Attribute, Color Attribute, UV Map, tangents), as
//! Cycles syncs and interpolates them: point values barycentrically over the triangle,
//! corner values per corner, face values constant. A program lists what it reads as
//! `AttributeRequest`s; whoever shades a mesh binds them once (`BoundAttributes::bind`)
//! and fills the shading point per hit (`fill`), allocation-free.

use crate::foundation::math::{Vec3, V3};
use crate::scene::{AttributeData, Domain, MeshData};

use super::point::ShadingPoint;
use super::tangent::mikk_tangents;

/// How many attribute values one shading point carries (a program may read no more).
pub const MAX_ATTRIBUTES: usize = 8;

/// A value a program reads from the mesh.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum AttributeRequest {
    /// A generic attribute (or UV map) by name.
    Named(String),
    /// The mesh's default (render) colour attribute: Color Attribute with no name.
    DefaultColor,
    /// MikkTSpace tangent and bitangent sign per corner of a UV map (None: the active
    /// render UV map), as (x, y, z, sign), object space.
    Tangent(Option<String>),
    /// Cycles' normal for tangent-space maps, object space and unnormalised: the
    /// interpolated vertex normals of a smooth face, the triangle normal of a flat one.
    MapNormal,
    /// Cycles' Pointiness (Geometry node, or an Attribute named "pointiness"): per
    /// vertex, see `derived::pointiness`.
    Pointiness,
    /// Cycles' Random Per Island (Geometry node, or an Attribute named
    /// "random_per_island"): per face, see `derived::random_per_island`.
    RandomPerIsland,
    /// An Attribute node of type Instancer: one value per rendered instance (see
    /// `render::build::MeshInstance::instancer_values`), by name.
    Instancer(String),
}

/// How the Attribute node's Fac reads a value (Cycles: float2 gives x, wider types the
/// average of the first three).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FacMode {
    X,
    Average,
}

impl FacMode {
    fn of(self, v: [f32; 4]) -> f32 {
        match self {
            FacMode::X => v[0],
            FacMode::Average => (v[0] + v[1] + v[2]) * (1.0 / 3.0),
        }
    }
}

/// Prefix of the point attribute that holds an Instancer attribute's value per realised
/// instance, written by the exporter for evaluated meshes whose Geometry Nodes instances
/// Blender realised (the name starts with "." so no Blender attribute takes it).
pub const NESTED_INSTANCER_PREFIX: &str = ".instancer.";

#[derive(Debug, Clone)]
enum Values {
    Missing,
    Point(Vec<[f32; 4]>),
    Corner(Vec<[f32; 4]>),
    Face(Vec<[f32; 4]>),
    /// Per corner of each triangle (index 3 * triangle + k): MikkTSpace runs on Cycles'
    /// triangles, so a quad's two triangles may give a shared corner different values.
    TriangleCorner(Vec<[f32; 4]>),
    /// Smooth faces: corner normals interpolated; flat ones (per face): the triangle normal.
    MapNormal {
        normals: Vec<V3>,
        flat: Vec<bool>,
    },
    /// The instance's value of this name (constant over the mesh).
    Instancer(String),
}

#[derive(Debug, Clone)]
struct Bound {
    values: Values,
    fac: FacMode,
}

/// A program's attribute requests resolved against one mesh.
#[derive(Debug, Clone, Default)]
pub struct BoundAttributes {
    items: Vec<Bound>,
}

fn to4_float(v: f32) -> [f32; 4] {
    [v, v, v, 1.0]
}

/// A generic attribute's values as Cycles stores them (x, y, z, alpha), and how Fac reads it.
fn convert(name: &str, data: &AttributeData) -> Result<(Vec<[f32; 4]>, FacMode), String> {
    use AttributeData as A;
    Ok(match data {
        A::Float(v) => (v.iter().map(|&x| to4_float(x)).collect(), FacMode::Average),
        A::Int(v) => (
            v.iter().map(|&x| to4_float(x as f32)).collect(),
            FacMode::Average,
        ),
        A::Int8(v) => (
            v.iter().map(|&x| to4_float(x as f32)).collect(),
            FacMode::Average,
        ),
        A::Bool(v) => (
            v.iter()
                .map(|&x| to4_float(if x { 1.0 } else { 0.0 }))
                .collect(),
            FacMode::Average,
        ),
        A::Float2(v) => (
            v.iter().map(|x| [x[0], x[1], 0.0, 1.0]).collect(),
            FacMode::X,
        ),
        A::Int2(v) => (
            v.iter()
                .map(|x| [x[0] as f32, x[1] as f32, 0.0, 1.0])
                .collect(),
            FacMode::X,
        ),
        A::Float3(v) => (
            v.iter().map(|x| [x[0], x[1], x[2], 1.0]).collect(),
            FacMode::Average,
        ),
        A::Color(v) => (v.clone(), FacMode::Average),
        A::Quaternion(_) | A::Float4x4(_) => {
            return Err(format!(
            "attribute {name:?}: quaternion and matrix attributes are not supported in shaders yet"
        ))
        }
    })
}

/// Blender's edge-to-point domain interpolation: each vertex the mean of its edges.
fn edge_to_point(mesh: &MeshData, v: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let mut sum = vec![[0.0f32; 4]; mesh.vertex_count()];
    let mut count = vec![0u32; mesh.vertex_count()];
    for (e, ends) in mesh.edges.iter().enumerate() {
        for &p in ends {
            for k in 0..4 {
                sum[p as usize][k] += v[e][k];
            }
            count[p as usize] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| if c == 0 { *s } else { s.map(|x| x / c as f32) })
        .collect()
}

impl BoundAttributes {
    /// Resolves `requests` on `mesh`. A name the mesh lacks reads as Cycles reads a missing
    /// attribute; a type no shader can read is an error naming it.
    pub fn bind(
        mesh: &MeshData,
        requests: &[AttributeRequest],
        active_render_uv: Option<&str>,
        default_color: Option<&str>,
    ) -> Result<BoundAttributes, String> {
        let mut items = Vec::with_capacity(requests.len());
        for r in requests {
            let named = |name: &str| -> Result<Bound, String> {
                let Some(a) = mesh.attribute(name) else {
                    return Ok(Bound {
                        values: Values::Missing,
                        fac: FacMode::Average,
                    });
                };
                let (v, fac) = convert(name, &a.data)?;
                let values = match a.domain {
                    Domain::Point => Values::Point(v),
                    Domain::Edge => Values::Point(edge_to_point(mesh, &v)),
                    Domain::Corner => Values::Corner(v),
                    Domain::Face => Values::Face(v),
                };
                Ok(Bound { values, fac })
            };
            items.push(match r {
                AttributeRequest::Named(name) => named(name)?,
                // Instances realised into one mesh carry their own values as a point
                // attribute (the exporter's, for Blender's evaluated meshes).
                AttributeRequest::Instancer(name) => {
                    let nested = format!("{NESTED_INSTANCER_PREFIX}{name}");
                    if mesh.attribute(&nested).is_some() {
                        named(&nested)?
                    } else {
                        Bound {
                            values: Values::Instancer(name.clone()),
                            fac: FacMode::Average,
                        }
                    }
                }
                AttributeRequest::DefaultColor => match default_color {
                    Some(name) => named(name)?,
                    None => Bound {
                        values: Values::Missing,
                        fac: FacMode::Average,
                    },
                },
                AttributeRequest::Tangent(uv) => {
                    let uv = uv.as_deref().or(active_render_uv);
                    match uv
                        .and_then(|n| mesh.attribute(n))
                        .map(|a| (&a.data, a.domain))
                    {
                        Some((AttributeData::Float2(uvs), Domain::Corner)) => Bound {
                            values: Values::TriangleCorner(mikk_tangents(mesh, uvs)),
                            fac: FacMode::Average,
                        },
                        _ => Bound {
                            values: Values::Missing,
                            fac: FacMode::Average,
                        },
                    }
                }
                AttributeRequest::MapNormal => {
                    let flat = match mesh.attribute("sharp_face").map(|a| &a.data) {
                        Some(AttributeData::Bool(v)) => v.clone(),
                        _ => vec![false; mesh.face_count()],
                    };
                    let vn = super::tangent::vertex_normals(mesh);
                    let normals = mesh.corner_verts.iter().map(|&v| vn[v as usize]).collect();
                    Bound {
                        values: Values::MapNormal { normals, flat },
                        fac: FacMode::Average,
                    }
                }
                // Float attributes: Fac is the value itself, Color (v, v, v), Alpha 1.
                AttributeRequest::Pointiness => {
                    let p = super::derived::pointiness(mesh, &super::tangent::vertex_normals(mesh));
                    Bound {
                        values: Values::Point(p.into_iter().map(to4_float).collect()),
                        fac: FacMode::X,
                    }
                }
                AttributeRequest::RandomPerIsland => Bound {
                    values: Values::Face(
                        super::derived::random_per_island(mesh)
                            .into_iter()
                            .map(to4_float)
                            .collect(),
                    ),
                    fac: FacMode::X,
                },
            });
        }
        if items.len() > MAX_ATTRIBUTES {
            return Err(format!(
                "the material reads {} mesh attributes; at most {MAX_ATTRIBUTES} are supported",
                items.len()
            ));
        }
        Ok(BoundAttributes { items })
    }

    /// Writes the attribute values at a point of triangle `tri` (Blender corners `c`, face
    /// `face`, barycentric weights `w` of its corners) into `sp`; Instancer attributes
    /// from the instance's `instancer` values.
    #[allow(clippy::too_many_arguments)]
    pub fn fill(
        &self,
        mesh: &MeshData,
        tri: usize,
        c: [usize; 3],
        face: usize,
        w: [f32; 3],
        instancer: &[(String, [f32; 4])],
        sp: &mut ShadingPoint,
    ) {
        sp.attr_missing = 0;
        let lerp = |v: [[f32; 4]; 3]| -> [f32; 4] {
            std::array::from_fn(|k| w[0] * v[0][k] + w[1] * v[1][k] + w[2] * v[2][k])
        };
        for (i, b) in self.items.iter().enumerate() {
            let v = match &b.values {
                Values::Missing => {
                    sp.attr_missing |= 1 << i;
                    [0.0; 4]
                }
                Values::Point(p) => lerp(c.map(|c| p[mesh.corner_verts[c] as usize])),
                Values::Corner(p) => lerp(c.map(|c| p[c])),
                Values::Face(p) => p[face],
                Values::TriangleCorner(p) => lerp([p[3 * tri], p[3 * tri + 1], p[3 * tri + 2]]),
                Values::Instancer(name) => instancer
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| *v)
                    .unwrap_or([0.0; 4]),
                Values::MapNormal { normals, flat } => {
                    if flat.get(face).copied().unwrap_or(false) {
                        let p =
                            c.map(|c| Vec3::from(mesh.positions[mesh.corner_verts[c] as usize]));
                        let n = (p[1] - p[0]).cross(p[2] - p[0]);
                        // Cycles' normalize: a true division by the length.
                        let n = n / n.length();
                        [n.x, n.y, n.z, 0.0]
                    } else {
                        let n = lerp(c.map(|c| {
                            let n = normals.get(c).copied().unwrap_or([0.0, 0.0, 1.0]);
                            [n[0], n[1], n[2], 0.0]
                        }));
                        [n[0], n[1], n[2], 1.0]
                    }
                }
            };
            sp.attrs[i] = v;
            sp.attr_fac[i] = b.fac.of(v);
        }
    }

    /// Resolves `requests` on hair: `attributes` by name, per key (true) or per curve, as
    /// Cycles exports them for particle hair (the emitter's UV maps and colours) and for
    /// Curves (their attributes). What hair has none of (tangents, the normal map's,
    /// Pointiness, Random Per Island) is an error naming it.
    pub fn bind_curves(
        attributes: &[(String, bool, AttributeData)],
        requests: &[AttributeRequest],
        default_color: Option<&str>,
    ) -> Result<BoundAttributes, String> {
        let named = |name: &str| -> Result<Bound, String> {
            let Some((_, per_key, data)) = attributes.iter().find(|a| a.0 == name) else {
                return Ok(Bound {
                    values: Values::Missing,
                    fac: FacMode::Average,
                });
            };
            let (v, fac) = convert(name, data)?;
            Ok(Bound {
                values: if *per_key {
                    Values::Point(v)
                } else {
                    Values::Face(v)
                },
                fac,
            })
        };
        let mut items = Vec::with_capacity(requests.len());
        for r in requests {
            items.push(match r {
                AttributeRequest::Named(name) => named(name)?,
                AttributeRequest::Instancer(name) => Bound {
                    values: Values::Instancer(name.clone()),
                    fac: FacMode::Average,
                },
                AttributeRequest::DefaultColor => match default_color {
                    Some(name) => named(name)?,
                    None => Bound {
                        values: Values::Missing,
                        fac: FacMode::Average,
                    },
                },
                other => {
                    return Err(format!(
                        "{other:?} on hair curves is not supported (hair has no faces to derive it from)"
                    ))
                }
            });
        }
        if items.len() > MAX_ATTRIBUTES {
            return Err(format!(
                "the material reads {} attributes; at most {MAX_ATTRIBUTES} are supported",
                items.len()
            ));
        }
        Ok(BoundAttributes { items })
    }

    /// Writes the attribute values at `u` along the hair segment from key `k0` to the
    /// next, on curve `curve` (per-key values linear along it, as Cycles'
    /// curve_attribute), into `sp`.
    pub fn fill_curve(
        &self,
        curve: usize,
        k0: usize,
        u: f32,
        instancer: &[(String, [f32; 4])],
        sp: &mut ShadingPoint,
    ) {
        sp.attr_missing = 0;
        for (i, b) in self.items.iter().enumerate() {
            let v = match &b.values {
                Values::Point(p) => {
                    let (a, c) = (p[k0], p[k0 + 1]);
                    std::array::from_fn(|k| (c[k] - a[k]) * u + a[k])
                }
                Values::Face(p) => p[curve],
                Values::Instancer(name) => instancer
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| *v)
                    .unwrap_or([0.0; 4]),
                _ => {
                    sp.attr_missing |= 1 << i;
                    [0.0; 4]
                }
            };
            sp.attrs[i] = v;
            sp.attr_fac[i] = b.fac.of(v);
        }
    }

    /// Writes the attributes' differentials into `sp.attrs_d` / `sp.attr_fac_d` for the
    /// hit's barycentric differentials `d` ([du, dv] along x and along y, as
    /// `bump::differential_dudv` gives them), for a Bump's offset points. Per-face values
    /// and normals do not change across the triangle.
    pub fn fill_differentials(
        &self,
        mesh: &MeshData,
        tri: usize,
        c: [usize; 3],
        d: [[f32; 2]; 2],
        sp: &mut ShadingPoint,
    ) {
        for (i, b) in self.items.iter().enumerate() {
            let corners = match &b.values {
                Values::Point(p) => Some(c.map(|c| p[mesh.corner_verts[c] as usize])),
                Values::Corner(p) => Some(c.map(|c| p[c])),
                Values::TriangleCorner(p) => Some([p[3 * tri], p[3 * tri + 1], p[3 * tri + 2]]),
                Values::Missing
                | Values::Face(_)
                | Values::MapNormal { .. }
                | Values::Instancer(_) => None,
            };
            for (k, dk) in d.iter().enumerate() {
                let dv: [f32; 4] = match corners {
                    Some(v) => std::array::from_fn(|j| {
                        (v[1][j] - v[0][j]) * dk[0] + (v[2][j] - v[0][j]) * dk[1]
                    }),
                    None => [0.0; 4],
                };
                sp.attrs_d[i][k] = dv;
                sp.attr_fac_d[i][k] = b.fac.of(dv);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hair attributes: per key linear along the segment, per curve constant, a missing
    /// name flagged; what hair cannot have is an error naming it.
    #[test]
    fn hair_attributes_interpolate_along_the_segment() {
        let attrs = vec![
            (
                "along".to_string(),
                true,
                AttributeData::Float(vec![0.0, 0.5, 1.0]),
            ),
            (
                "tint".to_string(),
                false,
                AttributeData::Color(vec![[0.2, 0.4, 0.6, 1.0]]),
            ),
        ];
        let req = [
            AttributeRequest::Named("along".into()),
            AttributeRequest::Named("tint".into()),
            AttributeRequest::Named("none".into()),
        ];
        let b = BoundAttributes::bind_curves(&attrs, &req, None).unwrap();
        let mut sp = ShadingPoint::default();
        b.fill_curve(0, 1, 0.25, &[], &mut sp);
        assert_eq!(sp.attrs[0], [0.625, 0.625, 0.625, 1.0]);
        assert_eq!(sp.attrs[1], [0.2, 0.4, 0.6, 1.0]);
        assert_eq!(sp.attr_missing, 0b100);
        let e = BoundAttributes::bind_curves(&attrs, &[AttributeRequest::Tangent(None)], None)
            .unwrap_err();
        assert!(e.contains("Tangent") && e.contains("hair"), "{e}");
    }
}

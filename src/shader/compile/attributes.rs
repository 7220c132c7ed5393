//! Compiling the nodes that read mesh attributes (Attribute, Color Attribute, a named UV
//! Map) and tangent space (Normal Map and Vector Displacement in tangent space, Tangent
//! in UV Map mode): each becomes an op reading an `AttributeRequest` the program lists.

use serde_json::Value;

use crate::shader::attributes::{AttributeRequest, MAX_ATTRIBUTES};

use super::{prop_str, CompileError, Compiler, Kind, Op};

/// Attribute names Cycles resolves to built-in data rather than to a mesh attribute.
const STANDARD_NAMES: [&str; 12] = [
    "generated",
    "uv",
    "tangent",
    "N",
    "Ng",
    "undeformed",
    "undisplaced",
    "pointiness",
    "random_per_island",
    "vertex_color",
    "ptex_face_id",
    "ptex_uv",
];

impl<'g, 'a> Compiler<'g, 'a> {
    /// The index of request `r`, added when new.
    fn request(&mut self, path: &str, r: AttributeRequest) -> Result<u8, CompileError> {
        if let Some(k) = self.attributes.iter().position(|x| *x == r) {
            return Ok(k as u8);
        }
        if self.attributes.len() == MAX_ATTRIBUTES {
            return Err(CompileError(format!(
                "node {path:?}: the material reads more than {MAX_ATTRIBUTES} mesh attributes"
            )));
        }
        self.attributes.push(r);
        Ok(self.attributes.len() as u8 - 1)
    }

    /// The tangent request of a node's `uv_map` (empty: the active render UV map).
    fn tangent_request(&mut self, i: usize, uv_key: Option<&str>) -> Result<u8, CompileError> {
        let n = &self.g.nodes[i];
        let uv = match uv_key {
            Some(k) => prop_str(n, k)?,
            None => "",
        };
        let r = AttributeRequest::Tangent((!uv.is_empty()).then(|| uv.to_string()));
        self.request(&n.path, r)
    }

    pub(super) fn attribute_node(&mut self, i: usize) -> Result<(), CompileError> {
        use Kind::{Color as C, Float as F, Vector as V};
        // At a bump's offset points the same ops read the attribute moved along the
        // triangle (`bump::offset_point`, Cycles' svm_node_attr_bump_dx).
        let n = &self.g.nodes[i];
        if n.node.bl_idname == "ShaderNodeVertexColor" {
            let name = prop_str(n, "layer_name")?;
            let r = if name.is_empty() {
                AttributeRequest::DefaultColor
            } else {
                AttributeRequest::Named(name.to_string())
            };
            let attr = self.request(&n.path, r)?;
            let (color, alpha) = (self.alloc(C), self.alloc(F));
            self.ops.push(Op::ColorAttribute { attr, color, alpha });
            self.outputs(i, n, &[("Color", color, C), ("Alpha", alpha, F)]);
            return Ok(());
        }
        let kind = prop_str(n, "attribute_type")?;
        let name = prop_str(n, "attribute_name")?;
        if kind == "INSTANCER" {
            let attr = self.request(&n.path, AttributeRequest::Instancer(name.to_string()))?;
            let (vector, fac, alpha) = (self.alloc(V), self.alloc(F), self.alloc(F));
            self.ops.push(Op::Attribute {
                attr,
                vector,
                fac,
                alpha,
            });
            self.outputs(
                i,
                n,
                &[
                    ("Color", vector, C),
                    ("Vector", vector, V),
                    ("Fac", fac, F),
                    ("Alpha", alpha, F),
                ],
            );
            return Ok(());
        }
        if kind != "GEOMETRY" {
            return Err(CompileError(format!(
                "node {:?}: Attribute type {kind} is not supported (only Geometry and Instancer)",
                n.path
            )));
        }
        let derived = match name {
            "pointiness" => Some(AttributeRequest::Pointiness),
            "random_per_island" => Some(AttributeRequest::RandomPerIsland),
            _ => None,
        };
        if let Some(r) = derived {
            let attr = self.request(&n.path, r)?;
            let (vector, fac, alpha) = (self.alloc(V), self.alloc(F), self.alloc(F));
            self.ops.push(Op::Attribute {
                attr,
                vector,
                fac,
                alpha,
            });
            self.outputs(
                i,
                n,
                &[
                    ("Color", vector, C),
                    ("Vector", vector, V),
                    ("Fac", fac, F),
                    ("Alpha", alpha, F),
                ],
            );
            return Ok(());
        }
        if STANDARD_NAMES.contains(&name) {
            return Err(CompileError(format!(
                "node {:?}: Attribute name {name:?} is Cycles built-in data, not supported yet",
                n.path
            )));
        }
        let attr = self.request(&n.path, AttributeRequest::Named(name.to_string()))?;
        let (vector, fac, alpha) = (self.alloc(V), self.alloc(F), self.alloc(F));
        self.ops.push(Op::Attribute {
            attr,
            vector,
            fac,
            alpha,
        });
        self.outputs(
            i,
            n,
            &[
                ("Color", vector, C),
                ("Vector", vector, V),
                ("Fac", fac, F),
                ("Alpha", alpha, F),
            ],
        );
        Ok(())
    }

    /// Principled Volume's Density, Color and Temperature Attribute names: each a named
    /// attribute request (Cycles finds voxel grids by them), recorded on the node as the
    /// property `attribute:<socket>` = request index for the renderer's volume shading.
    pub(super) fn principled_volume_attributes(&mut self, i: usize) -> Result<(), CompileError> {
        let n = &self.g.nodes[i];
        let mut found = Vec::new();
        for id in [
            "Density Attribute",
            "Color Attribute",
            "Temperature Attribute",
        ] {
            let Some(inp) = n.input(id) else { continue };
            let name = match inp.sources.first() {
                Some(crate::nodes::graph::Source::Default(sock)) => sock
                    .default_value
                    .as_ref()
                    .and_then(Value::as_str)
                    .unwrap_or(""),
                None => inp
                    .socket
                    .default_value
                    .as_ref()
                    .and_then(Value::as_str)
                    .unwrap_or(""),
                Some(_) => {
                    return Err(CompileError(format!(
                        "node {:?}: a link into {id} is not supported (a fixed attribute name is)",
                        n.path
                    )))
                }
            };
            if !name.is_empty() {
                found.push((id, name.to_string()));
            }
        }
        let path = n.path.clone();
        for (id, name) in found {
            let k = self.request(&path, AttributeRequest::Named(name))?;
            if let Some(b) = self.bsdfs.last_mut() {
                b.properties
                    .push((format!("attribute:{id}"), k.to_string()));
            }
        }
        Ok(())
    }

    /// Geometry > Pointiness and Random Per Island: Cycles compiles them as float
    /// attribute reads of its derived mesh attributes.
    pub(super) fn geometry_derived(&mut self, i: usize) -> Result<(), CompileError> {
        for (id, r) in [
            ("Pointiness", AttributeRequest::Pointiness),
            ("Random Per Island", AttributeRequest::RandomPerIsland),
        ] {
            let n = &self.g.nodes[i];
            let Some(k) = n.node.outputs.iter().position(|o| o.identifier == id) else {
                continue;
            };
            // At a bump's offset points the read sees the value moved along the
            // triangle (`bump::offset_point`).
            if !self.output_used(i, id) {
                continue;
            }
            let path = n.path.clone();
            let attr = self.request(&path, r)?;
            let (vector, fac, alpha) = (
                self.alloc(Kind::Vector),
                self.alloc(Kind::Float),
                self.alloc(Kind::Float),
            );
            self.ops.push(Op::Attribute {
                attr,
                vector,
                fac,
                alpha,
            });
            self.values[i][k] = Some((fac, Kind::Float));
        }
        Ok(())
    }

    pub(super) fn named_uv(&mut self, i: usize) -> Result<(), CompileError> {
        let n = &self.g.nodes[i];
        if n.property("from_instancer").and_then(Value::as_bool) == Some(true) {
            return Err(CompileError(format!(
                "node {:?}: UV Map 'From Instancer' is not supported yet",
                n.path
            )));
        }
        let name = prop_str(n, "uv_map")?.to_string();
        let attr = self.request(&n.path, AttributeRequest::Named(name))?;
        let dst = self.alloc(Kind::Vector);
        self.ops.push(Op::NamedUv { attr, dst });
        self.outputs(i, n, &[("UV", dst, Kind::Vector)]);
        Ok(())
    }

    pub(super) fn normal_map_tangent(&mut self, i: usize) -> Result<(), CompileError> {
        let tangent = self.tangent_request(i, Some("uv_map"))?;
        let n = &self.g.nodes[i];
        let normal = self.request(&n.path, AttributeRequest::MapNormal)?;
        let (color, strength) = (
            self.input(n, "Color", Kind::Color)?,
            self.input(n, "Strength", Kind::Float)?,
        );
        let dst = self.alloc(Kind::Vector);
        self.ops.push(Op::NormalMapTangent {
            tangent,
            normal,
            color,
            strength,
            dst,
        });
        self.outputs(i, n, &[("Normal", dst, Kind::Vector)]);
        Ok(())
    }

    /// Cycles' Vector Displacement reads the active render UV map's tangents.
    pub(super) fn vector_displacement_tangent(&mut self, i: usize) -> Result<(), CompileError> {
        let tangent = self.tangent_request(i, None)?;
        let n = &self.g.nodes[i];
        let (vector, midlevel, scale) = (
            self.input(n, "Vector", Kind::Vector)?,
            self.input(n, "Midlevel", Kind::Float)?,
            self.input(n, "Scale", Kind::Float)?,
        );
        let dst = self.alloc(Kind::Vector);
        self.ops.push(Op::VectorDisplacementTangent {
            tangent,
            vector,
            midlevel,
            scale,
            dst,
        });
        self.outputs(i, n, &[("Displacement", dst, Kind::Vector)]);
        Ok(())
    }

    pub(super) fn tangent_uv(&mut self, i: usize) -> Result<(), CompileError> {
        let tangent = self.tangent_request(i, Some("uv_map"))?;
        let n = &self.g.nodes[i];
        let dst = self.alloc(Kind::Vector);
        self.ops.push(Op::TangentUv { tangent, dst });
        self.outputs(i, n, &[("Tangent", dst, Kind::Vector)]);
        Ok(())
    }
}

//! Compiling the input nodes that read the shading context: each used output becomes
//! one `Op::Input` (or a node op for Fresnel, Layer Weight, Light Falloff, Normal,
//! Tangent); outputs nothing reads cost nothing per shading point.

use serde_json::Value;

use crate::nodes::graph::Source;
use crate::shader::inputs::Input;
use crate::shader::view::invert_affine;

use super::{floats, linked, prop_str, CompileError, Compiler, Kind, Op, Slot};

impl<'g, 'a> Compiler<'g, 'a> {
    /// True when some node reads output `output` of flat node `node`.
    fn output_index_used(&self, node: usize, output: usize) -> bool {
        self.g.nodes.iter().any(|n| n.inputs.iter().any(|i| i.sources.iter().any(|s| matches!(s, Source::Link { node: m, output: o, .. } if *m == node && *o == output))))
    }

    /// Each used output of node `i` whose identifier `Input::from` maps, as an input op.
    fn input_outputs(&mut self, i: usize, map: fn(&str) -> Option<Input>) {
        let n = &self.g.nodes[i];
        let mut slots = Vec::new();
        for (k, o) in n.node.outputs.iter().enumerate() {
            let Some(what) = map(&o.identifier) else {
                continue;
            };
            if !self.output_index_used(i, k) {
                continue;
            }
            let kind = if what.is_vector() {
                Kind::Vector
            } else {
                Kind::Float
            };
            let dst = self.alloc(kind);
            self.ops.push(Op::Input { what, dst });
            slots.push((o.identifier.as_str(), dst, kind));
        }
        let slots: Vec<(&str, Slot, Kind)> = slots;
        self.outputs(i, n, &slots);
    }

    /// The Normal input of Fresnel / Layer Weight / Normal: None when unlinked, so the
    /// op reads the shading normal as Cycles does.
    fn normal_input(&mut self, i: usize) -> Result<Option<Slot>, CompileError> {
        let n = &self.g.nodes[i];
        if linked(n, "Normal") {
            Ok(Some(self.input(n, "Normal", Kind::Vector)?))
        } else {
            Ok(None)
        }
    }

    pub(super) fn input_node(&mut self, i: usize) -> Result<(), CompileError> {
        use Kind::{Float as F, Vector as V};
        let n = &self.g.nodes[i];
        match n.node.bl_idname.as_str() {
            "ShaderNodeFresnel" => {
                let ior = self.input(n, "IOR", F)?;
                let normal = self.normal_input(i)?;
                let dst = self.alloc(F);
                self.ops.push(Op::Fresnel { ior, normal, dst });
                self.outputs(i, n, &[("Fac", dst, F)]);
            }
            "ShaderNodeLayerWeight" => {
                let blend = self.input(n, "Blend", F)?;
                let normal = self.normal_input(i)?;
                let (fresnel, facing) = (self.alloc(F), self.alloc(F));
                self.ops.push(Op::LayerWeight {
                    blend,
                    normal,
                    fresnel,
                    facing,
                });
                self.outputs(i, n, &[("Fresnel", fresnel, F), ("Facing", facing, F)]);
            }
            // Pointiness and Random Per Island read derived mesh attributes.
            "ShaderNodeNewGeometry" => {
                self.input_outputs(i, |id| {
                    Some(match id {
                        "Position" => Input::Position,
                        "Normal" => Input::Normal,
                        "Tangent" => Input::Tangent,
                        "True Normal" => Input::TrueNormal,
                        "Incoming" => Input::Incoming,
                        "Parametric" => Input::Parametric,
                        "Backfacing" => Input::Backfacing,
                        _ => return None,
                    })
                });
                self.geometry_derived(i)?;
            }
            "ShaderNodeObjectInfo" => {
                self.input_outputs(i, |id| {
                    Some(match id {
                        "Location" => Input::ObjectLocation,
                        "Color" => Input::ObjectColor,
                        "Alpha" => Input::ObjectAlpha,
                        "Object Index" => Input::ObjectIndex,
                        "Random" => Input::ObjectRandom,
                        _ => return None,
                    })
                });
                // The material's pass index is a constant of the program.
                if let Some(k) = n
                    .node
                    .outputs
                    .iter()
                    .position(|o| o.identifier == "Material Index")
                {
                    let s = self.constant(F, [self.material_pass_index; 3]);
                    self.values[i][k] = Some((s, F));
                }
            }
            "ShaderNodeCameraData" => self.input_outputs(i, |id| {
                Some(match id {
                    "View Vector" => Input::ViewVector,
                    "View Z Depth" => Input::ViewZDepth,
                    "View Distance" => Input::ViewDistance,
                    _ => return None,
                })
            }),
            "ShaderNodeLightPath" => self.input_outputs(i, Input::light_path),
            "ShaderNodeLightFalloff" => {
                let (strength, smooth) =
                    (self.input(n, "Strength", F)?, self.input(n, "Smooth", F)?);
                let dst = [self.alloc(F), self.alloc(F), self.alloc(F)];
                self.ops.push(Op::LightFalloff {
                    strength,
                    smooth,
                    dst,
                });
                self.outputs(
                    i,
                    n,
                    &[
                        ("Quadratic", dst[0], F),
                        ("Linear", dst[1], F),
                        ("Constant", dst[2], F),
                    ],
                );
            }
            "ShaderNodeNormal" => {
                let d = n
                    .node
                    .outputs
                    .iter()
                    .find(|o| o.identifier == "Normal")
                    .and_then(|o| o.default_value.as_ref())
                    .map(floats)
                    .unwrap_or([0.0, 0.0, 1.0, 1.0]);
                let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let direction = [d[0] / l, d[1] / l, d[2] / l];
                let out_n = self.constant(V, direction);
                let normal = self.input(n, "Normal", V)?;
                let dot = self.alloc(F);
                self.ops.push(Op::NormalDot {
                    direction,
                    normal,
                    dst: dot,
                });
                self.outputs(i, n, &[("Normal", out_n, V), ("Dot", dot, F)]);
            }
            "ShaderNodeTangent" => {
                if prop_str(n, "direction_type")? != "RADIAL" {
                    return self.tangent_uv(i);
                }
                let axis = match prop_str(n, "axis")? {
                    "X" => 0,
                    "Y" => 1,
                    "Z" => 2,
                    other => {
                        return Err(CompileError(format!(
                            "node {:?}: Tangent axis {other:?} is not supported",
                            n.path
                        )))
                    }
                };
                let dst = self.alloc(V);
                self.ops.push(Op::TangentRadial { axis, dst });
                self.outputs(i, n, &[("Tangent", dst, V)]);
            }
            other => {
                return Err(CompileError(format!(
                    "node {:?}: {other} is not supported yet",
                    n.path
                )))
            }
        }
        Ok(())
    }

    /// Texture Coordinate's Camera, Window and Reflection outputs, and Object relative
    /// to the node's `object` when it names one.
    pub(super) fn tex_coord_more(&mut self, i: usize) -> Result<(), CompileError> {
        use Kind::Vector as V;
        let n = &self.g.nodes[i];
        for (id, what) in [
            ("Camera", Input::Camera),
            ("Window", Input::Window),
            ("Reflection", Input::Reflection),
        ] {
            let Some(k) = n.node.outputs.iter().position(|o| o.identifier == id) else {
                continue;
            };
            if !self.output_index_used(i, k) {
                continue;
            }
            let dst = self.alloc(V);
            self.ops.push(Op::Input { what, dst });
            self.values[i][k] = Some((dst, V));
        }
        if n.node
            .properties
            .get("from_instancer")
            .and_then(Value::as_bool)
            == Some(true)
        {
            return Err(CompileError(format!(
                "node {:?}: Texture Coordinate 'From Instancer' is not supported yet",
                n.path
            )));
        }
        let object = n
            .node
            .properties
            .get("object")
            .and_then(|o| o.get("name"))
            .and_then(Value::as_str);
        if let (Some(name), Some(k)) = (
            object,
            n.node.outputs.iter().position(|o| o.identifier == "Object"),
        ) {
            let scene = self.scene.ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: object {name:?} needs the scene",
                    n.path
                ))
            })?;
            let ob = scene.object(name).ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: object {name:?} is not in the export",
                    n.path
                ))
            })?;
            let inv = invert_affine(&ob.matrix_world).ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: object {name:?} has a singular transform",
                    n.path
                ))
            })?;
            let to_object = std::array::from_fn(|r| std::array::from_fn(|c| inv[r][c] as f32));
            let dst = self.alloc(V);
            self.ops.push(Op::ObjectSpace { to_object, dst });
            self.values[i][k] = Some((dst, V));
        }
        Ok(())
    }
}

//! Remove Named Attribute (`node_geo_remove_attribute`), Exact and Wildcard pattern
//! modes, as Blender 4.5 runs it:
//! - an empty name, or a Wildcard pattern with more than one `*`, changes nothing (the
//!   latter only logs a note); a Wildcard pattern without `*` is Exact;
//! - Wildcard matches every named attribute that starts with the part before the `*` and
//!   ends with the part after it;
//! - components are visited in the order Mesh, Point Cloud, Curves, Instances, and the
//!   walk over one set's components stops at the first present component with nothing to
//!   remove (Blender's loop `break`s there), then goes on into the geometry its
//!   instances reference;
//! - built-ins Blender cannot remove (positions, topology, instance transforms) are not
//!   attributes here, so they stay as they do in Blender; names starting with "." are
//!   internal and never touched.

use super::super::attribute::{AttrId, Attributes};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::instances::InstanceReference;
use super::super::set::{ComponentType, GeometrySet};
use super::geometry_ops::geo;

enum Pattern {
    Exact(String),
    Wildcard { prefix: String, suffix: String },
}

impl Pattern {
    /// The names `pattern` picks among a component's attributes and its built-ins that
    /// are not attributes here (`fixed`: Blender lists them too, so they decide whether
    /// the walk over components goes on, though they are never removed).
    fn matching(&self, a: &Attributes, fixed: &[&str]) -> Vec<String> {
        let names = fixed
            .iter()
            .copied()
            .chain(a.iter().filter_map(|x| x.id.name()));
        match self {
            Pattern::Exact(name) => names.filter(|n| n == name).map(str::to_string).collect(),
            // Blender only compares both ends: "ab" matches "ab*b".
            Pattern::Wildcard { prefix, suffix } => names
                .filter(|n| n.starts_with(prefix.as_str()) && n.ends_with(suffix.as_str()))
                .map(str::to_string)
                .collect(),
        }
    }
}

fn remove_from(a: &mut Attributes, names: &[String]) {
    for n in names {
        // Blender's `allow_procedural_attribute_access`: internal names stay.
        if !n.starts_with('.') {
            a.remove(&AttrId::named(n));
        }
    }
}

/// Built-ins Blender lists but cannot remove, which blendsynth keeps outside the
/// attributes (positions, topology, instance transforms).
const MESH_FIXED: &[&str] = &["position", ".edge_verts", ".corner_vert", ".corner_edge"];
const POSITION: &[&str] = &["position"];
const INSTANCES_FIXED: &[&str] = &["instance_transform", ".reference_index"];

fn remove_recursive(g: &mut GeometrySet, pattern: &Pattern) {
    for t in [
        ComponentType::Mesh,
        ComponentType::PointCloud,
        ComponentType::Curves,
        ComponentType::Instances,
    ] {
        let found = match t {
            ComponentType::Mesh => g
                .mesh
                .as_ref()
                .map(|m| pattern.matching(&m.attributes, MESH_FIXED)),
            ComponentType::PointCloud => g
                .points
                .as_ref()
                .map(|p| pattern.matching(&p.attributes, POSITION)),
            ComponentType::Curves => g
                .curves
                .as_ref()
                .map(|c| pattern.matching(&c.attributes, POSITION)),
            ComponentType::Instances => g
                .instances
                .as_ref()
                .map(|i| pattern.matching(&i.attributes, INSTANCES_FIXED)),
        };
        let Some(ids) = found else { continue };
        if ids.is_empty() {
            break;
        }
        match t {
            ComponentType::Mesh => remove_from(&mut g.mesh_mut().unwrap().attributes, &ids),
            ComponentType::PointCloud => remove_from(&mut g.points_mut().unwrap().attributes, &ids),
            ComponentType::Curves => remove_from(&mut g.curves_mut().unwrap().attributes, &ids),
            ComponentType::Instances => {
                remove_from(&mut g.instances_mut().unwrap().attributes, &ids)
            }
        }
    }
    if let Some(inst) = g.instances_mut() {
        for r in inst.references.iter_mut() {
            match r {
                InstanceReference::Geometry(s) | InstanceReference::Object(_, s) => {
                    remove_recursive(s, pattern)
                }
                InstanceReference::None => {}
            }
        }
    }
}

pub fn remove_attribute(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let name = ctx.string("Name")?;
    let mode = ctx.prop_str("pattern_mode")?;
    let pattern = match mode {
        _ if name.is_empty() => None,
        "EXACT" => Some(Pattern::Exact(name)),
        "WILDCARD" => match name.matches('*').count() {
            0 => Some(Pattern::Exact(name)),
            1 => {
                let (prefix, suffix) = name.split_once('*').unwrap();
                Some(Pattern::Wildcard {
                    prefix: prefix.to_string(),
                    suffix: suffix.to_string(),
                })
            }
            _ => None,
        },
        other => return Err(ctx.err(format!("pattern mode {other:?} is not evaluated"))),
    };
    if let Some(p) = pattern {
        remove_recursive(&mut g, &p);
    }
    Ok(outputs([("Geometry", geo(g))]))
}

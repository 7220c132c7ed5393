//! Collection Info (`node_geo_collection_info`): a collection as instances, whole (one
//! instance of every object in it and its child collections, less its instance offset) or
//! one instance per child object and child collection, sorted by name as Blender sorts
//! them (case-insensitive, digit runs by value).

use std::cmp::Ordering;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::instances::{InstanceReference, Instances};
use super::super::math::{mat4_invert, mat4_mul, translation, Mat4f, MAT4_IDENTITY};
use super::super::set::GeometrySet;
use super::super::value::SocketValue;
use crate::scene::Collection;

/// Blender's BLI_strcasecmp_natural, in short: case-insensitive, runs of digits compared
/// by value.
fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (a, b) = (a.to_lowercase(), b.to_lowercase());
    let (mut x, mut y) = (a.as_bytes(), b.as_bytes());
    loop {
        match (x.first(), y.first()) {
            (None, None) => return Ordering::Equal,
            (None, _) => return Ordering::Less,
            (_, None) => return Ordering::Greater,
            (Some(p), Some(q)) if p.is_ascii_digit() && q.is_ascii_digit() => {
                let dx = x.iter().take_while(|c| c.is_ascii_digit()).count();
                let dy = y.iter().take_while(|c| c.is_ascii_digit()).count();
                let trim = |s: &[u8]| -> Vec<u8> {
                    let s: Vec<u8> = s.iter().copied().skip_while(|c| *c == b'0').collect();
                    s
                };
                let (nx, ny) = (trim(&x[..dx]), trim(&y[..dy]));
                let o = nx.len().cmp(&ny.len()).then_with(|| nx.cmp(&ny));
                if o != Ordering::Equal {
                    return o;
                }
                x = &x[dx..];
                y = &y[dy..];
            }
            (Some(p), Some(q)) => {
                if p != q {
                    return p.cmp(q);
                }
                x = &x[1..];
                y = &y[1..];
            }
        }
    }
}

struct Lookup<'c, 'e, 'a> {
    ctx: &'c NodeCtx<'e, 'a>,
}

impl Lookup<'_, '_, '_> {
    fn collection(&self, name: &str) -> Result<&Collection, GeometryError> {
        self.ctx.session().scene.collection(name).ok_or_else(|| {
            self.ctx
                .err(format!("collection {name:?} is not in the export"))
        })
    }
    fn world(&self, object: &str) -> Result<Mat4f, GeometryError> {
        self.ctx.session().world_matrix(object).ok_or_else(|| {
            self.ctx
                .err(format!("object {object:?} is not in the export"))
        })
    }
    fn object(&self, name: &str) -> Result<InstanceReference, GeometryError> {
        if name == self.ctx.ev.object.name {
            return Err(self.ctx.err(format!(
                "the collection contains the modifier's own object {name:?} (Blender reports a dependency cycle)"
            )));
        }
        let g = self
            .ctx
            .session()
            .evaluate_object(name)
            .map_err(|e| self.ctx.err(e))?;
        Ok(InstanceReference::Object(name.to_string(), g))
    }
    /// Every object of the collection, each once, in the order Blender realizes a
    /// collection instance: the child collections' objects first, then its own (fixture
    /// `collection_original`).
    fn all_objects(&self, c: &Collection, out: &mut Vec<String>) -> Result<(), GeometryError> {
        for ch in &c.children {
            let child = self.collection(ch)?;
            self.all_objects(child, out)?;
        }
        for o in &c.objects {
            if !out.contains(o) {
                out.push(o.clone());
            }
        }
        Ok(())
    }
    /// A collection as one reference: its objects at their world transforms less the
    /// collection's instance offset.
    fn collection_reference(&self, c: &Collection) -> Result<InstanceReference, GeometryError> {
        let mut names = Vec::new();
        self.all_objects(c, &mut names)?;
        let offset = translation(neg(c.instance_offset));
        let mut inst = Instances::default();
        for n in names {
            let h = inst.add_reference(self.object(&n)?);
            inst.handles.push(h);
            inst.transforms.push(mat4_mul(&offset, &self.world(&n)?));
        }
        Ok(InstanceReference::Geometry(GeometrySet::from_instances(
            inst,
        )))
    }
}

fn neg(v: [f32; 3]) -> [f32; 3] {
    [-v[0], -v[1], -v[2]]
}

pub fn collection_info(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let SocketValue::Collection(name) = ctx.input("Collection")? else {
        return Err(ctx.err("Collection input is not a collection"));
    };
    let Some(name) = name else {
        return Ok(outputs([(
            "Instances",
            SocketValue::Geometry(GeometrySet::default()),
        )]));
    };
    let look = Lookup { ctx };
    let c = look.collection(&name)?;
    let relative = ctx.prop_str("transform_space")? == "RELATIVE";
    let self_world = ctx
        .session()
        .world_matrix(&ctx.ev.object.name)
        .unwrap_or(MAT4_IDENTITY);
    let world_to_self = mat4_invert(&self_world).unwrap_or(MAT4_IDENTITY);
    let mut inst = Instances::default();
    if ctx.bool("Separate Children")? {
        let reset = ctx.bool("Reset Children")?;
        let mut entries: Vec<(String, InstanceReference, Mat4f)> = Vec::new();
        for ch in &c.children {
            let child = look.collection(ch)?;
            let mut t = MAT4_IDENTITY;
            if !reset {
                t = translation(child.instance_offset);
                if relative {
                    t = mat4_mul(&world_to_self, &t);
                } else {
                    t = mat4_mul(&translation(neg(c.instance_offset)), &t);
                }
            }
            entries.push((ch.clone(), look.collection_reference(child)?, t));
        }
        for o in &c.objects {
            let mut t = MAT4_IDENTITY;
            if !reset {
                let base = if relative {
                    world_to_self
                } else {
                    translation(neg(c.instance_offset))
                };
                t = mat4_mul(&base, &look.world(o)?);
            }
            entries.push((o.clone(), look.object(o)?, t));
        }
        // A stable sort, as std::sort is not: equal names cannot occur (IDs are unique).
        entries.sort_by(|a, b| natural_cmp(&a.0, &b.0));
        for (_, r, t) in entries {
            let h = inst.add_reference(r);
            inst.handles.push(h);
            inst.transforms.push(t);
        }
    } else {
        let t = if relative {
            mat4_mul(&world_to_self, &translation(c.instance_offset))
        } else {
            MAT4_IDENTITY
        };
        let h = inst.add_reference(look.collection_reference(c)?);
        inst.handles.push(h);
        inst.transforms.push(t);
    }
    Ok(outputs([(
        "Instances",
        SocketValue::Geometry(GeometrySet::from_instances(inst)),
    )]))
}

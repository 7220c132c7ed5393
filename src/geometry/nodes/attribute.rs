//! Attribute nodes: Store Named Attribute, Capture Attribute, Named Attribute, and the
//! `store` operation they and modifier output attributes share.

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field, FieldContext};
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::modify_geometry_sets;

/// Writes `field` as attribute `id` on `domain` of every top-level component that has the
/// domain: selected elements get the field's value, the others keep the attribute's old
/// values (moved to this domain and type) or the type's default.
pub fn store(
    g: &mut GeometrySet,
    id: &AttrId,
    domain: Domain,
    field: &Field,
    selection: &Field,
    ty: Option<DataType>,
) -> Result<(), String> {
    let ty = ty.unwrap_or_else(|| field.data_type());
    let is_position = id.name() == Some("position");
    let compute = |comp: ComponentRef| -> Result<Option<Array>, String> {
        if !comp.has_domain(domain) {
            return Ok(None);
        }
        let n = comp.domain_size(domain);
        let ctx = FieldContext::new(comp);
        let sel = ctx.eval(selection, domain, DataType::Bool)?;
        let values = ctx.eval(field, domain, ty)?;
        let sel = sel.as_bool();
        if sel.iter().all(|s| *s) {
            return Ok(Some(values));
        }
        let mut base = match comp.attribute(id) {
            Some((d, a)) => comp.adapt(&a, d, domain).convert(ty),
            None => Array::zeros(ty, n),
        };
        for i in 0..n {
            if sel[i] {
                base.set(i, values.get(i));
            }
        }
        Ok(Some(base))
    };
    if let Some(m) = g.mesh.clone() {
        if let Some(a) = compute(ComponentRef::Mesh(&m))? {
            let mm = g.mesh_mut().unwrap();
            if is_position {
                if domain != Domain::Point {
                    return Err("position can only be stored on points".into());
                }
                mm.positions = a.as_vector().into_owned();
                mm.custom_vert_normals = None;
            } else {
                mm.attributes.set(id.clone(), domain, a);
            }
        }
    }
    if let Some(p) = g.points.clone() {
        if let Some(a) = compute(ComponentRef::Points(&p))? {
            let pp = g.points_mut().unwrap();
            if is_position {
                pp.positions = a.as_vector().into_owned();
            } else {
                pp.attributes.set(id.clone(), domain, a);
            }
        }
    }
    if let Some(c) = g.curves.clone() {
        if let Some(a) = compute(ComponentRef::Curves(&c))? {
            let cc = g.curves_mut().unwrap();
            if is_position {
                cc.positions = a.as_vector().into_owned();
            } else {
                cc.attributes.set(id.clone(), domain, a);
            }
        }
    }
    if let Some(i) = g.instances.clone() {
        if let Some(a) = compute(ComponentRef::Instances(&i))? {
            let ii = g.instances_mut().unwrap();
            if is_position {
                for (t, p) in ii.transforms.iter_mut().zip(a.as_vector().iter()) {
                    t[3][0] = p[0];
                    t[3][1] = p[1];
                    t[3][2] = p[2];
                }
            } else {
                ii.attributes.set(id.clone(), domain, a);
            }
        }
    }
    Ok(())
}

fn domain_prop(ctx: &NodeCtx) -> Result<Domain, GeometryError> {
    let d = ctx.prop_str("domain")?;
    Domain::parse(d).ok_or_else(|| ctx.err(format!("unknown domain {d}")))
}

/// The enabled input named `name` (identifiers of typed sockets vary by Blender version).
fn input_by_name(ctx: &NodeCtx, name: &str) -> Option<String> {
    ctx.flat()
        .inputs
        .iter()
        .find(|i| i.socket.name == name)
        .map(|i| i.socket.identifier.clone())
}

pub fn store_named_attribute(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let name = ctx.string("Name")?;
    let dt = ctx.prop_str("data_type")?;
    let ty = DataType::parse(dt).ok_or_else(|| ctx.err(format!("data type {dt} not supported")))?;
    let domain = domain_prop(ctx)?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let vid = input_by_name(ctx, "Value").ok_or_else(|| ctx.err("no Value input"))?;
    let value = ctx.field(&vid, ty.socket_type())?;
    if name.is_empty() {
        return Ok(outputs([("Geometry", SocketValue::Geometry(g))]));
    }
    let id = AttrId::Named(name);
    let r = if domain == Domain::Instance {
        store(&mut g, &id, domain, &value, &sel, Some(ty))
    } else {
        modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
            store(s, &id, domain, &value, &sel, Some(ty))
        })
    };
    r.map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", SocketValue::Geometry(g))]))
}

pub fn capture_attribute(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let domain = domain_prop(ctx)?;
    let mut out = Outputs::new();
    let all = Field::Constant(super::super::types::Value::Bool(true));
    for inp in ctx.flat().inputs.iter().skip(1) {
        let id_s = &inp.socket.identifier;
        if inp.socket.kind == "CUSTOM" {
            continue;
        }
        let Some(ty) = DataType::from_socket(&inp.socket.kind) else {
            return Err(ctx.err(format!("cannot capture a {} socket", inp.socket.kind)));
        };
        let f = ctx.field(id_s, ty)?;
        let out_socket = ctx.node().outputs.iter().find(|o| {
            &o.identifier == id_s || o.name == inp.socket.name && o.kind == inp.socket.kind
        });
        let Some(out_socket) = out_socket else {
            continue;
        };
        let id = AttrId::anonymous(&format!("Capture {}", inp.socket.name));
        store(&mut g, &id, domain, &f, &all, Some(ty)).map_err(|e| ctx.err(e))?;
        out.insert(
            out_socket.identifier.clone(),
            SocketValue::Field(Field::input(AttributeInput { id, ty })),
        );
    }
    out.insert("Geometry".into(), SocketValue::Geometry(g));
    Ok(out)
}

pub fn named_attribute(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dt = ctx.prop_str("data_type")?;
    let ty = DataType::parse(dt).ok_or_else(|| ctx.err(format!("data type {dt} not supported")))?;
    let name = ctx.string("Name")?;
    let id = AttrId::Named(name);
    let attr = Field::input(AttributeInput {
        id: id.clone(),
        ty: ty.socket_type(),
    });
    let exists = Field::input(ExistsInput { id });
    let mut out = Outputs::new();
    for o in ctx.node().outputs.iter() {
        if o.name == "Attribute" && o.enabled {
            out.insert(o.identifier.clone(), SocketValue::Field(attr.clone()));
        }
    }
    out.insert("Exists".into(), SocketValue::Field(exists));
    Ok(out)
}

/// Whether an attribute exists on the component (Named Attribute's "Exists").
#[derive(Debug)]
struct ExistsInput {
    id: AttrId,
}
impl super::super::field::FieldInput for ExistsInput {
    fn data_type(&self) -> DataType {
        DataType::Bool
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let e = ctx.component.attribute(&self.id).is_some();
        Ok(Array::Bool(vec![e; ctx.component.domain_size(domain)]))
    }
}

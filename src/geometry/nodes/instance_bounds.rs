//! Instance Bounds (`node_geo_input_instance_bounds`): per instance, the Min or Max corner
//! of its referenced geometry's box, instances inside it left out (zero when it has no
//! real geometry). Meshes and, without Use Radius, point clouds are evaluated; curves
//! (their evaluated points) and point radii are refused by name.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::instances::InstanceReference;
use super::super::math::V3;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct InstanceBounds {
    use_radius: bool,
    max: bool,
}

fn bounds(g: &GeometrySet, use_radius: bool) -> Result<Option<(V3, V3)>, String> {
    if g.curves.is_some() {
        return Err("Instance Bounds of curves (their evaluated points) is not evaluated".into());
    }
    if use_radius && g.points.is_some() {
        return Err("Instance Bounds with Use Radius on a point cloud is not evaluated".into());
    }
    let mut mn = [f32::INFINITY; 3];
    let mut mx = [f32::NEG_INFINITY; 3];
    let mut any = false;
    let ps = g.mesh.iter().map(|m| &m.positions);
    let ps = ps.chain(g.points.iter().map(|p| &p.positions));
    for p in ps.flatten() {
        any = true;
        for k in 0..3 {
            mn[k] = mn[k].min(p[k]);
            mx[k] = mx[k].max(p[k]);
        }
    }
    Ok(any.then_some((mn, mx)))
}

impl FieldInput for InstanceBounds {
    fn data_type(&self) -> DataType {
        DataType::Vector
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let ComponentRef::Instances(inst) = ctx.component else {
            return Ok(Array::zeros(DataType::Vector, n));
        };
        // Only the references some instance uses are measured.
        let mut per_ref: Vec<Option<V3>> = vec![None; inst.references.len()];
        let mut out = Vec::with_capacity(inst.len());
        for &h in &inst.handles {
            let h = h as usize;
            if per_ref[h].is_none() {
                let b = match &inst.references[h] {
                    InstanceReference::Geometry(g) | InstanceReference::Object(_, g) => {
                        bounds(g, self.use_radius)?
                    }
                    InstanceReference::None => None,
                };
                per_ref[h] = Some(b.map_or([0.0; 3], |(lo, hi)| if self.max { hi } else { lo }));
            }
            out.push(per_ref[h].unwrap_or_default());
        }
        Ok(Array::Vector(out))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Instance)
    }
}

pub fn instance_bounds(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let use_radius = ctx.bool("Use Radius")?;
    let f = |max| SocketValue::Field(Field::input(InstanceBounds { use_radius, max }));
    Ok(outputs([("Min", f(false)), ("Max", f(true))]))
}

//! Point cloud and instance nodes (`node_geo_points`, `node_geo_set_point_radius`,
//! `node_geo_set_id`, `node_geo_instances_to_points`, `node_geo_input_instance_*`):
//! Points, Set Point Radius, Set ID, Instances to Points, and the Instance Transform,
//! Rotation and Scale inputs.

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::math::{mat3_to_quat_checked, Mat3f, Mat4f};
use super::super::pointcloud::PointCloud;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::attribute::store;
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

/// Blender's default `radius` of point cloud points.
const DEFAULT_RADIUS: f32 = 0.01;

/// Points: `Count` points, their position and radius fields evaluated with the point index
/// as the only context (no attributes exist yet, so ID reads the index).
pub fn points(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let count = ctx.int("Count")?;
    if count <= 0 {
        return Ok(outputs([("Geometry", geo(GeometrySet::default()))]));
    }
    let pos = ctx.field("Position", DataType::Vector)?;
    let radius = ctx.field("Radius", DataType::Float)?;
    let n = count as usize;
    let mut pc = PointCloud {
        positions: vec![[0.0; 3]; n],
        ..Default::default()
    };
    let r = eval_fields(
        ComponentRef::Points(&pc),
        Domain::Point,
        &[(&pos, DataType::Vector), (&radius, DataType::Float)],
    )
    .map_err(|e| ctx.err(e))?;
    pc.positions = r[0].as_vector().into_owned();
    pc.attributes
        .set(AttrId::named("radius"), Domain::Point, r[1].clone());
    Ok(outputs([(
        "Geometry",
        geo(GeometrySet {
            points: Some(Arc::new(pc)),
            ..Default::default()
        }),
    )]))
}

pub fn set_point_radius(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Points")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let radius = ctx.field("Radius", DataType::Float)?;
    let id = AttrId::named("radius");
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(p) = s.points_mut() else {
            return Ok(());
        };
        // Unselected points keep their radius, Blender's default where there is none.
        if p.attributes.get(&id).is_none() {
            let n = p.len();
            p.attributes.set(
                id.clone(),
                Domain::Point,
                Array::Float(vec![DEFAULT_RADIUS; n]),
            );
        }
        let only_points = &mut GeometrySet {
            points: s.points.take(),
            ..Default::default()
        };
        let r = store(
            only_points,
            &id,
            Domain::Point,
            &radius,
            &sel,
            Some(DataType::Float),
        );
        s.points = only_points.points.take();
        r
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Points", geo(g))]))
}

/// Set ID: the `id` attribute of the top-level mesh, point cloud and curve points and of
/// the instances (not inside instances), unselected elements keeping theirs (or 0).
pub fn set_id(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let value = ctx.field("ID", DataType::Int)?;
    let id = AttrId::named("id");
    store(
        &mut g,
        &id,
        Domain::Point,
        &value,
        &sel,
        Some(DataType::Int),
    )
    .and_then(|_| {
        store(
            &mut g,
            &id,
            Domain::Instance,
            &value,
            &sel,
            Some(DataType::Int),
        )
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", geo(g))]))
}

/// Instances to Points: a point per selected instance at its Position (the translation
/// unless linked) with its Radius; the instances' attributes come along; everything else
/// in the geometry is dropped.
pub fn instances_to_points(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Instances")?;
    let Some(inst) = g.instances.clone() else {
        return Ok(outputs([("Points", geo(GeometrySet::default()))]));
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    let pos = match ctx.input("Position")? {
        SocketValue::Field(f) if ctx.flat().input("Position").is_some_and(linked) => f,
        _ => Field::input(super::super::field::PositionInput),
    };
    let radius = ctx.field("Radius", DataType::Float)?;
    let r = eval_fields(
        ComponentRef::Instances(&inst),
        Domain::Instance,
        &[
            (&sel, DataType::Bool),
            (&pos, DataType::Vector),
            (&radius, DataType::Float),
        ],
    )
    .map_err(|e| ctx.err(e))?;
    let sel = r[0].as_bool();
    let idx: Vec<usize> = (0..sel.len()).filter(|&i| sel[i]).collect();
    if idx.is_empty() {
        return Ok(outputs([("Points", geo(GeometrySet::default()))]));
    }
    let pos = r[1].as_vector();
    let mut pc = PointCloud {
        positions: idx.iter().map(|&i| pos[i]).collect(),
        ..Default::default()
    };
    for a in inst.attributes.iter() {
        if a.id
            .name()
            .is_some_and(|n| n.starts_with('.') || n == "radius")
        {
            continue;
        }
        pc.attributes
            .set(a.id.clone(), Domain::Point, a.data.gather(&idx));
    }
    pc.attributes
        .set(AttrId::named("radius"), Domain::Point, r[2].gather(&idx));
    Ok(outputs([(
        "Points",
        geo(GeometrySet {
            points: Some(Arc::new(pc)),
            ..Default::default()
        }),
    )]))
}

fn linked(i: &crate::nodes::graph::FlatInput) -> bool {
    !i.sources.iter().all(|s| {
        matches!(
            s,
            crate::nodes::graph::Source::Default(_) | crate::nodes::graph::Source::Nothing
        )
    })
}

#[derive(Debug, Clone, Copy)]
enum InstanceValue {
    Transform,
    Rotation,
    Scale,
}

#[derive(Debug)]
struct InstanceInput(InstanceValue);

/// The 3x3 part's columns normalized, and their lengths.
fn columns(m: &Mat4f) -> (Mat3f, [f32; 3]) {
    let mut r = [[0.0f32; 3]; 3];
    let mut s = [0.0f32; 3];
    for c in 0..3 {
        let v = [m[c][0], m[c][1], m[c][2]];
        s[c] = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if s[c] > 0.0 {
            r[c] = v.map(|x| x / s[c]);
        }
    }
    (r, s)
}

fn is_negative(m: &Mat3f) -> bool {
    let c = [
        m[0][1] * m[1][2] - m[0][2] * m[1][1],
        m[0][2] * m[1][0] - m[0][0] * m[1][2],
        m[0][0] * m[1][1] - m[0][1] * m[1][0],
    ];
    c[0] * m[2][0] + c[1] * m[2][1] + c[2] * m[2][2] < 0.0
}

impl FieldInput for InstanceInput {
    fn data_type(&self) -> DataType {
        match self.0 {
            InstanceValue::Transform => DataType::Matrix,
            InstanceValue::Rotation => DataType::Quaternion,
            InstanceValue::Scale => DataType::Vector,
        }
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let ComponentRef::Instances(inst) = ctx.component else {
            return Ok(Array::zeros(self.data_type(), n));
        };
        let t = &inst.transforms;
        Ok(match self.0 {
            InstanceValue::Transform => Array::Matrix(t.clone()),
            // `to_quaternion(normalize(float3x3(transform)))`.
            InstanceValue::Rotation => Array::Quaternion(
                t.iter()
                    .map(|m| mat3_to_quat_checked(&columns(m).0))
                    .collect(),
            ),
            // `to_scale<true>`: the column lengths, negated for a mirroring transform.
            InstanceValue::Scale => Array::Vector(
                t.iter()
                    .map(|m| {
                        let (r, s) = columns(m);
                        let m3 = [
                            [m[0][0], m[0][1], m[0][2]],
                            [m[1][0], m[1][1], m[1][2]],
                            [m[2][0], m[2][1], m[2][2]],
                        ];
                        let _ = r;
                        if is_negative(&m3) {
                            s.map(|x| -x)
                        } else {
                            s
                        }
                    })
                    .collect(),
            ),
        })
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Instance)
    }
}

/// The Instance Transform field (also Set Instance Transform's unlinked Transform).
pub fn instance_transform_field() -> Field {
    Field::input(InstanceInput(InstanceValue::Transform))
}

pub fn instance_transform(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Transform",
        SocketValue::Field(Field::input(InstanceInput(InstanceValue::Transform))),
    )]))
}

pub fn instance_rotation(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Rotation",
        SocketValue::Field(Field::input(InstanceInput(InstanceValue::Rotation))),
    )]))
}

pub fn instance_scale(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Scale",
        SocketValue::Field(Field::input(InstanceInput(InstanceValue::Scale))),
    )]))
}

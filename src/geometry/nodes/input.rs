//! Input nodes: Position, Index, Normal, ID, Object Info, Self Object, Scene Time,
//! Material, String, Is Viewport, Color, Object, Collection.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{Field, IdInput, IndexInput, NormalInput, PositionInput};
use super::super::instances::InstanceReference;
use super::super::math::{mat4_invert, mat4_mul, mat4_to_quat_normalized, Mat4f, MAT4_IDENTITY};
use super::super::set::GeometrySet;
use super::super::types::Value;
use super::super::value::SocketValue;
use super::geometry_ops::{single_instance, transform_set};

fn f(x: Field) -> SocketValue {
    SocketValue::Field(x)
}

pub fn position(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Position", f(Field::input(PositionInput)))]))
}
pub fn index(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Index", f(Field::input(IndexInput)))]))
}
pub fn normal(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Normal", f(Field::input(NormalInput)))]))
}
pub fn id(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("ID", f(Field::input(IdInput)))]))
}

pub fn self_object(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Self Object",
        SocketValue::Object(Some(ctx.ev.object.name.clone())),
    )]))
}

pub fn scene_time(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = &ctx.session().scene.file.scene;
    let ctime = crate::anim::ctime(ctx.session().frame);
    let fps = (s.fps / s.fps_base) as f32;
    Ok(outputs([
        ("Seconds", SocketValue::float(ctime / fps)),
        ("Frame", SocketValue::float(ctime)),
    ]))
}

pub fn input_material(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx
        .prop("material")
        .and_then(|v| v.get("name"))
        .and_then(|v| v.as_str())
        .map(str::to_string);
    Ok(outputs([("Material", SocketValue::Material(m))]))
}

/// An ID input node's datablock (`object`, `collection`), as its socket would hold it.
pub(super) fn id_input(
    ctx: &NodeCtx,
    prop: &str,
    kind: &str,
    output: &str,
) -> Result<Outputs, GeometryError> {
    let v = match ctx.prop(prop) {
        Some(j) => SocketValue::from_json(kind, j).map_err(|e| ctx.err(e))?,
        None => SocketValue::zero(kind),
    };
    Ok(outputs([(output, v)]))
}

/// Object (`node_geo_input_object`): the node's object, for Object Info and others.
pub fn input_object(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    id_input(ctx, "object", "OBJECT", "Object")
}

/// Collection (`node_geo_input_collection`).
pub fn input_collection(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    id_input(ctx, "collection", "COLLECTION", "Collection")
}

/// Color (`node_input_color`): the node's RGBA value as it is stored (scene linear).
pub fn input_color(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let v = ctx
        .prop("value")
        .ok_or_else(|| ctx.err("property \"value\" missing"))?;
    let c = SocketValue::from_json("RGBA", v).map_err(|e| ctx.err(e))?;
    Ok(outputs([("Color", c)]))
}

pub fn input_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = ctx
        .prop("string")
        .and_then(|v| v.as_str())
        .unwrap_or_default()
        .to_string();
    Ok(outputs([("String", SocketValue::String(s))]))
}

pub fn is_viewport(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    // blendsynth renders: the final render's answer.
    Ok(outputs([(
        "Is Viewport",
        f(Field::Constant(Value::Bool(false))),
    )]))
}

/// Location, rotation and scale of a matrix (`to_loc_rot_scale_safe`).
fn decompose(m: &Mat4f) -> ([f32; 3], [f32; 4], [f32; 3]) {
    let loc = [m[3][0], m[3][1], m[3][2]];
    let len = |c: usize| (m[c][0] * m[c][0] + m[c][1] * m[c][1] + m[c][2] * m[c][2]).sqrt();
    let mut scale = [len(0), len(1), len(2)];
    let det = m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
    let mut r = *m;
    if det < 0.0 {
        scale = [-scale[0], -scale[1], -scale[2]];
        for c in 0..3 {
            for i in 0..3 {
                r[c][i] = -r[c][i];
            }
        }
    }
    (loc, mat4_to_quat_normalized(&r), scale)
}

pub fn object_info(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let SocketValue::Object(obj) = ctx.input("Object")? else {
        return Err(ctx.err("Object input is not an object"));
    };
    let relative = ctx.prop_str("transform_space")? == "RELATIVE";
    let Some(name) = obj else {
        return Ok(ctx
            .node()
            .outputs
            .iter()
            .map(|s| (s.identifier.clone(), SocketValue::zero(&s.kind)))
            .collect());
    };
    let session = ctx.session();
    let world = session
        .world_matrix(&name)
        .ok_or_else(|| ctx.err(format!("object {name:?} is not in the export")))?;
    let self_world = session
        .world_matrix(&ctx.ev.object.name)
        .unwrap_or(MAT4_IDENTITY);
    let self_inv = mat4_invert(&self_world).unwrap_or(MAT4_IDENTITY);
    let transform = mat4_mul(&self_inv, &world);
    let out_t = if relative { transform } else { world };
    let (loc, rot, scale) = decompose(&out_t);
    let as_instance = ctx.bool("As Instance")?;
    // Its own object gives its transform but no geometry (Blender: "Geometry cannot be
    // retrieved from the modifier object").
    let g = if name == ctx.ev.object.name {
        GeometrySet::default()
    } else if as_instance {
        let geometry = session.evaluate_object(&name).map_err(|e| ctx.err(e))?;
        let t = if relative { transform } else { MAT4_IDENTITY };
        GeometrySet::from_instances(single_instance(
            InstanceReference::Object(name.clone(), geometry),
            t,
        ))
    } else {
        let mut g = session.evaluate_object(&name).map_err(|e| ctx.err(e))?;
        if relative {
            transform_set(&mut g, &transform);
        }
        g
    };
    let mut o = outputs([
        ("Location", f(Field::Constant(Value::Vector(loc)))),
        ("Rotation", f(Field::Constant(Value::Quaternion(rot)))),
        ("Scale", f(Field::Constant(Value::Vector(scale)))),
        ("Geometry", SocketValue::Geometry(g)),
    ]);
    o.insert("Transform".into(), f(Field::Constant(Value::Matrix(out_t))));
    Ok(o)
}

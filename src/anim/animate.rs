//! Applies every ID's animation (its action's F-curves) at a frame to an evaluated copy of
//! the scene's datablocks, as Blender's animation system writes values through RNA:
//! muted and empty F-curves are skipped, booleans and enums are discrete, integers rounded.
//!
//! Handled targets: object transforms (`location`, `rotation_*`, `scale`, the deltas),
//! constraint settings (`constraints["X"].influence`, `.offset`, ...), object custom
//! properties, any curve / camera / light setting kept in their RNA maps (`eval_time`,
//! `lens`, `dof.focus_distance`, ...) and curve control points. Anything else is listed
//! in `unapplied` rather than silently dropped.

use serde_json::Value;

use super::error::AnimError;
use super::fcurve::{CompiledFCurve, ValueKind};
use crate::scene::datapath::{parse, Token};
use crate::scene::{quote, AnimData, Camera, Curve, FCurve, Light, Object, Rna, SceneFile};

/// Datablocks animation can change, copied from the scene file.
#[derive(Debug, Clone)]
pub struct Datablocks {
    pub objects: Vec<Object>,
    pub curves: Vec<Curve>,
    pub cameras: Vec<Camera>,
    pub lights: Vec<Light>,
}

impl Datablocks {
    pub fn from_file(f: &SceneFile) -> Self {
        Datablocks {
            objects: f.objects.clone(),
            curves: f.curves.clone(),
            cameras: f.cameras.clone(),
            lights: f.lights.clone(),
        }
    }
}

/// Blender's scene time for a frame: the integer frame plus the subframe, summed in single
/// precision (large frames have coarse float steps, so this matters).
pub fn ctime(frame: f64) -> f32 {
    let whole = frame.floor();
    whole as f32 + (frame - whole) as f32
}

fn fcurve_label(ad: &AnimData, fc: &FCurve) -> String {
    format!("{} fcurve {}[{}]", ad.id_path, fc.data_path, fc.array_index)
}

/// Applies all animation in `anim` at `frame`. Returns the F-curves it could not map onto
/// anything (as "id_path data_path[index]" strings).
pub fn apply(
    anim: &[AnimData],
    frame: f64,
    data: &mut Datablocks,
) -> Result<Vec<String>, AnimError> {
    let t = ctime(frame);
    let mut unapplied = Vec::new();
    for ad in anim {
        for fc in &ad.fcurves {
            let label = fcurve_label(ad, fc);
            let tokens = parse(&fc.data_path).map_err(|e| AnimError::new(label.clone(), e))?;
            let Some(kind) = value_kind(ad, &tokens, fc.array_index, data) else {
                unapplied.push(label);
                continue;
            };
            let c = CompiledFCurve::new(fc, kind).map_err(|e| e.within(&label))?;
            if c.mute || c.is_empty() {
                continue;
            }
            let v = c.eval(t) as f64;
            if !write(ad, &tokens, fc.array_index, v, data) {
                unapplied.push(label);
            }
        }
        for d in &ad.drivers {
            let label = format!("{} driver {}[{}]", ad.id_path, d.data_path, d.array_index);
            let tokens = parse(&d.data_path).map_err(|e| AnimError::new(label.clone(), e))?;
            // A driver on something that moves objects would be silently wrong if skipped.
            let moves = matches!(ad.id_type.as_str(), "OBJECT" | "CURVE");
            if moves && !d.mute && value_kind(ad, &tokens, d.array_index, data).is_some() {
                return Err(AnimError::new(label, "drivers are not supported"));
            }
            unapplied.push(label);
        }
    }
    Ok(unapplied)
}

const OBJECT_VECTORS: &[(&str, usize)] = &[
    ("location", 3),
    ("rotation_euler", 3),
    ("rotation_quaternion", 4),
    ("rotation_axis_angle", 4),
    ("scale", 3),
    ("delta_location", 3),
    ("delta_rotation_euler", 3),
    ("delta_rotation_quaternion", 4),
    ("delta_scale", 3),
];

fn object_slot<'a>(o: &'a mut Object, name: &str) -> Option<&'a mut [f64]> {
    Some(match name {
        "location" => &mut o.location[..],
        "rotation_euler" => &mut o.rotation_euler[..],
        "rotation_quaternion" => &mut o.rotation_quaternion[..],
        "rotation_axis_angle" => &mut o.rotation_axis_angle.get_or_insert([0.0, 0.0, 1.0, 0.0])[..],
        "scale" => &mut o.scale[..],
        "delta_location" => &mut o.delta_location.get_or_insert([0.0; 3])[..],
        "delta_rotation_euler" => &mut o.delta_rotation_euler.get_or_insert([0.0; 3])[..],
        "delta_rotation_quaternion" => &mut o
            .delta_rotation_quaternion
            .get_or_insert([1.0, 0.0, 0.0, 0.0])[..],
        "delta_scale" => &mut o.delta_scale.get_or_insert([1.0; 3])[..],
        _ => return None,
    })
}

fn kind_of_json(v: &Value) -> Option<ValueKind> {
    ValueKind::of_json(v)
}

/// Follows `tokens` inside an RNA map (nested structs, arrays by `index`).
fn rna_slot<'a>(map: &'a mut Rna, tokens: &[Token], index: usize) -> Option<&'a mut Value> {
    let (Token::Prop(first), rest) = tokens.split_first()? else {
        return None;
    };
    let mut v = map.get_mut(first)?;
    for t in rest {
        v = match t {
            Token::Prop(p) => v.as_object_mut()?.get_mut(p)?,
            Token::Index(i) => v.as_array_mut()?.get_mut(*i)?,
            Token::Key(_) => return None,
        };
    }
    if v.is_array() {
        v = v.as_array_mut()?.get_mut(index)?;
    }
    Some(v)
}

fn rna_kind(map: &mut Rna, tokens: &[Token], index: usize) -> Option<ValueKind> {
    kind_of_json(rna_slot(map, tokens, index)?)
}

fn rna_write(map: &mut Rna, tokens: &[Token], index: usize, v: f64) -> bool {
    let Some(slot) = rna_slot(map, tokens, index) else {
        return false;
    };
    *slot = match slot {
        // Blender's ANIMSYS_FLOAT_AS_BOOL.
        Value::Bool(_) => Value::Bool(v as f32 > 1.0 - f32::EPSILON),
        Value::Number(n) if !n.is_f64() => Value::from(v as i64),
        Value::Number(_) => serde_json::Number::from_f64(v)
            .map(Value::Number)
            .unwrap_or(Value::Null),
        _ => return false,
    };
    true
}

fn find<'a, T>(list: &'a mut [T], name: &str, get: impl Fn(&T) -> &str) -> Option<&'a mut T> {
    list.iter_mut().find(|x| get(x) == name)
}

/// The kind of value the target holds, or None when we cannot map the path.
fn value_kind(
    ad: &AnimData,
    tokens: &[Token],
    index: usize,
    data: &mut Datablocks,
) -> Option<ValueKind> {
    match ad.id_type.as_str() {
        "OBJECT" => {
            let o = find(&mut data.objects, &ad.id_name, |o| &o.name)?;
            match tokens {
                [Token::Prop(p)]
                    if OBJECT_VECTORS.iter().any(|(n, len)| n == p && index < *len) =>
                {
                    Some(ValueKind::default())
                }
                [Token::Prop(p)] if p == "hide_render" || p == "hide_viewport" => Some(ValueKind {
                    discrete: true,
                    integer: true,
                }),
                [Token::Prop(c), Token::Key(name), Token::Prop(p)] if c == "constraints" => {
                    let con = o.constraints.iter_mut().find(|c| &c.name == name)?;
                    match p.as_str() {
                        "influence" => Some(ValueKind::default()),
                        "mute" => Some(ValueKind {
                            discrete: true,
                            integer: true,
                        }),
                        _ => rna_kind(&mut con.properties, &tokens[2..], index),
                    }
                }
                [Token::Key(k)] => {
                    let v = o.custom_properties.get_mut(k)?;
                    let v = if v.is_array() {
                        v.as_array_mut()?.get_mut(index)?
                    } else {
                        v
                    };
                    kind_of_json(v)
                }
                _ => None,
            }
        }
        "CURVE" => {
            let c = find(&mut data.curves, &ad.id_name, |c| &c.name)?;
            match tokens {
                [Token::Prop(s), Token::Index(i), Token::Prop(kind), Token::Index(j), Token::Prop(field)]
                    if s == "splines" =>
                {
                    let sp = c.splines.get(*i)?;
                    let ok = match kind.as_str() {
                        "bezier_points" => {
                            sp.bezier_points.get(*j).is_some()
                                && matches!(
                                    field.as_str(),
                                    "co" | "handle_left" | "handle_right" | "radius" | "tilt"
                                )
                        }
                        "points" => {
                            sp.points.get(*j).is_some()
                                && matches!(field.as_str(), "co" | "radius" | "tilt" | "weight")
                        }
                        _ => false,
                    };
                    ok.then(ValueKind::default)
                }
                _ => rna_kind(&mut c.properties, tokens, index),
            }
        }
        "CAMERA" => rna_kind(
            &mut find(&mut data.cameras, &ad.id_name, |c| &c.name)?.properties,
            tokens,
            index,
        ),
        "LIGHT" => rna_kind(
            &mut find(&mut data.lights, &ad.id_name, |c| &c.name)?.properties,
            tokens,
            index,
        ),
        _ => None,
    }
}

fn write(ad: &AnimData, tokens: &[Token], index: usize, v: f64, data: &mut Datablocks) -> bool {
    match ad.id_type.as_str() {
        "OBJECT" => {
            let Some(o) = find(&mut data.objects, &ad.id_name, |o| &o.name) else {
                return false;
            };
            match tokens {
                [Token::Prop(p)] if p == "hide_render" => {
                    o.hide_render = v as f32 > 1.0 - f32::EPSILON;
                    true
                }
                [Token::Prop(p)] if p == "hide_viewport" => {
                    o.hide_viewport = v as f32 > 1.0 - f32::EPSILON;
                    true
                }
                [Token::Prop(p)] => match object_slot(o, p).and_then(|s| s.get_mut(index)) {
                    Some(slot) => {
                        *slot = v;
                        true
                    }
                    None => false,
                },
                [Token::Prop(c), Token::Key(name), Token::Prop(p)] if c == "constraints" => {
                    let Some(con) = o.constraints.iter_mut().find(|c| &c.name == name) else {
                        return false;
                    };
                    match p.as_str() {
                        // Blender clamps influence to its RNA range.
                        "influence" => {
                            con.influence = v.clamp(0.0, 1.0);
                            true
                        }
                        "mute" => {
                            con.mute = v as f32 > 1.0 - f32::EPSILON;
                            true
                        }
                        _ => rna_write(&mut con.properties, &tokens[2..], index, v),
                    }
                }
                [Token::Key(k)] => {
                    let Some(slot) = o.custom_properties.get_mut(k) else {
                        return false;
                    };
                    let slot = if slot.is_array() {
                        match slot.as_array_mut().and_then(|a| a.get_mut(index)) {
                            Some(s) => s,
                            None => return false,
                        }
                    } else {
                        slot
                    };
                    *slot = match slot {
                        Value::Bool(_) => Value::Bool(v as f32 > 1.0 - f32::EPSILON),
                        Value::Number(n) if !n.is_f64() => Value::from(v as i64),
                        _ => serde_json::Number::from_f64(v)
                            .map(Value::Number)
                            .unwrap_or(Value::Null),
                    };
                    true
                }
                _ => false,
            }
        }
        "CURVE" => {
            let Some(c) = find(&mut data.curves, &ad.id_name, |c| &c.name) else {
                return false;
            };
            match tokens {
                [Token::Prop(s), Token::Index(i), Token::Prop(kind), Token::Index(j), Token::Prop(field)]
                    if s == "splines" =>
                {
                    let Some(sp) = c.splines.get_mut(*i) else {
                        return false;
                    };
                    if kind == "bezier_points" {
                        let Some(p) = sp.bezier_points.get_mut(*j) else {
                            return false;
                        };
                        let slot = match field.as_str() {
                            "co" => p.co.get_mut(index),
                            "handle_left" => p.handle_left.get_mut(index),
                            "handle_right" => p.handle_right.get_mut(index),
                            "radius" => Some(&mut p.radius),
                            "tilt" => Some(&mut p.tilt),
                            _ => None,
                        };
                        slot.map(|s| *s = v).is_some()
                    } else {
                        let Some(p) = sp.points.get_mut(*j) else {
                            return false;
                        };
                        let slot = match field.as_str() {
                            "co" => p.co.get_mut(index),
                            "radius" => Some(&mut p.radius),
                            "tilt" => Some(&mut p.tilt),
                            "weight" => {
                                // The NURBS weight is also the fourth coordinate.
                                p.co[3] = v;
                                Some(&mut p.weight)
                            }
                            _ => None,
                        };
                        slot.map(|s| *s = v).is_some()
                    }
                }
                _ => rna_write(&mut c.properties, tokens, index, v),
            }
        }
        "CAMERA" => find(&mut data.cameras, &ad.id_name, |c| &c.name)
            .is_some_and(|c| rna_write(&mut c.properties, tokens, index, v)),
        "LIGHT" => find(&mut data.lights, &ad.id_name, |c| &c.name)
            .is_some_and(|c| rna_write(&mut c.properties, tokens, index, v)),
        _ => false,
    }
}

/// `objects["Name"]`-style label for errors.
pub fn object_label(name: &str) -> String {
    format!("objects[{}]", quote(name))
}

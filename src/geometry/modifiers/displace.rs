//! The Displace modifier without a texture (`MOD_displace.cc`): every vertex moves by
//! `strength * (1 - mid_level)` (clamped to +-10000) along X, Y or Z (of the object, or of
//! the world when the space is Global) or its normal. Legacy textures, custom normals and
//! vertex groups are not evaluated: `unsupported` names them.

use super::super::set::GeometrySet;
use super::{float, id_name, text, Context, Props};

pub fn unsupported(p: &Props) -> Option<String> {
    let mut out = Vec::new();
    if let Some(tex) = id_name(p, "texture") {
        out.push(format!(
            "Texture {tex:?} (legacy textures are not evaluated)"
        ));
    }
    let group = text(p, "vertex_group").unwrap_or("");
    if !group.is_empty() {
        out.push(format!(
            "Vertex Group {group:?} (vertex groups are not exported)"
        ));
    }
    match text(p, "direction") {
        Ok("X" | "Y" | "Z" | "NORMAL" | "RGB_TO_XYZ") => {}
        Ok("CUSTOM_NORMAL") => {
            out.push("Direction Custom Normal (custom normals are not exported)".into())
        }
        other => out.push(format!("direction {:?}", other.ok())),
    }
    match text(p, "space") {
        Ok("LOCAL" | "GLOBAL") => {}
        other => out.push(format!("space {:?}", other.ok())),
    }
    (!out.is_empty()).then(|| out.join(", "))
}

pub fn apply(p: &Props, ctx: &Context, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let strength = float(p, "strength")?;
    let direction = text(p, "direction")?;
    // Without a texture RGB to XYZ does nothing; neither does a zero strength.
    if strength == 0.0 || direction == "RGB_TO_XYZ" {
        return Ok(g);
    }
    let delta = ((1.0 - float(p, "mid_level")?) * strength).clamp(-10000.0, 10000.0);
    let global = text(p, "space")? == "GLOBAL";
    let mut co = m.positions.clone();
    if direction == "NORMAL" {
        let normals = m.vertex_normals();
        for (p, n) in co.iter_mut().zip(&normals) {
            for k in 0..3 {
                p[k] += n[k] * delta;
            }
        }
    } else {
        let axis = match direction {
            "X" => 0,
            "Y" => 1,
            _ => 2,
        };
        let step = if global {
            let w = (ctx.world)(ctx.object)
                .ok_or_else(|| format!("object {:?} has no world matrix", ctx.object))?;
            [delta * w[0][axis], delta * w[1][axis], delta * w[2][axis]]
        } else {
            let mut s = [0.0; 3];
            s[axis] = delta;
            s
        };
        for p in co.iter_mut() {
            if global {
                for k in 0..3 {
                    p[k] += step[k];
                }
            } else {
                p[axis] += delta;
            }
        }
    }
    let mm = g.mesh_mut().unwrap();
    mm.positions = co;
    mm.custom_vert_normals = None;
    Ok(g)
}

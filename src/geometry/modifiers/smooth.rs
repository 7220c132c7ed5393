//! The Smooth modifier (`MOD_smooth.cc`): `iterations` times, each vertex moves by
//! `factor` towards the average of its edges' midpoints, on the enabled axes only. A
//! vertex without edges averages nothing and so moves towards the origin, as in Blender.
//! Vertex groups are not exported: a modifier naming one is refused (`unsupported`).

use super::super::set::GeometrySet;
use super::{flag, float, int, text, Props};

pub fn unsupported(p: &Props) -> Option<String> {
    let group = text(p, "vertex_group").unwrap_or("");
    (!group.is_empty()).then(|| format!("Vertex Group {group:?} (vertex groups are not exported)"))
}

pub fn apply(p: &Props, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let axes = [flag(p, "use_x"), flag(p, "use_y"), flag(p, "use_z")];
    let fac_new = float(p, "factor")?;
    let repeat = int(p, "iterations")?.max(0);
    // Blender skips the modifier when it cannot do anything.
    if fac_new == 0.0 || !axes.iter().any(|&a| a) || repeat == 0 {
        return Ok(g);
    }
    let fac_orig = 1.0 - fac_new;
    let nv = m.vertex_count();
    let mut co = m.positions.clone();
    let mut acc = vec![[0.0f32; 3]; nv];
    let mut count = vec![0u32; nv];
    for _ in 0..repeat {
        acc.iter_mut().for_each(|a| *a = [0.0; 3]);
        count.iter_mut().for_each(|c| *c = 0);
        for e in &m.edges {
            let (a, b) = (e[0] as usize, e[1] as usize);
            let mid = [
                0.5 * (co[a][0] + co[b][0]),
                0.5 * (co[a][1] + co[b][1]),
                0.5 * (co[a][2] + co[b][2]),
            ];
            for v in [a, b] {
                count[v] += 1;
                for k in 0..3 {
                    acc[v][k] += mid[k];
                }
            }
        }
        for i in 0..nv {
            if count[i] > 0 {
                let inv = 1.0 / count[i] as f32;
                for k in 0..3 {
                    acc[i][k] *= inv;
                }
            }
            for k in 0..3 {
                if axes[k] {
                    co[i][k] = fac_orig * co[i][k] + fac_new * acc[i][k];
                }
            }
        }
    }
    let mm = g.mesh_mut().unwrap();
    mm.positions = co;
    mm.custom_vert_normals = None;
    Ok(g)
}

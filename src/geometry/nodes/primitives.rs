//! Mesh primitives with Blender's vertex, edge, face and corner order and UVs
//! (`geometry/intern/mesh_primitive_*.cc` and the primitive nodes): Grid, Cube, UV Sphere,
//! Circle, Cylinder, Cone, Line. Single-precision arithmetic follows Blender's expressions
//! (where a double literal promotes an expression, so does this code).

use std::f64::consts::PI;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, Field};
use super::super::limits;
use super::super::math::{add, scale, V3};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

pub(super) fn mesh_out(mesh: Mesh, extra: Vec<(&str, SocketValue)>) -> Outputs {
    let mut o = outputs([("Mesh", SocketValue::Geometry(GeometrySet::from_mesh(mesh)))]);
    for (k, v) in extra {
        o.insert(k.to_string(), v);
    }
    o
}

fn attr_field(id: &AttrId, ty: DataType) -> SocketValue {
    SocketValue::Field(Field::input(AttributeInput { id: id.clone(), ty }))
}

fn empty_out(ctx: &NodeCtx) -> Outputs {
    ctx.node()
        .outputs
        .iter()
        .map(|s| (s.identifier.clone(), SocketValue::zero(&s.kind)))
        .collect()
}

/// Stores `uvs` as the anonymous UV Map attribute when the output is used.
pub(super) fn with_uv(
    ctx: &NodeCtx,
    mesh: &mut Mesh,
    uvs: impl FnOnce(&Mesh) -> Vec<[f32; 2]>,
) -> Vec<(&'static str, SocketValue)> {
    if !ctx.output_used("UV Map") {
        return Vec::new();
    }
    let id = AttrId::anonymous("UV Map");
    let uv = uvs(mesh);
    mesh.attributes
        .set(id.clone(), Domain::Corner, Array::Float2(uv));
    vec![("UV Map", attr_field(&id, DataType::Vector))]
}

// --- Grid -------------------------------------------------------------------------------

/// `create_grid_mesh`: vertices column by column (x outer, y inner).
pub fn grid_mesh(verts_x: usize, verts_y: usize, size_x: f32, size_y: f32) -> Mesh {
    let (ex, ey) = (verts_x - 1, verts_y - 1);
    let mut m = Mesh::new();
    let dx = if ex == 0 { 0.0 } else { size_x / ex as f32 };
    let dy = if ey == 0 { 0.0 } else { size_y / ey as f32 };
    let x_shift = ex as f32 / 2.0;
    let y_shift = ey as f32 / 2.0;
    for x in 0..verts_x {
        for y in 0..verts_y {
            m.positions
                .push([(x as f32 - x_shift) * dx, (y as f32 - y_shift) * dy, 0.0]);
        }
    }
    let x_edges_start = verts_x * ey;
    m.edges = vec![[0, 0]; ex * verts_y + ey * verts_x];
    for x in 0..verts_x {
        for y in 0..ey {
            let v = (x * verts_y + y) as u32;
            m.edges[x * ey + y] = [v, v + 1];
        }
    }
    for y in 0..verts_y {
        for x in 0..ex {
            let v = (x * verts_y + y) as u32;
            m.edges[x_edges_start + y * ex + x] = [v, v + verts_y as u32];
        }
    }
    for x in 0..ex {
        for y in 0..ey {
            let v = (x * verts_y + y) as u32;
            let vy = verts_y as u32;
            m.corner_verts.extend([v, v + vy, v + vy + 1, v + 1]);
            m.corner_edges.extend([
                (x_edges_start + ex * y + x) as u32,
                (ey * (x + 1) + y) as u32,
                (x_edges_start + ex * (y + 1) + x) as u32,
                (ey * x + y) as u32,
            ]);
            m.face_offsets.push(m.corner_verts.len() as u32);
        }
    }
    m.set_smooth(false);
    m
}

fn grid_uvs(m: &Mesh, size_x: f32, size_y: f32) -> Vec<[f32; 2]> {
    let dx = if size_x == 0.0 { 0.0 } else { 1.0 / size_x };
    let dy = if size_y == 0.0 { 0.0 } else { 1.0 / size_y };
    m.corner_verts
        .iter()
        .map(|&v| {
            let co = m.positions[v as usize];
            [(co[0] + size_x * 0.5) * dx, (co[1] + size_y * 0.5) * dy]
        })
        .collect()
}

pub fn grid(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let (sx, sy) = (ctx.float("Size X")?, ctx.float("Size Y")?);
    let (vx, vy) = (ctx.int("Vertices X")?, ctx.int("Vertices Y")?);
    if vx < 1 || vy < 1 {
        return Ok(empty_out(ctx));
    }
    let (x, y) = (vx as u64, vy as u64);
    limits::check(limits::product(&[4, x, y]), "Vertices X x Vertices Y")
        .map_err(|m| ctx.err(m))?;
    let mut m = grid_mesh(vx as usize, vy as usize, sx, sy);
    // The node gives the mesh an empty material slot (as all primitive nodes do).
    m.materials = vec![None];
    let extra = if m.face_count() > 0 {
        with_uv(ctx, &mut m, |m| grid_uvs(m, sx, sy))
    } else {
        Vec::new()
    };
    Ok(mesh_out(m, extra))
}

// --- Line -------------------------------------------------------------------------------

pub fn line_mesh(start: V3, delta: V3, count: usize) -> Mesh {
    let mut m = Mesh::new();
    for i in 0..count {
        m.positions.push(add(start, scale(delta, i as f32)));
    }
    for i in 1..count {
        m.edges.push([(i - 1) as u32, i as u32]);
    }
    m
}

pub fn line(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mode = ctx.prop_str("mode")?;
    let start = ctx.vector("Start Location")?;
    let mesh = if mode == "END_POINTS" {
        let end = ctx.vector("Offset")?;
        let total = [end[0] - start[0], end[1] - start[1], end[2] - start[2]];
        match ctx.prop_str("count_mode")? {
            "RESOLUTION" => {
                let res = ctx.float("Resolution")?;
                let len = (total[0] * total[0] + total[1] * total[1] + total[2] * total[2]).sqrt();
                let count = (len / res) as i32 + 1;
                let n = super::super::math::normalize(total);
                line_mesh(start, scale(n, res), count.max(0) as usize)
            }
            _ => {
                let count = ctx.int("Count")?;
                if count == 1 {
                    line_mesh(start, [0.0; 3], 1)
                } else {
                    let c = (count - 1) as f32;
                    line_mesh(
                        start,
                        [total[0] / c, total[1] / c, total[2] / c],
                        count.max(0) as usize,
                    )
                }
            }
        }
    } else {
        let count = ctx.int("Count")?;
        line_mesh(start, ctx.vector("Offset")?, count.max(0) as usize)
    };
    if mesh.vertex_count() == 0 {
        return Ok(empty_out(ctx));
    }
    Ok(mesh_out(mesh, Vec::new()))
}

// --- Cube -------------------------------------------------------------------------------

struct Cuboid {
    size: V3,
    vx: usize,
    vy: usize,
    vz: usize,
    ex: usize,
    ey: usize,
    ez: usize,
}

fn cuboid_positions(c: &Cuboid) -> Vec<V3> {
    let z_bottom = -c.size[2] / 2.0;
    let z_delta = c.size[2] / c.ez as f32;
    let x_left = -c.size[0] / 2.0;
    let x_delta = c.size[0] / c.ex as f32;
    let y_front = -c.size[1] / 2.0;
    let y_delta = c.size[1] / c.ey as f32;
    let mut out = Vec::new();
    for z in 0..c.vz {
        let z_pos = z_bottom + z_delta * z as f32;
        if z == 0 || z == c.ez {
            for y in 0..c.vy {
                let y_pos = y_front + y_delta * y as f32;
                for x in 0..c.vx {
                    out.push([x_left + x_delta * x as f32, y_pos, z_pos]);
                }
            }
        } else {
            for y in 0..c.vy {
                let y_pos = y_front + y_delta * y as f32;
                if y == 0 || y == c.ey {
                    for x in 0..c.vx {
                        out.push([x_left + x_delta * x as f32, y_pos, z_pos]);
                    }
                } else {
                    out.push([x_left, y_pos, z_pos]);
                    out.push([x_left + x_delta * c.ex as f32, y_pos, z_pos]);
                }
            }
        }
    }
    out
}

fn cuboid_faces(c: &Cuboid) -> Vec<[u32; 4]> {
    let (vx, vy, vz) = (c.vx as i64, c.vy as i64, c.vz as i64);
    let (ex, ey, ez) = (c.ex as i64, c.ey as i64, c.ez as i64);
    let mut f: Vec<[i64; 4]> = Vec::new();
    let xy_cross = vx * vy - (vx - 2) * (vy - 2);
    // Bottom.
    let mut v1s = 0;
    for _ in 0..ey {
        for x in 0..ex {
            let v1 = v1s + x;
            let v2 = v1s + vx + x;
            f.push([v1, v2, v2 + 1, v1 + 1]);
        }
        v1s += vx;
    }
    // Front.
    v1s = 0;
    let mut v2s = vx * vy;
    for _ in 0..ez {
        for x in 0..ex {
            f.push([v1s + x, v1s + x + 1, v2s + x + 1, v2s + x]);
        }
        v1s = v2s;
        v2s += vx * vy - (vx - 2) * (vy - 2);
    }
    // Top.
    v1s = vx * vy + (vz - 2) * (vx * vy - (vx - 2) * (vy - 2));
    v2s = v1s + vx;
    for _ in 0..ey {
        for x in 0..ex {
            f.push([v1s + x, v1s + x + 1, v2s + x + 1, v2s + x]);
        }
        v2s += vx;
        v1s += vx;
    }
    // Back.
    v1s = vx * ey;
    v2s = v1s + xy_cross;
    for z in 0..ez {
        if z == ez - 1 {
            v2s += (vx - 2) * (vy - 2);
        }
        for x in 0..ex {
            f.push([v1s + x, v2s + x, v2s + x + 1, v1s + x + 1]);
        }
        v2s += xy_cross;
        v1s += xy_cross;
    }
    // Left.
    v1s = 0;
    v2s = vx * vy;
    for z in 0..ez {
        for y in 0..ey {
            let (v1, v4) = if z == 0 || y == 0 {
                let v1 = v1s + vx * y;
                (v1, v1 + vx)
            } else {
                let v1 = v1s + 2 * y + vx - 2;
                (v1, v1 + 2)
            };
            let (v2, v3) = if y == 0 || z == ez - 1 {
                let v2 = v2s + vx * y;
                (v2, v2 + vx)
            } else {
                let v2 = v2s + 2 * y + vx - 2;
                (v2, v2 + 2)
            };
            f.push([v1, v2, v3, v4]);
        }
        v1s += if z == 0 { vx * vy } else { xy_cross };
        v2s += xy_cross;
    }
    // Right.
    v1s = ex;
    v2s = v1s + vx * vy;
    for z in 0..ez {
        for y in 0..ey {
            let (v1, mut v4) = if z == 0 {
                let v1 = v1s + vx * y;
                (v1, v1 + vx)
            } else {
                let v1 = v1s + 2 * y;
                (v1, v1 + 2)
            };
            let (v2, mut v3) = if z == ez - 1 {
                let v2 = v2s + vx * y;
                (v2, v2 + vx)
            } else {
                let v2 = v2s + 2 * y;
                (v2, v2 + 2)
            };
            if y == ey - 1 {
                v3 = v2 + vx;
                v4 = v1 + vx;
            }
            f.push([v1, v4, v3, v2]);
        }
        v1s += if z == 0 { vx * vy } else { xy_cross };
        v2s += xy_cross;
    }
    f.into_iter()
        .map(|q| [q[0] as u32, q[1] as u32, q[2] as u32, q[3] as u32])
        .collect()
}

fn cuboid_uvs(c: &Cuboid) -> Vec<[f32; 2]> {
    let xd = 0.25 / c.ex as f32;
    let yd = 0.25 / c.ey as f32;
    let zd = 0.25 / c.ez as f32;
    let mut uv = Vec::new();
    for y in 0..c.ey {
        for x in 0..c.ex {
            let (x, y) = (x as f32, y as f32);
            uv.extend([
                [0.25 + x * xd, 0.375 - y * yd],
                [0.25 + x * xd, 0.375 - (y + 1.0) * yd],
                [0.25 + (x + 1.0) * xd, 0.375 - (y + 1.0) * yd],
                [0.25 + (x + 1.0) * xd, 0.375 - y * yd],
            ]);
        }
    }
    for z in 0..c.ez {
        for x in 0..c.ex {
            let (x, z) = (x as f32, z as f32);
            uv.extend([
                [0.25 + x * xd, 0.375 + z * zd],
                [0.25 + (x + 1.0) * xd, 0.375 + z * zd],
                [0.25 + (x + 1.0) * xd, 0.375 + (z + 1.0) * zd],
                [0.25 + x * xd, 0.375 + (z + 1.0) * zd],
            ]);
        }
    }
    for y in 0..c.ey {
        for x in 0..c.ex {
            let (x, y) = (x as f32, y as f32);
            uv.extend([
                [0.25 + x * xd, 0.625 + y * yd],
                [0.25 + (x + 1.0) * xd, 0.625 + y * yd],
                [0.25 + (x + 1.0) * xd, 0.625 + (y + 1.0) * yd],
                [0.25 + x * xd, 0.625 + (y + 1.0) * yd],
            ]);
        }
    }
    for z in 0..c.ez {
        for x in 0..c.ex {
            let (x, z) = (x as f32, z as f32);
            uv.extend([
                [1.0 - x * xd, 0.375 + z * zd],
                [1.0 - x * xd, 0.375 + (z + 1.0) * zd],
                [1.0 - (x + 1.0) * xd, 0.375 + (z + 1.0) * zd],
                [1.0 - (x + 1.0) * xd, 0.375 + z * zd],
            ]);
        }
    }
    for z in 0..c.ez {
        for y in 0..c.ey {
            let (y, z) = (y as f32, z as f32);
            uv.extend([
                [0.25 - y * yd, 0.375 + z * zd],
                [0.25 - y * yd, 0.375 + (z + 1.0) * zd],
                [0.25 - (y + 1.0) * yd, 0.375 + (z + 1.0) * zd],
                [0.25 - (y + 1.0) * yd, 0.375 + z * zd],
            ]);
        }
    }
    for z in 0..c.ez {
        for y in 0..c.ey {
            let (y, z) = (y as f32, z as f32);
            uv.extend([
                [0.50 + y * yd, 0.375 + z * zd],
                [0.50 + (y + 1.0) * yd, 0.375 + z * zd],
                [0.50 + (y + 1.0) * yd, 0.375 + (z + 1.0) * zd],
                [0.50 + y * yd, 0.375 + (z + 1.0) * zd],
            ]);
        }
    }
    uv
}

pub fn cube(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let size = ctx.vector("Size")?;
    let (vx, vy, vz) = (
        ctx.int("Vertices X")?,
        ctx.int("Vertices Y")?,
        ctx.int("Vertices Z")?,
    );
    if vx < 1 || vy < 1 || vz < 1 {
        return Ok(empty_out(ctx));
    }
    let dims = (vx > 1) as u8 + (vy > 1) as u8 + (vz > 1) as u8;
    if dims == 0 {
        return Ok(mesh_out(line_mesh([0.0; 3], [0.0; 3], 1), Vec::new()));
    }
    if dims == 1 {
        let (start, delta) = if vx > 1 {
            (
                [-size[0] / 2.0, 0.0, 0.0],
                [size[0] / (vx - 1) as f32, 0.0, 0.0],
            )
        } else if vy > 1 {
            (
                [0.0, -size[1] / 2.0, 0.0],
                [0.0, size[1] / (vy - 1) as f32, 0.0],
            )
        } else {
            (
                [0.0, 0.0, -size[2] / 2.0],
                [0.0, 0.0, size[2] / (vz - 1) as f32],
            )
        };
        return Ok(mesh_out(
            line_mesh(start, delta, (vx * vy * vz) as usize),
            Vec::new(),
        ));
    }
    if dims == 2 {
        if vz == 1 {
            let mut m = grid_mesh(vx as usize, vy as usize, size[0], size[1]);
            let extra = with_uv(ctx, &mut m, |m| grid_uvs(m, size[0], size[1]));
            return Ok(mesh_out(m, extra));
        }
        return Err(ctx.err("a cube flat in X or Y (one vertex along it) is not supported yet"));
    }
    let c = Cuboid {
        size,
        vx: vx as usize,
        vy: vy as usize,
        vz: vz as usize,
        ex: vx as usize - 1,
        ey: vy as usize - 1,
        ez: vz as usize - 1,
    };
    let mut m = Mesh::new();
    m.positions = cuboid_positions(&c);
    for q in cuboid_faces(&c) {
        m.corner_verts.extend(q);
        m.face_offsets.push(m.corner_verts.len() as u32);
    }
    m.calc_edges(false);
    m.set_smooth(false);
    m.materials = vec![None];
    let extra = with_uv(ctx, &mut m, |_| cuboid_uvs(&c));
    Ok(mesh_out(m, extra))
}

// --- UV Sphere --------------------------------------------------------------------------

pub fn uv_sphere_mesh(radius: f32, segments: usize, rings: usize) -> Mesh {
    let mut m = Mesh::new();
    let delta_theta = (PI / rings as f64) as f32;
    let delta_phi = ((2.0f32 as f64 * PI) / segments as f64) as f32;
    let mut cosines = vec![0.0f32; segments + 1];
    let mut sines = vec![0.0f32; segments + 1];
    for s in 1..=segments {
        let phi = s as f32 * delta_phi;
        cosines[s] = phi.cos();
        sines[s] = phi.sin();
    }
    let mut normals = vec![[0.0, 0.0, 1.0]];
    m.positions.push([0.0, 0.0, radius]);
    for ring in 1..rings {
        let theta = ring as f32 * delta_theta;
        let (sin_t, z) = (theta.sin(), theta.cos());
        for s in 1..=segments {
            let (x, y) = (sin_t * cosines[s], sin_t * sines[s]);
            m.positions.push([x * radius, y * radius, z * radius]);
            normals.push([x, y, z]);
        }
    }
    m.positions.push([0.0, 0.0, -radius]);
    normals.push([0.0, 0.0, -1.0]);
    let seg = segments as u32;
    // Edges.
    for s in 0..seg {
        m.edges.push([0, 1 + s]);
    }
    let mut ring_start = 1u32;
    for ring in 0..rings - 1 {
        let next = ring_start + seg;
        for s in 0..seg {
            m.edges.push([ring_start + s, ring_start + (s + 1) % seg]);
        }
        if ring + 2 < rings {
            for s in 0..seg {
                m.edges.push([ring_start + s, next + s]);
            }
        }
        ring_start += seg;
    }
    let last = m.positions.len() as u32 - 1;
    let last_ring = last - seg;
    for s in 0..seg {
        m.edges.push([last, last_ring + s]);
    }
    // Faces.
    let next_of = |s: u32| if s == seg - 1 { 0 } else { s + 1 };
    for s in 0..seg {
        let n = next_of(s);
        m.corner_verts.extend([0, 1 + s, 1 + n]);
        m.corner_edges.extend([s, seg + s, n]);
        m.face_offsets.push(m.corner_verts.len() as u32);
    }
    for ring in 1..rings as u32 - 1 {
        let rv = 1 + (ring - 1) * seg;
        let re = seg + (ring - 1) * seg * 2;
        let nv = rv + seg;
        let ne = re + seg * 2;
        let vert_e = re + seg;
        for s in 0..seg {
            let n = next_of(s);
            m.corner_verts.extend([rv + s, nv + s, nv + n, rv + n]);
            m.corner_edges
                .extend([vert_e + s, ne + s, vert_e + n, re + s]);
            m.face_offsets.push(m.corner_verts.len() as u32);
        }
    }
    let last_edge_ring = seg * (rings as u32 - 2) * 2 + seg;
    let fan = last_edge_ring + seg;
    for s in 0..seg {
        let n = next_of(s);
        m.corner_verts.extend([last, last_ring + n, last_ring + s]);
        m.corner_edges
            .extend([fan + n, last_edge_ring + s, fan + s]);
        m.face_offsets.push(m.corner_verts.len() as u32);
    }
    m.set_smooth(false);
    m.materials = vec![None];
    m.custom_vert_normals = Some(normals);
    m
}

fn uv_sphere_uvs(segments: usize, rings: usize) -> Vec<[f32; 2]> {
    let (segf, ringf) = (segments as f32, rings as f32);
    let dy = 1.0 / ringf;
    let inv = 1.0 / segf;
    let mut uv = Vec::new();
    for s in 0..segments {
        let s = s as f32;
        uv.extend([[(s + 0.5) * inv, 0.0], [s * inv, dy], [(s + 1.0) * inv, dy]]);
    }
    for r in 1..rings - 1 {
        let r = r as f32;
        for s in 0..segments {
            let s = s as f32;
            uv.extend([
                [s * inv, r / ringf],
                [s * inv, (r + 1.0) / ringf],
                [(s + 1.0) * inv, (r + 1.0) / ringf],
                [(s + 1.0) * inv, r / ringf],
            ]);
        }
    }
    for s in 0..segments {
        let s = s as f32;
        uv.extend([
            [(s + 0.5) * inv, 1.0],
            [(s + 1.0) * inv, 1.0 - dy],
            [s * inv, 1.0 - dy],
        ]);
    }
    uv
}

pub fn uv_sphere(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let segments = ctx.int("Segments")?;
    let rings = ctx.int("Rings")?;
    let radius = ctx.float("Radius")?;
    if segments < 3 || rings < 2 {
        return Ok(empty_out(ctx));
    }
    let (s, r) = (segments as usize, rings as usize);
    let mut m = uv_sphere_mesh(radius, s, r);
    let extra = with_uv(ctx, &mut m, |_| uv_sphere_uvs(s, r));
    Ok(mesh_out(m, extra))
}

// --- Circle -----------------------------------------------------------------------------

pub fn circle(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let n = ctx.int("Vertices")?;
    let radius = ctx.float("Radius")?;
    let fill = ctx.prop_str("fill_type")?;
    if n < 3 {
        return Ok(empty_out(ctx));
    }
    let n = n as usize;
    let mut m = Mesh::new();
    let delta = (2.0f32 as f64 * (PI / n as f64)) as f32;
    for i in 0..n {
        let a = i as f32 * delta;
        m.positions.push([a.cos() * radius, a.sin() * radius, 0.0]);
    }
    for i in 0..n {
        m.edges.push([i as u32, ((i + 1) % n) as u32]);
    }
    let nu = n as u32;
    match fill {
        "NGON" => {
            m.corner_verts = (0..nu).collect();
            m.corner_edges = (0..nu).collect();
            m.face_offsets.push(nu);
        }
        "TRIANGLE_FAN" => {
            m.positions.push([0.0; 3]);
            for i in 0..nu {
                m.edges.push([nu, i]);
            }
            for i in 0..nu {
                m.corner_verts.extend([i, (i + 1) % nu, nu]);
                m.corner_edges.extend([i, nu + (i + 1) % nu, nu + i]);
                m.face_offsets.push(m.corner_verts.len() as u32);
            }
        }
        _ => {}
    }
    m.set_smooth(false);
    m.materials = vec![None];
    Ok(mesh_out(m, Vec::new()))
}

// --- Cylinder / Cone --------------------------------------------------------------------

#[derive(Clone, Copy, PartialEq, Eq)]
enum Fill {
    None,
    NGon,
    Triangles,
}

struct Cone {
    radius_top: f32,
    radius_bottom: f32,
    height: f32,
    circle: usize,
    side: usize,
    fill_segments: usize,
    fill: Fill,
    top_is_point: bool,
    bottom_is_point: bool,
    top_center: bool,
    bottom_center: bool,
    quad_rings: usize,
    edge_rings: usize,
    tot_verts: usize,
    tot_edges: usize,
    first_ring_verts_start: usize,
    last_ring_verts_start: usize,
    last_vert: usize,
    first_ring_edges_start: usize,
    last_ring_edges_start: usize,
    last_fan_edges_start: usize,
    last_edge: usize,
    top_faces_len: usize,
    side_faces_start: usize,
    side_faces_len: usize,
    bottom_faces_start: usize,
    bottom_faces_len: usize,
}

impl Cone {
    fn new(
        radius_top: f32,
        radius_bottom: f32,
        depth: f32,
        circle: usize,
        side: usize,
        fill_segments: usize,
        fill: Fill,
    ) -> Cone {
        let top_is_point = radius_top == 0.0;
        let bottom_is_point = radius_bottom == 0.0;
        let top_center = top_is_point || fill == Fill::Triangles;
        let bottom_center = bottom_is_point || fill == Fill::Triangles;
        let quad_rings = if top_is_point && bottom_is_point {
            0
        } else {
            let mut q = 0;
            if !top_is_point {
                q += fill_segments - 1;
            }
            q += if !top_is_point && !bottom_is_point {
                side
            } else {
                side - 1
            };
            if !bottom_is_point {
                q += fill_segments - 1;
            }
            q
        };
        let edge_rings = if top_is_point && bottom_is_point {
            0
        } else {
            let mut e = 0;
            if !top_is_point {
                e += fill_segments;
            }
            e += side - 1;
            if !bottom_is_point {
                e += fill_segments;
            }
            e
        };
        let tot_verts = if top_is_point && bottom_is_point {
            side + 1
        } else {
            top_center as usize
                + if !top_is_point {
                    circle * fill_segments
                } else {
                    0
                }
                + circle * (side - 1)
                + if !bottom_is_point {
                    circle * fill_segments
                } else {
                    0
                }
                + bottom_center as usize
        };
        let tot_edges = if top_is_point && bottom_is_point {
            side
        } else {
            (if top_center { circle } else { 0 })
                + circle * (quad_rings * 2 + 1)
                + if bottom_center { circle } else { 0 }
        };
        let first_ring_verts_start = if top_center { 1 } else { 0 };
        let last_vert = tot_verts - 1;
        let last_ring_verts_start = last_vert.wrapping_sub(circle);
        let first_ring_edges_start = if top_center { circle } else { 0 };
        let last_ring_edges_start = first_ring_edges_start + quad_rings * circle * 2;
        let last_fan_edges_start = tot_edges.wrapping_sub(circle);
        let top_faces_len = if !top_is_point {
            (fill_segments - 1) * circle
                + if top_center { circle } else { 0 }
                + (fill == Fill::NGon) as usize
        } else {
            0
        };
        let side_faces_len = if top_is_point && bottom_is_point {
            0
        } else {
            side * circle
        };
        let bottom_faces_len = if !bottom_is_point {
            (fill_segments - 1) * circle
                + if bottom_center { circle } else { 0 }
                + (fill == Fill::NGon) as usize
        } else {
            0
        };
        Cone {
            radius_top,
            radius_bottom,
            height: 0.5 * depth,
            circle,
            side,
            fill_segments,
            fill,
            top_is_point,
            bottom_is_point,
            top_center,
            bottom_center,
            quad_rings,
            edge_rings,
            tot_verts,
            tot_edges,
            first_ring_verts_start,
            last_ring_verts_start,
            last_vert,
            first_ring_edges_start,
            last_ring_edges_start,
            last_fan_edges_start,
            last_edge: tot_edges.wrapping_sub(1),
            top_faces_len,
            side_faces_start: top_faces_len,
            side_faces_len,
            bottom_faces_start: top_faces_len + side_faces_len,
            bottom_faces_len,
        }
    }

    fn circle_points(&self, scale: f32) -> Vec<[f32; 2]> {
        let delta = (2.0f32 as f64 * (PI / self.circle as f64)) as f32;
        let mut angle = 0.0f32;
        let mut out = Vec::with_capacity(self.circle);
        for _ in 0..self.circle {
            out.push([angle.cos() * scale, angle.sin() * scale]);
            angle += delta;
        }
        out
    }

    fn mesh(&self) -> Mesh {
        let c = self.circle;
        let mut m = Mesh::new();
        let circle = self.circle_points(1.0);
        if self.top_center {
            m.positions.push([0.0, 0.0, self.height]);
        }
        if !self.top_is_point {
            let d = self.radius_top / self.fill_segments as f32;
            for i in 0..self.fill_segments {
                let r = d * (i + 1) as f32;
                for p in &circle {
                    m.positions.push([p[0] * r, p[1] * r, self.height]);
                }
            }
        }
        let side_d = (self.radius_bottom - self.radius_top) / self.side as f32;
        let h_d = 2.0 * self.height / self.side as f32;
        for i in 0..self.side - 1 {
            let r = self.radius_top + side_d * (i + 1) as f32;
            let h = self.height - h_d * (i + 1) as f32;
            for p in &circle {
                m.positions.push([p[0] * r, p[1] * r, h]);
            }
        }
        if !self.bottom_is_point {
            let d = self.radius_bottom / self.fill_segments as f32;
            for i in 0..self.fill_segments {
                let r = self.radius_bottom - i as f32 * d;
                for p in &circle {
                    m.positions.push([p[0] * r, p[1] * r, -self.height]);
                }
            }
        }
        if self.bottom_center {
            m.positions.push([0.0, 0.0, -self.height]);
        }
        // Edges.
        if self.top_center {
            for i in 0..c {
                m.edges.push([0, (self.first_ring_verts_start + i) as u32]);
            }
        }
        for i in 0..self.edge_rings {
            let this = self.first_ring_verts_start + i * c;
            let next = this + c;
            for j in 0..c {
                m.edges
                    .push([(this + j) as u32, (this + (j + 1) % c) as u32]);
            }
            if i == self.edge_rings - 1 {
                break;
            }
            for j in 0..c {
                m.edges.push([(this + j) as u32, (next + j) as u32]);
            }
        }
        if self.bottom_center {
            for i in 0..c {
                m.edges.push([
                    (self.last_ring_verts_start + i) as u32,
                    self.last_vert as u32,
                ]);
            }
        }
        // Faces.
        let push = |m: &mut Mesh, vs: &[usize], es: &[usize]| {
            m.corner_verts.extend(vs.iter().map(|&v| v as u32));
            m.corner_edges.extend(es.iter().map(|&e| e as u32));
            m.face_offsets.push(m.corner_verts.len() as u32);
        };
        if self.top_center {
            for i in 0..c {
                let n = (i + 1) % c;
                push(
                    &mut m,
                    &[
                        self.first_ring_verts_start + i,
                        self.first_ring_verts_start + n,
                        0,
                    ],
                    &[self.first_ring_edges_start + i, n, i],
                );
            }
        } else if self.fill == Fill::NGon {
            let vs: Vec<usize> = (0..c).collect();
            push(&mut m, &vs, &vs);
        }
        for i in 0..self.quad_rings {
            let this_v = self.first_ring_verts_start + i * c;
            let next_v = this_v + c;
            let this_e = self.first_ring_edges_start + i * 2 * c;
            let next_e = this_e + 2 * c;
            let conn = this_e + c;
            for j in 0..c {
                let n = (j + 1) % c;
                push(
                    &mut m,
                    &[this_v + j, next_v + j, next_v + n, this_v + n],
                    &[conn + j, next_e + j, conn + n, this_e + j],
                );
            }
        }
        if self.bottom_center {
            for i in 0..c {
                let n = (i + 1) % c;
                push(
                    &mut m,
                    &[
                        self.last_ring_verts_start + i,
                        self.last_vert,
                        self.last_ring_verts_start + n,
                    ],
                    &[
                        self.last_fan_edges_start + i,
                        self.last_fan_edges_start + n,
                        self.last_ring_edges_start + i,
                    ],
                );
            }
        } else if self.fill == Fill::NGon {
            let vs: Vec<usize> = (0..c).map(|i| self.last_vert - i).collect();
            let es: Vec<usize> = (0..c).map(|i| self.last_edge - (i + 1) % c).collect();
            push(&mut m, &vs, &es);
        }
        debug_assert_eq!(m.vertex_count(), self.tot_verts);
        debug_assert_eq!(m.edge_count(), self.tot_edges);
        m
    }

    fn uvs(&self) -> Vec<[f32; 2]> {
        let c = self.circle;
        let circle = self.circle_points(0.225);
        let add2 = |a: [f32; 2], f: f32, b: [f32; 2]| [f * a[0] + b[0], f * a[1] + b[1]];
        let mut uv = Vec::new();
        if self.top_is_point || self.fill != Fill::None {
            let center = [0.25, 0.25];
            let segs = if self.top_is_point {
                self.side
            } else {
                self.fill_segments
            };
            let d = 1.0 / segs as f32;
            if self.top_center {
                for i in 0..c {
                    uv.push(add2(circle[i], d, center));
                    uv.push(add2(circle[(i + 1) % c], d, center));
                    uv.push(center);
                }
            } else if !self.top_is_point && self.fill == Fill::NGon {
                for p in &circle {
                    uv.push(add2(*p, d, center));
                }
            }
            for i in 1..segs {
                let (inner, outer) = (i as f32 * d, (i + 1) as f32 * d);
                for j in 0..c {
                    let n = (j + 1) % c;
                    uv.push(add2(circle[j], inner, center));
                    uv.push(add2(circle[j], outer, center));
                    uv.push(add2(circle[n], outer, center));
                    uv.push(add2(circle[n], inner, center));
                }
            }
        }
        if !self.top_is_point && !self.bottom_is_point {
            let bottom = if self.fill == Fill::None { 0.0 } else { 0.5 };
            let xd = 1.0 / c as f32;
            let yd = (1.0 - bottom) / self.side as f32;
            for i in 0..self.side {
                for j in 0..c {
                    let (i, j) = (i as f32, j as f32);
                    uv.push([j * xd, i * yd + bottom]);
                    uv.push([j * xd, (i + 1.0) * yd + bottom]);
                    uv.push([(j + 1.0) * xd, (i + 1.0) * yd + bottom]);
                    uv.push([(j + 1.0) * xd, i * yd + bottom]);
                }
            }
        }
        if self.bottom_is_point || self.fill != Fill::None {
            let center = [0.75, 0.25];
            let segs = if self.bottom_is_point {
                self.side
            } else {
                self.fill_segments
            };
            let d = 1.0 / segs as f32;
            for i in 0..segs - 1 {
                let outer = 1.0 - i as f32 * d;
                let inner = 1.0 - (i + 1) as f32 * d;
                for j in 0..c {
                    let n = (j + 1) % c;
                    uv.push(add2(circle[j], outer, center));
                    uv.push(add2(circle[j], inner, center));
                    uv.push(add2(circle[n], inner, center));
                    uv.push(add2(circle[n], outer, center));
                }
            }
            if self.bottom_center {
                for i in 0..c {
                    uv.push(add2(circle[i], d, center));
                    uv.push(center);
                    uv.push(add2(circle[(i + 1) % c], d, center));
                }
            } else if !self.bottom_is_point && self.fill == Fill::NGon {
                for i in 0..c {
                    uv.push(add2(circle[c - 1 - i], d, center));
                }
            }
        }
        uv
    }

    /// Top / Side / Bottom selections (face domain when there is a fill, else points).
    fn selections(&self, m: &Mesh) -> [(Domain, Vec<bool>); 3] {
        let face_top = !self.top_is_point && self.fill != Fill::None;
        let mut top = vec![
            false;
            if face_top {
                m.face_count()
            } else {
                m.vertex_count()
            }
        ];
        if self.top_is_point {
            top[0] = true;
        } else {
            let n = if face_top {
                self.top_faces_len
            } else {
                self.circle
            };
            top[..n].iter_mut().for_each(|x| *x = true);
        }
        let face_bottom = !self.bottom_is_point && self.fill != Fill::None;
        let mut bottom = vec![
            false;
            if face_bottom {
                m.face_count()
            } else {
                m.vertex_count()
            }
        ];
        if self.bottom_is_point {
            bottom[self.last_vert] = true;
        } else if face_bottom {
            bottom[self.bottom_faces_start..self.bottom_faces_start + self.bottom_faces_len]
                .iter_mut()
                .for_each(|x| *x = true);
        } else {
            bottom[self.last_ring_verts_start + 1..self.last_ring_verts_start + 1 + self.circle]
                .iter_mut()
                .for_each(|x| *x = true);
        }
        let mut side = vec![false; m.face_count()];
        side[self.side_faces_start..self.side_faces_start + self.side_faces_len]
            .iter_mut()
            .for_each(|x| *x = true);
        [
            (
                if face_top {
                    Domain::Face
                } else {
                    Domain::Point
                },
                top,
            ),
            (Domain::Face, side),
            (
                if face_bottom {
                    Domain::Face
                } else {
                    Domain::Point
                },
                bottom,
            ),
        ]
    }
}

/// Cylinder and Cone; the Cone node moves its base to the origin (`lift`).
fn cone_like(
    ctx: &NodeCtx,
    radius_top: f32,
    radius_bottom: f32,
    lift: bool,
) -> Result<Outputs, GeometryError> {
    let circle = ctx.int("Vertices")?;
    let side = ctx.int("Side Segments")?;
    // Unavailable without a fill; Blender's default then.
    let fill_segments = if ctx.has_input("Fill Segments") {
        ctx.int("Fill Segments")?
    } else {
        1
    };
    let depth = ctx.float("Depth")?;
    let fill = match ctx.prop_str("fill_type")? {
        "NONE" => Fill::None,
        "NGON" => Fill::NGon,
        _ => Fill::Triangles,
    };
    if circle < 3 || side < 1 || (fill != Fill::None && fill_segments < 1) {
        return Ok(empty_out(ctx));
    }
    let cfg = Cone::new(
        radius_top,
        radius_bottom,
        depth,
        circle as usize,
        side as usize,
        fill_segments.max(1) as usize,
        fill,
    );
    if cfg.top_is_point && cfg.bottom_is_point {
        let m = if cfg.height == 0.0 {
            line_mesh([0.0; 3], [0.0; 3], 1)
        } else {
            let z_delta = -2.0 * cfg.height / cfg.side as f32;
            line_mesh([0.0, 0.0, cfg.height], [0.0, 0.0, z_delta], cfg.tot_verts)
        };
        return Ok(mesh_out(lifted(m, lift, depth), Vec::new()));
    }
    let mut m = lifted(cfg.mesh(), lift, depth);
    m.set_smooth(false);
    m.materials = vec![None];
    let mut extra = with_uv(ctx, &mut m, |_| cfg.uvs());
    let sels = cfg.selections(&m);
    for (name, (domain, values)) in ["Top", "Side", "Bottom"].into_iter().zip(sels) {
        if ctx.output_used(name) {
            let id = AttrId::anonymous(name);
            m.attributes.set(id.clone(), domain, Array::Bool(values));
            extra.push((name, attr_field(&id, DataType::Bool)));
        }
    }
    Ok(mesh_out(m, extra))
}

fn lifted(mut m: Mesh, lift: bool, depth: f32) -> Mesh {
    if lift {
        let dz = depth / 2.0;
        for p in m.positions.iter_mut() {
            p[2] += dz;
        }
    }
    m
}

pub fn cylinder(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let r = ctx.float("Radius")?;
    cone_like(ctx, r, r, false)
}

pub fn cone(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let (t, b) = (ctx.float("Radius Top")?, ctx.float("Radius Bottom")?);
    cone_like(ctx, t, b, true)
}

/// Blender's `create_cuboid_mesh` without a UV map (Bounding Box uses it): `size`
/// centred on the origin, at least two vertices along each axis.
pub fn cuboid_mesh(size: V3, vx: usize, vy: usize, vz: usize) -> Mesh {
    let c = Cuboid {
        size,
        vx,
        vy,
        vz,
        ex: vx - 1,
        ey: vy - 1,
        ez: vz - 1,
    };
    let mut m = Mesh::new();
    m.positions = cuboid_positions(&c);
    for q in cuboid_faces(&c) {
        m.corner_verts.extend(q);
        m.face_offsets.push(m.corner_verts.len() as u32);
    }
    m.calc_edges(false);
    m.set_smooth(false);
    m.materials = vec![None];
    m
}

/// The UV map of a 2x2x2-vertex cuboid of `size` (Bounding Box's "uv_map").
pub fn cuboid_uvs_for(size: V3) -> Vec<[f32; 2]> {
    cuboid_uvs(&Cuboid {
        size,
        vx: 2,
        vy: 2,
        vz: 2,
        ex: 1,
        ey: 1,
        ez: 1,
    })
}

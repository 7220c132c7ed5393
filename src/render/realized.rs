//! Instances Blender realised into an object's evaluated mesh (particles that instance
//! objects, vertex and face instancing, collection instances), split back into the objects
//! Cycles renders them as: each keeps its own object space, so Texture Coordinate >
//! Object and Generated, object-space normals and Object Info read what they read in
//! Cycles, not the instancer's.
//!
//! The exporter appends each instance's mesh after the instancer's own geometry, moved
//! into the instancer's space, and records every part's element counts: the parts follow
//! each other in every domain, so each is a run of vertices, edges, faces, corners and
//! triangles.

use crate::scene::{Attribute, AttributeData, Domain, MeshData, Realized, RealizedInstance};

/// One part of a realised mesh, in its own object space, and the instance it is, with its
/// index among the instances (None: the instancer's own geometry).
pub struct Part<'a> {
    pub mesh: MeshData,
    pub instance: Option<(usize, &'a RealizedInstance)>,
}

/// Splits `mesh` into the instancer's geometry and its realised instances, each instance
/// moved back into its own object space (its positions and corner normals through the
/// inverse of its transform). Empty parts are left out. An error says which count does not
/// add up.
pub fn split<'a>(mesh: &MeshData, realized: &'a Realized) -> Result<Vec<Part<'a>>, String> {
    let totals = [
        mesh.vertex_count(),
        mesh.edges.len(),
        mesh.face_count(),
        mesh.corner_count(),
        mesh.triangles.len(),
    ];
    let mut sum = [0usize; 5];
    for counts in
        std::iter::once(&realized.own_counts).chain(realized.instances.iter().map(|i| &i.counts))
    {
        for k in 0..5 {
            sum[k] = sum[k]
                .checked_add(counts[k])
                .ok_or("realized: counts overflow")?;
        }
    }
    if sum != totals {
        return Err(format!(
            "realized: the parts' counts {sum:?} (vertices, edges, faces, corners, triangles) do not add up to the mesh's {totals:?}"
        ));
    }
    let mut parts = Vec::with_capacity(realized.instances.len() + 1);
    let mut start = [0usize; 5];
    let own = std::iter::once((&realized.own_counts, None));
    let rest = realized
        .instances
        .iter()
        .enumerate()
        .map(|(k, i)| (&i.counts, Some((k, i))));
    for (counts, instance) in own.chain(rest) {
        let end: [usize; 5] = std::array::from_fn(|k| start[k] + counts[k]);
        if counts[0] > 0 {
            let mut part = slice(mesh, start, end)?;
            if let Some((_, inst)) = instance {
                to_own_space(&mut part, &inst.matrix).ok_or_else(|| {
                    format!("realized instance of {:?}: singular transform", inst.object)
                })?;
            }
            parts.push(Part {
                mesh: part,
                instance,
            });
        }
        start = end;
    }
    Ok(parts)
}

/// The elements `start..end` of every domain, their indices made relative to the part.
fn slice(m: &MeshData, start: [usize; 5], end: [usize; 5]) -> Result<MeshData, String> {
    let [v0, e0, f0, c0, t0] = start;
    let [v1, e1, f1, c1, t1] = end;
    let (v0u, e0u, f0u, c0u) = (v0 as u32, e0 as u32, f0 as u32, c0 as u32);
    let bad = |what: &str| format!("realized: a part's {what} reach outside it");
    let rebase =
        |x: u32, lo: u32, n: usize| x.checked_sub(lo).filter(|&r| (r as usize) < n).ok_or(());
    let edges = m.edges[e0..e1]
        .iter()
        .map(|e| Ok([rebase(e[0], v0u, v1 - v0)?, rebase(e[1], v0u, v1 - v0)?]))
        .collect::<Result<Vec<_>, ()>>()
        .map_err(|_| bad("edges"))?;
    let face_offsets = if f1 > f0 {
        m.face_offsets[f0..=f1]
            .iter()
            .map(|&o| rebase(o, c0u, c1 - c0 + 1))
            .collect::<Result<Vec<_>, ()>>()
            .map_err(|_| bad("faces"))?
    } else {
        Vec::new()
    };
    let corner_verts = m.corner_verts[c0..c1]
        .iter()
        .map(|&v| rebase(v, v0u, v1 - v0))
        .collect::<Result<Vec<_>, ()>>()
        .map_err(|_| bad("corners"))?;
    let corner_edges = if m.corner_edges.len() == m.corner_verts.len() {
        m.corner_edges[c0..c1]
            .iter()
            .map(|&e| rebase(e, e0u, e1 - e0))
            .collect::<Result<Vec<_>, ()>>()
            .map_err(|_| bad("corner edges"))?
    } else {
        Vec::new()
    };
    let triangles = m.triangles[t0..t1]
        .iter()
        .map(|t| {
            Ok([
                rebase(t[0], c0u, c1 - c0)?,
                rebase(t[1], c0u, c1 - c0)?,
                rebase(t[2], c0u, c1 - c0)?,
            ])
        })
        .collect::<Result<Vec<_>, ()>>()
        .map_err(|_| bad("triangles"))?;
    let triangle_faces = m.triangle_faces[t0..t1]
        .iter()
        .map(|&f| rebase(f, f0u, f1 - f0))
        .collect::<Result<Vec<_>, ()>>()
        .map_err(|_| bad("triangle faces"))?;
    let range = |d: Domain| match d {
        Domain::Point => v0..v1,
        Domain::Edge => e0..e1,
        Domain::Face => f0..f1,
        Domain::Corner => c0..c1,
    };
    let attributes = m
        .attributes
        .iter()
        .map(|a| Attribute {
            name: a.name.clone(),
            domain: a.domain,
            data_type: a.data_type.clone(),
            data: slice_data(&a.data, range(a.domain)),
        })
        .collect();
    Ok(MeshData {
        name: m.name.clone(),
        positions: m.positions[v0..v1].to_vec(),
        edges,
        face_offsets,
        corner_verts,
        corner_edges,
        corner_normals: if m.corner_normals.len() == m.corner_verts.len() {
            m.corner_normals[c0..c1].to_vec()
        } else {
            Vec::new()
        },
        triangles,
        triangle_faces,
        attributes,
    })
}

fn slice_data(d: &AttributeData, r: std::ops::Range<usize>) -> AttributeData {
    match d {
        AttributeData::Float(v) => AttributeData::Float(v[r].to_vec()),
        AttributeData::Float2(v) => AttributeData::Float2(v[r].to_vec()),
        AttributeData::Float3(v) => AttributeData::Float3(v[r].to_vec()),
        AttributeData::Color(v) => AttributeData::Color(v[r].to_vec()),
        AttributeData::Quaternion(v) => AttributeData::Quaternion(v[r].to_vec()),
        AttributeData::Float4x4(v) => AttributeData::Float4x4(v[r].to_vec()),
        AttributeData::Int(v) => AttributeData::Int(v[r].to_vec()),
        AttributeData::Int2(v) => AttributeData::Int2(v[r].to_vec()),
        AttributeData::Int8(v) => AttributeData::Int8(v[r].to_vec()),
        AttributeData::Bool(v) => AttributeData::Bool(v[r].to_vec()),
    }
}

/// Moves a part from the instancer's space back into the instance's own (`m`: the
/// instance's transform in the instancer's space, rows), in double precision.
fn to_own_space(part: &mut MeshData, m: &[[f64; 4]; 4]) -> Option<()> {
    let inv = crate::shader::view::invert_affine(m)?;
    for p in &mut part.positions {
        let q = p.map(|x| x as f64);
        *p = std::array::from_fn(|r| {
            (inv[r][0] * q[0] + inv[r][1] * q[1] + inv[r][2] * q[2] + inv[r][3]) as f32
        });
    }
    // A normal went in by the inverse transpose of m; it comes back by m's transpose.
    for n in &mut part.corner_normals {
        let q = n.map(|x| x as f64);
        let t: [f64; 3] = std::array::from_fn(|c| m[0][c] * q[0] + m[1][c] * q[1] + m[2][c] * q[2]);
        let l = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        if l > 0.0 {
            *n = t.map(|x| (x / l) as f32);
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(m: &MeshData) -> [usize; 5] {
        [
            m.vertex_count(),
            m.edges.len(),
            m.face_count(),
            m.corner_count(),
            m.triangles.len(),
        ]
    }

    /// A triangle mesh of `n` separate triangles, each its own face, translated by `dx` x i.
    fn triangles(n: usize, dx: f32) -> MeshData {
        let mut m = MeshData::default();
        m.face_offsets.push(0);
        for i in 0..n {
            let b = (3 * i) as u32;
            let x = dx * i as f32;
            m.positions
                .extend([[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]]);
            m.edges.extend([[b, b + 1], [b + 1, b + 2], [b + 2, b]]);
            m.corner_verts.extend([b, b + 1, b + 2]);
            m.corner_edges.extend([b, b + 1, b + 2]);
            m.face_offsets.push(b + 3);
            m.triangles.push([b, b + 1, b + 2]);
            m.triangle_faces.push(i as u32);
        }
        m.attributes.push(Attribute {
            name: "f".into(),
            domain: Domain::Face,
            data_type: "FLOAT".into(),
            data: AttributeData::Float((0..n).map(|i| i as f32).collect()),
        });
        m
    }

    fn instance(counts: [usize; 5], tx: f64) -> RealizedInstance {
        RealizedInstance {
            counts,
            matrix: [
                [2.0, 0.0, 0.0, tx],
                [0.0, 2.0, 0.0, 0.0],
                [0.0, 0.0, 2.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ],
            random_id: 7,
            object: "Blob".into(),
            color: [1.0; 4],
            pass_index: 0,
            texspace_location: None,
            texspace_size: None,
            particle: Some(None),
        }
    }

    #[test]
    fn parts_come_back_in_their_own_space_with_their_own_elements() {
        // Own geometry: one triangle at x 0; two instances of scale 2 at x 10 and x 20,
        // realised as the triangles their transforms make of the unit triangle.
        let mut m = triangles(3, 10.0);
        for (i, p) in m.positions.iter_mut().enumerate().skip(3) {
            let local = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]][i % 3];
            let tx = if i < 6 { 10.0 } else { 20.0 };
            *p = [local[0] * 2.0 + tx, local[1] * 2.0, 0.0];
        }
        let one = [3, 3, 1, 3, 1];
        let r = Realized {
            own_counts: one,
            instances: vec![instance(one, 10.0), instance(one, 20.0)],
        };
        let parts = split(&m, &r).unwrap();
        assert_eq!(parts.len(), 3);
        assert!(parts[0].instance.is_none());
        assert_eq!(parts[2].instance.map(|(k, _)| k), Some(1));
        for (k, p) in parts.iter().enumerate() {
            assert_eq!(counts(&p.mesh), one);
            assert_eq!(p.mesh.corner_verts, vec![0, 1, 2]);
            assert_eq!(p.mesh.triangles, vec![[0, 1, 2]]);
            assert_eq!(p.mesh.face_offsets, vec![0, 3]);
            assert_eq!(
                p.mesh.attributes[0].data,
                AttributeData::Float(vec![k as f32])
            );
            p.mesh.validate(std::path::Path::new("t")).unwrap();
        }
        // Every instance is the unit triangle again in its own space.
        for p in &parts[1..] {
            assert_eq!(
                p.mesh.positions,
                vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
            );
        }
        assert_eq!(parts[0].mesh.positions[1], [1.0, 0.0, 0.0]);
    }

    #[test]
    fn counts_that_do_not_add_up_are_an_error() {
        let m = triangles(2, 1.0);
        let r = Realized {
            own_counts: [3, 3, 1, 3, 1],
            instances: vec![instance([3, 3, 1, 3, 2], 0.0)],
        };
        let e = split(&m, &r).err().unwrap();
        assert!(e.contains("do not add up"), "{e}");
        // Parts whose indices point into another part are refused too.
        let mut m = triangles(2, 1.0);
        m.corner_verts[3] = 0;
        let r = Realized {
            own_counts: [3, 3, 1, 3, 1],
            instances: vec![instance([3, 3, 1, 3, 1], 0.0)],
        };
        assert!(split(&m, &r).err().unwrap().contains("reach outside"));
    }
}

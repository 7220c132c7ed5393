//! Volume to Mesh (`node_geo_volume_to_mesh.cc` -> `bke::volume_to_mesh_data` ->
//! OpenVDB `tools::volumeToMesh`): each grid's isosurface at Threshold as quads, the grids'
//! meshes concatenated in grid order, per geometry its instances reference.
//!
//! OpenVDB's uniform mesher (Adaptivity 0) is dual: every cell (the cube between voxels
//! `ijk` and `ijk + 1`) whose eight corners are not all on one side of the threshold holds
//! one point per surface sheet, the mean of the linear zero crossings on the sheet's edges
//! (in f64, in OpenVDB's edge order), taken to world space by the grid's transform in f64
//! and rounded to f32; Blender then adds half the voxel size (#85312). A cell with one
//! ambiguous face takes the complementary sheets when the neighbour across that face has
//! it as its own ambiguous face (`correctCellSigns`). Each crossing voxel edge joins the
//! four cells around it in one quad, at the sheet each cell has on that edge. A value
//! below the threshold is "inside" for OpenVDB; a fog grid (every Geometry Nodes grid)
//! flips the orientation, and Blender reverses every quad again.
//!
//! Element order is OpenVDB's: cells (and so points and quads) leaf node by leaf node in
//! its tree order (root table by coordinate, then the internal nodes' and the 8^3 leaves'
//! x-major child order), voxels x-major within a leaf, a cell's points in OpenVDB's sheet
//! order; each cell's quads on its x, y and z edges in that order. Edges follow from the
//! faces (`mesh_calc_edges`).
//!
//! Not matched, refused naming the node: Resolution Voxel Amount and Voxel Size (OpenVDB
//! resamples the grid with its `GridTransformer` first) and Adaptivity above 0 (OpenVDB
//! merges voxel regions and makes triangles).

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::math::V3;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::value::SocketValue;
use super::super::volume::VolumeGrid;
use super::geometry_ops::modify_geometry_sets;

pub fn volume_to_mesh(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mode = ctx.prop_str("resolution_mode")?;
    if mode != "GRID" {
        return Err(ctx.err(format!(
            "Resolution {mode:?} is not evaluated (OpenVDB resamples the grid first); only \"GRID\" is"
        )));
    }
    let threshold = ctx.float("Threshold")?;
    let adaptivity = ctx.float("Adaptivity")?;
    // OpenVDB meshes adaptively above 1e-7.
    if adaptivity as f64 > 1e-7 {
        return Err(ctx.err(format!(
            "Adaptivity {adaptivity} is not evaluated (OpenVDB's adaptive merging); only 0 is"
        )));
    }
    let mut g = ctx.geometry("Volume")?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let mesh = match s.volume.as_deref() {
            Some(v) if !v.grids.is_empty() => Some(volume_mesh(&v.grids, threshold)?),
            _ => None,
        };
        let instances = s.instances.take();
        *s = GeometrySet::default();
        s.instances = instances;
        s.mesh = mesh.map(Arc::new);
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}

/// The mesh of all grids, as `create_mesh_from_volume_grids` joins them.
fn volume_mesh(grids: &[VolumeGrid], iso: f32) -> Result<Mesh, String> {
    let mut mesh = Mesh::new();
    for g in grids {
        let base = mesh.positions.len() as u32;
        let (points, quads) = grid_surface(g, iso)?;
        mesh.positions.extend(points);
        for q in quads {
            // Blender reverses OpenVDB's corner order "to get correct normals".
            mesh.corner_verts.extend((0..4).map(|j| base + q[3 - j]));
            mesh.face_offsets.push(mesh.corner_verts.len() as u32);
        }
    }
    mesh.calc_edges(false);
    // `BKE_id_material_eval_ensure_default_slot`, `mesh_smooth_set(false)`.
    mesh.materials = vec![None];
    mesh.set_smooth(false);
    Ok(mesh)
}

/// Cube corners in OpenVDB's numbering (`getCellVertexValues`).
const CORNERS: [[i32; 3]; 8] = [
    [0, 0, 0],
    [1, 0, 0],
    [1, 0, 1],
    [0, 0, 1],
    [0, 1, 0],
    [1, 1, 0],
    [1, 1, 1],
    [0, 1, 1],
];

/// Cell edges in OpenVDB's order (`computePoint`): the two corners, from the one whose
/// crossing parameter starts at 0.
const EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [3, 2],
    [0, 3],
    [4, 5],
    [5, 6],
    [7, 6],
    [4, 7],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// Cell faces as corner cycles, each with OpenVDB's face number (1: z = 0, 2: x = 1,
/// 3: z = 1, 4: x = 0, 5: y = 0, 6: y = 1) and the neighbour cell across it.
const FACES: [([usize; 4], u8, [i32; 3]); 6] = [
    ([0, 1, 2, 3], 5, [0, -1, 0]),
    ([4, 5, 6, 7], 6, [0, 1, 0]),
    ([0, 3, 7, 4], 4, [-1, 0, 0]),
    ([1, 2, 6, 5], 2, [1, 0, 0]),
    ([0, 1, 5, 4], 1, [0, 0, -1]),
    ([3, 2, 6, 7], 3, [0, 0, 1]),
];

/// What a sign configuration means to the mesher.
#[derive(Clone, Copy, Default)]
struct Config {
    /// Surface sheets (points) in the cell.
    sheets: u8,
    /// Per edge, its sheet (1-based; 0 where the edge does not cross).
    sheet_of: [u8; 12],
    /// OpenVDB's face number of the one ambiguous face whose neighbour decides the cell
    /// (`sAmbiguousFace`), 0 for none.
    ambiguous: u8,
}

/// The sheets of a sign configuration: crossing edges joined across each face; on a face
/// whose diagonal corners are alike (ambiguous), the edges meeting at each outside corner
/// pair up, so the inside corners connect. This reproduces the partition of every entry
/// of OpenVDB's `sEdgeGroupTable`. A configuration with exactly one ambiguous face and at
/// most four inside corners is the one `sAmbiguousFace` names (checked on all 256).
/// Sheets are numbered as OpenVDB numbers them (`OPENVDB_SHEET_ORDER`).
fn config(signs: u8) -> Config {
    let inside = |c: usize| (signs >> c) & 1 == 1;
    let crosses = |e: usize| inside(EDGES[e][0]) != inside(EDGES[e][1]);
    let mut parent: [usize; 12] = std::array::from_fn(|e| e);
    fn root(p: &[usize; 12], mut e: usize) -> usize {
        while p[e] != e {
            e = p[e];
        }
        e
    }
    let mut ambiguous_faces = Vec::new();
    for (corners, number, _) in FACES {
        let on: Vec<usize> = (0..12)
            .filter(|&e| {
                crosses(e) && corners.contains(&EDGES[e][0]) && corners.contains(&EDGES[e][1])
            })
            .collect();
        let mut join = |a: usize, b: usize| {
            let (ra, rb) = (root(&parent, a), root(&parent, b));
            parent[ra] = rb;
        };
        match on.len() {
            2 => join(on[0], on[1]),
            4 => {
                ambiguous_faces.push(number);
                for c in corners.into_iter().filter(|&c| !inside(c)) {
                    let pair: Vec<usize> = on
                        .iter()
                        .copied()
                        .filter(|&e| EDGES[e].contains(&c))
                        .collect();
                    join(pair[0], pair[1]);
                }
            }
            _ => {}
        }
    }
    let mut cfg = Config::default();
    let mut roots: Vec<usize> = Vec::new();
    for e in (0..12).filter(|&e| crosses(e)) {
        let r = root(&parent, e);
        let n = match roots.iter().position(|&x| x == r) {
            Some(n) => n,
            None => {
                roots.push(r);
                roots.len() - 1
            }
        };
        cfg.sheet_of[e] = n as u8 + 1;
    }
    cfg.sheets = roots.len() as u8;
    if cfg.sheets > 1 {
        // OpenVDB's number for each of ours.
        let (_, order) = OPENVDB_SHEET_ORDER
            .iter()
            .find(|(s, _)| *s == signs)
            .expect("every configuration of several sheets is recorded");
        for n in cfg.sheet_of.iter_mut().filter(|n| **n > 0) {
            *n = order.iter().position(|&o| o + 1 == *n).unwrap() as u8 + 1;
        }
    }
    if ambiguous_faces.len() == 1 && signs.count_ones() <= 4 {
        cfg.ambiguous = ambiguous_faces[0];
    }
    cfg
}

/// For each sign configuration of several sheets, OpenVDB's sheet order: entry k is our
/// sheet (numbered by first edge, from 0) that OpenVDB numbers k + 1. Recorded from
/// Blender's OpenVDB by fixtures/geometry/vdb_sheet_order.py (vdb_sheet_order.json).
#[rustfmt::skip]
const OPENVDB_SHEET_ORDER: [(u8, [u8; 4]); 92] = [
    (20, [0, 1, 0, 0]), (26, [1, 0, 0, 0]), (30, [0, 1, 0, 0]), (37, [1, 0, 0, 0]),
    (40, [1, 0, 0, 0]), (45, [0, 1, 0, 0]), (53, [0, 1, 0, 0]), (58, [0, 1, 0, 0]),
    (60, [1, 0, 0, 0]), (61, [1, 0, 0, 0]), (62, [1, 0, 0, 0]), (65, [0, 1, 0, 0]),
    (74, [0, 1, 0, 0]), (75, [0, 1, 0, 0]), (82, [0, 1, 0, 0]), (83, [1, 0, 0, 0]),
    (85, [1, 0, 0, 0]), (86, [1, 0, 0, 0]), (87, [0, 1, 0, 0]), (88, [0, 1, 0, 0]),
    (89, [1, 0, 0, 0]), (90, [3, 1, 0, 2]), (91, [1, 0, 2, 0]), (92, [1, 0, 0, 0]),
    (93, [0, 1, 0, 0]), (94, [0, 1, 2, 0]), (95, [0, 1, 0, 0]), (101, [0, 1, 0, 0]),
    (105, [1, 0, 0, 0]), (106, [1, 0, 0, 0]), (107, [1, 0, 0, 0]), (109, [1, 0, 0, 0]),
    (117, [1, 0, 0, 0]), (120, [1, 0, 0, 0]), (121, [0, 1, 0, 0]), (122, [1, 0, 2, 0]),
    (123, [0, 1, 0, 0]), (124, [0, 1, 0, 0]), (125, [0, 1, 0, 0]), (126, [0, 1, 0, 0]),
    (130, [0, 1, 0, 0]), (133, [0, 1, 0, 0]), (135, [0, 1, 0, 0]), (149, [1, 0, 0, 0]),
    (150, [0, 1, 0, 0]), (151, [1, 0, 0, 0]), (154, [0, 1, 0, 0]), (158, [1, 0, 0, 0]),
    (161, [0, 1, 0, 0]), (163, [1, 0, 0, 0]), (164, [0, 1, 0, 0]), (165, [0, 2, 1, 3]),
    (166, [1, 0, 0, 0]), (167, [0, 1, 2, 0]), (169, [1, 0, 0, 0]), (170, [1, 0, 0, 0]),
    (171, [0, 1, 0, 0]), (172, [1, 0, 0, 0]), (173, [0, 2, 1, 0]), (174, [0, 1, 0, 0]),
    (175, [1, 0, 0, 0]), (180, [1, 0, 0, 0]), (181, [0, 1, 2, 0]), (182, [0, 1, 0, 0]),
    (183, [0, 1, 0, 0]), (186, [1, 0, 0, 0]), (188, [0, 1, 0, 0]), (189, [0, 1, 0, 0]),
    (190, [0, 1, 0, 0]), (195, [1, 0, 0, 0]), (197, [1, 0, 0, 0]), (199, [1, 0, 0, 0]),
    (202, [1, 0, 0, 0]), (203, [1, 0, 0, 0]), (210, [1, 0, 0, 0]), (211, [0, 1, 0, 0]),
    (213, [0, 1, 0, 0]), (214, [0, 1, 0, 0]), (215, [1, 0, 0, 0]), (218, [0, 1, 2, 0]),
    (219, [0, 1, 0, 0]), (222, [1, 0, 0, 0]), (225, [1, 0, 0, 0]), (227, [0, 1, 0, 0]),
    (229, [0, 2, 1, 0]), (231, [1, 0, 0, 0]), (233, [0, 1, 0, 0]), (234, [0, 1, 0, 0]),
    (235, [0, 1, 0, 0]), (237, [0, 1, 0, 0]), (245, [0, 1, 0, 0]), (250, [0, 1, 0, 0]),
];

fn configs() -> &'static [Config; 256] {
    static TABLE: std::sync::OnceLock<[Config; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|s| config(s as u8)))
}

/// Where a cell sits in OpenVDB's default tree (5, 4, 3): the root table sorted by the
/// 4096^3 node origin, then the 32^3 children, the 16^3 children and the 8^3 voxels of a
/// leaf, each x-major.
pub(super) fn tree_order(c: [i32; 3]) -> (i32, i32, i32, u32) {
    let part = |shift: u32, bits: u32| -> u32 {
        let m = (1u32 << bits) - 1;
        let a = ((c[0] >> shift) as u32) & m;
        let b = ((c[1] >> shift) as u32) & m;
        let d = ((c[2] >> shift) as u32) & m;
        (a << (2 * bits)) | (b << bits) | d
    };
    (
        c[0] >> 12,
        c[1] >> 12,
        c[2] >> 12,
        (part(7, 5) << 21) | (part(3, 4) << 9) | part(0, 3),
    )
}

/// OpenVDB's `isInsideValue` for float grids.
fn inside(v: f32, iso: f32) -> bool {
    v < iso
}

/// Points (world space, Blender's half-voxel offset added) and quads (OpenVDB's corner
/// order) of one grid. Long because OpenVDB's three passes (signs per cell, one point per
/// sheet, quads per crossing edge) share the cell indexing and are read in its order.
#[allow(clippy::type_complexity)]
fn grid_surface(g: &VolumeGrid, iso: f32) -> Result<(Vec<V3>, Vec<[u32; 4]>), String> {
    if g.dims.contains(&0) {
        return Ok((Vec::new(), Vec::new()));
    }
    let table = configs();
    let signs_at = |c: [i32; 3]| -> u8 {
        let mut s = 0u8;
        for (b, o) in CORNERS.iter().enumerate() {
            if inside(g.value([c[0] + o[0], c[1] + o[1], c[2] + o[2]]), iso) {
                s |= 1 << b;
            }
        }
        s
    };
    // A cell with corners on both sides holds a voxel off the background's side, so a
    // stored one: cells start one voxel before the stored box.
    let lo = g.origin.map(|o| o - 1);
    let n = g.dims.map(|d| d + 1);
    let at = |c: [i32; 3]| -> Option<usize> {
        let mut idx = 0usize;
        let mut stride = 1usize;
        for a in 0..3 {
            let r = c[a] - lo[a];
            if r < 0 || r as usize >= n[a] {
                return None;
            }
            idx += r as usize * stride;
            stride *= n[a];
        }
        Some(idx)
    };
    // (cell, signs as read, signs after OpenVDB's ambiguity correction).
    let mut cells: Vec<([i32; 3], u8, u8)> = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let c = [lo[0] + i as i32, lo[1] + j as i32, lo[2] + k as i32];
                let signs = signs_at(c);
                if signs == 0 || signs == 0xff {
                    continue;
                }
                // `correctCellSigns`: a cell whose ambiguous face the neighbour across it
                // also calls ambiguous (from its side) takes the complementary sheets.
                let mut used = signs;
                let face = table[signs as usize].ambiguous;
                if face != 0 {
                    let (_, _, d) = FACES.iter().find(|f| f.1 == face).unwrap();
                    let other = signs_at([c[0] + d[0], c[1] + d[1], c[2] + d[2]]);
                    let opposite = [0u8, 3, 4, 1, 2, 6, 5][face as usize];
                    if table[other as usize].ambiguous == opposite {
                        used = !signs;
                    }
                }
                cells.push((c, signs, used));
            }
        }
    }
    cells.sort_by_key(|(c, _, _)| tree_order(*c));
    // First point of each cell, its corrected signs.
    let mut first = vec![(u32::MAX, 0u8); n[0] * n[1] * n[2]];
    let mut count = 0u32;
    for (c, _, used) in &cells {
        first[at(*c).unwrap()] = (count, *used);
        count += table[*used as usize].sheets as u32;
    }
    let t = &g.transform;
    let axis_aligned = (0..3).all(|c| (0..3).all(|r| r == c || t[c][r] == 0.0));
    // OpenVDB's `voxelSize()`: |scale| for its scale maps, the length of each axis's image
    // (taken as applyMap(e) - applyMap(0)) for an affine one.
    let voxel_size: [f32; 3] = std::array::from_fn(|a| {
        if axis_aligned {
            t[a][a].abs() as f32
        } else {
            let d: [f64; 3] = std::array::from_fn(|r| (t[a][r] + t[3][r]) - t[3][r]);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() as f32
        }
    });
    let half = voxel_size.map(|s| s / 2.0);
    let iso64 = iso as f64;
    let mut points = Vec::with_capacity(count as usize);
    for (c, _, used) in &cells {
        let cfg = &table[*used as usize];
        let v: [f64; 8] = std::array::from_fn(|b| {
            let o = CORNERS[b];
            g.value([c[0] + o[0], c[1] + o[1], c[2] + o[2]]) as f64
        });
        for sheet in 1..=cfg.sheets {
            let mut avg = [0.0f64; 3];
            let mut samples = 0;
            for (e, [a, b]) in EDGES.into_iter().enumerate() {
                if cfg.sheet_of[e] != sheet {
                    continue;
                }
                let tz = (iso64 - v[a]) / (v[b] - v[a]);
                // Each coordinate of the crossing: the parameter along the edge's axis, 1
                // where both corners are at 1 (0 elsewhere is not added, as in OpenVDB).
                for (ax, s) in avg.iter_mut().enumerate() {
                    let (ca, cb) = (CORNERS[a][ax], CORNERS[b][ax]);
                    if ca != cb {
                        *s += tz;
                    } else if ca == 1 {
                        *s += 1.0;
                    }
                }
                samples += 1;
            }
            if samples > 1 {
                let w = 1.0 / samples as f64;
                for s in &mut avg {
                    *s *= w;
                }
            }
            if avg.iter().any(|x| !x.is_finite()) {
                return Err(format!(
                    "grid {:?} holds NaN or infinite values (OpenVDB's volumeToMesh fails on them)",
                    g.name
                ));
            }
            let p: [f64; 3] = std::array::from_fn(|a| avg[a] + c[a] as f64);
            let w: [f64; 3] =
                std::array::from_fn(|r| p[0] * t[0][r] + p[1] * t[1][r] + p[2] * t[2][r] + t[3][r]);
            points.push(std::array::from_fn(|r| w[r] as f32 + half[r]));
        }
    }
    // The point of cell `c` on the sheet holding its edge `e`.
    let id = |c: [i32; 3], e: usize| -> u32 {
        let (p, used) = first[at(c).unwrap()];
        let cfg = &table[used as usize];
        if cfg.sheets > 1 {
            p + cfg.sheet_of[e] as u32 - 1
        } else {
            p
        }
    };
    let mut quads = Vec::new();
    for (c, signs, _) in &cells {
        let [i, j, k] = *c;
        // Edge flags come from the signs as read, before the correction.
        let corner0_inside = signs & 1 != 0;
        // Fog grids invert OpenVDB's level-set orientation.
        let flip = !corner0_inside;
        let mut push = |q: [u32; 4], reverse: bool| {
            quads.push(if reverse { [q[3], q[2], q[1], q[0]] } else { q });
        };
        if corner0_inside != (signs & 0x02 != 0) {
            push(
                [
                    id(*c, 0),
                    id([i, j - 1, k], 4),
                    id([i, j - 1, k - 1], 6),
                    id([i, j, k - 1], 2),
                ],
                flip,
            );
        }
        if corner0_inside != (signs & 0x10 != 0) {
            push(
                [
                    id(*c, 8),
                    id([i, j, k - 1], 11),
                    id([i - 1, j, k - 1], 10),
                    id([i - 1, j, k], 9),
                ],
                flip,
            );
        }
        if corner0_inside != (signs & 0x08 != 0) {
            push(
                [
                    id(*c, 3),
                    id([i, j - 1, k], 7),
                    id([i - 1, j - 1, k], 5),
                    id([i - 1, j, k], 1),
                ],
                !flip,
            );
        }
    }
    Ok((points, quads))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sheets_join_inside_corners_across_ambiguous_faces() {
        // One corner inside: one sheet on its three edges.
        let c = config(0b0000_0001);
        assert_eq!((c.sheets, c.ambiguous), (1, 0));
        assert_eq!(c.sheet_of, [1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0]);
        // Corners 0 and 2 share face y = 0 (OpenVDB's face 5) diagonally: joined.
        let c = config(0b0000_0101);
        assert_eq!((c.sheets, c.ambiguous), (1, 5));
        // Corners 0 and 6 are opposite: two sheets, no ambiguous face.
        let c = config(0b0100_0001);
        assert_eq!((c.sheets, c.ambiguous), (2, 0));
        // Outside corners 0 and 2 on face y = 0: the inside ones join, two sheets (one
        // around each outside corner); six inside corners are never corrected.
        let c = config(!0b0000_0101);
        assert_eq!((c.sheets, c.ambiguous), (2, 0));
    }

    #[test]
    fn every_configuration_of_several_sheets_has_openvdbs_order() {
        let several: Vec<u8> = (0..=255u8).filter(|&s| config(s).sheets > 1).collect();
        let recorded: Vec<u8> = OPENVDB_SHEET_ORDER.iter().map(|(s, _)| *s).collect();
        assert_eq!(several, recorded);
        for (s, order) in OPENVDB_SHEET_ORDER {
            let n = config(s).sheets as usize;
            let mut o = order[..n].to_vec();
            o.sort();
            assert_eq!(o, (0..n as u8).collect::<Vec<_>>(), "{s}");
        }
    }

    #[test]
    fn tree_order_is_leaf_then_voxel_x_major() {
        // Same leaf: x-major.
        assert!(tree_order([0, 0, 1]) < tree_order([0, 1, 0]));
        assert!(tree_order([0, 7, 7]) < tree_order([1, 0, 0]));
        // A leaf further in z comes after every voxel of the leaf before it.
        assert!(tree_order([7, 7, 7]) < tree_order([0, 0, 8]));
        // Negative coordinates live in the root node before.
        assert!(tree_order([-1, 5, 5]) < tree_order([0, 0, 0]));
    }
}

//! Geometry Nodes parity with Blender: every case object in fixtures/geometry/scenes/*
//! (authored by fixtures/geometry/make_gn_refs.py) is evaluated by blendsynth and compared
//! with the exporter's Blender-evaluated mesh:
//!   - equal vertex, edge, face and corner counts;
//!   - vertex positions equal one to one within 1e-5;
//!   - symmetric Hausdorff distance between the vertex sets within 1e-4 of the bounding
//!     box diagonal (a second, order-independent look at the same geometry);
//!   - the same faces (corner vertices) and edges, in the same order;
//!   - attributes equal where both have them: UV maps, material_index, sharp_face and the
//!     cases' own stored attributes (absent built-ins compare as Blender's defaults).
//!
//! Each case prints its counts and errors; all cases run before the test fails, so one
//! report shows every mismatch.
//!
//! The `textures` scene (fixtures/geometry/make_gn_texture_refs.py) names its attributes
//! NODE.CASE[.OUTPUT]: texture nodes are held to 1e-4 (Blender's BLI noise and hashes in
//! float, ours shared with the shader side), the arithmetic nodes to 1e-5 like every other
//! attribute, and the report lists cases and the worst error per node.

use std::path::{Path, PathBuf};

use blendsynth::geometry::{self, types::Array, Mesh};
use blendsynth::scene::{AttributeData, MeshData, Scene};

const POS_TOL: f32 = 1e-5;
/// Attributes of texture nodes (by the node part of NODE.CASE names).
const TEXTURE_TOL: f64 = 1e-4;
/// (Image Texture: Blender turns sRGB texels linear with OpenColorIO's CPU exponent,
/// about 2e-5 relative from the exact transfer function ours computes.)
const TEXTURE_NODES: &[&str] = &[
    "voronoi",
    "white_noise",
    "gradient",
    "wave",
    "magic",
    "checker",
    "brick",
    "image_texture",
];
/// Blackbody in Geometry Nodes goes through Blender's Rec.709 -> scene-linear matrix,
/// derived from the OCIO config in float: identity to about 6e-6 relative (Cycles treats
/// it as identity, and so do we), 3e-5 absolute on the fit's largest values (~5.4).
const BLACKBODY_TOL: f64 = 5e-5;
const HAUSDORFF_REL_TOL: f64 = 1e-4;

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/scenes")
}

/// Symmetric Hausdorff distance between two point sets (brute force: cases are small).
fn hausdorff(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let d = |p: &[f32; 3], q: &[f32; 3]| -> f64 {
        (0..3)
            .map(|k| (p[k] as f64 - q[k] as f64).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let one = |x: &[[f32; 3]], y: &[[f32; 3]]| -> f64 {
        x.iter()
            .map(|p| y.iter().map(|q| d(p, q)).fold(f64::INFINITY, f64::min))
            .fold(0.0, f64::max)
    };
    if a.is_empty() || b.is_empty() {
        return if a.len() == b.len() {
            0.0
        } else {
            f64::INFINITY
        };
    }
    one(a, b).max(one(b, a))
}

fn diagonal(p: &[[f32; 3]]) -> f64 {
    let mut mn = [f64::INFINITY; 3];
    let mut mx = [f64::NEG_INFINITY; 3];
    for v in p {
        for k in 0..3 {
            mn[k] = mn[k].min(v[k] as f64);
            mx[k] = mx[k].max(v[k] as f64);
        }
    }
    if p.is_empty() {
        return 0.0;
    }
    (0..3).map(|k| (mx[k] - mn[k]).powi(2)).sum::<f64>().sqrt()
}

/// Reference attribute values as floats (for a uniform comparison).
fn ref_values(d: &AttributeData) -> Vec<Vec<f64>> {
    match d {
        AttributeData::Float(v) => v.iter().map(|x| vec![*x as f64]).collect(),
        AttributeData::Float2(v) => v
            .iter()
            .map(|x| x.iter().map(|c| *c as f64).collect())
            .collect(),
        AttributeData::Float3(v) => v
            .iter()
            .map(|x| x.iter().map(|c| *c as f64).collect())
            .collect(),
        AttributeData::Color(v) | AttributeData::Quaternion(v) => v
            .iter()
            .map(|x| x.iter().map(|c| *c as f64).collect())
            .collect(),
        AttributeData::Float4x4(v) => v
            .iter()
            .map(|x| x.iter().map(|c| *c as f64).collect())
            .collect(),
        AttributeData::Int(v) => v.iter().map(|x| vec![*x as f64]).collect(),
        AttributeData::Int2(v) => v
            .iter()
            .map(|x| x.iter().map(|c| *c as f64).collect())
            .collect(),
        AttributeData::Int8(v) => v.iter().map(|x| vec![*x as f64]).collect(),
        AttributeData::Bool(v) => v.iter().map(|x| vec![*x as u8 as f64]).collect(),
    }
}

fn our_values(a: &Array) -> Vec<Vec<f64>> {
    (0..a.len())
        .map(|i| match a.get(i) {
            geometry::types::Value::Float(x) => vec![x as f64],
            geometry::types::Value::Int(x) => vec![x as f64],
            geometry::types::Value::Bool(x) => vec![x as u8 as f64],
            geometry::types::Value::Float2(x) => x.iter().map(|c| *c as f64).collect(),
            geometry::types::Value::Vector(x) => x.iter().map(|c| *c as f64).collect(),
            geometry::types::Value::Color(x)
            | geometry::types::Value::ByteColor(x)
            | geometry::types::Value::Quaternion(x) => x.iter().map(|c| *c as f64).collect(),
            geometry::types::Value::Matrix(m) => {
                m.iter().flat_map(|c| c.iter().map(|x| *x as f64)).collect()
            }
            geometry::types::Value::Int8(x) => vec![x as f64],
            geometry::types::Value::Int2(x) => x.iter().map(|c| *c as f64).collect(),
        })
        .collect()
}

struct Report {
    lines: Vec<String>,
    failures: Vec<String>,
    /// Per node of NODE.CASE attributes: (cases, attributes, worst error, worst attribute).
    per_node: std::collections::BTreeMap<
        String,
        (std::collections::BTreeSet<String>, usize, f64, String),
    >,
}

fn compare(case: &str, ours: &Mesh, theirs: &MeshData, r: &mut Report) {
    let mut fail = |m: String| r.failures.push(format!("{case}: {m}"));
    let counts = |v: usize, e: usize, f: usize, c: usize| format!("v{v} e{e} f{f} c{c}");
    let oc = counts(
        ours.vertex_count(),
        ours.edge_count(),
        ours.face_count(),
        ours.corner_count(),
    );
    let tc = counts(
        theirs.vertex_count(),
        theirs.edges.len(),
        theirs.face_count(),
        theirs.corner_count(),
    );
    if oc != tc {
        fail(format!("counts differ: blendsynth {oc}, Blender {tc}"));
        r.lines.push(format!("{case:28} FAIL counts {oc} vs {tc}"));
        return;
    }
    let max_err = ours
        .positions
        .iter()
        .zip(&theirs.positions)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0f32, f32::max))
        .fold(0.0f32, f32::max);
    if max_err > POS_TOL {
        let worst = ours
            .positions
            .iter()
            .zip(&theirs.positions)
            .enumerate()
            .max_by(|x, y| {
                let e = |(a, b): (&[f32; 3], &[f32; 3])| {
                    (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0f32, f32::max)
                };
                e(x.1).partial_cmp(&e(y.1)).unwrap()
            });
        let (i, (a, b)) = worst.unwrap();
        fail(format!(
            "max position error {max_err:.3e} > {POS_TOL:e} (vertex {i}: {a:?} vs {b:?})"
        ));
    }
    let diag = diagonal(&theirs.positions);
    let h = hausdorff(&ours.positions, &theirs.positions);
    if h > HAUSDORFF_REL_TOL * diag.max(1e-9) {
        fail(format!(
            "Hausdorff distance {h:.3e} > {HAUSDORFF_REL_TOL:e} x diagonal {diag:.3}"
        ));
    }
    let offsets_ours: Vec<u32> = if ours.face_count() == 0 {
        vec![]
    } else {
        ours.face_offsets.clone()
    };
    let offsets_theirs: Vec<u32> = if theirs.face_count() == 0 {
        vec![]
    } else {
        theirs.face_offsets.clone()
    };
    if offsets_ours != offsets_theirs || ours.corner_verts != theirs.corner_verts {
        let first = ours
            .corner_verts
            .iter()
            .zip(&theirs.corner_verts)
            .position(|(a, b)| a != b);
        fail(format!("faces differ (first corner mismatch at {first:?})"));
    }
    if ours.edges != theirs.edges {
        let first = ours
            .edges
            .iter()
            .zip(&theirs.edges)
            .position(|(a, b)| a != b);
        fail(format!("edges differ (first at {first:?})"));
    } else if ours.corner_edges != theirs.corner_edges {
        fail("corner edges differ".into());
    }
    // Attributes.
    let mut checked = Vec::new();
    let mut worst_attr = 0.0f64;
    for ta in &theirs.attributes {
        let ours_attr = ours.attributes.named(&ta.name);
        let expected = ref_values(&ta.data);
        let got = match ours_attr {
            Some(a) => {
                if a.domain.name() != ta.domain.name() {
                    fail(format!(
                        "attribute {:?} on {} in Blender, {} here",
                        ta.name,
                        ta.domain.name(),
                        a.domain.name()
                    ));
                    continue;
                }
                our_values(&a.data)
            }
            None => match ta.name.as_str() {
                // Absent built-ins are Blender's defaults.
                "material_index" => vec![vec![0.0]; expected.len()],
                "sharp_face" | "sharp_edge" => vec![vec![0.0]; expected.len()],
                _ => {
                    fail(format!(
                        "attribute {:?} ({} {}) missing",
                        ta.name,
                        ta.domain.name(),
                        ta.data_type
                    ));
                    continue;
                }
            },
        };
        let err = expected
            .iter()
            .zip(&got)
            .map(|(e, g)| {
                e.iter()
                    .zip(g)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        let node = ta.name.split_once('.').map(|(node, _)| node);
        let tol = if matches!(
            ta.data,
            AttributeData::Int(_) | AttributeData::Bool(_) | AttributeData::Int8(_)
        ) {
            0.0
        } else if node.is_some_and(|n| TEXTURE_NODES.contains(&n)) {
            TEXTURE_TOL
        } else if node == Some("blackbody") {
            BLACKBODY_TOL
        } else {
            1e-5
        };
        if got.len() != expected.len() || err > tol {
            let worst = expected.iter().zip(&got).enumerate().max_by(|x, y| {
                let e = |(a, b): (&Vec<f64>, &Vec<f64>)| {
                    a.iter()
                        .zip(b)
                        .map(|(x, y)| (x - y).abs())
                        .fold(0.0, f64::max)
                };
                e(x.1).total_cmp(&e(y.1))
            });
            let at = worst
                .map(|(i, (e, g))| format!(" at element {i}: Blender {e:?}, blendsynth {g:?}"))
                .unwrap_or_default();
            fail(format!(
                "attribute {:?} differs (max error {err:.3e} > {tol:e}){at}",
                ta.name
            ));
        }
        if let Some(node) = node {
            let case = ta.name.split('.').take(2).collect::<Vec<_>>().join(".");
            let e = r.per_node.entry(node.to_string()).or_default();
            e.0.insert(case);
            e.1 += 1;
            if err > e.2 || e.3.is_empty() {
                e.2 = err;
                e.3 = ta.name.clone();
            }
        }
        worst_attr = worst_attr.max(err);
        checked.push(ta.name.clone());
    }
    // Built-ins we set that Blender does not have must be at their defaults.
    for name in ["material_index", "sharp_face"] {
        if theirs.attribute(name).is_none() {
            if let Some(a) = ours.attributes.named(name) {
                if our_values(&a.data).iter().any(|v| v[0] != 0.0) {
                    fail(format!(
                        "attribute {name:?} is set here but absent (default) in Blender"
                    ));
                }
            }
        }
    }
    r.lines.push(format!("{case:28} {oc:24} max err {max_err:.2e}  hausdorff {h:.2e}  attr err {worst_attr:.2e}  attrs [{}]", checked.join(", ")));
}

/// `ours` renumbered to the reference's element order: each vertex to the reference
/// vertex at its position (within POS_TOL), each face to the reference face with the same
/// corners in the same cyclic order (starting at the same corner), each edge to the
/// reference edge on the same vertices. An element without its match is an error.
fn in_reference_order(ours: &Mesh, theirs: &MeshData) -> Result<Mesh, String> {
    let nv = ours.vertex_count();
    if nv != theirs.vertex_count()
        || ours.face_count() != theirs.face_count()
        || ours.edge_count() != theirs.edges.len()
    {
        return Err("counts differ, not renumbered".into());
    }
    let close = |a: &[f32; 3], b: &[f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() <= POS_TOL);
    // vertex_of[reference vertex] = our vertex.
    let mut vertex_of = vec![usize::MAX; nv];
    let mut taken = vec![false; nv];
    for (j, tp) in theirs.positions.iter().enumerate() {
        let i = (0..nv)
            .find(|&i| !taken[i] && close(&ours.positions[i], tp))
            .ok_or_else(|| format!("reference vertex {j} {tp:?} has no match here"))?;
        taken[i] = true;
        vertex_of[j] = i;
    }
    let mut new_of = vec![0u32; nv];
    for (j, &i) in vertex_of.iter().enumerate() {
        new_of[i] = j as u32;
    }
    let our_face = |f: usize| -> Vec<u32> {
        ours.face(f)
            .map(|c| new_of[ours.corner_verts[c] as usize])
            .collect()
    };
    let mut m = ours.clone();
    m.positions = vertex_of.iter().map(|&i| ours.positions[i]).collect();
    m.attributes
        .gather_domain(blendsynth::geometry::types::Domain::Point, &vertex_of);
    // Faces and corners.
    let mut face_of = Vec::with_capacity(ours.face_count());
    let mut corner_of = Vec::with_capacity(ours.corner_count());
    let mut used = vec![false; ours.face_count()];
    for tf in 0..theirs.face_count() {
        let r = theirs.face_offsets[tf] as usize..theirs.face_offsets[tf + 1] as usize;
        let want = &theirs.corner_verts[r];
        let found = (0..ours.face_count()).find_map(|f| {
            let have = our_face(f);
            if used[f] || have.len() != want.len() {
                return None;
            }
            let shift = have.iter().position(|&v| v == want[0])?;
            (0..have.len())
                .all(|k| have[(k + shift) % have.len()] == want[k])
                .then_some((f, shift))
        });
        let (f, shift) =
            found.ok_or_else(|| format!("reference face {tf} {want:?} has no match here"))?;
        used[f] = true;
        face_of.push(f);
        let cr = ours.face(f);
        for k in 0..cr.len() {
            corner_of.push(cr.start + (k + shift) % cr.len());
        }
    }
    m.attributes
        .gather_domain(blendsynth::geometry::types::Domain::Face, &face_of);
    m.attributes
        .gather_domain(blendsynth::geometry::types::Domain::Corner, &corner_of);
    m.corner_verts = corner_of
        .iter()
        .map(|&c| new_of[ours.corner_verts[c] as usize])
        .collect();
    m.face_offsets = theirs.face_offsets.clone();
    if m.face_offsets.is_empty() {
        m.face_offsets = vec![0];
    }
    // Edges, oriented as the reference's.
    let mut edge_of = Vec::with_capacity(ours.edge_count());
    let mut new_edge = vec![0u32; ours.edge_count()];
    for (te, tv) in theirs.edges.iter().enumerate() {
        let e = ours
            .edges
            .iter()
            .position(|ev| {
                let (a, b) = (new_of[ev[0] as usize], new_of[ev[1] as usize]);
                (a, b) == (tv[0], tv[1]) || (b, a) == (tv[0], tv[1])
            })
            .ok_or_else(|| format!("reference edge {te} {tv:?} has no match here"))?;
        edge_of.push(e);
        new_edge[e] = te as u32;
    }
    m.attributes
        .gather_domain(blendsynth::geometry::types::Domain::Edge, &edge_of);
    m.edges = theirs.edges.clone();
    m.corner_edges = corner_of
        .iter()
        .map(|&c| new_edge[ours.corner_edges[c] as usize])
        .collect();
    Ok(m)
}

/// Cases blendsynth refuses by name (Blender's mesh is there to show why), each with the
/// test that checks its message.
const REFUSED_CASES: &[(&str, &str)] = &[
    (
        "import_nodes/imp_ply_bent",
        "import_ply_normals_deformed_are_refused_by_name",
    ),
    (
        "volume_nodes/refused_mesh_to_volume",
        "unmatched_volume_nodes_are_refused_by_name",
    ),
    (
        "volume_nodes/refused_distribute_random",
        "unmatched_volume_nodes_are_refused_by_name",
    ),
];

fn run_scene(dir: &Path, r: &mut Report) -> usize {
    let scene = Scene::load(dir).unwrap_or_else(|e| panic!("{e}"));
    let scene_name = dir.file_name().unwrap().to_string_lossy().to_string();
    for (i, e) in scene.file.evaluated.iter().enumerate() {
        let case = format!("{scene_name}/{}", e.object);
        let reference = scene.load_evaluated(i).unwrap_or_else(|e| panic!("{e}"));
        // A case blendsynth would not evaluate (an unsupported node or modifier makes the
        // object frozen: Blender's own mesh) compares Blender with itself: a failure.
        let object = scene.object(&e.object).expect("case object");
        if let Some((_, test)) = REFUSED_CASES.iter().find(|(c, _)| *c == case) {
            if geometry::evaluate_object(&scene, &e.object, e.frame, &[]).is_ok() {
                r.failures
                    .push(format!("{case}: evaluates now; compare it ({test})"));
            }
            r.lines.push(format!("{case:28} REFUSED ({test})"));
            continue;
        }
        // A volume made by a node blendsynth does not evaluate is refused by name, not
        // frozen (unmatched_volume_nodes_are_refused_by_name checks the message).
        if e.volume_grids > 0
            && geometry::source::object_source(&scene, object, e.frame, &[]).is_err()
        {
            r.lines.push(format!("{case:28} REFUSED (volume)"));
            continue;
        }
        if let Ok(geometry::source::Source::Frozen(_)) =
            geometry::source::object_source(&scene, object, e.frame, &[])
        {
            // A baked Simulation zone is Blender's mesh by design (tests below).
            if let Some(why) = geometry::source::simulation_after_start(&scene, object, e.frame) {
                if why.contains("baked data") {
                    r.lines.push(format!("{case:28} FROZEN (baked simulation)"));
                    continue;
                }
            }
            let node = geometry::source::unsupported_gn_node(&scene, object);
            r.failures.push(format!(
                "{case}: frozen, blendsynth does not evaluate it (unsupported node: {node:?})"
            ));
            r.lines.push(format!("{case:28} FROZEN"));
            continue;
        }
        match geometry::evaluate_object(&scene, &e.object, e.frame, &[])
            .and_then(|g| geometry::realize_to_mesh(&g))
        {
            Ok(m) => {
                if let Err(err) = m.validate() {
                    r.failures.push(format!("{case}: invalid mesh: {err}"));
                }
                // Convex Hull's element order is Bullet's internal one, not reproduced
                // (src/geometry/nodes/convex_hull.rs): its cases are renumbered to
                // Blender's order first, then held to the same checks.
                let m = if e.object.starts_with("hull_") {
                    match in_reference_order(&m, &reference) {
                        Ok(m) => m,
                        Err(err) => {
                            r.failures.push(format!("{case}: {err}"));
                            m
                        }
                    }
                } else {
                    m
                };
                compare(&case, &m, &reference, r)
            }
            Err(err) => {
                r.failures.push(format!("{case}: {err}"));
                r.lines.push(format!("{case:28} ERROR {err}"));
            }
        }
    }
    scene.file.evaluated.len()
}

#[test]
fn geometry_nodes_match_blender() {
    let mut r = Report {
        lines: Vec::new(),
        failures: Vec::new(),
        per_node: Default::default(),
    };
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("fixtures/geometry/scenes")
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    // The fixture scene of the renderer tests: Grid, Subdivide, noise Set Position,
    // Poisson distribution, instanced Ico Spheres, Join, Set Material, Shade Smooth.
    dirs.push(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/scenes/geonodes"));
    let mut n = 0;
    for d in &dirs {
        n += run_scene(d, &mut r);
    }
    println!("Geometry Nodes parity, {n} cases:");
    for l in &r.lines {
        println!("  {l}");
    }
    println!("Per node (NODE.CASE attributes): cases, attributes, worst absolute error");
    for (node, (cases, attrs, worst, name)) in &r.per_node {
        println!(
            "  {node:16} {:3} cases {attrs:3} attrs  worst {worst:.2e} ({name})",
            cases.len()
        );
    }
    if !r.failures.is_empty() {
        panic!(
            "{} mismatch(es):\n  {}",
            r.failures.len(),
            r.failures.join("\n  ")
        );
    }
    assert!(n >= 30, "expected the parity fixtures, found {n} cases");
}

fn load(name: &str) -> Scene {
    Scene::load(&scenes_dir().join(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn evaluated(scene: &Scene, object: &str) -> MeshData {
    let i = scene
        .file
        .evaluated
        .iter()
        .position(|e| e.object == object)
        .expect("reference");
    scene.load_evaluated(i).unwrap()
}

fn mesh_of(
    scene: &Scene,
    object: &str,
    frame: f64,
    overrides: &[(String, serde_json::Value)],
) -> Result<Mesh, String> {
    geometry::evaluate_object(scene, object, frame, overrides)
        .and_then(|g| geometry::realize_to_mesh(&g))
        .map_err(|e| e.to_string())
}

fn max_diff(a: &[[f32; 3]], b: &[[f32; 3]]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f32::max))
        .fold(0.0, f32::max)
}

#[test]
fn overrides_reach_modifier_inputs_and_node_values() {
    let scene = load("graph");
    let frame = scene.file.scene.frame_current as f64;
    // A modifier input set by data path gives what Blender gave the object that set it.
    let set = evaluated(&scene, "io_set");
    let m = mesh_of(
        &scene,
        "io_default",
        frame,
        &[(
            "objects[\"io_default\"].modifiers[\"io_default\"][\"Socket_2\"]".into(),
            serde_json::json!(1.75),
        )],
    )
    .unwrap();
    assert!(
        max_diff(&m.positions, &set.positions) <= POS_TOL,
        "modifier input override"
    );
    // A node socket value (here an animated one: the override wins over the F-curve).
    let base = mesh_of(&scene, "animated", frame, &[]).unwrap();
    let path = "bpy.data.node_groups[\"animated\"].nodes[\"Height\"].outputs[0].default_value";
    let m = mesh_of(
        &scene,
        "animated",
        frame,
        &[(path.into(), serde_json::json!(3.0))],
    )
    .unwrap();
    assert!(
        m.positions.iter().all(|p| (p[2] - 3.0).abs() < 1e-6),
        "{:?}",
        m.positions
    );
    assert!(base.positions.iter().all(|p| (p[2] - 3.0).abs() > 0.5));
    // The animation itself: at frame 11 the value is 1.2 and Scene Time says 11.
    let m = mesh_of(&scene, "animated", 11.0, &[]).unwrap();
    assert!(
        m.positions.iter().all(|p| (p[2] - 1.2).abs() < 1e-6),
        "{:?}",
        m.positions
    );
    // Bad paths are errors naming the path.
    let e = mesh_of(
        &scene,
        "io_default",
        frame,
        &[(
            "node_groups[\"nope\"].nodes[\"x\"].outputs[0].default_value".into(),
            serde_json::json!(1),
        )],
    )
    .unwrap_err();
    assert!(e.contains("nope"), "{e}");
}

#[test]
fn unsupported_nodes_are_errors_naming_tree_and_node() {
    let scene =
        Scene::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/scenes/geonodes"))
            .unwrap();
    let over = [(
        "node_groups[\"Terrain Builder\"].nodes[\"Noise Texture\"].noise_dimensions".to_string(),
        serde_json::json!("5D"),
    )];
    let e = mesh_of(&scene, "Terrain", 1.0, &over).unwrap_err();
    assert!(
        e.contains("Terrain Builder") && e.contains("Noise Texture") && e.contains("5D"),
        "{e}"
    );
    // (The Ico Sphere above level 1, this test's example until it was evaluated.)
    let over = [("node_groups[\"Terrain Builder\"].nodes[\"Ico Sphere\"].inputs[\"Subdivisions\"].default_value".to_string(), serde_json::json!(3))];
    mesh_of(&scene, "Terrain", 1.0, &over).unwrap();
    let e = mesh_of(&scene, "No Such Object", 1.0, &[]).unwrap_err();
    assert!(e.contains("No Such Object"), "{e}");
}

#[test]
fn exports_round_trip() {
    let scene = load("subdivide");
    let m = mesh_of(&scene, "sub_cylinder_1", 1.0, &[]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("m.glb");
    geometry::write_glb(&glb, &m, "sub_cylinder_1").unwrap();
    let back = blendsynth::scene::read_glb(&glb).unwrap();
    assert_eq!(back.positions, m.positions);
    assert_eq!(back.corner_verts, m.corner_verts);
    assert_eq!(back.edges, m.edges);
    assert!(back.attribute("UVMap").is_some());
    let ply = dir.path().join("m.ply");
    geometry::write_ply(&ply, &m).unwrap();
    let head = std::fs::read(&ply).unwrap();
    assert!(String::from_utf8_lossy(&head[..200])
        .contains(&format!("element vertex {}", m.vertex_count())));
    let obj = dir.path().join("m.obj");
    geometry::write_obj(&obj, &m).unwrap();
    let o = blendsynth::scene::read_obj(&obj).unwrap();
    assert_eq!(o.vertex_count(), m.vertex_count());
    assert_eq!(o.face_count(), m.face_count());
    // (tobj renumbers vertices in order of use, so compare what each corner points at.)
    let corner_pos =
        |p: &[[f32; 3]], cv: &[u32]| cv.iter().map(|&v| p[v as usize]).collect::<Vec<_>>();
    assert_eq!(
        corner_pos(&o.positions, &o.corner_verts),
        corner_pos(&m.positions, &m.corner_verts)
    );
}

#[test]
fn parity_fixtures_stay_small() {
    fn size(p: &Path) -> u64 {
        std::fs::read_dir(p)
            .unwrap()
            .map(|e| e.unwrap().path())
            .map(|p| {
                if p.is_dir() {
                    size(&p)
                } else {
                    p.metadata().unwrap().len()
                }
            })
            .sum()
    }
    let total = size(&scenes_dir());
    // 6 MB held the Geometry Nodes scenes; the modifier scenes (mirror, triangulate,
    // deform, solidify: 0.45 MB, inputs shared between cases) raised it to 7 MB; the
    // mesh topology, accumulate/blur, point/instance and function node scenes
    // (gn_mesh_nodes.py: 0.84 MB, mostly their node trees in scene.json), the zone and
    // string scenes (gn_zones.py: 0.57 MB, most of it scene.json) and the curve node
    // scenes (gn_curve_nodes.py: 0.66 MB, mostly node trees) to 10 MB; Trim Curve, Fillet
    // Curve, Index of Nearest, Shortest Edge Paths, instance propagation and Pick Instance
    // (gn_more_nodes.py: 0.97 MB, three quarters of it scene.json) to 10.5 MB; the
    // Simulation zone scene (gn_zones.py scene_simulation: 0.2 MB, three quarters of it
    // node trees; its per-frame references are simulation_refs.json, 11 kB) to 10.6 MB;
    // Duplicate Elements, Quadratic Bezier, Points to Curves and Face Set Boundaries
    // (gn_topo_nodes.py: 0.54 MB, nearly all of it scene.json), and the input,
    // pass-through, Remove Named Attribute and Replace Material scenes (gn_input_nodes.py:
    // 0.26 MB) to 11.4 MB; the NURBS and Catmull-Rom scene (gn_curve_nodes.py
    // scene_curve_types: 0.31 MB, 0.19 MB of it scene.json), the join defaults
    // (gn_mesh_nodes.py: 0.09 MB), the field statistics, gizmo, curve Bounding Box,
    // camera and image scenes (gn_field_stats.py: 0.38 MB, nearly all of it scene.json)
    // and Sample UV Surface, Split to Instances and Set Mesh Normal (gn_sample_nodes.py:
    // 0.5 MB, mostly scene.json) to 12.7 MB; Interpolate Curves, Trim Curve on Catmull-Rom
    // and NURBS to Bezier (gn_curve_nodes.py scene_interpolate_curves: 0.43 MB, nearly all
    // of it scene.json) to 13.1 MB; the volume scene (gn_volume_nodes.py: 0.15 MB, nearly
    // all of it scene.json; its grids are volume_refs.json, 12 kB) to 13.25 MB; the Import
    // nodes scene (gn_import_nodes.py: 0.12 MB, 5 kB of it the copied input files) to
    // 13.35 MB; the Format String, Import CSV / Text and Deform Curves on Surface scenes
    // (gn_misc_nodes.py: 0.32 MB, nearly all of it scene.json) and the Volume to Mesh cases
    // (gn_volume_nodes.py: 0.18 MB, 0.1 MB of it the evaluated meshes) to 13.9 MB; the
    // Mesh to Volume cases (gn_volume_nodes.py: 0.1 MB, mostly node trees; their grids
    // are volume_refs.json, 72 kB in all), the Points to Volume and Distribute Points in
    // Volume cases (gn_volume_nodes.py: 0.11 MB, mostly node trees; 20 kB the evaluated
    // points) to 14.1 MB; the cases from Molecular Nodes' files (gn_realfile_nodes.py:
    // 0.27 MB, one scene) to 14.4 MB; Set Curve Normal's Free mode
    // (gn_curve_normal_free.py: 0.91 MB, 0.45 MB of it scene.json) to 15.3 MB; free mesh
    // normals under Transform Geometry and Realize Instances (gn_sample_nodes.py: 58 kB)
    // fit under it.
    assert!(
        total < 15_300_000,
        "fixtures/geometry/scenes holds {total} bytes; keep it under 15.3 MB"
    );
}

/// Modifiers users randomise take `--set` overrides natively: an override of a Mirror's
/// merge or Bisect Flip gives what Blender gave the case authored that way; an override
/// turning on an option blendsynth does not evaluate (Triangulate's Keep Normals) is an
/// error naming the object, the modifier's option and the path, never Blender's mesh for
/// other settings.
#[test]
fn modifier_overrides_evaluate_or_are_refused_by_name() {
    let scene = load("mirror");
    let frame = scene.file.scene.frame_current as f64;
    let want = evaluated(&scene, "mirror_no_merge");
    let m = mesh_of(
        &scene,
        "mirror_x",
        frame,
        &[(
            "objects[\"mirror_x\"].modifiers[\"Mirror0\"].use_mirror_merge".into(),
            serde_json::json!(false),
        )],
    )
    .unwrap();
    assert_eq!(m.vertex_count(), want.vertex_count());
    assert!(max_diff(&m.positions, &want.positions) <= POS_TOL);
    // Turning on Bisect Flip (and off the merge) gives Blender's mesh for those settings.
    let scene = load("issue26_geo");
    let want = evaluated(&scene, "bisect_flip_x");
    let m = mesh_of(
        &scene,
        "bisect_x",
        frame,
        &[
            (
                "objects[\"bisect_x\"].modifiers[\"Mirror0\"].use_bisect_flip_axis".into(),
                serde_json::json!([true, false, false]),
            ),
            (
                "objects[\"bisect_x\"].modifiers[\"Mirror0\"].use_mirror_merge".into(),
                serde_json::json!(false),
            ),
        ],
    )
    .unwrap();
    assert_eq!(m.corner_verts, want.corner_verts);
    assert!(max_diff(&m.positions, &want.positions) <= POS_TOL);
    // An option blendsynth does not evaluate is refused naming object, option and path.
    let scene = load("triangulate");
    let path = "objects[\"tri_beauty\"].modifiers[\"Triangulate0\"].keep_custom_normals";
    let e = mesh_of(
        &scene,
        "tri_beauty",
        frame,
        &[(path.into(), serde_json::json!(true))],
    )
    .unwrap_err();
    assert!(
        e.contains("tri_beauty") && e.contains("Keep Normals") && e.contains("keep_custom_normals"),
        "{e}"
    );
    // A Displace with a legacy texture is refused by name too.
    let scene = load("deform");
    let o = scene.object("displace_normal").unwrap();
    let mut p = o.modifiers[0].properties.clone();
    p.insert("texture".into(), serde_json::json!({"name": "Clouds"}));
    let why = geometry::modifiers::unsupported("DISPLACE", &p).unwrap();
    assert!(
        why.contains("Clouds") && why.contains("legacy textures"),
        "{why}"
    );
}

/// The Screw modifier takes `--set` overrides natively: one of the fixture's cases with
/// another case's settings (axis, angle, offset, iterations, render steps, order, flip,
/// shading, UV stretch) set on it gives what Blender gave that case, UVs included.
#[test]
fn screw_overrides_evaluate_natively() {
    use serde_json::json;
    let scene = load("screw");
    let frame = scene.file.scene.frame_current as f64;
    let want = evaluated(&scene, "screw_open_offset");
    let path = |k: &str| format!("objects[\"screw_stretch_uv\"].modifiers[\"Screw0\"].{k}");
    let set: Vec<(String, serde_json::Value)> = [
        ("axis", json!("Y")),
        ("angle", json!(-(270f64.to_radians()))),
        ("screw_offset", json!(0.6)),
        ("iterations", json!(2)),
        ("render_steps", json!(5)),
        ("use_normal_calculate", json!(true)),
        ("use_normal_flip", json!(true)),
        ("use_smooth_shade", json!(false)),
        ("use_stretch_u", json!(false)),
        ("use_stretch_v", json!(false)),
    ]
    .into_iter()
    .map(|(k, v)| (path(k), v))
    .collect();
    let m = mesh_of(&scene, "screw_stretch_uv", frame, &set).unwrap();
    assert_eq!(m.corner_verts, want.corner_verts);
    assert_eq!(m.edges, want.edges);
    assert!(max_diff(&m.positions, &want.positions) <= POS_TOL);
    let uv = |d: &[[f32; 2]], e: &[[f32; 2]]| {
        d.iter()
            .zip(e)
            .map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()))
            .fold(0.0f32, f32::max)
    };
    let Array::Float2(ours) = &m.attributes.named("UVMap").expect("UV map").data else {
        panic!("UVMap is not FLOAT2 here");
    };
    let AttributeData::Float2(theirs) = &want.attribute("UVMap").expect("UV map").data else {
        panic!("UVMap is not FLOAT2");
    };
    assert_eq!(ours.len(), theirs.len());
    assert!(uv(ours, theirs) <= 1e-5);
    // An axis that is not X, Y or Z is named.
    let mut p = scene.object("screw_loop_z").unwrap().modifiers[0]
        .properties
        .clone();
    assert_eq!(geometry::modifiers::unsupported("SCREW", &p), None);
    p.insert("axis".into(), json!("W"));
    let why = geometry::modifiers::unsupported("SCREW", &p).unwrap();
    assert!(why.contains("axis"), "{why}");
}

/// Every option a native modifier does not evaluate is named (in the words `inspect` and
/// `render` print), starting from each fixture case's own settings, which are evaluated.
#[test]
fn unevaluated_modifier_options_are_named() {
    use serde_json::json;
    let cases: &[(&str, &str, &str, serde_json::Value, &str)] = &[
        (
            "triangulate",
            "tri_beauty",
            "keep_custom_normals",
            json!(true),
            "Keep Normals",
        ),
        (
            "deform",
            "smooth_default",
            "vertex_group",
            json!("Group"),
            "Vertex Group \"Group\"",
        ),
        (
            "deform",
            "weld_connected",
            "loose_edges",
            json!(true),
            "Only Loose Edges",
        ),
        (
            "deform",
            "weld_all",
            "vertex_group",
            json!("Group"),
            "Vertex Group \"Group\"",
        ),
        (
            "deform",
            "displace_normal",
            "direction",
            json!("CUSTOM_NORMAL"),
            "Custom Normal",
        ),
        (
            "deform",
            "displace_normal",
            "texture",
            json!({"name": "Tex"}),
            "Texture \"Tex\"",
        ),
        (
            "solidify",
            "solid_thick",
            "solidify_mode",
            json!("NON_MANIFOLD"),
            "Complex",
        ),
        (
            "solidify",
            "solid_thick",
            "use_quality_normals",
            json!(true),
            "High Quality Normals",
        ),
        (
            "solidify",
            "solid_thick",
            "thickness_clamp",
            json!(0.5),
            "Clamp",
        ),
        (
            "solidify",
            "solid_thick",
            "material_offset",
            json!(1),
            "Material Offset",
        ),
        (
            "array",
            "array_relative",
            "use_merge_vertices",
            json!(true),
            "Merge",
        ),
        (
            "issue26_geo",
            "wire_default",
            "use_relative_offset",
            json!(true),
            "Offset Relative",
        ),
        (
            "issue26_geo",
            "wire_default",
            "vertex_group",
            json!("Group"),
            "Vertex Group \"Group\"",
        ),
    ];
    for (scene, object, key, value, want) in cases {
        let s = load(scene);
        let m = &s.object(object).expect("case object").modifiers[0];
        assert_eq!(
            geometry::modifiers::unsupported(&m.kind, &m.properties),
            None,
            "{object}: the fixture's own settings are evaluated"
        );
        let mut p = m.properties.clone();
        p.insert(key.to_string(), value.clone());
        let why = geometry::modifiers::unsupported(&m.kind, &p)
            .unwrap_or_else(|| panic!("{object}: {key}={value} should keep it frozen"));
        assert!(why.contains(want), "{object}: {key}: {why}");
    }
}

/// A Subdivision Surface after a Solidify rim keeps the object frozen and is named:
/// blendsynth's subdivision of the rim is not Blender's yet (make_gn_refs.py,
/// scene_solidify); without a rim the same stack is evaluated natively.
#[test]
fn subdivision_after_a_solidify_rim_is_frozen_by_name() {
    let s = load("solidify");
    for (object, frozen) in [("solid_rim_only", true), ("solid_no_rim", false)] {
        let mut o = s.object(object).expect("case object").clone();
        let mut sub = o.modifiers[0].clone();
        sub.name = "Subdivision".into();
        sub.kind = "SUBSURF".into();
        sub.properties = Default::default();
        o.modifiers.push(sub);
        let why = geometry::source::frozen_reason(&s, &o);
        if frozen {
            let why = why.unwrap_or_else(|| panic!("{object}: a subdivided rim should be frozen"));
            assert!(
                why.contains("SUBSURF \"Subdivision\" after the rim of SOLIDIFY"),
                "{object}: {why}"
            );
        } else {
            assert_eq!(why, None, "{object}: no rim, evaluated natively");
        }
    }
}

/// FNV-1a 64 of u32s as little-endian bytes (make_ico_digest.py's).
fn fnv1a64(v: impl IntoIterator<Item = u32>) -> String {
    let mut h: u64 = 0xcbf29ce484222325;
    for x in v {
        for b in x.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x100000001b3);
        }
    }
    format!("{h:016x}")
}

/// The Ico Sphere at Subdivisions 1 to 5 against Blender's, held to digests
/// (fixtures/geometry/make_ico_digest.py; levels 4 and 5 whole would not fit the fixture
/// budget): counts, the topology by hash (so faces, corners and edges in Blender's
/// order), every STRIDE-th position and UV within 1e-5, and the sums of all of them.
#[test]
fn ico_sphere_levels_match_blender_digests() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/ico_digest.json");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let scene = load("issue26_geo");
    let node = "node_groups[\"ico_sub2\"].nodes[\"Ico Sphere\"].inputs";
    let levels = doc["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 5);
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    for lv in levels {
        let n = lv["subdivisions"].as_i64().unwrap();
        let over = [
            (
                format!("{node}[\"Subdivisions\"].default_value"),
                serde_json::json!(n),
            ),
            (
                format!("{node}[\"Radius\"].default_value"),
                lv["radius"].clone(),
            ),
        ];
        let m = mesh_of(&scene, "ico_sub2", 1.0, &over).unwrap();
        let counts: Vec<u64> = lv["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .collect();
        let ours = [
            m.vertex_count(),
            m.edge_count(),
            m.face_count(),
            m.corner_count(),
        ]
        .map(|c| c as u64);
        assert_eq!(ours.to_vec(), counts, "level {n}: counts");
        for (key, got) in [
            ("corner_verts", fnv1a64(m.corner_verts.iter().copied())),
            ("corner_edges", fnv1a64(m.corner_edges.iter().copied())),
            ("edges", fnv1a64(m.edges.iter().flatten().copied())),
            ("face_offsets", fnv1a64(m.face_offsets.iter().copied())),
        ] {
            assert_eq!(got, lv[key].as_str().unwrap(), "level {n}: {key}");
        }
        let uv = match &m.attributes.named("UVMap").expect("UVMap").data {
            Array::Float2(v) => v.clone(),
            _ => panic!("UVMap is not FLOAT2"),
        };
        let stride = lv["position_stride"].as_u64().unwrap() as usize;
        for (i, want) in lv["positions"].as_array().unwrap().iter().enumerate() {
            let p = m.positions[i * stride];
            for k in 0..3 {
                let w = f(&want[k]);
                assert!(
                    (p[k] as f64 - w).abs() <= POS_TOL as f64,
                    "level {n}: vertex {}: {p:?} vs {want}",
                    i * stride
                );
            }
        }
        let stride = lv["uv_stride"].as_u64().unwrap() as usize;
        for (i, want) in lv["uvs"].as_array().unwrap().iter().enumerate() {
            let u = uv[i * stride];
            for k in 0..2 {
                assert!(
                    (u[k] as f64 - f(&want[k])).abs() <= 1e-5,
                    "level {n}: corner {} UV {u:?} vs {want}",
                    i * stride
                );
            }
        }
        for k in 0..3 {
            let sum: f64 = m.positions.iter().map(|p| p[k] as f64).sum();
            let w = f(&lv["position_sum"][k]);
            assert!(
                (sum - w).abs() <= 1e-4,
                "level {n}: position sum {sum} vs {w}"
            );
        }
        for k in 0..2 {
            let sum: f64 = uv.iter().map(|u| u[k] as f64).sum();
            let w = f(&lv["uv_sum"][k]);
            assert!((sum - w).abs() <= 1e-3, "level {n}: UV sum {sum} vs {w}");
        }
    }
}

/// Curve node options blendsynth does not evaluate are errors naming the node and the
/// option, never another conversion: a Set Curve Normal mode Blender does not have. (NURBS
/// to Bezier and Set Curve Normal's Free mode, once refused here, are evaluated: cases
/// st_nurbs_bezier and curve_normal_free/*.)
#[test]
fn unevaluated_curve_node_options_are_named() {
    let scene = load("curve_edit");
    let frame = scene.file.scene.frame_current as f64;
    let cases = [(
        "ce_normal_z_up",
        "node_groups[\"ce_normal_z_up\"].nodes[\"Set Curve Normal\"].mode",
        "SPIRAL",
        "\"SPIRAL\"",
    )];
    for (object, path, value, want) in cases {
        let e = mesh_of(
            &scene,
            object,
            frame,
            &[(path.to_string(), serde_json::json!(value))],
        )
        .unwrap_err();
        let node = path.split('"').nth(3).unwrap();
        assert!(e.contains(node) && e.contains(want), "{object}: {e}");
    }
}

/// Simulation zones played from their start (fixtures/geometry/make_simulation_refs.py:
/// Blender opened afresh and played from frame 1 to each frame): positions and the
/// stored state items (single values, captured fields, a face-domain field) at frames
/// before the range, its start, steps, a subframe, its end and past it, for the scene's
/// range, a zone's own range, Simulation Cache off, Skip from Scene Time and a zone in a
/// node group; at 30/1.001 fps.
#[test]
fn simulation_zones_match_blender_played_to_each_frame() {
    let scene = load("simulation");
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/simulation_refs.json");
    let refs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    let mut checked = 0;
    for (case, frames) in refs.as_object().unwrap() {
        for (frame, want) in frames.as_object().unwrap() {
            let f: f64 = frame.parse().unwrap();
            let m = match mesh_of(&scene, case, f, &[]) {
                Ok(m) => m,
                Err(e) => {
                    failures.push(format!("{case} at {frame}: {e}"));
                    continue;
                }
            };
            let pos = want["positions"].as_array().unwrap();
            if pos.len() != m.vertex_count() {
                failures.push(format!(
                    "{case} at {frame}: {} vertices, Blender {}",
                    m.vertex_count(),
                    pos.len()
                ));
                continue;
            }
            let mut err = 0.0f64;
            for (p, q) in m.positions.iter().zip(pos) {
                for k in 0..3 {
                    err = err.max((p[k] as f64 - q[k].as_f64().unwrap()).abs());
                }
            }
            for (name, values) in want["attributes"].as_object().unwrap() {
                let Some(a) = m.attributes.named(name) else {
                    failures.push(format!("{case} at {frame}: no attribute {name:?}"));
                    continue;
                };
                let ours = our_values(&a.data);
                let theirs: Vec<Vec<f64>> = values
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| match v.as_array() {
                        Some(c) => c.iter().map(|x| x.as_f64().unwrap()).collect(),
                        None => vec![v.as_f64().unwrap()],
                    })
                    .collect();
                if ours.len() != theirs.len() {
                    failures.push(format!(
                        "{case} at {frame}: {name:?} has {} values, Blender {}",
                        ours.len(),
                        theirs.len()
                    ));
                    continue;
                }
                for (a, b) in ours.iter().zip(&theirs) {
                    for (x, y) in a.iter().zip(b) {
                        // Relative above 1: the doubling items reach 1024.
                        err = err.max((x - y).abs() / y.abs().max(1.0));
                    }
                }
            }
            // References are rounded to 1e-6; float steps accumulate a few ulps.
            if err > 2e-5 {
                failures.push(format!("{case} at {frame}: largest difference {err:.2e}"));
            }
            worst = worst.max(err);
            checked += 1;
        }
    }
    println!("simulation playback: {checked} case frames, worst difference {worst:.2e}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(checked >= 40, "{checked} case frames");
}

/// A zone whose bake is packed in the .blend is Blender's (baked) mesh at the exported
/// frame and an error naming the object and the zone at any other frame, never a
/// simulation of ours in place of the bake.
#[test]
fn baked_simulation_zones_are_refused_by_name() {
    let scene = load("simulation");
    let o = scene.object("sim_baked").unwrap();
    let frame = scene.file.scene.frame_current as f64;
    assert!(matches!(
        geometry::source::object_source(&scene, o, frame, &[]),
        Ok(geometry::source::Source::Frozen(_))
    ));
    let e = match geometry::source::object_source(&scene, o, 5.0, &[]) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("frame 5 of a baked simulation evaluated"),
    };
    assert!(
        e.contains("sim_baked") && e.contains("Simulation Output") && e.contains("baked data"),
        "{e}"
    );
    // The same zone unbaked plays (sim_rise is that tree).
    let o = scene.object("sim_rise").unwrap();
    assert!(!matches!(
        geometry::source::object_source(&scene, o, 5.0, &[]),
        Ok(geometry::source::Source::Frozen(_))
    ));
}

/// A frame far past the start is an error naming the limit, not hours of playback.
#[test]
fn simulation_playback_is_limited() {
    let scene = load("simulation");
    let e = mesh_of(&scene, "sim_rise", 1e9, &[]).unwrap_err();
    assert!(e.contains("limit") && e.contains("limits.md"), "{e}");
}

/// Remove Named Attribute leaves exactly the attributes Blender's evaluated mesh has
/// (the parity check above compares only the ones Blender has): per case, our named
/// attributes other than the built-ins that compare as defaults are Blender's set.
#[test]
fn removed_attributes_are_blenders() {
    let scene = load("remove_attribute");
    for case in ["ra_modes", "ra_components"] {
        let theirs = evaluated(&scene, case);
        let ours = mesh_of(&scene, case, 1.0, &[]).unwrap();
        let defaults = ["material_index", "sharp_face", "sharp_edge"];
        let mut want: Vec<&str> = theirs
            .attributes
            .iter()
            .map(|a| a.name.as_str())
            .filter(|n| !defaults.contains(n))
            .collect();
        let mut got: Vec<&str> = ours
            .attributes
            .iter()
            .filter_map(|a| a.id.name())
            .filter(|n| !defaults.contains(n))
            .collect();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want, "{case}");
        // The cases are meaningful: something was removed, something kept.
        assert!(!want.is_empty(), "{case}");
    }
}

/// Replace Material: the evaluated mesh's material slots are Blender's (empty Old
/// replaced the empty slot, the instanced cube's slot replaced before realizing).
#[test]
fn replaced_materials_are_blenders() {
    let scene = load("replace_material");
    let e = scene
        .file
        .evaluated
        .iter()
        .find(|e| e.object == "rm_grid")
        .unwrap();
    let ours = mesh_of(&scene, "rm_grid", 1.0, &[]).unwrap();
    assert_eq!(ours.materials, e.materials);
    assert_eq!(
        e.materials,
        [Some("rmD".into()), Some("rmA".into()), Some("rmC".into())]
    );
}

/// A Bake node with baked data is Blender's mesh where that is valid, else an error
/// naming the node; unbaked it passes through (`inputs_passthrough/gi_bake` above).
#[test]
fn baked_bake_nodes_are_refused_by_name() {
    let mut scene = load("inputs_passthrough");
    let o = scene.object("gi_bake").unwrap();
    assert!(matches!(
        geometry::source::object_source(&scene, o, 1.0, &[]),
        Ok(geometry::source::Source::Evaluate)
    ));
    let i = scene
        .file
        .objects
        .iter()
        .position(|o| o.name == "gi_bake")
        .unwrap();
    let bakes = scene.file.objects[i].modifiers[0]
        .bake_states
        .as_mut()
        .unwrap();
    bakes[0].baked = Some(true);
    let o = scene.object("gi_bake").unwrap();
    let why = geometry::source::simulation_after_start(&scene, o, 1.0).unwrap();
    assert!(
        why.contains("\"Bake\"") && why.contains("baked data"),
        "{why}"
    );
    // Blender's mesh stands for it while nothing it reads changes...
    assert!(matches!(
        geometry::source::object_source(&scene, o, 1.0, &[]),
        Ok(geometry::source::Source::Frozen(_))
    ));
    // ...and an override of what it reads is an error naming the node, never its inputs
    // passed on.
    let path = r#"node_groups["gi_bake"].nodes["Bake"].inputs[3].default_value"#;
    let e = mesh_of(
        &scene,
        "gi_bake",
        1.0,
        &[(path.into(), serde_json::json!(0.5))],
    )
    .unwrap_err();
    assert!(e.contains("Bake") && e.contains("baked data"), "{e}");
}

/// Field Average, Min & Max and Variance hold to the bit, not only to 1e-5: Blender's
/// ungrouped sums run in libstdc++'s `std::reduce` order (blocks of four) and its
/// ungrouped variance applies the squaring lambda to raw values too (Blender gives 0.8,
/// not 2, for the variance of 0..4); a sequential sum or the textbook variance differs.
#[test]
fn field_statistics_are_blenders_to_the_bit() {
    let scene = load("field_stats");
    let theirs = evaluated(&scene, "field_stats");
    let ours = mesh_of(
        &scene,
        "field_stats",
        scene.file.scene.frame_current as f64,
        &[],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut checked = 0;
    let mut inexact = Vec::new();
    for ta in &theirs.attributes {
        if !["avg_", "mm_", "var_"]
            .iter()
            .any(|p| ta.name.starts_with(p))
        {
            continue;
        }
        let a = ours
            .attributes
            .named(&ta.name)
            .unwrap_or_else(|| panic!("attribute {:?} missing", ta.name));
        let (e, g) = (ref_values(&ta.data), our_values(&a.data));
        let diff = e
            .iter()
            .zip(&g)
            .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
            .fold(0.0f64, f64::max);
        if e.len() != g.len() || diff != 0.0 {
            inexact.push(format!("{} (max difference {diff:e})", ta.name));
        }
        checked += 1;
    }
    assert!(
        checked >= 28,
        "expected the statistics attributes, found {checked}"
    );
    assert!(inexact.is_empty(), "not bit-exact: {inexact:?}");
}

/// Active Camera follows the timeline markers' switch (`Scene::camera_at`, checked against
/// Blender's frame_set in tests/render.rs): with a marker at frame 2 binding "Ortho", the
/// node's camera at frame 3 is Ortho (Object Info's location, as exported: -3, 0, 1), at
/// frame 1 the first marker's camera too; without markers it is the scene's Cam.
#[test]
fn active_camera_follows_camera_markers() {
    let location = |scene: &Scene, frame: f64| -> Vec<f64> {
        let m = mesh_of(scene, "camera_image", frame, &[]).unwrap_or_else(|e| panic!("{e}"));
        let a = m.attributes.named("cam_location").expect("cam_location");
        our_values(&a.data).concat()
    };
    let mut scene = load("camera_image");
    let exported = |name: &str| -> Vec<f64> {
        let o = scene.file.objects.iter().find(|o| o.name == name).unwrap();
        o.location.iter().map(|v| *v as f32 as f64).collect()
    };
    let (cam, ortho) = (exported("Cam"), exported("Ortho"));
    assert_ne!(cam, ortho);
    assert_eq!(location(&scene, 3.0), cam);
    scene
        .file
        .scene
        .camera_markers
        .push(blendsynth::scene::CameraMarker {
            frame: 2,
            camera: "Ortho".into(),
        });
    assert_eq!(location(&scene, 3.0), ortho);
    assert_eq!(location(&scene, 1.0), ortho);
}

/// Camera Info with a depth-of-field focus on a bone (Blender measures to the bone) is
/// an error naming the node and the bone, not the focus object's origin distance.
#[test]
fn camera_info_focus_on_a_bone_is_refused_by_name() {
    let mut scene = load("camera_image");
    let cam = scene
        .file
        .cameras
        .iter_mut()
        .find(|c| c.name == "CamData")
        .expect("camera data");
    cam.properties
        .get_mut("dof")
        .and_then(|d| d.as_object_mut())
        .expect("dof")
        .insert("focus_subtarget".into(), "Head".into());
    let err = mesh_of(&scene, "camera_image", 3.0, &[]).unwrap_err();
    assert!(
        err.contains("GeometryNodeCameraInfo") && err.contains("\"Head\""),
        "{err}"
    );
}

/// Set Mesh Normal: the corner normals blendsynth renders a Geometry Nodes mesh with
/// (`Mesh::corner_normals`, what `to_scene` hands the renderer) are Blender's evaluated
/// corner normals (the export's per-corner normals): Free custom normals on points, faces
/// and corners used unnormalized as Blender does, and Sharpness with the custom normals
/// removed or kept. Tangent Space is refused by name.
#[test]
fn set_mesh_normal_corner_normals_are_blenders() {
    let scene = load("set_mesh_normal");
    let cases = [
        "smn_free_point",
        "smn_free_face",
        "smn_free_corner",
        "smn_sharp_remove",
        "smn_sharp_keep",
    ];
    for case in cases {
        let theirs = evaluated(&scene, case);
        let ours = mesh_of(&scene, case, 1.0, &[]).unwrap();
        let cn = ours.corner_normals();
        assert_eq!(cn.len(), theirs.corner_normals.len(), "{case}");
        let err = max_diff(&cn, &theirs.corner_normals);
        assert!(err < 1e-5, "{case}: corner normals differ by {err:e}");
        // What the renderer is given is the same where Cycles reads Blender's corner
        // normals (corner custom normals, or none); point and face ones Cycles reads per
        // vertex on smooth faces only (`Mesh::shading_corner_normals`), and these meshes'
        // faces are all flat.
        let sd = ours.to_scene(case);
        if matches!(case, "smn_free_corner" | "smn_sharp_remove") {
            assert_eq!(sd.corner_normals, cn, "{case}");
        } else {
            // Smooth faces: Blender's corner normals; flat faces: the face normal.
            let sharp = ours.sharp_faces();
            let has_sharp = ours.attributes.named("sharp_face").is_some();
            for f in 0..ours.face_count() {
                let smooth = if has_sharp {
                    !sharp[f]
                } else {
                    case != "smn_free_face"
                };
                for c in ours.face(f) {
                    let want = if smooth && case != "smn_free_face" {
                        cn[c]
                    } else if smooth {
                        sd.corner_normals[c]
                    } else {
                        ours.face_normal(f)
                    };
                    assert_eq!(sd.corner_normals[c], want, "{case} corner {c}");
                }
            }
        }
    }
    // The cases are meaningful: unnormalized custom normals reach the corners, and
    // keeping or removing them changes the normals.
    let keep = mesh_of(&scene, "smn_sharp_keep", 1.0, &[])
        .unwrap()
        .corner_normals();
    let remove = mesh_of(&scene, "smn_sharp_remove", 1.0, &[])
        .unwrap()
        .corner_normals();
    assert!(max_diff(&keep, &remove) > 0.1);
    let free = evaluated(&scene, "smn_free_point");
    let len = |n: [f32; 3]| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    assert!(free
        .corner_normals
        .iter()
        .any(|n| (len(*n) - 1.0).abs() > 0.1));
    // Tangent Space (corner fan spaces) is an error naming the node and the mode.
    let path = "node_groups[\"smn_free_corner\"].nodes[\"Set Mesh Normal\"].mode";
    let e = mesh_of(
        &scene,
        "smn_free_corner",
        1.0,
        &[(path.to_string(), serde_json::json!("TANGENT_SPACE"))],
    )
    .unwrap_err();
    assert!(
        e.contains("Set Mesh Normal") && e.contains("Tangent Space"),
        "{e}"
    );
}

/// Geometry Nodes volumes against Blender's evaluated grids (fixtures/geometry/
/// gn_volume_nodes.py writes volume_refs.json with Blender's OpenVDB module): Volume Cube's
/// Density fields at its sample points (Position, a Noise Texture, a sphere mask that
/// prunes the box, Index read as 0 against Background 0.25), its index-to-object
/// transform, OpenVDB's active voxels, Transform Geometry, Join Geometry (two volumes
/// dropped, one kept beside a mesh), Separate Components, Realize Instances (the first
/// volume, untransformed) and a Resolution below 2 (no volume).
#[test]
fn volume_nodes_match_blenders_grids() {
    let scene = load("volume_nodes");
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/volume_refs.json");
    let refs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let refs = refs.as_object().unwrap();
    assert!(refs.len() >= 10, "{} cases", refs.len());
    let frame = scene.file.scene.frame_current as f64;
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let (mut worst_value, mut worst_transform, mut voxels) = (0.0f64, 0.0f64, 0usize);
    for (case, want) in refs {
        // Mesh and Points to Volume's cases: volume_cases_match_blender.
        if case.starts_with("m2v_") || case.starts_with("p2v_") {
            continue;
        }
        let set = geometry::evaluate_object(&scene, case, frame, &[])
            .unwrap_or_else(|e| panic!("{case}: {e}"));
        let Some(want) = want.as_array() else {
            assert!(set.volume.is_none(), "{case}: Blender has no volume");
            continue;
        };
        let vol = set
            .volume
            .as_ref()
            .unwrap_or_else(|| panic!("{case}: no volume"));
        assert_eq!(vol.grids.len(), want.len(), "{case}");
        for (g, w) in vol.grids.iter().zip(want) {
            assert_eq!(g.name, w["name"].as_str().unwrap(), "{case}");
            assert_eq!(g.background as f64, f(&w["background"]), "{case}");
            // Index (0,0,0)'s image and the unit steps' (OpenVDB's indexToWorld).
            let t = &g.transform;
            for k in 0..3 {
                let d = (t[3][k] - f(&w["origin"][k])).abs();
                worst_transform = worst_transform.max(d);
                for a in 0..3 {
                    let d = (t[a][k] - f(&w["axes"][a][k])).abs();
                    worst_transform = worst_transform.max(d);
                }
            }
            assert_eq!(
                g.active_voxel_count() as u64,
                w["active"].as_u64().unwrap(),
                "{case}: active voxels"
            );
            let Some(values) = w.get("values") else {
                continue;
            };
            let (lo, hi) = g.active_bounds().unwrap();
            let box_of = |i: usize| -> [i32; 3] {
                [0, 1, 2].map(|k| w["box"][i][k].as_i64().unwrap() as i32)
            };
            assert_eq!((lo, hi), (box_of(0), box_of(1)), "{case}: active box");
            let values = values.as_array().unwrap();
            let mut n = 0;
            for k in lo[2]..=hi[2] {
                for j in lo[1]..=hi[1] {
                    for i in lo[0]..=hi[0] {
                        let d = (g.value([i, j, k]) as f64 - f(&values[n])).abs();
                        worst_value = worst_value.max(d);
                        n += 1;
                    }
                }
            }
            voxels += n;
        }
    }
    println!("volume_nodes: {voxels} voxels, worst value {worst_value:e}, worst transform {worst_transform:e}");
    assert!(voxels >= 300, "{voxels} voxels compared");
    assert!(
        worst_value <= 1e-6,
        "worst voxel value difference {worst_value:e}"
    );
    assert!(
        worst_transform <= 1e-6,
        "worst transform difference {worst_transform:e}"
    );
}

/// The grids of the cases named `prefix*` against Blender's: every active voxel, values
/// within 1e-6. Returns a line per case.
fn volume_cases_match_blender(prefix: &str, min_cases: usize, min_voxels: usize) -> Vec<String> {
    let scene = load("volume_nodes");
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/volume_refs.json");
    let refs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let frame = scene.file.scene.frame_current as f64;
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let (mut cases, mut voxels, mut worst, mut worst_case) = (0, 0usize, 0.0f64, String::new());
    let mut report = Vec::new();
    for (case, want) in refs.as_object().unwrap() {
        if !case.starts_with(prefix) {
            continue;
        }
        cases += 1;
        let set = geometry::evaluate_object(&scene, case, frame, &[])
            .unwrap_or_else(|e| panic!("{case}: {e}"));
        let Some(want) = want.as_array() else {
            assert!(set.volume.is_none(), "{case}: Blender has no volume");
            // The points pass unchanged (Points to Vertices after).
            assert_eq!(
                set.mesh.as_ref().map(|m| m.positions.len()),
                Some(3),
                "{case}"
            );
            continue;
        };
        assert!(
            set.points.is_none() && set.mesh.is_none(),
            "{case}: only the volume stays"
        );
        let vol = set
            .volume
            .as_ref()
            .unwrap_or_else(|| panic!("{case}: no volume"));
        assert_eq!(vol.grids.len(), want.len(), "{case}");
        for (g, w) in vol.grids.iter().zip(want) {
            assert_eq!(g.name, w["name"].as_str().unwrap(), "{case}");
            assert_eq!(g.background as f64, f(&w["background"]), "{case}");
            let t = &g.transform;
            // The voxel size to an ulp: Voxel Amount divides the diagonal of our evaluated
            // mesh's bounds.
            for k in 0..3 {
                assert!(
                    (t[3][k] - f(&w["origin"][k])).abs() <= 1e-9,
                    "{case}: origin"
                );
                for a in 0..3 {
                    let (ours, theirs) = (t[a][k], f(&w["axes"][a][k]));
                    assert!(
                        (ours - theirs).abs() <= 1e-7 * theirs.abs(),
                        "{case}: axes {ours} {theirs}"
                    );
                }
            }
            let (lo, hi) = g.active_bounds().unwrap_or(([0; 3], [-1; 3]));
            let box_of = |i: usize| -> [i32; 3] {
                [0, 1, 2].map(|k| w["box"][i][k].as_i64().unwrap() as i32)
            };
            let values = w["values"].as_array().unwrap();
            let (wlo, whi) = (box_of(0), box_of(1));
            let mut n = 0;
            let (mut case_worst, mut off) = (0.0f64, 0);
            for k in wlo[2]..=whi[2] {
                for j in wlo[1]..=whi[1] {
                    for i in wlo[0]..=whi[0] {
                        let d = (g.value([i, j, k]) as f64 - f(&values[n])).abs();
                        case_worst = case_worst.max(d);
                        off += (d > 1e-6) as usize;
                        n += 1;
                    }
                }
            }
            report.push(format!(
                "{case}: {} active (Blender {}), box {lo:?}..{hi:?}, {off} of {n} voxels off by more than 1e-6, worst {case_worst:.3e}",
                g.active_voxel_count(),
                w["active"]
            ));
            assert_eq!((lo, hi), (wlo, whi), "{case}: active box; {report:#?}");
            assert_eq!(
                g.active_voxel_count() as u64,
                w["active"].as_u64().unwrap(),
                "{case}: active voxels; {report:#?}"
            );
            voxels += n;
            if case_worst > worst {
                worst = case_worst;
                worst_case = case.clone();
            }
        }
    }
    println!("{report:#?}");
    println!("{prefix}: {cases} cases, {voxels} voxels, worst {worst:e} ({worst_case})");
    assert!(
        cases >= min_cases && voxels >= min_voxels,
        "{cases} cases, {voxels} voxels"
    );
    assert!(
        worst <= 1e-6,
        "worst voxel value difference {worst:e} in {worst_case}: {report:#?}"
    );
    report
}

/// Mesh to Volume against Blender's grids (gn_volume_nodes.py's `m2v_*` cases, read back
/// with Blender's OpenVDB module): the voxel size from Voxel Size and from Voxel Amount, the
/// grid transform (a plain scale: the mesh went in half a voxel shifted), OpenVDB's active
/// voxels (every voxel inside, those on a face through voxel centres included), the fog
/// ramp over the interior band (its cutoff the deepest voxel when the band is wider than
/// the inside), Density, a concave torus, and the components kept (a geometry without a
/// mesh passes unchanged; a point cloud beside a mesh is dropped).
#[test]
fn mesh_to_volume_matches_blenders_grids() {
    volume_cases_match_blender("m2v_", 8, 4000);
}

/// Points to Volume against Blender's grids (`p2v_*`): spheres with a core (the fog's
/// cutoff -1, the cores reading 1) and without (radii under a voxel: the cutoff the
/// smallest distance), a Radius field, Density, Voxel Amount over a mesh's vertices, and a
/// mesh's vertices, a point cloud and curve control points together.
#[test]
fn points_to_volume_matches_blenders_grids() {
    volume_cases_match_blender("p2v_", 5, 1500);
}

/// Mesh to Volume of an open mesh (OpenVDB's exterior flood fill leaks through the
/// boundary) and Distribute Points in Volume's Random mode (OpenVDB's scatter drawing
/// from `std::mt19937`) are errors naming the node.
#[test]
fn unmatched_volume_nodes_are_refused_by_name() {
    let scene = load("volume_nodes");
    let frame = scene.file.scene.frame_current as f64;
    let e = geometry::evaluate_object(&scene, "refused_distribute_random", frame, &[])
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Distribute Points in Volume") && e.contains("\"DENSITY_RANDOM\""),
        "{e}"
    );
    let e = geometry::evaluate_object(&scene, "refused_mesh_to_volume", frame, &[])
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Mesh to Volume") && e.contains("not closed") && e.contains("open edges"),
        "{e}"
    );
}

/// Volume to Mesh's options OpenVDB evaluates differently (a resampled grid for the Voxel
/// Amount and Voxel Size resolutions, adaptive merging above Adaptivity 0) are refused
/// naming the node and the option, never meshed as Grid / Adaptivity 0.
#[test]
fn unmatched_volume_to_mesh_options_are_refused_by_name() {
    let scene = load("volume_nodes");
    let frame = scene.file.scene.frame_current as f64;
    let node = "node_groups[\"vtm_ball\"].nodes[\"Volume to Mesh\"]";
    for (path, value, want) in [
        (
            format!("{node}.resolution_mode"),
            serde_json::json!("VOXEL_AMOUNT"),
            "Resolution \"VOXEL_AMOUNT\"",
        ),
        (
            format!("{node}.resolution_mode"),
            serde_json::json!("VOXEL_SIZE"),
            "Resolution \"VOXEL_SIZE\"",
        ),
        (
            format!("{node}.inputs[\"Adaptivity\"].default_value"),
            serde_json::json!(0.25),
            "Adaptivity 0.25",
        ),
    ] {
        let e = mesh_of(&scene, "vtm_ball", frame, &[(path, value)]).unwrap_err();
        assert!(
            e.contains("GeometryNodeVolumeToMesh") && e.contains(want),
            "{e}"
        );
    }
}

/// The Import nodes read only the export's copies: a Path the export holds no copy of (as
/// a string computed at evaluation would be), an entry pointing out of the scene folder,
/// and a file left outside the .blend's folder are errors naming the node and the path; a
/// file missing when exported gives Blender's empty geometry.
#[test]
fn import_nodes_read_only_the_exports_copies() {
    let scene = load("import_nodes");
    let path = "node_groups[\"imp_stl_ascii\"].nodes[\"Import STL\"].inputs[0].default_value";
    let e = mesh_of(
        &scene,
        "imp_stl_ascii",
        1.0,
        &[(
            path.to_string(),
            serde_json::json!("//organs/liver_f12.stl"),
        )],
    )
    .unwrap_err();
    assert!(
        e.contains("Import STL")
            && e.contains("//organs/liver_f12.stl")
            && e.contains("not in the export"),
        "{e}"
    );
    let e = mesh_of(
        &scene,
        "imp_stl_ascii",
        1.0,
        &[(path.to_string(), serde_json::json!("/etc/passwd.stl"))],
    )
    .unwrap_err();
    assert!(
        e.contains("Import STL") && e.contains("/etc/passwd.stl"),
        "{e}"
    );
    // The exported JSON edited: a copy outside the scene folder, and a file the exporter
    // left outside the .blend's folder.
    let dir = scenes_dir().join("import_nodes");
    let text = std::fs::read_to_string(dir.join("scene.json")).unwrap();
    let stl = "//../../geometry/import_files/organ_ascii.stl";
    for (edit, want) in [
        ("../../../../Cargo.toml", "leaves the scene folder"),
        ("/etc/hostname", "absolute"),
    ] {
        let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
        for f in doc["import_files"].as_array_mut().unwrap() {
            if f["path"] == stl {
                f["file"] = serde_json::json!(edit);
            }
        }
        let bad = Scene::from_json(&dir, doc.to_string().as_bytes()).unwrap();
        let e = mesh_of(&bad, "imp_stl_ascii", 1.0, &[]).unwrap_err();
        assert!(e.contains("Import STL") && e.contains(want), "{edit}: {e}");
    }
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    for f in doc["import_files"].as_array_mut().unwrap() {
        if f["path"] == stl {
            f["file"] = serde_json::Value::Null;
            f["outside"] = serde_json::json!(true);
        }
    }
    let bad = Scene::from_json(&dir, doc.to_string().as_bytes()).unwrap();
    let e = mesh_of(&bad, "imp_stl_ascii", 1.0, &[]).unwrap_err();
    assert!(
        e.contains("Import STL") && e.contains("outside") && e.contains(stl),
        "{e}"
    );
    // Missing when exported: Blender's node gives empty geometry (and so does ours).
    let m = mesh_of(&scene, "imp_missing", 1.0, &[]).unwrap();
    assert_eq!(m.vertex_count(), 0);
    assert_eq!(evaluated(&scene, "imp_missing").vertex_count(), 0);
}

/// A PLY file's vertex normals become custom normals: Blender's corner normals (its
/// 16-bit encoding of them, hence the bound) are the file's, normalized, on every corner.
#[test]
fn import_ply_normals_are_blenders_corner_normals() {
    let scene = load("import_nodes");
    let theirs = evaluated(&scene, "imp_ply_ascii");
    let ours = mesh_of(&scene, "imp_ply_ascii", 1.0, &[]).unwrap();
    let cn = ours.corner_normals();
    assert_eq!(cn.len(), theirs.corner_normals.len());
    let err = max_diff(&cn, &theirs.corner_normals);
    println!("imp_ply_ascii corner normals: max difference {err:.2e}");
    assert!(err < 2e-4, "corner normals differ by {err:e}");
    // The renderer is given the same (the faces are smooth).
    assert_eq!(ours.to_scene("x").corner_normals, cn);
    // Not the faces' own normals: the file's normals matter.
    let face = mesh_of(&scene, "imp_ply_le", 1.0, &[]).unwrap();
    assert!(face.sharp_faces().iter().all(|&s| s));
    let flat: Vec<[f32; 3]> = (0..ours.face_count())
        .flat_map(|f| ours.face(f).map(move |_| f))
        .map(|f| ours.face_normal(f))
        .collect();
    assert!(max_diff(&flat, &cn) > 0.1);
}

/// Import PLY's custom normals are relative to the corner fans in Blender and follow a
/// deformation: after a bend (Set Position) and a turn (Transform) Blender's corner
/// normals are neither the file's nor the file's turned (fixture imp_ply_bent), so
/// blendsynth refuses the deformed mesh by name, for the render and for the Normal input;
/// undeformed (imp_ply_ascii) it matches (import_ply_normals_are_blenders_corner_normals).
#[test]
fn import_ply_normals_deformed_are_refused_by_name() {
    let scene = load("import_nodes");
    let theirs = evaluated(&scene, "imp_ply_bent");
    let rest = evaluated(&scene, "imp_ply_ascii");
    assert_eq!(theirs.corner_normals.len(), rest.corner_normals.len());
    // The Transform's rotation (0.3, 0.2, 0.5), XYZ Euler, applied to the file's normals.
    let (a, b, c) = (0.3f32, 0.2f32, 0.5f32);
    let rot = |v: [f32; 3]| {
        let x = [
            v[0],
            v[1] * a.cos() - v[2] * a.sin(),
            v[1] * a.sin() + v[2] * a.cos(),
        ];
        let y = [
            x[0] * b.cos() + x[2] * b.sin(),
            x[1],
            -x[0] * b.sin() + x[2] * b.cos(),
        ];
        [
            y[0] * c.cos() - y[1] * c.sin(),
            y[0] * c.sin() + y[1] * c.cos(),
            y[2],
        ]
    };
    let turned: Vec<[f32; 3]> = rest.corner_normals.iter().map(|&n| rot(n)).collect();
    let followed = max_diff(&theirs.corner_normals, &turned);
    println!(
        "imp_ply_bent: Blender's corner normals differ from the file's turned by {followed:.3}"
    );
    assert!(followed > 0.05);
    assert!(max_diff(&theirs.corner_normals, &rest.corner_normals) > 0.05);
    let err = mesh_of(&scene, "imp_ply_bent", 1.0, &[]).unwrap_err();
    assert!(
        err.contains("\"imp_ply_bent\"") && err.contains("Import PLY") && err.contains("deformed"),
        "{err}"
    );
    // Undeformed it is still Blender's mesh.
    assert!(mesh_of(&scene, "imp_ply_ascii", 1.0, &[]).is_ok());
}

/// Import OBJ outputs one instance per object of the file (identity transforms), whose
/// meshes joined are Blender's realized mesh (the parity case realizes them in the tree).
#[test]
fn import_obj_gives_one_instance_per_object() {
    let dir = scenes_dir().join("import_nodes");
    let text = std::fs::read_to_string(dir.join("scene.json")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    for g in doc["node_groups"].as_array_mut().unwrap() {
        if g["name"] == "imp_obj" {
            for n in g["nodes"].as_array_mut().unwrap() {
                if n["bl_idname"] == "GeometryNodeRealizeInstances" {
                    n["mute"] = serde_json::json!(true);
                }
            }
        }
    }
    let scene = Scene::from_json(&dir, doc.to_string().as_bytes()).unwrap();
    let set = geometry::evaluate_object(&scene, "imp_obj", 1.0, &[]).unwrap();
    assert!(set.mesh.is_none());
    let inst = set.instances.as_ref().expect("instances");
    assert_eq!(inst.len(), 2);
    let counts: Vec<[usize; 3]> = inst
        .references
        .iter()
        .map(|r| {
            let m = r.geometry().unwrap().mesh.as_ref().unwrap();
            [m.vertex_count(), m.edge_count(), m.face_count()]
        })
        .collect();
    // Liver: 5 used vertices (the one before `o` is not), the loose edge's object Kidney 4.
    assert_eq!(counts, vec![[5, 8, 4], [4, 6, 2]]);
    let theirs = evaluated(&load("import_nodes"), "imp_obj");
    assert_eq!(theirs.vertex_count(), 9);
}

/// What Blender reports as a node error is an error naming the node here: Import Text of
/// a file that is not UTF-8 (the JSON edited to point at a binary copy: Blender's "File
/// contains invalid UTF-8 characters"), and a Format String naming an item it lacks
/// (Blender's "Input does not exist").
#[test]
fn format_string_and_import_text_errors_name_the_node() {
    let dir = scenes_dir().join("import_csv_text");
    let text = std::fs::read_to_string(dir.join("scene.json")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    for f in doc["import_files"].as_array_mut().unwrap() {
        if f["file"] == "imports/0003_tag.txt" {
            f["file"] = serde_json::json!("evaluated/0003_text_import.glb");
        }
    }
    let bad = Scene::from_json(&dir, doc.to_string().as_bytes()).unwrap();
    let e = mesh_of(&bad, "text_import", 1.0, &[]).unwrap_err();
    assert!(
        e.contains("Import Text") && e.contains("tag.txt") && e.contains("not valid UTF-8"),
        "{e}"
    );
    let dir = scenes_dir().join("format_string");
    let text = std::fs::read_to_string(dir.join("scene.json")).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    for g in doc["node_groups"].as_array_mut().unwrap() {
        for n in g["nodes"].as_array_mut().unwrap() {
            for i in n["inputs"].as_array_mut().unwrap() {
                if i["default_value"] == "a{}b" {
                    i["default_value"] = serde_json::json!("a{y}b");
                }
            }
        }
    }
    let bad = Scene::from_json(&dir, doc.to_string().as_bytes()).unwrap();
    let e = mesh_of(&bad, "fmt_0", 1.0, &[]).unwrap_err();
    assert!(
        e.contains("\"Format String\"") && e.contains("Input does not exist: \"y\""),
        "{e}"
    );
    // Unedited, both evaluate.
    assert!(mesh_of(&load("format_string"), "fmt_0", 1.0, &[]).is_ok());
}

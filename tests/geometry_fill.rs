//! Fill Curve parity with Blender 4.5 (references by fixtures/geometry/make_fill_refs.py):
//! the curves' evaluated points Blender filled are filled by blendsynth, and the meshes
//! must have Blender's vertex, edge, face and corner counts, vertices within a Hausdorff
//! distance of 1e-4 of the diagonal, the same area, flat faces, and cover the same region
//! (every triangle centroid of either mesh covered as many times by both: once, or once
//! per group where groups overlap). The triangle sets themselves may differ
//! where Delaunay has ties (a circle's points are cocircular); each case prints how many
//! of Blender's triangles we have.

mod common;

use std::path::PathBuf;

use blendsynth::geometry::attribute::AttrId;
use blendsynth::geometry::cdt::Output;
use blendsynth::geometry::curves::{Curves, CURVE_TYPE_POLY};
use blendsynth::geometry::nodes::fill_curve::fill;
use blendsynth::geometry::types::{Array, Domain};
use blendsynth::geometry::{self, Mesh};
use blendsynth::scene::Scene;
use serde_json::Value;

fn refs() -> Value {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/fill_refs.json");
    serde_json::from_str(&std::fs::read_to_string(&p).expect("fill_refs.json"))
        .expect("fill_refs.json parses")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn index_lists(v: &Value) -> Vec<Vec<usize>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|f| {
            f.as_array()
                .unwrap()
                .iter()
                .map(|i| i.as_u64().unwrap() as usize)
                .collect()
        })
        .collect()
}

fn curves_of(case: &Value) -> Curves {
    let mut c = Curves {
        curve_offsets: vec![0],
        ..Default::default()
    };
    for pts in case["curves"].as_array().unwrap() {
        let xy = floats(pts);
        c.positions
            .extend(xy.chunks(2).map(|p| [p[0] as f32, p[1] as f32, 0.0]));
        c.curve_offsets.push(c.positions.len() as u32);
    }
    let n = c.curve_count();
    c.attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![CURVE_TYPE_POLY; n]),
    );
    c.attributes.set(
        AttrId::named("cyclic"),
        Domain::Curve,
        Array::Bool(vec![true; n]),
    );
    c
}

fn area(poly: &[[f64; 2]]) -> f64 {
    (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

fn inside(p: [f64; 2], poly: &[[f64; 2]]) -> bool {
    let mut c = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        {
            c = !c;
        }
    }
    c
}

fn centroid(t: &[[f64; 2]]) -> [f64; 2] {
    [
        (t[0][0] + t[1][0] + t[2][0]) / 3.0,
        (t[0][1] + t[1][1] + t[2][1]) / 3.0,
    ]
}

fn our_faces(m: &Mesh) -> Vec<Vec<[f64; 2]>> {
    (0..m.face_count())
        .map(|f| {
            m.face(f)
                .map(|c| {
                    let p = m.positions[m.corner_verts[c] as usize];
                    [p[0] as f64, p[1] as f64]
                })
                .collect()
        })
        .collect()
}

#[test]
fn fill_curve_matches_blender() {
    let doc = refs();
    let cases = doc["cases"].as_array().unwrap();
    assert!(cases.len() >= 12, "expected the fill cases");
    let mut failures = Vec::new();
    for case in cases {
        let name = case["name"].as_str().unwrap();
        let mut fail = |m: String| failures.push(format!("{name}: {m}"));
        let c = curves_of(case);
        let ids: Vec<i32> = if case["groups"] == "curve" {
            (0..c.curve_count() as i32).collect()
        } else {
            vec![0; c.curve_count()]
        };
        let output = if case["mode"] == "NGONS" {
            Output::ValidBmeshWithHoles
        } else {
            Output::InsideWithHoles
        };
        let m = fill(&c, &ids, output).unwrap_or_else(|e| panic!("{name}: {e}"));
        m.validate()
            .unwrap_or_else(|e| panic!("{name}: invalid mesh: {e}"));

        let bv: Vec<[f64; 3]> = floats(&case["verts"])
            .chunks(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        let bf = index_lists(&case["faces"]);
        let bt = index_lists(&case["tris"]);
        let b2 = |i: usize| [bv[i][0], bv[i][1]];
        let counts = |v: usize, e: usize, f: usize, c: usize| format!("v{v} e{e} f{f} c{c}");
        let ours = counts(
            m.vertex_count(),
            m.edge_count(),
            m.face_count(),
            m.corner_count(),
        );
        let theirs = counts(
            bv.len(),
            case["edges"].as_u64().unwrap() as usize,
            bf.len(),
            bf.iter().map(Vec::len).sum(),
        );
        if ours != theirs {
            fail(format!(
                "counts differ: blendsynth {ours}, Blender {theirs}"
            ));
        }
        // Hausdorff between the vertex sets.
        let d = |p: [f32; 3], q: [f64; 3]| {
            ((p[0] as f64 - q[0]).powi(2)
                + (p[1] as f64 - q[1]).powi(2)
                + (p[2] as f64 - q[2]).powi(2))
            .sqrt()
        };
        let h1 = m
            .positions
            .iter()
            .map(|p| bv.iter().map(|q| d(*p, *q)).fold(f64::INFINITY, f64::min))
            .fold(0.0, f64::max);
        let h2 = bv
            .iter()
            .map(|q| {
                m.positions
                    .iter()
                    .map(|p| d(*p, *q))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &bv {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
        let h = h1.max(h2);
        if h > 1e-4 * diag {
            fail(format!("Hausdorff {h:.3e} > 1e-4 x diagonal {diag:.3}"));
        }
        // Area and orientation.
        let of = our_faces(&m);
        let our_area: f64 = of.iter().map(|f| area(f)).sum();
        if of.iter().any(|f| area(f) <= 0.0) {
            fail("a face is not counter-clockwise (or has no area)".into());
        }
        let their_area: f64 = bf
            .iter()
            .map(|f| area(&f.iter().map(|&i| b2(i)).collect::<Vec<_>>()))
            .sum();
        if (our_area - their_area).abs() > 1e-5 * their_area.abs().max(1e-9) {
            fail(format!("area {our_area} vs Blender's {their_area}"));
        }
        // Same region covered as many times (groups fill apart, so their faces overlap).
        let bpolys: Vec<Vec<[f64; 2]>> = bf
            .iter()
            .map(|f| f.iter().map(|&i| b2(i)).collect())
            .collect();
        let cover =
            |p: [f64; 2], polys: &[Vec<[f64; 2]>]| polys.iter().filter(|f| inside(p, f)).count();
        let mut bad = 0;
        for t in &bt {
            let p = centroid(&[b2(t[0]), b2(t[1]), b2(t[2])]);
            if cover(p, &of) != cover(p, &bpolys) || cover(p, &of) == 0 {
                bad += 1;
            }
        }
        if output == Output::InsideWithHoles {
            for f in &of {
                let p = centroid(f);
                if cover(p, &of) != cover(p, &bpolys) {
                    bad += 1;
                }
            }
        }
        if bad > 0 {
            fail(format!(
                "{bad} triangle centroid(s) covered a different number of times by the two meshes"
            ));
        }
        let sharp = m
            .attributes
            .named("sharp_face")
            .map(|a| a.data.as_bool().iter().all(|s| *s))
            .unwrap_or(false);
        if sharp != case["all_sharp"].as_bool().unwrap() {
            fail(format!(
                "sharp_face all true: {sharp}, Blender {}",
                case["all_sharp"]
            ));
        }
        // Informational: Blender's triangles we have (vertex positions as keys).
        let key = |ps: [[f64; 2]; 3]| {
            let mut k: Vec<(i64, i64)> = ps
                .iter()
                .map(|p| ((p[0] * 1e5).round() as i64, (p[1] * 1e5).round() as i64))
                .collect();
            k.sort();
            k
        };
        let ours_t: std::collections::HashSet<_> = if output == Output::InsideWithHoles {
            of.iter().map(|f| key([f[0], f[1], f[2]])).collect()
        } else {
            Default::default()
        };
        let same = if output == Output::InsideWithHoles {
            let n = bt
                .iter()
                .filter(|t| ours_t.contains(&key([b2(t[0]), b2(t[1]), b2(t[2])])))
                .count();
            format!("same triangles {n}/{}", bt.len())
        } else {
            String::new()
        };
        println!(
            "  {name:20} {ours:24} Blender {theirs:24} hausdorff {h:.1e} area {our_area:.6} {same}"
        );
    }
    if !failures.is_empty() {
        panic!(
            "{} mismatch(es):\n  {}",
            failures.len(),
            failures.join("\n  ")
        );
    }
}

/// Through the node tree as Blender exports it (Mode menu, Group ID field, curves inside
/// instances filled in place, then realized): needs bpy, exports a fresh scene to a temp
/// folder (nothing committed) and compares with Blender's evaluated meshes.
#[test]
fn fill_curve_node_on_instances_matches_blender() {
    let Some(py) = common::require("bpy", common::bpy_python()) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fill");
    let script = common::repo().join("fixtures/geometry/make_fill_refs.py");
    common::run_python(&py, &script, &["--scene", out.to_str().unwrap()]);
    let scene = Scene::load(&out).unwrap();
    assert_eq!(scene.file.evaluated.len(), 2);
    for (i, e) in scene.file.evaluated.iter().enumerate() {
        let theirs = scene.load_evaluated(i).unwrap();
        let m = geometry::evaluate_object(&scene, &e.object, e.frame, &[])
            .and_then(|g| geometry::realize_to_mesh(&g))
            .unwrap();
        m.validate().unwrap();
        assert_eq!(
            (
                m.vertex_count(),
                m.edges.len(),
                m.face_count(),
                m.corner_count()
            ),
            (
                theirs.vertex_count(),
                theirs.edges.len(),
                theirs.face_count(),
                theirs.corner_count()
            ),
            "{}: counts (v, e, f, c)",
            e.object
        );
        let face_area = |pos: &[[f32; 3]], offs: &[u32], cv: &[u32]| -> f64 {
            (0..offs.len().saturating_sub(1))
                .map(|f| {
                    let poly: Vec<[f64; 2]> = (offs[f]..offs[f + 1])
                        .map(|c| {
                            let p = pos[cv[c as usize] as usize];
                            [p[0] as f64, p[1] as f64]
                        })
                        .collect();
                    area(&poly)
                })
                .sum()
        };
        let (a, b) = (
            face_area(&m.positions, &m.face_offsets, &m.corner_verts),
            face_area(
                &theirs.positions,
                &theirs.face_offsets,
                &theirs.corner_verts,
            ),
        );
        assert!(
            (a - b).abs() < 1e-5 * b.abs(),
            "{}: area {a} vs Blender's {b}",
            e.object
        );
        let d = |p: &[f32; 3], q: &[f32; 3]| {
            (0..3)
                .map(|k| (p[k] as f64 - q[k] as f64).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let h = m
            .positions
            .iter()
            .map(|p| {
                theirs
                    .positions
                    .iter()
                    .map(|q| d(p, q))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
            .max(
                theirs
                    .positions
                    .iter()
                    .map(|q| {
                        m.positions
                            .iter()
                            .map(|p| d(p, q))
                            .fold(f64::INFINITY, f64::min)
                    })
                    .fold(0.0, f64::max),
            );
        assert!(h < 1e-5, "{}: Hausdorff {h}", e.object);
        println!(
            "  {}: v{} f{} area {a:.6} hausdorff {h:.1e}",
            e.object,
            m.vertex_count(),
            m.face_count()
        );
    }
}

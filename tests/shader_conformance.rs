//! Shader-node conformance: blendsynth's node functions against values Cycles baked.
//!
//! `fixtures/shader_conformance/make_cases.py` (run with Blender's bpy) baked, for every
//! case, the exact values arriving at each varied input socket and the node's outputs,
//! 32x32 texels each (`refs/index.json` + `refs/data.bin`). This test evaluates the Rust
//! node at those inputs and requires max |rust - cycles| <= 1e-5 on every texel of every
//! case, except cases listed in `ALLOWED` (each with its reason and own bound).
//!
//! Cycles' film replaces every non-finite channel by 0, so where the Rust node returns
//! inf/NaN in a channel the reference must be exactly 0 there.
//!
//! The report (cases and worst error per node type, then per case) is printed and also
//! written to `target/conformance_report.txt`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use blendsynth::nodes::blackbody::blackbody;
use blendsynth::nodes::checker::checker_texture;
use blendsynth::nodes::clamp::{clamp_node, ClampType};
use blendsynth::nodes::color::{
    bright_contrast, gamma, hue_saturation, invert, rgb_to_bw, LINEAR_REC709,
};
use blendsynth::nodes::curves::{mapping_from_json, CurveKind, CurveTable};
use blendsynth::nodes::gradient::{gradient, GradientType};
use blendsynth::nodes::magic::magic;
use blendsynth::nodes::map_range::{map_range_float, map_range_vector, MapRangeInterpolation};
use blendsynth::nodes::mapping::{mapping, MappingType};
use blendsynth::nodes::math::{math_node, vector_math, MathOp, VectorMathOp};
use blendsynth::nodes::mix::{
    mix_color, mix_float, mix_rgb, mix_vector, mix_vector_non_uniform, MixBlend, MixDataType,
    MixFactorMode,
};
use blendsynth::nodes::noise::{noise_texture_cycles, NoiseParams, NoiseType};
use blendsynth::nodes::ramp::{
    ColorBand, HueInterpolation, RampColorMode, RampInterpolation, RampStop, RampTable,
};
use blendsynth::nodes::sepcomb::{combine_color, separate_color, ColorMode};
use blendsynth::nodes::vector_rotate::{vector_rotate, VectorRotateType};
use blendsynth::nodes::voronoi::{voronoi_texture, VoronoiFeature, VoronoiMetric, VoronoiParams};
use blendsynth::nodes::wave::{
    wave, BandsDirection, RingsDirection, WaveProfile, WaveSettings, WaveType,
};
use blendsynth::nodes::wavelength::wavelength;
use blendsynth::nodes::white_noise::white_noise;
use blendsynth::nodes::Support;
use blendsynth::shader::compile::support;
use serde_json::Value;

/// The project's bound for arithmetic and colour nodes.
const TOLERANCE: f64 = 1e-5;

/// The project's bound for texture nodes.
const TEXTURE_TOLERANCE: f64 = 1e-4;

fn is_texture(node: &str) -> bool {
    node.starts_with("ShaderNodeTex")
}

/// Cases that cannot meet `TOLERANCE`: (case name, bound, why). Empty while every case
/// passes; an entry here is reported, never silently skipped.
const ALLOWED: &[(&str, f64, &str)] = &[
    // One texel, (14, 18): W = 0.72, Scale 3.7, Lacunarity 3.3, Roughness 1, Detail 8.3,
    // Distortion 2.5, so the top octaves sample 1D Perlin noise near 7e4 where an f32's
    // fraction has steps of 0.008 and every octave weighs 1: Cycles' scalar 1D kernel
    // rounds differently there (its 2D-4D kernels match to 1e-6 on the same texel).
    // Every other texel of these cases is within 1e-4.
    ("noise_1d_fbm", 1.5e-4, ONE_D_NOISE),
    ("noise_1d_fbm_unnormalized", 3e-3, ONE_D_NOISE),
    ("noise_1d_multifractal", 2e-3, ONE_D_NOISE),
    ("noise_1d_hetero_terrain", 5e-3, ONE_D_NOISE),
];
const ONE_D_NOISE: &str =
    "one texel (14, 18) with unattenuated octaves near 7e4 (see above); all others <= 1e-4";

type V3 = [f32; 3];

struct Refs {
    index: Value,
    data: Vec<f32>,
}

fn refs_dir() -> PathBuf {
    // A freshly generated set can be tried before it replaces the committed one.
    if let Some(dir) = std::env::var_os("BLENDSYNTH_CONFORMANCE_REFS") {
        return PathBuf::from(dir);
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/shader_conformance/refs")
}

fn load_refs() -> Refs {
    let dir = refs_dir();
    let index: Value = serde_json::from_slice(
        &std::fs::read(dir.join("index.json")).expect("read refs/index.json"),
    )
    .expect("parse refs/index.json");
    let bytes = std::fs::read(dir.join("data.bin")).expect("read refs/data.bin");
    assert_eq!(bytes.len() % 4, 0, "data.bin is not a whole number of f32");
    let data: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(
        data.len() as u64,
        index["data_floats"].as_u64().unwrap(),
        "data.bin size"
    );
    Refs { index, data }
}

/// One input socket: per-texel data (1 or 3 channels) or its unlinked default.
enum Input<'a> {
    Linked { data: &'a [f32], channels: usize },
    Default(V3),
}

struct Case<'a> {
    name: &'a str,
    node: &'a str,
    props: &'a Value,
    case: &'a Value,
    inputs: BTreeMap<&'a str, Input<'a>>,
}

impl<'a> Case<'a> {
    fn prop(&self, key: &str) -> &'a str {
        self.props[key]
            .as_str()
            .unwrap_or_else(|| panic!("{}: no property {key}", self.name))
    }

    fn flag(&self, key: &str) -> bool {
        self.props
            .get(key)
            .and_then(Value::as_bool)
            .unwrap_or(false)
    }
}

/// Reads input sockets at one texel.
struct Texel<'c, 'a> {
    case: &'c Case<'a>,
    k: usize,
}

impl Texel<'_, '_> {
    fn v3(&self, socket: &str) -> V3 {
        match self.case.inputs.get(socket) {
            Some(Input::Linked { data, channels: 1 }) => [data[self.k]; 3],
            Some(Input::Linked { data, .. }) => {
                [data[3 * self.k], data[3 * self.k + 1], data[3 * self.k + 2]]
            }
            Some(Input::Default(v)) => *v,
            None => panic!("{}: no input socket {socket}", self.case.name),
        }
    }

    fn f(&self, socket: &str) -> f32 {
        self.v3(socket)[0]
    }
}

type Outputs = Vec<(&'static str, V3)>;
type Eval<'a> = Box<dyn Fn(&Texel) -> Outputs + 'a>;

fn f1(v: f32) -> V3 {
    [v, 0.0, 0.0]
}

fn parse<T>(case: &Case, what: &str, value: &str, f: fn(&str) -> Option<T>) -> T {
    f(value).unwrap_or_else(|| panic!("{}: unknown {what} {value:?}", case.name))
}

/// The Rust implementation of the case's node with its properties.
fn evaluator<'a>(c: &'a Case<'a>) -> Eval<'a> {
    match c.node {
        "ShaderNodeMath" => {
            let op = parse(c, "operation", c.prop("operation"), MathOp::from_blender);
            let clamp = c.flag("use_clamp");
            Box::new(move |t| {
                let r = math_node(op, clamp, t.f("Value"), t.f("Value_001"), t.f("Value_002"));
                vec![("Value", f1(r))]
            })
        }
        "ShaderNodeVectorMath" => {
            let op = parse(
                c,
                "operation",
                c.prop("operation"),
                VectorMathOp::from_blender,
            );
            Box::new(move |t| {
                let r = vector_math(
                    op,
                    t.v3("Vector"),
                    t.v3("Vector_001"),
                    t.v3("Vector_002"),
                    t.f("Scale"),
                );
                vec![("Vector", r.vector), ("Value", f1(r.value))]
            })
        }
        "ShaderNodeMapRange" => {
            let interp = parse(
                c,
                "interpolation",
                c.prop("interpolation_type"),
                MapRangeInterpolation::from_blender,
            );
            let clamp = c.flag("clamp");
            match c.prop("data_type") {
                "FLOAT" => Box::new(move |t| {
                    let r = map_range_float(
                        interp,
                        clamp,
                        t.f("Value"),
                        t.f("From Min"),
                        t.f("From Max"),
                        t.f("To Min"),
                        t.f("To Max"),
                        t.f("Steps"),
                    );
                    vec![("Result", f1(r))]
                }),
                "FLOAT_VECTOR" => Box::new(move |t| {
                    let r = map_range_vector(
                        interp,
                        clamp,
                        t.v3("Vector"),
                        t.v3("From_Min_FLOAT3"),
                        t.v3("From_Max_FLOAT3"),
                        t.v3("To_Min_FLOAT3"),
                        t.v3("To_Max_FLOAT3"),
                        t.v3("Steps_FLOAT3"),
                    );
                    vec![("Vector", r)]
                }),
                other => panic!("{}: data_type {other}", c.name),
            }
        }
        "ShaderNodeClamp" => {
            let ty = parse(
                c,
                "clamp_type",
                c.prop("clamp_type"),
                ClampType::from_blender,
            );
            Box::new(move |t| {
                vec![(
                    "Result",
                    f1(clamp_node(ty, t.f("Value"), t.f("Min"), t.f("Max"))),
                )]
            })
        }
        "ShaderNodeMix" => {
            let dt = parse(
                c,
                "data_type",
                c.prop("data_type"),
                MixDataType::from_blender,
            );
            let cf = c.flag("clamp_factor");
            match dt {
                MixDataType::Float => Box::new(move |t| {
                    let r = mix_float(cf, t.f("Factor_Float"), t.f("A_Float"), t.f("B_Float"));
                    vec![("Result_Float", f1(r))]
                }),
                MixDataType::Vector => {
                    let fm = parse(
                        c,
                        "factor_mode",
                        c.prop("factor_mode"),
                        MixFactorMode::from_blender,
                    );
                    Box::new(move |t| {
                        let (a, b) = (t.v3("A_Vector"), t.v3("B_Vector"));
                        let r = match fm {
                            MixFactorMode::Uniform => mix_vector(cf, t.f("Factor_Float"), a, b),
                            MixFactorMode::NonUniform => {
                                mix_vector_non_uniform(cf, t.v3("Factor_Vector"), a, b)
                            }
                        };
                        vec![("Result_Vector", r)]
                    })
                }
                MixDataType::Rgba => {
                    let bt = parse(
                        c,
                        "blend_type",
                        c.prop("blend_type"),
                        MixBlend::from_blender,
                    );
                    let cr = c.flag("clamp_result");
                    Box::new(move |t| {
                        let r = mix_color(
                            bt,
                            cf,
                            cr,
                            t.f("Factor_Float"),
                            t.v3("A_Color"),
                            t.v3("B_Color"),
                        );
                        vec![("Result_Color", r)]
                    })
                }
                MixDataType::Rotation => panic!("{}: rotation mix is Geometry Nodes only", c.name),
            }
        }
        "ShaderNodeMixRGB" => {
            let bt = parse(
                c,
                "blend_type",
                c.prop("blend_type"),
                MixBlend::from_blender,
            );
            let clamp = c.flag("use_clamp");
            Box::new(move |t| {
                vec![(
                    "Color",
                    mix_rgb(bt, clamp, t.f("Fac"), t.v3("Color1"), t.v3("Color2")),
                )]
            })
        }
        "ShaderNodeValToRGB" => {
            let table = RampTable::from_band(&color_band(c));
            Box::new(move |t| {
                let (rgb, alpha) = table.color_ramp(t.f("Fac"));
                vec![("Color", rgb), ("Alpha", f1(alpha))]
            })
        }
        "ShaderNodeRGBCurve" | "ShaderNodeVectorCurve" | "ShaderNodeFloatCurve" => {
            let m = mapping_from_json(&c.case["mapping"])
                .unwrap_or_else(|e| panic!("{}: {}", c.name, e.0));
            let kind = match c.node {
                "ShaderNodeRGBCurve" => CurveKind::Rgb,
                "ShaderNodeVectorCurve" => CurveKind::Vector,
                _ => CurveKind::Float,
            };
            let table = CurveTable::new(&m, kind).unwrap_or_else(|e| panic!("{}: {}", c.name, e.0));
            match kind {
                CurveKind::Rgb => {
                    Box::new(move |t| vec![("Color", table.eval3(t.f("Fac"), t.v3("Color")))])
                }
                CurveKind::Vector => {
                    Box::new(move |t| vec![("Vector", table.eval3(t.f("Fac"), t.v3("Vector")))])
                }
                CurveKind::Float => {
                    Box::new(move |t| vec![("Value", f1(table.eval1(t.f("Factor"), t.f("Value"))))])
                }
            }
        }
        "ShaderNodeVectorRotate" => {
            let kind = parse(
                c,
                "rotation_type",
                c.prop("rotation_type"),
                VectorRotateType::from_blender,
            );
            let invert = c.flag("invert");
            Box::new(move |t| {
                vec![(
                    "Vector",
                    vector_rotate(
                        kind,
                        invert,
                        t.v3("Vector"),
                        t.v3("Center"),
                        t.v3("Axis"),
                        t.f("Angle"),
                        t.v3("Rotation"),
                    ),
                )]
            })
        }
        "ShaderNodeInvert" => Box::new(|t| vec![("Color", invert(t.f("Fac"), t.v3("Color")))]),
        "ShaderNodeGamma" => Box::new(|t| vec![("Color", gamma(t.v3("Color"), t.f("Gamma")))]),
        "ShaderNodeBrightContrast" => Box::new(|t| {
            vec![(
                "Color",
                bright_contrast(t.v3("Color"), t.f("Bright"), t.f("Contrast")),
            )]
        }),
        "ShaderNodeHueSaturation" => Box::new(|t| {
            let r = hue_saturation(
                t.f("Hue"),
                t.f("Saturation"),
                t.f("Value"),
                t.f("Fac"),
                t.v3("Color"),
            );
            vec![("Color", r)]
        }),
        "ShaderNodeRGBToBW" => {
            Box::new(|t| vec![("Val", f1(rgb_to_bw(t.v3("Color"), &LINEAR_REC709)))])
        }
        "ShaderNodeSeparateXYZ" => Box::new(|t| {
            let v = t.v3("Vector");
            vec![("X", f1(v[0])), ("Y", f1(v[1])), ("Z", f1(v[2]))]
        }),
        "ShaderNodeCombineXYZ" => Box::new(|t| vec![("Vector", [t.f("X"), t.f("Y"), t.f("Z")])]),
        "ShaderNodeSeparateColor" | "ShaderNodeSeparateRGB" | "ShaderNodeSeparateHSV" => {
            let (mode, input, names): (ColorMode, &str, [&'static str; 3]) = match c.node {
                "ShaderNodeSeparateColor" => (
                    parse(c, "mode", c.prop("mode"), ColorMode::from_blender),
                    "Color",
                    ["Red", "Green", "Blue"],
                ),
                "ShaderNodeSeparateRGB" => (ColorMode::Rgb, "Image", ["R", "G", "B"]),
                _ => (ColorMode::Hsv, "Color", ["H", "S", "V"]),
            };
            Box::new(move |t| {
                let r = separate_color(mode, t.v3(input));
                vec![
                    (names[0], f1(r[0])),
                    (names[1], f1(r[1])),
                    (names[2], f1(r[2])),
                ]
            })
        }
        "ShaderNodeCombineColor" | "ShaderNodeCombineRGB" | "ShaderNodeCombineHSV" => {
            let (mode, names, output): (ColorMode, [&'static str; 3], &'static str) = match c.node {
                "ShaderNodeCombineColor" => (
                    parse(c, "mode", c.prop("mode"), ColorMode::from_blender),
                    ["Red", "Green", "Blue"],
                    "Color",
                ),
                "ShaderNodeCombineRGB" => (ColorMode::Rgb, ["R", "G", "B"], "Image"),
                _ => (ColorMode::Hsv, ["H", "S", "V"], "Color"),
            };
            Box::new(move |t| {
                let r = combine_color(mode, [t.f(names[0]), t.f(names[1]), t.f(names[2])]);
                vec![(output, r)]
            })
        }
        "ShaderNodeBlackbody" => Box::new(|t| vec![("Color", blackbody(t.f("Temperature")))]),
        "ShaderNodeWavelength" => {
            Box::new(|t| vec![("Color", wavelength(t.f("Wavelength"), &LINEAR_REC709))])
        }
        "ShaderNodeTexNoise" => {
            let dims = dimensions(c, "noise_dimensions");
            let kind = parse(
                c,
                "noise_type",
                c.prop("noise_type"),
                NoiseType::from_blender,
            );
            let normalize = c.flag("normalize");
            Box::new(move |t| {
                let params = NoiseParams {
                    kind,
                    normalize,
                    detail: t.f("Detail"),
                    roughness: t.f("Roughness"),
                    lacunarity: t.f("Lacunarity"),
                    offset: t.f("Offset"),
                    gain: t.f("Gain"),
                    distortion: t.f("Distortion"),
                };
                let (fac, col) =
                    noise_texture_cycles(dims, t.v3("Vector"), t.f("W"), t.f("Scale"), params);
                vec![("Fac", f1(fac)), ("Color", col)]
            })
        }
        "ShaderNodeTexVoronoi" => {
            let dims = dimensions(c, "voronoi_dimensions");
            let feature = parse(
                c,
                "feature",
                c.prop("feature"),
                VoronoiFeature::from_blender,
            );
            let metric = parse(
                c,
                "distance",
                c.prop("distance"),
                VoronoiMetric::from_blender,
            );
            let normalize = c.flag("normalize");
            Box::new(move |t| {
                let p = VoronoiParams::new(
                    feature,
                    metric,
                    normalize,
                    t.f("Scale"),
                    t.f("Detail"),
                    t.f("Roughness"),
                    t.f("Lacunarity"),
                    t.f("Smoothness"),
                    t.f("Exponent"),
                    t.f("Randomness"),
                );
                let o = voronoi_texture(dims, t.v3("Vector"), t.f("W"), p);
                vec![
                    ("Distance", f1(o.distance)),
                    ("Color", o.color),
                    ("Position", o.position),
                    ("W", f1(o.w)),
                    ("Radius", f1(o.radius)),
                ]
            })
        }
        "ShaderNodeTexWave" => {
            let s = WaveSettings {
                kind: parse(c, "wave_type", c.prop("wave_type"), WaveType::from_blender),
                bands: c
                    .props
                    .get("bands_direction")
                    .and_then(Value::as_str)
                    .and_then(BandsDirection::from_blender)
                    .unwrap_or(BandsDirection::X),
                rings: c
                    .props
                    .get("rings_direction")
                    .and_then(Value::as_str)
                    .and_then(RingsDirection::from_blender)
                    .unwrap_or(RingsDirection::X),
                profile: parse(
                    c,
                    "wave_profile",
                    c.prop("wave_profile"),
                    WaveProfile::from_blender,
                ),
            };
            Box::new(move |t| {
                let f = wave(
                    s,
                    t.v3("Vector"),
                    t.f("Scale"),
                    t.f("Distortion"),
                    t.f("Detail"),
                    t.f("Detail Scale"),
                    t.f("Detail Roughness"),
                    t.f("Phase Offset"),
                );
                vec![("Fac", f1(f)), ("Color", [f; 3])]
            })
        }
        "ShaderNodeTexGradient" => {
            let kind = parse(
                c,
                "gradient_type",
                c.prop("gradient_type"),
                GradientType::from_blender,
            );
            Box::new(move |t| {
                let f = gradient(kind, t.v3("Vector"));
                vec![("Fac", f1(f)), ("Color", [f; 3])]
            })
        }
        "ShaderNodeTexMagic" => {
            let depth = c.props["turbulence_depth"]
                .as_i64()
                .expect("turbulence_depth") as i32;
            Box::new(move |t| {
                let (col, fac) = magic(t.v3("Vector"), t.f("Scale"), depth, t.f("Distortion"));
                vec![("Fac", f1(fac)), ("Color", col)]
            })
        }
        "ShaderNodeTexWhiteNoise" => {
            let dims = dimensions(c, "noise_dimensions");
            Box::new(move |t| {
                let (v, col) = white_noise(dims, t.v3("Vector"), t.f("W"));
                vec![("Value", f1(v)), ("Color", col)]
            })
        }
        "ShaderNodeMapping" => {
            let kind = parse(
                c,
                "vector_type",
                c.prop("vector_type"),
                MappingType::from_blender,
            );
            Box::new(move |t| {
                let r = mapping(
                    kind,
                    t.v3("Vector"),
                    t.v3("Location"),
                    t.v3("Rotation"),
                    t.v3("Scale"),
                );
                vec![("Vector", r)]
            })
        }
        "ShaderNodeTexChecker" => Box::new(|t| {
            let (col, fac) =
                checker_texture(t.v3("Vector"), t.v3("Color1"), t.v3("Color2"), t.f("Scale"));
            vec![("Fac", f1(fac)), ("Color", col)]
        }),
        other => panic!("{}: no evaluator for node type {other}", c.name),
    }
}

/// "1D".."4D" as a number.
fn dimensions(c: &Case, key: &str) -> u8 {
    match c.prop(key) {
        "1D" => 1,
        "2D" => 2,
        "3D" => 3,
        "4D" => 4,
        other => panic!("{}: {key} {other:?}", c.name),
    }
}

fn color_band(c: &Case) -> ColorBand {
    let r = &c.case["color_ramp"];
    let stops: Vec<RampStop> = r["elements"]
        .as_array()
        .expect("color_ramp.elements")
        .iter()
        .map(|e| {
            let col: Vec<f32> = e["color"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect();
            RampStop {
                position: e["position"].as_f64().unwrap() as f32,
                color: [col[0], col[1], col[2], col[3]],
            }
        })
        .collect();
    let s = |k: &str| r[k].as_str().unwrap();
    ColorBand::new(
        &stops,
        parse(
            c,
            "interpolation",
            s("interpolation"),
            RampInterpolation::from_blender,
        ),
        parse(
            c,
            "color_mode",
            s("color_mode"),
            RampColorMode::from_blender,
        ),
        parse(
            c,
            "hue_interpolation",
            s("hue_interpolation"),
            HueInterpolation::from_blender,
        ),
    )
    .expect("valid colour band")
}

fn to_v3(v: &Value) -> V3 {
    match v {
        Value::Array(a) => {
            let x = |i: usize| a.get(i).and_then(Value::as_f64).unwrap_or(0.0) as f32;
            [x(0), x(1), x(2)]
        }
        other => [other.as_f64().expect("numeric default") as f32; 3],
    }
}

struct CaseResult {
    name: String,
    node: String,
    worst: f64,
    worst_at: String,
    bound: f64,
    /// Texels over the node family's bound.
    over: usize,
}

fn run_case<'a>(refs: &'a Refs, case: &'a Value, texels: usize) -> CaseResult {
    let name = case["name"].as_str().unwrap();
    let slice = |offset: &Value, channels: usize| {
        let o = offset.as_u64().unwrap() as usize;
        &refs.data[o..o + texels * channels]
    };
    let mut inputs = BTreeMap::new();
    for inp in case["inputs"].as_array().unwrap() {
        let socket = inp["socket"].as_str().unwrap();
        let channels = inp["channels"].as_u64().unwrap() as usize;
        let input = if inp["linked"].as_bool().unwrap() {
            Input::Linked {
                data: slice(&inp["offset"], channels),
                channels,
            }
        } else {
            Input::Default(to_v3(&inp["default"]))
        };
        inputs.insert(socket, input);
    }
    let c = Case {
        name,
        node: case["node"].as_str().unwrap(),
        props: &case["props"],
        case,
        inputs,
    };
    let eval = evaluator(&c);
    let outputs: Vec<(&str, usize, &[f32])> = case["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            let ch = o["channels"].as_u64().unwrap() as usize;
            (o["socket"].as_str().unwrap(), ch, slice(&o["offset"], ch))
        })
        .collect();
    let mut worst = 0.0f64;
    let mut worst_at = String::new();
    let texture = is_texture(c.node);
    let mut over = 0usize;
    for k in 0..texels {
        let mut texel_over = false;
        let texel = Texel { case: &c, k };
        let got = eval(&texel);
        for &(socket, ch, data) in &outputs {
            let ours = got
                .iter()
                .find(|(s, _)| *s == socket)
                .unwrap_or_else(|| panic!("{name}: evaluator has no output {socket}"))
                .1;
            let cycles = &data[k * ch..(k + 1) * ch];
            // Cycles' film replaces each non-finite channel by 0 (`ensure_finite`).
            let ours = ours.map(|x| if x.is_finite() { x } else { 0.0 });
            for i in 0..ch {
                let err = (ours[i] as f64 - cycles[i] as f64).abs();
                // Fractal textures reach values in the thousands, where one f32 ulp
                // exceeds 1e-4: above magnitude 1 their error is relative.
                let err = if texture {
                    err / (cycles[i].abs() as f64).max(1.0)
                } else {
                    err
                };
                let err = if err.is_nan() { f64::INFINITY } else { err };
                texel_over |= err
                    > if texture {
                        TEXTURE_TOLERANCE
                    } else {
                        TOLERANCE
                    };
                if err > worst {
                    worst = err;
                    worst_at = format!(
                        "texel {k} ({}, {}) {socket}[{i}]: rust {} cycles {}",
                        k % 32,
                        k / 32,
                        ours[i],
                        cycles[i]
                    );
                }
            }
        }
        over += texel_over as usize;
    }
    let bound = ALLOWED.iter().find(|a| a.0 == name).map_or(
        if is_texture(c.node) {
            TEXTURE_TOLERANCE
        } else {
            TOLERANCE
        },
        |a| a.1,
    );
    CaseResult {
        name: name.to_string(),
        node: c.node.to_string(),
        worst,
        worst_at,
        bound,
        over,
    }
}

#[test]
fn shader_nodes_match_cycles() {
    let refs = load_refs();
    let texels =
        (refs.index["width"].as_u64().unwrap() * refs.index["height"].as_u64().unwrap()) as usize;
    let cases = refs.index["cases"].as_array().expect("cases");
    assert!(
        cases.len() >= 250,
        "expected the full case set, found {}",
        cases.len()
    );

    let results: Vec<CaseResult> = cases.iter().map(|c| run_case(&refs, c, texels)).collect();

    let mut by_node: BTreeMap<&str, (usize, f64, &str)> = BTreeMap::new();
    for r in &results {
        let e = by_node.entry(&r.node).or_insert((0, 0.0, ""));
        e.0 += 1;
        if r.worst >= e.1 {
            e.1 = r.worst;
            e.2 = &r.name;
        }
    }
    let mut report = String::new();
    let _ = writeln!(
        report,
        "Shader-node conformance against Cycles (Blender {}), {} cases x {} texels, bound {:e}",
        refs.index["blender"].as_str().unwrap_or("?"),
        results.len(),
        texels,
        TOLERANCE
    );
    let _ = writeln!(
        report,
        "\n{:<28} {:>5}  {:>12}  worst case",
        "node type", "cases", "max |err|"
    );
    for (node, (n, worst, case)) in &by_node {
        let _ = writeln!(report, "{node:<28} {n:>5}  {worst:>12.3e}  {case}");
    }
    let _ = writeln!(report, "\nAllowlisted cases (own bound):");
    if ALLOWED.is_empty() {
        let _ = writeln!(report, "  none");
    }
    for (name, bound, why) in ALLOWED {
        let _ = writeln!(report, "  {name}: bound {bound:e}: {why}");
    }
    let _ = writeln!(report, "\nPer case:");
    for r in &results {
        let flag = if r.worst <= r.bound { "ok  " } else { "FAIL" };
        let _ = writeln!(
            report,
            "{flag} {:<44} {:>12.3e} {:>5} over  {}",
            r.name, r.worst, r.over, r.worst_at
        );
    }
    print!("{report}");
    if let Some(target) = Path::new(env!("CARGO_TARGET_TMPDIR")).parent() {
        let _ = std::fs::write(target.join("conformance_report.txt"), &report);
    }

    for (name, _, _) in ALLOWED {
        let r = results.iter().find(|r| r.name == *name);
        assert!(r.is_some(), "ALLOWED names a missing case {name}");
        // The allowance is for the one texel named in the reason, not for the case.
        assert!(
            r.unwrap().over <= 1,
            "{name}: {} texels over the family bound",
            r.unwrap().over
        );
    }
    // Written so that a NaN error counts as a failure.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    let failed: Vec<&CaseResult> = results.iter().filter(|r| !(r.worst <= r.bound)).collect();
    assert!(
        failed.is_empty(),
        "{} case(s) exceed their bound:\n{}",
        failed.len(),
        failed
            .iter()
            .map(|r| format!("  {} ({}): {:e} at {}", r.name, r.node, r.worst, r.worst_at))
            .collect::<Vec<_>>()
            .join("\n")
    );
    // SUPPORTED means every mode and option is covered: check the case set really has them.
    assert_modes_covered(cases);

    // The colour-space constants compiled in must be the ones Blender reported when the
    // references were made (RGB to BW and Wavelength also check them numerically above).
    let sl = &refs.index["scene_linear"];
    assert_eq!(to_v3(&sl["rgb_to_y"]), LINEAR_REC709.rgb_to_y, "rgb_to_y");
    for (i, row) in sl["xyz_to_rgb_rows"].as_array().unwrap().iter().enumerate() {
        assert_eq!(
            to_v3(row),
            LINEAR_REC709.xyz_to_rgb[i],
            "xyz_to_rgb row {i}"
        );
    }
    // Every node type proven here is registered as supported (and `inspect` says so).
    for node in by_node.keys() {
        assert_eq!(
            support(node),
            Support::Supported,
            "{node} passes but is not in the shader node table"
        );
    }
}

/// Fails unless the stored cases cover every mode/option combination the registered node
/// types offer in shaders (so a regenerated, smaller case set cannot pass silently).
fn assert_modes_covered(cases: &[Value]) {
    use std::collections::BTreeSet;
    let mut seen: BTreeSet<String> = BTreeSet::new();
    for c in cases {
        let node = c["node"].as_str().unwrap();
        let p = &c["props"];
        let s = |k: &str| p.get(k).and_then(Value::as_str).unwrap_or("-").to_string();
        let b = |k: &str| {
            p.get(k)
                .and_then(Value::as_bool)
                .unwrap_or(false)
                .to_string()
        };
        let key = match node {
            "ShaderNodeMath" => format!("{} {}", s("operation"), b("use_clamp")),
            "ShaderNodeVectorMath" => s("operation"),
            "ShaderNodeMapRange" => {
                format!(
                    "{} {} {}",
                    s("data_type"),
                    s("interpolation_type"),
                    b("clamp")
                )
            }
            "ShaderNodeClamp" => s("clamp_type"),
            "ShaderNodeMix" => format!(
                "{} {} {} {} {}",
                s("data_type"),
                s("factor_mode"),
                s("blend_type"),
                b("clamp_factor"),
                b("clamp_result")
            ),
            "ShaderNodeMixRGB" => format!("{} {}", s("blend_type"), b("use_clamp")),
            "ShaderNodeValToRGB" => {
                let r = &c["color_ramp"];
                let rs = |k: &str| r[k].as_str().unwrap().to_string();
                if rs("color_mode") == "RGB" {
                    format!("RGB {}", rs("interpolation"))
                } else {
                    format!("{} {}", rs("color_mode"), rs("hue_interpolation"))
                }
            }
            "ShaderNodeSeparateColor" | "ShaderNodeCombineColor" => s("mode"),
            "ShaderNodeTexNoise" => format!(
                "{} {} {}",
                s("noise_dimensions"),
                s("noise_type"),
                b("normalize")
            ),
            "ShaderNodeTexVoronoi" => format!(
                "{} {} {} {}",
                s("voronoi_dimensions"),
                s("feature"),
                s("distance"),
                b("normalize")
            ),
            "ShaderNodeTexWave" => {
                let dir = if s("wave_type") == "BANDS" {
                    s("bands_direction")
                } else {
                    s("rings_direction")
                };
                format!("{} {dir} {}", s("wave_type"), s("wave_profile"))
            }
            "ShaderNodeTexGradient" => s("gradient_type"),
            "ShaderNodeMapping" => s("vector_type"),
            "ShaderNodeVectorRotate" => format!("{} {}", s("rotation_type"), b("invert")),
            "ShaderNodeTexMagic" => p["turbulence_depth"].to_string(),
            "ShaderNodeTexWhiteNoise" => s("noise_dimensions"),
            "ShaderNodeRGBCurve" | "ShaderNodeVectorCurve" | "ShaderNodeFloatCurve" => {
                let m = &c["mapping"];
                let mut handles: Vec<&str> = m["curves"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .flat_map(|cu| {
                        cu["points"]
                            .as_array()
                            .unwrap()
                            .iter()
                            .map(|p| p["handle_type"].as_str().unwrap())
                    })
                    .collect();
                handles.sort();
                handles.dedup();
                format!("{} {}", m["extend"].as_str().unwrap(), handles.join(","))
            }
            _ => String::new(),
        };
        seen.insert(format!("{node} {key}"));
    }
    let mut want: Vec<String> = Vec::new();
    let bools = [false, true];
    for op in MathOp::ALL {
        for c in bools {
            want.push(format!("ShaderNodeMath {} {c}", op.blender_name()));
        }
    }
    for op in VectorMathOp::ALL {
        want.push(format!("ShaderNodeVectorMath {}", op.blender_name()));
    }
    for dt in ["FLOAT", "FLOAT_VECTOR"] {
        for i in MapRangeInterpolation::ALL {
            for c in bools {
                want.push(format!("ShaderNodeMapRange {dt} {} {c}", i.blender_name()));
            }
        }
    }
    for t in ClampType::ALL {
        want.push(format!("ShaderNodeClamp {}", t.blender_name()));
    }
    for cf in bools {
        want.push(format!("ShaderNodeMix FLOAT - - {cf} false"));
        for fm in MixFactorMode::ALL {
            want.push(format!(
                "ShaderNodeMix VECTOR {} - {cf} false",
                fm.blender_name()
            ));
        }
        for bt in MixBlend::ALL {
            for cr in bools {
                want.push(format!(
                    "ShaderNodeMix RGBA - {} {cf} {cr}",
                    bt.blender_name()
                ));
            }
            want.push(format!("ShaderNodeMixRGB {} {cf}", bt.blender_name()));
        }
    }
    for i in RampInterpolation::ALL {
        want.push(format!("ShaderNodeValToRGB RGB {}", i.blender_name()));
    }
    for m in ["HSV", "HSL"] {
        for h in HueInterpolation::ALL {
            want.push(format!("ShaderNodeValToRGB {m} {}", h.blender_name()));
        }
    }
    for m in ColorMode::ALL {
        want.push(format!("ShaderNodeSeparateColor {}", m.blender_name()));
        want.push(format!("ShaderNodeCombineColor {}", m.blender_name()));
    }
    let dims = ["1D", "2D", "3D", "4D"];
    for d in dims {
        for t in [
            "FBM",
            "MULTIFRACTAL",
            "HYBRID_MULTIFRACTAL",
            "RIDGED_MULTIFRACTAL",
            "HETERO_TERRAIN",
        ] {
            want.push(format!("ShaderNodeTexNoise {d} {t} true"));
        }
        want.push(format!("ShaderNodeTexNoise {d} FBM false"));
        want.push(format!("ShaderNodeTexWhiteNoise {d}"));
        // The metric only matters for F1, F2 and Smooth F1 beyond 1D.
        let metrics: &[VoronoiMetric] = if d == "1D" {
            &[VoronoiMetric::Euclidean]
        } else {
            VoronoiMetric::ALL
        };
        for f in VoronoiFeature::ALL {
            let ms: &[VoronoiMetric] = match f {
                VoronoiFeature::DistanceToEdge | VoronoiFeature::NSphereRadius => {
                    &[VoronoiMetric::Euclidean]
                }
                _ => metrics,
            };
            for m in ms {
                want.push(format!(
                    "ShaderNodeTexVoronoi {d} {} {} false",
                    f.blender_name(),
                    m.blender_name()
                ));
            }
            if *f != VoronoiFeature::NSphereRadius {
                let m = ms.last().unwrap();
                want.push(format!(
                    "ShaderNodeTexVoronoi {d} {} {} true",
                    f.blender_name(),
                    m.blender_name()
                ));
            }
        }
    }
    for t in WaveType::ALL {
        for p in WaveProfile::ALL {
            let dirs: Vec<&str> = match t {
                WaveType::Bands => BandsDirection::ALL
                    .iter()
                    .map(|d| d.blender_name())
                    .collect(),
                WaveType::Rings => RingsDirection::ALL
                    .iter()
                    .map(|d| d.blender_name())
                    .collect(),
            };
            for d in dirs {
                want.push(format!(
                    "ShaderNodeTexWave {} {d} {}",
                    t.blender_name(),
                    p.blender_name()
                ));
            }
        }
    }
    for g in GradientType::ALL {
        want.push(format!("ShaderNodeTexGradient {}", g.blender_name()));
    }
    for depth in 0..=10 {
        want.push(format!("ShaderNodeTexMagic {depth}"));
    }
    want.push("ShaderNodeTexChecker ".to_string());
    for m in MappingType::ALL {
        want.push(format!("ShaderNodeMapping {}", m.blender_name()));
    }
    for r in VectorRotateType::ALL {
        for inv in bools {
            want.push(format!("ShaderNodeVectorRotate {} {inv}", r.blender_name()));
        }
    }
    // Curves: both extend modes, each with a layout mixing every handle type.
    for node in [
        "ShaderNodeRGBCurve",
        "ShaderNodeVectorCurve",
        "ShaderNodeFloatCurve",
    ] {
        for ext in ["EXTRAPOLATED", "HORIZONTAL"] {
            want.push(format!("{node} {ext} AUTO,AUTO_CLAMPED,VECTOR"));
        }
    }
    let missing: Vec<&String> = want.iter().filter(|w| !seen.contains(*w)).collect();
    assert!(
        missing.is_empty(),
        "modes without a conformance case: {missing:?}"
    );
}

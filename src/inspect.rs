//! `blendsynth inspect`: a readable account of an exported scene, of which node types
//! blendsynth can evaluate, and the result of every check `render` and `mesh` make at
//! the frame (the same code: `render::check`, `geometry::evaluate_object`), so exit 0
//! means both succeed. Its verdict is those checks only: a node type blendsynth does not
//! evaluate, in a tree or material nothing renders (an add-on's trees, an unused
//! material, a Geometry Nodes group whose object renders Blender's evaluated mesh), is
//! listed but refuses nothing, as in `render`.

use std::collections::BTreeMap;
use std::fmt::Write;

use serde::Serialize;

use crate::geometry::support_in;
use crate::nodes::Support;
use crate::scene::{quote, Rna, Scene};
use crate::shader::compile_material;

#[derive(Debug, Serialize)]
pub struct Report {
    pub source_file: String,
    pub blender_version: String,
    pub file_version: Vec<u32>,
    pub scene: SceneSummary,
    pub objects: Vec<ObjectSummary>,
    pub animation: Vec<AnimSummary>,
    pub materials: Vec<String>,
    pub node_trees: Vec<TreeSummary>,
    pub images: Vec<ImageSummary>,
    /// The files the Geometry Nodes Import nodes may read (the export's copies).
    pub import_files: Vec<ImportFileSummary>,
    pub coverage: Vec<CoverageRow>,
    /// Whether each material compiles for the renderer, and if not, why.
    pub material_status: Vec<MaterialStatus>,
    /// Objects rendered from Blender's evaluated mesh in the export, and what would
    /// make it stale.
    pub frozen: Vec<FrozenSummary>,
    /// Smoke domains and the grids they render from (or why they render nothing).
    pub smoke_domains: Vec<GridSummary>,
    /// Volume objects (OpenVDB) and the grids they render from (or why they render
    /// nothing).
    pub volume_objects: Vec<GridSummary>,
    /// The frame the checks ran at.
    pub frame: f64,
    /// `render`'s verdict at the frame: None when it would render.
    pub render_error: Option<String>,
    /// Per object with geometry, `mesh`'s error at the frame.
    pub mesh_errors: Vec<ObjectError>,
    /// True when `render` and `mesh` would succeed at the frame: `render_error` is None
    /// and `mesh_errors` is empty (`inspect` exits 0). Unsupported node types and
    /// materials that do not compile count only where the render uses them.
    pub all_supported: bool,
    pub warnings: Vec<String>,
}

#[derive(Debug, Serialize)]
pub struct SceneSummary {
    pub name: String,
    pub frame_start: i32,
    pub frame_end: i32,
    pub frame_current: i32,
    /// The active camera at the report's frame (timeline markers switch it; an error
    /// there is the render check's, and the exported camera stands here).
    pub camera: Option<String>,
    pub world: Option<String>,
    pub resolution: Option<[i64; 2]>,
    pub resolution_percentage: Option<i64>,
    pub engine: Option<String>,
    pub samples: Option<i64>,
    pub adaptive_threshold: Option<f64>,
    pub denoising: Option<bool>,
    pub view_transform: Option<String>,
    pub look: Option<String>,
}

#[derive(Debug, Serialize)]
pub struct ObjectSummary {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub data: Option<String>,
    pub parent: Option<String>,
    pub renders: bool,
    pub materials: Vec<Option<String>>,
    pub modifiers: Vec<String>,
    pub constraints: Vec<ConstraintSummary>,
}

#[derive(Debug, Serialize)]
pub struct ConstraintSummary {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub target: Option<String>,
    pub settings: Vec<String>,
}

#[derive(Debug, Serialize)]
pub struct AnimSummary {
    /// Full Blender data path of the animated property, e.g. `curves["X"].eval_time`.
    pub path: String,
    pub array_index: usize,
    pub driver: bool,
    pub keyframes: usize,
    pub interpolations: Vec<String>,
    pub extrapolation: String,
    pub modifiers: Vec<String>,
}

#[derive(Debug, Serialize)]
pub struct TreeSummary {
    pub path: String,
    pub bl_idname: String,
    pub links: usize,
    pub nodes: Vec<NodeSummary>,
}

#[derive(Debug, Serialize)]
pub struct NodeSummary {
    pub name: String,
    pub bl_idname: String,
    pub mute: bool,
    pub inputs: usize,
    pub outputs: usize,
    pub support: Support,
}

#[derive(Debug, Serialize)]
pub struct ImageSummary {
    pub name: String,
    pub file: Option<String>,
    pub missing: bool,
}

#[derive(Debug, Serialize)]
pub struct ImportFileSummary {
    /// The path string as Blender's Import node passes it to the importer.
    pub path: String,
    pub file: Option<String>,
    /// What an Import node naming it gives.
    pub state: String,
}

#[derive(Debug, Serialize)]
pub struct FrozenSummary {
    pub object: String,
    /// Why blendsynth does not build it itself (modifiers, object type, shape keys, ...).
    pub reason: String,
    /// The frame Blender evaluated it at.
    pub frame: f64,
    /// What its evaluation reads: an override under one of these is an error.
    pub reads: Vec<String>,
    /// Animated inputs: any other frame is an error.
    pub animated: Vec<String>,
}

#[derive(Debug, Serialize)]
pub struct ObjectError {
    pub object: String,
    pub error: String,
}

#[derive(Debug, Serialize)]
pub struct MaterialStatus {
    pub name: String,
    /// None when the material compiles.
    pub error: Option<String>,
}

#[derive(Debug, Serialize)]
pub struct CoverageRow {
    pub bl_idname: String,
    pub count: usize,
    pub used_in: Vec<String>,
    pub support: Support,
}

/// The report at the scene's current frame.
pub fn report(scene: &Scene) -> Report {
    report_at(scene, None)
}

/// The report, its render and mesh checks run at `frame` (default: the current frame).
// Long because one section per part of the report, in the order it prints.
pub fn report_at(scene: &Scene, frame: Option<f64>) -> Report {
    let f = &scene.file;
    let frame = frame.unwrap_or(f.scene.frame_current as f64);
    let s = &f.scene;
    let render = &s.render;
    let res = match (int(render, "resolution_x"), int(render, "resolution_y")) {
        (Some(x), Some(y)) => Some([x, y]),
        _ => None,
    };
    let scene_summary = SceneSummary {
        name: s.name.clone(),
        frame_start: s.frame_start,
        frame_end: s.frame_end,
        frame_current: s.frame_current,
        camera: scene
            .camera_at(frame)
            .unwrap_or(s.camera.as_deref())
            .map(str::to_string),
        world: s.world.clone(),
        resolution: res,
        resolution_percentage: int(render, "resolution_percentage"),
        engine: string(render, "engine"),
        samples: int(&s.cycles, "samples"),
        adaptive_threshold: s.cycles.get("adaptive_threshold").and_then(|v| v.as_f64()),
        denoising: s.cycles.get("use_denoising").and_then(|v| v.as_bool()),
        view_transform: string(&s.view_settings, "view_transform"),
        look: string(&s.view_settings, "look"),
    };

    let objects = f
        .objects
        .iter()
        .map(|o| ObjectSummary {
            name: o.name.clone(),
            kind: o.kind.clone(),
            data: o.data.clone(),
            parent: o.parent.clone(),
            renders: !o.hide_render && o.in_render_layer,
            materials: o
                .material_slots
                .iter()
                .map(|s| s.material.clone())
                .collect(),
            modifiers: o
                .modifiers
                .iter()
                .map(|m| match &m.node_group {
                    Some(g) => format!("{} {:?} (node group {:?})", m.kind, m.name, g),
                    None => format!("{} {:?}", m.kind, m.name),
                })
                .collect(),
            constraints: o
                .constraints
                .iter()
                .map(|c| ConstraintSummary {
                    name: c.name.clone(),
                    kind: c.kind.clone(),
                    target: c
                        .properties
                        .get("target")
                        .and_then(|t| t.get("name"))
                        .and_then(|n| n.as_str())
                        .map(str::to_string),
                    settings: constraint_settings(&c.properties),
                })
                .collect(),
        })
        .collect();

    let mut animation = Vec::new();
    for a in &f.animation {
        for (fc, driver) in a
            .fcurves
            .iter()
            .map(|c| (c, false))
            .chain(a.drivers.iter().map(|c| (c, true)))
        {
            let mut interps: Vec<String> = fc
                .keyframes
                .iter()
                .map(|k| k.interpolation.clone())
                .collect();
            interps.sort();
            interps.dedup();
            animation.push(AnimSummary {
                path: format!("{}.{}", a.id_path, fc.data_path),
                array_index: fc.array_index,
                driver,
                keyframes: fc.keyframes.len(),
                interpolations: interps,
                extrapolation: fc.extrapolation.clone(),
                modifiers: fc.modifiers.iter().map(|m| m.kind.clone()).collect(),
            });
        }
    }

    let mut coverage: BTreeMap<String, (usize, Vec<String>, Support)> = BTreeMap::new();
    let mut node_trees = Vec::new();
    for (path, t) in scene.node_trees() {
        let nodes = t
            .nodes
            .iter()
            .map(|n| {
                let sup = support_in(&t.bl_idname, &n.bl_idname);
                let e = coverage
                    .entry(n.bl_idname.clone())
                    .or_insert((0, Vec::new(), sup));
                e.0 += 1;
                if !e.1.contains(&path) {
                    e.1.push(path.clone());
                }
                // A type is only as supported as its least supported use.
                if sup == Support::Unsupported {
                    e.2 = sup;
                }
                NodeSummary {
                    name: n.name.clone(),
                    bl_idname: n.bl_idname.clone(),
                    mute: n.mute,
                    inputs: n.inputs.len(),
                    outputs: n.outputs.len(),
                    support: sup,
                }
            })
            .collect();
        node_trees.push(TreeSummary {
            path,
            bl_idname: t.bl_idname.clone(),
            links: t.links.len(),
            nodes,
        });
    }
    let coverage: Vec<CoverageRow> = coverage
        .into_iter()
        .map(|(bl_idname, (count, used_in, support))| CoverageRow {
            support,
            bl_idname,
            count,
            used_in,
        })
        .collect();
    // Node types alone do not tell everything (an unsupported option, a Texture
    // Coordinate output, displacement): each material must also compile.
    // Use Nodes off materials compile as the surface Cycles builds for them.
    let material_status: Vec<MaterialStatus> = match crate::render::default_surface::apply(scene) {
        Ok(surfaced) => f
            .materials
            .iter()
            .map(|m| MaterialStatus {
                name: m.name.clone(),
                error: compile_material(&surfaced, &m.name)
                    .err()
                    .map(|e| e.to_string()),
            })
            .collect(),
        Err(e) => vec![MaterialStatus {
            name: String::new(),
            error: Some(e),
        }],
    };
    let (mut frozen, mesh_errors) = geometry_checks(scene, frame);
    let opts = crate::render::RenderOptions {
        frame: Some(frame),
        ..Default::default()
    };
    let render_error = match crate::render::check(scene, &opts, &[]) {
        Ok(checked) => {
            // Objects `render` draws from Blender's evaluated mesh although `mesh`
            // evaluates them (instances whose Instancer attributes the materials read).
            for z in checked.frozen_instead {
                if frozen.iter().any(|f| f.object == z.object) {
                    continue;
                }
                let e = &f.evaluated[z.evaluated];
                frozen.push(FrozenSummary {
                    object: z.object,
                    reason: format!("in renders: {}", z.reason),
                    frame: e.frame,
                    reads: e.reads.clone().unwrap_or_default(),
                    animated: e.animated.clone(),
                });
            }
            None
        }
        Err(e) => Some(e.to_string()),
    };
    // The render's verdict and mesh's, nothing else: the coverage table and material
    // list also show what nothing renders, which refuses nothing.
    let all_supported = render_error.is_none() && mesh_errors.is_empty();

    Report {
        source_file: f.source_file.clone(),
        blender_version: f.blender_version.clone(),
        file_version: f.file_version.clone(),
        scene: scene_summary,
        objects,
        animation,
        materials: f.materials.iter().map(|m| m.name.clone()).collect(),
        node_trees,
        images: f
            .images
            .iter()
            .map(|i| ImageSummary {
                name: i.name.clone(),
                file: i.file.clone(),
                missing: i.missing,
            })
            .collect(),
        import_files: f
            .import_files
            .iter()
            .map(|i| ImportFileSummary {
                path: i.path.clone(),
                file: i.file.clone(),
                state: if i.outside {
                    "outside the .blend's folder, not exported: an Import node naming it is an error".into()
                } else if i.missing {
                    "MISSING when exported: an Import node naming it gives empty geometry (Blender: empty geometry and an error on the node)".into()
                } else {
                    "copied".into()
                },
            })
            .collect(),
        coverage,
        material_status,
        frozen,
        smoke_domains: smoke_summaries(scene, frame),
        volume_objects: volume_summaries(scene, frame),
        frame,
        render_error,
        mesh_errors,
        all_supported,
        warnings: f.warnings.clone(),
    }
}

/// A smoke domain or Volume object in the export: the frame its grids are of, the grids
/// its materials read that Blender gave, and, when it renders nothing (as Cycles does
/// then), why.
#[derive(Debug, Serialize)]
pub struct GridSummary {
    pub object: String,
    pub frame: f64,
    pub grids: Vec<String>,
    pub empty: Option<String>,
}

/// Volume objects with a readable record, the one `render` uses at `frame` (`render`'s
/// check refuses the others by name).
fn volume_summaries(scene: &Scene, frame: f64) -> Vec<GridSummary> {
    let f = &scene.file;
    f.volume_objects
        .iter()
        .enumerate()
        .filter(|(i, v)| {
            scene
                .volume_object(&v.object, frame)
                .is_some_and(|(j, _)| j == *i)
        })
        .filter(|(_, v)| v.error.is_none() && v.unread.is_empty())
        .map(|(i, v)| {
            let empty = match scene.load_volume_grids(i) {
                Err(e) => Some(format!("its grids do not load: {e}")),
                Ok(g) if g.is_empty() => Some("its materials read none of its grids".into()),
                Ok(g) => all_clipped(g, v.clipping)
                    .then(|| "every voxel is at or below the Volume's clipping".into()),
            };
            GridSummary {
                object: v.object.clone(),
                frame: v.frame,
                grids: v.grids.iter().map(|g| g.name.clone()).collect(),
                empty,
            }
        })
        .collect()
}

/// Whether no voxel of `grids` is above `clipping`: the renderer's rule
/// (`DomainGrids::new`), under which the object renders nothing.
fn all_clipped(grids: Vec<crate::scene::volume_grid::VoxelGrid>, clipping: f32) -> bool {
    crate::render::volume_grid::DomainGrids::new(grids, clipping).is_none()
}

fn smoke_summaries(scene: &Scene, frame: f64) -> Vec<GridSummary> {
    let f = &scene.file;
    f.smoke_domains
        .iter()
        .enumerate()
        .filter(|(i, d)| scene.smoke_domain(&d.object, frame).is_some_and(|(j, _)| j == *i))
        .map(|(i, d)| {
            let unread: Vec<String> = d.unread.iter().map(|(n, why)| format!("{n}: {why}")).collect();
            let empty = match scene.load_smoke_grids(i) {
                Err(e) => Some(format!("its grids do not load: {e}")),
                Ok(g) if g.is_empty() && unread.is_empty() => {
                    Some("its materials read no grid (density, color, flame, heat, temperature, velocity)".into())
                }
                Ok(g) if g.is_empty() => Some(format!("no grid at the frame ({})", unread.join("; "))),
                Ok(g) => all_clipped(g, d.clipping).then(|| {
                    "every voxel is at or below the domain's clipping (an empty or unbaked cache)".into()
                }),
            };
            GridSummary {
                object: d.object.clone(),
                frame: d.frame,
                grids: d.grids.iter().map(|g| g.name.clone()).collect(),
                empty,
            }
        })
        .collect()
}

/// Frozen objects, and `mesh`'s errors for every object with geometry, at `frame`.
fn geometry_checks(scene: &Scene, frame: f64) -> (Vec<FrozenSummary>, Vec<ObjectError>) {
    use crate::geometry::source::{
        frozen_reason, object_source, simulation_after_start, unsupported_gn_node, Source,
    };
    let mut frozen = Vec::new();
    let mut errors = Vec::new();
    // A Volume object's geometry is its voxel grids, which `render`'s checks read; it
    // has no mesh.
    for o in scene.file.objects.iter().filter(|o| o.kind != "VOLUME") {
        match object_source(scene, o, frame, &[]) {
            Ok(Source::None) => continue,
            Ok(Source::Frozen(i)) => {
                let e = &scene.file.evaluated[i];
                frozen.push(FrozenSummary {
                    object: o.name.clone(),
                    reason: frozen_reason(scene, o)
                        .or_else(|| {
                            unsupported_gn_node(scene, o).map(|n| {
                                format!("Geometry Nodes node {n} that blendsynth does not evaluate")
                            })
                        })
                        .or_else(|| simulation_after_start(scene, o, frame))
                        .unwrap_or_default(),
                    frame: e.frame,
                    reads: e.reads.clone().unwrap_or_default(),
                    animated: e.animated.clone(),
                });
            }
            Ok(_) => {}
            Err(e) => {
                errors.push(ObjectError {
                    object: o.name.clone(),
                    error: e.to_string(),
                });
                continue;
            }
        }
        let r = crate::geometry::evaluate_object(scene, &o.name, frame, &[])
            .and_then(|set| crate::geometry::realize_to_mesh(&set));
        if let Err(e) = r {
            errors.push(ObjectError {
                object: o.name.clone(),
                error: format!("mesh {:?}: {e}", o.name),
            });
        }
    }
    (frozen, errors)
}

fn int(m: &Rna, k: &str) -> Option<i64> {
    m.get(k).and_then(|v| v.as_i64())
}
fn string(m: &Rna, k: &str) -> Option<String> {
    m.get(k).and_then(|v| v.as_str()).map(str::to_string)
}

/// The settings worth a glance, as `key=value`, for any constraint type: scalars only,
/// skipping bookkeeping properties.
fn constraint_settings(p: &Rna) -> Vec<String> {
    const SKIP: &[&str] = &[
        "name",
        "type",
        "show_expanded",
        "is_override_data",
        "active",
        "is_valid",
        "error_location",
        "error_rotation",
        "target",
        "enabled",
    ];
    p.iter()
        .filter(|(k, v)| {
            !SKIP.contains(&k.as_str()) && (v.is_boolean() || v.is_number() || v.is_string())
        })
        .filter(|(_, v)| v.as_str() != Some(""))
        .map(|(k, v)| {
            format!(
                "{k}={}",
                v.as_str()
                    .map(str::to_string)
                    .unwrap_or_else(|| v.to_string())
            )
        })
        .collect()
}

impl Report {
    pub fn to_text(&self) -> String {
        let mut o = String::new();
        let _ = self.write_text(&mut o);
        o
    }

    // Long because one section per part of the report, in the order it prints.
    fn write_text(&self, o: &mut String) -> std::fmt::Result {
        let s = &self.scene;
        writeln!(
            o,
            "Scene {:?} from {} (saved by Blender {}, exported by Blender {})",
            s.name,
            self.source_file,
            dotted(&self.file_version),
            self.blender_version
        )?;
        writeln!(
            o,
            "  frames {}..{} (current {}), camera {}, world {}",
            s.frame_start,
            s.frame_end,
            s.frame_current,
            opt(&s.camera),
            opt(&s.world)
        )?;
        if let Some([x, y]) = s.resolution {
            write!(
                o,
                "  {}x{} at {}%",
                x,
                y,
                s.resolution_percentage.unwrap_or(100)
            )?;
        }
        writeln!(
            o,
            ", engine {}, {} samples, noise threshold {}, denoising {}, view transform {} (look {})",
            opt(&s.engine),
            s.samples.map(|v| v.to_string()).unwrap_or("-".into()),
            s.adaptive_threshold.map(|v| format!("{v:.3}")).unwrap_or("-".into()),
            s.denoising.map(|d| if d { "on" } else { "off" }).unwrap_or("-"),
            opt(&s.view_transform),
            opt(&s.look)
        )?;

        writeln!(o, "\nObjects ({})", self.objects.len())?;
        for ob in &self.objects {
            write!(o, "  {} [{}]", ob.name, ob.kind)?;
            if let Some(d) = &ob.data {
                write!(o, " data {d:?}")?;
            }
            if let Some(p) = &ob.parent {
                write!(o, " parent {p:?}")?;
            }
            if !ob.renders {
                write!(o, " (not rendered: hidden in render or not in a collection the view layer renders)")?;
            }
            writeln!(o)?;
            let mats: Vec<String> = ob.materials.iter().map(opt).collect();
            if !mats.is_empty() {
                writeln!(o, "    materials: {}", mats.join(", "))?;
            }
            for m in &ob.modifiers {
                writeln!(o, "    modifier {m}")?;
            }
            for c in &ob.constraints {
                writeln!(
                    o,
                    "    constraint {} {:?} target {}: {}",
                    c.kind,
                    c.name,
                    opt(&c.target),
                    c.settings.join(" ")
                )?;
            }
        }

        writeln!(o, "\nAnimation ({} curves)", self.animation.len())?;
        for a in &self.animation {
            writeln!(
                o,
                "  {}[{}]{}: {} keyframes ({}), extrapolation {}{}",
                a.path,
                a.array_index,
                if a.driver { " (driver)" } else { "" },
                a.keyframes,
                if a.interpolations.is_empty() {
                    "-".to_string()
                } else {
                    a.interpolations.join("/")
                },
                a.extrapolation,
                if a.modifiers.is_empty() {
                    String::new()
                } else {
                    format!(", modifiers {}", a.modifiers.join(", "))
                }
            )?;
        }

        writeln!(
            o,
            "\nMaterials ({}): {}",
            self.materials.len(),
            self.materials
                .iter()
                .map(|m| quote(m))
                .collect::<Vec<_>>()
                .join(", ")
        )?;

        for t in &self.node_trees {
            writeln!(
                o,
                "\nNode tree {} [{}]: {} nodes, {} links",
                t.path,
                t.bl_idname,
                t.nodes.len(),
                t.links
            )?;
            for n in &t.nodes {
                writeln!(
                    o,
                    "  {:<32} {:<40} {:>2} in {:>2} out{}{}",
                    n.name,
                    n.bl_idname,
                    n.inputs,
                    n.outputs,
                    if n.mute { "  muted" } else { "" },
                    if n.support == Support::Unsupported {
                        "  (unsupported)"
                    } else {
                        ""
                    }
                )?;
            }
        }

        if !self.images.is_empty() {
            writeln!(o, "\nImages")?;
            for i in &self.images {
                writeln!(
                    o,
                    "  {}: {}",
                    i.name,
                    if i.missing {
                        "MISSING (not packed, file not found)".to_string()
                    } else {
                        opt(&i.file)
                    }
                )?;
            }
        }

        if !self.import_files.is_empty() {
            writeln!(o, "\nImport node files")?;
            for i in &self.import_files {
                writeln!(o, "  {}: {} ({})", i.path, opt(&i.file), i.state)?;
            }
        }

        let unsupported = self
            .coverage
            .iter()
            .filter(|r| r.support == Support::Unsupported)
            .count();
        writeln!(
            o,
            "\nNode coverage: {} node types used, {} unsupported (refusing the render only where it uses them: see the checks at the end)",
            self.coverage.len(),
            unsupported
        )?;
        writeln!(
            o,
            "  {:<40} {:>5}  {:<12} used in",
            "node type", "count", "support"
        )?;
        for r in &self.coverage {
            let sup = match r.support {
                Support::Supported => "yes",
                Support::Structural => "structural",
                Support::Unsupported => "NO",
                Support::IgnoredByCycles => "ignored",
            };
            writeln!(
                o,
                "  {:<40} {:>5}  {:<12} {}",
                r.bl_idname,
                r.count,
                sup,
                r.used_in.join(", ")
            )?;
        }
        if !self.material_status.is_empty() {
            writeln!(
                o,
                "\nMaterials for the renderer (one that does not compile refuses the render only if something that renders uses it)"
            )?;
            for m in &self.material_status {
                match &m.error {
                    None => writeln!(o, "  {:?}: compiles", m.name)?,
                    Some(e) => writeln!(o, "  {:?}: does not compile: {e}", m.name)?,
                }
            }
        }
        if !self.frozen.is_empty() {
            writeln!(
                o,
                "\nFrozen geometry (Blender's evaluated mesh from the export)"
            )?;
            for z in &self.frozen {
                writeln!(
                    o,
                    "  {:?}: {} (frame {}); reads {}{}",
                    z.object,
                    z.reason,
                    z.frame,
                    z.reads.join(", "),
                    if z.animated.is_empty() {
                        String::new()
                    } else {
                        format!("; ANIMATED {} (no other frame)", z.animated.join(", "))
                    }
                )?;
            }
        }
        let grid_lists = [
            ("Smoke domains", &self.smoke_domains),
            ("Volume objects (OpenVDB)", &self.volume_objects),
        ];
        for (title, list) in grid_lists.into_iter().filter(|l| !l.1.is_empty()) {
            writeln!(o, "\n{title} (voxel grids from the export)")?;
            for d in list {
                match &d.empty {
                    None => writeln!(
                        o,
                        "  {:?}: grids {} (frame {})",
                        d.object,
                        d.grids.join(", "),
                        d.frame
                    )?,
                    Some(why) => writeln!(
                        o,
                        "  {:?}: renders nothing, as in Cycles: {why} (frame {})",
                        d.object, d.frame
                    )?,
                }
            }
        }
        writeln!(o, "\nChecks at frame {}", self.frame)?;
        for m in &self.mesh_errors {
            writeln!(o, "  mesh NOT YET: {}", m.error)?;
        }
        match &self.render_error {
            None => writeln!(o, "  render: ok")?,
            Some(e) => writeln!(o, "  render NOT YET: {e}")?,
        }
        for w in &self.warnings {
            writeln!(o, "warning: {w}")?;
        }
        Ok(())
    }
}

fn opt(v: &Option<String>) -> String {
    v.clone().unwrap_or_else(|| "-".into())
}

fn dotted(v: &[u32]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(".")
}

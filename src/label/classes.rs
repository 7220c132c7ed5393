//! Which object is which class: the object's custom property (default `class`), else
//! the first `[[labels.class]]` whose `objects` glob matches the object's name.
//! Objects with neither are not labelled (background).

use toml::Value as Toml;

use crate::scene::Scene;

/// One class of the `[labels]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassSpec {
    pub name: String,
    /// Glob patterns (`*`, `?`) on object names.
    pub objects: Vec<String>,
    /// Write its segmentation (COCO RLE, semantic mask); boxes are always written.
    pub mask: bool,
}

/// The `[labels]` section of a spec.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelSpec {
    pub classes: Vec<ClassSpec>,
    /// Custom property naming an object's class.
    pub class_property: String,
    /// Instances with fewer visible pixels are dropped (the drop rule).
    pub min_pixels: u64,
    /// Millimetres per scene unit, for 3D sizes and distances.
    pub mm_per_unit: f64,
    /// Also write depth (16-bit PNG, millimetres) and normals (float EXR).
    pub depth: bool,
    pub normals: bool,
    /// The depth PNG's full scale in mm: value = round(depth_mm / depth_png_max_mm *
    /// 65535) (default 65535: whole millimetres; SimCol3D's convention is 200).
    pub depth_png_max_mm: f64,
    /// Metric depth as float32 too: `Some(Exr)` or `Some(Npy)`.
    pub depth_float: Option<FloatFormat>,
    /// The float depth's unit: millimetres (true) or scene units (false, the default).
    pub depth_float_mm: bool,
    /// Also write normals in OpenCV camera axes (x right, y down, z forward).
    pub normals_camera: bool,
    /// The view layer's shader AOV passes, one float EXR per frame (`aovs/`).
    pub aovs: bool,
    /// Optical flow to the next and previous frame of the sequence step (float EXR,
    /// pixels, x right, y down; NaN where invalid): `flow_fw/`, `flow_bw/`.
    pub flow: bool,
    /// The flow also as Middlebury `.flo` files beside the EXRs.
    pub flow_flo: bool,
    /// Occlusion masks per direction (8-bit PNG, 255 where the pixel's surface point is
    /// hidden or off the image at the other frame): `occlusion_fw/`, `occlusion_bw/`.
    pub occlusion: bool,
    /// The evaluated scene as a world-space glb (`meshes/SPLIT/N.glb`): for every frame,
    /// or for each sequence's first frame.
    pub mesh_glb: Option<MeshGlb>,
}

/// When `mesh_glb` writes the scene mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshGlb {
    Frame,
    Sequence,
}

/// A float32 file format for per-pixel values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FloatFormat {
    /// One-channel ("Y") float32 EXR, top row first.
    Exr,
    /// NumPy `.npy`, little-endian float32, shape (height, width), top row first.
    Npy,
}

impl FloatFormat {
    pub fn extension(self) -> &'static str {
        match self {
            FloatFormat::Exr => "exr",
            FloatFormat::Npy => "npy",
        }
    }
}

impl Default for LabelSpec {
    fn default() -> Self {
        LabelSpec {
            classes: Vec::new(),
            class_property: "class".into(),
            min_pixels: 16,
            mm_per_unit: 1000.0,
            depth: false,
            normals: false,
            depth_png_max_mm: 65535.0,
            depth_float: None,
            depth_float_mm: false,
            normals_camera: false,
            aovs: false,
            flow: false,
            flow_flo: false,
            occlusion: false,
            mesh_glb: None,
        }
    }
}

impl LabelSpec {
    pub fn from_toml(v: &Toml) -> Result<LabelSpec, String> {
        let t = v.as_table().ok_or("must be a table")?;
        let mut s = LabelSpec::default();
        for (k, x) in t {
            match k.as_str() {
                "class_property" => s.class_property = x.as_str().ok_or("class_property must be a string")?.to_string(),
                "min_pixels" => s.min_pixels = x.as_integer().filter(|i| *i >= 0).ok_or("min_pixels must be an integer >= 0")? as u64,
                "mm_per_unit" => {
                    s.mm_per_unit = match x {
                        Toml::Float(f) if *f > 0.0 => *f,
                        Toml::Integer(i) if *i > 0 => *i as f64,
                        _ => return Err("mm_per_unit must be a positive number".into()),
                    }
                }
                "depth" => s.depth = x.as_bool().ok_or("depth must be true or false")?,
                "normals" => s.normals = x.as_bool().ok_or("normals must be true or false")?,
                "normals_camera" => s.normals_camera = x.as_bool().ok_or("normals_camera must be true or false")?,
                "aovs" => s.aovs = x.as_bool().ok_or("aovs must be true or false")?,
                "flow" => s.flow = x.as_bool().ok_or("flow must be true or false")?,
                "flow_flo" => s.flow_flo = x.as_bool().ok_or("flow_flo must be true or false")?,
                "occlusion" => s.occlusion = x.as_bool().ok_or("occlusion must be true or false")?,
                "mesh_glb" => {
                    s.mesh_glb = match x.as_str() {
                        Some("frame") => Some(MeshGlb::Frame),
                        Some("sequence") => Some(MeshGlb::Sequence),
                        _ => return Err("mesh_glb must be \"frame\" (every frame) or \"sequence\" (each sequence's first frame)".into()),
                    }
                }
                "depth_png_max_mm" => {
                    s.depth_png_max_mm = match x {
                        Toml::Float(f) if f.is_finite() && *f > 0.0 => *f,
                        Toml::Integer(i) if *i > 0 => *i as f64,
                        _ => return Err("depth_png_max_mm must be a positive number (the 16-bit PNG's full scale in mm; SimCol3D uses 200)".into()),
                    }
                }
                "depth_float" => {
                    s.depth_float = match x.as_str() {
                        Some("exr") => Some(FloatFormat::Exr),
                        Some("npy") => Some(FloatFormat::Npy),
                        _ => return Err("depth_float must be \"exr\" or \"npy\"".into()),
                    }
                }
                "depth_float_unit" => {
                    s.depth_float_mm = match x.as_str() {
                        Some("mm") => true,
                        Some("scene") => false,
                        _ => return Err("depth_float_unit must be \"scene\" or \"mm\"".into()),
                    }
                }
                "class" => {
                    for (i, c) in x.as_array().ok_or("class must be an array of tables ([[labels.class]])")?.iter().enumerate() {
                        let c = c.as_table().ok_or(format!("class[{i}] must be a table"))?;
                        for key in c.keys() {
                            if !["name", "objects", "mask"].contains(&key.as_str()) {
                                return Err(format!("class[{i}]: unknown key {key:?} (expected name, objects, mask)"));
                            }
                        }
                        let name = c.get("name").and_then(Toml::as_str).ok_or(format!("class[{i}] needs name"))?.to_string();
                        let objects = match c.get("objects") {
                            None => Vec::new(),
                            Some(o) => o
                                .as_array()
                                .and_then(|a| a.iter().map(|p| p.as_str().map(String::from)).collect::<Option<Vec<_>>>())
                                .ok_or(format!("class {name:?}: objects must be a list of name patterns"))?,
                        };
                        let mask = match c.get("mask") {
                            None => true,
                            Some(m) => m.as_bool().ok_or(format!("class {name:?}: mask must be true or false"))?,
                        };
                        if s.classes.iter().any(|c| c.name == name) {
                            return Err(format!("class {name:?} appears twice"));
                        }
                        s.classes.push(ClassSpec { name, objects, mask });
                    }
                }
                other => return Err(format!("unknown key {other:?} (expected class, class_property, min_pixels, mm_per_unit, depth, depth_png_max_mm, depth_float, depth_float_unit, normals, normals_camera, aovs, flow, flow_flo, occlusion, mesh_glb)")),
            }
        }
        if s.flow_flo && !s.flow {
            return Err(
                "flow_flo = true writes the flow as .flo files too: it needs flow = true".into(),
            );
        }
        Ok(s)
    }

    /// Whether frames need the renderer's motion (flow or occlusion).
    pub fn motion(&self) -> bool {
        self.flow || self.occlusion
    }
}

/// Classes resolved against a scene: the category list and each object's class.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassMap {
    /// Category names; COCO ids are index + 1, YOLO ids the index. Spec classes first,
    /// in spec order, then classes only custom properties name, sorted.
    pub names: Vec<String>,
    pub masks: Vec<bool>,
    /// Class of each scene object (by `scene.file.objects` index).
    pub object_class: Vec<Option<usize>>,
    object_names: Vec<String>,
}

impl ClassMap {
    pub fn new(spec: &LabelSpec, scene: &Scene) -> ClassMap {
        let mut names: Vec<String> = spec.classes.iter().map(|c| c.name.clone()).collect();
        let mut masks: Vec<bool> = spec.classes.iter().map(|c| c.mask).collect();
        let mut extra: Vec<String> = scene
            .file
            .objects
            .iter()
            .filter_map(|o| {
                o.custom_properties
                    .get(&spec.class_property)
                    .and_then(|v| v.as_str())
                    .map(String::from)
            })
            .filter(|n| !names.contains(n))
            .collect();
        extra.sort();
        extra.dedup();
        for e in extra {
            names.push(e);
            masks.push(true);
        }
        let object_class = scene
            .file
            .objects
            .iter()
            .map(|o| {
                if let Some(c) = o
                    .custom_properties
                    .get(&spec.class_property)
                    .and_then(|v| v.as_str())
                {
                    return names.iter().position(|n| n == c);
                }
                spec.classes
                    .iter()
                    .position(|c| c.objects.iter().any(|p| glob(p, &o.name)))
            })
            .collect();
        ClassMap {
            names,
            masks,
            object_class,
            object_names: scene.file.objects.iter().map(|o| o.name.clone()).collect(),
        }
    }

    /// The class of an object by name.
    pub fn class_of(&self, object: &str) -> Option<usize> {
        self.object_names
            .iter()
            .position(|n| n == object)
            .and_then(|i| self.object_class[i])
    }
}

/// Shell-style glob: `*` any run, `?` one character.
pub fn glob(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    let (mut pi, mut ni, mut star, mut mark) = (0, 0, None, 0);
    while ni < n.len() {
        if pi < p.len() && (p[pi] == '?' || p[pi] == n[ni]) {
            pi += 1;
            ni += 1;
        } else if pi < p.len() && p[pi] == '*' {
            star = Some(pi);
            mark = ni;
            pi += 1;
        } else if let Some(s) = star {
            pi = s + 1;
            mark += 1;
            ni = mark;
        } else {
            return false;
        }
    }
    p[pi..].iter().all(|c| *c == '*')
}

#[cfg(test)]
mod tests {
    use super::glob;

    #[test]
    fn globs() {
        assert!(glob("Polyp*", "Polyp.003"));
        assert!(glob("*liver*", "the liver mesh"));
        assert!(glob("a?c", "abc"));
        assert!(!glob("Polyp*", "Colon"));
        assert!(glob("*", ""));
    }
}

//! The randomisation spec (TOML): which exported parameters change per frame, by Blender
//! data path (the `--set` syntax), with what distribution; the frame schedule; render
//! settings; label classes. README.md ("Randomisation spec") documents the format.
//!
//! Every value of frame `i` is a pure function of (spec, dataset seed, i): each parameter
//! draws from its own counter-based stream keyed by its data path (`rng`), so frames can
//! be regenerated alone and in any order.

use std::path::Path;

use serde_json::Value;
use toml::Value as Toml;

use super::rng;
use crate::label::classes::LabelSpec;
use crate::scene::datapath::{parse, Token};
use crate::scene::{Override, Scene};

/// An error in a spec, naming the parameter path (or spec field) at fault.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecError {
    pub at: String,
    pub message: String,
}

impl std::fmt::Display for SpecError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "spec: {}: {}", self.at, self.message)
    }
}
impl std::error::Error for SpecError {}

fn err(at: impl Into<String>, message: impl Into<String>) -> SpecError {
    SpecError {
        at: at.into(),
        message: message.into(),
    }
}

/// Render settings the spec fixes for every frame (None: the scene's own).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RenderSettings {
    pub resolution: Option<(u32, u32)>,
    pub samples: Option<u32>,
    pub threshold: Option<f32>,
    pub denoise: Option<bool>,
}

/// Which scene frame dataset frame `i` shows: `(start + i * step) mod modulo`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameSchedule {
    /// None: the scene's `frame_current`.
    pub start: Option<i64>,
    pub step: i64,
    pub modulo: Option<i64>,
}

/// `[sequence]`: dataset frames come in runs of `length` consecutive frames: frame i is
/// frame `i % length` of sequence `i / length`, which starts at the scene frame the
/// `[frames]` schedule gives index `i / length` and advances by `step` scene frames;
/// parameters are drawn once per sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct SequenceSpec {
    pub length: u64,
    pub step: i64,
    /// How many sequences (the dataset has count x length frames); None: --frames / length.
    pub count: Option<u64>,
}

impl SequenceSpec {
    /// The number of sequences of a dataset of `frames` frames; an error unless the
    /// frames are whole sequences (and `count` sequences when it is set).
    // `%`: u64::is_multiple_of needs Rust 1.87 (MSRV 1.80).
    #[allow(clippy::manual_is_multiple_of)]
    pub fn sequences(&self, frames: u64) -> Result<u64, SpecError> {
        if frames % self.length != 0 {
            return Err(err(
                "sequence.length",
                format!("{frames} frames are not whole sequences of {}", self.length),
            ));
        }
        let n = frames / self.length;
        match self.count {
            Some(c) if c != n => Err(err(
                "sequence.count",
                format!(
                    "{c} sequences of {} frames need {} frames, not {frames}",
                    self.length,
                    c as u128 * self.length as u128
                ),
            )),
            _ => Ok(n),
        }
    }
}

fn parse_sequence(v: &Toml) -> Result<SequenceSpec, SpecError> {
    let t = v
        .as_table()
        .ok_or_else(|| err("sequence", "must be a table"))?;
    let mut q = SequenceSpec {
        length: 0,
        step: 1,
        count: None,
    };
    let span = MAX_FRAME - MIN_FRAME;
    for (k, x) in t {
        let at = format!("sequence.{k}");
        let i = x
            .as_integer()
            .ok_or_else(|| err(&at, "must be an integer"))?;
        match k.as_str() {
            "length" if (1..=span).contains(&i) => q.length = i as u64,
            "length" => return Err(err(&at, format!("{i} is not within [1, {span}]"))),
            "step" if (-span..=span).contains(&i) && i != 0 => q.step = i,
            "step" => {
                return Err(err(
                    &at,
                    format!("{i} is not a non-zero step within [-{span}, {span}]"),
                ))
            }
            "count" if i >= 1 => q.count = Some(i as u64),
            "count" => return Err(err(&at, format!("{i}: need at least one sequence"))),
            _ => return Err(err(&at, "unknown key (expected length, step, count)")),
        }
    }
    if q.length == 0 {
        return Err(err("sequence.length", "missing (frames per sequence)"));
    }
    Ok(q)
}

/// Blender's frame limits (`MINAFRAME`, `MAXFRAME`): a scene frame outside them is not
/// one Blender can show.
pub const MIN_FRAME: i64 = -1_048_574;
pub const MAX_FRAME: i64 = 1_048_574;

impl FrameSchedule {
    /// The scene frame of dataset frame `index`. Exact (128-bit); `check` has made sure
    /// every index of the dataset lands within Blender's frame range.
    pub fn frame(&self, scene_current: i64, index: u64) -> i64 {
        let f = self.start.unwrap_or(scene_current) as i128 + self.step as i128 * index as i128;
        match self.modulo {
            Some(m) => f.rem_euclid(m as i128) as i64,
            None => f.clamp(i64::MIN as i128, i64::MAX as i128) as i64,
        }
    }

    /// Every frame of a dataset of `frames` frames must be a Blender frame: the schedule
    /// is linear in the index (or wraps into [0, modulo)), so its ends decide.
    pub fn check(&self, scene_current: i64, frames: u64) -> Result<(), SpecError> {
        let last = frames.saturating_sub(1);
        for (at, i) in [("frames.start", 0), ("frames.step", last)] {
            let f = self.start.unwrap_or(scene_current) as i128 + self.step as i128 * i as i128;
            let f = match self.modulo {
                Some(m) => f.rem_euclid(m as i128),
                None => f,
            };
            if !(MIN_FRAME as i128..=MAX_FRAME as i128).contains(&f) {
                return Err(err(
                    at,
                    format!(
                        "dataset frame {i} would show scene frame {f}, outside Blender's frame range [{MIN_FRAME}, {MAX_FRAME}]"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A distribution a parameter is drawn from.
#[derive(Debug, Clone, PartialEq)]
pub enum Dist {
    /// Uniform in [min, max); one component, or one per component of a vector/colour.
    Uniform { min: Vec<f64>, max: Vec<f64> },
    /// Uniform integer in [min, max], both included.
    UniformInt { min: i64, max: i64 },
    /// Normal, optionally clamped to [lo, hi].
    Normal {
        mean: f64,
        std: f64,
        clamp: Option<(f64, f64)>,
    },
    /// Log-uniform in [min, max), min > 0.
    LogUniform { min: f64, max: f64 },
    /// One of `values`, with optional weights.
    Choice {
        values: Vec<Value>,
        weights: Option<Vec<f64>>,
    },
    /// A colour from HSV components each uniform in its range, converted to RGB as
    /// Python's colorsys does (what the study's script did). Alpha is kept.
    Hsv {
        h: (f64, f64),
        s: (f64, f64),
        v: (f64, f64),
    },
    /// A colour with each RGB channel uniform between `min` and `max`. Alpha is kept.
    Color { min: [f64; 3], max: [f64; 3] },
}

/// One randomised parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Blender data path, without `bpy.data.`.
    pub path: String,
    /// Add the drawn value to the scene's value (object transform offsets) instead of
    /// replacing it.
    pub offset: bool,
    pub dist: Dist,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    pub render: RenderSettings,
    pub frames: FrameSchedule,
    /// Runs of consecutive scene frames (`[sequence]`), when set.
    pub sequence: Option<SequenceSpec>,
    pub labels: LabelSpec,
    pub params: Vec<Param>,
    /// The TOML text, recorded in the dataset manifest.
    pub source: String,
}

/// What frame `i` of a dataset gets: scene frame, render seed and parameter values.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameValues {
    pub index: u64,
    pub frame: i64,
    /// Cycles seed for this frame's render.
    pub render_seed: u32,
    /// (path, value drawn); for offsets the drawn offset.
    pub drawn: Vec<(String, Value)>,
    /// The overrides to apply (for offsets: base + offset).
    pub overrides: Vec<Override>,
}

impl Spec {
    pub fn load(path: &Path) -> Result<Spec, SpecError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| err(path.display().to_string(), format!("cannot read: {e}")))?;
        Spec::parse(&text).map_err(|e| SpecError {
            at: format!("{}: {}", path.display(), e.at),
            message: e.message,
        })
    }

    pub fn parse(text: &str) -> Result<Spec, SpecError> {
        let root: toml::Table =
            toml::from_str(text).map_err(|e| err("TOML", e.to_string().replace('\n', " ")))?;
        let mut spec = Spec {
            render: RenderSettings::default(),
            frames: FrameSchedule {
                start: None,
                step: 1,
                modulo: None,
            },
            sequence: None,
            labels: LabelSpec::default(),
            params: Vec::new(),
            source: text.to_string(),
        };
        for (k, v) in &root {
            match k.as_str() {
                "render" => spec.render = parse_render(v)?,
                "frames" => spec.frames = parse_frames(v)?,
                "sequence" => spec.sequence = Some(parse_sequence(v)?),
                "labels" => spec.labels = LabelSpec::from_toml(v).map_err(|m| err("labels", m))?,
                "param" => {
                    let Toml::Array(items) = v else {
                        return Err(err("param", "must be an array of tables ([[param]])"));
                    };
                    for (i, item) in items.iter().enumerate() {
                        spec.params.push(parse_param(item).map_err(|e| {
                            if e.at.is_empty() {
                                err(format!("param[{i}]"), e.message)
                            } else {
                                e
                            }
                        })?);
                    }
                }
                other => {
                    return Err(err(
                        other,
                        "unknown section (expected render, frames, sequence, labels, param)",
                    ))
                }
            }
        }
        let mut seen = std::collections::HashSet::new();
        for p in &spec.params {
            if !seen.insert(p.path.as_str()) {
                return Err(err(&p.path, "appears twice; give each path one [[param]]"));
            }
        }
        Ok(spec)
    }

    /// The values of dataset frame `index`: a pure function of (spec, scene, seed, index).
    pub fn frame_values(
        &self,
        scene_json: &Value,
        scene_current: i64,
        seed: u64,
        index: u64,
    ) -> Result<FrameValues, SpecError> {
        let mut drawn = Vec::with_capacity(self.params.len());
        let mut overrides = Vec::with_capacity(self.params.len());
        // In a sequence, parameters are drawn once per sequence (keyed by its index) and
        // the scene frame advances by the sequence's step.
        let (draw_index, frame) = match &self.sequence {
            Some(q) => {
                let (s, k) = (index / q.length, index % q.length);
                let f = self.frames.frame(scene_current, s) as i128 + q.step as i128 * k as i128;
                (s, f.clamp(i64::MIN as i128, i64::MAX as i128) as i64)
            }
            None => (index, self.frames.frame(scene_current, index)),
        };
        for p in &self.params {
            let key = rng::key(&p.path);
            let v = sample(&p.dist, seed, draw_index, key);
            let slot = lookup(scene_json, &p.path).map_err(|m| err(&p.path, m))?;
            let applied = if p.offset {
                add_offset(slot, &v).map_err(|m| err(&p.path, m))?
            } else {
                fit_colour(slot, v.clone())
            };
            drawn.push((p.path.clone(), v));
            overrides.push(Override {
                path: p.path.clone(),
                value: applied,
            });
        }
        let render_seed = rng::bits(seed, index, rng::key("#render_seed"), 0) as u32;
        Ok(FrameValues {
            index,
            frame,
            render_seed,
            drawn,
            overrides,
        })
    }

    /// Checks every parameter against the scene before anything renders: the path
    /// exists, the distribution fits the property's type, its values stay within the
    /// property's range, and the overrides apply. Returns warnings (paths an F-curve
    /// animates, whose override the animation would replace).
    pub fn validate(&self, scene: &Scene) -> Result<Vec<String>, SpecError> {
        let root = serde_json::to_value(&scene.file).map_err(|e| err("scene", e.to_string()))?;
        let mut warnings = Vec::new();
        for p in &self.params {
            let chain = walk(&root, &p.path).map_err(|m| err(&p.path, m))?;
            let slot = *chain.last().unwrap();
            check_type(slot, &p.dist, p.offset).map_err(|m| err(&p.path, m))?;
            if let Some((lo, hi)) = range_of(&root, &p.path, &chain) {
                let support = support(&p.dist).map_err(|m| {
                    err(
                        &p.path,
                        format!("{m}; the property's range is [{lo}, {hi}]"),
                    )
                })?;
                for (i, (a, b)) in support.iter().enumerate() {
                    let base = if p.offset { component(slot, i) } else { 0.0 };
                    let (a, b) = (a + base, b + base);
                    if a < lo || b > hi {
                        return Err(err(
                            &p.path,
                            format!("values [{a}, {b}] leave the property's range [{lo}, {hi}]"),
                        ));
                    }
                }
            }
            if let Some(w) = animated(scene, &p.path) {
                warnings.push(format!("{}: {w}", p.path));
            }
        }
        // Values of the first frame must apply (types the typed scene enforces too).
        let fv = self.frame_values(&root, scene.file.scene.frame_current as i64, 0, 0)?;
        scene
            .with_overrides(&fv.overrides)
            .map_err(|e| err("param", e.to_string()))?;
        Ok(warnings)
    }
}

/// Blender's largest render resolution side (`resolution_x`, `resolution_y`).
pub const MAX_RESOLUTION: i64 = 65536;
/// Cycles' largest sample count (`cycles.samples`).
pub const MAX_SAMPLES: i64 = 1 << 24;

fn parse_render(v: &Toml) -> Result<RenderSettings, SpecError> {
    let t = v
        .as_table()
        .ok_or_else(|| err("render", "must be a table"))?;
    let mut r = RenderSettings::default();
    for (k, x) in t {
        let at = format!("render.{k}");
        match k.as_str() {
            "resolution" => {
                let a = x
                    .as_array()
                    .filter(|a| a.len() == 2)
                    .ok_or_else(|| err(&at, "must be [width, height]"))?;
                let side = |v: &Toml, what: &str| {
                    v.as_integer()
                        .filter(|n| (1..=MAX_RESOLUTION).contains(n))
                        .map(|n| n as u32)
                        .ok_or_else(|| {
                            err(
                                &at,
                                format!("{what} must be an integer in [1, {MAX_RESOLUTION}] (Blender's limit), not {v}"),
                            )
                        })
                };
                r.resolution = Some((side(&a[0], "width")?, side(&a[1], "height")?));
            }
            "samples" => {
                r.samples = Some(
                    x.as_integer()
                        .filter(|s| (1..=MAX_SAMPLES).contains(s))
                        .ok_or_else(|| {
                            err(
                                &at,
                                format!("must be an integer in [1, {MAX_SAMPLES}] (Cycles' limit), not {x}"),
                            )
                        })? as u32,
                )
            }
            "threshold" => {
                r.threshold = Some(
                    num(x)
                        .filter(|t| (0.0..=1.0).contains(t))
                        .ok_or_else(|| {
                            err(
                                &at,
                                format!("must be a number in [0, 1] (Cycles' adaptive threshold range; 0 turns adaptive sampling off), not {x}"),
                            )
                        })? as f32,
                )
            }
            "denoise" => {
                r.denoise = Some(
                    x.as_bool()
                        .ok_or_else(|| err(&at, "must be true or false"))?,
                )
            }
            _ => {
                return Err(err(
                    &at,
                    "unknown key (expected resolution, samples, threshold, denoise)",
                ))
            }
        }
    }
    Ok(r)
}

fn parse_frames(v: &Toml) -> Result<FrameSchedule, SpecError> {
    let t = v
        .as_table()
        .ok_or_else(|| err("frames", "must be a table"))?;
    let mut f = FrameSchedule {
        start: None,
        step: 1,
        modulo: None,
    };
    for (k, x) in t {
        let at = format!("frames.{k}");
        let i = x
            .as_integer()
            .ok_or_else(|| err(&at, "must be an integer"))?;
        // Within Blender's frame range, so the schedule's arithmetic cannot overflow
        // and `check` can bound every frame.
        let span = MAX_FRAME - MIN_FRAME;
        match k.as_str() {
            "start" if (MIN_FRAME..=MAX_FRAME).contains(&i) => f.start = Some(i),
            "start" => {
                return Err(err(
                    &at,
                    format!("{i} is outside Blender's frame range [{MIN_FRAME}, {MAX_FRAME}]"),
                ))
            }
            "step" if (-span..=span).contains(&i) => f.step = i,
            "step" => {
                return Err(err(
                    &at,
                    format!("{i} is not within [-{span}, {span}] (Blender's frame range)"),
                ))
            }
            "modulo" if (1..=MAX_FRAME + 1).contains(&i) => f.modulo = Some(i),
            "modulo" => {
                return Err(err(
                    &at,
                    format!(
                        "must be positive and at most {} (Blender's frame range), not {i}",
                        MAX_FRAME + 1
                    ),
                ))
            }
            _ => return Err(err(&at, "unknown key (expected start, step, modulo)")),
        }
    }
    Ok(f)
}

/// A spec number: finite and within the 32-bit float range, since Blender stores its
/// float properties as 32-bit floats (a larger value would become infinity there).
fn num(v: &Toml) -> Option<f64> {
    match v {
        Toml::Float(f) => Some(*f),
        Toml::Integer(i) => Some(*i as f64),
        _ => None,
    }
    .filter(|x| x.is_finite() && x.abs() <= f32::MAX as f64)
}

fn nums(v: &Toml) -> Option<Vec<f64>> {
    match v {
        Toml::Array(a) => a.iter().map(num).collect(),
        x => num(x).map(|n| vec![n]),
    }
}

fn pair(v: Option<&Toml>, what: &str) -> Result<(f64, f64), SpecError> {
    let a = v.and_then(nums).filter(|a| a.len() == 2).ok_or_else(|| {
        err(
            "",
            format!("{what} must be [low, high], finite numbers within the 32-bit float range"),
        )
    })?;
    if a[0] > a[1] {
        return Err(err("", format!("{what}: low {} > high {}", a[0], a[1])));
    }
    Ok((a[0], a[1]))
}

fn toml_to_json(v: &Toml) -> Value {
    match v {
        Toml::String(s) => Value::String(s.clone()),
        Toml::Integer(i) => Value::from(*i),
        Toml::Float(f) => Value::from(*f),
        Toml::Boolean(b) => Value::Bool(*b),
        Toml::Array(a) => Value::Array(a.iter().map(toml_to_json).collect()),
        Toml::Table(t) => Value::Object(
            t.iter()
                .map(|(k, v)| (k.clone(), toml_to_json(v)))
                .collect(),
        ),
        Toml::Datetime(d) => Value::String(d.to_string()),
    }
}

// Long because one arm per distribution, each checking its own keys.
fn parse_param(v: &Toml) -> Result<Param, SpecError> {
    let t = v.as_table().ok_or_else(|| err("", "must be a table"))?;
    let path = t
        .get("path")
        .and_then(Toml::as_str)
        .ok_or_else(|| err("", "missing path = \"...\""))?;
    let path = path.strip_prefix("bpy.data.").unwrap_or(path).to_string();
    parse(&path).map_err(|m| err(&path, m))?;
    let at = |m: String| err(&path, m);
    let offset = match t.get("offset") {
        None => false,
        Some(x) => x
            .as_bool()
            .ok_or_else(|| at("offset must be true or false".into()))?,
    };
    let kind = t.get("dist").and_then(Toml::as_str).ok_or_else(|| at("missing dist = \"uniform\" | \"uniform_int\" | \"normal\" | \"log_uniform\" | \"choice\" | \"hsv\" | \"color\"".into()))?;
    let allowed: &[&str] = match kind {
        "uniform" | "log_uniform" | "uniform_int" | "color" => &["min", "max"],
        "normal" => &["mean", "std", "clamp"],
        "choice" => &["values", "weights"],
        "hsv" => &["h", "s", "v"],
        other => return Err(at(format!("unknown dist {other:?}"))),
    };
    for k in t.keys() {
        if !["path", "offset", "dist"].contains(&k.as_str()) && !allowed.contains(&k.as_str()) {
            return Err(at(format!(
                "unknown key {k:?} for dist {kind:?} (expected {})",
                allowed.join(", ")
            )));
        }
    }
    let get = |k: &str| {
        t.get(k)
            .ok_or_else(|| at(format!("dist {kind:?} needs {k}")))
    };
    let with_path = |e: SpecError| at(e.message);
    let dist = match kind {
        "uniform" => {
            let min = nums(get("min")?).ok_or_else(|| {
                at("min must be a finite number or a list of them (32-bit float range)".into())
            })?;
            let max = nums(get("max")?).ok_or_else(|| {
                at("max must be a finite number or a list of them (32-bit float range)".into())
            })?;
            if min.len() != max.len() || min.is_empty() {
                return Err(at("min and max must have the same length".into()));
            }
            if let Some(i) = (0..min.len()).find(|&i| min[i] > max[i]) {
                return Err(at(format!(
                    "min {} > max {} (component {i})",
                    min[i], max[i]
                )));
            }
            Dist::Uniform { min, max }
        }
        "uniform_int" => {
            let min = get("min")?
                .as_integer()
                .ok_or_else(|| at("min must be an integer".into()))?;
            let max = get("max")?
                .as_integer()
                .ok_or_else(|| at("max must be an integer".into()))?;
            if min > max {
                return Err(at(format!("min {min} > max {max}")));
            }
            Dist::UniformInt { min, max }
        }
        "log_uniform" => {
            let min = num(get("min")?)
                .ok_or_else(|| at("min must be a finite number (32-bit float range)".into()))?;
            let max = num(get("max")?)
                .ok_or_else(|| at("max must be a finite number (32-bit float range)".into()))?;
            if !(min > 0.0 && min <= max) {
                return Err(at(format!("needs 0 < min <= max (got {min}, {max})")));
            }
            Dist::LogUniform { min, max }
        }
        "normal" => {
            let mean = num(get("mean")?)
                .ok_or_else(|| at("mean must be a finite number (32-bit float range)".into()))?;
            let std = num(get("std")?).filter(|s| *s >= 0.0).ok_or_else(|| {
                at("std must be a finite number >= 0 (32-bit float range)".into())
            })?;
            let clamp = match t.get("clamp") {
                None => None,
                Some(c) => Some(pair(Some(c), "clamp").map_err(with_path)?),
            };
            Dist::Normal { mean, std, clamp }
        }
        "choice" => {
            let values: Vec<Value> = get("values")?
                .as_array()
                .ok_or_else(|| at("values must be a list".into()))?
                .iter()
                .map(toml_to_json)
                .collect();
            if values.is_empty() {
                return Err(at("values is empty".into()));
            }
            let weights = match t.get("weights") {
                None => None,
                Some(w) => {
                    let w = nums(w).filter(|w| w.len() == values.len()).ok_or_else(|| {
                        at("weights must be a list of finite numbers as long as values".into())
                    })?;
                    if w.iter().any(|x| *x < 0.0 || !x.is_finite()) || w.iter().sum::<f64>() <= 0.0
                    {
                        return Err(at("weights must be >= 0 with a positive sum".into()));
                    }
                    Some(w)
                }
            };
            Dist::Choice { values, weights }
        }
        "hsv" => Dist::Hsv {
            h: pair(t.get("h"), "h").map_err(with_path)?,
            s: pair(t.get("s"), "s").map_err(with_path)?,
            v: pair(t.get("v"), "v").map_err(with_path)?,
        },
        "color" => {
            let three = |k: &str| -> Result<[f64; 3], SpecError> {
                let a = t
                    .get(k)
                    .and_then(nums)
                    .filter(|a| a.len() == 3)
                    .ok_or_else(|| {
                        at(format!(
                            "{k} must be [r, g, b], finite numbers (32-bit float range)"
                        ))
                    })?;
                Ok([a[0], a[1], a[2]])
            };
            let (min, max) = (three("min")?, three("max")?);
            if let Some(i) = (0..3).find(|&i| min[i] > max[i]) {
                return Err(at(format!("min {} > max {} (channel {i})", min[i], max[i])));
            }
            Dist::Color { min, max }
        }
        _ => unreachable!("checked above"),
    };
    if offset
        && matches!(
            dist,
            Dist::Choice { .. } | Dist::Hsv { .. } | Dist::Color { .. }
        )
    {
        return Err(at(format!(
            "offset = true needs a numeric distribution, not {kind:?}"
        )));
    }
    Ok(Param { path, offset, dist })
}

/// Draws one value. Component `k` of a vector uses draw `k`; normal uses draws 0 and 1.
pub fn sample(d: &Dist, seed: u64, frame: u64, key: u64) -> Value {
    let u = |draw: u64| rng::unit(seed, frame, key, draw);
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    match d {
        Dist::Uniform { min, max } => {
            if min.len() == 1 {
                Value::from(lerp(min[0], max[0], u(0)))
            } else {
                Value::from(
                    (0..min.len())
                        .map(|k| lerp(min[k], max[k], u(k as u64)))
                        .collect::<Vec<f64>>(),
                )
            }
        }
        Dist::UniformInt { min, max } => {
            Value::from(rng::int_inclusive(seed, frame, key, 0, *min, *max))
        }
        Dist::Normal { mean, std, clamp } => {
            // Box-Muller; 1 - u keeps the logarithm's argument in (0, 1].
            let r = (-2.0 * (1.0 - u(0)).ln()).sqrt();
            let x = mean + std * r * (std::f64::consts::TAU * u(1)).cos();
            Value::from(match clamp {
                Some((lo, hi)) => x.clamp(*lo, *hi),
                None => x,
            })
        }
        Dist::LogUniform { min, max } => {
            Value::from((min.ln() + (max.ln() - min.ln()) * u(0)).exp())
        }
        Dist::Choice { values, weights } => {
            let i = match weights {
                None => {
                    rng::int_inclusive(seed, frame, key, 0, 0, values.len() as i64 - 1) as usize
                }
                Some(w) => {
                    let total: f64 = w.iter().sum();
                    let mut x = u(0) * total;
                    let mut pick = w.len() - 1;
                    for (i, wi) in w.iter().enumerate() {
                        if x < *wi {
                            pick = i;
                            break;
                        }
                        x -= wi;
                    }
                    pick
                }
            };
            values[i].clone()
        }
        Dist::Hsv { h, s, v } => {
            let rgb = hsv_to_rgb(
                lerp(h.0, h.1, u(0)),
                lerp(s.0, s.1, u(1)),
                lerp(v.0, v.1, u(2)),
            );
            Value::from(rgb.to_vec())
        }
        Dist::Color { min, max } => Value::from(
            (0..3)
                .map(|k| lerp(min[k], max[k], u(k as u64)))
                .collect::<Vec<f64>>(),
        ),
    }
}

/// Python's `colorsys.hsv_to_rgb`.
pub fn hsv_to_rgb(h: f64, s: f64, v: f64) -> [f64; 3] {
    if s == 0.0 {
        return [v, v, v];
    }
    let i = (h * 6.0).floor();
    let f = h * 6.0 - i;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    match (i as i64).rem_euclid(6) {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

/// A 3-channel colour into a 4-wide slot keeps the slot's alpha.
fn fit_colour(slot: &Value, v: Value) -> Value {
    match (slot, &v) {
        (Value::Array(old), Value::Array(new)) if old.len() == 4 && new.len() == 3 => {
            let mut out = new.clone();
            out.push(old[3].clone());
            Value::Array(out)
        }
        _ => v,
    }
}

fn component(slot: &Value, i: usize) -> f64 {
    match slot {
        Value::Array(a) => a
            .get(i)
            .or(a.first())
            .and_then(Value::as_f64)
            .unwrap_or(0.0),
        x => x.as_f64().unwrap_or(0.0),
    }
}

fn add_offset(slot: &Value, off: &Value) -> Result<Value, String> {
    match (slot, off) {
        (Value::Number(b), Value::Number(o)) => {
            if b.is_f64() {
                Ok(Value::from(b.as_f64().unwrap() + o.as_f64().unwrap()))
            } else if let (Some(b), Some(o)) = (b.as_i64(), o.as_i64()) {
                Ok(Value::from(b + o))
            } else {
                Err(format!("cannot add {o} to the integer {b}"))
            }
        }
        (Value::Array(b), Value::Number(_)) => Ok(Value::Array(
            b.iter()
                .map(|x| add_offset(x, off))
                .collect::<Result<_, _>>()?,
        )),
        (Value::Array(b), Value::Array(o)) if b.len() == o.len() => Ok(Value::Array(
            b.iter()
                .zip(o)
                .map(|(x, y)| add_offset(x, y))
                .collect::<Result<_, _>>()?,
        )),
        (b, o) => Err(format!("cannot add offset {o} to {b}")),
    }
}

/// The current value at a data path in the scene JSON.
pub fn lookup<'a>(root: &'a Value, path: &str) -> Result<&'a Value, String> {
    Ok(*walk(root, path)?.last().unwrap())
}

/// Read-only walk of a data path with the rules of `scene::overrides::set`, returning
/// every value passed through (the last is the addressed one).
fn walk<'a>(root: &'a Value, path: &str) -> Result<Vec<&'a Value>, String> {
    const COLLECTIONS: &[&str] = &[
        "objects",
        "meshes",
        "curves",
        "materials",
        "worlds",
        "node_groups",
        "cameras",
        "lights",
        "images",
    ];
    let tokens = parse(path)?;
    let mut it = tokens.iter();
    let mut chain = Vec::new();
    let first = match it.next() {
        Some(Token::Prop(c)) if c == "scenes" => {
            let Some(Token::Key(name)) = it.next() else {
                return Err("expected scenes[\"NAME\"]".into());
            };
            let s = &root["scene"];
            if s["name"].as_str() != Some(name.as_str()) {
                return Err(format!(
                    "no scene named {name:?} (the export holds {})",
                    s["name"]
                ));
            }
            s
        }
        Some(Token::Prop(c)) if COLLECTIONS.contains(&c.as_str()) => root
            .get(c.as_str())
            .ok_or_else(|| format!("the export has no {c}"))?,
        Some(t) => {
            return Err(format!(
                "{t:?} is not a bpy.data collection this format holds ({})",
                COLLECTIONS.join(", ")
            ))
        }
        None => return Err("empty path".into()),
    };
    chain.push(first);
    let mut cur = first;
    for t in it {
        cur = match t {
            Token::Prop(p) => {
                let map = cur
                    .as_object()
                    .ok_or_else(|| format!("no property {p:?} (not a structure)"))?;
                map.get(p.as_str())
                    .or_else(|| map.get("properties").and_then(|x| x.get(p.as_str())))
                    .ok_or_else(|| format!("no property {p:?}"))?
            }
            Token::Key(k) => match cur {
                Value::Array(items) => items
                    .iter()
                    .find(|x| x.get("identifier").and_then(Value::as_str) == Some(k.as_str()))
                    .or_else(|| {
                        items
                            .iter()
                            .find(|x| x.get("name").and_then(Value::as_str) == Some(k.as_str()))
                    })
                    .ok_or_else(|| format!("nothing named {k:?}"))?,
                Value::Object(map) => ["inputs", "custom_properties"]
                    .iter()
                    .find_map(|h| map.get(*h).and_then(|m| m.get(k.as_str())))
                    .ok_or_else(|| format!("no input or custom property {k:?}"))?,
                _ => return Err(format!("cannot look up [{k:?}] here")),
            },
            Token::Index(i) => cur
                .as_array()
                .and_then(|a| a.get(*i))
                .ok_or_else(|| format!("index {i} out of range"))?,
        };
        chain.push(cur);
    }
    Ok(chain)
}

fn is_int(v: &Value) -> bool {
    v.as_i64().is_some() && !v.is_f64()
}

/// Whether values of `d` can go into `slot`.
fn check_type(slot: &Value, d: &Dist, offset: bool) -> Result<(), String> {
    let numeric = |v: &Value| v.is_number();
    match slot {
        Value::Number(_) => {
            let int_slot = is_int(slot);
            match d {
                Dist::UniformInt { .. } => Ok(()),
                Dist::Choice { values, .. } if values.iter().all(|v| if int_slot { is_int(v) } else { numeric(v) }) => Ok(()),
                Dist::Uniform { min, .. } if min.len() == 1 && !int_slot => Ok(()),
                Dist::Normal { .. } | Dist::LogUniform { .. } if !int_slot => Ok(()),
                _ if int_slot => Err("is an integer property: use uniform_int, or choice of integers".into()),
                _ => Err("is a single number: use uniform, uniform_int, normal, log_uniform or choice of numbers".into()),
            }
        }
        Value::Bool(_) => match d {
            Dist::Choice { values, .. } if values.iter().all(Value::is_boolean) => Ok(()),
            Dist::UniformInt { min, max } if *min >= 0 && *max <= 1 => Ok(()),
            _ => Err("is a boolean: use choice of true/false or uniform_int 0..1".into()),
        },
        Value::String(_) => match d {
            Dist::Choice { values, .. } if values.iter().all(Value::is_string) && !offset => Ok(()),
            _ => Err("is a string or enum: use choice of strings".into()),
        },
        Value::Array(a) if a.iter().all(Value::is_number) => {
            let n = a.len();
            match d {
                Dist::Uniform { min, .. } if min.len() == 1 || min.len() == n => Ok(()),
                Dist::Uniform { min, .. } => Err(format!("has {n} components but min/max have {}", min.len())),
                Dist::Hsv { .. } | Dist::Color { .. } if n == 3 || n == 4 => Ok(()),
                Dist::Choice { values, .. } if values.iter().all(|v| v.as_array().is_some_and(|x| x.len() == n && x.iter().all(Value::is_number))) => Ok(()),
                Dist::UniformInt { .. } | Dist::Normal { .. } | Dist::LogUniform { .. } if offset => Ok(()),
                _ => Err(format!("is a vector/colour of {n} numbers: use uniform (one or {n} components), hsv, color, or choice of {n}-lists")),
            }
        }
        Value::Object(_) => Err("points at a structure, not a value".into()),
        _ => Err(format!("cannot randomise a {slot}")),
    }
}

/// Per component, the [low, high] the distribution can produce. Unbounded ones err.
fn support(d: &Dist) -> Result<Vec<(f64, f64)>, String> {
    Ok(match d {
        Dist::Uniform { min, max } => min.iter().zip(max).map(|(a, b)| (*a, *b)).collect(),
        Dist::UniformInt { min, max } => vec![(*min as f64, *max as f64)],
        Dist::Normal { clamp: Some(c), .. } => vec![*c],
        Dist::Normal { clamp: None, .. } => {
            return Err(
                "a normal distribution without clamp = [low, high] can leave the range".into(),
            )
        }
        Dist::LogUniform { min, max } => vec![(*min, *max)],
        Dist::Choice { values, .. } => {
            let xs: Vec<f64> = values
                .iter()
                .flat_map(|v| v.as_array().cloned().unwrap_or_else(|| vec![v.clone()]))
                .filter_map(|v| v.as_f64())
                .collect();
            if xs.is_empty() {
                return Ok(vec![]);
            }
            vec![(
                xs.iter().cloned().fold(f64::INFINITY, f64::min),
                xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
            )]
        }
        Dist::Hsv { .. } => {
            // colorsys keeps RGB within [v * (1 - s), v].
            let Dist::Hsv { s, v, .. } = d else {
                unreachable!()
            };
            vec![(v.0 * (1.0 - s.1), v.1); 3]
        }
        Dist::Color { min, max } => (0..3).map(|k| (min[k], max[k])).collect(),
    })
}

/// Blender's hard ranges of RNA properties specs commonly target, recorded from bpy by
/// `fixtures/replicate/rna_ranges.py`.
const RNA_RANGES: &str = include_str!("rna_ranges.json");

/// The hard [min, max] of the property at `path`, when known: a node-group interface
/// socket (group input, modifier input) records its own; RNA properties come from `RNA_RANGES`.
fn range_of(root: &Value, path: &str, chain: &[&Value]) -> Option<(f64, f64)> {
    let tokens = parse(path).ok()?;
    let slot_parent = chain.len().checked_sub(2).map(|i| chain[i]);
    // An interface item itself (node_groups["G"].interface[i].default_value).
    if let Some(p) = slot_parent {
        if let (Some(lo), Some(hi)) = (
            p.get("min_value").and_then(Value::as_f64),
            p.get("max_value").and_then(Value::as_f64),
        ) {
            return Some((lo, hi));
        }
    }
    // A modifier's group input: objects["O"].modifiers["M"]["Socket_2"].
    if let (Some(Token::Key(k)), Some(p)) = (tokens.last(), slot_parent) {
        if let Some(group) = p.get("node_group").and_then(Value::as_str) {
            return interface_range(root, group, k);
        }
    }
    // A node socket's default_value: group nodes take their group's interface range.
    if matches!(tokens.last(), Some(Token::Prop(p)) if p == "default_value") && chain.len() >= 4 {
        let socket = chain[chain.len() - 2];
        let node = chain[chain.len() - 4];
        if let (Some(group), Some(id)) = (
            node.get("node_tree").and_then(Value::as_str),
            socket.get("identifier").and_then(Value::as_str),
        ) {
            if let Some(r) = interface_range(root, group, id) {
                return Some(r);
            }
        }
        // Built-in nodes declare their sockets' ranges in C++ and the exporter does not
        // record them (a Factor subtype does not mean [0, 1]: Principled's Subsurface
        // IOR is a Factor in [1.01, 3.8]), so those are not checked.
        return None;
    }
    // RNA properties: match the root collection and the trailing attribute names.
    let root_name = match tokens.first() {
        Some(Token::Prop(r)) => r.as_str(),
        _ => return None,
    };
    let props: Vec<&str> = tokens
        .iter()
        .filter_map(|t| {
            if let Token::Prop(p) = t {
                Some(p.as_str())
            } else {
                None
            }
        })
        .collect();
    let table: Value = serde_json::from_str(RNA_RANGES).ok()?;
    for r in table["ranges"].as_array()? {
        let suffix: Vec<&str> = r["suffix"].as_str()?.split('.').collect();
        let root_ok = r["root"] == "*" || r["root"].as_str() == Some(root_name);
        if root_ok && props.len() > suffix.len() && props.ends_with(&suffix) {
            return Some((r["min"].as_f64()?, r["max"].as_f64()?));
        }
    }
    None
}

fn interface_range(root: &Value, group: &str, identifier: &str) -> Option<(f64, f64)> {
    let g = root["node_groups"]
        .as_array()?
        .iter()
        .find(|g| g["name"] == group)?;
    let item = g["interface"]
        .as_array()?
        .iter()
        .find(|i| i["identifier"] == identifier)?;
    Some((
        item.get("min_value")?.as_f64()?,
        item.get("max_value")?.as_f64()?,
    ))
}

/// Whether an F-curve animates the property (its override would be replaced).
fn animated(scene: &Scene, path: &str) -> Option<String> {
    for a in &scene.file.animation {
        for fc in &a.fcurves {
            let full = format!("{}.{}", a.id_path, fc.data_path);
            if path == full || path.starts_with(&format!("{full}[")) {
                return Some(format!("is animated by an F-curve ({full}[{}]); the animation replaces the drawn value", fc.array_index));
            }
        }
    }
    None
}

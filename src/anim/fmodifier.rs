//! F-curve modifiers, as Blender's `fmodifier.cc`. The stack runs twice: first the
//! time-changing modifiers from last to first (Cycles, Stepped, Limits' x range) to find
//! the time the keyframes are sampled at, then the value modifiers from first to last.
//! Each is blended by its influence and optional restricted frame range.

use super::error::AnimError;
use super::noise;
use crate::scene::{FModifier, Rna};

#[derive(Debug, Clone)]
enum Kind {
    Generator {
        factorised: bool,
        order: i32,
        coeffs: Vec<f32>,
        additive: bool,
    },
    FnGenerator {
        func: Func,
        amplitude: f32,
        phase_mult: f32,
        phase_off: f32,
        value_off: f32,
        additive: bool,
    },
    Envelope {
        mid: f32,
        min: f32,
        max: f32,
        points: Vec<[f32; 3]>,
    },
    Cycles {
        before_mode: i32,
        before_cycles: i32,
        after_mode: i32,
        after_cycles: i32,
    },
    Noise {
        size: f32,
        strength: f32,
        phase: f32,
        offset: f32,
        depth: i32,
        lacunarity: f32,
        roughness: f32,
        blend: NoiseBlend,
    },
    Limits {
        min_x: Option<f32>,
        max_x: Option<f32>,
        min_y: Option<f32>,
        max_y: Option<f32>,
    },
    Stepped {
        step: f32,
        offset: f32,
        start: Option<f32>,
        end: Option<f32>,
    },
}

#[derive(Debug, Clone, Copy)]
enum Func {
    Sin,
    Cos,
    Tan,
    Sqrt,
    Ln,
    Sinc,
}

#[derive(Debug, Clone, Copy)]
enum NoiseBlend {
    Replace,
    Add,
    Subtract,
    Multiply,
}

#[derive(Debug, Clone)]
pub struct FMod {
    kind: Kind,
    mute: bool,
    /// Blender disables a Cycles modifier that is not first in the stack.
    disabled: bool,
    range: Option<[f32; 4]>, // frame_start, frame_end, blend_in, blend_out
    influence: Option<f32>,
}

impl FMod {
    /// Curve-generating types (Blender's `FMI_TYPE_GENERATE_CURVE`) make an F-curve with no
    /// keyframes count as animated.
    pub fn generates_curve(&self) -> bool {
        matches!(
            self.kind,
            Kind::Generator { .. }
                | Kind::FnGenerator { .. }
                | Kind::Limits { .. }
                | Kind::Stepped { .. }
        )
    }

    fn in_range(&self, t: f32) -> bool {
        match self.range {
            None => true,
            Some([s, e, _, _]) => s <= t && e >= t,
        }
    }

    /// Blender's `eval_fmodifier_influence`: influence, ramped in and out at the ends of a
    /// restricted range.
    fn influence(&self, t: f32) -> f32 {
        let infl = self.influence.unwrap_or(1.0);
        if let Some([sfra, efra, blendin, blendout]) = self.range {
            if t < sfra || t > efra {
                return 0.0;
            }
            if blendin != 0.0 && t >= sfra && t <= sfra + blendin {
                let (a, b) = (sfra, sfra + blendin);
                return infl * (t - a) / (b - a);
            }
            if blendout != 0.0 && t <= efra && t >= efra - blendout {
                let (a, b) = (efra, efra - blendout);
                return infl * (t - a) / (b - a);
            }
        }
        infl
    }
}

fn prop<'a>(p: &'a Rna, key: &str) -> Result<&'a serde_json::Value, AnimError> {
    p.get(key)
        .ok_or_else(|| AnimError::new(format!("properties.{key}"), "missing"))
}
fn num(p: &Rna, key: &str) -> Result<f32, AnimError> {
    prop(p, key)?
        .as_f64()
        .map(|v| v as f32)
        .ok_or_else(|| AnimError::new(format!("properties.{key}"), "not a number"))
}
fn int(p: &Rna, key: &str) -> Result<i32, AnimError> {
    prop(p, key)?
        .as_f64()
        .map(|v| v as i32)
        .ok_or_else(|| AnimError::new(format!("properties.{key}"), "not a number"))
}
fn flag(p: &Rna, key: &str) -> Result<bool, AnimError> {
    prop(p, key)?
        .as_bool()
        .ok_or_else(|| AnimError::new(format!("properties.{key}"), "not a boolean"))
}
fn text<'a>(p: &'a Rna, key: &str) -> Result<&'a str, AnimError> {
    prop(p, key)?
        .as_str()
        .ok_or_else(|| AnimError::new(format!("properties.{key}"), "not a string"))
}
fn opt_flag(p: &Rna, key: &str) -> bool {
    p.get(key).and_then(|v| v.as_bool()).unwrap_or(false)
}

fn cycle_mode(s: &str) -> Result<i32, AnimError> {
    Ok(match s {
        "NONE" => 0,
        "REPEAT" => 1,
        "REPEAT_OFFSET" => 2,
        "MIRROR" => 3,
        other => return Err(AnimError::new("", format!("unknown cycle mode {other:?}"))),
    })
}

// Long because one arm per F-modifier type, each reading that type's settings as Blender's fcm_* functions do.
fn compile_one(m: &FModifier, first: bool) -> Result<FMod, AnimError> {
    let p = &m.properties;
    let kind = match m.kind.as_str() {
        "GENERATOR" => {
            let coeffs: Vec<f32> = prop(p, "coefficients")?
                .as_array()
                .ok_or_else(|| AnimError::new("properties.coefficients", "not a list"))?
                .iter()
                .map(|v| {
                    v.as_f64()
                        .map(|x| x as f32)
                        .ok_or_else(|| AnimError::new("properties.coefficients", "not a number"))
                })
                .collect::<Result<_, _>>()?;
            let factorised = match text(p, "mode")? {
                "POLYNOMIAL" => false,
                "POLYNOMIAL_FACTORISED" => true,
                other => {
                    return Err(AnimError::new(
                        "properties.mode",
                        format!("unknown generator mode {other:?}"),
                    ))
                }
            };
            Kind::Generator {
                factorised,
                order: int(p, "poly_order")?,
                coeffs,
                additive: flag(p, "use_additive")?,
            }
        }
        "FNGENERATOR" => {
            let func = match text(p, "function_type")? {
                "SIN" => Func::Sin,
                "COS" => Func::Cos,
                "TAN" => Func::Tan,
                "SQRT" => Func::Sqrt,
                "LN" => Func::Ln,
                "SINC" => Func::Sinc,
                other => {
                    return Err(AnimError::new(
                        "properties.function_type",
                        format!("unknown function {other:?}"),
                    ))
                }
            };
            Kind::FnGenerator {
                func,
                amplitude: num(p, "amplitude")?,
                phase_mult: num(p, "phase_multiplier")?,
                phase_off: num(p, "phase_offset")?,
                value_off: num(p, "value_offset")?,
                additive: flag(p, "use_additive")?,
            }
        }
        "ENVELOPE" => {
            let points = prop(p, "control_points")?
                .as_array()
                .ok_or_else(|| AnimError::new("properties.control_points", "not a list"))?
                .iter()
                .enumerate()
                .map(|(i, cp)| {
                    let cp = cp.as_object().ok_or_else(|| {
                        AnimError::new(format!("properties.control_points[{i}]"), "not an object")
                    })?;
                    Ok([num(cp, "frame")?, num(cp, "min")?, num(cp, "max")?])
                })
                .collect::<Result<Vec<_>, AnimError>>()?;
            Kind::Envelope {
                mid: num(p, "reference_value")?,
                min: num(p, "default_min")?,
                max: num(p, "default_max")?,
                points,
            }
        }
        "CYCLES" => Kind::Cycles {
            before_mode: cycle_mode(text(p, "mode_before")?)?,
            before_cycles: int(p, "cycles_before")?,
            after_mode: cycle_mode(text(p, "mode_after")?)?,
            after_cycles: int(p, "cycles_after")?,
        },
        "NOISE" => {
            if opt_flag(p, "use_legacy_noise") {
                // The legacy noise uses Blender's hash tables, which we do not carry.
                return Err(AnimError::new(
                    "properties.use_legacy_noise",
                    "legacy Noise modifiers are not supported; untick \"Legacy Noise\" in Blender",
                ));
            }
            let blend = match text(p, "blend_type")? {
                "REPLACE" => NoiseBlend::Replace,
                "ADD" => NoiseBlend::Add,
                "SUBTRACT" => NoiseBlend::Subtract,
                "MULTIPLY" => NoiseBlend::Multiply,
                other => {
                    return Err(AnimError::new(
                        "properties.blend_type",
                        format!("unknown blend type {other:?}"),
                    ))
                }
            };
            Kind::Noise {
                size: num(p, "scale")?,
                strength: num(p, "strength")?,
                phase: num(p, "phase")?,
                offset: num(p, "offset")?,
                depth: int(p, "depth")?,
                lacunarity: num(p, "lacunarity")?,
                roughness: num(p, "roughness")?,
                blend,
            }
        }
        "LIMITS" => {
            let lim = |use_key: &str, key: &str| -> Result<Option<f32>, AnimError> {
                Ok(if flag(p, use_key)? {
                    Some(num(p, key)?)
                } else {
                    None
                })
            };
            Kind::Limits {
                min_x: lim("use_min_x", "min_x")?,
                max_x: lim("use_max_x", "max_x")?,
                min_y: lim("use_min_y", "min_y")?,
                max_y: lim("use_max_y", "max_y")?,
            }
        }
        "STEPPED" => {
            // Stepped's own frame_start/frame_end shadow the base FModifier's restricted range
            // in RNA, so the exporter can only give us the former.
            if flag(p, "use_restricted_range")? {
                return Err(AnimError::new(
                    "properties.use_restricted_range",
                    "a Stepped modifier with a restricted frame range cannot be evaluated: its range is not exportable (RNA names clash with the step range)",
                ));
            }
            let start = if flag(p, "use_frame_start")? {
                Some(num(p, "frame_start")?)
            } else {
                None
            };
            let end = if flag(p, "use_frame_end")? {
                Some(num(p, "frame_end")?)
            } else {
                None
            };
            Kind::Stepped {
                step: num(p, "frame_step")?,
                offset: num(p, "frame_offset")?,
                start,
                end,
            }
        }
        other => {
            return Err(AnimError::new(
                "type",
                format!("F-modifier type {other:?} is not supported"),
            ))
        }
    };
    let range = if flag(p, "use_restricted_range")? {
        Some([
            num(p, "frame_start")?,
            num(p, "frame_end")?,
            num(p, "blend_in")?,
            num(p, "blend_out")?,
        ])
    } else {
        None
    };
    let influence = if flag(p, "use_influence")? {
        Some(num(p, "influence")?)
    } else {
        None
    };
    let disabled = matches!(kind, Kind::Cycles { .. }) && !first;
    Ok(FMod {
        kind,
        mute: m.mute,
        disabled,
        range,
        influence,
    })
}

pub fn compile(mods: &[FModifier]) -> Result<Vec<FMod>, AnimError> {
    mods.iter()
        .enumerate()
        .map(|(i, m)| {
            compile_one(m, i == 0).map_err(|e| e.within(&format!("modifiers[{i}] ({})", m.kind)))
        })
        .collect()
}

/// Per-evaluation state: the Cycles y-offset found in the time pass, used in the value pass.
pub struct Storage(Vec<f32>);

pub struct Stack<'a> {
    mods: &'a [FMod],
}

impl<'a> Stack<'a> {
    pub fn new(mods: &'a [FMod]) -> Self {
        Stack { mods }
    }

    /// The time at which to sample the keyframes. `first_last` are the first and last keys
    /// (x, y) when the curve has any.
    pub fn time(
        &self,
        first_last: Option<([f32; 2], [f32; 2])>,
        mut evaltime: f32,
    ) -> (f32, Storage) {
        let mut storage = Storage(vec![0.0; self.mods.len()]);
        for (i, m) in self.mods.iter().enumerate().rev() {
            if !m.in_range(evaltime) || m.mute || m.disabled {
                continue;
            }
            let nval = match &m.kind {
                Kind::Cycles { .. } => cycles_time(m, first_last, evaltime, &mut storage.0[i]),
                Kind::Limits { min_x, max_x, .. } => {
                    if min_x.is_some_and(|x| evaltime < x) {
                        min_x.unwrap()
                    } else if max_x.is_some_and(|x| evaltime > x) {
                        max_x.unwrap()
                    } else {
                        evaltime
                    }
                }
                Kind::Stepped {
                    step,
                    offset,
                    start,
                    end,
                } => {
                    if start.is_some_and(|s| evaltime < s) || end.is_some_and(|e| evaltime > e) {
                        evaltime
                    } else {
                        // Truncation toward zero, as C's int cast.
                        let block = ((evaltime - offset) / step) as i32;
                        block as f32 * step + offset
                    }
                }
                _ => continue,
            };
            let infl = m.influence(evaltime);
            evaltime = interpf(nval, evaltime, infl);
        }
        (evaltime, storage)
    }

    /// Applies the value modifiers at (modified) time `evaltime`.
    pub fn value(&self, storage: &Storage, cvalue: &mut f32, evaltime: f32) {
        for (i, m) in self.mods.iter().enumerate() {
            if !m.in_range(evaltime) || m.mute || m.disabled {
                continue;
            }
            let mut nval = *cvalue;
            match &m.kind {
                Kind::Stepped { .. } => continue,
                Kind::Cycles { .. } => nval += storage.0[i],
                Kind::Generator {
                    factorised,
                    order,
                    coeffs,
                    additive,
                } => generator(*factorised, *order, coeffs, *additive, &mut nval, evaltime),
                Kind::FnGenerator {
                    func,
                    amplitude,
                    phase_mult,
                    phase_off,
                    value_off,
                    additive,
                } => fn_generator(
                    *func,
                    *amplitude,
                    *phase_mult,
                    *phase_off,
                    *value_off,
                    *additive,
                    &mut nval,
                    evaltime,
                ),
                Kind::Envelope {
                    mid,
                    min,
                    max,
                    points,
                } => envelope(*mid, *min, *max, points, &mut nval, evaltime),
                Kind::Noise {
                    size,
                    strength,
                    phase,
                    offset,
                    depth,
                    lacunarity,
                    roughness,
                    blend,
                } => {
                    let n = noise_value(
                        *size,
                        *phase,
                        *offset,
                        *depth,
                        *lacunarity,
                        *roughness,
                        evaltime,
                    );
                    nval = match blend {
                        NoiseBlend::Add => nval + n * strength,
                        NoiseBlend::Subtract => nval - n * strength,
                        NoiseBlend::Multiply => nval * n * strength,
                        NoiseBlend::Replace => nval + (n - 0.5) * strength,
                    };
                }
                Kind::Limits { min_y, max_y, .. } => {
                    if let Some(y) = min_y {
                        if nval < *y {
                            nval = *y;
                        }
                    }
                    if let Some(y) = max_y {
                        if nval > *y {
                            nval = *y;
                        }
                    }
                }
            }
            let infl = m.influence(evaltime);
            *cvalue = interpf(nval, *cvalue, infl);
        }
    }
}

/// Blender's `interpf(target, origin, fac)`.
fn interpf(target: f32, origin: f32, fac: f32) -> f32 {
    (fac * target) + (1.0 - fac) * origin
}

fn generator(
    factorised: bool,
    order: i32,
    coeffs: &[f32],
    additive: bool,
    cvalue: &mut f32,
    t: f32,
) {
    let value = if !factorised {
        // Sum of c[i] * t^i with powers built up by repeated multiplication.
        let mut value = 0.0f32;
        let mut power = 1.0f32;
        for (i, c) in coeffs.iter().enumerate() {
            if i > 0 {
                power *= t;
            }
            value += c * power;
        }
        value
    } else {
        let mut value = 1.0f32;
        for pair in coeffs.chunks_exact(2).take(order.max(0) as usize) {
            value *= pair[0] * t + pair[1];
        }
        value
    };
    // An order-0 generator changes nothing.
    if order != 0 {
        if additive {
            *cvalue += value;
        } else {
            *cvalue = value;
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn fn_generator(
    func: Func,
    amplitude: f32,
    phase_mult: f32,
    phase_off: f32,
    value_off: f32,
    additive: bool,
    cvalue: &mut f32,
    t: f32,
) {
    let arg = (phase_mult * t + phase_off) as f64;
    let f: Option<fn(f64) -> f64> = match func {
        Func::Sin => Some(f64::sin),
        Func::Cos => Some(f64::cos),
        Func::Sinc => Some(|x: f64| {
            if x.abs() < 0.0001 {
                1.0
            } else {
                (std::f64::consts::PI * x).sin() / (std::f64::consts::PI * x)
            }
        }),
        Func::Tan => {
            // On the discontinuities Blender writes 0 (unless additive).
            if ((arg - std::f64::consts::FRAC_PI_2) % std::f64::consts::PI).abs()
                < f32::EPSILON as f64
            {
                None
            } else {
                Some(f64::tan)
            }
        }
        Func::Ln => (arg > 1.0).then_some(f64::ln as fn(f64) -> f64),
        Func::Sqrt => (arg > 0.0).then_some(f64::sqrt as fn(f64) -> f64),
    };
    match f {
        Some(f) => {
            let value = amplitude * (f(arg) as f32) + value_off;
            if additive {
                *cvalue += value;
            } else {
                *cvalue = value;
            }
        }
        None => {
            if !additive {
                *cvalue = 0.0;
            }
        }
    }
}

fn envelope(mid: f32, emin: f32, emax: f32, points: &[[f32; 3]], cvalue: &mut f32, t: f32) {
    if points.is_empty() {
        return;
    }
    let (first, last) = (points[0], points[points.len() - 1]);
    let (mut min, mut max) = (0.0f32, 0.0f32);
    if first[0] >= t {
        min = first[1];
        max = first[2];
    } else if last[0] <= t {
        min = last[1];
        max = last[2];
    } else {
        for w in points.windows(2) {
            let (p, n) = (w[0], w[1]);
            if p[0] <= t && n[0] >= t {
                let diff = n[0] - p[0];
                let afac = (t - p[0]) / diff;
                let bfac = (n[0] - t) / diff;
                min = bfac * p[1] + afac * n[1];
                max = bfac * p[2] + afac * n[2];
                break;
            }
        }
    }
    // Map the reference range [mid + emin, mid + emax] onto [min, max].
    let fac = (*cvalue - (mid + emin)) / (emax - emin);
    *cvalue = min + fac * (max - min);
}

fn cycles_time(
    m: &FMod,
    first_last: Option<([f32; 2], [f32; 2])>,
    evaltime: f32,
    cycyofs_out: &mut f32,
) -> f32 {
    let Kind::Cycles {
        before_mode,
        before_cycles,
        after_mode,
        after_cycles,
    } = m.kind
    else {
        return evaltime;
    };
    let Some((prevkey, lastkey)) = first_last else {
        return evaltime;
    };
    let (mut side, mut mode, mut cycles, mut ofs) = (0i32, 0i32, 0i32, 0.0f32);
    if evaltime < prevkey[0] {
        if before_mode != 0 {
            side = -1;
            mode = before_mode;
            cycles = before_cycles;
            ofs = prevkey[0];
        }
    } else if evaltime > lastkey[0] && after_mode != 0 {
        side = 1;
        mode = after_mode;
        cycles = after_cycles;
        ofs = lastkey[0];
    }
    if side == 0 || mode == 0 {
        return evaltime;
    }
    let cycdx = lastkey[0] - prevkey[0];
    let cycdy = lastkey[1] - prevkey[1];
    if cycdx == 0.0 {
        return evaltime;
    }
    let cycle = side as f32 * (evaltime - ofs) / cycdx;
    let cyct = (evaltime - ofs) % cycdx;
    // cycles == 0 means infinitely many.
    if cycles != 0 && cycle > cycles as f32 {
        return evaltime;
    }
    let mut cycyofs = 0.0f32;
    if mode == 2 {
        cycyofs = if side < 0 {
            ((evaltime - ofs) / cycdx).floor()
        } else {
            ((evaltime - ofs) / cycdx).ceil()
        };
        cycyofs *= cycdy;
    }
    let mut t;
    if cyct == 0.0 {
        t = if side == 1 { lastkey[0] } else { prevkey[0] };
        if mode == 3 && (cycle as i32) % 2 != 0 {
            t = if side == 1 { prevkey[0] } else { lastkey[0] };
        }
    } else if mode == 3 && ((cycle + 1.0) as i32) % 2 != 0 {
        // Mirrored cycles play backwards on odd counts.
        t = if side < 0 {
            prevkey[0] - cyct
        } else {
            lastkey[0] - cyct
        };
    } else {
        t = prevkey[0] + cyct;
    }
    if t < prevkey[0] {
        t += cycdx;
    }
    if mode == 2 {
        *cycyofs_out = cycyofs;
    }
    t
}

/// The Noise modifier's noise in [0, 1] (Blender 4.4+, non-legacy): fractal 2D Perlin
/// noise along scaled time, `phase` picking the row; time is shifted by the golden ratio so
/// integer frames do not land on the lattice, where Perlin noise is always zero. (The
/// formula was fitted to Blender 4.5's output; see the modifiers fixture.)
fn noise_value(
    size: f32,
    phase: f32,
    offset: f32,
    depth: i32,
    lacunarity: f32,
    roughness: f32,
    t: f32,
) -> f32 {
    #[allow(clippy::excessive_precision)] // Blender's literal, rounded to f32 as in C.
    const GOLDEN: f32 = 0.618_033_988_74;
    // Blender multiplies by the reciprocal size (this rounds differently from dividing).
    let x = (t - offset) * (1.0 / size) + GOLDEN;
    noise::perlin_fbm2(x, phase, depth as f32, roughness, lacunarity, true)
}

//! F-curve evaluation at a frame, as Blender's `fcurve.cc`: keyframe interpolation
//! (constant, linear, Bezier and the Penner easings), extrapolation, then the F-modifier
//! stack (`fmodifier.rs`). Blender does all of this in single precision and with exact
//! thresholds (binary-search tolerance, root range of the Bezier solve); we do the same
//! operations in `f32` so results match to the last bits, not just approximately.

use super::error::AnimError;
use super::fmodifier::{self, FMod};
use crate::scene::{FCurve, Keyframe};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Ipo {
    Constant,
    Linear,
    Bezier,
    Back,
    Bounce,
    Circ,
    Cubic,
    Elastic,
    Expo,
    Quad,
    Quart,
    Quint,
    Sine,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Ease {
    Auto,
    In,
    Out,
    InOut,
}

#[derive(Debug, Clone)]
struct Key {
    x: f32,
    y: f32,
    hl: [f32; 2],
    hr: [f32; 2],
    ipo: Ipo,
    ease: Ease,
    back: f32,
    amplitude: f32,
    period: f32,
}

/// How the animated property constrains values (Blender derives these flags from the RNA
/// property type: booleans and enums are discrete, integers are rounded).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ValueKind {
    pub discrete: bool,
    pub integer: bool,
}

impl ValueKind {
    /// The kind of property a JSON value (as the exporter writes RNA values) belongs to;
    /// None for strings (enums), which a number cannot be written back into.
    pub fn of_json(v: &serde_json::Value) -> Option<ValueKind> {
        match v {
            serde_json::Value::Bool(_) => Some(ValueKind {
                discrete: true,
                integer: true,
            }),
            serde_json::Value::Number(n) if n.is_f64() => Some(ValueKind::default()),
            serde_json::Value::Number(_) => Some(ValueKind {
                discrete: false,
                integer: true,
            }),
            _ => None,
        }
    }
}

/// An F-curve parsed once and evaluated at many frames.
#[derive(Debug, Clone)]
pub struct CompiledFCurve {
    keys: Vec<Key>,
    extrapolate_linear: bool,
    pub mute: bool,
    mods: Vec<FMod>,
    kind: ValueKind,
}

fn ipo_of(s: &str) -> Option<Ipo> {
    Some(match s {
        "CONSTANT" => Ipo::Constant,
        "LINEAR" => Ipo::Linear,
        "BEZIER" => Ipo::Bezier,
        "BACK" => Ipo::Back,
        "BOUNCE" => Ipo::Bounce,
        "CIRC" => Ipo::Circ,
        "CUBIC" => Ipo::Cubic,
        "ELASTIC" => Ipo::Elastic,
        "EXPO" => Ipo::Expo,
        "QUAD" => Ipo::Quad,
        "QUART" => Ipo::Quart,
        "QUINT" => Ipo::Quint,
        "SINE" => Ipo::Sine,
        _ => return None,
    })
}

fn key_of(k: &Keyframe, i: usize) -> Result<Key, AnimError> {
    let at = format!("keyframes[{i}]");
    let ipo = ipo_of(&k.interpolation).ok_or_else(|| {
        AnimError::new(&at, format!("unknown interpolation {:?}", k.interpolation))
    })?;
    let ease = match k.easing.as_deref().unwrap_or("AUTO") {
        "AUTO" => Ease::Auto,
        "EASE_IN" => Ease::In,
        "EASE_OUT" => Ease::Out,
        "EASE_IN_OUT" => Ease::InOut,
        other => return Err(AnimError::new(&at, format!("unknown easing {other:?}"))),
    };
    let f = |v: f64| v as f32;
    Ok(Key {
        x: f(k.co[0]),
        y: f(k.co[1]),
        hl: [f(k.handle_left[0]), f(k.handle_left[1])],
        hr: [f(k.handle_right[0]), f(k.handle_right[1])],
        ipo,
        ease,
        // Blender's defaults for keys inserted without these set.
        back: f(k.back.unwrap_or(1.70158)),
        amplitude: f(k.amplitude.unwrap_or(0.8)),
        period: f(k.period.unwrap_or(4.1)),
    })
}

impl CompiledFCurve {
    pub fn new(fc: &FCurve, kind: ValueKind) -> Result<Self, AnimError> {
        let keys = fc
            .keyframes
            .iter()
            .enumerate()
            .map(|(i, k)| key_of(k, i))
            .collect::<Result<Vec<_>, _>>()?;
        let extrapolate_linear = match fc.extrapolation.as_str() {
            "CONSTANT" => false,
            "LINEAR" => true,
            other => {
                return Err(AnimError::new(
                    "extrapolation",
                    format!("unknown extrapolation {other:?}"),
                ))
            }
        };
        let mods = fmodifier::compile(&fc.modifiers)?;
        Ok(CompiledFCurve {
            keys,
            extrapolate_linear,
            mute: fc.mute,
            mods,
            kind,
        })
    }

    /// Blender's `BKE_fcurve_is_empty`: no keys and no curve-generating modifier, so the
    /// animation system leaves the property alone.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty() && !self.mods.iter().any(|m| m.generates_curve())
    }

    /// The curve's value at `frame` (mute is the caller's business, as in Blender's
    /// `FCurve.evaluate`).
    pub fn eval(&self, frame: f32) -> f32 {
        let stack = fmodifier::Stack::new(&self.mods);
        let first_last = if self.keys.is_empty() {
            None
        } else {
            let (a, b) = (&self.keys[0], &self.keys[self.keys.len() - 1]);
            Some(([a.x, a.y], [b.x, b.y]))
        };
        let (t, storage) = stack.time(first_last, frame);
        let mut value = if self.keys.is_empty() {
            0.0
        } else {
            self.eval_keys(t)
        };
        stack.value(&storage, &mut value, t);
        if self.kind.integer {
            value = (value + 0.5).floor();
        }
        value
    }

    fn eval_keys(&self, t: f32) -> f32 {
        let k = &self.keys;
        if t <= k[0].x {
            return self.extrapolate(t, 0, 1);
        }
        let last = k.len() - 1;
        if k[last].x <= t {
            return self.extrapolate(t, last, -1);
        }
        self.interpolate(t)
    }

    fn extrapolate(&self, t: f32, end: usize, dir: isize) -> f32 {
        let e = &self.keys[end];
        if e.ipo == Ipo::Constant || !self.extrapolate_linear || self.kind.discrete {
            return e.y;
        }
        if e.ipo == Ipo::Linear {
            // Linear keys extrapolate along the line to the neighbouring key.
            if self.keys.len() == 1 {
                return e.y;
            }
            let n = &self.keys[(end as isize + dir) as usize];
            let dx = e.x - t;
            let fac = n.x - e.x;
            if fac == 0.0 {
                return e.y;
            }
            let fac = (n.y - e.y) / fac;
            return e.y - fac * dx;
        }
        // Everything else extrapolates along the outer handle.
        let h = if dir > 0 { e.hl } else { e.hr };
        let dx = e.x - t;
        let fac = e.x - h[0];
        if fac == 0.0 {
            return e.y;
        }
        let fac = (e.y - h[1]) / fac;
        e.y - fac * dx
    }

    fn interpolate(&self, t: f32) -> f32 {
        let k = &self.keys;
        let (a, exact) = binary_search(k, t, 0.0001);
        let bezt = &k[a];
        if exact {
            return bezt.y;
        }
        let prev = if a > 0 { &k[a - 1] } else { bezt };
        if (bezt.x - t).abs() < 1e-8 {
            return bezt.y;
        }
        if t < prev.x || bezt.x < t {
            return 0.0;
        }
        let begin = prev.y;
        let change = bezt.y - prev.y;
        let duration = bezt.x - prev.x;
        let time = t - prev.x;
        if prev.ipo == Ipo::Constant || self.kind.discrete || duration == 0.0 {
            return prev.y;
        }
        let (amp, per, back) = (prev.amplitude, prev.period, prev.back);
        use Ease::*;
        match prev.ipo {
            Ipo::Constant => prev.y,
            Ipo::Bezier => bezier_segment(prev, bezt, t),
            Ipo::Linear => change * time / duration + begin,
            Ipo::Back => match prev.ease {
                In => ease::back_in(time, begin, change, duration, back),
                InOut => ease::back_in_out(time, begin, change, duration, back),
                Out | Auto => ease::back_out(time, begin, change, duration, back),
            },
            Ipo::Bounce => match prev.ease {
                In => ease::bounce_in(time, begin, change, duration),
                InOut => ease::bounce_in_out(time, begin, change, duration),
                Out | Auto => ease::bounce_out(time, begin, change, duration),
            },
            Ipo::Circ => match prev.ease {
                Out => ease::circ_out(time, begin, change, duration),
                InOut => ease::circ_in_out(time, begin, change, duration),
                In | Auto => ease::circ_in(time, begin, change, duration),
            },
            Ipo::Cubic => match prev.ease {
                Out => ease::cubic_out(time, begin, change, duration),
                InOut => ease::cubic_in_out(time, begin, change, duration),
                In | Auto => ease::cubic_in(time, begin, change, duration),
            },
            Ipo::Elastic => match prev.ease {
                In => ease::elastic_in(time, begin, change, duration, amp, per),
                InOut => ease::elastic_in_out(time, begin, change, duration, amp, per),
                Out | Auto => ease::elastic_out(time, begin, change, duration, amp, per),
            },
            Ipo::Expo => match prev.ease {
                Out => ease::expo_out(time, begin, change, duration),
                InOut => ease::expo_in_out(time, begin, change, duration),
                In | Auto => ease::expo_in(time, begin, change, duration),
            },
            Ipo::Quad => match prev.ease {
                Out => ease::quad_out(time, begin, change, duration),
                InOut => ease::quad_in_out(time, begin, change, duration),
                In | Auto => ease::quad_in(time, begin, change, duration),
            },
            Ipo::Quart => match prev.ease {
                Out => ease::quart_out(time, begin, change, duration),
                InOut => ease::quart_in_out(time, begin, change, duration),
                In | Auto => ease::quart_in(time, begin, change, duration),
            },
            Ipo::Quint => match prev.ease {
                Out => ease::quint_out(time, begin, change, duration),
                InOut => ease::quint_in_out(time, begin, change, duration),
                In | Auto => ease::quint_in(time, begin, change, duration),
            },
            Ipo::Sine => match prev.ease {
                Out => ease::sine_out(time, begin, change, duration),
                InOut => ease::sine_in_out(time, begin, change, duration),
                In | Auto => ease::sine_in(time, begin, change, duration),
            },
        }
    }
}

/// Blender's keyframe binary search: the index to insert `frame` at, and whether a key
/// already sits within `threshold` of it.
fn binary_search(k: &[Key], frame: f32, threshold: f32) -> (usize, bool) {
    let eqt = |a: f32, b: f32| {
        if a > b {
            a - b <= threshold
        } else {
            b - a <= threshold
        }
    };
    let len = k.len() as isize;
    if eqt(frame, k[0].x) {
        return (0, true);
    }
    if frame < k[0].x {
        return (0, false);
    }
    let lastx = k[(len - 1) as usize].x;
    if eqt(frame, lastx) {
        return ((len - 1) as usize, true);
    }
    if frame > lastx {
        return (len as usize, false);
    }
    let (mut start, mut end) = (0isize, len);
    let maxloop = len * 2;
    let mut loops = 0;
    while start <= end && loops < maxloop {
        let mid = start + (end - start) / 2;
        let midx = k[mid as usize].x;
        if eqt(frame, midx) {
            return (mid as usize, true);
        }
        if frame > midx {
            start = mid + 1;
        } else if frame < midx {
            end = mid - 1;
        }
        loops += 1;
    }
    (start as usize, false)
}

/// Value of the Bezier segment between two keys at time `t`: handles are first limited so
/// the curve cannot loop back in time, then the cubic in x is solved for the parameter.
fn bezier_segment(prev: &Key, next: &Key, t: f32) -> f32 {
    let v1 = [prev.x, prev.y];
    let mut v2 = prev.hr;
    let mut v3 = next.hl;
    let v4 = [next.x, next.y];
    if (v1[1] - v4[1]).abs() < f32::EPSILON
        && (v2[1] - v3[1]).abs() < f32::EPSILON
        && (v3[1] - v4[1]).abs() < f32::EPSILON
    {
        return v1[1];
    }
    correct_bezpart(v1, &mut v2, &mut v3, v4);
    let mut roots = [0.0f32; 4];
    if find_zero(t, v1[0], v2[0], v3[0], v4[0], &mut roots) == 0 {
        return 0.0;
    }
    bezier_y(v1[1], v2[1], v3[1], v4[1], roots[0])
}

/// Blender's `BKE_fcurve_correct_bezpart`: a handle may not reach past the other key.
fn correct_bezpart(v1: [f32; 2], v2: &mut [f32; 2], v3: &mut [f32; 2], v4: [f32; 2]) {
    let h1 = [v1[0] - v2[0], v1[1] - v2[1]];
    let h2 = [v4[0] - v3[0], v4[1] - v3[1]];
    let len = v4[0] - v1[0];
    let len1 = h1[0].abs();
    let len2 = h2[0].abs();
    if len1 + len2 == 0.0 {
        return;
    }
    if len1 > len {
        let fac = len / len1;
        v2[0] = v1[0] - fac * h1[0];
        v2[1] = v1[1] - fac * h1[1];
    }
    if len2 > len {
        let fac = len / len2;
        v3[0] = v4[0] - fac * h2[0];
        v3[1] = v4[1] - fac * h2[1];
    }
}

fn sqrt3d(d: f64) -> f64 {
    if d == 0.0 {
        0.0
    } else if d < 0.0 {
        -((-d).ln() / 3.0).exp()
    } else {
        (d.ln() / 3.0).exp()
    }
}

/// Roots in [~0, ~1] of `c0 + c1 x + c2 x^2 + c3 x^3`, written to `o` (Blender keeps only
/// roots inside the segment, with its exact tolerances).
fn solve_cubic(c0: f64, c1: f64, c2: f64, c3: f64, o: &mut [f32; 4]) -> usize {
    let small = -1.0e-10f64 as f32;
    let ok = |v: f32| v >= small && v <= 1.000001f32;
    let mut nr = 0usize;
    if c3 != 0.0 {
        let mut a = c2 / c3;
        let b = c1 / c3;
        let c = c0 / c3;
        a /= 3.0;
        let mut p = b / 3.0 - a * a;
        let mut q = (2.0 * a * a * a - a * b + c) / 2.0;
        let d = q * q + p * p * p;
        if d > 0.0 {
            let t = d.sqrt();
            o[0] = (sqrt3d(-q + t) + sqrt3d(-q - t) - a) as f32;
            return usize::from(ok(o[0]));
        }
        if d == 0.0 {
            let t = sqrt3d(-q);
            o[0] = (2.0 * t - a) as f32;
            if ok(o[0]) {
                nr += 1;
            }
            o[nr] = (-t - a) as f32;
            return if ok(o[nr]) { nr + 1 } else { nr };
        }
        let phi = (-q / (-(p * p * p)).sqrt()).acos();
        let t = (-p).sqrt();
        p = (phi / 3.0).cos();
        q = (3.0 - 3.0 * p * p).sqrt();
        o[0] = (2.0 * t * p - a) as f32;
        if ok(o[0]) {
            nr += 1;
        }
        o[nr] = (-t * (p + q) - a) as f32;
        if ok(o[nr]) {
            nr += 1;
        }
        o[nr] = (-t * (p - q) - a) as f32;
        return if ok(o[nr]) { nr + 1 } else { nr };
    }
    let (a, b, c) = (c2, c1, c0);
    if a != 0.0 {
        let p = b * b - 4.0 * a * c;
        if p > 0.0 {
            let p = p.sqrt();
            o[0] = ((-b - p) / (2.0 * a)) as f32;
            if ok(o[0]) {
                nr += 1;
            }
            o[nr] = ((-b + p) / (2.0 * a)) as f32;
            return if ok(o[nr]) { nr + 1 } else { nr };
        }
        if p == 0.0 {
            o[0] = (-b / (2.0 * a)) as f32;
            if ok(o[0]) {
                return 1;
            }
        }
        return 0;
    }
    if b != 0.0 {
        o[0] = (-c / b) as f32;
        return usize::from(ok(o[0]));
    }
    if c == 0.0 {
        o[0] = 0.0;
        return 1;
    }
    0
}

fn find_zero(x: f32, q0: f32, q1: f32, q2: f32, q3: f32, o: &mut [f32; 4]) -> usize {
    // Coefficients are computed in float, then solved in double (as Blender does).
    let c0 = (q0 - x) as f64;
    let c1 = (3.0f32 * (q1 - q0)) as f64;
    let c2 = (3.0f32 * (q0 - 2.0f32 * q1 + q2)) as f64;
    let c3 = (q3 - q0 + 3.0f32 * (q1 - q2)) as f64;
    solve_cubic(c0, c1, c2, c3, o)
}

fn bezier_y(f1: f32, f2: f32, f3: f32, f4: f32, t: f32) -> f32 {
    let c0 = f1;
    let c1 = 3.0f32 * (f2 - f1);
    let c2 = 3.0f32 * (f1 - 2.0f32 * f2 + f3);
    let c3 = f4 - f1 + 3.0f32 * (f2 - f3);
    c0 + t * c1 + t * t * c2 + t * t * t * c3
}

/// Robert Penner's easing equations as Blender's `BLI_easing` (single precision).
mod ease {
    use std::f32::consts::{FRAC_PI_2, PI};

    pub fn back_in(time: f32, begin: f32, change: f32, duration: f32, overshoot: f32) -> f32 {
        let t = time / duration;
        change * t * t * ((overshoot + 1.0) * t - overshoot) + begin
    }
    pub fn back_out(time: f32, begin: f32, change: f32, duration: f32, overshoot: f32) -> f32 {
        let t = time / duration - 1.0;
        change * (t * t * ((overshoot + 1.0) * t + overshoot) + 1.0) + begin
    }
    pub fn back_in_out(time: f32, begin: f32, change: f32, duration: f32, overshoot: f32) -> f32 {
        let overshoot = overshoot * 1.525;
        let mut t = time / (duration / 2.0);
        if t < 1.0 {
            return change / 2.0 * (t * t * ((overshoot + 1.0) * t - overshoot)) + begin;
        }
        t -= 2.0;
        change / 2.0 * (t * t * ((overshoot + 1.0) * t + overshoot) + 2.0) + begin
    }
    pub fn bounce_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let mut t = time / duration;
        if t < 1.0 / 2.75 {
            return change * (7.5625 * t * t) + begin;
        }
        if t < 2.0 / 2.75 {
            t -= 1.5 / 2.75;
            return change * ((7.5625 * t) * t + 0.75) + begin;
        }
        if t < 2.5 / 2.75 {
            t -= 2.25 / 2.75;
            return change * ((7.5625 * t) * t + 0.9375) + begin;
        }
        t -= 2.625 / 2.75;
        change * ((7.5625 * t) * t + 0.984375) + begin
    }
    pub fn bounce_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        change - bounce_out(duration - time, 0.0, change, duration) + begin
    }
    pub fn bounce_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        if time < duration / 2.0 {
            return bounce_in(time * 2.0, 0.0, change, duration) * 0.5 + begin;
        }
        bounce_out(time * 2.0 - duration, 0.0, change, duration) * 0.5 + change * 0.5 + begin
    }
    pub fn circ_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration;
        -change * ((1.0 - t * t).sqrt() - 1.0) + begin
    }
    pub fn circ_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration - 1.0;
        change * (1.0 - t * t).sqrt() + begin
    }
    pub fn circ_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let mut t = time / (duration / 2.0);
        if t < 1.0 {
            return -change / 2.0 * ((1.0 - t * t).sqrt() - 1.0) + begin;
        }
        t -= 2.0;
        change / 2.0 * ((1.0 - t * t).sqrt() + 1.0) + begin
    }
    pub fn cubic_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration;
        change * t * t * t + begin
    }
    pub fn cubic_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration - 1.0;
        change * (t * t * t + 1.0) + begin
    }
    pub fn cubic_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let mut t = time / (duration / 2.0);
        if t < 1.0 {
            return change / 2.0 * t * t * t + begin;
        }
        t -= 2.0;
        change / 2.0 * (t * t * t + 2.0) + begin
    }

    /// Near the crossing point Blender blends the sine in when the amplitude is smaller
    /// than the change, to avoid a sharp falloff.
    fn elastic_blend(
        time: f32,
        change: f32,
        duration: f32,
        amplitude: f32,
        s: f32,
        mut f: f32,
    ) -> f32 {
        if change != 0.0 {
            let t = s.abs();
            if amplitude != 0.0 {
                f *= amplitude / change.abs();
            } else {
                f = 0.0;
            }
            if (time * duration).abs() < t {
                let l = (time * duration).abs() / t;
                f = (f * l) + (1.0 - l);
            }
        }
        f
    }

    pub fn elastic_in(
        time: f32,
        begin: f32,
        change: f32,
        duration: f32,
        mut amplitude: f32,
        mut period: f32,
    ) -> f32 {
        let mut f = 1.0f32;
        if time == 0.0 {
            return begin;
        }
        let mut t = time / duration;
        if t == 1.0 {
            return begin + change;
        }
        t -= 1.0;
        if period == 0.0 {
            period = duration * 0.3;
        }
        let s;
        if amplitude == 0.0 || amplitude < change.abs() {
            s = period / 4.0;
            f = elastic_blend(t, change, duration, amplitude, s, f);
            amplitude = change;
        } else {
            s = period / (2.0 * PI) * (change / amplitude).asin();
        }
        (-f * (amplitude * 2f32.powf(10.0 * t) * ((t * duration - s) * (2.0 * PI) / period).sin()))
            + begin
    }

    pub fn elastic_out(
        time: f32,
        begin: f32,
        change: f32,
        duration: f32,
        mut amplitude: f32,
        mut period: f32,
    ) -> f32 {
        let mut f = 1.0f32;
        if time == 0.0 {
            return begin;
        }
        let mut t = time / duration;
        if t == 1.0 {
            return begin + change;
        }
        t = -t;
        if period == 0.0 {
            period = duration * 0.3;
        }
        let s;
        if amplitude == 0.0 || amplitude < change.abs() {
            s = period / 4.0;
            f = elastic_blend(t, change, duration, amplitude, s, f);
            amplitude = change;
        } else {
            s = period / (2.0 * PI) * (change / amplitude).asin();
        }
        (f * (amplitude * 2f32.powf(10.0 * t) * ((t * duration - s) * (2.0 * PI) / period).sin()))
            + change
            + begin
    }

    pub fn elastic_in_out(
        time: f32,
        begin: f32,
        change: f32,
        duration: f32,
        mut amplitude: f32,
        mut period: f32,
    ) -> f32 {
        let mut f = 1.0f32;
        if time == 0.0 {
            return begin;
        }
        let mut t = time / (duration / 2.0);
        if t == 2.0 {
            return begin + change;
        }
        t -= 1.0;
        if period == 0.0 {
            period = duration * (0.3 * 1.5);
        }
        let s;
        if amplitude == 0.0 || amplitude < change.abs() {
            s = period / 4.0;
            f = elastic_blend(t, change, duration, amplitude, s, f);
            amplitude = change;
        } else {
            s = period / (2.0 * PI) * (change / amplitude).asin();
        }
        if t < 0.0 {
            f *= -0.5;
            return (f
                * (amplitude
                    * 2f32.powf(10.0 * t)
                    * ((t * duration - s) * (2.0 * PI) / period).sin()))
                + begin;
        }
        t = -t;
        f *= 0.5;
        (f * (amplitude * 2f32.powf(10.0 * t) * ((t * duration - s) * (2.0 * PI) / period).sin()))
            + change
            + begin
    }

    // Blender rescales the exponential so it starts and ends exactly on the keys.
    const POW_MIN: f32 = 0.0009765625;
    const POW_SCALE: f32 = 1.0 / (1.0 - 0.0009765625);

    pub fn expo_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        if time == 0.0 {
            return begin;
        }
        change * (2f32.powf(10.0 * (time / duration - 1.0)) - POW_MIN) * POW_SCALE + begin
    }
    pub fn expo_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        if time == 0.0 {
            return begin;
        }
        change * (1.0 - (2f32.powf(-10.0 * time / duration) - POW_MIN) * POW_SCALE) + begin
    }
    pub fn expo_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let dh = duration / 2.0;
        let ch = change / 2.0;
        if time <= dh {
            return expo_in(time, begin, ch, dh);
        }
        expo_out(time - dh, begin + ch, ch, dh)
    }
    pub fn quad_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration;
        change * t * t + begin
    }
    pub fn quad_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration;
        -change * t * (t - 2.0) + begin
    }
    pub fn quad_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let mut t = time / (duration / 2.0);
        if t < 1.0 {
            return change / 2.0 * t * t + begin;
        }
        t -= 1.0;
        -change / 2.0 * (t * (t - 2.0) - 1.0) + begin
    }
    pub fn quart_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration;
        change * t * t * t * t + begin
    }
    pub fn quart_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration - 1.0;
        -change * (t * t * t * t - 1.0) + begin
    }
    pub fn quart_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let mut t = time / (duration / 2.0);
        if t < 1.0 {
            return change / 2.0 * t * t * t * t + begin;
        }
        t -= 2.0;
        -change / 2.0 * (t * t * t * t - 2.0) + begin
    }
    pub fn quint_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration;
        change * t * t * t * t * t + begin
    }
    pub fn quint_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let t = time / duration - 1.0;
        change * (t * t * t * t * t + 1.0) + begin
    }
    pub fn quint_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        let mut t = time / (duration / 2.0);
        if t < 1.0 {
            return change / 2.0 * t * t * t * t * t + begin;
        }
        t -= 2.0;
        change / 2.0 * (t * t * t * t * t + 2.0) + begin
    }
    pub fn sine_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        -change * (time / duration * FRAC_PI_2).cos() + change + begin
    }
    pub fn sine_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        change * (time / duration * FRAC_PI_2).sin() + begin
    }
    pub fn sine_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
        -change / 2.0 * ((PI * time / duration).cos() - 1.0) + begin
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(x: f64, y: f64, ipo: &str) -> Keyframe {
        Keyframe {
            co: [x, y],
            handle_left: [x - 1.0, y],
            handle_right: [x + 1.0, y],
            handle_left_type: None,
            handle_right_type: None,
            interpolation: ipo.into(),
            easing: None,
            back: None,
            amplitude: None,
            period: None,
        }
    }

    #[test]
    fn linear_and_extrapolation() {
        let fc = FCurve {
            data_path: "x".into(),
            array_index: 0,
            extrapolation: "LINEAR".into(),
            mute: false,
            keyframes: vec![key(1.0, 0.0, "LINEAR"), key(11.0, 10.0, "LINEAR")],
            modifiers: vec![],
            driver: None,
        };
        let c = CompiledFCurve::new(&fc, ValueKind::default()).unwrap();
        assert_eq!(c.eval(6.0), 5.0);
        assert_eq!(c.eval(21.0), 20.0);
        assert_eq!(c.eval(-1.0), -2.0);
    }
}

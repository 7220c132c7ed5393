//! Math and Vector Math nodes, and the scalar/vector helpers the other families share.
//!
//! Semantics follow Cycles' SVM (`kernel/svm/math_util.h`, `util/math_base.h`,
//! `util/math_float3.h`): the "safe" variants that return 0 instead of NaN/inf, the
//! ternary `min`/`max` (which pick the second operand when the first is NaN), and the
//! evaluation order of every expression, so results match Cycles to the last bit or two
//! (Cycles' AVX2 kernel fuses some multiply-adds; plain Rust does not).

/// A 3-component vector or colour as a plain array (Cycles `float3`), as the node maths
/// takes and returns it (`foundation::math::Vec3` is the operator type).
pub use crate::foundation::math::V3;
// Cycles' float3 helpers under the names the node code uses (util/math_float3.h).
pub use crate::foundation::math::{
    add as add3, cross as cross3, dot as dot3, len as length3, mul as mul3, scale as scale3,
    sub as sub3,
};

// --- Scalar helpers (Cycles util/math_base.h) -------------------------------------------

/// Cycles `min(a, b)`: `a < b ? a : b`.
#[inline]
pub fn min_c(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// Cycles `max(a, b)`: `a > b ? a : b`.
#[inline]
pub fn max_c(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// Cycles `clamp(a, mn, mx)`: `min(max(a, mn), mx)`; NaN becomes `mn`.
#[inline]
pub fn clamp_c(a: f32, mn: f32, mx: f32) -> f32 {
    min_c(max_c(a, mn), mx)
}

/// Cycles `saturatef`: clamp to [0, 1].
#[inline]
pub fn saturate(a: f32) -> f32 {
    clamp_c(a, 0.0, 1.0)
}

#[inline]
pub fn fract(a: f32) -> f32 {
    a - a.floor()
}

#[inline]
pub fn safe_divide(a: f32, b: f32) -> f32 {
    if b != 0.0 {
        a / b
    } else {
        0.0
    }
}

/// C `fmodf` semantics (truncated), 0 for a zero divisor.
#[inline]
pub fn safe_modulo(a: f32, b: f32) -> f32 {
    if b != 0.0 {
        a % b
    } else {
        0.0
    }
}

/// Floored modulo (result takes the divisor's sign), 0 for a zero divisor.
#[inline]
pub fn safe_floored_modulo(a: f32, b: f32) -> f32 {
    if b != 0.0 {
        a - (a / b).floor() * b
    } else {
        0.0
    }
}

#[inline]
pub fn safe_sqrt(a: f32) -> f32 {
    max_c(a, 0.0).sqrt()
}

#[inline]
pub fn inverse_sqrt(a: f32) -> f32 {
    if a > 0.0 {
        1.0 / a.sqrt()
    } else {
        0.0
    }
}

#[inline]
pub fn safe_asin(a: f32) -> f32 {
    clamp_c(a, -1.0, 1.0).asin()
}

#[inline]
pub fn safe_acos(a: f32) -> f32 {
    clamp_c(a, -1.0, 1.0).acos()
}

/// `powf`, but 0 for a negative base with a non-integer exponent (instead of NaN).
#[inline]
pub fn safe_pow(a: f32, b: f32) -> f32 {
    // Cycles tests `b != float_to_int(b)`, a truncating int conversion.
    if a < 0.0 && b != (b as i32) as f32 {
        return 0.0;
    }
    a.powf(b)
}

/// Logarithm of `a` in base `b`; 0 when either is not positive or the base is 1.
#[inline]
pub fn safe_log(a: f32, b: f32) -> f32 {
    if a <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    safe_divide(a.ln(), b.ln())
}

/// Sign with `sign(0) = 0` (GLSL/OSL convention).
#[inline]
pub fn compatible_sign(a: f32) -> f32 {
    if a == 0.0 {
        0.0
    } else if a < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Wraps `value` into [min, max); `min` when the range is empty. Note Blender's argument
/// order: (value, max, min).
#[inline]
pub fn wrap(value: f32, max: f32, min: f32) -> f32 {
    let range = max - min;
    if range != 0.0 {
        value - range * ((value - min) / range).floor()
    } else {
        min
    }
}

/// Ping-pong of `a` between 0 and `b`; 0 when `b` is 0.
#[inline]
pub fn pingpong(a: f32, b: f32) -> f32 {
    if b != 0.0 {
        (fract((a - b) / (b * 2.0)) * b * 2.0 - b).abs()
    } else {
        0.0
    }
}

/// Polynomial smooth minimum with blend distance `k`.
#[inline]
pub fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
    if k != 0.0 {
        let h = max_c(k - (a - b).abs(), 0.0) / k;
        a.min(b) - h * h * h * k * (1.0 / 6.0)
    } else {
        a.min(b)
    }
}

// --- Math node --------------------------------------------------------------------------

blender_enum! {
    /// `ShaderNodeMath.operation`.
    pub enum MathOp {
        Add = "ADD",
        Subtract = "SUBTRACT",
        Multiply = "MULTIPLY",
        Divide = "DIVIDE",
        MultiplyAdd = "MULTIPLY_ADD",
        Power = "POWER",
        Logarithm = "LOGARITHM",
        Sqrt = "SQRT",
        InverseSqrt = "INVERSE_SQRT",
        Absolute = "ABSOLUTE",
        Exponent = "EXPONENT",
        Minimum = "MINIMUM",
        Maximum = "MAXIMUM",
        LessThan = "LESS_THAN",
        GreaterThan = "GREATER_THAN",
        Sign = "SIGN",
        Compare = "COMPARE",
        SmoothMin = "SMOOTH_MIN",
        SmoothMax = "SMOOTH_MAX",
        Round = "ROUND",
        Floor = "FLOOR",
        Ceil = "CEIL",
        Trunc = "TRUNC",
        Fract = "FRACT",
        Modulo = "MODULO",
        FlooredModulo = "FLOORED_MODULO",
        Wrap = "WRAP",
        Snap = "SNAP",
        PingPong = "PINGPONG",
        Sine = "SINE",
        Cosine = "COSINE",
        Tangent = "TANGENT",
        Arcsine = "ARCSINE",
        Arccosine = "ARCCOSINE",
        Arctangent = "ARCTANGENT",
        Arctan2 = "ARCTAN2",
        Sinh = "SINH",
        Cosh = "COSH",
        Tanh = "TANH",
        Radians = "RADIANS",
        Degrees = "DEGREES",
    }
}

/// The Math node's operation on its three inputs (unused inputs are ignored).
pub fn math(op: MathOp, a: f32, b: f32, c: f32) -> f32 {
    use MathOp::*;
    match op {
        Add => a + b,
        Subtract => a - b,
        Multiply => a * b,
        Divide => safe_divide(a, b),
        MultiplyAdd => a * b + c,
        Power => safe_pow(a, b),
        Logarithm => safe_log(a, b),
        Sqrt => safe_sqrt(a),
        InverseSqrt => inverse_sqrt(a),
        Absolute => a.abs(),
        Exponent => a.exp(),
        Minimum => a.min(b),
        Maximum => a.max(b),
        LessThan => (a < b) as u8 as f32,
        GreaterThan => (a > b) as u8 as f32,
        Sign => compatible_sign(a),
        Compare => ((a == b) || (a - b).abs() <= c.max(f32::EPSILON)) as u8 as f32,
        SmoothMin => smooth_min(a, b, c),
        SmoothMax => -smooth_min(-a, -b, c),
        Round => (a + 0.5).floor(),
        Floor => a.floor(),
        Ceil => a.ceil(),
        Trunc => {
            if a >= 0.0 {
                a.floor()
            } else {
                a.ceil()
            }
        }
        Fract => fract(a),
        Modulo => safe_modulo(a, b),
        FlooredModulo => safe_floored_modulo(a, b),
        Wrap => wrap(a, b, c),
        Snap => safe_divide(a, b).floor() * b,
        PingPong => pingpong(a, b),
        Sine => a.sin(),
        Cosine => a.cos(),
        Tangent => a.tan(),
        Arcsine => safe_asin(a),
        Arccosine => safe_acos(a),
        Arctangent => a.atan(),
        // atan2(0, 0) is 0 (Cycles makes it explicit; libm agrees).
        Arctan2 => {
            if a == 0.0 && b == 0.0 {
                0.0
            } else {
                a.atan2(b)
            }
        }
        Sinh => a.sinh(),
        Cosh => a.cosh(),
        Tanh => a.tanh(),
        Radians => a * (std::f32::consts::PI / 180.0),
        Degrees => a * (180.0 / std::f32::consts::PI),
    }
}

/// The Math node with its "Clamp" option (Cycles appends a [0, 1] Clamp node).
pub fn math_node(op: MathOp, use_clamp: bool, a: f32, b: f32, c: f32) -> f32 {
    let r = math(op, a, b, c);
    if use_clamp {
        saturate(r)
    } else {
        r
    }
}

// --- Vector helpers (Cycles util/math_float3.h) -----------------------------------------

#[inline]
pub fn map3(a: V3, f: impl Fn(f32) -> f32) -> V3 {
    [f(a[0]), f(a[1]), f(a[2])]
}

#[inline]
pub fn zip3(a: V3, b: V3, f: impl Fn(f32, f32) -> f32) -> V3 {
    [f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2])]
}

/// Unit vector; a zero vector stays zero.
#[inline]
pub fn safe_normalize3(a: V3) -> V3 {
    let t = length3(a);
    if t != 0.0 {
        scale3(a, 1.0 / t)
    } else {
        a
    }
}

/// Unit vector, NaN for a zero vector (Cycles `normalize`, true division per component).
#[inline]
pub fn normalize3(a: V3) -> V3 {
    let t = length3(a);
    [a[0] / t, a[1] / t, a[2] / t]
}

/// Cycles `saturate(float3)`.
#[inline]
pub fn saturate3(a: V3) -> V3 {
    map3(a, saturate)
}

/// Cycles `interp(a, b, t)`: `a + t * (b - a)`.
#[inline]
pub fn interp3(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}

fn project3(v: V3, onto: V3) -> V3 {
    let len_squared = dot3(onto, onto);
    if len_squared != 0.0 {
        scale3(onto, dot3(v, onto) / len_squared)
    } else {
        [0.0; 3]
    }
}

fn reflect3(incident: V3, unit_normal: V3) -> V3 {
    let d = dot3(incident, unit_normal);
    let n2 = scale3(unit_normal, 2.0);
    sub3(incident, scale3(n2, d))
}

fn refract3(incident: V3, normal: V3, eta: f32) -> V3 {
    let d = dot3(normal, incident);
    let k = 1.0 - eta * eta * (1.0 - d * d);
    if k < 0.0 {
        return [0.0; 3];
    }
    let s = eta * d + k.sqrt();
    sub3(scale3(incident, eta), scale3(normal, s))
}

// --- Vector Math node -------------------------------------------------------------------

blender_enum! {
    /// `ShaderNodeVectorMath.operation`.
    pub enum VectorMathOp {
        Add = "ADD",
        Subtract = "SUBTRACT",
        Multiply = "MULTIPLY",
        Divide = "DIVIDE",
        MultiplyAdd = "MULTIPLY_ADD",
        CrossProduct = "CROSS_PRODUCT",
        Project = "PROJECT",
        Reflect = "REFLECT",
        Refract = "REFRACT",
        Faceforward = "FACEFORWARD",
        DotProduct = "DOT_PRODUCT",
        Distance = "DISTANCE",
        Length = "LENGTH",
        Scale = "SCALE",
        Normalize = "NORMALIZE",
        Absolute = "ABSOLUTE",
        Power = "POWER",
        Sign = "SIGN",
        Minimum = "MINIMUM",
        Maximum = "MAXIMUM",
        Floor = "FLOOR",
        Ceil = "CEIL",
        Fraction = "FRACTION",
        Modulo = "MODULO",
        Wrap = "WRAP",
        Snap = "SNAP",
        Sine = "SINE",
        Cosine = "COSINE",
        Tangent = "TANGENT",
    }
}

impl VectorMathOp {
    /// Whether the operation's result is the "Value" output (otherwise "Vector").
    pub fn outputs_value(self) -> bool {
        matches!(
            self,
            VectorMathOp::DotProduct | VectorMathOp::Distance | VectorMathOp::Length
        )
    }
}

/// The two outputs of the Vector Math node. Only the one the operation produces is
/// meaningful (Blender hides the other); it is returned as zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VectorMathResult {
    pub vector: V3,
    pub value: f32,
}

/// The Vector Math node: inputs A, B, C (`Vector`, `Vector_001`, `Vector_002`) and the
/// float `Scale` (also the IOR of Refract).
pub fn vector_math(op: VectorMathOp, a: V3, b: V3, c: V3, scale: f32) -> VectorMathResult {
    use VectorMathOp::*;
    let v = |vector| VectorMathResult { vector, value: 0.0 };
    let s = |value| VectorMathResult {
        vector: [0.0; 3],
        value,
    };
    match op {
        Add => v(add3(a, b)),
        Subtract => v(sub3(a, b)),
        Multiply => v(mul3(a, b)),
        Divide => v(zip3(a, b, safe_divide)),
        MultiplyAdd => v(add3(mul3(a, b), c)),
        CrossProduct => v(cross3(a, b)),
        Project => v(project3(a, b)),
        Reflect => v(reflect3(a, safe_normalize3(b))),
        Refract => v(refract3(a, safe_normalize3(b), scale)),
        Faceforward => v(if dot3(c, b) < 0.0 { a } else { map3(a, |x| -x) }),
        DotProduct => s(dot3(a, b)),
        Distance => s(length3(sub3(a, b))),
        Length => s(length3(a)),
        Scale => v(scale3(a, scale)),
        Normalize => v(safe_normalize3(a)),
        Absolute => v(map3(a, f32::abs)),
        Power => v(zip3(a, b, safe_pow)),
        Sign => v(map3(a, compatible_sign)),
        Minimum => v(zip3(a, b, min_c)),
        Maximum => v(zip3(a, b, max_c)),
        Floor => v(map3(a, f32::floor)),
        Ceil => v(map3(a, f32::ceil)),
        Fraction => v(map3(a, fract)),
        Modulo => v(zip3(a, b, safe_modulo)),
        Wrap => v([
            wrap(a[0], b[0], c[0]),
            wrap(a[1], b[1], c[1]),
            wrap(a[2], b[2], c[2]),
        ]),
        Snap => v(mul3(map3(zip3(a, b, safe_divide), f32::floor), b)),
        Sine => v(map3(a, f32::sin)),
        Cosine => v(map3(a, f32::cos)),
        Tangent => v(map3(a, f32::tan)),
    }
}

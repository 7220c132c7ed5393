//! Attribute domains, Blender's attribute data types, single values and typed arrays, with
//! Blender's implicit conversions between types (`type_conversions.cc`).

use super::math::{euler_to_quat, quat_to_euler, quat_to_mat4, Mat4f};

/// Where attribute values live.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Domain {
    Point,
    Edge,
    Face,
    Corner,
    Curve,
    Instance,
    Layer,
}

impl Domain {
    pub fn parse(s: &str) -> Option<Domain> {
        Some(match s {
            "POINT" => Domain::Point,
            "EDGE" => Domain::Edge,
            "FACE" => Domain::Face,
            "CORNER" => Domain::Corner,
            "CURVE" => Domain::Curve,
            "INSTANCE" => Domain::Instance,
            "LAYER" => Domain::Layer,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            Domain::Point => "POINT",
            Domain::Edge => "EDGE",
            Domain::Face => "FACE",
            Domain::Corner => "CORNER",
            Domain::Curve => "CURVE",
            Domain::Instance => "INSTANCE",
            Domain::Layer => "LAYER",
        }
    }
    /// Blender's order of mesh domains when picking the "highest" of several
    /// (`attribute_domain_highest_priority`): corner > face > edge > point.
    pub fn priority(self) -> u8 {
        match self {
            Domain::Point => 0,
            Domain::Edge => 1,
            Domain::Face => 2,
            Domain::Corner => 3,
            Domain::Curve => 1,
            Domain::Instance => 4,
            Domain::Layer => 5,
        }
    }
}

/// Blender's attribute data types (`eCustomDataType` as RNA names them). Field values use
/// Float, Int, Bool, Vector, Color, Quaternion (rotation sockets) and Matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataType {
    Float,
    Int,
    Bool,
    Float2,
    Vector,
    Color,
    ByteColor,
    Quaternion,
    Matrix,
    Int8,
    Int2,
}

impl DataType {
    pub fn parse(s: &str) -> Option<DataType> {
        Some(match s {
            "FLOAT" => DataType::Float,
            "INT" => DataType::Int,
            "BOOLEAN" => DataType::Bool,
            "FLOAT2" => DataType::Float2,
            "FLOAT_VECTOR" => DataType::Vector,
            "FLOAT_COLOR" => DataType::Color,
            "BYTE_COLOR" => DataType::ByteColor,
            "QUATERNION" => DataType::Quaternion,
            "FLOAT4X4" => DataType::Matrix,
            "INT8" => DataType::Int8,
            "INT32_2D" => DataType::Int2,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            DataType::Float => "FLOAT",
            DataType::Int => "INT",
            DataType::Bool => "BOOLEAN",
            DataType::Float2 => "FLOAT2",
            DataType::Vector => "FLOAT_VECTOR",
            DataType::Color => "FLOAT_COLOR",
            DataType::ByteColor => "BYTE_COLOR",
            DataType::Quaternion => "QUATERNION",
            DataType::Matrix => "FLOAT4X4",
            DataType::Int8 => "INT8",
            DataType::Int2 => "INT32_2D",
        }
    }
    /// The socket type of a field with values of this type (`NodeSocket.type`).
    pub fn from_socket(kind: &str) -> Option<DataType> {
        Some(match kind {
            "VALUE" => DataType::Float,
            "INT" => DataType::Int,
            "BOOLEAN" => DataType::Bool,
            "VECTOR" => DataType::Vector,
            "RGBA" => DataType::Color,
            "ROTATION" => DataType::Quaternion,
            "MATRIX" => DataType::Matrix,
            _ => return None,
        })
    }
    /// The type a field of this attribute type is read as (sockets have no FLOAT2 etc.).
    pub fn socket_type(self) -> DataType {
        match self {
            DataType::Float2 => DataType::Vector,
            DataType::ByteColor => DataType::Color,
            DataType::Int8 => DataType::Int,
            DataType::Int2 => DataType::Vector,
            t => t,
        }
    }
    /// Blender's order when joining attributes of different types
    /// (`attribute_data_type_highest_complexity`): the most complex type wins.
    pub fn complexity(self) -> u8 {
        match self {
            DataType::Bool => 0,
            DataType::Int8 => 1,
            DataType::Int => 2,
            DataType::Int2 => 3,
            DataType::Float => 4,
            DataType::Float2 => 5,
            DataType::Vector => 6,
            DataType::ByteColor => 7,
            DataType::Quaternion => 8,
            DataType::Color => 9,
            DataType::Matrix => 10,
        }
    }
}

/// One value of a data type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    Float(f32),
    Int(i32),
    Bool(bool),
    Float2([f32; 2]),
    Vector([f32; 3]),
    Color([f32; 4]),
    /// Stored linear, as the exporter writes byte colours.
    ByteColor([f32; 4]),
    /// (w, x, y, z)
    Quaternion([f32; 4]),
    /// Column-major.
    Matrix(Mat4f),
    Int8(i8),
    Int2([i32; 2]),
}

pub const IDENTITY_QUAT: [f32; 4] = [1.0, 0.0, 0.0, 0.0];

impl Value {
    pub fn data_type(&self) -> DataType {
        match self {
            Value::Float(_) => DataType::Float,
            Value::Int(_) => DataType::Int,
            Value::Bool(_) => DataType::Bool,
            Value::Float2(_) => DataType::Float2,
            Value::Vector(_) => DataType::Vector,
            Value::Color(_) => DataType::Color,
            Value::ByteColor(_) => DataType::ByteColor,
            Value::Quaternion(_) => DataType::Quaternion,
            Value::Matrix(_) => DataType::Matrix,
            Value::Int8(_) => DataType::Int8,
            Value::Int2(_) => DataType::Int2,
        }
    }
    /// The type's default value (zero; identity for rotations and matrices).
    pub fn zero(t: DataType) -> Value {
        match t {
            DataType::Float => Value::Float(0.0),
            DataType::Int => Value::Int(0),
            DataType::Bool => Value::Bool(false),
            DataType::Float2 => Value::Float2([0.0; 2]),
            DataType::Vector => Value::Vector([0.0; 3]),
            DataType::Color => Value::Color([0.0; 4]),
            DataType::ByteColor => Value::ByteColor([0.0; 4]),
            DataType::Quaternion => Value::Quaternion(IDENTITY_QUAT),
            DataType::Matrix => Value::Matrix(super::math::MAT4_IDENTITY),
            DataType::Int8 => Value::Int8(0),
            DataType::Int2 => Value::Int2([0; 2]),
        }
    }

    pub fn as_float(&self) -> f32 {
        match self.convert(DataType::Float) {
            Value::Float(f) => f,
            _ => unreachable!(),
        }
    }
    pub fn as_int(&self) -> i32 {
        match self.convert(DataType::Int) {
            Value::Int(f) => f,
            _ => unreachable!(),
        }
    }
    pub fn as_bool(&self) -> bool {
        match self.convert(DataType::Bool) {
            Value::Bool(f) => f,
            _ => unreachable!(),
        }
    }
    pub fn as_vector(&self) -> [f32; 3] {
        match self.convert(DataType::Vector) {
            Value::Vector(f) => f,
            _ => unreachable!(),
        }
    }
    pub fn as_color(&self) -> [f32; 4] {
        match self.convert(DataType::Color) {
            Value::Color(f) => f,
            _ => unreachable!(),
        }
    }
    pub fn as_quat(&self) -> [f32; 4] {
        match self.convert(DataType::Quaternion) {
            Value::Quaternion(f) => f,
            _ => unreachable!(),
        }
    }
    pub fn as_matrix(&self) -> Mat4f {
        match self.convert(DataType::Matrix) {
            Value::Matrix(f) => f,
            _ => unreachable!(),
        }
    }

    /// Whether Blender converts this type to `to` implicitly (else the link is invalid
    /// and the consumer sees its default).
    pub fn can_convert(from: DataType, to: DataType) -> bool {
        use DataType::*;
        if from == to {
            return true;
        }
        match (from, to) {
            (Matrix, Quaternion) => true,
            (Matrix, _) | (_, Matrix) if !(from == Quaternion && to == Matrix) => false,
            (Quaternion, Vector) | (Quaternion, Matrix) => true,
            (Quaternion, _) => false,
            (Float | Float2 | Vector, Quaternion) => true,
            (_, Quaternion) => false,
            _ => true,
        }
    }

    /// Blender's implicit conversion (`type_conversions.cc`).
    pub fn convert(&self, to: DataType) -> Value {
        use DataType as T;
        if self.data_type() == to {
            return *self;
        }
        if to == T::ByteColor {
            // Byte colours are stored as 8-bit sRGB (`color::encode`); reading one back
            // gives the decoded linear value.
            let c = self.convert(T::Color).as_color();
            return Value::ByteColor(byte_color_roundtrip(c));
        }
        // BLI `rgb_to_grayscale`: fixed Rec.709 weights, not the colour config's.
        let lum = |c: [f32; 4]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        match *self {
            Value::Float(a) => match to {
                T::Int => Value::Int(a as i32),
                T::Bool => Value::Bool(a > 0.0),
                T::Float2 => Value::Float2([a; 2]),
                T::Vector => Value::Vector([a; 3]),
                T::Color => Value::Color([a, a, a, 1.0]),
                T::ByteColor => Value::ByteColor([a, a, a, 1.0]),
                T::Quaternion => Value::Quaternion(euler_to_quat([a; 3])),
                T::Int8 => Value::Int8(a.clamp(-128.0, 127.0) as i8),
                T::Int2 => Value::Int2([a as i32; 2]),
                _ => Value::zero(to),
            },
            Value::Int(a) => match to {
                T::Float => Value::Float(a as f32),
                T::Bool => Value::Bool(a > 0),
                T::Float2 => Value::Float2([a as f32; 2]),
                T::Vector => Value::Vector([a as f32; 3]),
                T::Color => Value::Color([a as f32, a as f32, a as f32, 1.0]),
                T::ByteColor => Value::ByteColor([a as f32, a as f32, a as f32, 1.0]),
                T::Int8 => Value::Int8(a.clamp(-128, 127) as i8),
                T::Int2 => Value::Int2([a; 2]),
                _ => Value::zero(to),
            },
            Value::Bool(a) => {
                let f = if a { 1.0 } else { 0.0 };
                match to {
                    T::Float => Value::Float(f),
                    T::Int => Value::Int(a as i32),
                    T::Float2 => Value::Float2([f; 2]),
                    T::Vector => Value::Vector([f; 3]),
                    T::Color => Value::Color([f, f, f, 1.0]),
                    T::ByteColor => Value::ByteColor([f, f, f, 1.0]),
                    T::Int8 => Value::Int8(a as i8),
                    T::Int2 => Value::Int2([a as i32; 2]),
                    _ => Value::zero(to),
                }
            }
            Value::Float2(a) => match to {
                T::Float => Value::Float((a[0] + a[1]) / 2.0),
                T::Int => Value::Int(((a[0] + a[1]) / 2.0) as i32),
                T::Bool => Value::Bool(a != [0.0, 0.0]),
                T::Vector => Value::Vector([a[0], a[1], 0.0]),
                T::Color => Value::Color([a[0], a[1], 0.0, 1.0]),
                T::ByteColor => Value::ByteColor([a[0], a[1], 0.0, 1.0]),
                T::Quaternion => Value::Quaternion(euler_to_quat([a[0], a[1], 0.0])),
                T::Int8 => Value::Int8(((a[0] + a[1]) / 2.0).clamp(-128.0, 127.0) as i8),
                T::Int2 => Value::Int2([a[0] as i32, a[1] as i32]),
                _ => Value::zero(to),
            },
            Value::Vector(a) => match to {
                T::Float => Value::Float((a[0] + a[1] + a[2]) / 3.0),
                T::Int => Value::Int(((a[0] + a[1] + a[2]) / 3.0) as i32),
                T::Bool => Value::Bool(a != [0.0; 3]),
                T::Float2 => Value::Float2([a[0], a[1]]),
                T::Color => Value::Color([a[0], a[1], a[2], 1.0]),
                T::ByteColor => Value::ByteColor([a[0], a[1], a[2], 1.0]),
                T::Quaternion => Value::Quaternion(euler_to_quat(a)),
                T::Int8 => Value::Int8(((a[0] + a[1] + a[2]) / 3.0).clamp(-128.0, 127.0) as i8),
                T::Int2 => Value::Int2([a[0] as i32, a[1] as i32]),
                _ => Value::zero(to),
            },
            Value::Color(c) | Value::ByteColor(c) => match to {
                T::Float => Value::Float(lum(c)),
                T::Int => Value::Int(lum(c) as i32),
                T::Bool => Value::Bool(lum(c) > 0.0),
                T::Float2 => Value::Float2([c[0], c[1]]),
                T::Vector => Value::Vector([c[0], c[1], c[2]]),
                T::Color => Value::Color(c),
                T::ByteColor => Value::ByteColor(c),
                T::Int8 => Value::Int8((lum(c) as i32).clamp(-128, 127) as i8),
                T::Int2 => Value::Int2([c[0] as i32, c[1] as i32]),
                _ => Value::zero(to),
            },
            Value::Quaternion(q) => match to {
                T::Vector => Value::Vector(quat_to_euler(q)),
                T::Matrix => Value::Matrix(quat_to_mat4(q)),
                _ => Value::zero(to),
            },
            Value::Matrix(m) => match to {
                T::Quaternion => Value::Quaternion(super::math::mat4_to_quat_normalized(&m)),
                _ => Value::zero(to),
            },
            Value::Int8(a) => Value::Int(a as i32).convert(to),
            Value::Int2(a) => match to {
                T::Int => Value::Int(((a[0] as i64 + a[1] as i64) / 2) as i32),
                T::Float => Value::Float((a[0] as f32 + a[1] as f32) / 2.0),
                T::Float2 => Value::Float2([a[0] as f32, a[1] as f32]),
                T::Vector => Value::Vector([a[0] as f32, a[1] as f32, 0.0]),
                T::Bool => Value::Bool(a != [0, 0]),
                T::Color => Value::Color([a[0] as f32, a[1] as f32, 0.0, 1.0]),
                T::ByteColor => Value::ByteColor([a[0] as f32, a[1] as f32, 0.0, 1.0]),
                T::Int8 => {
                    Value::Int8((((a[0] as i64 + a[1] as i64) / 2) as i32).clamp(-128, 127) as i8)
                }
                _ => Value::zero(to),
            },
        }
    }
}

fn linear_to_srgb(c: f32) -> f32 {
    if c < 0.003_130_8 {
        if c < 0.0 {
            0.0
        } else {
            c * 12.92
        }
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn srgb_to_linear(c: f32) -> f32 {
    if c < 0.04045 {
        if c < 0.0 {
            0.0
        } else {
            c * (1.0 / 12.92)
        }
    } else {
        ((c + 0.055) * (1.0 / 1.055)).powf(2.4)
    }
}

/// Blender's `unit_float_to_uchar_clamp`.
pub(crate) fn unit_to_byte(f: f32) -> u8 {
    if f <= 0.0 {
        0
    } else if f > 1.0 - 0.5 / 255.0 {
        255
    } else {
        (255.0 * f + 0.5) as u8
    }
}

/// A linear colour as it comes back from a BYTE_COLOR attribute: RGB encoded to 8-bit
/// sRGB, alpha to 8-bit linear, then decoded.
pub fn byte_color_roundtrip(c: [f32; 4]) -> [f32; 4] {
    let rgb = |x: f32| srgb_to_linear(unit_to_byte(linear_to_srgb(x)) as f32 / 255.0);
    [
        rgb(c[0]),
        rgb(c[1]),
        rgb(c[2]),
        unit_to_byte(c[3]) as f32 / 255.0,
    ]
}

/// Values of one type, one per domain element.
#[derive(Debug, Clone, PartialEq)]
pub enum Array {
    Float(Vec<f32>),
    Int(Vec<i32>),
    Bool(Vec<bool>),
    Float2(Vec<[f32; 2]>),
    Vector(Vec<[f32; 3]>),
    Color(Vec<[f32; 4]>),
    ByteColor(Vec<[f32; 4]>),
    Quaternion(Vec<[f32; 4]>),
    Matrix(Vec<Mat4f>),
    Int8(Vec<i8>),
    Int2(Vec<[i32; 2]>),
}

macro_rules! each_array {
    ($a:expr, $v:ident => $body:expr) => {
        match $a {
            Array::Float($v) => $body,
            Array::Int($v) => $body,
            Array::Bool($v) => $body,
            Array::Float2($v) => $body,
            Array::Vector($v) => $body,
            Array::Color($v) => $body,
            Array::ByteColor($v) => $body,
            Array::Quaternion($v) => $body,
            Array::Matrix($v) => $body,
            Array::Int8($v) => $body,
            Array::Int2($v) => $body,
        }
    };
}

macro_rules! map_array {
    ($a:expr, $v:ident => $body:expr) => {
        match $a {
            Array::Float($v) => Array::Float($body),
            Array::Int($v) => Array::Int($body),
            Array::Bool($v) => Array::Bool($body),
            Array::Float2($v) => Array::Float2($body),
            Array::Vector($v) => Array::Vector($body),
            Array::Color($v) => Array::Color($body),
            Array::ByteColor($v) => Array::ByteColor($body),
            Array::Quaternion($v) => Array::Quaternion($body),
            Array::Matrix($v) => Array::Matrix($body),
            Array::Int8($v) => Array::Int8($body),
            Array::Int2($v) => Array::Int2($body),
        }
    };
}

impl Array {
    pub fn data_type(&self) -> DataType {
        match self {
            Array::Float(_) => DataType::Float,
            Array::Int(_) => DataType::Int,
            Array::Bool(_) => DataType::Bool,
            Array::Float2(_) => DataType::Float2,
            Array::Vector(_) => DataType::Vector,
            Array::Color(_) => DataType::Color,
            Array::ByteColor(_) => DataType::ByteColor,
            Array::Quaternion(_) => DataType::Quaternion,
            Array::Matrix(_) => DataType::Matrix,
            Array::Int8(_) => DataType::Int8,
            Array::Int2(_) => DataType::Int2,
        }
    }
    pub fn len(&self) -> usize {
        each_array!(self, v => v.len())
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// `n` copies of `v`.
    pub fn filled(v: Value, n: usize) -> Array {
        match v {
            Value::Float(x) => Array::Float(vec![x; n]),
            Value::Int(x) => Array::Int(vec![x; n]),
            Value::Bool(x) => Array::Bool(vec![x; n]),
            Value::Float2(x) => Array::Float2(vec![x; n]),
            Value::Vector(x) => Array::Vector(vec![x; n]),
            Value::Color(x) => Array::Color(vec![x; n]),
            Value::ByteColor(x) => Array::ByteColor(vec![x; n]),
            Value::Quaternion(x) => Array::Quaternion(vec![x; n]),
            Value::Matrix(x) => Array::Matrix(vec![x; n]),
            Value::Int8(x) => Array::Int8(vec![x; n]),
            Value::Int2(x) => Array::Int2(vec![x; n]),
        }
    }
    pub fn zeros(t: DataType, n: usize) -> Array {
        Array::filled(Value::zero(t), n)
    }
    pub fn get(&self, i: usize) -> Value {
        match self {
            Array::Float(v) => Value::Float(v[i]),
            Array::Int(v) => Value::Int(v[i]),
            Array::Bool(v) => Value::Bool(v[i]),
            Array::Float2(v) => Value::Float2(v[i]),
            Array::Vector(v) => Value::Vector(v[i]),
            Array::Color(v) => Value::Color(v[i]),
            Array::ByteColor(v) => Value::ByteColor(v[i]),
            Array::Quaternion(v) => Value::Quaternion(v[i]),
            Array::Matrix(v) => Value::Matrix(v[i]),
            Array::Int8(v) => Value::Int8(v[i]),
            Array::Int2(v) => Value::Int2(v[i]),
        }
    }
    /// Sets element `i`, converting `v` to the array's type.
    pub fn set(&mut self, i: usize, v: Value) {
        let v = v.convert(self.data_type());
        match (self, v) {
            (Array::Float(a), Value::Float(x)) => a[i] = x,
            (Array::Int(a), Value::Int(x)) => a[i] = x,
            (Array::Bool(a), Value::Bool(x)) => a[i] = x,
            (Array::Float2(a), Value::Float2(x)) => a[i] = x,
            (Array::Vector(a), Value::Vector(x)) => a[i] = x,
            (Array::Color(a), Value::Color(x)) => a[i] = x,
            (Array::ByteColor(a), Value::ByteColor(x)) => a[i] = x,
            (Array::Quaternion(a), Value::Quaternion(x)) => a[i] = x,
            (Array::Matrix(a), Value::Matrix(x)) => a[i] = x,
            (Array::Int8(a), Value::Int8(x)) => a[i] = x,
            (Array::Int2(a), Value::Int2(x)) => a[i] = x,
            _ => unreachable!("convert returns the array's type"),
        }
    }
    /// Converts every element (Blender's implicit conversions).
    pub fn convert(&self, to: DataType) -> Array {
        if self.data_type() == to {
            return self.clone();
        }
        let n = self.len();
        let mut out = Array::zeros(to, n);
        for i in 0..n {
            out.set(i, self.get(i));
        }
        out
    }
    /// Elements at `indices`, in that order.
    pub fn gather(&self, indices: &[usize]) -> Array {
        map_array!(self, v => indices.iter().map(|&i| v[i]).collect())
    }
    /// Appends `other` (converted to this type).
    pub fn extend(&mut self, other: &Array) {
        let other = other.convert(self.data_type());
        match (self, &other) {
            (Array::Float(a), Array::Float(b)) => a.extend_from_slice(b),
            (Array::Int(a), Array::Int(b)) => a.extend_from_slice(b),
            (Array::Bool(a), Array::Bool(b)) => a.extend_from_slice(b),
            (Array::Float2(a), Array::Float2(b)) => a.extend_from_slice(b),
            (Array::Vector(a), Array::Vector(b)) => a.extend_from_slice(b),
            (Array::Color(a), Array::Color(b)) => a.extend_from_slice(b),
            (Array::ByteColor(a), Array::ByteColor(b)) => a.extend_from_slice(b),
            (Array::Quaternion(a), Array::Quaternion(b)) => a.extend_from_slice(b),
            (Array::Matrix(a), Array::Matrix(b)) => a.extend_from_slice(b),
            (Array::Int8(a), Array::Int8(b)) => a.extend_from_slice(b),
            (Array::Int2(a), Array::Int2(b)) => a.extend_from_slice(b),
            _ => unreachable!(),
        }
    }
    /// Appends `n` default values.
    pub fn extend_default(&mut self, n: usize) {
        let z = Array::zeros(self.data_type(), n);
        self.extend(&z);
    }
    /// An empty array of the same type.
    pub fn empty_like(&self) -> Array {
        Array::zeros(self.data_type(), 0)
    }
    /// Writes `src[k]` to `self[indices[k]]` for each k.
    pub fn scatter(&mut self, indices: &[usize], src: &Array) {
        for (k, &i) in indices.iter().enumerate() {
            self.set(i, src.get(k));
        }
    }

    pub fn as_float(&self) -> std::borrow::Cow<'_, [f32]> {
        match self {
            Array::Float(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Float) {
                Array::Float(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
    pub fn as_int(&self) -> std::borrow::Cow<'_, [i32]> {
        match self {
            Array::Int(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Int) {
                Array::Int(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
    pub fn as_bool(&self) -> std::borrow::Cow<'_, [bool]> {
        match self {
            Array::Bool(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Bool) {
                Array::Bool(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
    pub fn as_vector(&self) -> std::borrow::Cow<'_, [[f32; 3]]> {
        match self {
            Array::Vector(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Vector) {
                Array::Vector(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
    pub fn as_color(&self) -> std::borrow::Cow<'_, [[f32; 4]]> {
        match self {
            Array::Color(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Color) {
                Array::Color(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
    pub fn as_quat(&self) -> std::borrow::Cow<'_, [[f32; 4]]> {
        match self {
            Array::Quaternion(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Quaternion) {
                Array::Quaternion(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
    pub fn as_matrix(&self) -> std::borrow::Cow<'_, [Mat4f]> {
        match self {
            Array::Matrix(v) => std::borrow::Cow::Borrowed(v),
            other => match other.convert(DataType::Matrix) {
                Array::Matrix(v) => std::borrow::Cow::Owned(v),
                _ => unreachable!(),
            },
        }
    }
}

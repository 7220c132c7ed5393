//! What flows along a link: a field (single values are constant fields), a geometry set,
//! or an ID / string value; and reading the exporter's socket defaults into them.

use serde_json::Value as Json;

use super::field::Field;
use super::math::euler_to_quat;
use super::set::GeometrySet;
use super::types::{DataType, Value};

#[derive(Debug, Clone)]
pub enum SocketValue {
    Field(Field),
    Geometry(GeometrySet),
    String(String),
    /// ID sockets: the datablock's name (None when empty).
    Material(Option<String>),
    Object(Option<String>),
    Collection(Option<String>),
    Image(Option<String>),
    Texture(Option<String>),
    /// A menu socket's selected item identifier.
    Menu(String),
    /// Bundles, closures and other socket types blendsynth does not evaluate.
    None,
}

impl SocketValue {
    pub fn float(v: f32) -> SocketValue {
        SocketValue::Field(Field::Constant(Value::Float(v)))
    }
    pub fn int(v: i32) -> SocketValue {
        SocketValue::Field(Field::Constant(Value::Int(v)))
    }
    pub fn kind(&self) -> &'static str {
        match self {
            SocketValue::Field(_) => "field",
            SocketValue::Geometry(_) => "geometry",
            SocketValue::String(_) => "string",
            SocketValue::Material(_) => "material",
            SocketValue::Object(_) => "object",
            SocketValue::Collection(_) => "collection",
            SocketValue::Image(_) => "image",
            SocketValue::Texture(_) => "texture",
            SocketValue::Menu(_) => "menu",
            SocketValue::None => "nothing",
        }
    }

    /// The zero value of a socket type (`NodeSocket.type`): what an unlinked socket
    /// without a default, or a link from nothing, gives.
    pub fn zero(kind: &str) -> SocketValue {
        if let Some(t) = DataType::from_socket(kind) {
            return SocketValue::Field(Field::Constant(Value::zero(t)));
        }
        match kind {
            "GEOMETRY" => SocketValue::Geometry(GeometrySet::default()),
            "STRING" => SocketValue::String(String::new()),
            "MATERIAL" => SocketValue::Material(None),
            "OBJECT" => SocketValue::Object(None),
            "COLLECTION" => SocketValue::Collection(None),
            "IMAGE" => SocketValue::Image(None),
            "TEXTURE" => SocketValue::Texture(None),
            "MENU" => SocketValue::Menu(String::new()),
            _ => SocketValue::None,
        }
    }

    /// Reads a default value as the exporter wrote it for a socket of type `kind`.
    pub fn from_json(kind: &str, v: &Json) -> Result<SocketValue, String> {
        let num = |x: &Json| {
            x.as_f64()
                .map(|f| f as f32)
                .or_else(|| x.as_bool().map(|b| b as u8 as f32))
        };
        let floats = |x: &Json| -> Option<Vec<f32>> {
            match x {
                Json::Array(a) => a.iter().map(num).collect(),
                other => num(other).map(|f| vec![f]),
            }
        };
        let bad = || format!("default value {v} is not a valid {kind}");
        let field = |val: Value| Ok(SocketValue::Field(Field::Constant(val)));
        match kind {
            "VALUE" => field(Value::Float(num(v).ok_or_else(bad)?)),
            "INT" => field(Value::Int(
                v.as_i64()
                    .or_else(|| v.as_f64().map(|f| f as i64))
                    .or_else(|| v.as_bool().map(|b| b as i64))
                    .ok_or_else(bad)? as i32,
            )),
            "BOOLEAN" => field(Value::Bool(
                v.as_bool()
                    .or_else(|| v.as_f64().map(|f| f != 0.0))
                    .ok_or_else(bad)?,
            )),
            "VECTOR" => {
                let f = floats(v).ok_or_else(bad)?;
                let g = |i: usize| {
                    f.get(i)
                        .copied()
                        .unwrap_or(if f.len() == 1 { f[0] } else { 0.0 })
                };
                field(Value::Vector([g(0), g(1), g(2)]))
            }
            "RGBA" => {
                let f = floats(v).ok_or_else(bad)?;
                let g = |i: usize, d: f32| f.get(i).copied().unwrap_or(d);
                field(Value::Color([g(0, 0.0), g(1, 0.0), g(2, 0.0), g(3, 1.0)]))
            }
            // Rotation sockets store an Euler default.
            "ROTATION" => {
                let f = floats(v).ok_or_else(bad)?;
                if f.len() == 4 {
                    field(Value::Quaternion([f[0], f[1], f[2], f[3]]))
                } else {
                    let g = |i: usize| f.get(i).copied().unwrap_or(0.0);
                    field(Value::Quaternion(euler_to_quat([g(0), g(1), g(2)])))
                }
            }
            "MATRIX" => {
                let f = floats(v).ok_or_else(bad)?;
                if f.len() == 16 {
                    let mut m = [[0.0f32; 4]; 4];
                    for (k, x) in f.iter().enumerate() {
                        m[k / 4][k % 4] = *x;
                    }
                    field(Value::Matrix(m))
                } else {
                    field(Value::zero(DataType::Matrix))
                }
            }
            "STRING" => Ok(SocketValue::String(
                v.as_str().unwrap_or_default().to_string(),
            )),
            "MENU" => Ok(SocketValue::Menu(
                v.as_str().unwrap_or_default().to_string(),
            )),
            "MATERIAL" | "OBJECT" | "COLLECTION" | "IMAGE" | "TEXTURE" => {
                let name = match v {
                    Json::Null => None,
                    Json::Object(m) => m.get("name").and_then(Json::as_str).map(str::to_string),
                    Json::String(s) => Some(s.clone()),
                    _ => return Err(bad()),
                };
                Ok(match kind {
                    "MATERIAL" => SocketValue::Material(name),
                    "OBJECT" => SocketValue::Object(name),
                    "COLLECTION" => SocketValue::Collection(name),
                    "IMAGE" => SocketValue::Image(name),
                    _ => SocketValue::Texture(name),
                })
            }
            _ => Ok(SocketValue::zero(kind)),
        }
    }

    /// The socket type (`NodeSocket.type`) an interface socket's `bl_idname` stands for.
    pub fn interface_kind(socket_type: &str) -> &'static str {
        let s = socket_type
            .strip_prefix("NodeSocket")
            .unwrap_or(socket_type);
        if s.starts_with("Float") {
            "VALUE"
        } else if s.starts_with("Int") {
            "INT"
        } else if s.starts_with("Bool") {
            "BOOLEAN"
        } else if s.starts_with("Vector") {
            "VECTOR"
        } else if s.starts_with("Color") {
            "RGBA"
        } else if s.starts_with("Rotation") {
            "ROTATION"
        } else if s.starts_with("Matrix") {
            "MATRIX"
        } else if s.starts_with("String") {
            "STRING"
        } else if s.starts_with("Geometry") {
            "GEOMETRY"
        } else if s.starts_with("Material") {
            "MATERIAL"
        } else if s.starts_with("Object") {
            "OBJECT"
        } else if s.starts_with("Collection") {
            "COLLECTION"
        } else if s.starts_with("Image") {
            "IMAGE"
        } else if s.starts_with("Texture") {
            "TEXTURE"
        } else if s.starts_with("Menu") {
            "MENU"
        } else {
            "CUSTOM"
        }
    }
}

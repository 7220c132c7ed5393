//! Turns the symbolic transforms of an OCIO config into a flat list of per-pixel
//! operations, following OCIO's semantics: colour-space conversions go through the
//! scene reference space (src to_reference, then dst from_reference, or the inverse of
//! the other direction when only one is given), groups invert by reversing their
//! children, data colour spaces convert to nothing.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use super::config::{Config, Dir, GradingTone, Transform};
use super::lut::{self, Lut1D, Lut3D, LutFile};
use super::ColorError;

/// One pixel operation on RGB (alpha is never touched).
#[derive(Debug, Clone)]
pub enum Op {
    /// out = M * rgb + offset
    Matrix {
        m: [[f32; 3]; 3],
        offset: [f32; 3],
    },
    /// out = rgb * scale + offset, per channel
    Affine {
        scale: [f32; 3],
        offset: [f32; 3],
    },
    /// log2(max(x, FLT_MIN))
    Log2,
    /// 2^x
    Exp2,
    Lut1D {
        lut: Arc<Lut1D>,
        inverse: bool,
    },
    Lut3D {
        lut: Arc<Lut3D>,
        tetrahedral: bool,
    },
    /// pow(max(x, 0), e) per channel (ExponentTransform's default negative clamp)
    Pow([f32; 3]),
    /// Moncurve (ExponentWithLinearTransform): encode = linear to encoded (its inverse).
    MonCurve {
        gamma: [f32; 3],
        offset: [f32; 3],
        encode: bool,
    },
    Clamp {
        min: Option<f32>,
        max: Option<f32>,
    },
    /// ASC CDL without clamping (OCIO v2's default style).
    Cdl {
        slope: [f32; 3],
        offset: [f32; 3],
        power: [f32; 3],
        sat: f32,
        inverse: bool,
    },
    GradingPrimaryLog {
        brightness: [f32; 3],
        contrast: [f32; 3],
        gamma: [f32; 3],
        pivot: f32,
        saturation: f32,
        inverse: bool,
    },
    GradingTone(Box<super::tone::ToneOp>),
}

pub struct Builder<'a> {
    pub config: &'a Config,
    luts: HashMap<PathBuf, LutFile>,
    ops: Vec<Op>,
    /// Consecutive matrix-like ops are multiplied together in f64 (as OCIO's optimizer
    /// does), so round trips through the reference space cancel exactly.
    pending: Option<([[f64; 3]; 3], [f64; 3])>,
    depth: usize,
}

fn mat4_to3(m: &[f64; 16]) -> [[f64; 3]; 3] {
    [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]]
}

fn invert3(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if det.abs() < 1e-300 {
        return None;
    }
    let d = 1.0 / det;
    Some([
        [
            (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * d,
            (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * d,
            (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * d,
        ],
        [
            (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * d,
            (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * d,
            (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * d,
        ],
        [
            (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * d,
            (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * d,
            (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * d,
        ],
    ])
}

fn f3(v: [f64; 3]) -> [f32; 3] {
    [v[0] as f32, v[1] as f32, v[2] as f32]
}

impl<'a> Builder<'a> {
    pub fn new(config: &'a Config) -> Self {
        Builder {
            config,
            luts: HashMap::new(),
            ops: Vec::new(),
            pending: None,
            depth: 0,
        }
    }

    fn cerr(&self, msg: impl std::fmt::Display) -> ColorError {
        ColorError::Config {
            path: self.config.path.clone(),
            message: msg.to_string(),
        }
    }

    /// out = m * in + offset, fused with a preceding matrix.
    pub fn push_matrix(&mut self, m: [[f64; 3]; 3], offset: [f64; 3]) {
        self.pending = Some(match self.pending.take() {
            None => (m, offset),
            Some((a, ao)) => {
                let mut p = [[0.0; 3]; 3];
                let mut o = offset;
                for i in 0..3 {
                    for j in 0..3 {
                        p[i][j] = (0..3).map(|k| m[i][k] * a[k][j]).sum();
                        o[i] += m[i][j] * ao[j];
                    }
                }
                (p, o)
            }
        });
    }

    fn push_scale_offset(&mut self, scale: f64, offset: f64) {
        self.push_matrix(
            [[scale, 0.0, 0.0], [0.0, scale, 0.0], [0.0, 0.0, scale]],
            [offset; 3],
        );
    }

    fn flush(&mut self) {
        if let Some((m, o)) = self.pending.take() {
            let identity = (0..3).all(|i| {
                (0..3).all(|j| (m[i][j] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12)
                    && o[i].abs() < 1e-12
            });
            if !identity {
                let diagonal = (0..3).all(|i| (0..3).all(|j| i == j || m[i][j] == 0.0));
                self.ops.push(if diagonal {
                    Op::Affine {
                        scale: f3([m[0][0], m[1][1], m[2][2]]),
                        offset: f3(o),
                    }
                } else {
                    Op::Matrix {
                        m: [f3(m[0]), f3(m[1]), f3(m[2])],
                        offset: f3(o),
                    }
                });
            }
        }
    }

    fn push(&mut self, op: Op) {
        self.flush();
        self.ops.push(op);
    }

    /// The finished list of operations.
    pub fn finish(mut self) -> Vec<Op> {
        self.flush();
        self.ops
    }

    /// Converts from colour space `src` to `dst` (names, aliases or roles).
    pub fn convert(&mut self, src: &str, dst: &str) -> Result<(), ColorError> {
        let cfg = self.config;
        let s = cfg
            .space(src)
            .ok_or_else(|| self.cerr(format!("unknown colour space {src:?}")))?;
        let d = cfg
            .space(dst)
            .ok_or_else(|| self.cerr(format!("unknown colour space {dst:?}")))?;
        if s.name == d.name || s.is_data || d.is_data {
            return Ok(());
        }
        self.enter()?;
        match (&s.to_ref, &s.from_ref) {
            (Some(t), _) => self.transform(t, Dir::Forward)?,
            (None, Some(f)) => self.transform(f, Dir::Inverse)?,
            (None, None) => {}
        }
        match (&d.from_ref, &d.to_ref) {
            (Some(f), _) => self.transform(f, Dir::Forward)?,
            (None, Some(t)) => self.transform(t, Dir::Inverse)?,
            (None, None) => {}
        }
        self.depth -= 1;
        Ok(())
    }

    fn enter(&mut self) -> Result<(), ColorError> {
        self.depth += 1;
        if self.depth > 32 {
            return Err(self.cerr("colour-space transforms refer to each other in a cycle"));
        }
        Ok(())
    }

    /// Applies look `name` from colour space `src`; returns the look's process space
    /// (where the pixels are afterwards).
    pub fn look(&mut self, src: &str, name: &str) -> Result<String, ColorError> {
        let look = self.config.look(name).ok_or_else(|| {
            let names: Vec<&str> = self.config.looks.iter().map(|l| l.name.as_str()).collect();
            self.cerr(format!(
                "unknown look {name:?} (the config has: {})",
                names.join(", ")
            ))
        })?;
        let look = look.clone();
        self.convert(src, &look.process_space)?;
        match (&look.transform, &look.inverse_transform) {
            (Some(t), _) => self.transform(t, Dir::Forward)?,
            (None, Some(t)) => self.transform(t, Dir::Inverse)?,
            (None, None) => {}
        }
        Ok(look.process_space)
    }

    fn load_lut(&mut self, name: &str) -> Result<LutFile, ColorError> {
        let path = self.config.find_file(name)?.ok_or_else(|| {
            self.cerr(format!(
                "LUT file {name:?} not found in the config's search path"
            ))
        })?;
        if let Some(l) = self.luts.get(&path) {
            return Ok(l.clone());
        }
        let l = lut::load(&path)?;
        self.luts.insert(path, l.clone());
        Ok(l)
    }

    // Long because one arm per OCIO transform type, as OCIO builds its ops.
    pub fn transform(&mut self, t: &Transform, outer: Dir) -> Result<(), ColorError> {
        match t {
            Transform::Group(children, dir) => {
                if outer.combine(*dir) == Dir::Forward {
                    for c in children {
                        self.transform(c, Dir::Forward)?;
                    }
                } else {
                    for c in children.iter().rev() {
                        self.transform(c, Dir::Inverse)?;
                    }
                }
            }
            Transform::ColorSpace { src, dst, dir } => {
                if outer.combine(*dir) == Dir::Forward {
                    self.convert(src, dst)?
                } else {
                    self.convert(dst, src)?
                }
            }
            Transform::Matrix { m, offset, dir } => {
                let m3 = mat4_to3(m);
                let off = [offset[0], offset[1], offset[2]];
                if outer.combine(*dir) == Dir::Forward {
                    self.push_matrix(m3, off);
                } else {
                    let inv = invert3(m3)
                        .ok_or_else(|| self.cerr("a MatrixTransform to invert is singular"))?;
                    let o = [
                        -(inv[0][0] * off[0] + inv[0][1] * off[1] + inv[0][2] * off[2]),
                        -(inv[1][0] * off[0] + inv[1][1] * off[1] + inv[1][2] * off[2]),
                        -(inv[2][0] * off[0] + inv[2][1] * off[1] + inv[2][2] * off[2]),
                    ];
                    self.push_matrix(inv, o);
                }
            }
            Transform::Allocation { lg2, vars, dir } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                let (lo, hi) = if vars.len() >= 2 {
                    (vars[0], vars[1])
                } else if *lg2 {
                    (-10.0, 6.0)
                } else {
                    (0.0, 1.0)
                };
                let lin_offset = if *lg2 && vars.len() >= 3 {
                    vars[2]
                } else {
                    0.0
                };
                // Fit lo..hi to 0..1.
                let fit = |b: &mut Self, fwd: bool| {
                    let s = 1.0 / (hi - lo);
                    if fwd {
                        b.push_scale_offset(s, -lo * s)
                    } else {
                        b.push_scale_offset(hi - lo, lo)
                    }
                };
                if !*lg2 {
                    fit(self, fwd);
                } else if fwd {
                    if lin_offset != 0.0 {
                        self.push_scale_offset(1.0, lin_offset);
                    }
                    self.push(Op::Log2);
                    fit(self, true);
                } else {
                    fit(self, false);
                    self.push(Op::Exp2);
                    if lin_offset != 0.0 {
                        self.push_scale_offset(1.0, -lin_offset);
                    }
                }
            }
            Transform::File {
                src,
                tetrahedral,
                dir,
            } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                match self.load_lut(src)? {
                    LutFile::OneD(l) => self.push(Op::Lut1D {
                        lut: Arc::new(l),
                        inverse: !fwd,
                    }),
                    LutFile::ThreeD(l) => {
                        if !fwd {
                            return Err(self
                                .cerr(format!("inverse of the 3D LUT {src:?} is not supported")));
                        }
                        self.push(Op::Lut3D {
                            lut: Arc::new(l),
                            tetrahedral: *tetrahedral,
                        })
                    }
                    LutFile::Matrix(m) => {
                        let t = Transform::Matrix {
                            m: [
                                m[0][0], m[0][1], m[0][2], 0.0, m[1][0], m[1][1], m[1][2], 0.0,
                                m[2][0], m[2][1], m[2][2], 0.0, 0.0, 0.0, 0.0, 1.0,
                            ],
                            offset: [m[0][3], m[1][3], m[2][3], 0.0],
                            dir: Dir::Forward,
                        };
                        self.transform(&t, if fwd { Dir::Forward } else { Dir::Inverse })?;
                    }
                }
            }
            Transform::Exponent { value, dir } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                let e = |v: f64| if fwd { v as f32 } else { (1.0 / v) as f32 };
                self.push(Op::Pow([e(value[0]), e(value[1]), e(value[2])]));
            }
            Transform::ExponentWithLinear { gamma, offset, dir } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                self.push(Op::MonCurve {
                    gamma: f3([gamma[0], gamma[1], gamma[2]]),
                    offset: f3([offset[0], offset[1], offset[2]]),
                    encode: !fwd,
                });
            }
            Transform::Range {
                min_in,
                max_in,
                min_out,
                max_out,
                dir,
            } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                let (a_min, a_max, b_min, b_max) = if fwd {
                    (min_in, max_in, min_out, max_out)
                } else {
                    (min_out, max_out, min_in, max_in)
                };
                // Only the clamp-only form (in == out) is used by Blender's configs.
                if a_min != b_min || a_max != b_max {
                    return Err(self.cerr("RangeTransform that rescales is not supported"));
                }
                self.push(Op::Clamp {
                    min: a_min.map(|v| v as f32),
                    max: a_max.map(|v| v as f32),
                });
            }
            Transform::Cdl {
                slope,
                offset,
                power,
                sat,
                dir,
            } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                self.push(Op::Cdl {
                    slope: f3(*slope),
                    offset: f3(*offset),
                    power: f3(*power),
                    sat: *sat as f32,
                    inverse: !fwd,
                });
            }
            Transform::GradingPrimaryLog {
                contrast,
                saturation,
                pivot,
                brightness,
                gamma,
                dir,
            } => {
                let fwd = outer.combine(*dir) == Dir::Forward;
                let s = 6.25 / 1023.0;
                self.push(Op::GradingPrimaryLog {
                    brightness: f3([brightness[0] * s, brightness[1] * s, brightness[2] * s]),
                    contrast: f3(*contrast),
                    gamma: f3([1.0 / gamma[0], 1.0 / gamma[1], 1.0 / gamma[2]]),
                    pivot: (0.5 + pivot * 0.5) as f32,
                    saturation: *saturation as f32,
                    inverse: !fwd,
                });
            }
            Transform::GradingTone(g) => {
                let g: &GradingTone = g;
                let fwd = outer.combine(g.dir) == Dir::Forward;
                if !fwd {
                    return Err(self.cerr("inverse GradingToneTransform is not supported"));
                }
                self.push(Op::GradingTone(Box::new(
                    super::tone::ToneOp::new(g).map_err(|m| self.cerr(m))?,
                )));
            }
            Transform::Unsupported(what) => {
                return Err(self.cerr(format!("{what} is not supported")))
            }
        }
        Ok(())
    }
}

const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

impl Op {
    #[inline]
    pub fn apply(&self, p: &mut [f32; 3]) {
        match self {
            Op::Matrix { m, offset } => {
                let [r, g, b] = *p;
                for i in 0..3 {
                    p[i] = m[i][0] * r + m[i][1] * g + m[i][2] * b + offset[i];
                }
            }
            Op::Affine { scale, offset } => {
                for i in 0..3 {
                    p[i] = p[i] * scale[i] + offset[i];
                }
            }
            Op::Log2 => {
                for v in p.iter_mut() {
                    *v = v.max(f32::MIN_POSITIVE).log2();
                }
            }
            Op::Exp2 => {
                for v in p.iter_mut() {
                    *v = v.exp2();
                }
            }
            Op::Lut1D { lut, inverse } => {
                for (c, v) in p.iter_mut().enumerate() {
                    *v = if *inverse {
                        lut.eval_inverse(c, *v)
                    } else {
                        lut.eval(c, *v)
                    };
                }
            }
            Op::Lut3D { lut, tetrahedral } => {
                *p = if *tetrahedral {
                    lut.tetrahedral(*p)
                } else {
                    lut.trilinear(*p)
                };
            }
            Op::Pow(e) => {
                for i in 0..3 {
                    p[i] = p[i].max(0.0).powf(e[i]);
                }
            }
            Op::MonCurve {
                gamma,
                offset,
                encode,
            } => {
                for i in 0..3 {
                    p[i] = moncurve(p[i], gamma[i], offset[i], *encode);
                }
            }
            Op::Clamp { min, max } => {
                for v in p.iter_mut() {
                    if let Some(lo) = min {
                        *v = v.max(*lo);
                    }
                    if let Some(hi) = max {
                        *v = v.min(*hi);
                    }
                }
            }
            Op::Cdl {
                slope,
                offset,
                power,
                sat,
                inverse,
            } => {
                let pw = |x: f32, e: f32| if x > 0.0 { x.powf(e) } else { x };
                let saturate = |p: &mut [f32; 3], s: f32| {
                    let l = LUMA[0] * p[0] + LUMA[1] * p[1] + LUMA[2] * p[2];
                    for v in p.iter_mut() {
                        *v = l + s * (*v - l);
                    }
                };
                if !*inverse {
                    for i in 0..3 {
                        p[i] = pw(p[i] * slope[i] + offset[i], power[i]);
                    }
                    saturate(p, *sat);
                } else {
                    saturate(p, 1.0 / *sat);
                    for i in 0..3 {
                        p[i] = (pw(p[i], 1.0 / power[i]) - offset[i]) / slope[i];
                    }
                }
            }
            Op::GradingPrimaryLog {
                brightness,
                contrast,
                gamma,
                pivot,
                saturation,
                inverse,
            } => {
                let (black, white) = (0.0f32, 1.0f32);
                let gam = |x: f32, g: f32| {
                    let d = x - black;
                    (d.abs() / (white - black)).powf(g) * d.signum() * (white - black) + black
                };
                if !*inverse {
                    for i in 0..3 {
                        let mut v = p[i] + brightness[i];
                        v = (v - pivot) * contrast[i] + pivot;
                        if gamma[i] != 1.0 {
                            v = gam(v, gamma[i]);
                        }
                        p[i] = v;
                    }
                    if *saturation != 1.0 {
                        let l = LUMA[0] * p[0] + LUMA[1] * p[1] + LUMA[2] * p[2];
                        for v in p.iter_mut() {
                            *v = l + saturation * (*v - l);
                        }
                    }
                } else {
                    if *saturation != 1.0 && *saturation != 0.0 {
                        let l = LUMA[0] * p[0] + LUMA[1] * p[1] + LUMA[2] * p[2];
                        for v in p.iter_mut() {
                            *v = l + (*v - l) / saturation;
                        }
                    }
                    for i in 0..3 {
                        let mut v = p[i];
                        if gamma[i] != 1.0 {
                            v = gam(v, 1.0 / gamma[i]);
                        }
                        v = (v - pivot) / if contrast[i] == 0.0 { 1.0 } else { contrast[i] }
                            + pivot;
                        p[i] = v - brightness[i];
                    }
                }
            }
            Op::GradingTone(t) => t.apply(p),
        }
    }
}

/// OCIO's moncurve with a linear segment (and its linear extension below zero).
#[inline]
fn moncurve(x: f32, gamma: f32, offset: f32, encode: bool) -> f32 {
    let (g, a) = (gamma as f64, offset as f64);
    // Break point in the encoded domain and its image in the linear domain.
    let brk_enc = a / (g - 1.0);
    let brk_lin = ((brk_enc + a) / (1.0 + a)).powf(g);
    let slope = brk_lin / brk_enc; // linear = encoded * slope below the break
    let x = x as f64;
    let y = if encode {
        if x <= brk_lin {
            x / slope
        } else {
            (1.0 + a) * x.powf(1.0 / g) - a
        }
    } else if x <= brk_enc {
        x * slope
    } else {
        ((x + a) / (1.0 + a)).powf(g)
    };
    y as f32
}

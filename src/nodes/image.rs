//! Image and Environment Texture maths as Cycles' CPU kernel does it
//! (`kernel/device/cpu/image.h`, `svm/image.h`): texel reads from byte, 16-bit or float
//! storage, closest / bilinear / bicubic B-spline interpolation with texel centres at
//! half-integers, the four extension modes, box-projection weights, sphere and tube
//! projections, and the equirectangular and mirror-ball environment mappings.
//! The pixels themselves live in `shader::images` (loaded once, shared).

use super::math::V3;

blender_enum! {
    /// Image Texture `interpolation`; Cycles' CPU kernel samples Smart as Cubic.
    pub enum Interpolation {
        Linear = "Linear",
        Closest = "Closest",
        Cubic = "Cubic",
        Smart = "Smart",
    }
}

blender_enum! {
    pub enum Extension {
        Repeat = "REPEAT",
        Extend = "EXTEND",
        Clip = "CLIP",
        Mirror = "MIRROR",
    }
}

blender_enum! {
    pub enum Projection {
        Flat = "FLAT",
        Box = "BOX",
        Sphere = "SPHERE",
        Tube = "TUBE",
    }
}

blender_enum! {
    pub enum EnvProjection {
        Equirectangular = "EQUIRECTANGULAR",
        MirrorBall = "MIRROR_BALL",
    }
}

/// The colour of a texture whose image is missing or unreadable (Cycles'
/// `TEX_IMAGE_MISSING_*`): magenta, opaque.
pub const MISSING: [f32; 4] = [1.0, 0.0, 1.0, 1.0];

/// A stored texel, read as Cycles reads it (bytes times 1/255, shorts times 1/65535).
pub trait Texel: Copy {
    fn read(self) -> [f32; 4];
}

impl Texel for [u8; 4] {
    #[inline]
    fn read(self) -> [f32; 4] {
        let f = 1.0f32 / 255.0;
        self.map(|v| v as f32 * f)
    }
}

impl Texel for [u16; 4] {
    #[inline]
    fn read(self) -> [f32; 4] {
        let f = 1.0f32 / 65535.0;
        self.map(|v| v as f32 * f)
    }
}

impl Texel for [f32; 4] {
    #[inline]
    fn read(self) -> [f32; 4] {
        self
    }
}

/// Pixels of one image, rows bottom to top (Cycles' and Blender's order).
#[derive(Debug, Clone, Copy)]
pub struct Pixels<'a, T> {
    pub data: &'a [T],
    pub width: i32,
    pub height: i32,
}

#[inline]
fn scale4(s: f32, v: [f32; 4]) -> [f32; 4] {
    v.map(|x| s * x)
}

#[inline]
fn add4(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}

/// Cycles' `frac`: the integer part truncates and then steps down for negatives, so an
/// exact negative integer lands one cell lower with a fraction of 1.
#[inline]
fn frac(x: f32) -> (f32, i32) {
    let i = (x as i32) - (x < 0.0) as i32;
    (x - i as f32, i)
}

#[inline]
fn wrap_periodic(x: i32, w: i32) -> i32 {
    let x = x % w;
    if x < 0 {
        x + w
    } else {
        x
    }
}

#[inline]
fn wrap_clamp(x: i32, w: i32) -> i32 {
    x.clamp(0, w - 1)
}

#[inline]
fn wrap_mirror(x: i32, w: i32) -> i32 {
    let m = (x + (x < 0) as i32).abs() % (2 * w);
    if m >= w {
        2 * w - m - 1
    } else {
        m
    }
}

impl<T: Texel> Pixels<'_, T> {
    #[inline]
    fn read(&self, x: i32, y: i32) -> [f32; 4] {
        self.data[(y * self.width + x) as usize].read()
    }

    #[inline]
    fn read_clip(&self, x: i32, y: i32) -> [f32; 4] {
        if x < 0 || x >= self.width || y < 0 || y >= self.height {
            return [0.0; 4];
        }
        self.read(x, y)
    }

    /// The interpolated texel value at texture coordinates (x, y) (0..1 over the image).
    pub fn interp(
        &self,
        x: f32,
        y: f32,
        interpolation: Interpolation,
        extension: Extension,
    ) -> [f32; 4] {
        match interpolation {
            Interpolation::Closest => self.closest(x, y, extension),
            Interpolation::Linear => self.linear(x, y, extension),
            Interpolation::Cubic | Interpolation::Smart => self.cubic(x, y, extension),
        }
    }

    /// The lookup of Geometry Nodes' Image Texture (`node_geo_image_texture.cc`): Cycles'
    /// except Closest with Clip, which is black only left of / below the image and more
    /// than one texel right of / above it, and clamps to the edge in between.
    pub fn interp_geometry_nodes(
        &self,
        x: f32,
        y: f32,
        interpolation: Interpolation,
        extension: Extension,
    ) -> [f32; 4] {
        if interpolation == Interpolation::Closest && extension == Extension::Clip {
            let (_, ix) = frac(x * self.width as f32);
            let (_, iy) = frac(y * self.height as f32);
            if ix < 0 || iy < 0 || ix > self.width || iy > self.height {
                return [0.0; 4];
            }
            return self.read(wrap_clamp(ix, self.width), wrap_clamp(iy, self.height));
        }
        self.interp(x, y, interpolation, extension)
    }

    fn closest(&self, x: f32, y: f32, ext: Extension) -> [f32; 4] {
        let (w, h) = (self.width, self.height);
        let (_, mut ix) = frac(x * w as f32);
        let (_, mut iy) = frac(y * h as f32);
        match ext {
            Extension::Repeat => {
                ix = wrap_periodic(ix, w);
                iy = wrap_periodic(iy, h);
            }
            Extension::Clip => {
                if ix < 0 || ix >= w || iy < 0 || iy >= h {
                    return [0.0; 4];
                }
            }
            Extension::Extend => {
                ix = wrap_clamp(ix, w);
                iy = wrap_clamp(iy, h);
            }
            Extension::Mirror => {
                ix = wrap_mirror(ix, w);
                iy = wrap_mirror(iy, h);
            }
        }
        self.read(ix, iy)
    }

    fn linear(&self, x: f32, y: f32, ext: Extension) -> [f32; 4] {
        let (w, h) = (self.width, self.height);
        // Texel centres sit at half-integers: -0.5 centres the 2x2 footprint.
        let (tx, mut ix) = frac(x * w as f32 - 0.5);
        let (ty, mut iy) = frac(y * h as f32 - 0.5);
        let (nix, niy);
        match ext {
            Extension::Repeat => {
                ix = wrap_periodic(ix, w);
                nix = wrap_periodic(ix + 1, w);
                iy = wrap_periodic(iy, h);
                niy = wrap_periodic(iy + 1, h);
            }
            Extension::Clip => {
                if ix < -1 || ix >= w || iy < -1 || iy >= h {
                    return [0.0; 4];
                }
                let (nix, niy) = (ix + 1, iy + 1);
                let r = scale4((1.0 - ty) * (1.0 - tx), self.read_clip(ix, iy));
                let r = add4(r, scale4((1.0 - ty) * tx, self.read_clip(nix, iy)));
                let r = add4(r, scale4(ty * (1.0 - tx), self.read_clip(ix, niy)));
                return add4(r, scale4(ty * tx, self.read_clip(nix, niy)));
            }
            Extension::Extend => {
                nix = wrap_clamp(ix + 1, w);
                ix = wrap_clamp(ix, w);
                niy = wrap_clamp(iy + 1, h);
                iy = wrap_clamp(iy, h);
            }
            Extension::Mirror => {
                nix = wrap_mirror(ix + 1, w);
                ix = wrap_mirror(ix, w);
                niy = wrap_mirror(iy + 1, h);
                iy = wrap_mirror(iy, h);
            }
        }
        let r = scale4((1.0 - ty) * (1.0 - tx), self.read(ix, iy));
        let r = add4(r, scale4((1.0 - ty) * tx, self.read(nix, iy)));
        let r = add4(r, scale4(ty * (1.0 - tx), self.read(ix, niy)));
        add4(r, scale4(ty * tx, self.read(nix, niy)))
    }

    fn cubic(&self, x: f32, y: f32, ext: Extension) -> [f32; 4] {
        let (w, h) = (self.width, self.height);
        let (tx, mut ix) = frac(x * w as f32 - 0.5);
        let (ty, mut iy) = frac(y * h as f32 - 0.5);
        let (pix, nix, nnix, piy, niy, nniy);
        match ext {
            Extension::Repeat => {
                ix = wrap_periodic(ix, w);
                pix = wrap_periodic(ix - 1, w);
                nix = wrap_periodic(ix + 1, w);
                nnix = wrap_periodic(ix + 2, w);
                iy = wrap_periodic(iy, h);
                piy = wrap_periodic(iy - 1, h);
                niy = wrap_periodic(iy + 1, h);
                nniy = wrap_periodic(iy + 2, h);
            }
            Extension::Clip => {
                if ix < -2 || ix > w || iy < -2 || iy > h {
                    return [0.0; 4];
                }
                (pix, nix, nnix) = (ix - 1, ix + 1, ix + 2);
                (piy, niy, nniy) = (iy - 1, iy + 1, iy + 2);
            }
            Extension::Extend => {
                pix = wrap_clamp(ix - 1, w);
                nix = wrap_clamp(ix + 1, w);
                nnix = wrap_clamp(ix + 2, w);
                ix = wrap_clamp(ix, w);
                piy = wrap_clamp(iy - 1, h);
                niy = wrap_clamp(iy + 1, h);
                nniy = wrap_clamp(iy + 2, h);
                iy = wrap_clamp(iy, h);
            }
            Extension::Mirror => {
                pix = wrap_mirror(ix - 1, w);
                nix = wrap_mirror(ix + 1, w);
                nnix = wrap_mirror(ix + 2, w);
                ix = wrap_mirror(ix, w);
                piy = wrap_mirror(iy - 1, h);
                niy = wrap_mirror(iy + 1, h);
                nniy = wrap_mirror(iy + 2, h);
                iy = wrap_mirror(iy, h);
            }
        }
        let xc = [pix, ix, nix, nnix];
        let yc = [piy, iy, niy, nniy];
        let u = cubic_weights(tx);
        let v = cubic_weights(ty);
        let mut r = [0.0f32; 4];
        for (col, &yy) in yc.iter().enumerate() {
            let mut row = scale4(u[0], self.read_clip(xc[0], yy));
            for k in 1..4 {
                row = add4(row, scale4(u[k], self.read_clip(xc[k], yy)));
            }
            r = add4(r, scale4(v[col], row));
        }
        r
    }
}

/// Uniform cubic B-spline weights (Cycles' `SET_CUBIC_SPLINE_WEIGHTS`).
#[inline]
fn cubic_weights(t: f32) -> [f32; 4] {
    [
        (((-1.0 / 6.0) * t + 0.5) * t - 0.5) * t + (1.0 / 6.0),
        ((0.5 * t - 1.0) * t) * t + (2.0 / 3.0),
        ((-0.5 * t + 0.5) * t + 0.5) * t + (1.0 / 6.0),
        (1.0 / 6.0) * t * t * t,
    ]
}

/// sRGB transfer function to linear (Cycles' `color_srgb_to_linear`).
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
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

/// What `svm_image_texture` does after interpolation: unassociate alpha when the Alpha
/// output is used, then decode sRGB-stored images to linear.
#[inline]
pub fn finish_lookup(mut r: [f32; 4], unassociate: bool, srgb: bool) -> [f32; 4] {
    let alpha = r[3];
    if unassociate && alpha != 1.0 && alpha != 0.0 {
        r = r.map(|x| x / alpha);
        r[3] = alpha;
    }
    if srgb {
        r = [
            srgb_to_linear(r[0]),
            srgb_to_linear(r[1]),
            srgb_to_linear(r[2]),
            r[3],
        ];
    }
    r
}

/// Flat-projection coordinates of the Sphere and Tube projections (`map_to_sphere`,
/// `map_to_tube` of the 0..1 box remapped to -1..1).
pub fn project(p: Projection, co: V3) -> [f32; 2] {
    let sq = |v: f32| (v - 0.5) * 2.0;
    match p {
        Projection::Flat | Projection::Box => [co[0], co[1]],
        Projection::Sphere => {
            let c = co.map(sq);
            let l = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
            if l > 0.0 {
                let u = if c[0] == 0.0 && c[1] == 0.0 {
                    0.0
                } else {
                    (1.0 - c[0].atan2(c[1]) / std::f32::consts::PI) / 2.0
                };
                let v = 1.0 - (c[2] / l.sqrt()).clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
                [u, v]
            } else {
                [0.0, 0.0]
            }
        }
        Projection::Tube => {
            let c = co.map(sq);
            let len = (c[0] * c[0] + c[1] * c[1]).sqrt();
            if len > 0.0 {
                [
                    (1.0 - (c[0] / len).atan2(c[1] / len) / std::f32::consts::PI) * 0.5,
                    (c[2] + 1.0) * 0.5,
                ]
            } else {
                [0.0, 0.0]
            }
        }
    }
}

/// Box projection: the weight of the X, Y and Z facing images for object-space normal
/// `n` and the node's blend (Cycles' seven zones of the barycentric triangle).
pub fn box_weights(n: V3, blend: f32) -> V3 {
    let mut n = n.map(f32::abs);
    let s = n[0] + n[1] + n[2];
    n = n.map(|x| x / s);
    let [nx, ny, nz] = n;
    let mut w = [0.0f32; 3];
    let limit = 0.5 * (1.0 + blend);
    if nx > limit * (nx + ny) && nx > limit * (nx + nz) {
        w[0] = 1.0;
    } else if ny > limit * (nx + ny) && ny > limit * (ny + nz) {
        w[1] = 1.0;
    } else if nz > limit * (nx + nz) && nz > limit * (ny + nz) {
        w[2] = 1.0;
    } else if blend > 0.0 {
        #[allow(clippy::manual_clamp)]
        let sat = |x: f32| x.max(0.0).min(1.0);
        if nz < (1.0 - limit) * (ny + nx) {
            w[0] = sat((nx / (nx + ny) - 0.5 * (1.0 - blend)) / blend);
            w[1] = 1.0 - w[0];
        } else if nx < (1.0 - limit) * (ny + nz) {
            w[1] = sat((ny / (ny + nz) - 0.5 * (1.0 - blend)) / blend);
            w[2] = 1.0 - w[1];
        } else if ny < (1.0 - limit) * (nx + nz) {
            w[0] = sat((nx / (nx + nz) - 0.5 * (1.0 - blend)) / blend);
            w[2] = 1.0 - w[0];
        } else {
            let k = |v: f32| ((2.0 - limit) * v + (limit - 1.0)) / (2.0 * limit - 1.0);
            w = [k(nx), k(ny), k(nz)];
        }
    } else {
        // No valid zone without blending: fall back to one side, as Cycles does.
        w[0] = 1.0;
    }
    w
}

/// The image coordinates each box face samples (no face appears mirrored).
pub fn box_uvs(signed_n: V3, co: V3) -> [[f32; 2]; 3] {
    [
        [
            if signed_n[0] < 0.0 {
                1.0 - co[1]
            } else {
                co[1]
            },
            co[2],
        ],
        [
            if signed_n[1] > 0.0 {
                1.0 - co[0]
            } else {
                co[0]
            },
            co[2],
        ],
        [
            if signed_n[2] > 0.0 {
                1.0 - co[1]
            } else {
                co[1]
            },
            co[0],
        ],
    ]
}

/// Equirectangular image coordinates of a direction (Cycles' default range).
pub fn direction_to_equirectangular(d: V3) -> [f32; 2] {
    if d == [0.0; 3] {
        return [0.0, 0.0];
    }
    use std::f32::consts::PI;
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u = (d[1].atan2(d[0]) - PI) / (-2.0 * PI);
    let v = ((d[2] / len).acos() - PI) / (-PI);
    [u, v]
}

/// Mirror-ball image coordinates of a direction.
pub fn direction_to_mirrorball(mut d: V3) -> [f32; 2] {
    d[1] -= 1.0;
    let div = 2.0 * (-0.5 * d[1]).max(0.0).sqrt();
    if div > 0.0 {
        d = d.map(|x| x / div);
    }
    [0.5 * (d[0] + 1.0), 0.5 * (d[2] + 1.0)]
}

/// Cycles' `safe_normalize`: a zero vector stays zero.
pub fn safe_normalize(v: V3) -> V3 {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l != 0.0 {
        v.map(|x| x / l)
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frac_steps_negative_integers_down() {
        assert_eq!(frac(-1.0), (1.0, -2));
        assert_eq!(frac(1.5), (0.5, 1));
        assert_eq!(frac(-0.25), (0.75, -1));
    }

    #[test]
    fn mirror_reflects_about_edges() {
        let w = 4;
        let got: Vec<i32> = (-5..9).map(|x| wrap_mirror(x, w)).collect();
        assert_eq!(got, vec![3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
    }

    #[test]
    fn cubic_weights_sum_to_one() {
        for t in [0.0f32, 0.25, 0.5, 0.9] {
            let s: f32 = cubic_weights(t).iter().sum();
            assert!((s - 1.0).abs() < 1e-6);
        }
    }
}

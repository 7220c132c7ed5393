//! Voronoi Texture with Cycles' semantics (`kernel/svm/voronoi.h`): F1, F2, Smooth F1,
//! Distance to Edge and N-Sphere Radius in 1 to 4 dimensions, four distance metrics,
//! randomness, and the fractal (detail/roughness/lacunarity) layering with normalize.
//!
//! One generic implementation over `[f32; N]` points; cells are visited in Cycles' order
//! (x fastest) because ties keep the first cell found.

use super::math::Vec3;
use super::white_noise::{hash_f1_to_f3, hash_f2_to_f2, hash_f2_to_f3, hash_f3_to_f3, hash_f4_to_f3, hash_f4_to_f4};
use super::random::hash_float_to_float1;

blender_enum! {
    pub enum VoronoiFeature {
        F1 = "F1",
        F2 = "F2",
        SmoothF1 = "SMOOTH_F1",
        DistanceToEdge = "DISTANCE_TO_EDGE",
        NSphereRadius = "N_SPHERE_RADIUS",
    }
}
blender_enum! {
    pub enum VoronoiMetric {
        Euclidean = "EUCLIDEAN",
        Manhattan = "MANHATTAN",
        Chebychev = "CHEBYCHEV",
        Minkowski = "MINKOWSKI",
    }
}

#[derive(Debug, Clone, Copy)]
pub struct VoronoiParams {
    pub feature: VoronoiFeature,
    pub metric: VoronoiMetric,
    pub normalize: bool,
    pub scale: f32,
    pub detail: f32,
    pub roughness: f32,
    pub lacunarity: f32,
    pub smoothness: f32,
    pub exponent: f32,
    pub randomness: f32,
    max_distance: f32,
}

/// The node's outputs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct VoronoiOutput {
    pub distance: f32,
    pub color: Vec3,
    pub position: Vec3,
    pub w: f32,
    pub radius: f32,
}

trait Cell<const N: usize> {
    fn jitter(cell: [f32; N]) -> [f32; N];
    fn color(cell: [f32; N]) -> Vec3;
    /// The cell's colour given its jitter hash (in 3D both are the same hash).
    fn color_with(cell: [f32; N], _jitter: [f32; N]) -> Vec3 {
        Self::color(cell)
    }
    /// Cycles' `voronoi_position`: where the N components land in (x, y, z, w).
    fn position(p: [f32; N]) -> [f32; 4];
}
struct D;
impl Cell<1> for D {
    fn jitter(c: [f32; 1]) -> [f32; 1] {
        [hash_float_to_float1(c[0])]
    }
    fn color(c: [f32; 1]) -> Vec3 {
        hash_f1_to_f3(c[0])
    }
    fn position(p: [f32; 1]) -> [f32; 4] {
        [0.0, 0.0, 0.0, p[0]]
    }
}
impl Cell<2> for D {
    fn jitter(c: [f32; 2]) -> [f32; 2] {
        hash_f2_to_f2(c)
    }
    fn color(c: [f32; 2]) -> Vec3 {
        hash_f2_to_f3(c)
    }
    fn position(p: [f32; 2]) -> [f32; 4] {
        [p[0], p[1], 0.0, 0.0]
    }
}
impl Cell<3> for D {
    fn jitter(c: [f32; 3]) -> [f32; 3] {
        hash_f3_to_f3(c)
    }
    fn color(c: [f32; 3]) -> Vec3 {
        hash_f3_to_f3(c)
    }
    fn color_with(_: [f32; 3], jitter: [f32; 3]) -> Vec3 {
        jitter
    }
    fn position(p: [f32; 3]) -> [f32; 4] {
        [p[0], p[1], p[2], 0.0]
    }
}
impl Cell<4> for D {
    fn jitter(c: [f32; 4]) -> [f32; 4] {
        hash_f4_to_f4(c)
    }
    fn color(c: [f32; 4]) -> Vec3 {
        hash_f4_to_f3(c)
    }
    fn position(p: [f32; 4]) -> [f32; 4] {
        p
    }
}

#[inline]
fn add<const N: usize>(a: [f32; N], b: [f32; N]) -> [f32; N] {
    std::array::from_fn(|i| a[i] + b[i])
}
#[inline]
fn sub<const N: usize>(a: [f32; N], b: [f32; N]) -> [f32; N] {
    std::array::from_fn(|i| a[i] - b[i])
}
#[inline]
fn scale<const N: usize>(a: [f32; N], s: f32) -> [f32; N] {
    a.map(|x| x * s)
}
#[inline]
fn dot<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    (0..N).fold(0.0, |s, i| s + a[i] * b[i])
}
#[inline]
fn mix1(a: f32, b: f32, t: f32) -> f32 {
    a + t * (b - a)
}
#[inline]
fn mixn<const N: usize>(a: [f32; N], b: [f32; N], t: f32) -> [f32; N] {
    std::array::from_fn(|i| mix1(a[i], b[i], t))
}
fn euclidean<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

fn metric_distance<const N: usize>(a: [f32; N], b: [f32; N], p: &VoronoiParams) -> f32 {
    if N == 1 {
        return (b[0] - a[0]).abs();
    }
    let d = sub(a, b).map(f32::abs);
    match p.metric {
        VoronoiMetric::Euclidean => euclidean(a, b),
        VoronoiMetric::Manhattan => reduce_add(d),
        VoronoiMetric::Chebychev => d.iter().fold(d[0], |m, &x| m.max(x)),
        VoronoiMetric::Minkowski => reduce_add(d.map(|x| x.powf(p.exponent))).powf(1.0 / p.exponent),
    }
}

/// Cycles' `reduce_add`: float4 sums pairwise in its SSE kernels, (x + y) + (z + w);
/// the order decides exact distance ties between lattice points (randomness 0).
#[inline]
fn reduce_add<const N: usize>(v: [f32; N]) -> f32 {
    if N == 4 {
        (v[0] + v[1]) + (v[2] + v[3])
    } else {
        v.iter().sum()
    }
}

/// Calls `f` with every cell offset in [-r, r]^N, x fastest (Cycles' loop nesting).
#[inline]
fn for_cells<const N: usize>(r: i32, mut f: impl FnMut([f32; N])) {
    let side = 2 * r + 1;
    let total = side.pow(N as u32);
    for t in 0..total {
        let mut k = t;
        let off = std::array::from_fn(|_| {
            let v = (k % side - r) as f32;
            k /= side;
            v
        });
        f(off);
    }
}

struct Octave {
    distance: f32,
    color: Vec3,
    position: [f32; 4],
}

fn split<const N: usize>(coord: [f32; N]) -> ([f32; N], [f32; N]) {
    let cell = coord.map(f32::floor);
    (cell, sub(coord, cell))
}

fn f1<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N>,
{
    let (cell, local) = split(coord);
    let mut min_d = f32::MAX;
    let (mut target_off, mut target_pos) = ([0.0; N], [0.0; N]);
    for_cells(1, |off: [f32; N]| {
        let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
        let d = metric_distance(point, local, p);
        if d < min_d {
            target_off = off;
            min_d = d;
            target_pos = point;
        }
    });
    Octave { distance: min_d, color: D::color(add(cell, target_off)), position: D::position(add(target_pos, cell)) }
}

fn smooth_f1<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N>,
{
    let (cell, local) = split(coord);
    let mut sd = 0.0f32;
    let mut sc = [0.0f32; 3];
    let mut sp = [0.0f32; N];
    let mut h = -1.0f32;
    for_cells(2, |off: [f32; N]| {
        let jitter = D::jitter(add(cell, off));
        let point = add(off, scale(jitter, p.randomness));
        let d = metric_distance(point, local, p);
        h = if h == -1.0 { 1.0 } else { smoothstep(0.5 + 0.5 * (sd - d) / p.smoothness) };
        let mut corr = p.smoothness * h * (1.0 - h);
        sd = mix1(sd, d, h) - corr;
        corr /= 1.0 + 3.0 * p.smoothness;
        let c = D::color_with(add(cell, off), jitter);
        sc = mixn(sc, c, h).map(|x| x - corr);
        sp = mixn(sp, point, h).map(|x| x - corr);
    });
    Octave { distance: sd, color: sc, position: D::position(add(cell, sp)) }
}

fn smoothstep(x: f32) -> f32 {
    if x < 0.0 {
        0.0
    } else if x >= 1.0 {
        1.0
    } else {
        x * x * (3.0 - 2.0 * x)
    }
}

fn f2<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N>,
{
    let (cell, local) = split(coord);
    let (mut d1, mut d2) = (f32::MAX, f32::MAX);
    let (mut off1, mut pos1, mut off2, mut pos2) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
    for_cells(1, |off: [f32; N]| {
        let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
        let d = metric_distance(point, local, p);
        if d < d1 {
            d2 = d1;
            d1 = d;
            off2 = off1;
            off1 = off;
            pos2 = pos1;
            pos1 = point;
        } else if d < d2 {
            d2 = d;
            off2 = off;
            pos2 = point;
        }
    });
    Octave { distance: d2, color: D::color(add(cell, off2)), position: D::position(add(pos2, cell)) }
}

fn distance_to_edge<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
where
    D: Cell<N>,
{
    let (cell, local) = split(coord);
    if N == 1 {
        let r = p.randomness;
        let mid = hash_float_to_float1(cell[0]) * r;
        let left = -1.0 + hash_float_to_float1(cell[0] - 1.0) * r;
        let right = 1.0 + hash_float_to_float1(cell[0] + 1.0) * r;
        let dl = ((mid + left) / 2.0 - local[0]).abs();
        let dr = ((mid + right) / 2.0 - local[0]).abs();
        return dl.min(dr);
    }
    let to_point = |off: [f32; N]| sub(add(off, scale(D::jitter(add(cell, off)), p.randomness)), local);
    let mut min_d = f32::MAX;
    let mut closest = [0.0; N];
    for_cells(1, |off: [f32; N]| {
        let v = to_point(off);
        let d = dot(v, v);
        if d < min_d {
            min_d = d;
            closest = v;
        }
    });
    min_d = f32::MAX;
    for_cells(1, |off: [f32; N]| {
        let v = to_point(off);
        let perp = sub(v, closest);
        if dot(perp, perp) > 0.0001 {
            let len = dot(perp, perp).sqrt();
            let n = perp.map(|x| x / len);
            let d = dot(add(closest, v).map(|x| x / 2.0), n);
            min_d = min_d.min(d);
        }
    });
    min_d
}

fn n_sphere_radius<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
where
    D: Cell<N>,
{
    let (cell, local) = split(coord);
    let mut closest = [0.0; N];
    let mut closest_off = [0.0; N];
    let mut min_d = f32::MAX;
    for_cells(1, |off: [f32; N]| {
        let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
        let d = euclidean(point, local);
        if d < min_d {
            min_d = d;
            closest = point;
            closest_off = off;
        }
    });
    min_d = f32::MAX;
    let mut next = [0.0; N];
    for_cells(1, |o: [f32; N]| {
        if o.iter().all(|&x| x == 0.0) {
            return;
        }
        let off = add(o, closest_off);
        let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
        let d = euclidean(closest, point);
        if d < min_d {
            min_d = d;
            next = point;
        }
    });
    euclidean(next, closest) / 2.0
}

fn fractal_x_fx<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N>,
{
    let mut amplitude = 1.0f32;
    let mut max_amplitude = 0.0f32;
    let mut sc = 1.0f32;
    let mut out = Octave { distance: 0.0, color: [0.0; 3], position: [0.0; 4] };
    let zero_input = p.detail == 0.0 || p.roughness == 0.0;
    let mut i = 0;
    while i as f32 <= p.detail.ceil() {
        let c = scale(coord, sc);
        let octave = match p.feature {
            VoronoiFeature::F2 => f2(p, c),
            VoronoiFeature::SmoothF1 if p.smoothness != 0.0 => smooth_f1(p, c),
            _ => f1(p, c),
        };
        if zero_input {
            max_amplitude = 1.0;
            out = octave;
            break;
        }
        if i as f32 <= p.detail {
            max_amplitude += amplitude;
            out.distance += octave.distance * amplitude;
            out.color = std::array::from_fn(|k| out.color[k] + octave.color[k] * amplitude);
            out.position = mixn(out.position, octave.position.map(|x| x / sc), amplitude);
            sc *= p.lacunarity;
            amplitude *= p.roughness;
        } else {
            let rem = p.detail - p.detail.floor();
            if rem != 0.0 {
                max_amplitude = mix1(max_amplitude, max_amplitude + amplitude, rem);
                out.distance = mix1(out.distance, out.distance + octave.distance * amplitude, rem);
                out.color = std::array::from_fn(|k| mix1(out.color[k], out.color[k] + octave.color[k] * amplitude, rem));
                let inner = mixn(out.position, octave.position.map(|x| x / sc), amplitude);
                out.position = mixn(out.position, inner, rem);
            }
        }
        i += 1;
    }
    if p.normalize {
        out.distance /= max_amplitude * p.max_distance;
        out.color = out.color.map(|x| x / max_amplitude);
    }
    out.position = out.position.map(|x| if p.scale != 0.0 { x / p.scale } else { 0.0 });
    out
}

fn fractal_distance_to_edge<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
where
    D: Cell<N>,
{
    let mut amplitude = 1.0f32;
    let mut max_amplitude = p.max_distance;
    let mut sc = 1.0f32;
    let mut distance = 8.0f32;
    let zero_input = p.detail == 0.0 || p.roughness == 0.0;
    let mut i = 0;
    while i as f32 <= p.detail.ceil() {
        let od = distance_to_edge(p, scale(coord, sc));
        if zero_input {
            distance = od;
            break;
        }
        if i as f32 <= p.detail {
            max_amplitude = mix1(max_amplitude, p.max_distance / sc, amplitude);
            distance = mix1(distance, distance.min(od / sc), amplitude);
            sc *= p.lacunarity;
            amplitude *= p.roughness;
        } else {
            let rem = p.detail - p.detail.floor();
            if rem != 0.0 {
                let la = mix1(max_amplitude, p.max_distance / sc, amplitude);
                max_amplitude = mix1(max_amplitude, la, rem);
                let ld = mix1(distance, distance.min(od / sc), amplitude);
                distance = mix1(distance, distance.min(ld), rem);
            }
        }
        i += 1;
    }
    if p.normalize {
        distance /= max_amplitude;
    }
    distance
}

impl VoronoiParams {
    /// Node settings as the sockets give them; clamped here as Cycles clamps them.
    #[allow(clippy::too_many_arguments)]
    pub fn new(feature: VoronoiFeature, metric: VoronoiMetric, normalize: bool, scale: f32, detail: f32, roughness: f32, lacunarity: f32, smoothness: f32, exponent: f32, randomness: f32) -> Self {
        VoronoiParams {
            feature,
            metric,
            normalize,
            scale,
            detail: detail.clamp(0.0, 15.0),
            roughness: roughness.clamp(0.0, 1.0),
            lacunarity,
            smoothness: (smoothness / 2.0).clamp(0.0, 0.5),
            exponent,
            randomness: randomness.clamp(0.0, 1.0),
            max_distance: 0.0,
        }
    }
}

fn run<const N: usize>(mut p: VoronoiParams, coord: [f32; N]) -> VoronoiOutput
where
    D: Cell<N>,
{
    match p.feature {
        VoronoiFeature::DistanceToEdge => {
            p.max_distance = 0.5 + 0.5 * p.randomness;
            VoronoiOutput { distance: fractal_distance_to_edge(&p, coord), ..Default::default() }
        }
        VoronoiFeature::NSphereRadius => VoronoiOutput { radius: n_sphere_radius(&p, coord), ..Default::default() },
        _ => {
            let f2_factor = if p.feature == VoronoiFeature::F2 { 2.0 } else { 1.0 };
            let half = 0.5 + 0.5 * p.randomness;
            p.max_distance = metric_distance([0.0; N], [half; N], &p) * f2_factor;
            let o = fractal_x_fx(&p, coord);
            VoronoiOutput { distance: o.distance, color: o.color, position: [o.position[0], o.position[1], o.position[2]], w: o.position[3], radius: 0.0 }
        }
    }
}

/// The Voronoi Texture node on one point: `dimensions` 1-4 (`vector` for 2-4, `w` for 1
/// and 4).
pub fn voronoi_texture(dimensions: u8, vector: Vec3, w: f32, p: VoronoiParams) -> VoronoiOutput {
    let v = vector.map(|x| x * p.scale);
    let w = w * p.scale;
    match dimensions {
        1 => run(p, [w]),
        2 => run(p, [v[0], v[1]]),
        4 => run(p, [v[0], v[1], v[2], w]),
        _ => run(p, v),
    }
}

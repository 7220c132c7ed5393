//! Voronoi Texture with Cycles' semantics (`kernel/svm/voronoi.h`): F1, F2, Smooth F1,
//! Distance to Edge and N-Sphere Radius in 1 to 4 dimensions, four distance metrics,
//! randomness, and the fractal (detail/roughness/lacunarity) layering with normalize.
//!
//! One generic implementation over `[f32; N]` points; cells are visited in Cycles' order
//! (x fastest) because ties keep the first cell found.
//!
//! Speed: each feature first hashes its whole block of cells (3^N, or 5^N for Smooth F1)
//! into struct-of-arrays on the stack and computes all distances, in loops without
//! dependencies between cells that the compiler vectorises (8 cells per AVX2
//! instruction); only the choice of the winning cell (and Smooth F1's blend) runs cell
//! by cell, in Cycles' order. Distance to Edge and N-Sphere Radius hash each cell once,
//! and a 3D cell's colour is its jitter hash, reused. Each thread keeps its last hashed
//! blocks (`BlockCache`): the points a Bump node and displacement-as-bump evaluate lie in
//! the same cells, so their hashes are computed once. Every value is the same bits as the
//! cell-by-cell evaluation (tests/noise_speed.rs).

use super::math::V3;
use super::white_noise::{
    hash_f1_to_f1, hash_f1_to_f3, hash_f2_to_f2, hash_f2_to_f3, hash_f3_to_f3, hash_f4_to_f3,
    hash_f4_to_f4,
};

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
    pub color: V3,
    pub position: V3,
    pub w: f32,
    pub radius: f32,
}

trait Cell<const N: usize> {
    fn jitter(cell: [f32; N]) -> [f32; N];
    fn color(cell: [f32; N]) -> V3;
    /// The cell's colour given its jitter hash (in 3D both are the same hash).
    #[inline(always)]
    fn color_with(cell: [f32; N], _jitter: [f32; N]) -> V3 {
        Self::color(cell)
    }
    /// Cycles' `voronoi_position`: where the N components land in (x, y, z, w).
    fn position(p: [f32; N]) -> [f32; 4];
}
struct D;
impl Cell<1> for D {
    #[inline(always)]
    fn jitter(c: [f32; 1]) -> [f32; 1] {
        [hash_f1_to_f1(c[0])]
    }
    #[inline(always)]
    fn color(c: [f32; 1]) -> V3 {
        hash_f1_to_f3(c[0])
    }
    fn position(p: [f32; 1]) -> [f32; 4] {
        [0.0, 0.0, 0.0, p[0]]
    }
}
impl Cell<2> for D {
    #[inline(always)]
    fn jitter(c: [f32; 2]) -> [f32; 2] {
        hash_f2_to_f2(c)
    }
    #[inline(always)]
    fn color(c: [f32; 2]) -> V3 {
        hash_f2_to_f3(c)
    }
    fn position(p: [f32; 2]) -> [f32; 4] {
        [p[0], p[1], 0.0, 0.0]
    }
}
impl Cell<3> for D {
    #[inline(always)]
    fn jitter(c: [f32; 3]) -> [f32; 3] {
        hash_f3_to_f3(c)
    }
    #[inline(always)]
    fn color(c: [f32; 3]) -> V3 {
        hash_f3_to_f3(c)
    }
    #[inline(always)]
    fn color_with(_: [f32; 3], jitter: [f32; 3]) -> V3 {
        jitter
    }
    fn position(p: [f32; 3]) -> [f32; 4] {
        [p[0], p[1], p[2], 0.0]
    }
}
impl Cell<4> for D {
    #[inline(always)]
    fn jitter(c: [f32; 4]) -> [f32; 4] {
        hash_f4_to_f4(c)
    }
    #[inline(always)]
    fn color(c: [f32; 4]) -> V3 {
        hash_f4_to_f3(c)
    }
    fn position(p: [f32; 4]) -> [f32; 4] {
        p
    }
}

#[inline(always)]
fn add<const N: usize>(a: [f32; N], b: [f32; N]) -> [f32; N] {
    std::array::from_fn(|i| a[i] + b[i])
}
#[inline(always)]
fn sub<const N: usize>(a: [f32; N], b: [f32; N]) -> [f32; N] {
    std::array::from_fn(|i| a[i] - b[i])
}
#[inline(always)]
fn scale<const N: usize>(a: [f32; N], s: f32) -> [f32; N] {
    a.map(|x| x * s)
}
#[inline(always)]
fn dot<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    (0..N).fold(0.0, |s, i| s + a[i] * b[i])
}
#[inline(always)]
fn mix1(a: f32, b: f32, t: f32) -> f32 {
    a + t * (b - a)
}
#[inline(always)]
fn mixn<const N: usize>(a: [f32; N], b: [f32; N], t: f32) -> [f32; N] {
    std::array::from_fn(|i| mix1(a[i], b[i], t))
}
#[inline(always)]
fn euclidean<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

#[inline(always)]
fn manhattan<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    reduce_add(sub(a, b).map(f32::abs))
}
#[inline(always)]
fn chebychev<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
    let d = sub(a, b).map(f32::abs);
    d.iter().fold(d[0], |m, &x| m.max(x))
}
fn minkowski<const N: usize>(a: [f32; N], b: [f32; N], exponent: f32) -> f32 {
    reduce_add(sub(a, b).map(|x| x.abs().powf(exponent))).powf(1.0 / exponent)
}

fn metric_distance<const N: usize>(a: [f32; N], b: [f32; N], p: &VoronoiParams) -> f32 {
    if N == 1 {
        return (b[0] - a[0]).abs();
    }
    match p.metric {
        VoronoiMetric::Euclidean => euclidean(a, b),
        VoronoiMetric::Manhattan => manhattan(a, b),
        VoronoiMetric::Chebychev => chebychev(a, b),
        VoronoiMetric::Minkowski => minkowski(a, b, p.exponent),
    }
}

/// Cycles' `reduce_add`: float4 sums pairwise in its SSE kernels, (x + y) + (z + w);
/// the order decides exact distance ties between lattice points (randomness 0).
#[inline(always)]
fn reduce_add<const N: usize>(v: [f32; N]) -> f32 {
    if N == 4 {
        (v[0] + v[1]) + (v[2] + v[3])
    } else {
        v.iter().sum()
    }
}

/// N coordinates of P cells, one array per axis. P is the cell count rounded up to a
/// multiple of 8 (one AVX2 vector) so that the loops over cells vectorise without a
/// scalar remainder; the padding cells are hashed but never read.
type Soa<const N: usize, const P: usize> = [[f32; P]; N];

#[inline(always)]
fn at<const N: usize, const P: usize>(a: &Soa<N, P>, t: usize) -> [f32; N] {
    std::array::from_fn(|i| a[i][t])
}

/// The (2r+1)^N cells around `cell`, x fastest (Cycles' loop nesting, which decides
/// ties): their offsets `base + o` for o in [-r, r]^N, their jitter hashes and their
/// jittered points relative to `cell`.
#[derive(Clone, Copy)]
struct Block<const N: usize, const P: usize> {
    /// The number of real cells, (2r+1)^N <= P.
    m: usize,
    off: Soa<N, P>,
    jitter: Soa<N, P>,
    point: Soa<N, P>,
}

impl<const N: usize, const P: usize> Block<N, P>
where
    D: Cell<N>,
{
    const EMPTY: Self = Block {
        m: 0,
        off: [[0.0; P]; N],
        jitter: [[0.0; P]; N],
        point: [[0.0; P]; N],
    };

    /// Hashes the block of radius `r` around `cell + base` in place.
    #[inline(always)]
    fn fill(&mut self, cell: [f32; N], base: [f32; N], r: i32, randomness: f32) {
        let side = 2 * r + 1;
        let m = side.pow(N as u32) as usize;
        debug_assert!(m <= P && P.is_multiple_of(8));
        self.m = m;
        let mut stride = 1;
        for (i, axis) in self.off.iter_mut().enumerate() {
            for (t, o) in axis.iter_mut().enumerate().take(m) {
                *o = base[i] + ((t as i32 / stride) % side - r) as f32;
            }
            stride *= side;
        }
        for t in 0..P {
            let o = at(&self.off, t);
            let j = D::jitter(add(cell, o));
            let q = add(o, scale(j, randomness));
            for i in 0..N {
                self.jitter[i][t] = j[i];
                self.point[i][t] = q[i];
            }
        }
    }

    /// `metric_distance(point, local)` of every cell.
    #[inline(always)]
    fn distances(&self, local: [f32; N], p: &VoronoiParams) -> [f32; P] {
        let mut d = [0.0f32; P];
        let pt = &self.point;
        // One loop per metric (not a match per cell) so each loop vectorises.
        if N == 1 {
            d.iter_mut()
                .enumerate()
                .for_each(|(t, d)| *d = (local[0] - pt[0][t]).abs());
            return d;
        }
        match p.metric {
            VoronoiMetric::Euclidean => d
                .iter_mut()
                .enumerate()
                .for_each(|(t, d)| *d = euclidean(at(pt, t), local)),
            VoronoiMetric::Manhattan => d
                .iter_mut()
                .enumerate()
                .for_each(|(t, d)| *d = manhattan(at(pt, t), local)),
            VoronoiMetric::Chebychev => d
                .iter_mut()
                .enumerate()
                .for_each(|(t, d)| *d = chebychev(at(pt, t), local)),
            VoronoiMetric::Minkowski => d
                .iter_mut()
                .take(self.m)
                .enumerate()
                .for_each(|(t, d)| *d = minkowski(at(pt, t), local, p.exponent)),
        }
        d
    }
}

/// How many hashed blocks a thread keeps per block shape.
const WAYS: usize = 4;

/// What a block's hashes depend on, as bits (so -0 and NaN cells are keys like others).
#[derive(Clone, Copy, PartialEq, Eq)]
struct BlockKey<const N: usize> {
    cell: [u32; N],
    base: [u32; N],
    r: i32,
    randomness: u32,
}

/// The blocks a thread hashed last. A Bump node evaluates its height at the shading
/// point and two points a ray differential away, and Cycles' displacement-as-bump does it
/// again: those points almost always lie in the same cell, so the 3^N or 5^N cell hashes
/// (most of a Voronoi evaluation) are computed once for all of them. Round-robin
/// replacement; a hit returns the very values a new hashing would.
struct BlockCache<const N: usize, const P: usize> {
    keys: [Option<BlockKey<N>>; WAYS],
    blocks: Vec<Block<N, P>>,
    next: usize,
}

impl<const N: usize, const P: usize> BlockCache<N, P>
where
    D: Cell<N>,
{
    fn new() -> Box<Self> {
        Box::new(BlockCache {
            keys: [None; WAYS],
            blocks: vec![Block::EMPTY; WAYS],
            next: 0,
        })
    }

    #[inline(always)]
    fn get(&mut self, cell: [f32; N], base: [f32; N], r: i32, randomness: f32) -> &Block<N, P> {
        let key = Some(BlockKey {
            cell: bits(cell),
            base: bits(base),
            r,
            randomness: randomness.to_bits(),
        });
        let i = match self.keys.iter().position(|k| *k == key) {
            Some(i) => i,
            None => {
                let i = self.next;
                self.next = (i + 1) % WAYS;
                self.keys[i] = key;
                self.blocks[i].fill(cell, base, r, randomness);
                i
            }
        };
        &self.blocks[i]
    }
}

#[inline(always)]
fn bits<const N: usize>(v: [f32; N]) -> [u32; N] {
    v.map(f32::to_bits)
}

/// The hashed block of radius `r` around `cell + base`, from this thread's cache of
/// blocks of its shape (a thread-local per (N, P), hence a trait per shape).
trait Blocks<const N: usize, const P: usize> {
    fn with<R>(
        cell: [f32; N],
        base: [f32; N],
        r: i32,
        randomness: f32,
        f: impl FnOnce(&Block<N, P>) -> R,
    ) -> R;
}

macro_rules! block_caches {
    ($(($n:literal, $p:literal)),*) => {$(
        impl Blocks<$n, $p> for D {
            #[inline(always)]
            fn with<R>(
                cell: [f32; $n],
                base: [f32; $n],
                r: i32,
                randomness: f32,
                f: impl FnOnce(&Block<$n, $p>) -> R,
            ) -> R {
                thread_local! {
                    static CACHE: std::cell::RefCell<Option<Box<BlockCache<$n, $p>>>> =
                        const { std::cell::RefCell::new(None) };
                }
                CACHE.with(|c| {
                    let mut c = c.borrow_mut();
                    f(c.get_or_insert_with(BlockCache::new).get(cell, base, r, randomness))
                })
            }
        }
    )*};
}
// The shapes `voronoi_texture` uses: (N, 3^N) and (N, 5^N) rounded up to 8.
block_caches!(
    (1, 8),
    (2, 16),
    (2, 32),
    (3, 32),
    (3, 128),
    (4, 88),
    (4, 632)
);

/// The first index among the first `m` of the smallest value below `f32::MAX`, as a
/// strict `<` scan in order finds it (NaN never wins).
#[inline(always)]
fn first_min(d: &[f32], m: usize) -> Option<usize> {
    let mut min_d = f32::MAX;
    let mut best = None;
    for (t, &x) in d[..m].iter().enumerate() {
        if x < min_d {
            min_d = x;
            best = Some(t);
        }
    }
    best
}

struct Octave {
    distance: f32,
    color: V3,
    position: [f32; 4],
}

#[inline(always)]
fn split<const N: usize>(coord: [f32; N]) -> ([f32; N], [f32; N]) {
    let cell = coord.map(f32::floor);
    (cell, sub(coord, cell))
}

fn f1<const N: usize, const P: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N> + Blocks<N, P>,
{
    let (cell, local) = split(coord);
    <D as Blocks<N, P>>::with(cell, [0.0; N], 1, p.randomness, |b| {
        let d = b.distances(local, p);
        match first_min(&d, b.m) {
            Some(t) => {
                let target = add(cell, at(&b.off, t));
                Octave {
                    distance: d[t],
                    color: D::color_with(target, at(&b.jitter, t)),
                    position: D::position(add(at(&b.point, t), cell)),
                }
            }
            // No cell nearer than f32::MAX (NaN input): the initial target, offset 0.
            None => Octave {
                distance: f32::MAX,
                color: D::color(add(cell, [0.0; N])),
                position: D::position(add([0.0; N], cell)),
            },
        }
    })
}

fn smooth_f1<const N: usize, const P: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N> + Blocks<N, P>,
{
    let (cell, local) = split(coord);
    <D as Blocks<N, P>>::with(cell, [0.0; N], 2, p.randomness, |b| {
        let dist = b.distances(local, p);
        let mut sd = 0.0f32;
        let mut sc = [0.0f32; 3];
        let mut sp = [0.0f32; N];
        // Cells with smoothstep argument x < 0 (h = 0, most of the 5^N) leave every sum
        // unchanged, so they are skipped, which takes them off the serial dependency
        // chain (and a cell's colour is only hashed when it blends; in 3D it is the
        // jitter hash). Exactly unchanged: with h = 0 both corrections are +0 and each
        // sum s becomes (s + 0 * (v - s)) - 0, which is s when v - s is finite (all
        // distances are, and the colours, points and sums are bounded) and s is not -0.
        // Non-short-circuit `all`, so it vectorises.
        let finite = dist[..b.m].iter().fold(true, |a, d| a & (d.abs() < 1e30));
        let neg_zero = |x: f32| x.to_bits() == (-0.0f32).to_bits();
        let mut any_neg_zero = false;
        // A cheaper sufficient test for that skip, without the division: the blend is a
        // smooth minimum, never above the least distance so far (exactly; in floats by at
        // most a few ulps per cell, under 5e-3 over 625 cells for distances below 16, which all
        // metrics but Minkowski keep here), so a cell farther than `least + margin`
        // has x < -0.49 and is skipped by the exact test too.
        let bounded = finite && p.metric != VoronoiMetric::Minkowski;
        let margin = 2.0 * p.smoothness + 0.01;
        let mut least = f32::INFINITY;
        for t in 0..b.m {
            let d = dist[t];
            if bounded && !any_neg_zero && d > least + margin {
                continue;
            }
            least = least.min(d);
            // The first cell blends with h = 1; smoothstep never gives Cycles' marker -1.
            let h = if t == 0 {
                1.0
            } else {
                let x = 0.5 + 0.5 * (sd - d) / p.smoothness;
                if x < 0.0 && finite && !any_neg_zero {
                    continue;
                }
                smoothstep(x)
            };
            let color = D::color_with(add(cell, at(&b.off, t)), at(&b.jitter, t));
            let mut corr = p.smoothness * h * (1.0 - h);
            sd = mix1(sd, d, h) - corr;
            corr /= 1.0 + 3.0 * p.smoothness;
            sc = mixn(sc, color, h).map(|x| x - corr);
            sp = mixn(sp, at(&b.point, t), h).map(|x| x - corr);
            any_neg_zero =
                neg_zero(sd) || sc.iter().any(|&x| neg_zero(x)) || sp.iter().any(|&x| neg_zero(x));
        }
        Octave {
            distance: sd,
            color: sc,
            position: D::position(add(cell, sp)),
        }
    })
}

#[inline(always)]
fn smoothstep(x: f32) -> f32 {
    if x < 0.0 {
        0.0
    } else if x >= 1.0 {
        1.0
    } else {
        x * x * (3.0 - 2.0 * x)
    }
}

fn f2<const N: usize, const P: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
where
    D: Cell<N> + Blocks<N, P>,
{
    let (cell, local) = split(coord);
    <D as Blocks<N, P>>::with(cell, [0.0; N], 1, p.randomness, |b| {
        let dist = b.distances(local, p);
        let (mut d1, mut d2) = (f32::MAX, f32::MAX);
        let (mut t1, mut t2) = (None, None);
        for (t, &d) in dist[..b.m].iter().enumerate() {
            if d < d1 {
                d2 = d1;
                d1 = d;
                t2 = t1;
                t1 = Some(t);
            } else if d < d2 {
                d2 = d;
                t2 = Some(t);
            }
        }
        // Without a second cell (NaN input) the target is the initial one, offset 0.
        let (off2, pos2, jitter2) = match t2 {
            Some(t) => (at(&b.off, t), at(&b.point, t), Some(at(&b.jitter, t))),
            None => ([0.0; N], [0.0; N], None),
        };
        let target = add(cell, off2);
        let color = match jitter2 {
            Some(j) => D::color_with(target, j),
            None => D::color(target),
        };
        Octave {
            distance: d2,
            color,
            position: D::position(add(pos2, cell)),
        }
    })
}

fn distance_to_edge<const N: usize, const P: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
where
    D: Cell<N> + Blocks<N, P>,
{
    let (cell, local) = split(coord);
    if N == 1 {
        let r = p.randomness;
        let mid = hash_f1_to_f1(cell[0]) * r;
        let left = -1.0 + hash_f1_to_f1(cell[0] - 1.0) * r;
        let right = 1.0 + hash_f1_to_f1(cell[0] + 1.0) * r;
        let dl = ((mid + left) / 2.0 - local[0]).abs();
        let dr = ((mid + right) / 2.0 - local[0]).abs();
        return dl.min(dr);
    }
    // Both passes see the same cells: hash them once.
    <D as Blocks<N, P>>::with(cell, [0.0; N], 1, p.randomness, |b| {
        let mut v = [[0.0f32; P]; N];
        let mut d = [0.0f32; P];
        for t in 0..P {
            let vt = sub(at(&b.point, t), local);
            d[t] = dot(vt, vt);
            for i in 0..N {
                v[i][t] = vt[i];
            }
        }
        let closest = first_min(&d, b.m).map_or([0.0; N], |t| at(&v, t));
        // Distance to each bisector; cells too close to the nearest one give +inf, which
        // `min` passes over exactly as the skipped cell.
        let mut e = [0.0f32; P];
        for (t, e) in e.iter_mut().enumerate() {
            let vt = at(&v, t);
            let perp = sub(vt, closest);
            *e = if dot(perp, perp) > 0.0001 {
                let len = dot(perp, perp).sqrt();
                let n = perp.map(|x| x / len);
                dot(add(closest, vt).map(|x| x / 2.0), n)
            } else {
                f32::INFINITY
            };
        }
        e[..b.m].iter().fold(f32::MAX, |m, &x| m.min(x))
    })
}

fn n_sphere_radius<const N: usize, const P: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
where
    D: Cell<N> + Blocks<N, P>,
{
    let (cell, local) = split(coord);
    let (closest, closest_off) = <D as Blocks<N, P>>::with(cell, [0.0; N], 1, p.randomness, |b| {
        let mut d = [0.0f32; P];
        for (t, d) in d.iter_mut().enumerate() {
            *d = euclidean(at(&b.point, t), local);
        }
        first_min(&d, b.m).map_or(([0.0; N], [0.0; N]), |t| (at(&b.point, t), at(&b.off, t)))
    });
    // The cells around the closest one, except itself (the middle of the block).
    let next = <D as Blocks<N, P>>::with(cell, closest_off, 1, p.randomness, |b2| {
        let mut d = [0.0f32; P];
        for (t, d) in d.iter_mut().enumerate() {
            *d = euclidean(closest, at(&b2.point, t));
        }
        d[(b2.m - 1) / 2] = f32::NAN;
        first_min(&d, b2.m).map_or([0.0; N], |t| at(&b2.point, t))
    });
    euclidean(next, closest) / 2.0
}

fn fractal_x_fx<const N: usize, const P3: usize, const P5: usize>(
    p: &VoronoiParams,
    coord: [f32; N],
) -> Octave
where
    D: Cell<N> + Blocks<N, P3> + Blocks<N, P5>,
{
    let mut amplitude = 1.0f32;
    let mut max_amplitude = 0.0f32;
    let mut sc = 1.0f32;
    let mut out = Octave {
        distance: 0.0,
        color: [0.0; 3],
        position: [0.0; 4],
    };
    let zero_input = p.detail == 0.0 || p.roughness == 0.0;
    let mut i = 0;
    while i as f32 <= p.detail.ceil() {
        let c = scale(coord, sc);
        let octave = match p.feature {
            VoronoiFeature::F2 => f2::<N, P3>(p, c),
            VoronoiFeature::SmoothF1 if p.smoothness != 0.0 => smooth_f1::<N, P5>(p, c),
            _ => f1::<N, P3>(p, c),
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
                out.distance = mix1(
                    out.distance,
                    out.distance + octave.distance * amplitude,
                    rem,
                );
                out.color = std::array::from_fn(|k| {
                    mix1(
                        out.color[k],
                        out.color[k] + octave.color[k] * amplitude,
                        rem,
                    )
                });
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
    out.position = out
        .position
        .map(|x| if p.scale != 0.0 { x / p.scale } else { 0.0 });
    out
}

fn fractal_distance_to_edge<const N: usize, const P3: usize>(
    p: &VoronoiParams,
    coord: [f32; N],
) -> f32
where
    D: Cell<N> + Blocks<N, P3>,
{
    let mut amplitude = 1.0f32;
    let mut max_amplitude = p.max_distance;
    let mut sc = 1.0f32;
    let mut distance = 8.0f32;
    let zero_input = p.detail == 0.0 || p.roughness == 0.0;
    let mut i = 0;
    while i as f32 <= p.detail.ceil() {
        let od = distance_to_edge::<N, P3>(p, scale(coord, sc));
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
    pub fn new(
        feature: VoronoiFeature,
        metric: VoronoiMetric,
        normalize: bool,
        scale: f32,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
        smoothness: f32,
        exponent: f32,
        randomness: f32,
    ) -> Self {
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

/// `P3` and `P5`: 3^N and 5^N cells (the neighbourhoods of radius 1 and 2) rounded up to
/// a multiple of 8. Not inlined,
/// so each dimension has a stack frame of its own size.
#[inline(never)]
fn run<const N: usize, const P3: usize, const P5: usize>(
    mut p: VoronoiParams,
    coord: [f32; N],
) -> VoronoiOutput
where
    D: Cell<N> + Blocks<N, P3> + Blocks<N, P5>,
{
    match p.feature {
        VoronoiFeature::DistanceToEdge => {
            p.max_distance = 0.5 + 0.5 * p.randomness;
            VoronoiOutput {
                distance: fractal_distance_to_edge::<N, P3>(&p, coord),
                ..Default::default()
            }
        }
        VoronoiFeature::NSphereRadius => VoronoiOutput {
            radius: n_sphere_radius::<N, P3>(&p, coord),
            ..Default::default()
        },
        _ => {
            let f2_factor = if p.feature == VoronoiFeature::F2 {
                2.0
            } else {
                1.0
            };
            let half = 0.5 + 0.5 * p.randomness;
            p.max_distance = metric_distance([0.0; N], [half; N], &p) * f2_factor;
            let o = fractal_x_fx::<N, P3, P5>(&p, coord);
            VoronoiOutput {
                distance: o.distance,
                color: o.color,
                position: [o.position[0], o.position[1], o.position[2]],
                w: o.position[3],
                radius: 0.0,
            }
        }
    }
}

/// The Voronoi Texture node on one point: `dimensions` 1-4 (`vector` for 2-4, `w` for 1
/// and 4).
pub fn voronoi_texture(dimensions: u8, vector: V3, w: f32, p: VoronoiParams) -> VoronoiOutput {
    let v = vector.map(|x| x * p.scale);
    let w = w * p.scale;
    match dimensions {
        1 => run::<1, 8, 8>(p, [w]),
        2 => run::<2, 16, 32>(p, [v[0], v[1]]),
        4 => run::<4, 88, 632>(p, [v[0], v[1], v[2], w]),
        _ => run::<3, 32, 128>(p, v),
    }
}

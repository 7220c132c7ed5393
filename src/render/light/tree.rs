//! Light selection as Cycles 4.x does it: each shading point takes one light sample, from
//! one emitter drawn by the light tree (Conty and Kulla's many-lights tree with Cycles'
//! changes: the average of a lower and an upper bound of each node's importance, and a
//! leaf of distant lights beside the local ones), or, with the tree turned off, from a
//! flat distribution (triangles by area, lights alike).
//!
//! This is not only about noise. Clamping acts on a light sample divided by its selection
//! probability, so with several lights Cycles' defaults (indirect clamp 10) darken a
//! scene by an amount that depends on how lights are picked; a renderer that sampled
//! every light at every vertex renders the same scene 1.5-3% brighter.

use std::f32::consts::{FRAC_PI_2, PI};

use crate::render::math::{vec3, Vec3, V3};

/// Cycles' max_lights_in_leaf (LightManager::device_update_tree).
const MAX_IN_LEAF: usize = 8;
/// Cycles' LightTreeBucket::num_buckets.
const BUCKETS: usize = 12;

/// What an emitter is: what light sampling draws once the emitter is picked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pick {
    /// Index into the scene's lights.
    Lamp(u32),
    /// The world's importance map.
    World,
    /// One emissive triangle (scene primitive index), sampled over its area.
    Triangle(u32),
}

/// Where light selection looks from (Cycles' light tree `P` and `N_or_D`).
#[derive(Clone, Copy, Debug)]
pub enum Viewer {
    /// A shading point with its normal (zero for none); `trans`: its BSDF transmits.
    Point { p: V3, n: V3, trans: bool },
    /// A ray segment in a volume from `p` along unit `d` for `t` (Cycles'
    /// in_volume_segment): direct light is sampled somewhere along it.
    Segment { p: V3, d: V3, t: f32 },
}

/// The geometry an emitter's importance is computed from (Cycles' *_light_tree_parameters).
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// Point or spot light. `spot_smooth`: Cycles' spot.spot_smooth (None for a point).
    Point {
        pos: Vec3,
        radius: f32,
        sphere: bool,
        spot_smooth: Option<f32>,
    },
    /// Area light: centre and full extents along its two axes.
    Area {
        pos: Vec3,
        eu: Vec3,
        ev: Vec3,
    },
    /// Sun: the cone's axis is the direction its light travels.
    Distant,
    World,
    Triangle {
        v: [Vec3; 3],
    },
    /// An emissive object: the root node of its triangles' subtree.
    Mesh {
        root: u32,
    },
}

/// Cycles' OrientationBounds: the emitters' normals lie within `theta_o` of `axis`, and
/// they emit within `theta_e` of their normals.
#[derive(Clone, Copy, Debug)]
pub struct Cone {
    pub axis: Vec3,
    pub theta_o: f32,
    pub theta_e: f32,
}

impl Cone {
    const EMPTY: Cone = Cone {
        axis: Vec3::ZERO,
        theta_o: f32::MIN_POSITIVE,
        theta_e: f32::MIN_POSITIVE,
    };

    fn is_empty(&self) -> bool {
        self.axis.is_zero()
    }

    /// The orientation term of the split cost (Eq. 1 of the paper, as Cycles has it).
    fn measure(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let theta_w = (self.theta_o + self.theta_e).min(PI);
        let (s, c) = self.theta_o.sin_cos();
        2.0 * PI * (1.0 - c)
            + FRAC_PI_2
                * (2.0 * theta_w * s
                    - (self.theta_o - 2.0 * theta_w).cos()
                    - 2.0 * self.theta_o * s
                    + c)
    }

    fn merge(a: Cone, b: Cone) -> Cone {
        if a.is_empty() {
            return b;
        }
        if b.is_empty() {
            return a;
        }
        let (a, b) = if b.theta_o > a.theta_o {
            (b, a)
        } else {
            (a, b)
        };
        let cos_ab = a.axis.dot(b.axis);
        let theta_d = cos_ab.clamp(-1.0, 1.0).acos();
        let theta_e = a.theta_e.max(b.theta_e);
        if a.theta_o + 5e-4 >= PI.min(theta_d + b.theta_o) {
            return Cone {
                axis: a.axis,
                theta_o: a.theta_o,
                theta_e,
            };
        }
        let theta_o = (theta_d + a.theta_o + b.theta_o) * 0.5;
        if theta_o >= PI {
            return Cone {
                axis: a.axis,
                theta_o: PI,
                theta_e,
            };
        }
        let axis = if cos_ab < -0.9995 {
            a.axis.basis().0
        } else {
            let theta_r = theta_o - a.theta_o;
            let ortho = (b.axis - a.axis * cos_ab).normalize();
            a.axis * theta_r.cos() + ortho * theta_r.sin()
        };
        Cone {
            axis,
            theta_o,
            theta_e,
        }
    }
}

/// A cone's trigonometry, computed once when the tree is built: every importance
/// evaluation needs it (five per light sample and five per MIS weight in a scene of
/// four lights), and sin, cos of the same angles gives the same bits either way.
#[derive(Clone, Copy, Debug)]
struct ConeTrig {
    sin_o: f32,
    cos_o: f32,
    /// cos(theta_o + theta_e)
    cos_o_plus_e: f32,
    /// cos(theta_e - theta_o)
    cos_e_minus_o: f32,
    cos_e: f32,
}

impl ConeTrig {
    /// Placeholder until `LightTree::build` fills it in at the end.
    const UNSET: ConeTrig = ConeTrig {
        sin_o: f32::NAN,
        cos_o: f32::NAN,
        cos_o_plus_e: f32::NAN,
        cos_e_minus_o: f32::NAN,
        cos_e: f32::NAN,
    };

    fn of(c: &Cone) -> ConeTrig {
        let (sin_o, cos_o) = c.theta_o.sin_cos();
        ConeTrig {
            sin_o,
            cos_o,
            cos_o_plus_e: (c.theta_o + c.theta_e).cos(),
            cos_e_minus_o: (c.theta_e - c.theta_o).cos(),
            cos_e: c.theta_e.cos(),
        }
    }

    /// The trigonometry of the cone with theta_o set to 0 (a point light's disk facing
    /// the viewer): sin 0 = 0 and cos 0 = 1 exactly, and theta_e +- 0 is theta_e.
    fn with_zero_theta_o(self) -> ConeTrig {
        ConeTrig {
            sin_o: 0.0,
            cos_o: 1.0,
            cos_o_plus_e: self.cos_e,
            cos_e_minus_o: self.cos_e,
            cos_e: self.cos_e,
        }
    }
}

/// Cycles' LightTreeMeasure: bounds, orientation and energy of a cluster.
#[derive(Clone, Copy, Debug)]
pub struct Measure {
    pub bmin: Vec3,
    pub bmax: Vec3,
    pub cone: Cone,
    pub energy: f32,
}

impl Measure {
    pub const EMPTY: Measure = Measure {
        bmin: Vec3::splat(f32::INFINITY),
        bmax: Vec3::splat(f32::NEG_INFINITY),
        cone: Cone::EMPTY,
        energy: 0.0,
    };

    pub fn new(points: &[Vec3], cone: Cone, energy: f32) -> Measure {
        let mut m = Measure {
            cone,
            energy,
            ..Measure::EMPTY
        };
        for &p in points {
            m.grow(p);
        }
        m
    }

    fn grow(&mut self, p: Vec3) {
        self.bmin = self.bmin.min(p);
        self.bmax = self.bmax.max(p);
    }

    fn add(&mut self, o: &Measure) {
        if o.energy == 0.0 {
            return;
        }
        self.bmin = self.bmin.min(o.bmin);
        self.bmax = self.bmax.max(o.bmax);
        self.cone = Cone::merge(self.cone, o.cone);
        self.energy += o.energy;
    }

    /// The surface area orientation heuristic (Eq. 2 of the paper).
    fn cost(&self) -> f32 {
        if self.energy == 0.0 {
            return 0.0;
        }
        let d = self.bmax - self.bmin;
        let valid = (0..3).all(|k| self.bmin[k] <= self.bmax[k]);
        let area = if valid {
            2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
        } else {
            0.0
        };
        let area_measure = if area == 0.0 { d.length() } else { area };
        self.energy * area_measure * self.cone.measure()
    }

    fn centre(&self) -> Vec3 {
        (self.bmin + self.bmax) * 0.5
    }
}

/// One emitter as the tree's builder takes it.
#[derive(Clone, Copy, Debug)]
pub struct Emitter {
    pub pick: Option<Pick>,
    pub shape: Shape,
    pub centroid: Vec3,
    pub measure: Measure,
}

#[derive(Clone, Copy, Debug)]
struct Stored {
    e: Emitter,
    /// The path from the root of its tree (or subtree) to its leaf: bit d set where the
    /// path goes right at depth d.
    bit_trail: u64,
    /// For a triangle, the index of its object's mesh emitter.
    parent: u32,
    /// Of `e.measure.cone`.
    trig: ConeTrig,
}

#[derive(Clone, Copy, Debug)]
enum NodeKind {
    Inner { left: u32, right: u32 },
    Leaf { first: u32, count: u32 },
    Distant { first: u32, count: u32 },
}

#[derive(Clone, Copy, Debug)]
struct Node {
    m: Measure,
    kind: NodeKind,
    /// Of `m.cone`.
    trig: ConeTrig,
}

pub struct LightTree {
    nodes: Vec<Node>,
    emitters: Vec<Stored>,
    lamp_emitter: Vec<u32>,
    world_emitter: Option<u32>,
    prim_emitter: std::collections::HashMap<u32, u32>,
}

/// Cycles' sample_reservoir: keep `current` with probability weight / total so far,
/// reusing the random number.
#[inline]
fn reservoir(
    current: usize,
    weight: f32,
    selected: &mut Option<usize>,
    selected_weight: &mut f32,
    total: &mut f32,
    rand: &mut f32,
) {
    if !(weight > 0.0) {
        return;
    }
    *total += weight;
    if selected.is_none() {
        *selected = Some(current);
        *selected_weight = weight;
        return;
    }
    let thresh = weight / *total;
    if *rand <= thresh {
        *selected = Some(current);
        *selected_weight = weight;
        *rand /= thresh;
    } else {
        *rand = (*rand - thresh) / (1.0 - thresh);
    }
    *rand = rand.clamp(0.0, 1.0);
}

fn normalize_len(v: Vec3) -> (Vec3, f32) {
    let l = v.length();
    if l > 0.0 {
        (v * (1.0 / l), l)
    } else {
        (Vec3::ZERO, 0.0)
    }
}

fn sin_from_cos(c: f32) -> f32 {
    (1.0 - c * c).max(0.0).sqrt()
}

fn smoothstep(x: f32) -> f32 {
    if x <= 0.0 {
        0.0
    } else if x >= 1.0 {
        1.0
    } else {
        x * x * (3.0 - 2.0 * x)
    }
}

/// Cycles' light_tree_importance: upper and lower bounds of what a cluster can send to a
/// point with normal `n` (a surface; `trans` if it transmits too), or, with `theta_d`
/// (the angle the segment spans as seen from the cluster), to a volume ray segment:
/// no incidence term, the distance term theta_d / distance, and no lower bound.
#[allow(clippy::too_many_arguments)]
fn importance(
    n: Vec3,
    trans: bool,
    ptc: Vec3,
    cos_u: f32,
    cone: Cone,
    trig: &ConeTrig,
    max_d: f32,
    min_d: f32,
    energy: f32,
    theta_d: Option<f32>,
) -> (f32, f32) {
    let sin_u = sin_from_cos(cos_u);
    let (cos_min_incidence, cos_max_incidence) = if theta_d.is_some() {
        (1.0, 1.0)
    } else {
        let cos_i = if trans { ptc.dot(n).abs() } else { ptc.dot(n) };
        let sin_i = sin_from_cos(cos_i);
        let cos_min_incidence = if cos_i >= cos_u {
            1.0
        } else {
            cos_i * cos_u + sin_i * sin_u
        };
        if !trans && cos_min_incidence < 0.0 {
            return (0.0, 0.0);
        }
        (cos_min_incidence, (cos_i * cos_u - sin_i * sin_u).max(0.0))
    };
    let (cos_t, sin_t) = if cone.axis == -ptc {
        (1.0, 0.0)
    } else {
        let c = cone.axis.dot(-ptc);
        (c, sin_from_cos(c))
    };
    let cos_t_minus_u = cos_t * cos_u + sin_t * sin_u;
    let (sin_o, cos_o) = (trig.sin_o, trig.cos_o);
    let cos_min_outgoing = if cos_t >= cos_u || cos_t_minus_u >= cos_o {
        1.0
    } else if cone.theta_o + cone.theta_e > PI || cos_t_minus_u > trig.cos_o_plus_e {
        let sin_t_minus_u = sin_from_cos(cos_t_minus_u);
        cos_t_minus_u * cos_o + sin_t_minus_u * sin_o
    } else {
        return (0.0, 0.0);
    };
    if let Some(theta_d) = theta_d {
        return ((energy * cos_min_outgoing * theta_d / min_d).abs(), 0.0);
    }
    let max_imp = (cos_min_incidence * energy * cos_min_outgoing / (min_d * min_d)).abs();
    let cos_t_plus_u = cos_t * cos_u - sin_t * sin_u;
    let min_imp = if cone.theta_e - cone.theta_o < 0.0
        || cos_t < 0.0
        || cos_u < 0.0
        || cos_t_plus_u < trig.cos_e_minus_o
    {
        0.0
    } else {
        let sin_t_plus_u = sin_from_cos(cos_t_plus_u);
        let cos_max_outgoing = cos_t_plus_u * cos_o - sin_t_plus_u * sin_o;
        (cos_max_incidence * energy * cos_max_outgoing / (max_d * max_d)).abs()
    };
    (max_imp, min_imp)
}

/// The corners of an area light at `pos` with full extents `eu`, `ev`, in Cycles' order.
fn area_corners(pos: Vec3, eu: Vec3, ev: Vec3) -> [Vec3; 4] {
    [0, 1, 2, 3].map(|i| eu * ((i & 1) as f32 - 0.5) + ev * (0.5 * ((i & 2) as f32 - 1.0)) + pos)
}

/// Seen from `p` looking along `ptc`: the smallest cosine to any of `points`, and the
/// largest distance to one (Cycles' cos_theta_u and max distance of a polygon emitter).
fn subtended(p: Vec3, ptc: Vec3, points: &[Vec3]) -> (f32, f32) {
    points.iter().fold((f32::MAX, 0.0f32), |(c, d), &q| {
        let (ptq, dq) = normalize_len(q - p);
        (c.min(ptc.dot(ptq)), d.max(dq))
    })
}

/// Cycles' light_tree_cos_bound_subtended_angle: the cosine of the half-angle under
/// which the box's bounding sphere is seen from `p` (-1 from inside it).
fn cos_sphere_angle(bmax: Vec3, centroid: Vec3, p: Vec3) -> f32 {
    let d2 = (p - centroid).dot(p - centroid);
    let r2 = (bmax - centroid).dot(bmax - centroid);
    if d2 <= r2 {
        -1.0
    } else {
        (1.0 - r2 / d2).max(0.0).sqrt()
    }
}

/// Cycles' compute_v (Fig. 8 of the paper): of the directions from the segment `p + s d`,
/// s in [0, t], toward `centroid`, the one closest to the cone's axis, negated.
fn compute_v(centroid: Vec3, p: Vec3, d: Vec3, axis: Vec3, t: f32) -> Vec3 {
    let u0 = p - centroid;
    let u1 = u0 + d * t.min(1e12);
    let v0 = u0.normalize();
    let v1 = u1.normalize();
    // Cycles' make_orthonormals_tangent(o0, v1): o1 in the plane of v0 and v1.
    let o0 = v0;
    let o1 = o0.cross(v1).cross(o0).normalize();
    let a0 = o0.dot(axis);
    let a1 = o1.dot(axis);
    let inv_len = 1.0 / (a0 * a0 + a1 * a1).sqrt();
    let cos_phi0 = a0 * inv_len;
    if a1 < 0.0 || v0.dot(v1) > cos_phi0 {
        if a0 > v1.dot(axis) {
            v0
        } else {
            v1
        }
    } else {
        o0 * cos_phi0 + o1 * (a1 * inv_len)
    }
}

/// The segment's point nearest `centroid` (clamped to the segment), the distance from
/// the segment's line to `centroid`, and the angle the segment spans seen from it.
fn segment_view(p: Vec3, d: Vec3, t: f32, centroid: Vec3) -> (Vec3, f32, f32) {
    let closest_t = (centroid - p).dot(d);
    let closest = p + d * closest_t.clamp(0.0, t);
    let dist = (centroid - p - d * closest_t).length();
    let theta_d = (t - closest_t).atan2(dist) + closest_t.atan2(dist);
    (closest, dist, theta_d)
}

impl LightTree {
    /// Builds the tree as Cycles' LightTree::build: each emissive object gets a subtree of
    /// its triangles (`meshes`, one list per object) and becomes one emitter beside the
    /// local lights; the root's left child holds those, its right child is one leaf of
    /// the distant lights (suns and the world).
    pub fn build(
        local: Vec<Emitter>,
        distant: Vec<Emitter>,
        meshes: Vec<Vec<Emitter>>,
    ) -> LightTree {
        let mut t = LightTree {
            nodes: Vec::new(),
            emitters: Vec::new(),
            lamp_emitter: Vec::new(),
            world_emitter: None,
            prim_emitter: Default::default(),
        };
        // The root first, so that it is node 0.
        t.nodes.push(Node {
            m: Measure::EMPTY,
            kind: NodeKind::Leaf { first: 0, count: 0 },
            trig: ConeTrig::UNSET,
        });
        let mut top: Vec<Emitter> = local;
        let mut mesh_ranges = Vec::new();
        for tris in meshes {
            let start = t.emitters.len();
            t.emitters.extend(tris.into_iter().map(|e| Stored {
                e,
                bit_trail: 0,
                parent: u32::MAX,
                trig: ConeTrig::UNSET,
            }));
            let end = t.emitters.len();
            let root = t.recursive_build(start, end, 0, 0);
            let m = t.nodes[root as usize].m;
            mesh_ranges.push((root, start, end));
            top.push(Emitter {
                pick: None,
                shape: Shape::Mesh { root },
                centroid: m.centre(),
                measure: m,
            });
        }
        let start = t.emitters.len();
        t.emitters.extend(top.into_iter().map(|e| Stored {
            e,
            bit_trail: 0,
            parent: u32::MAX,
            trig: ConeTrig::UNSET,
        }));
        let end = t.emitters.len();
        let left = t.recursive_build(start, end, 0, 1);
        let dstart = t.emitters.len();
        let mut dm = Measure::EMPTY;
        for e in &distant {
            dm.add(&e.measure);
        }
        t.emitters.extend(distant.into_iter().map(|e| Stored {
            e,
            bit_trail: 1,
            parent: u32::MAX,
            trig: ConeTrig::UNSET,
        }));
        let right = t.nodes.len() as u32;
        t.nodes.push(Node {
            m: dm,
            kind: NodeKind::Distant {
                first: dstart as u32,
                count: (t.emitters.len() - dstart) as u32,
            },
            trig: ConeTrig::UNSET,
        });
        let mut rm = t.nodes[left as usize].m;
        rm.add(&dm);
        t.nodes[0] = Node {
            m: rm,
            kind: NodeKind::Inner { left, right },
            trig: ConeTrig::UNSET,
        };
        for n in &mut t.nodes {
            n.trig = ConeTrig::of(&n.m.cone);
        }
        for s in &mut t.emitters {
            s.trig = ConeTrig::of(&s.e.measure.cone);
        }
        // Lookups from what light sampling knows (a light, a triangle) to emitters.
        for (i, s) in t.emitters.iter().enumerate() {
            match s.e.pick {
                Some(Pick::Lamp(l)) => {
                    if t.lamp_emitter.len() <= l as usize {
                        t.lamp_emitter.resize(l as usize + 1, u32::MAX);
                    }
                    t.lamp_emitter[l as usize] = i as u32;
                }
                Some(Pick::World) => t.world_emitter = Some(i as u32),
                Some(Pick::Triangle(p)) => {
                    t.prim_emitter.insert(p, i as u32);
                }
                None => {}
            }
        }
        // Each object's triangles belong to the emitter of their subtree's root (the
        // top-level build has reordered the object emitters).
        let emitter_of_root: std::collections::HashMap<u32, u32> = t
            .emitters
            .iter()
            .enumerate()
            .filter_map(|(i, s)| {
                if let Shape::Mesh { root } = s.e.shape {
                    Some((root, i as u32))
                } else {
                    None
                }
            })
            .collect();
        for (root, s, e) in mesh_ranges {
            let parent = emitter_of_root[&root];
            for st in &mut t.emitters[s..e] {
                st.parent = parent;
            }
        }
        t
    }

    /// Cycles' LightTree::recursive_build; returns the node's index.
    fn recursive_build(&mut self, start: usize, end: usize, bit_trail: u64, depth: u32) -> u32 {
        let idx = self.nodes.len();
        self.nodes.push(Node {
            m: Measure::EMPTY,
            kind: NodeKind::Leaf {
                first: start as u32,
                count: (end - start) as u32,
            },
            trig: ConeTrig::UNSET,
        });
        let (split, middle, dim, m) = self.should_split(start, end);
        self.nodes[idx].m = m;
        if split && depth < 63 && end - start > 1 {
            if let Some(dim) = dim {
                if middle > start && middle < end {
                    self.emitters[start..end].select_nth_unstable_by(middle - start, |a, b| {
                        a.e.centroid[dim].total_cmp(&b.e.centroid[dim])
                    });
                }
            }
            let left = self.recursive_build(start, middle, bit_trail, depth + 1);
            let right = self.recursive_build(middle, end, bit_trail | (1u64 << depth), depth + 1);
            self.nodes[idx].kind = NodeKind::Inner { left, right };
        } else {
            for s in &mut self.emitters[start..end] {
                s.bit_trail = bit_trail;
            }
        }
        idx as u32
    }

    /// Cycles' LightTree::should_split (including its quirks: a zero extent along x
    /// skips the cost of the unsplit node, and more than 8 emitters always split).
    fn should_split(&self, start: usize, end: usize) -> (bool, usize, Option<usize>, Measure) {
        let n = end - start;
        if n < 2 {
            let m = if n == 1 {
                self.emitters[start].e.measure
            } else {
                Measure::EMPTY
            };
            return (false, start, None, m);
        }
        let mut middle = (start + end) / 2;
        let mut cmin = Vec3::splat(f32::INFINITY);
        let mut cmax = Vec3::splat(f32::NEG_INFINITY);
        for s in &self.emitters[start..end] {
            cmin = cmin.min(s.e.centroid);
            cmax = cmax.max(s.e.centroid);
        }
        let extent = cmax - cmin;
        let max_extent = extent[0].max(extent[1]).max(extent[2]).max(0.0);
        let mut measure = Measure::EMPTY;
        let mut total_cost = 0.0f32;
        let mut min_cost = f32::MAX;
        let mut split_dim = None;
        for dim in 0..3 {
            if extent[dim] == 0.0 && dim != 0 {
                continue;
            }
            let inv_extent = 1.0 / extent[dim];
            let mut buckets = [(Measure::EMPTY, 0usize); BUCKETS];
            for s in &self.emitters[start..end] {
                let b = (BUCKETS as f32 * (s.e.centroid[dim] - cmin[dim]) * inv_extent) as i64;
                let b = b.clamp(0, BUCKETS as i64 - 1) as usize;
                buckets[b].0.add(&s.e.measure);
                buckets[b].1 += 1;
            }
            let mut left = [(Measure::EMPTY, 0usize); BUCKETS - 1];
            left[0] = buckets[0];
            for i in 1..BUCKETS - 1 {
                let mut m = left[i - 1].0;
                m.add(&buckets[i].0);
                left[i] = (m, left[i - 1].1 + buckets[i].1);
            }
            if dim == 0 {
                measure = left[BUCKETS - 2].0;
                measure.add(&buckets[BUCKETS - 1].0);
                if extent.is_zero() {
                    break;
                }
                if extent[0] == 0.0 {
                    continue;
                }
                total_cost = measure.cost();
                if total_cost == 0.0 {
                    break;
                }
            }
            let mut right = [(Measure::EMPTY, 0usize); BUCKETS - 1];
            right[BUCKETS - 2] = buckets[BUCKETS - 1];
            for i in (0..BUCKETS - 2).rev() {
                let mut m = right[i + 1].0;
                m.add(&buckets[i + 1].0);
                right[i] = (m, right[i + 1].1 + buckets[i + 1].1);
            }
            let regularization = max_extent * inv_extent;
            for split in 0..BUCKETS - 1 {
                let cost = regularization * (left[split].0.cost() + right[split].0.cost());
                if cost < total_cost && cost < min_cost {
                    min_cost = cost;
                    split_dim = Some(dim);
                    middle = start + left[split].1;
                }
            }
        }
        (
            min_cost < total_cost || n > MAX_IN_LEAF,
            middle,
            split_dim,
            measure,
        )
    }

    /// Cycles' light_tree_node_importance.
    fn node_importance(&self, v: Viewer, node: &Node) -> (f32, f32) {
        let m = &node.m;
        let (p, n, trans) = match v {
            Viewer::Point { p, n, trans } => (Vec3::from(p), Vec3::from(n), trans),
            Viewer::Segment { p, d, t } => {
                let (p, d) = (Vec3::from(p), Vec3::from(d));
                let (ptc, cos_u, distance, theta_d) = if let NodeKind::Distant { .. } = node.kind {
                    let theta_d = if t.is_finite() { t } else { 1.0 };
                    (-m.cone.axis, node.trig.cos_o_plus_e, 1.0, theta_d)
                } else {
                    let centroid = m.centre();
                    let (closest, dist, theta_d) = segment_view(p, d, t, centroid);
                    (
                        -compute_v(centroid, p, d, m.cone.axis, t),
                        cos_sphere_angle(m.bmax, centroid, closest),
                        (0.5 * (centroid - m.bmax).length()).max(dist),
                        theta_d,
                    )
                };
                return importance(
                    d,
                    true,
                    ptc,
                    cos_u,
                    m.cone,
                    &node.trig,
                    distance,
                    distance,
                    m.energy,
                    Some(theta_d),
                );
            }
        };
        let (ptc, cos_u, distance) = if let NodeKind::Distant { .. } = node.kind {
            (-m.cone.axis, node.trig.cos_o_plus_e, 1.0)
        } else {
            let centroid = m.centre();
            let ext = m.bmax - centroid;
            let visible = trans || n.dot(centroid - p) + n.abs().dot(ext.abs()) > 0.0;
            if !visible {
                return (0.0, 0.0);
            }
            let (ptc, d) = normalize_len(centroid - p);
            let cos_u = cos_sphere_angle(m.bmax, centroid, p);
            (ptc, cos_u, (0.5 * (centroid - m.bmax).length()).max(d))
        };
        importance(
            n, trans, ptc, cos_u, m.cone, &node.trig, distance, distance, m.energy, None,
        )
    }

    /// Cycles' light_tree_emitter_importance.
    fn emitter_importance(&self, v: Viewer, st: &Stored) -> (f32, f32) {
        let (p, n, trans) = match v {
            Viewer::Point { p, n, trans } => (Vec3::from(p), Vec3::from(n), trans),
            Viewer::Segment { p, d, t } => {
                return self.emitter_importance_segment(p.into(), d.into(), t, st)
            }
        };
        let e = &st.e;
        let m = &e.measure;
        let mut cone = m.cone;
        let mut trig = st.trig;
        let mut energy = m.energy;
        let centroid = e.centroid;
        let (visible, ptc, cos_u, dist) = match e.shape {
            Shape::Mesh { root } => return self.node_importance(v, &self.nodes[root as usize]),
            Shape::Point {
                pos,
                radius,
                sphere,
                spot_smooth,
            } => {
                let (ptc, min_d) = normalize_len(pos - p);
                let (cos_u, dist) = if sphere {
                    if min_d > radius {
                        let c = sin_from_cos(radius / min_d);
                        (c, [min_d / c, min_d])
                    } else {
                        (-1.0, [radius / std::f32::consts::SQRT_2; 2])
                    }
                } else {
                    let hyp = (radius * radius + min_d * min_d).sqrt();
                    (min_d / hyp, [hyp, min_d])
                };
                match spot_smooth {
                    None => {
                        // Disk-oriented: facing the shading point.
                        cone.axis = (p - pos).normalize();
                        cone.theta_o = 0.0;
                        trig = trig.with_zero_theta_o();
                    }
                    Some(smooth) => {
                        let cos_min_out = (cone.axis.dot(-ptc).clamp(-1.0, 1.0).acos()
                            - cos_u.clamp(-1.0, 1.0).acos())
                        .max(0.0)
                        .cos();
                        let x = (cos_min_out - trig.cos_e) * smooth;
                        energy *= if smooth.is_finite() {
                            smoothstep(x)
                        } else if cos_min_out > trig.cos_e {
                            1.0
                        } else {
                            0.0
                        };
                    }
                }
                (true, ptc, cos_u, dist)
            }
            Shape::Area { pos, eu, ev } => {
                let (ptc, min_d) = normalize_len(pos - p);
                let (cos_u, max_d) = subtended(p, ptc, &area_corners(pos, eu, ev));
                let dist = [max_d.max(min_d), min_d];
                let front = cone.axis.dot(ptc) < 0.0;
                let above = n.dot(pos - p) + n.dot(eu).abs() + n.dot(ev).abs() > 0.0;
                (front && above, ptc, cos_u, dist)
            }
            Shape::Distant => {
                let cos_u = trig.cos_e;
                (true, -centroid, cos_u, [1.0 / cos_u, 1.0])
            }
            Shape::World => {
                cone.axis = vec3(0.0, 0.0, -1.0);
                (true, vec3(0.0, 0.0, -1.0), -1.0, [1.0, 1.0])
            }
            Shape::Triangle { v } => {
                let (ptc, min_d) = normalize_len(centroid - p);
                let mut dist = [min_d, min_d];
                let mut cos_u = f32::MAX;
                let mut above = false;
                for c in v {
                    let (ptk, dk) = normalize_len(c - p);
                    cos_u = cos_u.min(ptc.dot(ptk));
                    above |= ptk.dot(n) > 0.0;
                    dist[0] = dist[0].max(dk);
                }
                let front = cone.theta_o != 0.0 || cone.axis.dot(ptc) < 0.0;
                (front && above, ptc, cos_u, dist)
            }
        };
        if !(visible || trans) {
            return (0.0, 0.0);
        }
        importance(
            n, trans, ptc, cos_u, cone, &trig, dist[0], dist[1], energy, None,
        )
    }

    /// Cycles' light_tree_emitter_importance<in_volume_segment = true> for the segment
    /// from `p` along `d` for `t`: the emitter's parameters seen from the segment's point
    /// nearest it, its direction term from the segment's best-aligned point.
    fn emitter_importance_segment(&self, p: Vec3, d: Vec3, t: f32, st: &Stored) -> (f32, f32) {
        let e = &st.e;
        let m = &e.measure;
        let mut cone = m.cone;
        let mut trig = st.trig;
        let ray_length = if t.is_finite() { t } else { 1.0 };
        let (centroid, cos_u, dist, theta_d) = match e.shape {
            Shape::Mesh { root } => {
                let v = Viewer::Segment {
                    p: p.into(),
                    d: d.into(),
                    t,
                };
                return self.node_importance(v, &self.nodes[root as usize]);
            }
            Shape::Distant => {
                let cos_u = trig.cos_e;
                let ptc = -e.centroid;
                return importance(
                    d,
                    true,
                    ptc,
                    cos_u,
                    cone,
                    &trig,
                    1.0 / cos_u,
                    1.0,
                    m.energy,
                    Some(ray_length),
                );
            }
            Shape::World => {
                // Cycles' arbitrary centroid and direction for the background.
                cone.axis = vec3(0.0, 0.0, -1.0);
                (vec3(0.0, 0.0, 1.0), -1.0, [1.0, 1.0], ray_length)
            }
            Shape::Point {
                pos,
                radius,
                sphere,
                spot_smooth,
            } => {
                let (pc, _, theta_d) = segment_view(p, d, t, pos);
                let min_d = (pos - pc).length();
                let cos_u = match spot_smooth {
                    None => {
                        // Disk-oriented, facing the segment's start.
                        cone.axis = (p - pos).normalize();
                        cone.theta_o = 0.0;
                        trig = trig.with_zero_theta_o();
                        1.0
                    }
                    Some(_) if sphere => {
                        if min_d > radius {
                            sin_from_cos(radius / min_d)
                        } else {
                            -1.0
                        }
                    }
                    Some(_) => min_d / (radius * radius + min_d * min_d).sqrt(),
                };
                (pos, cos_u, [min_d, min_d], theta_d)
            }
            Shape::Area { pos, eu, ev } => {
                let (pc, _, theta_d) = segment_view(p, d, t, pos);
                let (ptc, min_d) = normalize_len(pos - pc);
                let (cos_u, _) = subtended(pc, ptc, &area_corners(pos, eu, ev));
                (pos, cos_u, [min_d, min_d], theta_d)
            }
            Shape::Triangle { v } => {
                let centroid = e.centroid;
                let (pc, _, theta_d) = segment_view(p, d, t, centroid);
                let (ptc, min_d) = normalize_len(centroid - pc);
                let (cos_u, _) = subtended(pc, ptc, &v);
                (centroid, cos_u, [min_d, min_d], theta_d)
            }
        };
        let ptc = -compute_v(centroid, p, d, cone.axis, t);
        importance(
            d,
            true,
            ptc,
            cos_u,
            cone,
            &trig,
            dist[0],
            dist[1],
            m.energy,
            Some(theta_d),
        )
    }

    /// Cycles' light_tree_child_importance.
    fn child_importance(&self, v: Viewer, node: u32) -> (f32, f32) {
        let nd = &self.nodes[node as usize];
        match nd.kind {
            NodeKind::Leaf { first, count } | NodeKind::Distant { first, count } if count == 1 => {
                self.emitter_importance(v, &self.emitters[first as usize])
            }
            NodeKind::Leaf { count: 0, .. } | NodeKind::Distant { count: 0, .. } => (0.0, 0.0),
            _ => self.node_importance(v, nd),
        }
    }

    /// Cycles' get_left_probability; None when neither child can contribute.
    fn left_probability(&self, v: Viewer, left: u32, right: u32) -> Option<f32> {
        let (lmax, lmin) = self.child_importance(v, left);
        let (rmax, rmin) = self.child_importance(v, right);
        let total_max = lmax + rmax;
        if total_max == 0.0 {
            return None;
        }
        let total_min = lmin + rmin;
        let pmax = lmax / total_max;
        let pmin = if total_min > 0.0 {
            lmin / total_min
        } else {
            0.5 * ((lmax > 0.0) as u32 as f32 + (rmax == 0.0) as u32 as f32)
        };
        Some(0.5 * (pmax + pmin))
    }

    /// Picks an emitter for what `v` sees: what to sample and the probability of having
    /// picked it.
    pub fn select(&self, v: Viewer, rand: f32) -> Option<(Pick, f32)> {
        let mut rand = rand;
        let mut node = 0u32;
        let mut pdf_leaf = 1.0f32;
        let mut pdf_sel = 1.0f32;
        loop {
            match self.nodes[node as usize].kind {
                NodeKind::Leaf { first, count } | NodeKind::Distant { first, count } => {
                    let e = self.select_in_leaf(v, first, count, &mut rand, &mut pdf_sel)?;
                    let st = &self.emitters[e];
                    match st.e.shape {
                        Shape::Mesh { root } => node = root,
                        _ => return st.e.pick.map(|k| (k, pdf_sel * pdf_leaf)),
                    }
                }
                NodeKind::Inner { left, right } => {
                    let lp = self.left_probability(v, left, right)?;
                    // Cycles' sample_reservoir of the right child against the left.
                    let wr = 1.0 - lp;
                    let mut go_right = false;
                    if wr > 0.0 {
                        let thresh = wr / (lp + wr);
                        if rand <= thresh {
                            go_right = true;
                            rand /= thresh;
                        } else {
                            rand = (rand - thresh) / (1.0 - thresh);
                        }
                        rand = rand.clamp(0.0, 1.0);
                    }
                    if go_right {
                        pdf_leaf *= wr;
                        node = right;
                    } else {
                        pdf_leaf *= lp;
                        node = left;
                    }
                }
            }
        }
    }

    /// Cycles' light_tree_cluster_select_emitter: two reservoirs, by the upper and by the
    /// lower bound of each emitter's importance, one chosen by the random number.
    fn select_in_leaf(
        &self,
        v: Viewer,
        first: u32,
        count: u32,
        rand: &mut f32,
        pdf: &mut f32,
    ) -> Option<usize> {
        let mut sel_imp = [0.0f32; 2];
        let mut total = [0.0f32; 2];
        let mut selected = None;
        let mut has_importance = 0u64;
        let sample_max = *rand > 0.5;
        let (smax, smin) = (sample_max as usize, (!sample_max) as usize);
        if count > 1 {
            *rand = *rand * 2.0 - sample_max as u32 as f32;
        }
        let range = first as usize..(first + count) as usize;
        for (i, ei) in range.clone().enumerate() {
            let (imax, imin) = self.emitter_importance(v, &self.emitters[ei]);
            let imp = [imax, imin];
            reservoir(
                ei,
                imp[smin],
                &mut selected,
                &mut sel_imp[smin],
                &mut total[smin],
                rand,
            );
            if selected == Some(ei) {
                sel_imp[smax] = imp[smax];
            }
            total[smax] += imp[smax];
            if imax > 0.0 && i < 64 {
                has_importance |= 1 << i;
            }
        }
        if has_importance == 0 {
            return None;
        }
        if total[1] == 0.0 {
            // Uniform among the emitters with a positive upper bound.
            if sample_max {
                sel_imp[1] = 1.0;
                total[1] = has_importance.count_ones() as f32;
            } else {
                selected = None;
                let mut hi = has_importance;
                for ei in range {
                    reservoir(
                        ei,
                        (hi & 1) as f32,
                        &mut selected,
                        &mut sel_imp[1],
                        &mut total[1],
                        rand,
                    );
                    hi >>= 1;
                }
                sel_imp[0] = self.emitter_importance(v, &self.emitters[selected?]).0;
            }
        }
        *pdf *= 0.5 * (sel_imp[0] / total[0] + sel_imp[1] / total[1]);
        selected
    }

    /// The probability that `select` for `v` picks `pick` (Cycles' light_tree_pdf), for
    /// MIS of what BSDF rays find; 0 if it is not an emitter.
    pub fn pdf(&self, v: Viewer, pick: Pick) -> f32 {
        let target = match pick {
            Pick::Lamp(l) => self
                .lamp_emitter
                .get(l as usize)
                .copied()
                .unwrap_or(u32::MAX),
            Pick::World => self.world_emitter.unwrap_or(u32::MAX),
            Pick::Triangle(prim) => self.prim_emitter.get(&prim).copied().unwrap_or(u32::MAX),
        };
        if target == u32::MAX {
            return 0.0;
        }
        let t = &self.emitters[target as usize];
        // A triangle is reached through its object's emitter, then the object's subtree.
        let (mut target, mut bits, mut then) = if t.parent != u32::MAX {
            (
                t.parent,
                self.emitters[t.parent as usize].bit_trail,
                Some((target, t.bit_trail)),
            )
        } else {
            (target, t.bit_trail, None)
        };
        let mut pdf = 1.0f32;
        let mut node = 0u32;
        loop {
            match self.nodes[node as usize].kind {
                NodeKind::Leaf { first, count } | NodeKind::Distant { first, count } => {
                    let (mut tmax, mut tmin, mut total_max, mut total_min, mut num) =
                        (0.0f32, 0.0f32, 0.0f32, 0.0f32, 0u32);
                    for ei in first..first + count {
                        let (imax, imin) = self.emitter_importance(v, &self.emitters[ei as usize]);
                        num += (imax > 0.0) as u32;
                        if ei == target {
                            tmax = imax;
                            tmin = imin;
                        }
                        total_max += imax;
                        total_min += imin;
                    }
                    if !(tmax > 0.0) {
                        return 0.0;
                    }
                    pdf *= 0.5
                        * (tmax / total_max
                            + if total_min > 0.0 {
                                tmin / total_min
                            } else {
                                1.0 / num as f32
                            });
                    match then.take() {
                        Some((tri, tri_bits)) => {
                            let Shape::Mesh { root } = self.emitters[target as usize].e.shape
                            else {
                                return 0.0;
                            };
                            node = root;
                            target = tri;
                            bits = tri_bits;
                        }
                        None => return pdf,
                    }
                }
                NodeKind::Inner { left, right } => {
                    let Some(lp) = self.left_probability(v, left, right) else {
                        return 0.0;
                    };
                    let go_left = bits & 1 == 0;
                    bits >>= 1;
                    node = if go_left { left } else { right };
                    pdf *= if go_left { lp } else { 1.0 - lp };
                    if pdf == 0.0 {
                        return 0.0;
                    }
                }
            }
        }
    }
}

/// Cycles' light distribution (Use Light Tree off): emissive triangles by area, each
/// light (lamps, suns, the world) alike; half the probability to each group when both
/// are present.
pub struct Distribution {
    /// Cumulative over triangles then lights.
    cdf: Vec<f32>,
    entries: Vec<Pick>,
    /// Per unit area of an emissive triangle.
    pdf_triangles: f32,
    pdf_lights: f32,
    prim_area: std::collections::HashMap<u32, f32>,
    lights: Vec<Pick>,
}

impl Distribution {
    /// `triangles`: (primitive, area); `lights`: the lights and the world, if sampled.
    pub fn build(triangles: &[(u32, f32)], lights: &[Pick]) -> Distribution {
        let mut cdf = Vec::with_capacity(triangles.len() + lights.len());
        let mut entries = Vec::with_capacity(cdf.capacity());
        let mut total = 0.0f64;
        for &(prim, area) in triangles {
            total += area as f64;
            cdf.push(total);
            entries.push(Pick::Triangle(prim));
        }
        let tri_area = total;
        let light_area = if tri_area > 0.0 {
            tri_area / lights.len().max(1) as f64
        } else {
            1.0
        };
        for &l in lights {
            total += light_area;
            cdf.push(total);
            entries.push(l);
        }
        let cdf = cdf
            .iter()
            .map(|&c| if total > 0.0 { (c / total) as f32 } else { 0.0 })
            .collect();
        let both = tri_area > 0.0 && !lights.is_empty();
        let pdf_triangles = if tri_area > 0.0 {
            (1.0 / tri_area) as f32 * if both { 0.5 } else { 1.0 }
        } else {
            0.0
        };
        let pdf_lights = if lights.is_empty() {
            0.0
        } else {
            1.0 / lights.len() as f32 * if both { 0.5 } else { 1.0 }
        };
        Distribution {
            cdf,
            entries,
            pdf_triangles,
            pdf_lights,
            prim_area: triangles.iter().copied().collect(),
            lights: lights.to_vec(),
        }
    }

    pub fn select(&self, rand: f32) -> Option<(Pick, f32)> {
        if self.entries.is_empty() {
            return None;
        }
        let i = self
            .cdf
            .partition_point(|&c| c <= rand)
            .min(self.entries.len() - 1);
        let k = self.entries[i];
        Some((k, self.pdf(k)))
    }

    pub fn pdf(&self, k: Pick) -> f32 {
        match k {
            Pick::Triangle(p) => self
                .prim_area
                .get(&p)
                .map(|a| a * self.pdf_triangles)
                .unwrap_or(0.0),
            _ if self.lights.contains(&k) => self.pdf_lights,
            _ => 0.0,
        }
    }
}

/// How a scene picks the emitter of each light sample.
pub enum LightSelect {
    None,
    Tree(LightTree),
    Flat(Distribution),
}

impl LightSelect {
    /// Picks an emitter for a shading point at `p` with shading normal `n` (`trans`: its
    /// BSDF transmits).
    #[inline]
    pub fn select(&self, p: V3, n: V3, trans: bool, rand: f32) -> Option<(Pick, f32)> {
        self.select_for(Viewer::Point { p, n, trans }, rand)
    }

    #[inline]
    pub fn select_for(&self, v: Viewer, rand: f32) -> Option<(Pick, f32)> {
        match self {
            LightSelect::None => None,
            LightSelect::Tree(t) => t.select(v, rand),
            LightSelect::Flat(d) => d.select(rand),
        }
    }

    #[inline]
    pub fn pdf(&self, p: V3, n: V3, trans: bool, k: Pick) -> f32 {
        self.pdf_for(Viewer::Point { p, n, trans }, k)
    }

    #[inline]
    pub fn pdf_for(&self, v: Viewer, k: Pick) -> f32 {
        match self {
            LightSelect::None => 0.0,
            LightSelect::Tree(t) => t.pdf(v, k),
            LightSelect::Flat(d) => d.pdf(k),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(l: u32, pos: V3, energy: f32) -> Emitter {
        let (pos, r) = (Vec3::from(pos), 0.1);
        let m = Measure::new(
            &[pos - Vec3::splat(r), pos + Vec3::splat(r)],
            Cone {
                axis: vec3(0.0, 0.0, -1.0),
                theta_o: PI,
                theta_e: FRAC_PI_2,
            },
            energy,
        );
        Emitter {
            pick: Some(Pick::Lamp(l)),
            shape: Shape::Point {
                pos,
                radius: r,
                sphere: false,
                spot_smooth: None,
            },
            centroid: pos,
            measure: m,
        }
    }

    fn tri(prim: u32, v: [V3; 3]) -> Emitter {
        let v = v.map(Vec3::from);
        let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
        let c = (v[0] + v[1] + v[2]) * (1.0 / 3.0);
        let m = Measure::new(
            &v,
            Cone {
                axis: (v[0] - v[1]).normalize(),
                theta_o: FRAC_PI_2,
                theta_e: FRAC_PI_2,
            },
            area,
        );
        Emitter {
            pick: Some(Pick::Triangle(prim)),
            shape: Shape::Triangle { v },
            centroid: c,
            measure: m,
        }
    }

    /// Selection probabilities over all emitters sum to one, and `pdf` gives the
    /// probability with which `select` picks each: checked by counting picks.
    #[test]
    fn select_and_pdf_agree() {
        let mut local = Vec::new();
        for i in 0..13 {
            let f = i as f32;
            local.push(point(
                i,
                [f.sin() * 3.0, f.cos() * 2.0, 2.0 + 0.3 * f],
                1.0 + f,
            ));
        }
        let mut mesh = Vec::new();
        for i in 0..20u32 {
            let x = i as f32 * 0.2 - 2.0;
            mesh.push(tri(
                100 + i,
                [[x, -1.0, 3.0], [x + 0.2, -1.0, 3.0], [x, -0.8, 3.2]],
            ));
        }
        let sun = Emitter {
            pick: Some(Pick::Lamp(13)),
            shape: Shape::Distant,
            centroid: vec3(0.3, 0.2, -1.0).normalize(),
            measure: Measure::new(
                &[],
                Cone {
                    axis: vec3(0.3, 0.2, -1.0).normalize(),
                    theta_o: 0.0,
                    theta_e: 0.01,
                },
                3.0,
            ),
        };
        let t = LightTree::build(local, vec![sun], vec![mesh]);
        let mut picks: Vec<Pick> = (0..14).map(Pick::Lamp).collect();
        picks.extend((100..120).map(Pick::Triangle));
        // Shading points, and volume segments (Cycles' in_volume_segment selection).
        for v in [
            Viewer::Point {
                p: [0.0, 0.0, 0.0],
                n: [0.0, 0.0, 1.0],
                trans: false,
            },
            Viewer::Point {
                p: [1.0, 0.5, 2.5],
                n: vec3(0.2, -0.5, 0.4).normalize().into(),
                trans: true,
            },
            Viewer::Point {
                p: [-1.0, -1.0, 1.0],
                n: [0.0, 1.0, 0.0],
                trans: false,
            },
            Viewer::Segment {
                p: [-3.0, -2.0, 1.0],
                d: vec3(1.0, 0.6, 0.3).normalize().into(),
                t: 7.0,
            },
            Viewer::Segment {
                p: [0.5, 0.5, 4.0],
                d: [0.0, 0.0, -1.0],
                t: f32::INFINITY,
            },
        ] {
            let sum: f32 = picks.iter().map(|&k| t.pdf(v, k)).sum();
            assert!((sum - 1.0).abs() < 1e-4, "pdfs sum to {sum}");
            let draws = 200_000;
            let mut counts = std::collections::HashMap::new();
            for i in 0..draws {
                let u = (i as f32 + 0.5) / draws as f32;
                let (k, pr) = t.select(v, u).expect("something is picked");
                let want = t.pdf(v, k);
                assert!(
                    (pr - want).abs() <= 1e-4 * want.max(1e-3),
                    "{k:?}: select says {pr}, pdf {want}"
                );
                *counts.entry(k).or_insert(0u32) += 1;
            }
            for &k in &picks {
                let got = *counts.get(&k).unwrap_or(&0) as f32 / draws as f32;
                let want = t.pdf(v, k);
                assert!(
                    (got - want).abs() < 0.003 + 0.02 * want,
                    "{k:?} for {v:?}: picked {got}, pdf {want}"
                );
            }
        }
    }

    /// Several emissive objects, which the top-level build reorders: each triangle's pdf
    /// goes through its own object's emitter, so the pdfs still sum to one and agree with
    /// what `select` reports.
    #[test]
    fn triangles_of_several_objects() {
        let mut meshes = Vec::new();
        for m in 0..6u32 {
            let x = 3.0 - m as f32;
            meshes.push(
                (0..4u32)
                    .map(|i| {
                        tri(
                            10 * m + i,
                            [
                                [x, i as f32 * 0.3, 2.0],
                                [x + 0.5, i as f32 * 0.3, 2.0],
                                [x, i as f32 * 0.3 + 0.3, 2.4],
                            ],
                        )
                    })
                    .collect::<Vec<_>>(),
            );
        }
        let t = LightTree::build(vec![point(0, [0.0, -2.0, 3.0], 2.0)], Vec::new(), meshes);
        let mut picks = vec![Pick::Lamp(0)];
        picks.extend((0..6u32).flat_map(|m| (0..4u32).map(move |i| Pick::Triangle(10 * m + i))));
        for p in [[0.0f32, 0.0, 0.0], [2.0, 1.0, 0.5]] {
            let n = [0.0, 0.0, 1.0];
            let v = Viewer::Point { p, n, trans: false };
            let sum: f32 = picks.iter().map(|&k| t.pdf(v, k)).sum();
            assert!((sum - 1.0).abs() < 1e-4, "pdfs sum to {sum}");
            for i in 0..2000 {
                let (k, pr) = t.select(v, (i as f32 + 0.5) / 2000.0).expect("a pick");
                let want = t.pdf(v, k);
                assert!(
                    (pr - want).abs() <= 1e-4 * want.max(1e-3),
                    "{k:?}: select says {pr}, pdf {want}"
                );
            }
        }
    }

    #[test]
    fn distribution_halves_between_triangles_and_lights() {
        let d = Distribution::build(&[(7, 1.0), (9, 3.0)], &[Pick::Lamp(0), Pick::World]);
        assert!((d.pdf(Pick::Triangle(9)) - 0.375).abs() < 1e-6);
        assert!((d.pdf(Pick::Lamp(0)) - 0.25).abs() < 1e-6);
        assert_eq!(d.select(0.2).unwrap().0, Pick::Triangle(9));
        assert_eq!(d.select(0.9).unwrap().0, Pick::World);
    }
}

//! A BVH over axis-aligned boxes whose primitives the caller intersects: the ray query
//! visits the leaves a ray's segment passes, nearest first, and hands each primitive id
//! to a closure that may shorten the segment. Used for primitives that are not
//! triangles (the renderer's hair curves), whose intersection depends on the ray.

use super::math::*;

#[derive(Debug, Clone, Copy)]
struct Node {
    min: V3,
    max: V3,
    /// Leaf: first id in `ids`; inner: index of the left child (right = left + 1).
    start: u32,
    /// Id count; 0 for inner nodes.
    count: u32,
}

pub struct BoxBvh {
    nodes: Vec<Node>,
    ids: Vec<u32>,
}

const MAX_LEAF: usize = 4;

impl BoxBvh {
    /// A BVH over `boxes` (min, max); a primitive's id is its index there. Boxes with a
    /// non-finite corner are left out (no ray can hit them).
    pub fn build(boxes: &[(V3, V3)]) -> BoxBvh {
        let ok = |b: &(V3, V3)| finite(b.0) && finite(b.1);
        let mut ids: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&i| ok(&boxes[i as usize]))
            .collect();
        let centre = |i: u32| scale(add(boxes[i as usize].0, boxes[i as usize].1), 0.5);
        let mut nodes = vec![Node {
            min: [f32::INFINITY; 3],
            max: [f32::NEG_INFINITY; 3],
            start: 0,
            count: ids.len() as u32,
        }];
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let (start, count) = (nodes[ni].start as usize, nodes[ni].count as usize);
            let (mut bmin, mut bmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            let (mut cmin, mut cmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for &id in &ids[start..start + count] {
                bmin = vmin(bmin, boxes[id as usize].0);
                bmax = vmax(bmax, boxes[id as usize].1);
                cmin = vmin(cmin, centre(id));
                cmax = vmax(cmax, centre(id));
            }
            nodes[ni].min = bmin;
            nodes[ni].max = bmax;
            if count <= MAX_LEAF {
                continue;
            }
            // Median split along the widest centroid extent (curve segments are small and
            // numerous; build time matters more than the last few percent of speed).
            let d = sub(cmax, cmin);
            let axis = if d[0] >= d[1] && d[0] >= d[2] {
                0
            } else if d[1] >= d[2] {
                1
            } else {
                2
            };
            let half = count / 2;
            ids[start..start + count]
                .select_nth_unstable_by(half, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]));
            let left = nodes.len();
            nodes.push(Node {
                min: bmin,
                max: bmax,
                start: start as u32,
                count: half as u32,
            });
            nodes.push(Node {
                min: bmin,
                max: bmax,
                start: (start + half) as u32,
                count: (count - half) as u32,
            });
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push(left);
            stack.push(left + 1);
        }
        BoxBvh { nodes, ids }
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Visits the primitives whose boxes the ray `org + t dir`, `t` in [tmin, tmax],
    /// passes, nearer nodes first. `hit(id, tmax)` intersects primitive `id` and returns
    /// the new far end of the segment (a hit's distance) or None; `stop` ends the walk
    /// after the first hit (occlusion queries). Returns the last far end when any hit.
    pub fn traverse(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        stop: bool,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<f32> {
        if self.ids.is_empty() {
            return None;
        }
        let inv = dir.map(|d| 1.0 / d);
        let mut far = tmax;
        let mut found = None;
        let mut stack = [0u32; 64];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if slab(node, org, inv, tmin, far).is_none() {
                continue;
            }
            if node.count > 0 {
                for &id in &self.ids[node.start as usize..(node.start + node.count) as usize] {
                    if let Some(t) = hit(id, far) {
                        far = t;
                        found = Some(t);
                        if stop {
                            return found;
                        }
                    }
                }
                continue;
            }
            let (l, r) = (node.start, node.start + 1);
            let tl = slab(&self.nodes[l as usize], org, inv, tmin, far);
            let tr = slab(&self.nodes[r as usize], org, inv, tmin, far);
            // Push the farther child first so the nearer one is visited next.
            let order = match (tl, tr) {
                (Some(a), Some(b)) if b < a => [Some(l), Some(r)],
                (Some(_), Some(_)) => [Some(r), Some(l)],
                (Some(_), None) => [None, Some(l)],
                (None, Some(_)) => [None, Some(r)],
                (None, None) => [None, None],
            };
            for c in order.into_iter().flatten() {
                if sp < stack.len() {
                    stack[sp] = c;
                    sp += 1;
                }
            }
        }
        found
    }
}

/// Where the ray enters `node`'s box within [tmin, tmax], or None when it misses.
#[inline]
fn slab(node: &Node, org: V3, inv: V3, tmin: f32, tmax: f32) -> Option<f32> {
    let (mut t0, mut t1) = (tmin, tmax);
    for k in 0..3 {
        let a = (node.min[k] - org[k]) * inv[k];
        let b = (node.max[k] - org[k]) * inv[k];
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        // NaN (a zero direction component on the slab's plane) keeps the bound.
        t0 = if lo > t0 { lo } else { t0 };
        t1 = if hi < t1 { hi } else { t1 };
    }
    (t0 <= t1 * (1.0 + 2.0 * f32::EPSILON)).then_some(t0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visits_the_boxes_a_ray_passes_nearest_first() {
        let boxes: Vec<(V3, V3)> = (0..100)
            .map(|i| {
                let x = i as f32;
                ([x, -0.1, -0.1], [x + 0.5, 0.1, 0.1])
            })
            .collect();
        let bvh = BoxBvh::build(&boxes);
        let mut seen = Vec::new();
        let got = bvh.traverse(
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            0.0,
            1e9,
            false,
            |id, far| {
                seen.push(id);
                let t = id as f32 + 1.0;
                (id >= 40 && t < far).then_some(t)
            },
        );
        assert_eq!(got, Some(41.0));
        // Nothing beyond the hit's distance is visited once it is found.
        assert!(seen.iter().all(|&i| i < 48), "{seen:?}");
        assert!(bvh
            .traverse(
                [-1.0, 5.0, 0.0],
                [1.0, 0.0, 0.0],
                0.0,
                1e9,
                false,
                |_, _| Some(0.0)
            )
            .is_none());
    }
}

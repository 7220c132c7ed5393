//! Blender's `BLI_kdtree_3d` laid out node for node: points balanced by
//! `kdtree_balance` (a quick-select about the median on x, y, z in turn,
//! `weld::kdtree_balanced_order`) and walked as its searches walk it, so among points at
//! equal distances the one Blender meets first wins and the nearest-n lists come out in
//! Blender's order.

use super::weld::kdtree_balanced_order;

type V3 = [f32; 3];

const UNSET: usize = usize::MAX;

/// A balanced kd-tree over some of the points of a position array.
pub struct KdTree {
    /// Point index per node.
    index: Vec<usize>,
    /// Split axis, left and right child per node (`UNSET`: none).
    axis: Vec<usize>,
    left: Vec<usize>,
    right: Vec<usize>,
    root: usize,
}

/// `len_squared_vnvn`: the squared distance summed axis by axis.
#[inline]
fn dist_sq(p: V3, co: V3) -> f32 {
    let mut d = 0.0f32;
    for k in 0..3 {
        let x = p[k] - co[k];
        d += x * x;
    }
    d
}

impl KdTree {
    /// The tree over `members` (indices into `positions`), inserted in that order.
    pub fn new(positions: &[V3], members: Vec<usize>) -> KdTree {
        let mut index = members;
        kdtree_balanced_order(positions, &mut index, 0);
        let n = index.len();
        let mut t = KdTree {
            index,
            axis: vec![0; n],
            left: vec![UNSET; n],
            right: vec![UNSET; n],
            root: UNSET,
        };
        t.root = t.link(0, n, 0);
        t
    }

    /// `kdtree_balance`'s structure: the median of each slice is its node; a single node
    /// keeps axis 0.
    fn link(&mut self, ofs: usize, len: usize, axis: usize) -> usize {
        if len == 0 {
            return UNSET;
        }
        if len == 1 {
            return ofs;
        }
        let median = len / 2;
        let node = ofs + median;
        self.axis[node] = axis;
        let next = (axis + 1) % 3;
        self.left[node] = self.link(ofs, median, next);
        self.right[node] = self.link(node + 1, len - (median + 1), next);
        node
    }

    /// The nearest point other than `skip` (`BLI_kdtree_3d_find_nearest_cb` with a filter
    /// rejecting `skip`), or -1.
    pub fn nearest_other(
        &self,
        positions: &[V3],
        co: V3,
        skip: usize,
        stack: &mut Vec<usize>,
    ) -> i32 {
        if self.root == UNSET {
            return -1;
        }
        stack.clear();
        stack.push(self.root);
        let mut min_dist = f32::MAX;
        let mut found = -1i32;
        let test = |node: usize, min_dist: &mut f32, found: &mut i32| {
            let d = dist_sq(positions[self.index[node]], co);
            if d < *min_dist && self.index[node] != skip {
                *min_dist = d;
                *found = self.index[node] as i32;
            }
        };
        while let Some(node) = stack.pop() {
            let a = self.axis[node];
            let cur = positions[self.index[node]][a] - co[a];
            if cur < 0.0 {
                if cur * cur < min_dist {
                    test(node, &mut min_dist, &mut found);
                    if self.left[node] != UNSET {
                        stack.push(self.left[node]);
                    }
                }
                if self.right[node] != UNSET {
                    stack.push(self.right[node]);
                }
            } else {
                if cur * cur < min_dist {
                    test(node, &mut min_dist, &mut found);
                    if self.right[node] != UNSET {
                        stack.push(self.right[node]);
                    }
                }
                if self.left[node] != UNSET {
                    stack.push(self.left[node]);
                }
            }
        }
        found
    }

    /// `BLI_kdtree_3d_find_nearest_n`: up to `capacity` nearest points as (point index,
    /// distance), nearest first; equal distances keep the order the walk met them in.
    /// `out` and `stack` are reused buffers.
    pub fn nearest_n(
        &self,
        positions: &[V3],
        co: V3,
        capacity: usize,
        out: &mut Vec<(usize, f32)>,
        stack: &mut Vec<usize>,
    ) {
        out.clear();
        if self.root == UNSET || capacity == 0 {
            return;
        }
        // `nearest_ordered_insert`: grows to `capacity`, then the last entry falls off.
        let insert = |out: &mut Vec<(usize, f32)>, index: usize, d: f32| {
            if out.len() < capacity {
                out.push((index, d));
            }
            let mut i = out.len() - 1;
            while i > 0 && d < out[i - 1].1 {
                out[i] = out[i - 1];
                i -= 1;
            }
            out[i] = (index, d);
        };
        stack.clear();
        let root = self.root;
        let p = positions[self.index[root]];
        insert(out, self.index[root], dist_sq(co, p));
        let a = self.axis[root];
        let (first, second) = if co[a] < p[a] {
            (self.right[root], self.left[root])
        } else {
            (self.left[root], self.right[root])
        };
        for c in [first, second] {
            if c != UNSET {
                stack.push(c);
            }
        }
        while let Some(node) = stack.pop() {
            let p = positions[self.index[node]];
            let a = self.axis[node];
            let cur = p[a] - co[a];
            // Blender pushes one child only when the split plane is close enough and the
            // other always; the one pushed last is walked first.
            let (inner, outer) = if cur < 0.0 {
                (self.left[node], self.right[node])
            } else {
                (self.right[node], self.left[node])
            };
            let room = out.len() < capacity;
            if room || cur * cur < out[out.len() - 1].1 {
                let d = dist_sq(co, p);
                if out.len() < capacity || d < out[out.len() - 1].1 {
                    insert(out, self.index[node], d);
                }
                if inner != UNSET {
                    stack.push(inner);
                }
            }
            if outer != UNSET {
                stack.push(outer);
            }
        }
        for e in out.iter_mut() {
            e.1 = e.1.sqrt();
        }
    }
}

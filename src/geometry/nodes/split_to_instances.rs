//! Split to Instances (`node_geo_split_to_instances.cc`): the selected elements of the
//! chosen domain are grouped by Group ID, each group becomes one instance (identity
//! transform) of a geometry holding that group's part of every component: mesh points,
//! edges or faces (with what they fully contain, as Separate Geometry keeps them), point
//! cloud points, or instances. The Group ID output is each instance's group id.
//!
//! The instances come in Blender's order: the groups are kept in a `blender::Map<int, ..>`
//! and read back in its slot order (`BlenderIntMap`), the ids added component by component
//! (mesh, point cloud, curves, instances), each in first-appearance order among the
//! selected elements. A component whose whole domain is selected with a constant Group ID
//! goes into its group whole.
//!
//! Curves are split only whole (all selected, constant Group ID); other curve splits and
//! the grease pencil layer domain are errors naming the node.

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::instances::{InstanceReference, Instances};
use super::super::math::MAT4_IDENTITY;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::delete::{mesh_keep, Mode};
use super::geometry_ops::eval_fields;

/// The slot order of Blender's `Map<int, ...>` (`BLI_map.hh`): open addressing over a
/// power-of-two slot array (at least 8 slots, at most half of them used), the key itself as
/// hash (sign-extended to 64 bits), CPython's probing (`PythonProbingStrategy`), and on
/// growth the old slots reinserted in slot order.
pub struct BlenderIntMap {
    slots: Vec<Option<i32>>,
    len: usize,
}

impl BlenderIntMap {
    pub fn new() -> Self {
        BlenderIntMap {
            slots: Vec::new(),
            len: 0,
        }
    }

    fn place(slots: &mut [Option<i32>], key: i32) -> bool {
        let mask = slots.len() as u64 - 1;
        let mut hash = key as i64 as u64;
        let mut perturb = hash;
        loop {
            let i = (hash & mask) as usize;
            match slots[i] {
                None => {
                    slots[i] = Some(key);
                    return true;
                }
                Some(k) if k == key => return false,
                Some(_) => {}
            }
            perturb >>= 5;
            hash = hash.wrapping_mul(5).wrapping_add(1).wrapping_add(perturb);
        }
    }

    /// Adds `key` unless present (`lookup_or_add`, which makes room for one more before
    /// looking: a full map grows even when the key is there).
    pub fn add(&mut self, key: i32) {
        if self.len >= self.slots.len() / 2 {
            // Grow to fit one more: usable = total / 2, total a power of two >= 8.
            let total = (2 * (self.len + 1)).next_power_of_two().max(8);
            let mut slots = vec![None; total];
            for k in self.slots.iter().flatten() {
                Self::place(&mut slots, *k);
            }
            self.slots = slots;
        }
        if Self::place(&mut self.slots, key) {
            self.len += 1;
        }
    }

    /// The keys in slot order.
    pub fn keys(&self) -> impl Iterator<Item = i32> + '_ {
        self.slots.iter().flatten().copied()
    }
}

impl Default for BlenderIntMap {
    fn default() -> Self {
        Self::new()
    }
}

/// One component's split: the selected element indices of each group, groups in
/// first-appearance order; None when the component goes whole into one group.
enum Split {
    Empty,
    Whole(i32),
    Groups(Vec<(i32, Vec<usize>)>),
}

fn split_component(
    comp: ComponentRef,
    domain: Domain,
    sel: &Field,
    ids: &Field,
) -> Result<Split, String> {
    let n = comp.domain_size(domain);
    let r = eval_fields(comp, domain, &[(sel, DataType::Bool), (ids, DataType::Int)])?;
    let (sel_v, id_v) = (r[0].as_bool(), r[1].as_int());
    let count = sel_v.iter().filter(|s| **s).count();
    if count == 0 {
        return Ok(Split::Empty);
    }
    if count == n {
        if let Some(v) = ids.as_constant() {
            return Ok(Split::Whole(v.as_int()));
        }
    }
    let mut groups: Vec<(i32, Vec<usize>)> = Vec::new();
    let mut index: std::collections::HashMap<i32, usize> = std::collections::HashMap::new();
    for i in (0..n).filter(|&i| sel_v[i]) {
        let k = *index.entry(id_v[i]).or_insert_with(|| {
            groups.push((id_v[i], Vec::new()));
            groups.len() - 1
        });
        groups[k].1.push(i);
    }
    Ok(Split::Groups(groups))
}

/// The group geometries, keyed by group id, in insertion order (their slot order comes
/// from `BlenderIntMap`).
#[derive(Default)]
struct Groups {
    order: BlenderIntMap,
    sets: std::collections::HashMap<i32, GeometrySet>,
}

impl Groups {
    /// `lookup_or_add`: the group's geometry, the id added to the map.
    fn entry(&mut self, id: i32) -> &mut GeometrySet {
        self.order.add(id);
        self.sets.entry(id).or_default()
    }
    /// `lookup` of a group added before (no map insertion, so no growth).
    fn get(&mut self, id: i32) -> &mut GeometrySet {
        self.sets.entry(id).or_default()
    }
}

pub fn split_to_instances(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Geometry")?;
    let d = ctx.prop_str("domain")?;
    let domain = match Domain::parse(d) {
        Some(
            x @ (Domain::Point | Domain::Edge | Domain::Face | Domain::Curve | Domain::Instance),
        ) => x,
        _ => return Err(ctx.err(format!("domain {d} is not supported"))),
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    let ids = ctx.field("Group ID", DataType::Int)?;
    let mut groups = Groups::default();
    let e = |e: String| ctx.err(e);

    if let Some(m) = g.mesh.clone() {
        if matches!(domain, Domain::Point | Domain::Edge | Domain::Face) {
            match split_component(ComponentRef::Mesh(&m), domain, &sel, &ids).map_err(e)? {
                Split::Empty => {}
                Split::Whole(id) => groups.entry(id).mesh = Some(m.clone()),
                Split::Groups(parts) => {
                    // All groups are added before any is filled (`ensure_group_geometries`).
                    for (id, _) in &parts {
                        groups.entry(*id);
                    }
                    for (id, idx) in parts {
                        let mut keep = vec![false; m.domain_size(domain)];
                        for i in idx {
                            keep[i] = true;
                        }
                        groups.get(id).mesh =
                            Some(Arc::new(mesh_keep(&m, domain, &keep, Mode::All)));
                    }
                }
            }
        }
    }
    if let Some(p) = g.points.clone() {
        if domain == Domain::Point {
            match split_component(ComponentRef::Points(&p), domain, &sel, &ids).map_err(e)? {
                Split::Empty => {}
                Split::Whole(id) => groups.entry(id).points = Some(p.clone()),
                Split::Groups(parts) => {
                    for (id, _) in &parts {
                        groups.entry(*id);
                    }
                    for (id, idx) in parts {
                        let mut q = (*p).clone();
                        q.positions = idx.iter().map(|&i| p.positions[i]).collect();
                        q.attributes.gather_domain(Domain::Point, &idx);
                        groups.get(id).points = Some(Arc::new(q));
                    }
                }
            }
        }
    }
    if let Some(c) = g.curves.clone() {
        if matches!(domain, Domain::Point | Domain::Curve) {
            match split_component(ComponentRef::Curves(&c), domain, &sel, &ids).map_err(e)? {
                Split::Empty => {}
                Split::Whole(id) => groups.entry(id).curves = Some(c.clone()),
                Split::Groups(_) => {
                    return Err(ctx.err(
                        "splitting curves by a varying Group ID or a partial selection is not supported",
                    ))
                }
            }
        }
    }
    if let Some(inst) = g.instances.clone() {
        if domain == Domain::Instance {
            match split_component(ComponentRef::Instances(&inst), domain, &sel, &ids).map_err(e)? {
                Split::Empty => {}
                Split::Whole(id) => groups.entry(id).instances = Some(inst.clone()),
                Split::Groups(parts) => {
                    for (id, _) in &parts {
                        groups.entry(*id);
                    }
                    for (id, idx) in parts {
                        groups.get(id).instances = Some(Arc::new(gather_instances(&inst, &idx)));
                    }
                }
            }
        }
    }

    let keys: Vec<i32> = groups.order.keys().collect();
    let mut out = Instances::default();
    for (k, id) in keys.iter().enumerate() {
        let set = groups.sets.remove(id).unwrap_or_default();
        out.references.push(InstanceReference::Geometry(set));
        out.handles.push(k as u32);
        out.transforms.push(MAT4_IDENTITY);
    }
    let id_attr = ctx
        .output_used("Group ID")
        .then(|| AttrId::anonymous("Group ID"));
    if let Some(a) = &id_attr {
        out.attributes
            .set(a.clone(), Domain::Instance, Array::Int(keys));
    }
    let mut o = outputs([(
        "Instances",
        SocketValue::Geometry(GeometrySet::from_instances(out)),
    )]);
    if let Some(id) = id_attr {
        o.insert(
            "Group ID".into(),
            SocketValue::Field(Field::input(AttributeInput {
                id,
                ty: DataType::Int,
            })),
        );
    }
    Ok(o)
}

/// The instances at `idx`, their references renumbered to the used ones in reference order
/// (`remove_unused_references`).
fn gather_instances(src: &Instances, idx: &[usize]) -> Instances {
    let mut used = vec![false; src.references.len()];
    for &i in idx {
        used[src.handles[i] as usize] = true;
    }
    let mut remap = vec![u32::MAX; src.references.len()];
    let mut out = Instances::default();
    for (r, reference) in src.references.iter().enumerate() {
        if used[r] {
            remap[r] = out.add_reference(reference.clone());
        }
    }
    out.handles = idx
        .iter()
        .map(|&i| remap[src.handles[i] as usize])
        .collect();
    out.transforms = idx.iter().map(|&i| src.transforms[i]).collect();
    out.attributes = src.attributes.clone();
    out.attributes.gather_domain(Domain::Instance, idx);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_order_is_blenders() {
        // Orders Blender 4.5 gave (Split to Instances' Group ID output, read with bpy);
        // the last: a point cloud re-adding id 1 to a full map grows it.
        let order = |keys: &[i32]| {
            let mut m = BlenderIntMap::new();
            for &k in keys {
                m.add(k);
            }
            m.keys().collect::<Vec<_>>()
        };
        assert_eq!(
            order(&[5, 3, 9, 1, 13, 2, -1, 7, 100, 33]),
            vec![1, 2, 3, 100, 5, 7, 9, 13, 33, -1]
        );
        assert_eq!(order(&[3, 3, 1]), vec![1, 3]);
        assert_eq!(order(&[8, 1, 2, 3, 1]), vec![1, 2, 3, 8]);
    }
}

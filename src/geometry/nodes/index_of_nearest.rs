//! Index of Nearest (`node_geo_index_of_nearest`): per element, the index of the nearest
//! other element of the same Group ID (-1 when it is alone), and whether its group has
//! another element.
//!
//! Blender searches a balanced `BLI_kdtree_3d` per group; among elements at the same
//! distance the one it meets first wins, so the tree is rebuilt here in Blender's node
//! order and walked as `BLI_kdtree_3d_find_nearest_cb` walks it (`geometry::kdtree`).

use std::collections::HashMap;

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{Field, FieldContext, FieldInput};
use super::super::kdtree::KdTree;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct IndexOfNearest {
    position: Field,
    group: Field,
}

impl FieldInput for IndexOfNearest {
    fn data_type(&self) -> DataType {
        DataType::Int
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let pos = ctx.eval(&self.position, domain, DataType::Vector)?;
        let pos = pos.as_vector();
        let mut out = vec![-1i32; n];
        let mut stack = Vec::new();
        let groups: Vec<Vec<usize>> = if self.group.as_constant().is_some() {
            vec![(0..n).collect()]
        } else {
            let ids = ctx.eval(&self.group, domain, DataType::Int)?;
            group_members(&ids.as_int())
        };
        for members in groups {
            let tree = KdTree::new(&pos, members.clone());
            for i in members {
                out[i] = tree.nearest_other(&pos, pos[i], i, &mut stack);
            }
        }
        Ok(Array::Int(out))
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        self.position.preferred_domain(ctx)
    }
}

/// Elements per group ID, groups in order of first appearance.
fn group_members(ids: &[i32]) -> Vec<Vec<usize>> {
    let mut slot: HashMap<i32, usize> = HashMap::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, id) in ids.iter().enumerate() {
        let k = *slot.entry(*id).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[k].push(i);
    }
    groups
}

#[derive(Debug)]
struct HasNeighbor {
    group: Field,
}

impl FieldInput for HasNeighbor {
    fn data_type(&self) -> DataType {
        DataType::Bool
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        if n == 1 {
            return Ok(Array::Bool(vec![false]));
        }
        if self.group.as_constant().is_some() {
            return Ok(Array::Bool(vec![true; n]));
        }
        let ids = ctx.eval(&self.group, domain, DataType::Int)?;
        let ids = ids.as_int();
        let mut counts: HashMap<i32, usize> = HashMap::new();
        for id in ids.iter() {
            *counts.entry(*id).or_default() += 1;
        }
        Ok(Array::Bool(ids.iter().map(|id| counts[id] > 1).collect()))
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        self.group.preferred_domain(ctx)
    }
}

pub fn index_of_nearest(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let position = ctx.field("Position", DataType::Vector)?;
    let group = ctx.field("Group ID", DataType::Int)?;
    let mut out = Outputs::new();
    out.insert(
        "Index".into(),
        SocketValue::Field(Field::input(IndexOfNearest {
            position,
            group: group.clone(),
        })),
    );
    out.insert(
        "Has Neighbor".into(),
        SocketValue::Field(Field::input(HasNeighbor { group })),
    );
    Ok(out)
}

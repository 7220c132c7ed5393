//! Fields: functions evaluated per element of a geometry component, on the domain the
//! consuming node asks for.
//!
//! A field is a constant, a context input (Position, Index, Normal, an attribute, ...)
//! evaluated on its own domain and moved to the requested one, or an operation over
//! other fields evaluated element-wise on the requested domain. Operations whose inputs
//! are all constants are folded when built, so single values are just constant fields.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt;
use std::sync::Arc;

use super::attribute::AttrId;
use super::curves::Curves;
use super::instances::Instances;
use super::interpolate::{adapt_curves, adapt_mesh};
use super::mesh::Mesh;
use super::pointcloud::PointCloud;
use super::types::{Array, DataType, Domain, Value};

/// The component a field is evaluated on.
#[derive(Clone, Copy)]
pub enum ComponentRef<'a> {
    Mesh(&'a Mesh),
    Curves(&'a Curves),
    Points(&'a PointCloud),
    Instances(&'a Instances),
}

impl<'a> ComponentRef<'a> {
    pub fn domain_size(&self, d: Domain) -> usize {
        match self {
            ComponentRef::Mesh(m) => m.domain_size(d),
            ComponentRef::Curves(c) => c.domain_size(d),
            ComponentRef::Points(p) => p.domain_size(d),
            ComponentRef::Instances(i) => i.domain_size(d),
        }
    }
    /// Whether the component has this domain.
    pub fn has_domain(&self, d: Domain) -> bool {
        match self {
            ComponentRef::Mesh(_) => matches!(
                d,
                Domain::Point | Domain::Edge | Domain::Face | Domain::Corner
            ),
            ComponentRef::Curves(_) => matches!(d, Domain::Point | Domain::Curve),
            ComponentRef::Points(_) => d == Domain::Point,
            ComponentRef::Instances(_) => d == Domain::Instance,
        }
    }
    pub fn adapt(&self, data: &Array, from: Domain, to: Domain) -> Array {
        if from == to {
            return data.clone();
        }
        match self {
            ComponentRef::Mesh(m) => adapt_mesh(m, data, from, to),
            ComponentRef::Curves(c) => adapt_curves(c, data, from, to),
            _ => Array::zeros(data.data_type(), self.domain_size(to)),
        }
    }
    /// An attribute by id (built-in `position` included), with its domain.
    pub fn attribute(&self, id: &AttrId) -> Option<(Domain, Array)> {
        let is_pos = id.name() == Some("position");
        match self {
            ComponentRef::Mesh(m) => m.attribute(id),
            ComponentRef::Curves(c) => {
                if is_pos {
                    return Some((Domain::Point, Array::Vector(c.positions.clone())));
                }
                c.attributes.get(id).map(|a| (a.domain, a.data.clone()))
            }
            ComponentRef::Points(p) => {
                if is_pos {
                    return Some((Domain::Point, Array::Vector(p.positions.clone())));
                }
                p.attributes.get(id).map(|a| (a.domain, a.data.clone()))
            }
            ComponentRef::Instances(i) => {
                if is_pos {
                    return Some((
                        Domain::Instance,
                        Array::Vector(
                            i.transforms
                                .iter()
                                .map(|t| [t[3][0], t[3][1], t[3][2]])
                                .collect(),
                        ),
                    ));
                }
                i.attributes.get(id).map(|a| (a.domain, a.data.clone()))
            }
        }
    }
    /// The domain positions live on.
    pub fn point_domain(&self) -> Domain {
        match self {
            ComponentRef::Instances(_) => Domain::Instance,
            _ => Domain::Point,
        }
    }
}

/// Results of operations per (operation, domain).
type OpCache = RefCell<HashMap<(usize, Domain), Arc<Vec<Array>>>>;

/// Evaluation state for one component: results of operations are kept per domain, so a
/// field used twice is computed once.
pub struct FieldContext<'a> {
    pub component: ComponentRef<'a>,
    cache: OpCache,
    /// Blender's `Grid3DFieldContext` (Volume Cube): only the `position` attribute is
    /// given, every other context input reads its type's default (0).
    position_only: bool,
}

impl<'a> FieldContext<'a> {
    pub fn new(component: ComponentRef<'a>) -> Self {
        FieldContext {
            component,
            cache: RefCell::new(HashMap::new()),
            position_only: false,
        }
    }
    /// A context over `points`' positions that gives nothing else, as Blender's
    /// `Grid3DFieldContext` (Index, ID, Normal, other attributes, and inputs such as
    /// Evaluate on Domain all read 0 there).
    pub fn position_only(points: &'a PointCloud) -> Self {
        FieldContext {
            position_only: true,
            ..FieldContext::new(ComponentRef::Points(points))
        }
    }
    /// Evaluates `field` on `domain`, converted to `ty`.
    pub fn eval(&self, field: &Field, domain: Domain, ty: DataType) -> Result<Array, String> {
        Ok(field.evaluate(self, domain)?.convert(ty))
    }
}

/// A context-dependent input: evaluated on a domain of a component.
pub trait FieldInput: fmt::Debug + Send + Sync {
    fn data_type(&self) -> DataType;
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String>;
    /// The domain the input naturally lives on (for Capture/Store "auto" choices).
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        None
    }
    /// The attribute the input reads when it is Blender's `AttributeFieldInput`
    /// (Position, Named Attribute).
    fn attribute_name(&self) -> Option<&str> {
        None
    }
    /// Whether the input is one of Blender's multi-functions that read another geometry
    /// (Sample Index): those work in every context, the grid's included, where the
    /// context's own inputs read 0.
    fn samples_other_geometry(&self) -> bool {
        false
    }
}

type OpFn = dyn Fn(usize, &[Array]) -> Result<Vec<Array>, String> + Send + Sync;

/// An element-wise operation with several inputs and outputs.
pub struct FieldOp {
    pub label: String,
    pub inputs: Vec<Field>,
    pub outputs: Vec<DataType>,
    pub func: Box<OpFn>,
}

impl fmt::Debug for FieldOp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "FieldOp({})", self.label)
    }
}

#[derive(Debug, Clone)]
pub enum Field {
    Constant(Value),
    Input(Arc<dyn FieldInput>),
    Op(Arc<FieldOp>, usize),
}

impl Field {
    pub fn constant(v: Value) -> Field {
        Field::Constant(v)
    }
    pub fn input(i: impl FieldInput + 'static) -> Field {
        Field::Input(Arc::new(i))
    }
    pub fn data_type(&self) -> DataType {
        match self {
            Field::Constant(v) => v.data_type(),
            Field::Input(i) => i.data_type(),
            Field::Op(op, k) => op.outputs[*k],
        }
    }
    pub fn as_constant(&self) -> Option<Value> {
        match self {
            Field::Constant(v) => Some(*v),
            _ => None,
        }
    }

    /// Builds an operation (folded to constants when every input is one).
    pub fn op(
        label: impl Into<String>,
        inputs: Vec<Field>,
        outputs: Vec<DataType>,
        func: impl Fn(usize, &[Array]) -> Result<Vec<Array>, String> + Send + Sync + 'static,
    ) -> Result<Vec<Field>, String> {
        if inputs.iter().all(|f| matches!(f, Field::Constant(_))) {
            let arrays: Vec<Array> = inputs
                .iter()
                .map(|f| Array::filled(f.as_constant().unwrap(), 1))
                .collect();
            let out = func(1, &arrays)?;
            return Ok(out
                .into_iter()
                .zip(&outputs)
                .map(|(a, t)| Field::Constant(a.convert(*t).get(0)))
                .collect());
        }
        let n = outputs.len();
        let op = Arc::new(FieldOp {
            label: label.into(),
            inputs,
            outputs,
            func: Box::new(func),
        });
        Ok((0..n).map(|k| Field::Op(op.clone(), k)).collect())
    }

    /// One-output convenience for `op`.
    pub fn op1(
        label: impl Into<String>,
        inputs: Vec<Field>,
        output: DataType,
        func: impl Fn(usize, &[Array]) -> Result<Array, String> + Send + Sync + 'static,
    ) -> Result<Field, String> {
        Ok(Field::op(label, inputs, vec![output], move |n, a| {
            Ok(vec![func(n, a)?])
        })?
        .remove(0))
    }

    /// The field with Blender's implicit conversion to `to` applied.
    pub fn convert(self, to: DataType) -> Field {
        if self.data_type() == to {
            return self;
        }
        match self {
            Field::Constant(v) => Field::Constant(v.convert(to)),
            f => Field::op1("convert", vec![f], to, move |_, a| Ok(a[0].convert(to)))
                .expect("conversion cannot fail"),
        }
    }

    /// Whether the value depends on the geometry it is evaluated on.
    pub fn depends_on_context(&self) -> bool {
        !matches!(self, Field::Constant(_))
    }

    /// Evaluates on `domain` of the context's component.
    pub fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        match self {
            Field::Constant(v) => Ok(Array::filled(*v, n)),
            Field::Input(i)
                if ctx.position_only
                    && i.attribute_name() != Some("position")
                    && !i.samples_other_geometry() =>
            {
                Ok(Array::zeros(i.data_type(), n))
            }
            Field::Input(i) => {
                let a = i.evaluate(ctx, domain)?;
                debug_assert_eq!(a.len(), n);
                Ok(a)
            }
            Field::Op(op, k) => {
                let key = (Arc::as_ptr(op) as *const u8 as usize, domain);
                if let Some(r) = ctx.cache.borrow().get(&key) {
                    return Ok(r[*k].clone());
                }
                let mut args = Vec::with_capacity(op.inputs.len());
                for f in &op.inputs {
                    args.push(f.evaluate(ctx, domain)?);
                }
                let out = (op.func)(n, &args).map_err(|e| format!("{}: {e}", op.label))?;
                let out: Vec<Array> = out
                    .into_iter()
                    .zip(&op.outputs)
                    .map(|(a, t)| a.convert(*t))
                    .collect();
                let r = out[*k].clone();
                ctx.cache.borrow_mut().insert(key, Arc::new(out));
                Ok(r)
            }
        }
    }

    /// The highest-priority domain any input prefers (None for constants).
    pub fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        match self {
            Field::Constant(_) => None,
            Field::Input(i) => i.preferred_domain(ctx),
            Field::Op(op, _) => op
                .inputs
                .iter()
                .filter_map(|f| f.preferred_domain(ctx))
                .max_by_key(|d| d.priority()),
        }
    }
}

// --- Common inputs -----------------------------------------------------------------------

/// Position: vertex / point positions, instance translations.
#[derive(Debug)]
pub struct PositionInput;
impl FieldInput for PositionInput {
    fn data_type(&self) -> DataType {
        DataType::Vector
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let c = &ctx.component;
        let (d, a) = c
            .attribute(&AttrId::named("position"))
            .ok_or("no positions")?;
        Ok(c.adapt(&a, d, domain))
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        Some(ctx.component.point_domain())
    }
    fn attribute_name(&self) -> Option<&str> {
        Some("position")
    }
}

/// Index of the element in the domain.
#[derive(Debug)]
pub struct IndexInput;
impl FieldInput for IndexInput {
    fn data_type(&self) -> DataType {
        DataType::Int
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        Ok(Array::Int(
            (0..ctx.component.domain_size(domain) as i32).collect(),
        ))
    }
}

/// ID: the `id` attribute when there is one, else the index (`id_or_index`).
#[derive(Debug)]
pub struct IdInput;
impl FieldInput for IdInput {
    fn data_type(&self) -> DataType {
        DataType::Int
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        match ctx.component.attribute(&AttrId::named("id")) {
            Some((d, a)) => Ok(ctx.component.adapt(&a.convert(DataType::Int), d, domain)),
            None => IndexInput.evaluate(ctx, domain),
        }
    }
}

/// A stored attribute read as `ty` (the type's default where it does not exist).
#[derive(Debug)]
pub struct AttributeInput {
    pub id: AttrId,
    pub ty: DataType,
}
impl FieldInput for AttributeInput {
    fn data_type(&self) -> DataType {
        self.ty
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        match ctx.component.attribute(&self.id) {
            Some((d, a)) if ctx.component.has_domain(d) => Ok(ctx
                .component
                .adapt(&a.convert(self.ty.socket_type()), d, domain)
                .convert(self.ty)),
            _ => Ok(Array::zeros(self.ty, n)),
        }
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        ctx.component.attribute(&self.id).map(|(d, _)| d)
    }
    fn attribute_name(&self) -> Option<&str> {
        self.id.name()
    }
}

/// Normal: mesh vertex, edge, face or corner normals as Blender's Normal node gives them.
#[derive(Debug)]
pub struct NormalInput;
impl FieldInput for NormalInput {
    fn data_type(&self) -> DataType {
        DataType::Vector
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        match ctx.component {
            ComponentRef::Mesh(m) if m.free_custom_normals().is_some() => {
                m.custom_normals_on(domain).unwrap().map(Array::Vector)
            }
            ComponentRef::Mesh(m) => Ok(Array::Vector(match domain {
                Domain::Point => m.vertex_normals(),
                Domain::Face => m.face_normals(),
                Domain::Corner => m.corner_normals(),
                Domain::Edge => {
                    let vn = m.vertex_normals();
                    m.edges
                        .iter()
                        .map(|e| {
                            let (a, b) = (vn[e[0] as usize], vn[e[1] as usize]);
                            super::math::normalize([
                                a[0] * 0.5 + b[0] * 0.5,
                                a[1] * 0.5 + b[1] * 0.5,
                                a[2] * 0.5 + b[2] * 0.5,
                            ])
                        })
                        .collect()
                }
                _ => vec![[0.0; 3]; m.domain_size(domain)],
            })),
            ComponentRef::Points(p) => {
                Ok(Array::Vector(vec![[0.0, 0.0, 1.0]; p.domain_size(domain)]))
            }
            ComponentRef::Curves(c) => Ok(ctx.component.adapt(
                &Array::Vector(super::curve_eval::control_point_normals(c)?),
                Domain::Point,
                domain,
            )),
            _ => {
                Err("the Normal input is only supported on meshes, curves and point clouds".into())
            }
        }
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        match ctx.component {
            ComponentRef::Mesh(_) => Some(Domain::Face),
            _ => None,
        }
    }
}

/// Evaluates a field on another domain and moves the result (Evaluate on Domain).
#[derive(Debug)]
pub struct EvaluateOnDomain {
    pub field: Field,
    pub domain: Domain,
}
impl FieldInput for EvaluateOnDomain {
    fn data_type(&self) -> DataType {
        self.field.data_type()
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        if !ctx.component.has_domain(self.domain) {
            return Ok(Array::zeros(
                self.data_type(),
                ctx.component.domain_size(domain),
            ));
        }
        let a = self.field.evaluate(ctx, self.domain)?;
        Ok(ctx.component.adapt(&a, self.domain, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(self.domain)
    }
}

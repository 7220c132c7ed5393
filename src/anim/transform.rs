//! Object transforms: the basis matrix from location / rotation (every Euler order,
//! quaternion, axis-angle) / scale and their deltas (`BKE_object_to_mat4`), then world
//! matrices through parent chains with the parent inverse (`solve_parenting`, including
//! the path offset of a child of a path curve) and the constraint stack.

use std::collections::HashMap;

use super::animate::{object_label, Datablocks};
use super::constraint::{self, Kind};
use super::error::AnimError;
use super::math::*;
use super::path::{build_path, Path};
use crate::scene::{quote, Object};

/// Blender's rotation order table: axis permutation and parity per Euler order.
fn euler_order(mode: &str) -> Option<([usize; 3], bool)> {
    Some(match mode {
        "XYZ" => ([0, 1, 2], false),
        "XZY" => ([0, 2, 1], true),
        "YXZ" => ([1, 0, 2], true),
        "YZX" => ([1, 2, 0], false),
        "ZXY" => ([2, 0, 1], false),
        "ZYX" => ([2, 1, 0], true),
        _ => return None,
    })
}

/// Blender's `eulO_to_mat3`, as a row-major matrix.
pub fn euler_to_mat3(e: [f64; 3], mode: &str) -> Option<Mat3> {
    let ([i, j, k], parity) = euler_order(mode)?;
    let (ti, tj, th) = if parity {
        (-e[i], -e[j], -e[k])
    } else {
        (e[i], e[j], e[k])
    };
    let (ci, cj, ch) = (ti.cos(), tj.cos(), th.cos());
    let (si, sj, sh) = (ti.sin(), tj.sin(), th.sin());
    let (cc, cs, sc, ss) = (ci * ch, ci * sh, si * ch, si * sh);
    let mut m = [[0.0; 3]; 3];
    // Blender's M[col][row] entries, transposed into m[row][col].
    m[i][i] = cj * ch;
    m[i][j] = sj * sc - cs;
    m[i][k] = sj * cc + ss;
    m[j][i] = cj * sh;
    m[j][j] = sj * ss + cc;
    m[j][k] = sj * cs - sc;
    m[k][i] = -sj;
    m[k][j] = cj * si;
    m[k][k] = cj * ci;
    Some(m)
}

fn axis_angle_to_mat3(axis: [f64; 3], angle: f64) -> Mat3 {
    let mut n = axis;
    if normalize64(&mut n) == 0.0 {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    let (s, c) = angle.sin_cos();
    let ico = 1.0 - c;
    let nsi = [n[0] * s, n[1] * s, n[2] * s];
    [
        [
            n[0] * n[0] * ico + c,
            n[0] * n[1] * ico - nsi[2],
            n[0] * n[2] * ico + nsi[1],
        ],
        [
            n[0] * n[1] * ico + nsi[2],
            n[1] * n[1] * ico + c,
            n[1] * n[2] * ico - nsi[0],
        ],
        [
            n[0] * n[2] * ico - nsi[1],
            n[1] * n[2] * ico + nsi[0],
            n[2] * n[2] * ico + c,
        ],
    ]
}

/// The object's own transform (no parent, no constraints): `matrix_basis`.
pub fn basis_matrix(o: &Object) -> Result<Mat4, AnimError> {
    let dscale = o.delta_scale.unwrap_or([1.0; 3]);
    let size = [
        o.scale[0] * dscale[0],
        o.scale[1] * dscale[1],
        o.scale[2] * dscale[2],
    ];
    let (rmat, dmat) = match o.rotation_mode.as_str() {
        "QUATERNION" => {
            let q = normalize_quat64(o.rotation_quaternion);
            let dq = normalize_quat64(o.delta_rotation_quaternion.unwrap_or([1.0, 0.0, 0.0, 0.0]));
            (quat_to_mat3_64(q), quat_to_mat3_64(dq))
        }
        "AXIS_ANGLE" => {
            // RNA order is (angle, x, y, z); the delta axis-angle is not exposed in RNA
            // (it is identity unless set from C).
            let aa = o.rotation_axis_angle.unwrap_or([0.0, 0.0, 1.0, 0.0]);
            (
                axis_angle_to_mat3([aa[1], aa[2], aa[3]], aa[0]),
                axis_angle_to_mat3([0.0, 1.0, 0.0], 0.0),
            )
        }
        mode => {
            let r = euler_to_mat3(o.rotation_euler, mode).ok_or_else(|| {
                AnimError::new("rotation_mode", format!("unknown rotation mode {mode:?}"))
            })?;
            let d = euler_to_mat3(o.delta_rotation_euler.unwrap_or([0.0; 3]), mode).unwrap();
            (r, d)
        }
    };
    let rot = mul3(&dmat, &rmat);
    let smat = [
        [size[0], 0.0, 0.0],
        [0.0, size[1], 0.0],
        [0.0, 0.0, size[2]],
    ];
    let mut m = mat3_to_mat4(&mul3(&rot, &smat));
    let dloc = o.delta_location.unwrap_or([0.0; 3]);
    set_translation(
        &mut m,
        [
            o.location[0] + dloc[0],
            o.location[1] + dloc[1],
            o.location[2] + dloc[2],
        ],
    );
    Ok(m)
}

#[derive(Clone, Copy, PartialEq)]
enum State {
    Todo,
    Busy,
    Done,
    /// Its matrix could not be computed (`Solver::failed` holds why).
    Failed,
}

/// Computes world matrices in dependency order (parents and constraint targets first).
pub struct Solver<'a> {
    data: &'a Datablocks,
    for_render: bool,
    /// Objects' `track_axis`/`up_axis`, when the export has them (only a
    /// child of a following path curve needs them).
    track_axes: &'a HashMap<String, (i32, i32)>,
    index: HashMap<&'a str, usize>,
    state: Vec<State>,
    world: Vec<Mat4>,
    paths: HashMap<String, Option<Path>>,
    bones: Option<BoneParents>,
    failed: HashMap<usize, AnimError>,
}

/// What bone parenting needs: pose bones are not exported, so a bone's matrix relative to
/// its armature is taken from the exported world matrices (child world times the inverse
/// of its parent inverse and basis, relative to the armature's world), which holds at
/// every frame while nothing poses the armature, and only at the exported frame otherwise.
#[derive(Debug, Clone, Default)]
pub struct BoneParents {
    pub frame: f64,
    pub export_frame: f64,
    /// Armature object name -> an animated pose path (F-curve or driver).
    pub posed: HashMap<String, String>,
}

impl<'a> Solver<'a> {
    pub fn new(
        data: &'a Datablocks,
        for_render: bool,
        track_axes: &'a HashMap<String, (i32, i32)>,
    ) -> Self {
        let index = data
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| (o.name.as_str(), i))
            .collect();
        let n = data.objects.len();
        Solver {
            data,
            for_render,
            track_axes,
            index,
            state: vec![State::Todo; n],
            world: vec![IDENTITY; n],
            paths: HashMap::new(),
            bones: None,
            failed: HashMap::new(),
        }
    }

    /// Enables bone parents (see `BoneParents`).
    pub fn with_bone_parents(mut self, bones: BoneParents) -> Self {
        self.bones = Some(bones);
        self
    }

    /// A bone parent's matrix at this frame: the armature's world times the bone's pose
    /// relative to it at the export.
    fn bone_parent(&self, o: &Object, p: usize, pw: &Mat4) -> Result<Mat4, AnimError> {
        let arm = &self.data.objects[p];
        let bone = o.parent_bone.as_deref().unwrap_or("");
        let Some(b) = &self.bones else {
            return Err(AnimError::new(
                "parent_type",
                "parent type \"BONE\" is not supported here",
            ));
        };
        if let Some(path) = b.posed.get(&arm.name) {
            if (b.frame - b.export_frame).abs() > 1e-6 {
                return Err(AnimError::new(
                    "parent_type",
                    format!(
                        "parent type \"BONE\" (bone {bone:?} of {:?}): the armature is posed by animation ({path}), and pose bones are only known at the exported frame {}",
                        arm.name, b.export_frame
                    ),
                ));
            }
        }
        let (Some(basis), Some(mpi)) = (o.matrix_basis, o.matrix_parent_inverse) else {
            return Err(AnimError::new(
                "parent_type",
                "parent type \"BONE\": the export lacks matrix_basis / matrix_parent_inverse",
            ));
        };
        let singular = || AnimError::new("parent_type", "parent type \"BONE\": singular matrix");
        let local = super::math::inverse(&mul(&mpi, &basis)).ok_or_else(singular)?;
        let bone_world = mul(&o.matrix_world, &local);
        let arm_inv = super::math::inverse(&arm.matrix_world).ok_or_else(singular)?;
        Ok(mul(pw, &mul(&arm_inv, &bone_world)))
    }

    /// Every object's world matrix; an object `needed` rejects whose matrix cannot be
    /// computed (a camera that is not the scene's with an unsupported constraint) keeps
    /// its exported matrix instead of failing the frame: Blender evaluates it, but
    /// nothing rendered depends on it. Objects it parents or targets are still solved
    /// through it and fail by name.
    pub fn solve_needed(
        mut self,
        needed: impl Fn(&Object) -> bool,
    ) -> Result<Vec<Mat4>, AnimError> {
        for i in 0..self.data.objects.len() {
            if let Err(e) = self.world(i) {
                let o = &self.data.objects[i];
                if needed(o) {
                    return Err(e);
                }
                self.world[i] = o.matrix_world;
            }
        }
        Ok(self.world)
    }

    fn object_index(&self, name: &str, context: &str) -> Result<usize, AnimError> {
        self.index.get(name).copied().ok_or_else(|| {
            AnimError::new(
                context,
                format!("names object {name:?}, which does not exist"),
            )
        })
    }

    fn path_of(&mut self, curve_name: &str) -> Result<Option<&Path>, AnimError> {
        if !self.paths.contains_key(curve_name) {
            let curve = self
                .data
                .curves
                .iter()
                .find(|c| c.name == curve_name)
                .ok_or_else(|| {
                    AnimError::new(format!("curves[{}]", quote(curve_name)), "not in the scene")
                })?;
            let p = build_path(curve, self.for_render)
                .map_err(|e| e.within(&format!("curves[{}]", quote(curve_name))))?;
            self.paths.insert(curve_name.to_string(), p);
        }
        Ok(self.paths[curve_name].as_ref())
    }

    fn world(&mut self, i: usize) -> Result<Mat4, AnimError> {
        match self.state[i] {
            State::Done => return Ok(self.world[i]),
            State::Failed => return Err(self.failed[&i].clone()),
            State::Busy => {
                return Err(AnimError::new(
                    object_label(&self.data.objects[i].name),
                    "dependency cycle through parents or constraint targets",
                ));
            }
            State::Todo => {}
        }
        self.state[i] = State::Busy;
        let o = &self.data.objects[i];
        let label = object_label(&o.name);
        let m = match self.compute(i) {
            Ok(m) => m,
            Err(e) => {
                let e = e.within(&label);
                self.state[i] = State::Failed;
                self.failed.insert(i, e.clone());
                return Err(e);
            }
        };
        self.world[i] = m;
        self.state[i] = State::Done;
        Ok(m)
    }

    fn compute(&mut self, i: usize) -> Result<Mat4, AnimError> {
        let data = self.data;
        let o = &data.objects[i];
        let local = basis_matrix(o)?;
        let mut m = match &o.parent {
            None => local,
            Some(pname) => {
                let p = self.object_index(pname, "parent")?;
                let pw = self.world(p)?;
                let parent_mat = match o.parent_type.as_deref().unwrap_or("OBJECT") {
                    "OBJECT" => match self.parent_curve_offset(o, p)? {
                        Some(path_mat) => mul(&pw, &path_mat),
                        None => pw,
                    },
                    // Armature/lattice deform parents move children like a plain parent.
                    "ARMATURE" | "LATTICE" => pw,
                    "BONE" => self.bone_parent(o, p, &pw)?,
                    other => {
                        return Err(AnimError::new(
                            "parent_type",
                            format!("parent type {other:?} is not supported"),
                        ))
                    }
                };
                let inv = o.matrix_parent_inverse.unwrap_or(IDENTITY);
                mul(&mul(&parent_mat, &inv), &local)
            }
        };
        for c in &o.constraints {
            let at = format!("constraints[{}]", quote(&c.name));
            let Some(parsed) = constraint::parse(c).map_err(|e| e.within(&at))? else {
                continue;
            };
            let t = self.object_index(parsed.target(), &format!("{at}.target"))?;
            let target_world = self.world(t)?;
            let old = m;
            m = match &parsed.kind {
                Kind::FollowPath { .. } => {
                    let tobj = &data.objects[t];
                    let curve = match (tobj.kind.as_str(), &tobj.data) {
                        ("CURVE", Some(d)) => data.curves.iter().find(|cv| &cv.name == d),
                        _ => None,
                    };
                    match curve {
                        // Blender treats a non-curve target as an identity target matrix.
                        None => constraint::follow_path(&parsed.kind, &m, &IDENTITY),
                        Some(curve) => {
                            let path = self.path_of(&curve.name).map_err(|e| e.within(&at))?;
                            let tm = constraint::follow_path_target(
                                &parsed.kind,
                                curve,
                                &target_world,
                                path,
                            );
                            constraint::follow_path(&parsed.kind, &m, &tm)
                        }
                    }
                }
                Kind::TrackTo { .. } => constraint::track_to(&parsed.kind, &m, &target_world),
                Kind::DampedTrack { .. } => {
                    constraint::damped_track(&parsed.kind, &m, &target_world)
                }
            };
            // Influence blends in world space (Blender's interp_m4_m4m4).
            if parsed.influence < 1.0 {
                m = interp_mat4(&old, &m, parsed.influence);
            }
        }
        Ok(m)
    }

    /// Blender's `ob_parcurve`: a child of a curve with path animation sits on the path at
    /// the curve's `eval_time`.
    fn parent_curve_offset(&mut self, o: &Object, p: usize) -> Result<Option<Mat4>, AnimError> {
        let data = self.data;
        let po = &data.objects[p];
        let (true, Some(cname)) = (po.kind == "CURVE", &po.data) else {
            return Ok(None);
        };
        let Some(curve) = data.curves.iter().find(|c| &c.name == cname) else {
            return Ok(None);
        };
        let rb = |k: &str| {
            curve
                .properties
                .get(k)
                .and_then(|v| v.as_bool())
                .unwrap_or(false)
        };
        if !rb("use_path") {
            return Ok(None);
        }
        let follow = rb("use_path_follow");
        let use_radius = rb("use_radius");
        let clamp = rb("use_path_clamp");
        let eval_time = curve
            .properties
            .get("eval_time")
            .and_then(|v| v.as_f64())
            .unwrap_or(0.0) as f32;
        let pathlen = curve
            .properties
            .get("path_duration")
            .and_then(|v| v.as_f64())
            .unwrap_or(100.0) as i32;
        let axes = if follow {
            Some(*self.track_axes.get(&o.name).ok_or_else(|| {
                AnimError::new(
                    "parent",
                    "is a curve with Follow on its path, which needs the object's track_axis/up_axis; the export does not have them (re-export with a current exporter)",
                )
            })?)
        } else {
            None
        };
        let Some(path) = self.path_of(cname)? else {
            return Ok(None);
        };
        let mut ctime = if pathlen != 0 {
            eval_time / pathlen as f32
        } else {
            eval_time
        };
        if clamp {
            ctime = ctime.clamp(0.0, 1.0);
        }
        let s = path.sample(ctime);
        let mut r = IDENTITY;
        if let Some((track, up)) = axes {
            let mut q = quat_apply_track(s.quat, track, up);
            qnormalize(&mut q);
            let m3 = quat_to_mat3(q);
            for a in 0..3 {
                for b in 0..3 {
                    r[a][b] = m3[a][b] as f64;
                }
            }
        }
        if use_radius {
            for row in r.iter_mut().take(3) {
                for v in row.iter_mut().take(3) {
                    *v *= s.radius as f64;
                }
            }
        }
        set_translation(&mut r, [s.pos[0] as f64, s.pos[1] as f64, s.pos[2] as f64]);
        Ok(Some(r))
    }
}

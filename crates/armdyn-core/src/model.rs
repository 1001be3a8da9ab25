//! The immutable model: built once from a robot description, then shared (read-only)
//! by any number of threads, each with its own [`crate::Data`] workspace.

use crate::joint::JointKind;
use crate::joint_multi::MultiKind;
use crate::real::Real;
use crate::spatial::{Motion, RigidInertia, Sym3, Xform, M3, V3};
use std::fmt;

/// A joint's type in the description.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    Revolute,
    Prismatic,
    Fixed,
    /// Joints of several coordinates (`joint_multi.rs`); their `axis` is ignored.
    Spherical,
    Planar,
    Free,
}

impl JointType {
    /// The joint of several coordinates this type is, if it is one.
    pub fn multi(self) -> Option<MultiKind> {
        match self {
            JointType::Spherical => Some(MultiKind::Spherical),
            JointType::Planar => Some(MultiKind::Planar),
            JointType::Free => Some(MultiKind::Free),
            JointType::Revolute | JointType::Prismatic | JointType::Fixed => None,
        }
    }

    /// Velocity coordinates (= bodies in the model): 0 for a fixed joint, 1 for a
    /// revolute or prismatic one, a joint of several coordinates' parts.
    pub fn nv(self) -> usize {
        match (self, self.multi()) {
            (_, Some(kind)) => kind.parts().len(),
            (JointType::Fixed, None) => 0,
            _ => 1,
        }
    }
}

/// How a body's transform from its parent follows from `q` (`joint_multi.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyMotion {
    /// A 1-dof joint's body: `kind.xup(xtree, q[idx_q])`.
    Axis,
    /// The first part of a joint of several coordinates: its whole motion, from
    /// `q[idx_q..idx_q + nq]`.
    Head(MultiKind),
    /// A later part: a constant re-framing `xtree` of the part before it.
    Tail,
}

/// A joint of several coordinates: its kind, its first body and its block of `q`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MultiJoint {
    pub kind: MultiKind,
    pub body: usize,
    pub idx_q: usize,
}

/// One joint of the description, with its child link's inertia (the convention of
/// armdyn's `model.py`).
///
/// * `parent`: index of the joint whose child link is this joint's parent link, or
///   `None` for the base. Joints are in tree order: `parent < ` this joint's index.
/// * `rotation` (3x3, row-major) and `translation` (3): the placement frame in the parent
///   link's frame (the placement's axes as columns, in parent coordinates; its origin).
/// * `axis` (3): unit axis of motion in the placement frame (ignored when fixed).
///   Revolute: child frame = placement * Rot(axis, q); prismatic: placement translated
///   by `q axis`; fixed: the placement.
/// * `mass`, `com` (3, child link frame), `inertia` (3x3 about the centre of mass, child
///   link axes): the child link.
#[derive(Clone, Debug)]
pub struct JointSpec {
    pub parent: Option<usize>,
    pub jtype: JointType,
    pub rotation: [[f64; 3]; 3],
    pub translation: [f64; 3],
    pub axis: [f64; 3],
    pub mass: f64,
    pub com: [f64; 3],
    pub inertia: [[f64; 3]; 3],
}

/// What a movable joint adds to the rigid-body torque (docs/architecture.md):
/// `tau_i += armature qdd_i + viscous qd_i + coulomb sign(qd_i) + offset` (sign(0) = 0).
/// `armature` is the rotor inertia reflected to the joint (Pinocchio's `armature`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointDynamics {
    pub armature: f64,
    pub viscous: f64,
    pub coulomb: f64,
    pub offset: f64,
}

impl JointDynamics {
    /// Whether every term is zero (the joint adds nothing).
    pub fn is_zero(&self) -> bool {
        *self == JointDynamics::default()
    }
    /// `viscous qd + coulomb sign(qd) + offset`: the torque the motor spends on the joint
    /// itself at rate `qd` (what the ABA subtracts from `tau` before it reaches the link).
    #[inline(always)]
    pub fn passive_torque<T: Real>(&self, qd: T) -> T {
        T::splat(self.viscous) * qd + T::splat(self.coulomb) * qd.sign0() + T::splat(self.offset)
    }
}

/// An invalid description: which joint (if any) and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelError {
    pub joint: Option<usize>,
    pub message: String,
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self.joint {
            Some(k) => write!(f, "joint {k}: {}", self.message),
            None => write!(f, "{}", self.message),
        }
    }
}
impl std::error::Error for ModelError {}

/// Where a link frame sits: rigidly attached to a movable body (or the base), at a
/// constant pose in that body's frame.
#[derive(Clone, Copy, Debug)]
pub struct LinkFrame {
    /// The movable body carrying the link, `None` for links welded to the base.
    pub body: Option<usize>,
    /// Orientation of the link frame in the body frame (link axes as columns).
    pub rotation: M3<f64>,
    /// Origin of the link frame in the body frame.
    pub translation: V3<f64>,
}

/// The dynamics model: one body per movable joint, fixed joints merged away.
///
/// Body `i` (0..nv) is the child of the i-th movable joint; its frame is the joint's
/// placement frame re-oriented so that the joint axis is z (see `joint.rs`), after the
/// joint's motion. Links rigidly attached to it by fixed joints have their inertia
/// added to it and keep their frames in `links` for kinematics.
#[derive(Clone, Debug)]
pub struct Model {
    /// Number of velocity coordinates (= bodies: a joint of several coordinates has one
    /// body per velocity coordinate, `joint_multi.rs`).
    pub nv: usize,
    /// Number of configuration coordinates (`nv` plus one per quaternion or planar turn).
    pub nq: usize,
    /// Where body i's coordinate (or, for a head, its joint's block) starts in `q`.
    pub idx_q: Vec<usize>,
    /// How body i's transform follows from `q`.
    pub motion: Vec<BodyMotion>,
    /// A head's re-framing `Ra^T` (z to its first part's axis); identity elsewhere.
    pub head_frame: Vec<M3<f64>>,
    /// The joints of several coordinates, in tree order (empty for an arm of 1-dof joints).
    pub multi: Vec<MultiJoint>,
    /// `lambda(i)`: the parent body, `None` for the base. Always `< i`.
    pub parent: Vec<Option<usize>>,
    /// Joint type of body i, after re-framing (`S` along z).
    pub kind: Vec<JointKind>,
    /// `X_T(i)`: from the parent body's frame to joint i's placement frame.
    pub xtree: Vec<Xform<f64>>,
    /// Body i's spatial inertia (merged with its fixed descendants), body frame.
    pub inertia: Vec<RigidInertia<f64>>,
    /// Gravity, base frame (m/s^2).
    pub gravity: V3<f64>,
    /// `a_0 = -a_g = [0; -gravity]`: the base acceleration that makes the RNEA and ABA
    /// include gravity (RBDA 5.3).
    pub a0: Motion<f64>,
    /// Every link of the description, base first then each joint's child in order.
    pub links: Vec<LinkFrame>,
    /// For each description joint, its body index (`None` for fixed joints).
    pub joint_body: Vec<Option<usize>>,
    /// Potential energy of the links welded to the base (constant, `-sum m g . p_c`).
    pub welded_potential: f64,
    /// Spatial inertia of the base link and the links welded to it, base frame: what
    /// moves with a floating base (`algo::floating`); a fixed base ignores it.
    pub base_inertia: RigidInertia<f64>,
    /// Joint friction, rotor inertia and offset of body i's joint (zero by default; set
    /// with [`Model::set_joint_dynamics`]).
    pub joint_dynamics: Vec<JointDynamics>,
    /// Whether any `joint_dynamics` is nonzero (the algorithms skip the terms otherwise).
    pub has_joint_dynamics: bool,
}

const TOL: f64 = 1e-9;

/// A rotation `Ra` (columns: an orthonormal right-handed basis) with `Ra e_z = axis`.
/// Exact for the coordinate axes, so axis-aligned models stay exact.
fn frame_with_z(a: V3<f64>) -> M3<f64> {
    let exact = |ra: [[f64; 3]; 3]| M3::from_rows(V3::from_array(ra[0]), V3::from_array(ra[1]), V3::from_array(ra[2]));
    match a.to_array() {
        [0.0, 0.0, 1.0] => exact([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        [0.0, 0.0, -1.0] => exact([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]),
        [1.0, 0.0, 0.0] => exact([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
        [-1.0, 0.0, 0.0] => exact([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
        [0.0, 1.0, 0.0] => exact([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
        [0.0, -1.0, 0.0] => exact([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
        _ => {
            // x: the coordinate axis least aligned with `a`, made orthogonal to it.
            let ab = [a.x.abs(), a.y.abs(), a.z.abs()];
            let k = (0..3).min_by(|&i, &j| ab[i].total_cmp(&ab[j])).unwrap();
            let mut e = [0.0; 3];
            e[k] = 1.0;
            let x = V3::from_array(e) - a.scale(a.to_array()[k]);
            let x = x.scale(1.0 / x.dot(x).sqrt());
            let y = a.cross(x);
            M3::from_rows(x, y, a).transpose()
        }
    }
}

fn m3(a: &[[f64; 3]; 3]) -> M3<f64> {
    M3::from_rows(V3::from_array(a[0]), V3::from_array(a[1]), V3::from_array(a[2]))
}

impl Model {
    /// Build the model from joints in tree order (see [`JointSpec`]) and gravity (3,)
    /// in the base frame. Checks the tree order, finiteness, orthonormal rotations,
    /// unit axes (to 1e-9, then normalised), non-negative masses and symmetric
    /// inertia tensors.
    pub fn new(joints: &[JointSpec], gravity: [f64; 3]) -> Result<Model, ModelError> {
        let err = |joint: Option<usize>, message: String| Err(ModelError { joint, message });
        if !gravity.iter().all(|g| g.is_finite()) {
            return err(None, format!("gravity {gravity:?} is not finite"));
        }
        let mut links = vec![LinkFrame { body: None, rotation: M3::identity(), translation: V3::zero() }];
        let mut m = Model {
            nv: 0,
            nq: 0,
            idx_q: vec![],
            motion: vec![],
            head_frame: vec![],
            multi: vec![],
            parent: vec![],
            kind: vec![],
            xtree: vec![],
            inertia: vec![],
            gravity: V3::from_array(gravity),
            a0: Motion::new(V3::zero(), -V3::from_array(gravity)),
            links: vec![],
            joint_body: vec![],
            welded_potential: 0.0,
            base_inertia: RigidInertia::zero(),
            joint_dynamics: vec![],
            has_joint_dynamics: false,
        };
        for (k, j) in joints.iter().enumerate() {
            let numbers = j.rotation.iter().flatten().chain(&j.translation).chain(&j.axis);
            let numbers = numbers.chain(std::iter::once(&j.mass)).chain(&j.com).chain(j.inertia.iter().flatten());
            if !numbers.clone().all(|x| x.is_finite()) {
                return err(Some(k), "a number is NaN or infinite".into());
            }
            if let Some(p) = j.parent {
                if p >= k {
                    return err(Some(k), format!("parent joint {p} does not come before it (tree order)"));
                }
            }
            let rot = m3(&j.rotation);
            let rtr = rot.transpose().mul_m(&rot);
            let ortho_err = (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| (rtr.at(a, b) - if a == b { 1.0 } else { 0.0 }).abs())
                .fold(0.0, f64::max);
            let det = rot.rows[0].dot(rot.rows[1].cross(rot.rows[2]));
            if ortho_err > TOL || det < 0.0 {
                return err(Some(k), "rotation is not a proper orthonormal matrix".into());
            }
            if j.mass < 0.0 {
                return err(Some(k), format!("negative mass {}", j.mass));
            }
            let ic = m3(&j.inertia);
            if (0..3).any(|a| (0..3).any(|b| (ic.at(a, b) - ic.at(b, a)).abs() > TOL * (1.0 + ic.at(a, b).abs()))) {
                return err(Some(k), "inertia tensor is not symmetric".into());
            }

            // The placement frame in the frame of the body carrying the parent link.
            let parent_link = links[j.parent.map_or(0, |p| p + 1)];
            let r_place = parent_link.rotation.mul_m(&rot);
            let p_place = parent_link.translation + parent_link.rotation.mul_v(V3::from_array(j.translation));

            let link = match j.jtype {
                JointType::Fixed => {
                    m.joint_body.push(None);
                    LinkFrame { body: parent_link.body, rotation: r_place, translation: p_place }
                }
                JointType::Revolute | JointType::Prismatic => {
                    let axis = V3::from_array(j.axis);
                    let norm = axis.dot(axis).sqrt();
                    if (norm - 1.0).abs() > TOL {
                        return err(Some(k), format!("axis {:?} is not a unit vector", j.axis));
                    }
                    let ra = frame_with_z(axis.scale(1.0 / norm));
                    let b = m.nv;
                    m.nv += 1;
                    m.parent.push(parent_link.body);
                    m.kind.push(if j.jtype == JointType::Revolute {
                        JointKind::RevoluteZ
                    } else {
                        JointKind::PrismaticZ
                    });
                    m.xtree.push(Xform::from_pose(&r_place.mul_m(&ra), p_place));
                    m.inertia.push(RigidInertia::zero());
                    m.joint_body.push(Some(b));
                    m.idx_q.push(m.nq);
                    m.nq += 1;
                    m.motion.push(BodyMotion::Axis);
                    m.head_frame.push(M3::identity());
                    // child link frame = body frame * Ra^T (Rot(axis, q) = Ra Rz(q) Ra^T)
                    LinkFrame { body: Some(b), rotation: ra.transpose(), translation: V3::zero() }
                }
                JointType::Spherical | JointType::Planar | JointType::Free => {
                    let kind = j.jtype.multi().expect("a joint of several coordinates");
                    m.joint_body.push(Some(m.nv));
                    m.multi.push(MultiJoint { kind, body: m.nv, idx_q: m.nq });
                    let mut previous: Option<M3<f64>> = None;
                    for &(part, axis) in kind.parts() {
                        let ra = frame_with_z(V3::from_array(axis));
                        let b = m.nv;
                        m.nv += 1;
                        m.kind.push(part);
                        m.inertia.push(RigidInertia::zero());
                        m.idx_q.push(m.nq);
                        match previous {
                            None => {
                                m.parent.push(parent_link.body);
                                m.motion.push(BodyMotion::Head(kind));
                                m.head_frame.push(ra.transpose());
                                m.xtree.push(Xform::from_pose(&r_place, p_place));
                            }
                            Some(ra_before) => {
                                m.parent.push(Some(b - 1));
                                m.motion.push(BodyMotion::Tail);
                                m.head_frame.push(M3::identity());
                                m.xtree.push(Xform::from_pose(&ra_before.transpose().mul_m(&ra), V3::zero()));
                            }
                        }
                        previous = Some(ra);
                    }
                    m.nq += kind.nq();
                    let ra_last = previous.expect("a joint has parts");
                    LinkFrame { body: Some(m.nv - 1), rotation: ra_last.transpose(), translation: V3::zero() }
                }
            };
            links.push(link);

            // The child link's inertia, moved into its body's frame (parallel axis in
            // spatial form, RBDA eq. 2.63). Links welded to the base only add a constant
            // potential energy.
            let i_link = RigidInertia::from_mass_com(j.mass, V3::from_array(j.com), Sym3::from_m3(&ic));
            let link_x_body = Xform::from_pose(&link.rotation, link.translation);
            let i_body = i_link.tr_transform(&link_x_body);
            match link.body {
                Some(b) => m.inertia[b] += i_body,
                None => {
                    m.welded_potential -= m.gravity.dot(i_body.h);
                    m.base_inertia += i_body;
                }
            }
        }
        m.links = links;
        m.joint_dynamics = vec![JointDynamics::default(); m.nv];
        Ok(m)
    }

    /// Set body `body`'s joint friction, rotor inertia and offset. Every value must be
    /// finite; armature, viscous and Coulomb coefficients must not be negative.
    pub fn set_joint_dynamics(&mut self, body: usize, jd: JointDynamics) -> Result<(), ModelError> {
        let err = |message: String| Err(ModelError { joint: None, message: format!("body {body}: {message}") });
        if body >= self.nv {
            return err(format!("no such body (the model has {})", self.nv));
        }
        let values =
            [("armature", jd.armature), ("viscous", jd.viscous), ("coulomb", jd.coulomb), ("offset", jd.offset)];
        for (name, x) in values {
            if !x.is_finite() {
                return err(format!("{name} {x} is not finite"));
            }
            if name != "offset" && x < 0.0 {
                return err(format!("{name} {x} is negative"));
            }
        }
        self.joint_dynamics[body] = jd;
        self.has_joint_dynamics = self.joint_dynamics.iter().any(|d| !d.is_zero());
        Ok(())
    }

    /// Count a point of mass `mass` at `com` (base frame) fixed to the base, e.g. the
    /// base link itself, in the potential energy (a constant; no other effect).
    pub fn add_base_mass(&mut self, mass: f64, com: [f64; 3]) {
        self.welded_potential -= mass * self.gravity.dot(V3::from_array(com));
    }

    /// Add the base link's own inertia (mass, centre of mass and inertia tensor about it,
    /// base frame) to [`Model::base_inertia`]; it also counts in the potential energy,
    /// as [`Model::add_base_mass`]. Refuses a negative mass, a non-finite number or a
    /// tensor that is not symmetric.
    pub fn add_base_inertia(&mut self, mass: f64, com: [f64; 3], inertia: [[f64; 3]; 3]) -> Result<(), ModelError> {
        let err = |message: &str| Err(ModelError { joint: None, message: format!("base link: {message}") });
        if !(mass.is_finite() && com.iter().chain(inertia.iter().flatten()).all(|x| x.is_finite())) {
            return err("a number is NaN or infinite");
        }
        if mass < 0.0 {
            return err("negative mass");
        }
        let ic = m3(&inertia);
        if (0..3).any(|a| (0..3).any(|b| (ic.at(a, b) - ic.at(b, a)).abs() > TOL * (1.0 + ic.at(a, b).abs()))) {
            return err("inertia tensor is not symmetric");
        }
        self.base_inertia += RigidInertia::from_mass_com(mass, V3::from_array(com), Sym3::from_m3(&ic));
        self.add_base_mass(mass, com);
        Ok(())
    }

    /// `^i X_lambda(i)` at configuration `q` (nq,): what every algorithm's first loop
    /// computes (RBDA Table 5.1 `jcalc`), for 1-dof bodies and joint parts alike.
    #[inline(always)]
    pub fn xup<T: Real>(&self, i: usize, q: &[T]) -> Xform<T> {
        match self.motion[i] {
            BodyMotion::Axis => self.kind[i].xup(&self.xtree[i], q[self.idx_q[i]]),
            BodyMotion::Head(kind) => kind.head_xup(&self.xtree[i], &self.head_frame[i], &q[self.idx_q[i]..]),
            BodyMotion::Tail => Xform::splat(&self.xtree[i]),
        }
    }

    /// The velocity body i's velocity product is taken with (`joint_multi.rs`):
    /// `xup v_lambda` (the parent's velocity in body i's frame) for a 1-dof body or a
    /// head, `xup vjp_lambda` for a tail, where `vjp` holds this value for every body.
    /// For a 1-dof body `v_i x S_i qd_i` is the same with either velocity, bit for bit
    /// (`S_i qd_i` only changes the component the cross product with `S_i` drops).
    #[inline(always)]
    pub fn joint_parent_velocity<T: Real>(
        &self,
        i: usize,
        xup: &Xform<T>,
        vp: Motion<T>,
        vjp: &[Motion<T>],
    ) -> Motion<T> {
        match (self.motion[i], self.parent[i]) {
            (BodyMotion::Tail, Some(p)) => xup.apply_motion(&vjp[p]),
            _ => vp,
        }
    }

    /// The body carrying the child of body `i`'s joint: `i` for a 1-dof joint, the last
    /// part of a joint of several coordinates (whose axes all turn with that child).
    pub fn joint_child_body(&self, i: usize) -> usize {
        let mut b = i;
        while b + 1 < self.nv && self.motion[b + 1] == BodyMotion::Tail {
            b += 1;
        }
        if self.motion[i] == BodyMotion::Axis {
            i
        } else {
            b
        }
    }

    /// Whether a joint has several coordinates (nq != nv, joint parts in the tree).
    pub fn has_multi(&self) -> bool {
        !self.multi.is_empty()
    }

    /// Number of link frames (base included): joints + 1.
    pub fn nlinks(&self) -> usize {
        self.links.len()
    }

    /// Whether body `a` is `b` or one of its ancestors.
    pub fn supports(&self, a: usize, b: usize) -> bool {
        let mut j = Some(b);
        while let Some(k) = j {
            if k == a {
                return true;
            }
            if k < a {
                return false;
            }
            j = self.parent[k];
        }
        false
    }
}

//! Kinematics and energies in the world frame, for a floating base (Pinocchio's
//! free-flyer arrays, laid out as `algo::floating` says) or a fixed one (the world frame
//! is then the base frame, the base pose the identity).
//!
//! Every function takes the whole `q` (and `v`): `(7 + nv,)` (`(6 + nv,)`) when
//! `floating`, `(nv,)` otherwise.

use crate::algo::floating::{base_motion, quaternion_rotation, NQ_BASE, NV_BASE};
use crate::algo::kinematics::{link_pose, update_x0, update_xup};
use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;
use crate::spatial::{Motion, Xform, M3, V3};

/// The base's pose in the world frame: `r` its axes (columns) and `p` its origin, in
/// world coordinates; the identity for a fixed base.
#[derive(Clone, Copy, Debug)]
pub struct BasePose {
    pub r: M3<f64>,
    pub p: V3<f64>,
}

impl BasePose {
    /// `^B X_0`: world coordinates to base coordinates.
    pub fn xform(&self) -> Xform<f64> {
        Xform::from_pose(&self.r, self.p)
    }
}

/// The number of base coordinates in `q` and in `v`: `(7, 6)` or `(0, 0)`.
pub fn base_widths(floating: bool) -> (usize, usize) {
    if floating {
        (NQ_BASE, NV_BASE)
    } else {
        (0, 0)
    }
}

/// The base pose and the joint coordinates of the whole configuration `q`.
pub fn split_configuration<'a>(model: &Model, q: &'a [f64], floating: bool) -> (BasePose, &'a [f64]) {
    let (nqb, _) = base_widths(floating);
    assert_eq!(q.len(), model.nq + nqb, "q length");
    let pose = if floating {
        BasePose { r: quaternion_rotation(q[3], q[4], q[5], q[6]), p: V3::new(q[0], q[1], q[2]) }
    } else {
        BasePose { r: M3::identity(), p: V3::zero() }
    };
    (pose, &q[nqb..])
}

/// The base's spatial velocity (base frame, `[w; v]`) and the joint rates of the whole
/// velocity `v` (zero base velocity for a fixed base).
pub fn split_velocity<'a>(model: &Model, v: &'a [f64], floating: bool) -> (Motion<f64>, &'a [f64]) {
    let (_, nvb) = base_widths(floating);
    assert_eq!(v.len(), model.nv + nvb, "v length");
    let vb = if floating { base_motion(&v[..NV_BASE]) } else { Motion::zero() };
    (vb, &v[nvb..])
}

/// Pose `(R, p)` of link `link` in the world frame, with `data.x0` up to date.
fn world_link_pose(model: &Model, data: &Data<f64>, base: &BasePose, link: usize) -> (M3<f64>, V3<f64>) {
    let (r, p) = link_pose(model, data, link);
    (base.r.mul_m(&r), base.p + base.r.mul_v(p))
}

/// Homogeneous poses of all link frames in the world frame: `(nlinks, 4, 4)` row-major,
/// links in description order (base first), `[R p; 0 0 0 1]`. For a floating base each
/// is the base pose composed with the link's pose in the base frame.
pub fn forward_kinematics_world(model: &Model, data: &mut Data<f64>, q: &[f64], floating: bool, out: &mut [f64]) {
    assert_eq!(out.len(), model.nlinks() * 16, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    for (k, o) in out.chunks_exact_mut(16).enumerate() {
        let (r, p) = world_link_pose(model, data, &base, k);
        for i in 0..3 {
            o[4 * i..4 * i + 3].copy_from_slice(&r.rows[i].to_array());
            o[4 * i + 3] = p.to_array()[i];
        }
        o[12..16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
    }
}

/// The Jacobian `(6, nv)` (row-major, `nv` the velocity's length: `6 + model.nv` for a
/// floating base) of link `link`'s frame with `[v; w] = J v`: `v` the velocity of its
/// origin `p`, `w` its angular velocity, both in world axes (Pinocchio's
/// LOCAL_WORLD_ALIGNED; [`crate::algo::jacobian`] for a fixed base).
///
/// The base's linear columns are its axes `R_B e_k` (its velocity is in the base frame),
/// its angular ones `[z x (p - p_B); z]` with `z = R_B e_k`; a supporting revolute joint's
/// `[z x (p - o); z]`, a prismatic one's `[z; 0]` (`z`, `o`: its axis and origin); the
/// rest 0.
pub fn jacobian_world(model: &Model, data: &mut Data<f64>, q: &[f64], floating: bool, link: usize, out: &mut [f64]) {
    let (_, nvb) = base_widths(floating);
    let nv = model.nv + nvb;
    assert!(out.len() == 6 * nv && link < model.nlinks(), "argument size");
    let (base, qj) = split_configuration(model, q, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    out.fill(0.0);
    let (_, p) = world_link_pose(model, data, &base, link);
    let mut put = |col: usize, v: V3<f64>, w: V3<f64>| {
        for (k, x) in v.to_array().into_iter().chain(w.to_array()).enumerate() {
            out[k * nv + col] = x;
        }
    };
    if floating {
        for k in 0..3 {
            let z = base.r.col(k);
            put(k, z, V3::zero());
            put(3 + k, z.cross(p - base.p), z);
        }
    }
    let mut body = model.links[link].body;
    while let Some(j) = body {
        let (r0j, o0j) = data.x0[j].to_pose();
        let z = base.r.mul_v(r0j.col(2));
        let o = base.p + base.r.mul_v(o0j);
        match model.kind[j] {
            JointKind::RevoluteZ => put(nvb + j, z.cross(p - o), z),
            JointKind::PrismaticZ => put(nvb + j, z, V3::zero()),
        }
        body = model.parent[j];
    }
}

/// Kinetic energy `T = 1/2 v_B . (I_B v_B) + 1/2 sum_i v_i . (I_i v_i)` (plus the rotors'
/// `1/2 Ia qd^2`), body velocities from the base's by the forward pass of RBDA Table 5.1:
/// independent of the CRBA, so `T = 1/2 v^T M v` is a check. The base term only when
/// `floating` (a fixed base does not move).
pub fn kinetic_energy_world(model: &Model, data: &mut Data<f64>, q: &[f64], v: &[f64], floating: bool) -> f64 {
    let (_, qj) = split_configuration(model, q, floating);
    let (vb, vj) = split_velocity(model, v, floating);
    update_xup(model, data, qj);
    // (zero for a fixed base: `vb` is then zero)
    let mut t = vb.dot(&model.base_inertia.mul_motion(&vb));
    for i in 0..model.nv {
        let parent = model.parent[i].map_or(vb, |p| data.v[p]);
        let vi = data.xup[i].apply_motion(&parent) + model.kind[i].s_times(vj[i]);
        data.v[i] = vi;
        t += vi.dot(&model.inertia[i].mul_motion(&vi)) + model.joint_dynamics[i].armature * vj[i] * vj[i];
    }
    0.5 * t
}

/// Mass and first moment `(m, m c)` of the bodies that move (the base's inertia too when
/// `floating`), base frame, from `data.x0`.
pub(crate) fn mass_and_moment(model: &Model, data: &Data<f64>, floating: bool) -> (f64, V3<f64>) {
    let (mut m, mut h) = if floating { (model.base_inertia.m, model.base_inertia.h) } else { (0.0, V3::zero()) };
    for i in 0..model.nv {
        let (r0i, p0i) = data.x0[i].to_pose();
        let inertia = &model.inertia[i];
        m += inertia.m;
        h += p0i.scale(inertia.m) + r0i.mul_v(inertia.h);
    }
    (m, h)
}

/// Potential energy of a floating robot, `V = -g . sum_i m_i c_i` over every body, the
/// base's included (`c_i` in the world frame, `g` the model's gravity in the world frame),
/// as Pinocchio's `computePotentialEnergy`. `q`: (7 + nv,).
pub fn potential_energy_floating(model: &Model, data: &mut Data<f64>, q: &[f64]) -> f64 {
    let (base, qj) = split_configuration(model, q, true);
    update_xup(model, data, qj);
    update_x0(model, data);
    let (m, h) = mass_and_moment(model, data, true);
    -model.gravity.dot(base.p.scale(m) + base.r.mul_v(h))
}

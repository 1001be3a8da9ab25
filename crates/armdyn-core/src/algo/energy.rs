//! Kinetic and potential energy.

use crate::algo::kinematics::{update_x0, update_xup};
use crate::data::Data;
use crate::model::Model;

/// `T = 1/2 sum_i v_i . (I_i v_i)` with body velocities `v_i` from the forward pass of
/// RBDA Table 5.1 (independent of the CRBA's `M`, so `T = 1/2 qd^T M qd` is a check).
/// `q`, `qd`: (nv,).
pub fn kinetic_energy(model: &Model, data: &mut Data<f64>, q: &[f64], qd: &[f64]) -> f64 {
    assert!(q.len() == model.nq && qd.len() == model.nv, "state length");
    update_xup(model, data, q);
    let mut t = 0.0;
    for i in 0..model.nv {
        let vj = model.kind[i].s_times(qd[i]);
        let v = match model.parent[i] {
            Some(p) => data.xup[i].apply_motion(&data.v[p]) + vj,
            None => vj,
        };
        data.v[i] = v;
        t += v.dot(&model.inertia[i].mul_motion(&v));
        // the rotor spinning at qd_i (reflected through its gear): Ia qd_i^2
        t += model.joint_dynamics[i].armature * qd[i] * qd[i];
    }
    0.5 * t
}

/// `V = -sum_i m_i g . p_ci` over all links but the base: zero when every centre of
/// mass is at the base origin. `p_ci` is body i's centre of mass in the base frame
/// (`m p_c = m p_0i + R_0i h_i`); links welded to the base (and the base link, see
/// `Model::add_base_mass`) add a constant.
/// `q`: (nv,).
pub fn potential_energy(model: &Model, data: &mut Data<f64>, q: &[f64]) -> f64 {
    assert!(q.len() == model.nq, "state length");
    update_xup(model, data, q);
    update_x0(model, data);
    let mut v = model.welded_potential;
    for i in 0..model.nv {
        let (r0i, p0i) = data.x0[i].to_pose();
        let inertia = &model.inertia[i];
        let mp = p0i.scale(inertia.m) + r0i.mul_v(inertia.h);
        v -= model.gravity.dot(mp);
    }
    v
}

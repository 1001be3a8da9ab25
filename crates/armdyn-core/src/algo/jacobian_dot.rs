//! The time derivative of a link's geometric Jacobian (`jacobian.rs`), for
//! operational-space control: `xdd = J qdd + Jdot qd`.

use crate::algo::kinematics::{link_pose, update_x0, update_xup};
use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;
use crate::spatial::V3;

/// `dJ/dt` (6, nv), row-major in `out`, of `J` = [`crate::algo::jacobian`] of link
/// `link` (rows `[v; w]`, base-frame axes, the link origin's velocity; Pinocchio's
/// LOCAL_WORLD_ALIGNED). `q`, `qd`: (nv,).
///
/// Differentiating the column of a supporting joint j (axis `z_j` through `o_j`, body
/// j's angular velocity `w_j`, so `zdot_j = w_j x z_j`; `p` the link origin):
/// revolute `[zdot_j x (p - o_j) + z_j x (pdot - odot_j); zdot_j]`, prismatic
/// `[zdot_j; 0]`. Velocities come from the forward pass in base coordinates
/// (`v_i = v_lambda + J_i qd_i`); a point `x` on body i moves at `v_i.v + v_i.w x x`.
pub fn jacobian_dot(model: &Model, data: &mut Data<f64>, q: &[f64], qd: &[f64], link: usize, out: &mut [f64]) {
    let n = model.nv;
    assert!(q.len() == model.nq && qd.len() == n && out.len() == 6 * n && link < model.nlinks(), "argument size");
    update_xup(model, data, q);
    update_x0(model, data);
    // base-frame body velocities, in data.v
    for i in 0..n {
        let s = data.x0[i].inv_apply_motion(&model.kind[i].s());
        let vp = model.parent[i].map(|p| data.v[p]).unwrap_or(crate::spatial::Motion::zero());
        data.v[i] = vp + s.scale(qd[i]);
    }
    out.fill(0.0);
    let (_, p) = link_pose(model, data, link);
    let mut body = model.links[link].body;
    let pdot = match body {
        Some(b) => data.v[b].v + data.v[b].w.cross(p),
        None => V3::zero(),
    };
    while let Some(j) = body {
        let (r0j, o) = data.x0[j].to_pose();
        let z = r0j.col(2);
        // the axis turns, and the point o moves, with the body carrying the joint's child
        // (j itself for a 1-dof joint; the last part of a joint of several coordinates)
        let vj = data.v[model.joint_child_body(j)];
        let zdot = vj.w.cross(z);
        let (top, bottom) = match model.kind[j] {
            JointKind::RevoluteZ => {
                let odot = vj.v + vj.w.cross(o);
                (zdot.cross(p - o) + z.cross(pdot - odot), zdot)
            }
            JointKind::PrismaticZ => (zdot, V3::zero()),
        };
        let (top, bottom) = (top.to_array(), bottom.to_array());
        for r in 0..3 {
            out[r * n + j] = top[r];
            out[(r + 3) * n + j] = bottom[r];
        }
        body = model.parent[j];
    }
}

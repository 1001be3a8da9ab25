//! The geometric Jacobian of a link frame's origin.

use crate::algo::kinematics::{link_pose, update_x0, update_xup};
use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;

/// `J(q)` (6, nv), row-major in `out`, such that `[v; w] = J qd` with `v` the velocity
/// of link `link`'s origin and `w` its angular velocity, both in base-frame axes
/// (rows `[v_x v_y v_z w_x w_y w_z]`: Spong's `[J_v; J_w]`, Pinocchio's
/// LOCAL_WORLD_ALIGNED). `link`: description order, 0 = base (J = 0).
///
/// Column of a supporting joint j with base-frame axis `z_j` through the point `o_j`:
/// revolute `[z_j x (p - o_j); z_j]`, prismatic `[z_j; 0]`; other columns are 0.
pub fn jacobian(model: &Model, data: &mut Data<f64>, q: &[f64], link: usize, out: &mut [f64]) {
    let n = model.nv;
    assert!(q.len() == model.nq && out.len() == 6 * n && link < model.nlinks(), "argument size");
    update_xup(model, data, q);
    update_x0(model, data);
    out.fill(0.0);
    let (_, p) = link_pose(model, data, link);
    let mut body = model.links[link].body;
    while let Some(j) = body {
        let (r0j, o) = data.x0[j].to_pose();
        let z = r0j.col(2);
        let (v, w) = match model.kind[j] {
            JointKind::RevoluteZ => (z.cross(p - o).to_array(), z.to_array()),
            JointKind::PrismaticZ => (z.to_array(), [0.0; 3]),
        };
        for r in 0..3 {
            out[r * n + j] = v[r];
            out[(r + 3) * n + j] = w[r];
        }
        body = model.parent[j];
    }
}

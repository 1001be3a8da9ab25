//! Forward kinematics: joint transforms `xup`, body poses, link poses.

use crate::data::Data;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{M3, V3};

/// `data.xup[i] = X_J(q_i) X_T(i)` for every body (RBDA Table 5.1, first loop).
#[inline(always)]
pub fn update_xup<T: Real>(model: &Model, data: &mut Data<T>, q: &[T]) {
    for i in 0..model.nv {
        data.xup[i] = model.xup(i, q);
    }
}

/// `data.x0[i] = ^i X_0 = xup[i] x0[lambda(i)]`, from `data.xup`.
#[inline(always)]
pub fn update_x0<T: Real>(model: &Model, data: &mut Data<T>) {
    for i in 0..model.nv {
        data.x0[i] = match model.parent[i] {
            Some(p) => data.xup[i].compose(&data.x0[p]),
            None => data.xup[i],
        };
    }
}

/// Pose `(R_0L, p_0L)` of link `link` (description order, 0 = base) in the base frame,
/// from `data.x0`.
pub fn link_pose(model: &Model, data: &Data<f64>, link: usize) -> (M3<f64>, V3<f64>) {
    let lf = &model.links[link];
    match lf.body {
        None => (lf.rotation, lf.translation),
        Some(b) => {
            let (r0b, p0b) = data.x0[b].to_pose();
            (r0b.mul_m(&lf.rotation), p0b + r0b.mul_v(lf.translation))
        }
    }
}

/// Homogeneous poses of all link frames in the base frame.
///
/// `q`: (nv,). `out`: (nlinks, 4, 4) row-major, link order of the description (base
/// first, then each joint's child), `[R p; 0 0 0 1]` with `R` the link's axes in base
/// coordinates and `p` its origin.
pub fn forward_kinematics(model: &Model, data: &mut Data<f64>, q: &[f64], out: &mut [f64]) {
    assert_eq!(q.len(), model.nq, "q length");
    assert_eq!(out.len(), model.nlinks() * 16, "output length");
    update_xup(model, data, q);
    update_x0(model, data);
    for (k, o) in out.chunks_exact_mut(16).enumerate() {
        let (r, p) = link_pose(model, data, k);
        for i in 0..3 {
            let row = r.rows[i].to_array();
            o[4 * i..4 * i + 3].copy_from_slice(&row);
            o[4 * i + 3] = p.to_array()[i];
        }
        o[12..16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
    }
}

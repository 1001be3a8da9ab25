//! Centre of mass and centroidal momentum (Orin and Goswami's centroidal momentum
//! matrix; Pinocchio's `centerOfMass`, `jacobianCenterOfMass`, `computeCentroidalMap`,
//! `computeCentroidalMomentum`, `computeCentroidalMomentumTimeVariation`, and the time
//! derivative of the matrix), for a floating base or a fixed one (`floating`; arrays as in
//! `algo::floating_kinematics`).
//!
//! The mass is that of the bodies that move: every movable body, and the base (with the
//! links welded to it, [`Model::base_inertia`]) when it floats. A fixed base and the links
//! welded to it are left out, as Pinocchio leaves out its universe body.
//!
//! The centroidal momentum `h_G = [p; k_G]` is the robot's linear momentum `p = m c'`
//! and its angular momentum about the centre of mass `c`, both in world axes: from the
//! spatial momentum `[n_B; f_B]` about the base origin in base axes, `p = R_B f_B` and
//! `k_G = R_B (n_B - c_B x f_B)` ([`to_centroidal`]). Outputs are ordered linear first,
//! as Pinocchio's.

use crate::algo::floating::base_motion;
use crate::algo::floating_kinematics::{base_widths, mass_and_moment, split_configuration, split_velocity, BasePose};
use crate::algo::kinematics::{update_x0, update_xup};
use crate::algo::rnea::rnea_tree;
use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;
use crate::spatial::{Force, Motion, RigidInertia, V3};

/// The centre of mass `c` in the world frame into `out` (3,) (NaN without mass); returns
/// the mass.
pub fn center_of_mass(model: &Model, data: &mut Data<f64>, q: &[f64], floating: bool, out: &mut [f64]) -> f64 {
    assert_eq!(out.len(), 3, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    let (m, h) = mass_and_moment(model, data, floating);
    out.copy_from_slice(&(base.p + base.r.mul_v(h.scale(1.0 / m))).to_array());
    m
}

/// The unit velocity of the base's coordinate k (`[v; w]` order) as a motion `[w; v]`.
fn base_axis(k: usize) -> Motion<f64> {
    let mut unit = [0.0; 6];
    unit[k] = 1.0;
    base_motion(&unit)
}

/// Write the spatial momentum (or its rate) `f` (base frame, about the base origin) as
/// `[p; k_G]` in world axes, `k_G` about the centre of mass `c_B = h / m` (base frame).
fn to_centroidal(base: &BasePose, m: f64, h: V3<f64>, f: &Force<f64>, out: &mut [f64]) {
    let c = h.scale(1.0 / m);
    out[..3].copy_from_slice(&base.r.mul_v(f.f).to_array());
    out[3..6].copy_from_slice(&base.r.mul_v(f.n - c.cross(f.f)).to_array());
}

/// The composite inertia `I^c_i` of each body's subtree (body frame) in `data.ic`, and
/// that of the whole robot (base frame, the base's own inertia when `floating`).
/// `data.xup` must be up to date.
fn composite_inertias(model: &Model, data: &mut Data<f64>, floating: bool) -> RigidInertia<f64> {
    for i in 0..model.nv {
        data.ic[i] = model.inertia[i];
    }
    let mut total = if floating { model.base_inertia } else { RigidInertia::zero() };
    for i in (0..model.nv).rev() {
        let ic = data.ic[i].tr_transform(&data.xup[i]);
        match model.parent[i] {
            Some(p) => data.ic[p] += ic,
            None => total += ic,
        }
    }
    total
}

/// The centroidal momentum matrix `A_G` (6, nv) (row-major, `nv` the velocity's length)
/// with `h_G = A_G v`, and the mass. Column of joint i: the momentum of its subtree
/// moving at a unit rate, `^B X_i^* I^c_i S_i` (RBDA's CRBA composite inertias) moved to
/// the centre of mass; of the base's coordinate k: the whole robot's composite inertia
/// times the unit base velocity.
pub fn centroidal_map(model: &Model, data: &mut Data<f64>, q: &[f64], floating: bool, out: &mut [f64]) -> f64 {
    let (_, nvb) = base_widths(floating);
    let nv = model.nv + nvb;
    assert_eq!(out.len(), 6 * nv, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    let total = composite_inertias(model, data, floating);
    let mut col = [0.0; 6];
    let mut put = |k: usize, f: &Force<f64>| {
        to_centroidal(&base, total.m, total.h, f, &mut col);
        for (r, x) in col.iter().enumerate() {
            out[r * nv + k] = *x;
        }
    };
    if floating {
        for k in 0..6 {
            put(k, &total.mul_motion(&base_axis(k)));
        }
    }
    for i in 0..model.nv {
        let f = data.x0[i].tr_apply_force(&model.kind[i].rigid_inertia_s(&data.ic[i]));
        put(nvb + i, &f);
    }
    total.m
}

/// The Jacobian of the centre of mass `J_c` (3, nv) (row-major) with `c' = J_c v`, world
/// axes, and the mass. Column of joint i (axis `z_i`, origin `o_i`): `z_i x (c_i - o_i)`
/// for a revolute joint, `z_i` for a prismatic one, times `m_i / m` (`m_i`, `c_i`: the mass
/// and centre of mass of its subtree); of the base: its axes `R_B e_k` (linear), and
/// `R_B e_k x (c - p_B)` (angular). Only the subtrees' masses and first moments are summed
/// (`data.ic[i].m`, `.h`, body frame; `.ibar` is left unset).
pub fn com_jacobian(model: &Model, data: &mut Data<f64>, q: &[f64], floating: bool, out: &mut [f64]) -> f64 {
    let (_, nvb) = base_widths(floating);
    let nv = model.nv + nvb;
    assert_eq!(out.len(), 3 * nv, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    for i in 0..model.nv {
        data.ic[i].m = model.inertia[i].m;
        data.ic[i].h = model.inertia[i].h;
    }
    let (mut m, mut h) = if floating { (model.base_inertia.m, model.base_inertia.h) } else { (0.0, V3::zero()) };
    for i in (0..model.nv).rev() {
        // the subtree's first moment about the parent's origin, parent axes
        let (mi, x) = (data.ic[i].m, &data.xup[i]);
        let hp = x.e.tr_mul_v(data.ic[i].h) + x.r.scale(mi);
        match model.parent[i] {
            Some(p) => {
                data.ic[p].m += mi;
                data.ic[p].h += hp;
            }
            None => {
                m += mi;
                h += hp;
            }
        }
    }
    let inv = 1.0 / m;
    let mut put = |k: usize, c: V3<f64>| {
        for (r, x) in base.r.mul_v(c.scale(inv)).to_array().into_iter().enumerate() {
            out[r * nv + k] = x;
        }
    };
    if floating {
        for k in 0..3 {
            let mut unit = [0.0; 3];
            unit[k] = 1.0;
            let e = V3::from_array(unit);
            put(k, e.scale(m));
            put(3 + k, e.cross(h));
        }
    }
    for i in 0..model.nv {
        let ic = &data.ic[i];
        // I^c S's force part in body axes: e_z x h, or m e_z
        let f = match model.kind[i] {
            JointKind::RevoluteZ => V3::new(-ic.h.y, ic.h.x, 0.0),
            JointKind::PrismaticZ => V3::new(0.0, 0.0, ic.m),
        };
        put(nvb + i, data.x0[i].e.tr_mul_v(f));
    }
    m
}

/// The centroidal momentum `h_G = A_G v` (6,) by one forward pass: the momenta `I_i v_i`
/// of the bodies (and the base's) summed in the base frame. Returns the mass.
pub fn centroidal_momentum(
    model: &Model,
    data: &mut Data<f64>,
    q: &[f64],
    v: &[f64],
    floating: bool,
    out: &mut [f64],
) -> f64 {
    assert_eq!(out.len(), 6, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    let (vb, vj) = split_velocity(model, v, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    let mut momentum = model.base_inertia.mul_motion(&vb); // zero for a fixed base (vb = 0)
    for i in 0..model.nv {
        let parent = model.parent[i].map_or(vb, |p| data.v[p]);
        let vi = data.xup[i].apply_motion(&parent) + model.kind[i].s_times(vj[i]);
        data.v[i] = vi;
        momentum += data.x0[i].tr_apply_force(&model.inertia[i].mul_motion(&vi));
    }
    let (m, h) = mass_and_moment(model, data, floating);
    to_centroidal(&base, m, h, &momentum, out);
    m
}

/// The rate of change of the centroidal momentum `dh_G/dt = A_G a + A_G' v` (6,), for the
/// acceleration `a` (same layout as `v`; `a = 0` gives `A_G' v`): the net forces
/// `I_i a_i + v_i x* I_i v_i` of the bodies (and the base's), by the RNEA without
/// gravity, summed in the base frame, moved to the centre of mass as the momentum is
/// (the term `c' x p` vanishes: `p = m c'`). Returns the mass.
#[allow(clippy::too_many_arguments)]
pub fn centroidal_momentum_rate(
    model: &Model,
    data: &mut Data<f64>,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    floating: bool,
    out: &mut [f64],
) -> f64 {
    assert_eq!(out.len(), 6, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    let (vb, vj) = split_velocity(model, v, floating);
    let (ab, aj) = split_velocity(model, a, floating);
    let mut torques = std::mem::take(&mut data.u);
    let on_base = rnea_tree(model, data, qj, vj, aj, &mut torques, Some((vb, ab)));
    data.u = torques;
    let ib = &model.base_inertia;
    // the base's own net force (zero for a fixed base: vb = ab = 0)
    let rate = on_base + ib.mul_motion(&ab) + vb.cross_force(&ib.mul_motion(&vb));
    update_x0(model, data);
    let (m, h) = mass_and_moment(model, data, floating);
    to_centroidal(&base, m, h, &rate, out);
    m
}

/// Column `k` of a (6, nv) row-major matrix as a force `[n; f]` (rows `[f; n]`).
fn column(out: &[f64], nv: usize, k: usize) -> Force<f64> {
    let at = |r: usize| out[r * nv + k];
    Force::new(V3::new(at(3), at(4), at(5)), V3::new(at(0), at(1), at(2)))
}

/// Write the force `[n; f]` as column `k` (rows `[f; n]`) of a (6, nv) row-major matrix.
fn put_column(out: &mut [f64], nv: usize, k: usize, f: &Force<f64>) {
    for (r, x) in f.f.to_array().into_iter().chain(f.n.to_array()).enumerate() {
        out[r * nv + k] = x;
    }
}

/// The time derivative of the centroidal momentum matrix, `A_G'(q, v)` (6, nv) (row-major),
/// with `A_G' v` the velocity term of [`centroidal_momentum_rate`]. Returns the mass.
/// (Pinocchio's `computeCentroidalMapTimeVariation` moves the moments to a centre of mass
/// standing still: its `dAg` adds `c' x` the linear rows to the angular ones.)
///
/// In the world frame about its origin the column of coordinate j is `I^c_j S_j` (world
/// inertias and motion subspaces, [`centroidal_map`]), whose rate is
/// `sum_{i in subtree(j)} (v_i x* I_i S_j - I_i (v_i x S_j)) + I^c_j (v_j x S_j)` (each
/// body's inertia turns with it: `I_i' = v_i x* I_i - I_i v_i x`; `S_j' = v_j x S_j`, with
/// `v_j` the velocity of the body that carries joint j's child, the last part of a joint
/// of several coordinates), the base a body whose subtree is the robot with six axes
/// `^0 X_B e_k`; moving the moment to the centre of mass `c` (`n_G = n - c x f`) adds
/// `-c' x f - c x f'`.
pub fn centroidal_map_rate(
    model: &Model,
    data: &mut Data<f64>,
    q: &[f64],
    v: &[f64],
    floating: bool,
    out: &mut [f64],
) -> f64 {
    let (_, nvb) = base_widths(floating);
    let nv = model.nv + nvb;
    assert_eq!(out.len(), 6 * nv, "output length");
    let (base, qj) = split_configuration(model, q, floating);
    let (vb, vj) = split_velocity(model, v, floating);
    update_xup(model, data, qj);
    update_x0(model, data);
    // world quantities about the world origin: data.x0 = ^i X_0, data.c = S_i, data.v = v_i,
    // data.ic = I_i; the momentum summed on the way
    let xb = base.xform();
    let vb0 = xb.inv_apply_motion(&vb);
    let ib0 = if floating { model.base_inertia.tr_transform(&xb) } else { RigidInertia::zero() };
    let mut momentum = ib0.mul_motion(&vb0);
    for i in 0..model.nv {
        data.x0[i] = data.x0[i].compose(&xb);
        data.c[i] = data.x0[i].inv_apply_motion(&model.kind[i].s_times(1.0));
        let parent = model.parent[i].map_or(vb0, |p| data.v[p]);
        data.v[i] = parent + data.c[i].scale(vj[i]);
        data.ic[i] = model.inertia[i].tr_transform(&data.x0[i]);
        momentum += data.ic[i].mul_motion(&data.v[i]);
    }
    let base_axes: [Motion<f64>; 6] = std::array::from_fn(|k| xb.inv_apply_motion(&base_axis(k)));
    // sum over the bodies i of the turning of I_i, on each column j at or above i
    let turning = |i: &RigidInertia<f64>, vi: &Motion<f64>, s: &Motion<f64>| {
        vi.cross_force(&i.mul_motion(s)) - i.mul_motion(&vi.cross_motion(s))
    };
    out.fill(0.0);
    for i in 0..model.nv {
        let (inertia, vi) = (data.ic[i], data.v[i]);
        let mut j = Some(i);
        while let Some(b) = j {
            let sum = column(out, nv, nvb + b) + turning(&inertia, &vi, &data.c[b]);
            put_column(out, nv, nvb + b, &sum);
            j = model.parent[b];
        }
        if floating {
            for (k, s) in base_axes.iter().enumerate() {
                let sum = column(out, nv, k) + turning(&inertia, &vi, s);
                put_column(out, nv, k, &sum);
            }
        }
    }
    // composite inertias (world), and each column's own term and shift
    let mut total = ib0;
    for i in (0..model.nv).rev() {
        let ic = data.ic[i];
        match model.parent[i] {
            Some(p) => data.ic[p] += ic,
            None => total += ic,
        }
    }
    let c = total.h.scale(1.0 / total.m);
    let cdot = momentum.f.scale(1.0 / total.m);
    let finish = |out: &mut [f64], k: usize, ic: &RigidInertia<f64>, vj: &Motion<f64>, s: &Motion<f64>| {
        let a = ic.mul_motion(s);
        let da = column(out, nv, k) + ic.mul_motion(&vj.cross_motion(s));
        let n = da.n - cdot.cross(a.f) - c.cross(da.f);
        put_column(out, nv, k, &Force::new(n, da.f));
    };
    if floating {
        for (k, s) in base_axes.iter().enumerate() {
            // the base body's own turning, then the whole robot's composite
            let sum = column(out, nv, k) + turning(&ib0, &vb0, s);
            put_column(out, nv, k, &sum);
            finish(out, k, &total, &vb0, s);
        }
    }
    for i in 0..model.nv {
        let (ic, vi, s) = (data.ic[i], data.v[model.joint_child_body(i)], data.c[i]);
        finish(out, nvb + i, &ic, &vi, &s);
    }
    total.m
}

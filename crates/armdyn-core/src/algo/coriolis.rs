//! The Coriolis matrix `C(q, qd)` consistent with the Christoffel symbols, so that
//! `C qd = h - g` and `Mdot - 2C` is skew-symmetric.
//!
//! S. Echeandia and P. M. Wensing, "Numerical Methods to Compute the Coriolis Matrix
//! and Christoffel Symbols for Rigid-Body Systems", J. Comput. Nonlinear Dyn. 16(9), 2021:
//! with every quantity in the base frame,
//!
//! ```text
//! C = sum_k J_k^T (I_k Jdot_k + B_k J_k),
//! B_k = 1/2 [ (v_k x*) I_k - I_k (v_k x) + (I_k v_k) xbar ],   (f xbar) v := v x* f
//! ```
//!
//! where `J_k` maps `qd` to body k's spatial velocity `v_k`. Column j of `J_k` is the
//! joint axis `S_j` (base frame) when j supports k, with derivative `Sdot_j = v_j x S_j`.
//! Summing over the subtree gives composite `I^c_i`, `B^c_i`, and for `a` an ancestor of
//! `d` (or `a = d`):
//! `C_da = Sdot_a^T I^c_d S_d + S_a^T B^c_d^T S_d`, `C_ad = S_a^T (I^c_d Sdot_d + B^c_d S_d)`.

use crate::algo::kinematics::{update_x0, update_xup};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::{Motion, RigidInertia, M3};

type Mat6 = [[f64; 6]; 6];
type Vec6 = [f64; 6];

fn blocks(tl: M3<f64>, tr: M3<f64>, bl: M3<f64>, br: M3<f64>) -> Mat6 {
    let mut m = [[0.0; 6]; 6];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = tl.at(i, j);
            m[i][j + 3] = tr.at(i, j);
            m[i + 3][j] = bl.at(i, j);
            m[i + 3][j + 3] = br.at(i, j);
        }
    }
    m
}

/// `I` as 6x6: `[ibar h^x; -h^x m1]`.
fn rigid6(i: &RigidInertia<f64>) -> Mat6 {
    let hx = M3::skew(i.h);
    blocks(i.ibar.to_m3(), hx, hx.scale(-1.0), M3::identity().scale(i.m))
}

/// `crm(v) = [w^x 0; v^x w^x]` (RBDA eq. 2.31).
fn crm(v: &Motion<f64>) -> Mat6 {
    let (wx, vx) = (M3::skew(v.w), M3::skew(v.v));
    blocks(wx, M3::zero(), vx, wx)
}

/// `crf(v) = -crm(v)^T = [w^x v^x; 0 w^x]`.
fn crf(v: &Motion<f64>) -> Mat6 {
    let (wx, vx) = (M3::skew(v.w), M3::skew(v.v));
    blocks(wx, vx, M3::zero(), wx)
}

/// `f xbar`, the matrix with `(f xbar) v = v x* f`: `[-n^x -f^x; -f^x 0]` (skew).
fn crf_bar(f: &Vec6) -> Mat6 {
    let nx = M3::skew(crate::spatial::V3::new(f[0], f[1], f[2])).scale(-1.0);
    let fx = M3::skew(crate::spatial::V3::new(f[3], f[4], f[5])).scale(-1.0);
    blocks(nx, fx, fx, M3::zero())
}

fn mul(a: &Mat6, b: &Mat6) -> Mat6 {
    let mut c = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            c[i][j] = (0..6).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn mul_v(a: &Mat6, x: &Vec6) -> Vec6 {
    let mut y = [0.0; 6];
    for i in 0..6 {
        y[i] = (0..6).map(|k| a[i][k] * x[k]).sum();
    }
    y
}

fn tr_mul_v(a: &Mat6, x: &Vec6) -> Vec6 {
    let mut y = [0.0; 6];
    for i in 0..6 {
        y[i] = (0..6).map(|k| a[k][i] * x[k]).sum();
    }
    y
}

fn dot(a: &Vec6, b: &Vec6) -> f64 {
    (0..6).map(|k| a[k] * b[k]).sum()
}

/// Scratch for [`coriolis_matrix`], per body (base frame).
#[derive(Clone, Debug, Default)]
pub struct CoriolisWork {
    s: Vec<Vec6>,
    sdot: Vec<Vec6>,
    ic: Vec<RigidInertia<f64>>,
    bc: Vec<Mat6>,
}

impl CoriolisWork {
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        CoriolisWork {
            s: vec![[0.0; 6]; n],
            sdot: vec![[0.0; 6]; n],
            ic: vec![RigidInertia::zero(); n],
            bc: vec![[[0.0; 6]; 6]; n],
        }
    }
}

/// `C(q, qd)` (nv, nv), row-major in `c`. `q`, `qd`: (nv,).
pub fn coriolis_matrix(
    model: &Model,
    data: &mut Data<f64>,
    work: &mut CoriolisWork,
    q: &[f64],
    qd: &[f64],
    c: &mut [f64],
) {
    let n = model.nv;
    assert!(q.len() == model.nq && qd.len() == n && c.len() == n * n, "state length");
    update_xup(model, data, q);
    update_x0(model, data);
    for i in 0..n {
        let vj = model.kind[i].s_times(qd[i]);
        data.v[i] = match model.parent[i] {
            Some(p) => data.xup[i].apply_motion(&data.v[p]) + vj,
            None => vj,
        };
    }
    for i in 0..n {
        // base-frame axis, velocity, axis derivative, inertia. The axis turns with the
        // body carrying its joint's child (itself for a 1-dof joint, where v_i x S_i =
        // v_lambda x S_i; the last part for a joint of several coordinates, whose axes are
        // constant in the child frame: Pinocchio's dJ = v_child x J).
        let x0 = &data.x0[i];
        let s0 = x0.inv_apply_motion(&model.kind[i].s());
        let v0 = x0.inv_apply_motion(&data.v[i]);
        let child = model.joint_child_body(i);
        let v_child = if child == i { v0 } else { data.x0[child].inv_apply_motion(&data.v[child]) };
        work.s[i] = s0.to_array();
        work.sdot[i] = v_child.cross_motion(&s0).to_array();
        let i0 = model.inertia[i].tr_transform(x0);
        let i6 = rigid6(&i0);
        let iv = i0.mul_motion(&v0).to_array();
        let (a, b, cb) = (mul(&crf(&v0), &i6), mul(&i6, &crm(&v0)), crf_bar(&iv));
        work.ic[i] = i0;
        for r in 0..6 {
            for k in 0..6 {
                work.bc[i][r][k] = 0.5 * (a[r][k] - b[r][k] + cb[r][k]);
            }
        }
    }
    for i in (0..n).rev() {
        if let Some(p) = model.parent[i] {
            let (ici, bci) = (work.ic[i], work.bc[i]);
            work.ic[p] += ici;
            for r in 0..6 {
                for k in 0..6 {
                    work.bc[p][r][k] += bci[r][k];
                }
            }
        }
    }
    c.fill(0.0);
    for d in 0..n {
        let (s, sdot) = (&work.s[d], &work.sdot[d]);
        let ic6 = rigid6(&work.ic[d]);
        let bc = &work.bc[d];
        let fa = mul_v(&ic6, s);
        let fb = tr_mul_v(bc, s);
        let isd = mul_v(&ic6, sdot);
        let bs = mul_v(bc, s);
        let fc: Vec6 = std::array::from_fn(|k| isd[k] + bs[k]);
        c[d * n + d] = dot(s, &fc);
        let mut a = model.parent[d];
        while let Some(j) = a {
            c[d * n + j] = dot(&work.sdot[j], &fa) + dot(&work.s[j], &fb);
            c[j * n + d] = dot(&work.s[j], &fc);
            a = model.parent[j];
        }
    }
}

//! A floating base: the tree's base is a free rigid body (Pinocchio's free-flyer root
//! joint), for the RNEA, the CRBA and the ABA (RBDA ch. 9: the floating-base RNEA,
//! the CRBA with its 6x6 base block, the floating-base ABA). The movable joints are the
//! model's 1-dof joints, run by the fixed-base code with the base's motion given to
//! the root bodies.
//!
//! The arrays are laid out as Pinocchio's, so that they pass unchanged between the two:
//!
//! * `q` (7 + nv): the base frame's origin in the world frame (3), its orientation as
//!   a unit quaternion `x, y, z, w` (4; base axes in world coordinates), then the joints;
//! * `v`, `a` (6 + nv): the base's spatial velocity (acceleration) in the base frame,
//!   linear part first (`v`: velocity of the base-fixed point at the base origin, base
//!   axes; `w`: angular velocity, base axes), then the joint rates; `a` is the time
//!   derivative of `v` (the spatial acceleration in the base frame);
//! * `tau` (6 + nv): the wrench on the base, base frame, force then moment about the
//!   base origin, then the joint torques;
//! * `M` ((6 + nv)^2, row-major): in the order of `v`.
//!
//! The base's inertia is [`Model::base_inertia`]; gravity is the model's vector, in the
//! world frame. Inside, spatial vectors keep the core's `[angular; linear]` order.

use crate::algo::aba::{articulated_inertias, handed_to_parent, joint_accelerations, velocities_and_bias, BodyFrames};
use crate::algo::crba::crba_tree;
use crate::algo::rnea::rnea_tree;
use crate::data::Data;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Force, Motion, RigidInertia, M3, V3};

/// Configuration coordinates of the base: position (3) and quaternion (4).
pub const NQ_BASE: usize = 7;
/// Velocity coordinates of the base: linear (3) and angular (3).
pub const NV_BASE: usize = 6;

/// The rotation of the quaternion `x, y, z, w` (base axes as columns, world
/// coordinates), scaled by `2 / |q|^2` so that it is a rotation for any nonzero `q`.
/// The callers refuse quaternions far from unit length before they get here.
#[inline(always)]
pub fn quaternion_rotation<T: Real>(x: T, y: T, z: T, w: T) -> M3<T> {
    let s = T::splat(2.0) / (x * x + y * y + z * z + w * w);
    let (xs, ys, zs) = (x * s, y * s, z * s);
    let (wx, wy, wz) = (w * xs, w * ys, w * zs);
    let (xx, xy, xz) = (x * xs, x * ys, x * zs);
    let (yy, yz, zz) = (y * ys, y * zs, z * zs);
    let one = T::splat(1.0);
    M3::from_rows(
        V3::new(one - (yy + zz), xy - wz, xz + wy),
        V3::new(xy + wz, one - (xx + zz), yz - wx),
        V3::new(xz - wy, yz + wx, one - (xx + yy)),
    )
}

/// A base velocity or acceleration `[linear (3); angular (3)]` as a motion `[w; v]`.
#[inline(always)]
pub(crate) fn base_motion<T: Real>(x: &[T]) -> Motion<T> {
    Motion::new(V3::new(x[3], x[4], x[5]), V3::new(x[0], x[1], x[2]))
}

/// Write a force `[n; f]` as the base's `[f (3); n (3)]`.
#[inline(always)]
fn put_wrench<T: Real>(f: &Force<T>, out: &mut [T]) {
    out[..3].copy_from_slice(&f.f.to_array());
    out[3..6].copy_from_slice(&f.n.to_array());
}

/// `[0; -R^T g]`: gravity as a fictitious acceleration of the base, base frame
/// (RBDA 5.3), for the base orientation `q[3..7]`.
#[inline(always)]
pub(crate) fn gravity_acceleration<T: Real>(model: &Model, q: &[T]) -> Motion<T> {
    let r = quaternion_rotation(q[3], q[4], q[5], q[6]);
    Motion::new(V3::zero(), -r.tr_mul_v(V3::splat(model.gravity)))
}

fn check_lengths(model: &Model, q: usize, v: usize, w: usize, out: usize) {
    let n = model.nv;
    assert!(q == model.nq + NQ_BASE && v == n + NV_BASE && w == n + NV_BASE && out == n + NV_BASE, "state length");
}

/// Inverse dynamics of the floating-base tree: `tau = M(q) a + C(q, v) v + g(q)`, the
/// wrench the base needs (zero for a free-flying robot at the physical acceleration)
/// and the joint torques. `q` (7 + nv), `v`, `a`, `tau` (6 + nv), laid out as the module
/// says. The base's net force `f_B = I_B a_B + v_B x* I_B v_B` plus what the root bodies
/// exert on it (RBDA ch. 9, with the base acceleration given).
#[inline(always)]
pub fn rnea_floating<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], v: &[T], a: &[T], tau: &mut [T]) {
    check_lengths(model, q.len(), v.len(), a.len(), tau.len());
    let vb = base_motion(&v[..NV_BASE]);
    let ab = base_motion(&a[..NV_BASE]) + gravity_acceleration(model, q);
    let ib = RigidInertia::splat(&model.base_inertia);
    let (head, tail) = tau.split_at_mut(NV_BASE);
    let on_base = rnea_tree(model, data, &q[NQ_BASE..], &v[NV_BASE..], &a[NV_BASE..], tail, Some((vb, ab)));
    let fb = ib.mul_motion(&ab) + vb.cross_force(&ib.mul_motion(&vb)) + on_base;
    put_wrench(&fb, head);
}

/// The floating-base joint-space inertia matrix ((6 + nv)^2, row-major, in the order of
/// `v`): the CRBA (RBDA Table 6.2, ch. 9) with the base's 6x6 block, the composite
/// inertia of the whole robot in the base frame. Depends on the joints only (`q[7..]`),
/// not on the base's pose. `q`: (7 + nv).
#[inline(always)]
pub fn crba_floating<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], m: &mut [T]) {
    let n = model.nv;
    let s = n + NV_BASE;
    assert!(q.len() == model.nq + NQ_BASE && m.len() == s * s, "state length");
    let ic = RigidInertia::splat(&model.base_inertia) + crba_tree(model, data, &q[NQ_BASE..], m, NV_BASE);
    put_base_block(&ic, m, s);
}

/// M's base block (rows and columns 0..6 of `m`, `s` wide): the whole robot's composite
/// inertia `ic` (base frame) in the `[v; w]` order of the base's velocities.
#[inline(always)]
pub(crate) fn put_base_block<T: Real>(ic: &RigidInertia<T>, m: &mut [T], s: usize) {
    for k in 0..NV_BASE {
        // column k: the composite inertia times the unit base motion k ([v; w] order)
        let mut unit = [T::zero(); NV_BASE];
        unit[k] = T::splat(1.0);
        let col = ic.mul_motion(&base_motion(&unit));
        for (r, h) in col.f.to_array().into_iter().chain(col.n.to_array()).enumerate() {
            m[r * s + k] = h;
        }
    }
}

/// Forward dynamics of the floating-base tree: `a = M(q)^-1 (tau - C(q, v) v - g(q))`
/// by the floating-base ABA (RBDA ch. 9): pass 1 from the base's velocity, pass 2
/// as for a fixed base with the root bodies' articulated inertias and bias forces
/// gathered on the base, whose spatial acceleration (gravity's `-g` included) is then
/// `a_B = -(I^A_B)^-1 p^A_B` with `p^A_B = v_B x* I_B v_B - tau_B + ...`; pass 3 from `a_B`.
/// `q` (7 + nv), `v`, `tau`, `a` (6 + nv), laid out as the module says. A base of zero
/// articulated inertia (a massless robot) gives inf/NaN.
#[inline(always)]
pub fn aba_floating<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], v: &[T], tau: &[T], a: &mut [T]) {
    check_lengths(model, q.len(), v.len(), tau.len(), a.len());
    let vb = base_motion(&v[..NV_BASE]);
    let (qj, vj, tauj) = (&q[NQ_BASE..], &v[NV_BASE..], &tau[NV_BASE..]);
    velocities_and_bias(model, data, qj, vj, Some(&vb));
    let frames = BodyFrames(&model.kind);
    articulated_inertias(model, data, &frames, Some((vj, tauj)));
    let ib = RigidInertia::splat(&model.base_inertia);
    let mut ia_b = ArticulatedInertia::from_rigid(&ib);
    let tau_b = Force::new(V3::new(tau[3], tau[4], tau[5]), V3::new(tau[0], tau[1], tau[2]));
    let mut pa_b = vb.cross_force(&ib.mul_motion(&vb)) - tau_b;
    for i in 0..model.nv {
        if model.parent[i].is_none() {
            let (ia, pa) = handed_to_parent(data, i);
            ia_b += ia.tr_transform(&data.xup[i]);
            pa_b += data.xup[i].tr_apply_force(&pa);
        }
    }
    let a_b = solve_articulated(&ia_b, &(Force::zero() - pa_b));
    let (head, tail) = a.split_at_mut(NV_BASE);
    joint_accelerations(model, data, &frames, tail, &a_b);
    // the base's own coordinates: its acceleration less gravity's fictitious one
    let ag = gravity_acceleration(model, q);
    let abase = a_b - ag;
    head[..3].copy_from_slice(&abase.v.to_array());
    head[3..].copy_from_slice(&abase.w.to_array());
}

/// `x` with `I^A x = f`, for a symmetric positive definite articulated inertia `I^A`,
/// by the LDL^T factorisation of its 6x6 matrix (no square roots: lane types have none).
#[inline(always)]
pub(crate) fn solve_articulated<T: Real>(ia: &ArticulatedInertia<T>, f: &Force<T>) -> Motion<T> {
    let (a, c) = (ia.a.to_m3(), ia.c.to_m3());
    let mut k = [[T::zero(); 6]; 6];
    for r in 0..3 {
        for col in 0..3 {
            k[r][col] = a.at(r, col);
            k[r][col + 3] = ia.b.at(r, col);
            k[r + 3][col] = ia.b.at(col, r);
            k[r + 3][col + 3] = c.at(r, col);
        }
    }
    // L (unit lower triangle, below the diagonal of k) and D (d)
    let mut d = [T::zero(); 6];
    for j in 0..6 {
        let mut dj = k[j][j];
        for l in 0..j {
            dj -= k[j][l] * k[j][l] * d[l];
        }
        d[j] = dj;
        let inv = T::splat(1.0) / dj;
        for i in j + 1..6 {
            let mut x = k[i][j];
            for l in 0..j {
                x -= k[i][l] * k[j][l] * d[l];
            }
            k[i][j] = x * inv;
        }
    }
    let mut y = f.to_array();
    for i in 0..6 {
        for l in 0..i {
            let t = k[i][l] * y[l];
            y[i] -= t;
        }
    }
    for i in 0..6 {
        y[i] = y[i] / d[i];
    }
    for i in (0..6).rev() {
        for l in i + 1..6 {
            let t = k[l][i] * y[l];
            y[i] -= t;
        }
    }
    Motion::new(V3::new(y[0], y[1], y[2]), V3::new(y[3], y[4], y[5]))
}

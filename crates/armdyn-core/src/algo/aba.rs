//! Forward dynamics by the articulated-body algorithm (RBDA Table 7.1).
//!
//! Passes 2 and 3 are written once ([`articulated_inertias`], [`joint_accelerations`])
//! for any choice of coordinates ([`AbaFrames`]): `aba` works in each body's own frame,
//! as the book; `aba_derivatives` and `minverse` work in base coordinates for every body
//! (Carpentier's "world" ABA), where no transform is needed between bodies.

use crate::data::Data;
use crate::joint::JointKind;
use crate::model::Model;
use crate::real::Real;
use crate::spatial::{ArticulatedInertia, Force, Motion, RigidInertia, V3};

/// `qdd = M(q)^-1 (tau - C(q, qd) qd - g(q))`. `q`, `qd`, `tau`, `qdd`: (nv,).
///
/// Gravity enters as the base acceleration `a_0 = [0; -g]`. Bodies of zero
/// articulated inertia about their joint axis (`D_i = 0`) give inf/NaN, as M is then
/// singular. Leaves body-frame quantities in `data` (see [`articulated_inertias`]).
#[inline(always)]
pub fn aba<T: Real>(model: &Model, data: &mut Data<T>, q: &[T], qd: &[T], tau: &[T], qdd: &mut [T]) {
    let n = model.nv;
    assert!(q.len() == model.nq && qd.len() == n && tau.len() == n && qdd.len() == n, "state length");
    velocities_and_bias(model, data, q, qd, None);
    let frames = BodyFrames(&model.kind);
    articulated_inertias(model, data, &frames, Some((qd, tau)));
    let a0 = Motion::new(V3::splat(model.a0.w), V3::splat(model.a0.v));
    joint_accelerations(model, data, &frames, qdd, &a0);
}

/// Pass 1 of RBDA Table 7.1 (root to leaves), body frames: velocities `v_i`,
/// velocity-product accelerations `c_i`, `I^A_i = I_i` and `p^A_i = v_i x* I_i v_i`;
/// the root bodies' parent moves with `base_v` (base frame; None: at rest). Writes
/// `data.xup`, `data.v`, `data.c`, `data.ia`, `data.pa`. `q`, `qd`: (nv,).
#[inline(always)]
pub(crate) fn velocities_and_bias<T: Real>(
    model: &Model,
    data: &mut Data<T>,
    q: &[T],
    qd: &[T],
    base_v: Option<&Motion<T>>,
) {
    for i in 0..model.nv {
        let kind = model.kind[i];
        let xup = model.xup(i, q);
        let vp = match (model.parent[i], base_v) {
            (Some(p), _) => xup.apply_motion(&data.v[p]),
            (None, Some(vb)) => xup.apply_motion(vb),
            (None, None) => Motion::zero(),
        };
        let v = vp + kind.s_times(qd[i]);
        let inertia = RigidInertia::splat(&model.inertia[i]);
        // the velocity product with the joint's parent velocity (joint_multi.rs)
        let vjp = model.joint_parent_velocity(i, &xup, vp, &data.vjp);
        data.vjp[i] = vjp;
        data.c[i] = kind.v_cross_s(&vjp, qd[i]);
        data.ia[i] = ArticulatedInertia::from_rigid(&inertia);
        data.pa[i] = v.cross_force(&inertia.mul_motion(&v));
        data.xup[i] = xup;
        data.v[i] = v;
    }
}

/// What body i hands to its parent in pass 2, in body i's coordinates, after
/// [`articulated_inertias`] with a bias: `I^a_i = I^A_i - U_i U_i^T / D_i` and
/// `p^a_i = p^A_i + I^a_i c_i + U_i u_i / D_i`.
#[inline(always)]
pub(crate) fn handed_to_parent<T: Real>(data: &Data<T>, i: usize) -> (ArticulatedInertia<T>, Force<T>) {
    let ia = data.ia[i].sub_outer(&data.u_col[i], data.d_inv[i]);
    let pa = data.pa[i] + ia.mul_motion(&data.c[i]) + data.u_col[i].scale(data.u[i] * data.d_inv[i]);
    (ia, pa)
}

/// The coordinates the articulated-body passes express body i's quantities in: how
/// joint i's axis `S_i` acts there, and how a quantity crosses joint i between body i
/// and its parent `lambda(i)`. Forces and inertias are (6,) `[n; f]` and 6x6 in those
/// coordinates; the transforms read `data` (`data.xup` for body frames).
pub(crate) trait AbaFrames<T: Real> {
    /// `U = I^A S_i` (6,).
    fn inertia_s(&self, i: usize, ia: &ArticulatedInertia<T>) -> Force<T>;
    /// `S_i^T f`.
    fn s_dot(&self, i: usize, f: &Force<T>) -> T;
    /// `S_i x` (6,).
    fn s_times(&self, i: usize, x: T) -> Motion<T>;
    /// `^lambda X_i^* I^a ^i X_lambda`: body i's articulated inertia in its parent's coordinates.
    fn inertia_to_parent(&self, data: &Data<T>, i: usize, ia: &ArticulatedInertia<T>) -> ArticulatedInertia<T>;
    /// `^lambda X_i^* f`: a force on body i in its parent's coordinates.
    fn force_to_parent(&self, data: &Data<T>, i: usize, f: &Force<T>) -> Force<T>;
    /// `^i X_lambda m`: a motion of the parent in body i's coordinates.
    fn motion_from_parent(&self, data: &Data<T>, i: usize, m: &Motion<T>) -> Motion<T>;
}

/// Each body in its own frame (RBDA as written): `S_i` is joint i's constant axis there
/// (its [`JointKind`], one per body), and quantities cross joints by `data.xup`.
pub(crate) struct BodyFrames<'a>(pub &'a [JointKind]);

impl<T: Real> AbaFrames<T> for BodyFrames<'_> {
    #[inline(always)]
    fn inertia_s(&self, i: usize, ia: &ArticulatedInertia<T>) -> Force<T> {
        self.0[i].articulated_inertia_s(ia)
    }
    #[inline(always)]
    fn s_dot(&self, i: usize, f: &Force<T>) -> T {
        self.0[i].s_dot(f)
    }
    #[inline(always)]
    fn s_times(&self, i: usize, x: T) -> Motion<T> {
        self.0[i].s_times(x)
    }
    #[inline(always)]
    fn inertia_to_parent(&self, data: &Data<T>, i: usize, ia: &ArticulatedInertia<T>) -> ArticulatedInertia<T> {
        ia.tr_transform(&data.xup[i])
    }
    #[inline(always)]
    fn force_to_parent(&self, data: &Data<T>, i: usize, f: &Force<T>) -> Force<T> {
        data.xup[i].tr_apply_force(f)
    }
    #[inline(always)]
    fn motion_from_parent(&self, data: &Data<T>, i: usize, m: &Motion<T>) -> Motion<T> {
        data.xup[i].apply_motion(m)
    }
}

/// Every body in base coordinates: `S_i` is `J_i = ^0X_i S_i` (nv,) (`DerivData::s`), and
/// nothing changes crossing a joint.
pub(crate) struct BaseFrame<'a, T>(pub &'a [Motion<T>]);

impl<T: Real> AbaFrames<T> for BaseFrame<'_, T> {
    #[inline(always)]
    fn inertia_s(&self, i: usize, ia: &ArticulatedInertia<T>) -> Force<T> {
        ia.mul_motion(&self.0[i])
    }
    #[inline(always)]
    fn s_dot(&self, i: usize, f: &Force<T>) -> T {
        self.0[i].dot(f)
    }
    #[inline(always)]
    fn s_times(&self, i: usize, x: T) -> Motion<T> {
        self.0[i].scale(x)
    }
    #[inline(always)]
    fn inertia_to_parent(&self, _: &Data<T>, _: usize, ia: &ArticulatedInertia<T>) -> ArticulatedInertia<T> {
        *ia
    }
    #[inline(always)]
    fn force_to_parent(&self, _: &Data<T>, _: usize, f: &Force<T>) -> Force<T> {
        *f
    }
    #[inline(always)]
    fn motion_from_parent(&self, _: &Data<T>, _: usize, m: &Motion<T>) -> Motion<T> {
        *m
    }
}

/// Pass 2 of RBDA Table 7.1 (leaves to root) in the coordinates of `frames`, given
/// `data.ia[i]` = body i's rigid inertia `I_i` and, with `bias = Some((qd, tau))` (each
/// (nv,)), `data.pa[i]` = its bias force `p_i` (`v_i x* I_i v_i`, less any external
/// force) and `data.c[i]` = `c_i`. Per body
///
/// ```text
/// U_i = I^A_i S_i,   D_i = S_i^T U_i + Ia_i,   u_i = tau_i - Fv qd_i - Fc sign(qd_i) - offset_i - S_i^T p^A_i
/// I^A_lambda += X^* (I^A_i - U_i U_i^T / D_i) X,   p^A_lambda += X^* (p^A_i + I^a_i c_i + U_i u_i / D_i)
/// ```
///
/// (`X = ^i X_lambda`): the rotor inertia `Ia` adds to the joint's own inertia, and
/// friction and offset are torques the motor does not deliver to the link. Turns
/// `data.ia` (and `data.pa`) into the articulated inertias (bias forces); writes
/// `data.u_col` (`U_i`), `data.d_inv` (`1 / D_i`) and, with `bias`, `data.u` (`u_i`).
/// Without `bias` (M^-1 needs only the inertias) `data.pa`, `data.c`, `data.u` are not read
/// nor written.
#[inline(always)]
pub(crate) fn articulated_inertias<T: Real, F: AbaFrames<T>>(
    model: &Model,
    data: &mut Data<T>,
    frames: &F,
    bias: Option<(&[T], &[T])>,
) {
    // `bias` is a constant at each (inlined) call site, so its tests fold away; plain
    // matches, as closures here were left out of line.
    for i in (0..model.nv).rev() {
        let u_col = frames.inertia_s(i, &data.ia[i]);
        let jd = &model.joint_dynamics[i];
        let d_inv = T::splat(1.0) / (frames.s_dot(i, &u_col) + T::splat(jd.armature));
        let u = match bias {
            Some((qd, tau)) => {
                let mut u = tau[i] - frames.s_dot(i, &data.pa[i]);
                if model.has_joint_dynamics {
                    u -= jd.passive_torque(qd[i]);
                }
                Some(u)
            }
            None => None,
        };
        data.u_col[i] = u_col;
        data.d_inv[i] = d_inv;
        if let Some(u) = u {
            data.u[i] = u;
        }
        if let Some(p) = model.parent[i] {
            match u {
                Some(_) => {
                    let (ia, pa) = handed_to_parent(data, i);
                    let ia_p = frames.inertia_to_parent(data, i, &ia);
                    let pa_p = frames.force_to_parent(data, i, &pa);
                    data.ia[p] += ia_p;
                    data.pa[p] += pa_p;
                }
                None => {
                    let ia = data.ia[i].sub_outer(&u_col, d_inv);
                    let ia_p = frames.inertia_to_parent(data, i, &ia);
                    data.ia[p] += ia_p;
                }
            }
        }
    }
}

/// Pass 3 of RBDA Table 7.1 (root to leaves), after [`articulated_inertias`] with a bias,
/// in the same coordinates: `a'_i = X a_lambda + c_i` (`a_lambda = a_root` at a root),
/// `qdd_i = (u_i - U_i^T a'_i) / D_i`, `a_i = a'_i + S_i qdd_i`. Writes `qdd` (nv,)
/// and `data.a`. `a_root`: the acceleration of the root bodies' parent (the base), in
/// its coordinates, gravity's `-g` included (`[0; -g]` for a fixed base).
#[inline(always)]
pub(crate) fn joint_accelerations<T: Real, F: AbaFrames<T>>(
    model: &Model,
    data: &mut Data<T>,
    frames: &F,
    qdd: &mut [T],
    a_root: &Motion<T>,
) {
    for i in 0..model.nv {
        let ap = match model.parent[i] {
            Some(p) => frames.motion_from_parent(data, i, &data.a[p]),
            None => frames.motion_from_parent(data, i, a_root),
        };
        let a = ap + data.c[i];
        let qddi = (data.u[i] - a.dot(&data.u_col[i])) * data.d_inv[i];
        qdd[i] = qddi;
        data.a[i] = a + frames.s_times(i, qddi);
    }
}

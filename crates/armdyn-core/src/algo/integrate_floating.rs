//! Time integration of a model whose configuration is not flat, for many initial
//! states at once: an optional floating base (`algo::floating`, Pinocchio's layout: `q`
//! (7 + nq), `v` (6 + nv)) and joints of several coordinates anywhere in the tree
//! (`joint_multi.rs`). The fixed-base integrator's methods ([`crate::algo::integrate`])
//! with every block of `q` moved on its group ([`crate::algo::manifold`]): the base and
//! free joints on SE(3), spherical joints on SO(3), planar joints on SE(2), as
//! `armdyn.configuration.integrate` and Pinocchio's `integrate`; the 1-dof joints add.
//! Written `q (+) xi`:
//!
//! * [`Method::SemiImplicitEuler`]: `v' = v + h a(q, v)`, `q' = q (+) h v'`.
//! * [`Method::Rk4`]: Runge-Kutta-Munthe-Kaas (Hairer, Lubich, Wanner, *Geometric
//!   Numerical Integration*, IV.8.2) with the classical tableau: the stages live in the
//!   tangent space at the step's start, `q_i = q (+) theta_i`, and the local coordinate
//!   obeys `theta' = dexp^-1_{-theta}(v)`, on each block the Bernoulli series `v +
//!   [theta, v] / 2 + [theta, [theta, v]] / 12 + O(theta^4)` with the block's bracket
//!   (its `theta^3` term is zero, so the truncation keeps fourth order). Velocities are
//!   a vector space: plain RK4.
//!
//! Torques ([`Input`]): zero, constant, or a series, of width `v`'s (a floating base's
//! wrench in the base frame first, then the joints); or a controller evaluated at every
//! stage, its error on the tangent space, `e = q* (-) q = log(q^-1 q*)` (Pinocchio's
//! `difference(q, q*)`, in `q`'s frame: the velocity that moves `q` to `q*` in unit time;
//! [`Manifold::difference_lanes`]), gains and `qd*` per coordinate of `v`, `q*` of `q`'s
//! width:
//!
//! * PD: `tau = [g(q)] + Kp e + Kd (qd* - v)`; with a floating base its six rows are set to
//!   zero (the base is unactuated) and `g(q)` is the generalized gravity with the base not
//!   accelerating (`rnea_floating(q, 0, 0)`, its joint rows);
//! * computed torque: `tau = rnea(q, v, Kp e + Kd (qd* - v))`, so that `v' = Kp e + Kd
//!   (qd* - v)`: with `qd* = 0` and an error along one axis of a block (or a small one)
//!   `e'' + Kd e' + Kp e = 0`, since then `e' = -v`. With a floating base (unactuated) the
//!   joints get that acceleration and the base the one it then has
//!   ([`unactuated_base`]: collocated partial feedback linearization, Spong 1994).
//!
//! Outputs as [`crate::algo::integrate::Outputs`], `q` of width
//! `q`'s and `qd`, `qdd`, `tau` of width `v`'s; `limit_joint` and `nonfinite_joint`
//! index `v`'s coordinates (a floating base's six first); `lower`, `upper` are the
//! joints' (`model.nv`), checked on the 1-dof joints only. The work is of the whole
//! torque, `tau . v` (the base wrench's power included).
//!
//! States run in SIMD lanes (4 or 8 per group, as [`crate::algo::integrate`]; the
//! leftover rows one by one), groups spread over rayon threads. The dynamics run on the
//! lanes; the blocks' exponentials (square roots and sines, which the lane types do not
//! have) lane by lane in `f64`. Every lane performs exactly the operations of a single
//! state, so results do not depend on the kernels, threads or grouping.

use crate::algo::aba;
use crate::algo::floating::{aba_floating, crba_floating, rnea_floating, NQ_BASE, NV_BASE};
use crate::algo::integrate::{Input, Method, Outputs, Settings, STOP_POLL};
use crate::algo::manifold::Manifold;
use crate::algo::rnea::{gravity, rnea};
use crate::batch::{install, kernels, thread_count, Kernels};
use crate::data::Data;
use crate::model::Model;
use crate::real::{F64x4, F64x8, Real};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// `out = q (+) xi` for a floating base with 1-dof joints: the base pose (`q[..7]`)
/// times `exp(xi[..6])`, the joints plus `xi[6..]`.
pub fn integrate_configuration(q: &[f64], xi: &[f64], out: &mut [f64]) {
    crate::algo::manifold::se3_exp(q, xi, out);
    for (o, (x, dx)) in out[NQ_BASE..].iter_mut().zip(q[NQ_BASE..].iter().zip(&xi[NV_BASE..])) {
        *o = x + dx;
    }
}

/// One output row: what [`Outputs`] holds for one state.
struct Row<'a> {
    q: &'a mut [f64],
    work: &'a mut [f64],
    qd: &'a mut [f64],
    qdd: &'a mut [f64],
    tau: &'a mut [f64],
    q_final: &'a mut [f64],
    qd_final: &'a mut [f64],
    limit_step: &'a mut i64,
    limit_joint: &'a mut i64,
    nonfinite_step: &'a mut i64,
    nonfinite_joint: &'a mut i64,
}

/// [`simulate_manifold_until`] with a floating base: `q0` (N, 7 + nq), `v0` (N, 6 + nv).
#[allow(clippy::too_many_arguments)]
pub fn simulate_floating_until(
    model: &Model,
    q0: &[f64],
    v0: &[f64],
    input: Input,
    settings: Settings,
    lower: &[f64],
    upper: &[f64],
    out: Outputs,
    threads: Option<usize>,
    stop: &AtomicBool,
) -> bool {
    simulate_manifold_until(model, true, q0, v0, input, settings, lower, upper, out, threads, stop)
}

/// Integrate `N` states `q0` (N, nq), `v0` (N, nv) of `model` (`floating`: with a
/// floating base, widths 7 + `model.nq` and 6 + `model.nv`) as the module says, ending
/// early once `stop` is set (read every [`STOP_POLL`] steps). Returns false if it was
/// stopped. Controllers: `kp`, `kd` (nv), `target` (N, nq), `target_qd` (N, nv), the
/// manifold's widths (a floating base's included: its rows are not actuated). Panics on
/// mis-sized arrays.
#[allow(clippy::too_many_arguments)]
pub fn simulate_manifold_until(
    model: &Model,
    floating: bool,
    q0: &[f64],
    v0: &[f64],
    input: Input,
    settings: Settings,
    lower: &[f64],
    upper: &[f64],
    out: Outputs,
    threads: Option<usize>,
    stop: &AtomicBool,
) -> bool {
    let n = model.nv;
    let manifold = Manifold::new(model, floating);
    let (nq, nv) = (manifold.nq, manifold.nv);
    assert!(settings.stride >= 1 && settings.dt.is_finite(), "settings");
    assert!(lower.len() == n && upper.len() == n, "limits length");
    let rows = q0.len() / nq;
    let s = settings.samples();
    assert!(q0.len() == rows * nq && v0.len() == rows * nv, "initial state size");
    assert!(out.q.len() == rows * s * nq && out.q_final.len() == rows * nq, "output size");
    for o in [&out.qd, &out.qdd, &out.tau] {
        assert_eq!(o.len(), rows * s * nv, "output size");
    }
    assert!(out.work.len() == rows * s && out.qd_final.len() == rows * nv, "output size");
    assert!(out.limit_step.len() == rows && out.limit_joint.len() == rows && out.nonfinite_step.len() == rows);
    assert!(out.nonfinite_joint.len() == rows);
    match input {
        Input::Zero => {}
        Input::Constant(t) => assert_eq!(t.len(), rows * nv, "constant torque size"),
        Input::Series { tau, shared } => {
            assert!(settings.steps >= 1, "a torque series needs at least one step");
            assert_eq!(tau.len(), if shared { 1 } else { rows } * settings.steps * nv, "torque series size")
        }
        Input::Pd { kp, kd, target, target_qd, .. } | Input::ComputedTorque { kp, kd, target, target_qd } => {
            assert!(kp.len() == nv && kd.len() == nv, "gain size");
            assert!(target.len() == rows * nq && target_qd.len() == rows * nv, "target size");
        }
    }
    let Outputs { q, work, qd, qdd, tau, q_final, qd_final, limit_step, limit_joint, nonfinite_step, nonfinite_joint } =
        out;
    let mut all: Vec<Row> = Vec::with_capacity(rows);
    let mut ints =
        limit_step.iter_mut().zip(limit_joint.iter_mut()).zip(nonfinite_step.iter_mut().zip(nonfinite_joint));
    let mut q_rows = q.chunks_mut(s * nq).zip(q_final.chunks_mut(nq));
    let mut v_rows = qd.chunks_mut(s * nv).zip(qdd.chunks_mut(s * nv)).zip(tau.chunks_mut(s * nv));
    let mut w_rows = work.chunks_mut(s).zip(qd_final.chunks_mut(nv));
    for _ in 0..rows {
        let ((ls, lj), (ns, nj)) = ints.next().expect("rows");
        let (q, q_final) = q_rows.next().expect("rows");
        let ((qd, qdd), tau) = v_rows.next().expect("rows");
        let (work, qd_final) = w_rows.next().expect("rows");
        all.push(Row {
            q,
            work,
            qd,
            qdd,
            tau,
            q_final,
            qd_final,
            limit_step: ls,
            limit_joint: lj,
            nonfinite_step: ns,
            nonfinite_joint: nj,
        });
    }
    // groups of the widest kernel's lanes, then the leftover rows one by one
    let lanes = match kernels() {
        #[cfg(target_arch = "x86_64")]
        Kernels::Avx512 => 8,
        #[cfg(target_arch = "x86_64")]
        Kernels::Avx2 => 4,
        #[cfg(target_arch = "x86_64")]
        _ => 1,
        #[cfg(not(target_arch = "x86_64"))]
        _ => 4,
    };
    let mut groups: Vec<(usize, Vec<Row>)> = Vec::new();
    let mut rest = all.into_iter();
    let mut first = 0;
    while first < rows {
        let width = if rows - first >= lanes { lanes } else { 1 };
        groups.push((first, rest.by_ref().take(width).collect()));
        first += width;
    }
    let job = Job { model, manifold, floating, q0, v0, input, settings, lower, upper, stop };
    let mut groups = Some(groups);
    let mut run = || {
        let groups = groups.take().expect("runs once");
        if thread_count(threads) == 1 || groups.len() < 2 {
            groups.into_iter().for_each(|(first, mut rows)| job.dispatch(first, &mut rows));
        } else {
            groups.into_par_iter().for_each(|(first, mut rows)| job.dispatch(first, &mut rows));
        }
    };
    match threads {
        None => run(),
        Some(k) => install(k, &mut run),
    }
    !stop.load(Ordering::Relaxed)
}

/// The shared read-only inputs of one call.
struct Job<'a> {
    model: &'a Model,
    manifold: Manifold,
    floating: bool,
    q0: &'a [f64],
    v0: &'a [f64],
    input: Input<'a>,
    settings: Settings,
    lower: &'a [f64],
    upper: &'a [f64],
    stop: &'a AtomicBool,
}

/// Per-group workspace: lane vectors (q: nq, the others nv, the manifold's).
struct Work<T> {
    data: Data<T>,
    q: Vec<T>,
    v: Vec<T>,
    qs: Vec<T>,
    vs: Vec<T>,
    tau: Vec<T>,
    a: Vec<T>,
    /// A controller's target (nq), target velocity, error (nv), zeros (nv), and the mass
    /// matrix (nv^2, computed torque with a floating base).
    target: Vec<T>,
    target_v: Vec<T>,
    err: Vec<T>,
    zeros: Vec<T>,
    mass: Vec<T>,
    /// RK4: the stage's local coordinate, its rate, and the weighted sums.
    theta: Vec<T>,
    rate: Vec<T>,
    sum_rate: Vec<T>,
    sum_a: Vec<T>,
}

impl<T: Real> Work<T> {
    /// `floating_ct`: computed torque with a floating base (which needs the mass matrix).
    fn new(model: &Model, manifold: &Manifold, floating_ct: bool) -> Self {
        let z = |k: usize| vec![T::zero(); k];
        let (nq, nv) = (manifold.nq, manifold.nv);
        Work {
            data: Data::new(model),
            q: z(nq),
            v: z(nv),
            qs: z(nq),
            vs: z(nv),
            tau: z(nv),
            a: z(nv),
            target: z(nq),
            target_v: z(nv),
            err: z(nv),
            zeros: z(nv),
            mass: if floating_ct { z(nv * nv) } else { vec![] },
            theta: z(nv),
            rate: z(nv),
            sum_rate: z(nv),
            sum_a: z(nv),
        }
    }
}

/// Computed torque on a floating base (collocated partial feedback linearization): given
/// `tau = rnea(q, v, [0; a*])`, whose base rows `f_b = M_bj a* + h_b` are the wrench the
/// base would need to stay unaccelerated, let the base accelerate instead, `a_b = -M_bb^-1
/// f_b` (`M_bb` the whole robot's composite inertia, positive definite), and return the
/// joint torques that give the joints `a*` with it, `tau_j + M_jb a_b`; the base rows zero.
/// `mass`: M (nv^2, row-major).
#[inline(always)]
fn unactuated_base<T: Real>(mass: &[T], tau: &mut [T]) {
    let nv = tau.len();
    // Gaussian elimination on M_bb (symmetric positive definite: no pivoting needed)
    let mut m = [[T::zero(); NV_BASE]; NV_BASE];
    let mut b = [T::zero(); NV_BASE];
    for r in 0..NV_BASE {
        m[r].copy_from_slice(&mass[r * nv..r * nv + NV_BASE]);
        b[r] = -tau[r];
    }
    for k in 0..NV_BASE {
        for r in k + 1..NV_BASE {
            let f = m[r][k] / m[k][k];
            for c in k..NV_BASE {
                let x = m[k][c];
                m[r][c] -= f * x;
            }
            let x = b[k];
            b[r] -= f * x;
        }
    }
    for k in (0..NV_BASE).rev() {
        let mut x = b[k];
        for c in k + 1..NV_BASE {
            x -= m[k][c] * b[c];
        }
        b[k] = x / m[k][k];
    }
    for (j, t) in tau.iter_mut().enumerate().skip(NV_BASE) {
        for (k, ab) in b.iter().enumerate() {
            *t += mass[j * nv + k] * *ab;
        }
    }
    tau[..NV_BASE].fill(T::zero());
}

/// Lanes of `dst` from rows `first..first + LANES` of the (rows, width) array `src`.
#[inline(always)]
fn load<T: Real>(dst: &mut [T], src: &[f64], first: usize) {
    let width = dst.len();
    for (j, d) in dst.iter_mut().enumerate() {
        for l in 0..T::LANES {
            d.set_lane(l, src[(first + l) * width + j]);
        }
    }
}

/// Lane `l` of `src` into `dst`.
#[inline(always)]
fn put<T: Real>(dst: &mut [f64], src: &[T], l: usize) {
    for (d, x) in dst.iter_mut().zip(src) {
        *d = T::lane_of(x, l);
    }
}

impl Job<'_> {
    /// Computed torque with a floating base: the stages need the mass matrix.
    fn floating_ct(&self) -> bool {
        self.floating && matches!(self.input, Input::ComputedTorque { .. })
    }

    /// Integrate the rows of one group: in SIMD lanes if it is a whole group of the
    /// widest kernel's, else one by one.
    fn dispatch(&self, first: usize, rows: &mut [Row]) {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        unsafe fn avx512(job: &Job, first: usize, rows: &mut [Row]) {
            job.group(&mut Work::<F64x8>::new(job.model, &job.manifold, job.floating_ct()), first, rows)
        }
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn avx2(job: &Job, first: usize, rows: &mut [Row]) {
            job.group(&mut Work::<F64x4>::new(job.model, &job.manifold, job.floating_ct()), first, rows)
        }
        match (kernels(), rows.len()) {
            // SAFETY: the CPU supports the features (checked by `kernels`).
            #[cfg(target_arch = "x86_64")]
            (Kernels::Avx512, 8) => unsafe { avx512(self, first, rows) },
            #[cfg(target_arch = "x86_64")]
            (Kernels::Avx2, 4) => unsafe { avx2(self, first, rows) },
            #[cfg(not(target_arch = "x86_64"))]
            (_, 4) => self.group(&mut Work::<F64x4>::new(self.model, &self.manifold, self.floating_ct()), first, rows),
            _ => {
                let mut w = Work::<f64>::new(self.model, &self.manifold, self.floating_ct());
                for (k, row) in rows.iter_mut().enumerate() {
                    self.group(&mut w, first + k, std::slice::from_mut(row));
                }
            }
        }
    }

    /// The torque during step `k` of the lanes' rows `r..` at the stage state `w.qs`,
    /// `w.vs`, into `w.tau`.
    #[inline(always)]
    fn torque<T: Real>(&self, w: &mut Work<T>, r: usize, k: usize) {
        let nv = w.tau.len();
        let tau = &mut w.tau;
        match self.input {
            Input::Pd { kp, kd, gravity_compensation, .. } => {
                if !gravity_compensation {
                    tau.fill(T::zero());
                } else if self.floating {
                    rnea_floating(self.model, &mut w.data, &w.qs, &w.zeros, &w.zeros, tau);
                } else {
                    gravity(self.model, &mut w.data, &w.qs, tau);
                }
                self.manifold.difference_lanes(&w.qs, &w.target, &mut w.err);
                for j in 0..nv {
                    tau[j] += T::splat(kp[j]) * w.err[j] + T::splat(kd[j]) * (w.target_v[j] - w.vs[j]);
                }
                if self.floating {
                    tau[..NV_BASE].fill(T::zero());
                }
            }
            Input::ComputedTorque { kp, kd, .. } => {
                self.manifold.difference_lanes(&w.qs, &w.target, &mut w.err);
                for j in 0..nv {
                    w.err[j] = T::splat(kp[j]) * w.err[j] + T::splat(kd[j]) * (w.target_v[j] - w.vs[j]);
                }
                if self.floating {
                    w.err[..NV_BASE].fill(T::zero());
                    rnea_floating(self.model, &mut w.data, &w.qs, &w.vs, &w.err, tau);
                    crba_floating(self.model, &mut w.data, &w.qs, &mut w.mass);
                    unactuated_base(&w.mass, tau);
                } else {
                    rnea(self.model, &mut w.data, &w.qs, &w.vs, &w.err, tau);
                }
            }
            Input::Constant(t) => load(tau, t, r),
            Input::Series { tau: t, shared } => {
                let k = k.min(self.settings.steps - 1);
                for (j, x) in tau.iter_mut().enumerate() {
                    if shared {
                        *x = T::splat(t[k * nv + j]);
                    } else {
                        for l in 0..T::LANES {
                            x.set_lane(l, t[((r + l) * self.settings.steps + k) * nv + j]);
                        }
                    }
                }
            }
            _ => tau.fill(T::zero()),
        }
    }

    /// Record limit crossings and non-finite coordinates of the lanes' `(q, v)` at step
    /// `k`; true once every lane is not finite.
    #[inline(always)]
    fn check<T: Real>(&self, q: &[T], v: &[T], rows: &mut [Row], k: usize) -> bool {
        let mut diverged = 0;
        for (l, row) in rows.iter_mut().enumerate() {
            let x = |j: usize| T::lane_of(&q[j], l);
            if *row.limit_step < 0 {
                // the 1-dof joints' coordinates (the limits are the joints', v's less a base's)
                let base = if self.floating { NV_BASE } else { 0 };
                if let Some(&(_, iv)) = self.manifold.flat().iter().find(|&&(iq, iv)| {
                    let y = x(iq);
                    y < self.lower[iv - base] || y > self.upper[iv - base]
                }) {
                    *row.limit_step = k as i64;
                    *row.limit_joint = iv as i64;
                }
            }
            if *row.nonfinite_step < 0 {
                let q_finite = |j: usize| self.manifold.q_of_v(j).all(|i| x(i).is_finite());
                if let Some(j) = (0..v.len()).find(|&j| !(T::lane_of(&v[j], l).is_finite() && q_finite(j))) {
                    *row.nonfinite_step = k as i64;
                    *row.nonfinite_joint = j as i64;
                }
            }
            diverged += (*row.nonfinite_step >= 0) as usize;
        }
        diverged == T::LANES
    }

    /// Store sample `s` of the lanes: the state `w.q`, `w.v` with `w.a`, `w.tau`.
    #[inline(always)]
    fn store<T: Real>(&self, w: &Work<T>, work: T, rows: &mut [Row], s: usize) {
        let (nq, nv) = (w.q.len(), w.v.len());
        for (l, row) in rows.iter_mut().enumerate() {
            put(&mut row.q[s * nq..(s + 1) * nq], &w.q, l);
            put(&mut row.qd[s * nv..(s + 1) * nv], &w.v, l);
            put(&mut row.qdd[s * nv..(s + 1) * nv], &w.a, l);
            put(&mut row.tau[s * nv..(s + 1) * nv], &w.tau, l);
            row.work[s] = work.lane(l);
        }
    }

    /// Integrate the lanes of rows `r..r + LANES` into `rows`.
    #[inline(always)]
    fn group<T: Real>(&self, w: &mut Work<T>, r: usize, rows: &mut [Row]) {
        let nv = w.v.len();
        let Settings { method, dt, steps, stride } = self.settings;
        let (h, h2, h6, two) = (T::splat(dt), T::splat(0.5 * dt), T::splat(dt / 6.0), T::splat(2.0));
        load(&mut w.q, self.q0, r);
        load(&mut w.v, self.v0, r);
        if let Input::Pd { target, target_qd, .. } | Input::ComputedTorque { target, target_qd, .. } = self.input {
            load(&mut w.target, target, r);
            load(&mut w.target_v, target_qd, r);
        }
        w.qs.copy_from_slice(&w.q);
        w.vs.copy_from_slice(&w.v);
        let (mut work, mut sum_work) = (T::zero(), T::zero());
        for row in rows.iter_mut() {
            *row.limit_step = -1;
            *row.limit_joint = -1;
            *row.nonfinite_step = -1;
            *row.nonfinite_joint = -1;
        }
        self.check(&w.q, &w.v, rows, 0);
        let stages = if method == Method::Rk4 { 4 } else { 1 };
        let (mut k, mut st) = (0, 0);
        loop {
            self.torque(w, r, k);
            if self.floating {
                aba_floating(self.model, &mut w.data, &w.qs, &w.vs, &w.tau, &mut w.a);
            } else {
                aba(self.model, &mut w.data, &w.qs, &w.vs, &w.tau, &mut w.a);
            }
            let mut power = T::zero();
            for j in 0..nv {
                power += w.tau[j] * w.vs[j];
            }
            if st == 0 {
                if k % stride == 0 {
                    self.store(w, work, rows, k / stride);
                }
                if k == steps {
                    break;
                }
            }
            match method {
                Method::SemiImplicitEuler => {
                    work += h * power;
                    for j in 0..nv {
                        w.v[j] += h * w.a[j];
                        w.rate[j] = h * w.v[j];
                    }
                    self.manifold.integrate_lanes(&w.q, &w.rate, &mut w.qs);
                    w.q.copy_from_slice(&w.qs);
                }
                Method::Rk4 => {
                    // the stage's rate of theta: v_i at theta_i (theta_1 = 0: v itself)
                    if st == 0 {
                        w.rate.copy_from_slice(&w.vs);
                        w.sum_rate.fill(T::zero());
                        w.sum_a.fill(T::zero());
                        sum_work = T::zero();
                    } else {
                        self.manifold.local_rate(&w.theta, &w.vs, &mut w.rate);
                    }
                    let weight = if st == 0 || st == 3 { T::splat(1.0) } else { two };
                    sum_work += weight * power;
                    for j in 0..nv {
                        w.sum_rate[j] += weight * w.rate[j];
                        w.sum_a[j] += weight * w.a[j];
                    }
                    if st < 3 {
                        let c = if st == 2 { h } else { h2 };
                        for j in 0..nv {
                            w.theta[j] = c * w.rate[j];
                            w.vs[j] = w.v[j] + c * w.a[j];
                        }
                        self.manifold.integrate_lanes(&w.q, &w.theta, &mut w.qs);
                    } else {
                        work += h6 * sum_work;
                        for j in 0..nv {
                            w.theta[j] = h6 * w.sum_rate[j];
                            w.v[j] += h6 * w.sum_a[j];
                        }
                        self.manifold.integrate_lanes(&w.q, &w.theta, &mut w.qs);
                        w.q.copy_from_slice(&w.qs);
                    }
                }
            }
            st += 1;
            if st == stages {
                st = 0;
                k += 1;
                if self.check(&w.q, &w.v, rows, k) || (k == steps && steps % stride != 0) {
                    break;
                }
                if k % STOP_POLL == 0 && self.stop.load(Ordering::Relaxed) {
                    break;
                }
                w.qs.copy_from_slice(&w.q);
                w.vs.copy_from_slice(&w.v);
            }
        }
        for (l, row) in rows.iter_mut().enumerate() {
            put(row.q_final, &w.q, l);
            put(row.qd_final, &w.v, l);
        }
    }
}

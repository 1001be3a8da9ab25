//! Time integration of a floating-base robot (`algo::floating`, Pinocchio's layout:
//! `q` (7 + nv), `v` (6 + nv)) for many initial states at once: the fixed-base
//! integrator's methods ([`crate::algo::integrate`]) with the base moved on SE(3).
//!
//! The configuration space is not flat: the base pose moves as `M' = M exp(xi)` for a
//! base twist `xi` (base frame, linear then angular; the exponential of SE(3), as
//! `armdyn.configuration.integrate` and Pinocchio's `integrate`), the joints add.
//! Written `q (+) xi`:
//!
//! * [`Method::SemiImplicitEuler`]: `v' = v + h a(q, v)`, `q' = q (+) h v'`.
//! * [`Method::Rk4`]: Runge-Kutta-Munthe-Kaas (Hairer, Lubich, Wanner, *Geometric
//!   Numerical Integration*, IV.8.2) with the classical tableau: the stages live in the
//!   tangent space at the step's start, `q_i = q (+) theta_i`, and the local coordinate
//!   obeys `theta' = dexp^-1_{-theta}(v)`, the Bernoulli series `v + [theta, v] / 2 +
//!   [theta, [theta, v]] / 12 + O(theta^4)` (its `theta^3` term is zero, so the
//!   truncation keeps fourth order). Velocities are a vector space: plain RK4.
//!
//! Torques ([`Input`]): zero, constant, or a series, of width 6 + nv (the base wrench
//! in the base frame, then the joints); controllers are fixed-base only. Outputs as
//! [`crate::algo::integrate::Outputs`], `q` of width 7 + nv and `qd`, `qdd`, `tau` of
//! width 6 + nv; `limit_joint` and `nonfinite_joint` index `v`'s coordinates (the
//! base's six first), `lower`, `upper` are the joints' (nv). The work is of the whole
//! wrench, `tau . v` (the base wrench's power included).
//!
//! One state per thread task, in `f64` (the exponential needs square roots and sines
//! the lane types do not have); results do not depend on the number of threads.

use crate::algo::floating::{aba_floating, NQ_BASE, NV_BASE};
use crate::algo::integrate::{Input, Method, Outputs, Settings, STOP_POLL};
use crate::batch::{install, thread_count};
use crate::data::Data;
use crate::model::Model;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Below this rotation angle (rad) the series of the SE(3) maps are used (their closed
/// forms divide 0 by 0 at 0), as in `armdyn.configuration`.
const SMALL: f64 = 1e-4;

type V3 = [f64; 3];

fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Hamilton product of quaternions `x, y, z, w`.
fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let c = cross([a[0], a[1], a[2]], [b[0], b[1], b[2]]);
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    [
        a[3] * b[0] + b[3] * a[0] + c[0],
        a[3] * b[1] + b[3] * a[1] + c[1],
        a[3] * b[2] + b[3] * a[2] + c[2],
        a[3] * b[3] - dot,
    ]
}

/// `R(quat) x` for a unit quaternion `x, y, z, w`.
fn rotate(quat: [f64; 4], x: V3) -> V3 {
    let v = [quat[0], quat[1], quat[2]];
    let t = cross(v, x).map(|c| 2.0 * c);
    let vt = cross(v, t);
    [0, 1, 2].map(|k| x[k] + quat[3] * t[k] + vt[k])
}

/// `out = q (+) xi`: the base pose (`q[..7]`) times `exp(xi[..6])`, the joints plus
/// `xi[6..]`. The quaternion is renormalised and kept on the side of `q`'s.
pub fn integrate_configuration(q: &[f64], xi: &[f64], out: &mut [f64]) {
    let lin = [xi[0], xi[1], xi[2]];
    let w = [xi[3], xi[4], xi[5]];
    let theta = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let t2 = theta * theta;
    // V(w) = 1 + a [w]x + b [w]x^2: the translation of exp(xi) is V(w) lin
    let (a, b, s) = if theta < SMALL {
        (0.5 - t2 / 24.0 + t2 * t2 / 720.0, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, 0.5 - t2 / 48.0)
    } else {
        ((1.0 - theta.cos()) / t2, (theta - theta.sin()) / (t2 * theta), (0.5 * theta).sin() / theta)
    };
    let wl = cross(w, lin);
    let wwl = cross(w, wl);
    let p = [0, 1, 2].map(|k| lin[k] + a * wl[k] + b * wwl[k]);
    let quat0 = [q[3], q[4], q[5], q[6]];
    let e = [w[0] * s, w[1] * s, w[2] * s, (0.5 * theta).cos()];
    let mut quat = quat_mul(quat0, e);
    let side: f64 = (0..4).map(|k| quat[k] * quat0[k]).sum();
    let norm = (0..4).map(|k| quat[k] * quat[k]).sum::<f64>().sqrt();
    let scale = if side < 0.0 { -1.0 / norm } else { 1.0 / norm };
    quat = quat.map(|c| c * scale);
    let d = rotate(quat0, p);
    for k in 0..3 {
        out[k] = q[k] + d[k];
    }
    out[3..NQ_BASE].copy_from_slice(&quat);
    for (o, (x, dx)) in out[NQ_BASE..].iter_mut().zip(q[NQ_BASE..].iter().zip(&xi[NV_BASE..])) {
        *o = x + dx;
    }
}

/// `[x, y]` in se(3), twists as (linear, angular).
fn bracket(x: &[f64], y: &[f64]) -> [f64; 6] {
    let (rho, om) = ([x[0], x[1], x[2]], [x[3], x[4], x[5]]);
    let (u, w) = ([y[0], y[1], y[2]], [y[3], y[4], y[5]]);
    let (a, b, c) = (cross(om, u), cross(rho, w), cross(om, w));
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], c[0], c[1], c[2]]
}

/// The base part of `k = dexp^-1_{-theta}(v)` (see the module doc), into `k[..6]`.
fn local_rate(theta: &[f64], v: &[f64], k: &mut [f64]) {
    let b1 = bracket(theta, v);
    let b2 = bracket(theta, &b1);
    for i in 0..NV_BASE {
        k[i] = v[i] + 0.5 * b1[i] + b2[i] / 12.0;
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

/// Integrate `N` floating-base states `q0` (N, 7 + nv), `v0` (N, 6 + nv) as the module
/// says, ending early once `stop` is set (read every [`STOP_POLL`] steps). Returns false
/// if it was stopped. Panics on a controller input or on mis-sized arrays.
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
    let n = model.nv;
    let (nq, nv) = (n + NQ_BASE, n + NV_BASE);
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
        Input::Pd { .. } | Input::ComputedTorque { .. } => {
            panic!("controllers are fixed-base only")
        }
    }
    let Outputs { q, work, qd, qdd, tau, q_final, qd_final, limit_step, limit_joint, nonfinite_step, nonfinite_joint } =
        out;
    let mut tasks: Vec<(usize, Row)> = Vec::with_capacity(rows);
    let mut ints =
        limit_step.iter_mut().zip(limit_joint.iter_mut()).zip(nonfinite_step.iter_mut().zip(nonfinite_joint));
    let mut q_rows = q.chunks_mut(s * nq).zip(q_final.chunks_mut(nq));
    let mut v_rows = qd.chunks_mut(s * nv).zip(qdd.chunks_mut(s * nv)).zip(tau.chunks_mut(s * nv));
    let mut w_rows = work.chunks_mut(s).zip(qd_final.chunks_mut(nv));
    for r in 0..rows {
        let ((ls, lj), (ns, nj)) = ints.next().expect("rows");
        let (q, q_final) = q_rows.next().expect("rows");
        let ((qd, qdd), tau) = v_rows.next().expect("rows");
        let (work, qd_final) = w_rows.next().expect("rows");
        let row = Row {
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
        };
        tasks.push((r, row));
    }
    let job = Job { model, q0, v0, input, settings, lower, upper, stop };
    let mut tasks = Some(tasks);
    let mut run = || {
        let tasks = tasks.take().expect("runs once");
        if thread_count(threads) == 1 || rows < 2 {
            let mut data = Data::new(model);
            tasks.into_iter().for_each(|(r, mut row)| job.row(&mut data, r, &mut row));
        } else {
            tasks.into_par_iter().for_each_init(|| Data::new(model), |data, (r, mut row)| job.row(data, r, &mut row));
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
    q0: &'a [f64],
    v0: &'a [f64],
    input: Input<'a>,
    settings: Settings,
    lower: &'a [f64],
    upper: &'a [f64],
    stop: &'a AtomicBool,
}

impl Job<'_> {
    /// The torque during step `k` of state `r`.
    fn torque(&self, r: usize, k: usize, tau: &mut [f64]) {
        let nv = tau.len();
        match self.input {
            Input::Constant(t) => tau.copy_from_slice(&t[r * nv..(r + 1) * nv]),
            Input::Series { tau: t, shared } => {
                let k = k.min(self.settings.steps - 1);
                let at = if shared { k } else { r * self.settings.steps + k } * nv;
                tau.copy_from_slice(&t[at..at + nv]);
            }
            _ => tau.fill(0.0),
        }
    }

    /// Record limit crossings and non-finite coordinates of `(q, v)` at step `k`; true
    /// once the state is not finite.
    fn check(&self, q: &[f64], v: &[f64], row: &mut Row, k: usize) -> bool {
        if *row.limit_step < 0 {
            let mut joints = q[NQ_BASE..].iter().enumerate();
            if let Some((j, _)) = joints.find(|&(j, &x)| x < self.lower[j] || x > self.upper[j]) {
                *row.limit_step = k as i64;
                *row.limit_joint = (NV_BASE + j) as i64;
            }
        }
        if *row.nonfinite_step < 0 {
            // q's coordinates in v's layout: the base position (0..3), its orientation (3..6)
            let q_finite = |j: usize| match j {
                0..=2 => q[j].is_finite(),
                3..=5 => q[3..NQ_BASE].iter().all(|x| x.is_finite()),
                _ => q[j + 1].is_finite(),
            };
            if let Some(j) = (0..v.len()).find(|&j| !(v[j].is_finite() && q_finite(j))) {
                *row.nonfinite_step = k as i64;
                *row.nonfinite_joint = j as i64;
            }
        }
        *row.nonfinite_step >= 0
    }

    /// Integrate state `r` into `row`.
    fn row(&self, data: &mut Data<f64>, r: usize, row: &mut Row) {
        let n = self.model.nv;
        let (nq, nv) = (n + NQ_BASE, n + NV_BASE);
        let Settings { method, dt: h, steps, stride } = self.settings;
        let mut q = self.q0[r * nq..(r + 1) * nq].to_vec();
        let mut v = self.v0[r * nv..(r + 1) * nv].to_vec();
        let (mut qs, mut vs) = (q.clone(), v.clone());
        let (mut tau, mut a) = (vec![0.0; nv], vec![0.0; nv]);
        // RK4: the stage's local coordinate theta, its rate, and the weighted sums
        let (mut theta, mut rate) = (vec![0.0; nv], vec![0.0; nv]);
        let (mut sum_rate, mut sum_a) = (vec![0.0; nv], vec![0.0; nv]);
        let (mut work, mut sum_work) = (0.0, 0.0);
        *row.limit_step = -1;
        *row.limit_joint = -1;
        *row.nonfinite_step = -1;
        *row.nonfinite_joint = -1;
        self.check(&q, &v, row, 0);
        let stages = if method == Method::Rk4 { 4 } else { 1 };
        let (mut k, mut st) = (0, 0);
        loop {
            self.torque(r, k, &mut tau);
            aba_floating(self.model, data, &qs, &vs, &tau, &mut a);
            let power: f64 = tau.iter().zip(&vs).map(|(t, x)| t * x).sum();
            if st == 0 {
                if k % stride == 0 {
                    let s = k / stride;
                    row.q[s * nq..(s + 1) * nq].copy_from_slice(&q);
                    row.qd[s * nv..(s + 1) * nv].copy_from_slice(&v);
                    row.qdd[s * nv..(s + 1) * nv].copy_from_slice(&a);
                    row.tau[s * nv..(s + 1) * nv].copy_from_slice(&tau);
                    row.work[s] = work;
                }
                if k == steps {
                    break;
                }
            }
            match (method, st) {
                (Method::SemiImplicitEuler, _) => {
                    work += h * power;
                    for j in 0..nv {
                        v[j] += h * a[j];
                        rate[j] = h * v[j];
                    }
                    integrate_configuration(&q, &rate, &mut qs);
                    q.copy_from_slice(&qs);
                }
                (Method::Rk4, _) => {
                    // the stage's rate of theta: v_i at theta_i (theta_1 = 0: v itself)
                    if st == 0 {
                        rate.copy_from_slice(&vs);
                    } else {
                        local_rate(&theta, &vs, &mut rate);
                        rate[NV_BASE..].copy_from_slice(&vs[NV_BASE..]);
                    }
                    let weight = if st == 0 || st == 3 { 1.0 } else { 2.0 };
                    if st == 0 {
                        sum_rate.fill(0.0);
                        sum_a.fill(0.0);
                        sum_work = 0.0;
                    }
                    sum_work += weight * power;
                    for j in 0..nv {
                        sum_rate[j] += weight * rate[j];
                        sum_a[j] += weight * a[j];
                    }
                    if st < 3 {
                        let c = if st == 2 { h } else { 0.5 * h };
                        for j in 0..nv {
                            theta[j] = c * rate[j];
                            vs[j] = v[j] + c * a[j];
                        }
                        integrate_configuration(&q, &theta, &mut qs);
                    } else {
                        work += h / 6.0 * sum_work;
                        for j in 0..nv {
                            theta[j] = h / 6.0 * sum_rate[j];
                            v[j] += h / 6.0 * sum_a[j];
                        }
                        integrate_configuration(&q, &theta, &mut qs);
                        q.copy_from_slice(&qs);
                    }
                }
            }
            st += 1;
            if st == stages {
                st = 0;
                k += 1;
                if self.check(&q, &v, row, k) || (k == steps && steps % stride != 0) {
                    break;
                }
                if k % STOP_POLL == 0 && self.stop.load(Ordering::Relaxed) {
                    break;
                }
                qs.copy_from_slice(&q);
                vs.copy_from_slice(&v);
            }
        }
        row.q_final.copy_from_slice(&q);
        row.qd_final.copy_from_slice(&v);
    }
}

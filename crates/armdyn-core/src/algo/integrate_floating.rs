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
//! States run in SIMD lanes (4 or 8 per group, as [`crate::algo::integrate`]; the
//! leftover rows one by one), groups spread over rayon threads. The dynamics run on the
//! lanes; the base's exponential (square roots and sines, which the lane types do not
//! have) lane by lane in `f64`. Every lane performs exactly the operations of a single
//! state, so results do not depend on the kernels, threads or grouping.

use crate::algo::floating::{aba_floating, NQ_BASE, NV_BASE};
use crate::algo::integrate::{Input, Method, Outputs, Settings, STOP_POLL};
use crate::batch::{install, kernels, thread_count, Kernels};
use crate::data::Data;
use crate::model::Model;
use crate::real::{F64x4, F64x8, Real};
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
    integrate_base(q, xi, out);
    for (o, (x, dx)) in out[NQ_BASE..].iter_mut().zip(q[NQ_BASE..].iter().zip(&xi[NV_BASE..])) {
        *o = x + dx;
    }
}

/// [`integrate_configuration`] lane by lane: the base in `f64`, the joints on the lanes.
#[inline(always)]
fn integrate_lanes<T: Real>(q: &[T], xi: &[T], out: &mut [T]) {
    let (mut qa, mut xa, mut oa) = ([0.0; NQ_BASE], [0.0; NV_BASE], [0.0; NQ_BASE]);
    for l in 0..T::LANES {
        for k in 0..NQ_BASE {
            qa[k] = T::lane_of(&q[k], l);
        }
        for k in 0..NV_BASE {
            xa[k] = T::lane_of(&xi[k], l);
        }
        integrate_base(&qa, &xa, &mut oa);
        for k in 0..NQ_BASE {
            out[k].set_lane(l, oa[k]);
        }
    }
    for (o, (x, dx)) in out[NQ_BASE..].iter_mut().zip(q[NQ_BASE..].iter().zip(&xi[NV_BASE..])) {
        *o = *x + *dx;
    }
}

/// The base part of [`integrate_configuration`]: `out[..7]` from `q[..7]`, `xi[..6]`.
#[inline(always)]
fn integrate_base(q: &[f64], xi: &[f64], out: &mut [f64]) {
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
}

/// `a x b` on lanes.
#[inline(always)]
fn cross_lanes<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `[x, y]` in se(3), twists as (linear, angular).
#[inline(always)]
fn bracket<T: Real>(x: &[T], y: &[T]) -> [T; 6] {
    let (rho, om) = ([x[0], x[1], x[2]], [x[3], x[4], x[5]]);
    let (u, w) = ([y[0], y[1], y[2]], [y[3], y[4], y[5]]);
    let (a, b, c) = (cross_lanes(om, u), cross_lanes(rho, w), cross_lanes(om, w));
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], c[0], c[1], c[2]]
}

/// The base part of `k = dexp^-1_{-theta}(v)` (see the module doc), into `k[..6]`.
#[inline(always)]
fn local_rate<T: Real>(theta: &[T], v: &[T], k: &mut [T]) {
    let b1 = bracket(theta, v);
    let b2 = bracket(theta, &b1);
    let (half, twelfth) = (T::splat(0.5), T::splat(1.0 / 12.0));
    for i in 0..NV_BASE {
        k[i] = v[i] + half * b1[i] + b2[i] * twelfth;
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
        Input::Pd { .. } | Input::ComputedTorque { .. } => panic!("controllers are fixed-base only"),
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
    let job = Job { model, q0, v0, input, settings, lower, upper, stop };
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
    q0: &'a [f64],
    v0: &'a [f64],
    input: Input<'a>,
    settings: Settings,
    lower: &'a [f64],
    upper: &'a [f64],
    stop: &'a AtomicBool,
}

/// Per-group workspace: lane vectors (q: 7 + nv, the others 6 + nv).
struct Work<T> {
    data: Data<T>,
    q: Vec<T>,
    v: Vec<T>,
    qs: Vec<T>,
    vs: Vec<T>,
    tau: Vec<T>,
    a: Vec<T>,
    /// RK4: the stage's local coordinate, its rate, and the weighted sums.
    theta: Vec<T>,
    rate: Vec<T>,
    sum_rate: Vec<T>,
    sum_a: Vec<T>,
}

impl<T: Real> Work<T> {
    fn new(model: &Model) -> Self {
        let z = |k: usize| vec![T::zero(); model.nv + k];
        Work {
            data: Data::new(model),
            q: z(NQ_BASE),
            v: z(NV_BASE),
            qs: z(NQ_BASE),
            vs: z(NV_BASE),
            tau: z(NV_BASE),
            a: z(NV_BASE),
            theta: z(NV_BASE),
            rate: z(NV_BASE),
            sum_rate: z(NV_BASE),
            sum_a: z(NV_BASE),
        }
    }
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
    /// Integrate the rows of one group: in SIMD lanes if it is a whole group of the
    /// widest kernel's, else one by one.
    fn dispatch(&self, first: usize, rows: &mut [Row]) {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        unsafe fn avx512(job: &Job, first: usize, rows: &mut [Row]) {
            job.group(&mut Work::<F64x8>::new(job.model), first, rows)
        }
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn avx2(job: &Job, first: usize, rows: &mut [Row]) {
            job.group(&mut Work::<F64x4>::new(job.model), first, rows)
        }
        match (kernels(), rows.len()) {
            // SAFETY: the CPU supports the features (checked by `kernels`).
            #[cfg(target_arch = "x86_64")]
            (Kernels::Avx512, 8) => unsafe { avx512(self, first, rows) },
            #[cfg(target_arch = "x86_64")]
            (Kernels::Avx2, 4) => unsafe { avx2(self, first, rows) },
            #[cfg(not(target_arch = "x86_64"))]
            (_, 4) => self.group(&mut Work::<F64x4>::new(self.model), first, rows),
            _ => {
                let mut w = Work::<f64>::new(self.model);
                for (k, row) in rows.iter_mut().enumerate() {
                    self.group(&mut w, first + k, std::slice::from_mut(row));
                }
            }
        }
    }

    /// The torque during step `k` of the lanes' rows `r..`.
    #[inline(always)]
    fn torque<T: Real>(&self, r: usize, k: usize, tau: &mut [T]) {
        let nv = tau.len();
        match self.input {
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
                if let Some(j) = (0..self.lower.len()).find(|&j| {
                    let y = x(NQ_BASE + j);
                    y < self.lower[j] || y > self.upper[j]
                }) {
                    *row.limit_step = k as i64;
                    *row.limit_joint = (NV_BASE + j) as i64;
                }
            }
            if *row.nonfinite_step < 0 {
                // q's coordinates in v's layout: the base position (0..3), its orientation (3..6)
                let q_finite = |j: usize| match j {
                    0..=2 => x(j).is_finite(),
                    3..=5 => (3..NQ_BASE).all(|i| x(i).is_finite()),
                    _ => x(j + 1).is_finite(),
                };
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
            self.torque(r, k, &mut w.tau);
            aba_floating(self.model, &mut w.data, &w.qs, &w.vs, &w.tau, &mut w.a);
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
                    integrate_lanes(&w.q, &w.rate, &mut w.qs);
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
                        local_rate(&w.theta, &w.vs, &mut w.rate);
                        w.rate[NV_BASE..].copy_from_slice(&w.vs[NV_BASE..]);
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
                        integrate_lanes(&w.q, &w.theta, &mut w.qs);
                    } else {
                        work += h6 * sum_work;
                        for j in 0..nv {
                            w.theta[j] = h6 * w.sum_rate[j];
                            w.v[j] += h6 * w.sum_a[j];
                        }
                        integrate_lanes(&w.q, &w.theta, &mut w.qs);
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

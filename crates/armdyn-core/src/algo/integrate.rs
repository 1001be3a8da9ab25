//! Time integration of the forward dynamics `qdd = aba(q, qd, tau)` for many initial
//! states at once.
//!
//! The state is `x = (q, qd)`, `xd = (qd, aba(q, qd, tau(t, q, qd)))`. Two fixed-step
//! methods (step `h = dt`):
//!
//! * [`Method::Rk4`]: the classical fourth-order Runge-Kutta method (Hairer, Norsett,
//!   Wanner, *Solving ODEs I*, Table 1.2, "the" Runge-Kutta method); four `aba` per step.
//! * [`Method::SemiImplicitEuler`]: symplectic Euler, `qd' = qd + h qdd(q, qd)`,
//!   `q' = q + h qd'` (Hairer, Lubich, Wanner, *Geometric Numerical Integration*,
//!   eq. I.1.9); one `aba` per step, first order, bounded energy error for conservative
//!   systems.
//!
//! Forward dynamics is [`crate::algo::aba`] itself, so whatever the model's `aba`
//! includes is integrated.
//!
//! Torque ([`Input`]): zero; constant per state; a series held constant over each step
//! (zero-order hold; the last row is held at the final sample); or a controller
//! evaluated at every stage (a continuous-time feedback law, part of the ODE):
//! joint PD (optionally plus gravity compensation `g(q)`) or computed torque
//! `tau = rnea(q, qd, Kp (q* - q) + Kd (qd* - qd))` (Spong, Hutchinson, Vidyasagar,
//! *Robot Modeling and Control*, eq. 8.58 with `qdd* = 0`).
//!
//! Every `stride`-th step (`0, stride, 2 stride, ...` up to `steps`) is stored: `q`,
//! `qd`, the `qdd` and `tau` at that state, and the work done by the torque since the
//! start, `W = integral of tau . qd dt`, integrated alongside the state by the same
//! method (its stages' powers `tau . qd` with the RK4 weights; Euler: `h tau . qd` at
//! the step's start), so that `E(t) - E(0) - W(t)` measures the integration error of a
//! run with torques applied as the energy drift does for a passive one. The last state is always returned
//! separately (`q_final`, `qd_final`), so that a long run can continue in pieces
//! bit-for-bit. Joint limits are reported (first step and joint at which a state is
//! outside `[lower, upper]`), never enforced; the first step at which a state is not
//! finite, and the joint, is reported as well, and that state's integration stops there
//! (the samples after it are left as they were: NaN is all a diverged run would give).
//!
//! [`simulate_until`] takes a stop flag, read every [`STOP_POLL`] steps, so that a caller
//! (e.g. a Ctrl-C handler) can end a long run early without slowing the step loop.
//!
//! States run in SIMD lanes (4 or 8 per group, the kernels of [`crate::batch`]), the
//! groups spread over threads by rayon; every lane performs exactly the operations of
//! a single state, so results do not depend on the kernels, threads or grouping.

use crate::algo;
use crate::batch::{install, kernels, thread_count, Kernels};
use crate::data::Data;
use crate::model::Model;
use crate::real::{F64x4, F64x8, Real};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Steps between two reads of the stop flag of [`simulate_until`] (a power of two: the
/// test is a mask; a relaxed atomic load per 256 steps costs nothing measurable).
pub const STOP_POLL: usize = 256;

/// The integration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Rk4,
    SemiImplicitEuler,
}

/// The joint torque applied. Arrays are row-major; `N` states, `nv` joints.
#[derive(Clone, Copy, Debug)]
pub enum Input<'a> {
    /// `tau = 0` (passive).
    Zero,
    /// `(N, nv)`: one constant torque per state.
    Constant(&'a [f64]),
    /// `(steps, nv)` for every state (`shared`), or `(N, steps, nv)`. Row `k` acts over
    /// `[t_k, t_k + dt)`.
    Series { tau: &'a [f64], shared: bool },
    /// `tau = [g(q)] + Kp (q* - q) + Kd (qd* - qd)`; `kp`, `kd` (nv,) diagonal gains,
    /// `target`, `target_qd` (N, nv).
    Pd { kp: &'a [f64], kd: &'a [f64], target: &'a [f64], target_qd: &'a [f64], gravity_compensation: bool },
    /// `tau = rnea(q, qd, Kp (q* - q) + Kd (qd* - qd))`: the closed loop is
    /// `e'' + Kd e' + Kp e = 0` for `e = q* - q` when `qd* = 0`.
    ComputedTorque { kp: &'a [f64], kd: &'a [f64], target: &'a [f64], target_qd: &'a [f64] },
}

/// Step size, number of steps, storage stride.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub method: Method,
    pub dt: f64,
    pub steps: usize,
    /// Store every `stride`-th state (`>= 1`): `steps / stride + 1` samples.
    pub stride: usize,
}

impl Settings {
    /// Number of stored samples per state.
    pub fn samples(&self) -> usize {
        self.steps / self.stride + 1
    }
}

/// Where results go. `S = settings.samples()`.
pub struct Outputs<'a> {
    /// `(N, S, nv)` each.
    pub q: &'a mut [f64],
    /// `(N, S)`: work done by the torque from the start to each stored sample.
    pub work: &'a mut [f64],
    pub qd: &'a mut [f64],
    pub qdd: &'a mut [f64],
    pub tau: &'a mut [f64],
    /// `(N, nv)`: the state after the last step.
    pub q_final: &'a mut [f64],
    pub qd_final: &'a mut [f64],
    /// `(N,)`: first step at which a joint is outside its limits (`-1`: never), and
    /// which joint (the lowest index at that step).
    pub limit_step: &'a mut [i64],
    pub limit_joint: &'a mut [i64],
    /// `(N,)`: first step at which `q` or `qd` is not finite (`-1`: never), and the
    /// lowest joint index whose `q` or `qd` is not finite at that step. The state's
    /// integration stops at that step: later samples are not written.
    pub nonfinite_step: &'a mut [i64],
    pub nonfinite_joint: &'a mut [i64],
}

/// Integrate `N` initial states `q0`, `qd0` (N, nv) for `settings.steps` steps.
/// `lower`, `upper`: (nv,) joint limits (use infinities for none).
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    model: &Model,
    q0: &[f64],
    qd0: &[f64],
    input: Input,
    settings: Settings,
    lower: &[f64],
    upper: &[f64],
    out: Outputs,
    threads: Option<usize>,
) {
    simulate_until(model, q0, qd0, input, settings, lower, upper, out, threads, &AtomicBool::new(false));
}

/// [`simulate`], ending early once `stop` is set (read every [`STOP_POLL`] steps of each
/// state). Returns false if it was stopped: the outputs are then incomplete.
#[allow(clippy::too_many_arguments)]
pub fn simulate_until(
    model: &Model,
    q0: &[f64],
    qd0: &[f64],
    input: Input,
    settings: Settings,
    lower: &[f64],
    upper: &[f64],
    out: Outputs,
    threads: Option<usize>,
    stop: &AtomicBool,
) -> bool {
    let n = model.nv;
    assert!(settings.stride >= 1 && settings.dt.is_finite(), "settings");
    assert!(lower.len() == n && upper.len() == n, "limits length");
    let rows = if n == 0 { out.limit_step.len() } else { q0.len() / n };
    let s = settings.samples();
    assert!(q0.len() == rows * n && qd0.len() == rows * n, "initial state size");
    for o in [&out.q, &out.qd, &out.qdd, &out.tau] {
        assert_eq!(o.len(), rows * s * n, "output size");
    }
    assert_eq!(out.work.len(), rows * s, "work size");
    assert!(out.q_final.len() == rows * n && out.qd_final.len() == rows * n, "final state size");
    assert!(out.limit_step.len() == rows && out.limit_joint.len() == rows && out.nonfinite_step.len() == rows);
    assert!(out.nonfinite_joint.len() == rows);
    match input {
        Input::Zero => {}
        Input::Constant(t) => assert_eq!(t.len(), rows * n, "constant torque size"),
        Input::Series { tau, shared } => {
            assert!(settings.steps >= 1, "a torque series needs at least one step");
            assert_eq!(tau.len(), if shared { 1 } else { rows } * settings.steps * n, "torque series size")
        }
        Input::Pd { kp, kd, target, target_qd, .. } | Input::ComputedTorque { kp, kd, target, target_qd } => {
            assert!(kp.len() == n && kd.len() == n, "gain size");
            assert!(target.len() == rows * n && target_qd.len() == rows * n, "target size");
        }
    }
    let task = Task { model, q0, qd0, input, settings, lower, upper, stop };

    // Chunks of rows (multiples of 8 so that lane groups never straddle chunks).
    let nthreads = thread_count(threads);
    let chunk_rows = if nthreads == 1 || rows < 16 { rows.max(1) } else { rows.div_ceil(4 * nthreads).next_multiple_of(8) };
    let mut chunks = Vec::new();
    let Outputs {
        mut q, mut work, mut qd, mut qdd, mut tau, mut q_final, mut qd_final, mut limit_step, mut limit_joint,
        mut nonfinite_step, mut nonfinite_joint,
    } = out;
    let mut first = 0;
    while first < rows {
        let r = chunk_rows.min(rows - first);
        macro_rules! take {
            ($a:ident, $per:expr) => {{
                let (head, tail) = std::mem::take(&mut $a).split_at_mut(r * $per);
                $a = tail;
                head
            }};
        }
        chunks.push((
            first,
            Outputs {
                q: take!(q, s * n),
                work: take!(work, s),
                qd: take!(qd, s * n),
                qdd: take!(qdd, s * n),
                tau: take!(tau, s * n),
                q_final: take!(q_final, n),
                qd_final: take!(qd_final, n),
                limit_step: take!(limit_step, 1),
                limit_joint: take!(limit_joint, 1),
                nonfinite_step: take!(nonfinite_step, 1),
                nonfinite_joint: take!(nonfinite_joint, 1),
            },
        ));
        first += r;
    }
    let mut chunks = Some(chunks);
    let mut run = || {
        let chunks = chunks.take().expect("runs once").into_par_iter();
        chunks.for_each(|(first, mut chunk)| task.chunk(first, &mut chunk))
    };
    match threads {
        None => run(),
        Some(k) => install(k, &mut run),
    }
    !stop.load(Ordering::Relaxed)
}

/// The shared read-only inputs of one call.
struct Task<'a> {
    model: &'a Model,
    q0: &'a [f64],
    qd0: &'a [f64],
    input: Input<'a>,
    settings: Settings,
    lower: &'a [f64],
    upper: &'a [f64],
    stop: &'a AtomicBool,
}

/// Per-group workspace: lane vectors of length nv.
struct Work<T> {
    data: Data<T>,
    /// State at the start of the step.
    q: Vec<T>,
    qd: Vec<T>,
    /// Stage state, torque and acceleration.
    qs: Vec<T>,
    qds: Vec<T>,
    tau: Vec<T>,
    qdd: Vec<T>,
    /// RK4 weighted sums of the stage derivatives (of q and of qd).
    sum_q: Vec<T>,
    sum_qd: Vec<T>,
    /// Work done so far, and the RK4 weighted sum of the stage powers.
    work: T,
    sum_work: T,
    /// Per-state constants: constant torque or controller targets; scratch.
    c0: Vec<T>,
    c1: Vec<T>,
    tmp: Vec<T>,
}

impl<T: Real> Work<T> {
    fn new(model: &Model) -> Self {
        let z = || vec![T::zero(); model.nv];
        Work {
            data: Data::new(model),
            q: z(),
            qd: z(),
            qs: z(),
            qds: z(),
            tau: z(),
            qdd: z(),
            sum_q: z(),
            sum_qd: z(),
            work: T::zero(),
            sum_work: T::zero(),
            c0: z(),
            c1: z(),
            tmp: z(),
        }
    }
}

/// Lanes of `dst` from rows `first..first + LANES` of the (rows, n) array `src`.
#[inline(always)]
fn load<T: Real>(dst: &mut [T], src: &[f64], n: usize, first: usize) {
    for (j, d) in dst.iter_mut().enumerate() {
        for l in 0..T::LANES {
            d.set_lane(l, src[(first + l) * n + j]);
        }
    }
}

impl Task<'_> {
    /// Run rows `first..` of one chunk: lane groups with the widest kernels, then the
    /// leftover rows one by one.
    fn chunk(&self, first: usize, out: &mut Outputs) {
        let rows = out.limit_step.len();
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        unsafe fn avx512(t: &Task, first: usize, out: &mut Outputs) -> usize {
            t.groups::<F64x8>(first, out)
        }
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn avx2(t: &Task, first: usize, out: &mut Outputs) -> usize {
            t.groups::<F64x4>(first, out)
        }
        let done = match kernels() {
            // SAFETY: the CPU supports the features (checked by `kernels`).
            #[cfg(target_arch = "x86_64")]
            Kernels::Avx512 => unsafe { avx512(self, first, out) },
            #[cfg(target_arch = "x86_64")]
            Kernels::Avx2 => unsafe { avx2(self, first, out) },
            // x86-64 without AVX2: every row by the scalar loop below (see
            // `batch::BaselineLanes`: no third copy of the integrator for such CPUs).
            #[cfg(target_arch = "x86_64")]
            _ => 0,
            #[cfg(not(target_arch = "x86_64"))]
            _ => self.groups::<F64x4>(first, out),
        };
        let mut w = Work::<f64>::new(self.model);
        for r in done..rows {
            self.group(&mut w, first, r, out);
        }
    }

    /// All whole groups of `L::LANES` rows of the chunk; returns the rows done.
    #[inline(always)]
    fn groups<L: Real>(&self, first: usize, out: &mut Outputs) -> usize {
        let rows = out.limit_step.len();
        let mut w = Work::<L>::new(self.model);
        let mut r = 0;
        while r + L::LANES <= rows {
            self.group(&mut w, first, r, out);
            r += L::LANES;
        }
        r
    }

    /// Torque at a stage state (`q`, `qd`) during step `k`, into `w.tau`.
    #[inline(always)]
    fn torque<T: Real>(&self, w: &mut Work<T>, row: usize, k: usize, stage: bool) {
        let n = self.model.nv;
        let (q, qd) = if stage { (&w.qs, &w.qds) } else { (&w.q, &w.qd) };
        match self.input {
            Input::Zero => w.tau.fill(T::zero()),
            Input::Constant(_) => w.tau.copy_from_slice(&w.c0),
            Input::Series { tau, shared } => {
                let k = k.min(self.settings.steps - 1);
                if shared {
                    for j in 0..n {
                        w.tau[j] = T::splat(tau[k * n + j]);
                    }
                } else {
                    for j in 0..n {
                        for l in 0..T::LANES {
                            w.tau[j].set_lane(l, tau[((row + l) * self.settings.steps + k) * n + j]);
                        }
                    }
                }
            }
            Input::Pd { kp, kd, gravity_compensation, .. } => {
                if gravity_compensation {
                    algo::gravity(self.model, &mut w.data, q, &mut w.tau);
                } else {
                    w.tau.fill(T::zero());
                }
                for j in 0..n {
                    w.tau[j] += T::splat(kp[j]) * (w.c0[j] - q[j]) + T::splat(kd[j]) * (w.c1[j] - qd[j]);
                }
            }
            Input::ComputedTorque { kp, kd, .. } => {
                for j in 0..n {
                    w.tmp[j] = T::splat(kp[j]) * (w.c0[j] - q[j]) + T::splat(kd[j]) * (w.c1[j] - qd[j]);
                }
                algo::rnea(self.model, &mut w.data, q, qd, &w.tmp, &mut w.tau);
            }
        }
    }

    /// `w.qdd = aba(stage state, w.tau)`, torque evaluated first.
    #[inline(always)]
    fn stage<T: Real>(&self, w: &mut Work<T>, row: usize, k: usize) {
        self.torque(w, row, k, true);
        algo::aba(self.model, &mut w.data, &w.qs, &w.qds, &w.tau, &mut w.qdd);
    }

    /// Write sample `s` (state `w.q`, `w.qd`, with `w.qdd`, `w.tau`) of the lanes of
    /// chunk rows `r..`.
    #[inline(always)]
    fn store<T: Real>(&self, w: &Work<T>, out: &mut Outputs, r: usize, s: usize) {
        let n = self.model.nv;
        let per = self.settings.samples() * n;
        for l in 0..T::LANES {
            out.work[(r + l) * self.settings.samples() + s] = w.work.lane(l);
            let at = (r + l) * per + s * n;
            for j in 0..n {
                out.q[at + j] = w.q[j].lane(l);
                out.qd[at + j] = w.qd[j].lane(l);
                out.qdd[at + j] = w.qdd[j].lane(l);
                out.tau[at + j] = w.tau[j].lane(l);
            }
        }
    }

    /// Record limit crossings and non-finite states of `w.q`, `w.qd` at step `k`; true
    /// when every lane is non-finite (nothing left to integrate).
    #[inline(always)]
    fn check<T: Real>(&self, w: &Work<T>, out: &mut Outputs, r: usize, k: usize) -> bool {
        let mut diverged = 0;
        for l in 0..T::LANES {
            let row = r + l;
            if out.limit_step[row] < 0 {
                for j in 0..self.model.nv {
                    let x = w.q[j].lane(l);
                    if x < self.lower[j] || x > self.upper[j] {
                        out.limit_step[row] = k as i64;
                        out.limit_joint[row] = j as i64;
                        break;
                    }
                }
            }
            if out.nonfinite_step[row] < 0 {
                if let Some(j) = (0..self.model.nv).find(|&j| !(w.q[j].lane(l) + w.qd[j].lane(l)).is_finite()) {
                    out.nonfinite_step[row] = k as i64;
                    out.nonfinite_joint[row] = j as i64;
                }
            }
            diverged += (out.nonfinite_step[row] >= 0) as usize;
        }
        diverged == T::LANES
    }

    /// Integrate the lanes of chunk rows `r..r + LANES` (global rows `first + r..`).
    #[inline(always)]
    fn group<T: Real>(&self, w: &mut Work<T>, first: usize, r: usize, out: &mut Outputs) {
        let n = self.model.nv;
        let row = first + r;
        let Settings { method, dt, steps, stride } = self.settings;
        load(&mut w.q, self.q0, n, row);
        load(&mut w.qd, self.qd0, n, row);
        match self.input {
            Input::Constant(t) => load(&mut w.c0, t, n, row),
            Input::Pd { target, target_qd, .. } | Input::ComputedTorque { target, target_qd, .. } => {
                load(&mut w.c0, target, n, row);
                load(&mut w.c1, target_qd, n, row);
            }
            _ => {}
        }
        for l in 0..T::LANES {
            out.limit_step[r + l] = -1;
            out.limit_joint[r + l] = -1;
            out.nonfinite_step[r + l] = -1;
            out.nonfinite_joint[r + l] = -1;
        }
        self.check(w, out, r, 0);
        w.work = T::zero();
        let (h, h2, h6) = (T::splat(dt), T::splat(0.5 * dt), T::splat(dt / 6.0));
        let two = T::splat(2.0);
        let stages = match method {
            Method::Rk4 => 4,
            Method::SemiImplicitEuler => 1,
        };
        // One loop over stage evaluations (a single call site of `stage`, so that aba is
        // inlined once per kernel). Stage `st` of step `k` evaluates w.qdd at (qs, qds).
        let (mut k, mut st) = (0, 0);
        w.qs.copy_from_slice(&w.q);
        w.qds.copy_from_slice(&w.qd);
        loop {
            self.stage(w, row, k);
            // power of the torque at the stage state
            let mut power = T::zero();
            for j in 0..n {
                power += w.tau[j] * w.qds[j];
            }
            if st == 0 {
                // stage 1 is at the step's start: the stored sample
                if k % stride == 0 {
                    self.store(w, out, r, k / stride);
                }
                if k == steps {
                    break;
                }
            }
            match (method, st) {
                (Method::SemiImplicitEuler, _) => {
                    w.work += h * power;
                    for j in 0..n {
                        w.qd[j] += h * w.qdd[j];
                        w.q[j] += h * w.qd[j];
                    }
                }
                // k1 = (qd, qdd1); stage 2 at x + h/2 k1.
                (Method::Rk4, 0) => {
                    w.sum_work = power;
                    for j in 0..n {
                        w.sum_q[j] = w.qd[j];
                        w.sum_qd[j] = w.qdd[j];
                        w.qs[j] = w.q[j] + h2 * w.qd[j];
                        w.qds[j] = w.qd[j] + h2 * w.qdd[j];
                    }
                }
                // k2 = (qds, qdd2) (k3 likewise); stage 3 at x + h/2 k2, stage 4 at x + h k3.
                (Method::Rk4, 1 | 2) => {
                    let c = if st == 1 { h2 } else { h };
                    w.sum_work += two * power;
                    for j in 0..n {
                        let kq = w.qds[j];
                        w.sum_q[j] += two * kq;
                        w.sum_qd[j] += two * w.qdd[j];
                        w.qs[j] = w.q[j] + c * kq;
                        w.qds[j] = w.qd[j] + c * w.qdd[j];
                    }
                }
                // x += h/6 (k1 + 2 k2 + 2 k3 + k4)
                (Method::Rk4, _) => {
                    w.work += h6 * (w.sum_work + power);
                    for j in 0..n {
                        w.q[j] += h6 * (w.sum_q[j] + w.qds[j]);
                        w.qd[j] += h6 * (w.sum_qd[j] + w.qdd[j]);
                    }
                }
            }
            st += 1;
            if st == stages {
                st = 0;
                k += 1;
                if self.check(w, out, r, k) || (k == steps && steps % stride != 0) {
                    break;
                }
                if k % STOP_POLL == 0 && self.stop.load(Ordering::Relaxed) {
                    break;
                }
                w.qs.copy_from_slice(&w.q);
                w.qds.copy_from_slice(&w.qd);
            }
        }
        for l in 0..T::LANES {
            for j in 0..n {
                out.q_final[(r + l) * n + j] = w.q[j].lane(l);
                out.qd_final[(r + l) * n + j] = w.qd[j].lane(l);
            }
        }
    }
}

//! The integrator on a pendulum: its small-angle period, divergence and stop flags, the
//! work of the torques, and lanes and threads that give the same bits as single states.

use armdyn_core::algo::integrate::*;
use armdyn_core::model::{JointSpec, JointType, Model};
use std::sync::atomic::AtomicBool;


/// A point mass `m` at distance `l` on a revolute joint about y, gravity -z.
fn pendulum(m: f64, l: f64) -> Model {
    pendulum_in(m, l, [0.0, 0.0, -9.81])
}

fn pendulum_in(m: f64, l: f64, gravity: [f64; 3]) -> Model {
    let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let j = JointSpec {
        parent: None,
        jtype: JointType::Revolute,
        rotation: eye,
        translation: [0.0; 3],
        axis: [0.0, 1.0, 0.0],
        mass: m,
        com: [0.0, 0.0, -l],
        inertia: [[0.0; 3]; 3],
    };
    Model::new(&[j], gravity).unwrap()
}

fn run(model: &Model, q0: &[f64], method: Method, dt: f64, steps: usize, stride: usize, threads: Option<usize>) -> Vec<f64> {
    let n = model.nv;
    let rows = q0.len() / n;
    let s = Settings { method, dt, steps, stride };
    let len = rows * s.samples() * n;
    let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; len], vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    let mut work = vec![0.0; rows * s.samples()];
    let (mut qf, mut qdf) = (vec![0.0; rows * n], vec![0.0; rows * n]);
    let (mut ls, mut lj, mut nf, mut nj) = (vec![0; rows], vec![0; rows], vec![0; rows], vec![0; rows]);
    let inf = vec![f64::INFINITY; n];
    let ninf = vec![f64::NEG_INFINITY; n];
    let out = Outputs {
        q: &mut q,
        work: &mut work,
        qd: &mut qd,
        qdd: &mut qdd,
        tau: &mut tau,
        q_final: &mut qf,
        qd_final: &mut qdf,
        limit_step: &mut ls,
        limit_joint: &mut lj,
        nonfinite_step: &mut nf,
        nonfinite_joint: &mut nj,
    };
    simulate(model, q0, &vec![0.0; rows * n], Input::Zero, s, &ninf, &inf, out, threads);
    assert!(nf.iter().all(|&k| k == -1));
    q
}

#[test]
fn small_angle_pendulum_period() {
    // theta'' = -(g / l) sin theta; for 1e-3 rad the period is 2 pi sqrt(l / g)
    // to ~1e-7 relative; find the time of the first return through zero from above.
    let (l, g) = (0.7, 9.81);
    let model = pendulum(1.3, l);
    let dt = 1e-4;
    let q = run(&model, &[1e-3], Method::Rk4, dt, 40000, 1, Some(1));
    let mut crossings = vec![];
    for k in 1..q.len() {
        if (q[k - 1] > 0.0) != (q[k] > 0.0) {
            crossings.push((k - 1) as f64 * dt + dt * q[k - 1] / (q[k - 1] - q[k]));
        }
    }
    let period = crossings[2] - crossings[0];
    let expect = 2.0 * std::f64::consts::PI * (l / g).sqrt();
    assert!((period - expect).abs() < 1e-6 * expect, "{period} vs {expect}");
}

/// Outputs for `rows` states of `model`: (q, limit/nonfinite steps and joints, q_final).
fn run_input(model: &Model, q0: &[f64], input: Input, dt: f64, steps: usize, stop: &AtomicBool) -> (Vec<f64>, Vec<i64>, Vec<i64>, bool) {
    let n = model.nv;
    let rows = q0.len() / n;
    let s = Settings { method: Method::Rk4, dt, steps, stride: 1 };
    let len = rows * s.samples() * n;
    let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; len], vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    let mut work = vec![0.0; rows * s.samples()];
    let (mut qf, mut qdf) = (vec![0.0; rows * n], vec![0.0; rows * n]);
    let (mut ls, mut lj, mut nf, mut nj) = (vec![0; rows], vec![0; rows], vec![0; rows], vec![0; rows]);
    let (inf, ninf) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n]);
    let out = Outputs {
        q: &mut q, work: &mut work, qd: &mut qd, qdd: &mut qdd, tau: &mut tau, q_final: &mut qf, qd_final: &mut qdf,
        limit_step: &mut ls, limit_joint: &mut lj, nonfinite_step: &mut nf, nonfinite_joint: &mut nj,
    };
    let finished = simulate_until(model, q0, &vec![0.0; rows * n], input, s, &ninf, &inf, out, Some(1), stop);
    (q, nf, nj, finished)
}

#[test]
fn diverging_state_stops_at_its_first_nonfinite_step() {
    // A torque near f64::MAX overflows qd within a step or two: qd_k = k * dt * tau / (m l^2)
    // (gravity is negligible next to it). The state stops there; the step before is finite.
    let model = pendulum(1.0, 1.0);
    let tau = [1e308];
    let (q, nf, nj, finished) = run_input(&model, &[0.3], Input::Constant(&tau), 1.0, 1000, &AtomicBool::new(false));
    assert!(finished);
    let k = nf[0];
    assert!(k > 0 && k < 1000, "nonfinite step {k}");
    assert_eq!(nj[0], 0);
    assert!(q[..k as usize].iter().all(|x| x.is_finite()));
    assert!(!q[k as usize].is_finite() || q[k as usize] == 0.0);
    // nothing written after the stop: the samples past k + 1 are the untouched zeros
    assert!(q[k as usize + 1..].iter().all(|&x| x == 0.0));
}

#[test]
fn work_of_a_constant_torque_is_the_kinetic_energy_gained() {
    // no gravity: theta'' = tau / I, the work tau * theta(t) equals 1/2 I w(t)^2 (both
    // quadratic in t: RK4 integrates them exactly up to round-off)
    let model = pendulum_in(2.0, 0.5, [0.0; 3]);
    let (n, rows, steps) = (1, 1, 100);
    let s = Settings { method: Method::Rk4, dt: 1e-2, steps, stride: 10 };
    let len = rows * s.samples() * n;
    let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; len], vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    let mut work = vec![0.0; rows * s.samples()];
    let (mut qf, mut qdf) = (vec![0.0; rows * n], vec![0.0; rows * n]);
    let (mut ls, mut lj, mut nf, mut nj) = (vec![0; rows], vec![0; rows], vec![0; rows], vec![0; rows]);
    let out = Outputs {
        q: &mut q, work: &mut work, qd: &mut qd, qdd: &mut qdd, tau: &mut tau, q_final: &mut qf,
        qd_final: &mut qdf, limit_step: &mut ls, limit_joint: &mut lj, nonfinite_step: &mut nf,
        nonfinite_joint: &mut nj,
    };
    let torque = [3.0];
    simulate(&model, &[0.1], &[0.0], Input::Constant(&torque), s, &[f64::NEG_INFINITY], &[f64::INFINITY], out, Some(1));
    let inertia = 2.0 * 0.25; // point mass m l^2
    for k in 0..s.samples() {
        let kinetic = 0.5 * inertia * qd[k] * qd[k];
        assert!((work[k] - kinetic).abs() <= 1e-12 * kinetic.max(1.0), "{k}: {} vs {kinetic}", work[k]);
        assert!((work[k] - 3.0 * (q[k] - 0.1)).abs() <= 1e-12 * work[k].max(1.0));
    }
    assert!(work[s.samples() - 1] > 1.0);
}

#[test]
fn stop_flag_ends_the_run() {
    let model = pendulum(1.0, 1.0);
    let (q, nf, _, finished) = run_input(&model, &[0.3], Input::Zero, 1e-3, 10 * STOP_POLL, &AtomicBool::new(true));
    assert!(!finished);
    assert_eq!(nf[0], -1);
    // the first poll (after step STOP_POLL) ends it: sample STOP_POLL - 1 is the last written
    assert!(q[STOP_POLL - 1] != 0.0 && q[STOP_POLL..].iter().all(|&x| x == 0.0));
}

#[test]
fn lanes_and_threads_equal_single_states() {
    let model = pendulum(2.0, 0.5);
    let q0: Vec<f64> = (0..37).map(|k| 0.1 * k as f64 - 1.5).collect();
    for method in [Method::Rk4, Method::SemiImplicitEuler] {
        let all = run(&model, &q0, method, 1e-3, 50, 7, Some(2));
        let per = all.len() / q0.len();
        for (k, &x) in q0.iter().enumerate() {
            let one = run(&model, &[x], method, 1e-3, 50, 7, Some(1));
            assert_eq!(one.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                       all[k * per..(k + 1) * per].iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        }
    }
}

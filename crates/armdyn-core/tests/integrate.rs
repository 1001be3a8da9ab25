//! The integrator on a pendulum: its small-angle period, and lanes and threads that give
//! the same bits as single states.

use armdyn_core::algo::integrate::*;
use armdyn_core::model::{JointSpec, JointType, Model};

/// A point mass `m` at distance `l` on a revolute joint about y, gravity -z.
fn pendulum(m: f64, l: f64) -> Model {
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
    Model::new(&[j], [0.0, 0.0, -9.81]).unwrap()
}

fn run(model: &Model, q0: &[f64], method: Method, dt: f64, steps: usize, stride: usize, threads: Option<usize>) -> Vec<f64> {
    let n = model.nv;
    let rows = q0.len() / n;
    let s = Settings { method, dt, steps, stride };
    let len = rows * s.samples() * n;
    let (mut q, mut qd, mut qdd, mut tau) = (vec![0.0; len], vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    let (mut qf, mut qdf) = (vec![0.0; rows * n], vec![0.0; rows * n]);
    let (mut ls, mut lj, mut nf) = (vec![0; rows], vec![0; rows], vec![0; rows]);
    let inf = vec![f64::INFINITY; n];
    let ninf = vec![f64::NEG_INFINITY; n];
    let out = Outputs {
        q: &mut q,
        qd: &mut qd,
        qdd: &mut qdd,
        tau: &mut tau,
        q_final: &mut qf,
        qd_final: &mut qdf,
        limit_step: &mut ls,
        limit_joint: &mut lj,
        nonfinite_step: &mut nf,
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

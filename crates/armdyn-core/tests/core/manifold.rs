//! The configuration manifold (`algo::manifold`) and the integrator on it
//! (`algo::integrate_floating::simulate_manifold_until`) for joints of several
//! coordinates: the exponentials of SO(3) and SE(2) against their closed forms, the
//! dexp^-1 series against SO(3)'s closed form, and lanes and threads that give the same
//! bits as single states. (Energies, orders, MuJoCo: `tests/test_simulate_joints.py`.)

use crate::common::assert_close;
use armdyn_core::algo::integrate::{Input, Method, Outputs, Settings};
use armdyn_core::algo::integrate_floating::simulate_manifold_until;
use armdyn_core::algo::manifold::Manifold;
use armdyn_core::model::{JointSpec, JointType, Model};

const EYE: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn joint(parent: Option<usize>, jtype: JointType, translation: [f64; 3], axis: [f64; 3], com: [f64; 3]) -> JointSpec {
    let inertia = [[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]];
    JointSpec { parent, jtype, rotation: EYE, translation, axis, mass: 1.5, com, inertia }
}

/// A ball joint, a planar joint below it, then a hinge: q = quaternion (4), planar (4),
/// angle (1); v = 3 + 3 + 1.
fn chain() -> Model {
    let joints = [
        joint(None, JointType::Spherical, [0.0; 3], [0.0; 3], [0.0, 0.1, -0.4]),
        joint(Some(0), JointType::Planar, [0.0, 0.0, -0.5], [0.0; 3], [0.1, 0.0, -0.1]),
        joint(Some(1), JointType::Revolute, [0.2, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -0.3]),
    ];
    Model::new(&joints, [0.0, 0.0, -9.81]).expect("a valid chain")
}

#[test]
fn exponentials_are_the_closed_forms() {
    let model = chain();
    let m = Manifold::new(&model, false);
    assert_eq!((m.nq, m.nv), (9, 7));
    let (s, t) = (0.5f64.sqrt(), std::f64::consts::FRAC_PI_2);
    // the ball at a quarter turn about x, turned by pi/2 about its own z: q_x(pi/2)
    // q_z(pi/2) = (s, 0, 0, s)(0, 0, s, s) = (1/2, -1/2, 1/2, 1/2); the planar pose at
    // (1, 2) turned by pi/2, moved by (vx, vy, wz) = (1, 0, pi/2): in its own frame the
    // arc (sin t / t, (1 - cos t) / t) = (2 / pi, 2 / pi), turned by pi/2: (-2 / pi, 2 / pi);
    // its angle pi; the hinge adds
    let q = [s, 0.0, 0.0, s, 1.0, 2.0, 0.0, 1.0, 0.25];
    let xi = [0.0, 0.0, t, 1.0, 0.0, t, 0.5];
    let mut out = [0.0; 9];
    m.integrate(&q, &xi, &mut out);
    let a = 2.0 / std::f64::consts::PI;
    let expected = [0.5, -0.5, 0.5, 0.5, 1.0 - a, 2.0 + a, -1.0, 0.0, 0.75];
    assert_close(&out, &expected, 1e-15, "q (+) xi");
    // a tiny turn takes the series: exp(w) = (w / 2, 1) to second order
    let xi = [1e-6, -2e-6, 3e-6, 0.0, 0.0, 0.0, 0.0];
    let q = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    m.integrate(&q, &xi, &mut out);
    assert_close(&out[..4], &[5e-7, -1e-6, 1.5e-6, 1.0], 1e-12, "small turn");
}

#[test]
fn local_rate_is_so3_dexp_inverse_to_fourth_order() {
    // dexp^-1_{-theta}(v) = v + theta x v / 2 + c theta x (theta x v), c = (1 - (t / 2)
    // cot(t / 2)) / t^2 (t = |theta|), the closed form of SO(3); the series stops at
    // theta^2 (c ~ 1/12 + t^2 / 720), so the error is O(t^4)
    let model = chain();
    let m = Manifold::new(&model, false);
    for scale in [1e-1, 5e-2] {
        let theta = [0.3 * scale, -0.5 * scale, 0.8 * scale, 0.0, 0.0, 0.0, 0.0];
        let v = [1.0, 2.0, -0.5, 0.0, 0.0, 0.0, 0.7];
        let mut k = [0.0; 7];
        m.local_rate(&theta, &v, &mut k);
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let (th, w) = ([theta[0], theta[1], theta[2]], [v[0], v[1], v[2]]);
        let t = th.iter().map(|x| x * x).sum::<f64>().sqrt();
        let c = (1.0 - 0.5 * t / (0.5 * t).tan()) / (t * t);
        let (a, b) = (cross(th, w), cross(th, cross(th, w)));
        let want: Vec<f64> = (0..3).map(|i| w[i] + 0.5 * a[i] + c * b[i]).collect();
        let err = (0..3).map(|i| (k[i] - want[i]).abs()).fold(0.0, f64::max);
        // the dropped term t^2 / 720 |theta x (theta x v)| ~ t^4 |v| / 720
        assert!(err < 2.0 * t.powi(4) * 2.5 / 720.0 && err > 0.0, "scale {scale}: error {err}");
        assert_eq!(k[6], v[6], "a hinge's rate is its velocity");
    }
}

/// The end states (q, v) of `rows` states of `model` integrated by `method`.
fn rollout(model: &Model, q0: &[f64], v0: &[f64], method: Method, steps: usize, threads: Option<usize>) -> Vec<f64> {
    let (nq, nv) = (model.nq, model.nv);
    let rows = q0.len() / nq;
    let s = Settings { method, dt: 2e-3, steps, stride: steps };
    let k = s.samples();
    let mut q = vec![0.0; rows * k * nq];
    let (mut qd, mut qdd, mut tau) = (vec![0.0; rows * k * nv], vec![0.0; rows * k * nv], vec![0.0; rows * k * nv]);
    let mut work = vec![0.0; rows * k];
    let (mut qf, mut qdf) = (vec![0.0; rows * nq], vec![0.0; rows * nv]);
    let (mut ls, mut lj, mut nf, mut nj) = (vec![0; rows], vec![0; rows], vec![0; rows], vec![0; rows]);
    let (inf, ninf) = (vec![f64::INFINITY; nv], vec![f64::NEG_INFINITY; nv]);
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
    let stop = std::sync::atomic::AtomicBool::new(false);
    assert!(simulate_manifold_until(model, false, q0, v0, Input::Zero, s, &ninf, &inf, out, threads, &stop));
    assert!(nf.iter().all(|&k| k == -1));
    qf.into_iter().chain(qdf).collect()
}

#[test]
fn lanes_and_threads_equal_single_states_and_blocks_stay_unit() {
    let model = chain();
    let (nq, nv, rows) = (model.nq, model.nv, 11);
    let (mut q0, mut v0) = (vec![], vec![]);
    for r in 0..rows {
        let x = r as f64;
        let (h, th) = (0.1 + 0.2 * x, 0.3 * x);
        let axis = [0.6, -0.48, 0.64]; // unit
        q0.extend([axis[0] * h.sin(), axis[1] * h.sin(), axis[2] * h.sin(), h.cos()]);
        q0.extend([0.1 * x, -0.05 * x, th.cos(), th.sin(), 0.2 - 0.1 * x]);
        v0.extend([0.5, -1.0 + 0.1 * x, 2.0, 0.3, -0.2, 1.5 - 0.2 * x, 0.4]);
    }
    for method in [Method::Rk4, Method::SemiImplicitEuler] {
        for threads in [Some(1), Some(2)] {
            let all = rollout(&model, &q0, &v0, method, 100, threads);
            for r in 0..rows {
                let one = rollout(&model, &q0[r * nq..(r + 1) * nq], &v0[r * nv..(r + 1) * nv], method, 100, Some(1));
                assert_eq!(&all[r * nq..(r + 1) * nq], &one[..nq], "q of state {r}");
                assert_eq!(&all[rows * nq + r * nv..rows * nq + (r + 1) * nv], &one[nq..], "v of state {r}");
                let norm = |x: &[f64]| x.iter().map(|c| c * c).sum::<f64>().sqrt();
                assert!((norm(&one[..4]) - 1.0).abs() < 1e-15, "quaternion of state {r}");
                assert!((norm(&one[6..8]) - 1.0).abs() < 1e-15, "(cos, sin) of state {r}");
            }
        }
    }
}

#[test]
fn difference_inverts_integrate() {
    // q1 = q0 (+) xi with every block's turn below pi: q1 (-) q0 = xi (the logs invert the
    // exponentials), on the chain and with a floating base; at the identity, the log of
    // a quarter turn about z is (0, 0, pi/2)
    let model = chain();
    let m = Manifold::new(&model, false);
    let s = 0.5f64.sqrt();
    let q0 = [0.1, -0.3, 0.2, (1.0f64 - 0.14).sqrt(), 1.0, 2.0, 0.6, 0.8, 0.25];
    for scale in [1.0, 1e-6] {
        let xi: Vec<f64> = [0.4, -1.1, 0.7, 0.3, -0.2, 2.5, 0.9].iter().map(|x| x * scale).collect();
        let mut q1 = [0.0; 9];
        m.integrate(&q0, &xi, &mut q1);
        let mut back = [0.0; 7];
        m.difference_lanes(&q0, &q1, &mut back);
        assert_close(&back, &xi, if scale < 1.0 { 1e-15 } else { 1e-13 }, "q1 (-) q0");
    }
    let (mut w, id) = ([0.0; 7], [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    m.difference_lanes(&id, &[0.0, 0.0, s, s, 0.0, 0.0, 1.0, 0.0, 0.0], &mut w);
    assert_close(&w[..3], &[0.0, 0.0, std::f64::consts::FRAC_PI_2], 1e-15, "quarter turn");
    let f = Manifold::new(&model, true);
    let mut qf = vec![0.3, -0.2, 1.0, 0.5, -0.5, 0.5, 0.5];
    qf.extend_from_slice(&q0);
    let xi = [0.5, 0.2, -0.3, 1.2, -0.4, 0.8, 0.4, -1.1, 0.7, 0.3, -0.2, 2.5, 0.9];
    let (mut q1, mut back) = (vec![0.0; 16], vec![0.0; 13]);
    f.integrate(&qf, &xi, &mut q1);
    f.difference_lanes(&qf, &q1, &mut back);
    assert_close(&back, &xi, 1e-13, "floating q1 (-) q0");
}

//! The floating base (`algo::floating`): identities on random trees, and the f64x4 lanes
//! equal to single states bit for bit.

use crate::common::*;
use armdyn_core::algo::floating::{aba_floating, crba_floating, rnea_floating};
use armdyn_core::{algo, batch_derivatives as bd, Data, F64x4, Model, Real};

pub(crate) fn floating_model(rng: &mut Rng, njoints: usize) -> Model {
    let mut model = random_model(rng, njoints, true);
    let inertia = random_inertia(rng);
    let com = [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)];
    model.add_base_inertia(rng.uniform(1.0, 5.0), com, inertia).expect("a valid base");
    model
}

/// (q, v, a) of one state.
pub(crate) type State = (Vec<f64>, Vec<f64>, Vec<f64>);

/// Random (q, v, a): any base pose (a unit quaternion), joints in [-3, 3].
pub(crate) fn state(rng: &mut Rng, n: usize) -> State {
    let mut q = rng.vec(7 + n, -3.0, 3.0);
    let quat = rng.vec(4, -1.0, 1.0);
    let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
    for k in 0..4 {
        q[3 + k] = quat[k] / norm;
    }
    (q, rng.vec(6 + n, -1.0, 1.0), rng.vec(6 + n, -1.0, 1.0))
}

#[test]
fn floating_identities() {
    let mut rng = Rng::new(41);
    for njoints in [1, 3, 6, 9] {
        let model = floating_model(&mut rng, njoints);
        let (n, nv) = (model.nv, model.nv + 6);
        let mut data = Data::new(&model);
        for _ in 0..4 {
            let (q, v, a) = state(&mut rng, n);
            let mut tau = vec![0.0; nv];
            rnea_floating(&model, &mut data, &q, &v, &a, &mut tau);
            let mut m = vec![0.0; nv * nv];
            crba_floating(&model, &mut data, &q, &mut m);
            let mut h = vec![0.0; nv];
            rnea_floating(&model, &mut data, &q, &v, &vec![0.0; nv], &mut h);
            // tau = M a + h
            let ma: Vec<f64> = (0..nv).map(|i| (0..nv).map(|j| m[i * nv + j] * a[j]).sum::<f64>() + h[i]).collect();
            assert_close(&ma, &tau, 1e-10, "rnea = crba a + rnea(a = 0)");
            for i in 0..nv {
                for j in 0..nv {
                    assert_eq!(m[i * nv + j], m[j * nv + i], "M symmetric");
                }
            }
            // the joint block is the fixed-base M
            let mut fixed = vec![0.0; n * n];
            algo::crba(&model, &mut data, &q[7..], &mut fixed);
            let block: Vec<f64> = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| m[(6 + i) * nv + 6 + j]).collect();
            assert_close(&block, &fixed, 1e-12, "joint block");
            let mut acc = vec![0.0; nv];
            aba_floating(&model, &mut data, &q, &v, &tau, &mut acc);
            assert_close(&acc, &a, 1e-8, "aba(rnea(a)) = a");
        }
    }
}

#[test]
fn floating_lanes_equal_single_states() {
    let mut rng = Rng::new(7);
    let model = floating_model(&mut rng, 5);
    let (n, nv) = (model.nv, model.nv + 6);
    let states: Vec<_> = (0..4).map(|_| state(&mut rng, n)).collect();
    let lanes = |pick: fn(&State) -> &Vec<f64>, len: usize| -> Vec<F64x4> {
        (0..len)
            .map(|k| {
                let mut x = F64x4::zero();
                for (l, s) in states.iter().enumerate() {
                    x.set_lane(l, pick(s)[k]);
                }
                x
            })
            .collect()
    };
    let (q4, v4, a4) = (lanes(|s| &s.0, 7 + n), lanes(|s| &s.1, nv), lanes(|s| &s.2, nv));
    let mut data4 = Data::<F64x4>::new(&model);
    let mut tau4 = vec![F64x4::zero(); nv];
    rnea_floating(&model, &mut data4, &q4, &v4, &a4, &mut tau4);
    let mut acc4 = vec![F64x4::zero(); nv];
    aba_floating(&model, &mut data4, &q4, &v4, &tau4, &mut acc4);
    let mut data = Data::new(&model);
    for (l, (q, v, a)) in states.iter().enumerate() {
        let mut tau = vec![0.0; nv];
        rnea_floating(&model, &mut data, q, v, a, &mut tau);
        let mut acc = vec![0.0; nv];
        aba_floating(&model, &mut data, q, v, &tau, &mut acc);
        for k in 0..nv {
            assert_eq!(tau4[k].lane(l).to_bits(), tau[k].to_bits(), "rnea lane {l}");
            assert_eq!(acc4[k].lane(l).to_bits(), acc[k].to_bits(), "aba lane {l}");
        }
    }
}

#[test]
fn floating_batches_equal_single_states() {
    let mut rng = Rng::new(11);
    let model = floating_model(&mut rng, 4);
    let (n, nv) = (model.nv, model.nv + 6);
    let rows = 13; // groups of lanes and leftover rows
    let states: Vec<_> = (0..rows).map(|_| state(&mut rng, n)).collect();
    let flat = |pick: fn(&State) -> &Vec<f64>| -> Vec<f64> { states.iter().flat_map(|s| pick(s).clone()).collect() };
    let (q, v, a) = (flat(|s| &s.0), flat(|s| &s.1), flat(|s| &s.2));
    let mut tau = vec![0.0; rows * nv];
    armdyn_core::batch::rnea_floating(&model, [&q, &v, &a], &mut tau, Some(2));
    let mut acc = vec![0.0; rows * nv];
    armdyn_core::batch::aba_floating(&model, [&q, &v, &tau], &mut acc, Some(2));
    let mut m = vec![0.0; rows * nv * nv];
    armdyn_core::batch::crba_floating(&model, [&q], &mut m, Some(2));
    let mut data = Data::new(&model);
    for (r, (qs, vs, as_)) in states.iter().enumerate() {
        let mut t = vec![0.0; nv];
        rnea_floating(&model, &mut data, qs, vs, as_, &mut t);
        assert_eq!(&tau[r * nv..(r + 1) * nv], &t[..], "rnea row {r}");
        let mut x = vec![0.0; nv];
        aba_floating(&model, &mut data, qs, vs, &t, &mut x);
        assert_eq!(&acc[r * nv..(r + 1) * nv], &x[..], "aba row {r}");
        let mut mm = vec![0.0; nv * nv];
        crba_floating(&model, &mut data, qs, &mut mm);
        assert_eq!(&m[r * nv * nv..(r + 1) * nv * nv], &mm[..], "crba row {r}");
    }
}

/// The end states (q, v) of `rows` floating states integrated by RK4 for `steps` steps.
fn integrate_floating(model: &Model, q0: &[f64], v0: &[f64], steps: usize, threads: Option<usize>) -> Vec<f64> {
    use armdyn_core::algo::integrate::{Input, Method, Outputs, Settings};
    use armdyn_core::algo::integrate_floating::simulate_floating_until;
    let (n, rows) = (model.nv, q0.len() / (model.nv + 7));
    let s = Settings { method: Method::Rk4, dt: 1e-3, steps, stride: steps };
    let (nq, nv, k) = (n + 7, n + 6, s.samples());
    let mut q = vec![0.0; rows * k * nq];
    let (mut qd, mut qdd, mut tau) = (vec![0.0; rows * k * nv], vec![0.0; rows * k * nv], vec![0.0; rows * k * nv]);
    let mut work = vec![0.0; rows * k];
    let (mut qf, mut qdf) = (vec![0.0; rows * nq], vec![0.0; rows * nv]);
    let (mut ls, mut lj, mut nf, mut nj) = (vec![0; rows], vec![0; rows], vec![0; rows], vec![0; rows]);
    let (inf, ninf) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n]);
    let out = Outputs {
        q: &mut q, work: &mut work, qd: &mut qd, qdd: &mut qdd, tau: &mut tau, q_final: &mut qf, qd_final: &mut qdf,
        limit_step: &mut ls, limit_joint: &mut lj, nonfinite_step: &mut nf, nonfinite_joint: &mut nj,
    };
    let stop = std::sync::atomic::AtomicBool::new(false);
    assert!(simulate_floating_until(model, q0, v0, Input::Zero, s, &ninf, &inf, out, threads, &stop));
    assert!(nf.iter().all(|&k| k == -1));
    qf.into_iter().chain(qdf).collect()
}

#[test]
fn integrate_floating_lanes_equal_single_states() {
    // 11 states: a group of 8 (or two of 4) in SIMD lanes and leftovers alone, on 1 and 2
    // threads: every state ends where it ends integrated alone, bit for bit
    let mut rng = Rng::new(43);
    let model = floating_model(&mut rng, 5);
    let (n, rows) = (model.nv, 11);
    let (mut q0, mut v0) = (vec![], vec![]);
    for _ in 0..rows {
        let (q, v, _) = state(&mut rng, n);
        q0.extend(q);
        v0.extend(v);
    }
    let (nq, nv) = (n + 7, n + 6);
    for threads in [Some(1), Some(2)] {
        let all = integrate_floating(&model, &q0, &v0, 40, threads);
        for r in 0..rows {
            let one = integrate_floating(&model, &q0[r * nq..(r + 1) * nq], &v0[r * nv..(r + 1) * nv], 40, Some(1));
            assert_eq!(&all[r * nq..(r + 1) * nq], &one[..nq], "q of state {r}");
            assert_eq!(&all[rows * nq + r * nv..rows * nq + (r + 1) * nv], &one[nq..], "v of state {r}");
        }
    }
}

#[test]
fn integrate_configuration_is_the_se3_exponential() {
    use armdyn_core::algo::integrate_floating::integrate_configuration;
    // a turn by pi/2 about z with a linear twist (1, 0, 0): the screw motion's closed
    // form, from a base at (1, 2, 3) turned pi/2 about x
    let s = 0.5f64.sqrt();
    let q = [1.0, 2.0, 3.0, s, 0.0, 0.0, s, 0.5];
    let xi = [1.0, 0.0, 0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_2, 0.25];
    let mut out = [0.0; 8];
    integrate_configuration(&q, &xi, &mut out);
    // exp: R_z(pi/2), p = V lin = (sin t / t, (1 - cos t) / t, 0) with t = pi/2; then
    // turned by R_x(pi/2): (x, y, z) -> (x, -z, y); the orientation q_x(pi/2) q_z(pi/2)
    // = (s, 0, 0, s)(0, 0, s, s) = (1/2, -1/2, 1/2, 1/2) (x y z w)
    let t = std::f64::consts::FRAC_PI_2;
    let p = [t.sin() / t, (1.0 - t.cos()) / t, 0.0];
    let expected = [1.0 + p[0], 2.0 - p[2], 3.0 + p[1], 0.5, -0.5, 0.5, 0.5, 0.75];
    assert_close(&out, &expected, 1e-15, "q (+) xi");
}

/// The floating-base derivatives (`algo::floating_derivatives`), with rotor inertia and
/// viscous friction on one joint: `dtau/da` is `crba_floating`, `M^-1 M = 1`, the `M^-1`
/// of `aba_derivatives_floating` is `minverse_floating`'s, and batches (lanes, leftover
/// rows, threads) equal single states bit for bit. (Pinocchio and finite differences:
/// `tests/test_floating_derivatives.py`.)
#[test]
fn floating_derivatives_identities_and_batches() {
    let mut rng = Rng::new(13);
    let mut model = floating_model(&mut rng, 6);
    let jd = armdyn_core::JointDynamics { armature: 0.3, viscous: 0.7, coulomb: 0.0, offset: 0.0 };
    model.set_joint_dynamics(0, jd).expect("a movable joint");
    let (n, s) = (model.nv, model.nv + 6);
    let mut data = Data::new(&model);
    let mut dd = armdyn_core::DerivData::new(&model);
    let rows = 13;
    let states: Vec<_> = (0..rows).map(|_| state(&mut rng, n)).collect();
    let mut single = vec![vec![0.0; s * s]; 7];
    let flat = |pick: fn(&State) -> &Vec<f64>| -> Vec<f64> { states.iter().flat_map(|x| pick(x).clone()).collect() };
    let (q, v, a) = (flat(|x| &x.0), flat(|x| &x.1), flat(|x| &x.2));
    let mut batch: Vec<Vec<f64>> = vec![vec![0.0; rows * s * s]; 7];
    {
        let [b0, b1, b2, b3, b4, b5, b6] = &mut batch[..] else { unreachable!() };
        bd::rnea_derivatives_floating(&model, [&q, &v, &a], None, [b0, b1, b2], Some(2));
        bd::aba_derivatives_floating(&model, [&q, &v, &a], None, [b3, b4, b5], Some(2));
        bd::minverse_floating(&model, &q, b6, Some(2));
    }
    for (r, (qs, vs, as_)) in states.iter().enumerate() {
        {
            let [o0, o1, o2, o3, o4, o5, o6] = &mut single[..] else { unreachable!() };
            algo::rnea_derivatives_floating(&model, &mut data, &mut dd, qs, vs, as_, None, o0, o1, o2);
            algo::aba_derivatives_floating(&model, &mut data, &mut dd, qs, vs, as_, None, o3, o4, o5);
            algo::minverse_floating(&model, &mut data, &mut dd, qs, o6);
        }
        for (k, (b, x)) in batch.iter().zip(&single).enumerate() {
            assert_eq!(&b[r * s * s..(r + 1) * s * s], &x[..], "output {k}, row {r}");
        }
        let mut m = vec![0.0; s * s];
        crba_floating(&model, &mut data, qs, &mut m);
        assert_close(&single[2], &m, 1e-12, "dtau/da = crba");
        assert_close(&single[5], &single[6], 1e-12, "aba_derivatives' M^-1 = minverse");
        assert_inverse(&m, &single[6], s, 1e-10, "M M^-1 = 1");
    }
}

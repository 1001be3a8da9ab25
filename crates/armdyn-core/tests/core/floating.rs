//! The floating base (`algo::floating`): identities on random trees, and the f64x4 lanes
//! equal to single states bit for bit.

use crate::common::*;
use armdyn_core::algo::floating::{aba_floating, crba_floating, rnea_floating};
use armdyn_core::{algo, batch_derivatives as bd, Data, F64x4, Model, Real};

fn floating_model(rng: &mut Rng, njoints: usize) -> Model {
    let mut model = random_model(rng, njoints, true);
    let inertia = random_inertia(rng);
    let com = [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)];
    model.add_base_inertia(rng.uniform(1.0, 5.0), com, inertia).expect("a valid base");
    model
}

/// (q, v, a) of one state.
type State = (Vec<f64>, Vec<f64>, Vec<f64>);

/// Random (q, v, a): any base pose (a unit quaternion), joints in [-3, 3].
fn state(rng: &mut Rng, n: usize) -> State {
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

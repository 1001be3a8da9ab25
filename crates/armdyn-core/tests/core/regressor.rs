//! The regressor and the joint dynamics (friction, rotor inertia, offset) on random
//! trees: `Y pi == rnea` with pi the standard parameters built here from the
//! description (not from the model's merged inertias); the identities with the joint
//! terms (`rnea = crba qdd + rnea(q, qd, 0)`, `aba(rnea) = qdd`); batch == loop, bit for bit.

use armdyn_core::{algo, batch, Data, JointDynamics, JointType, Model};
use crate::common::*;

/// Standard parameters of every description link, in the link frame (about its origin):
/// `[m, m c, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`, `I = I_c + m (c.c 1 - c c^T)`; then
/// `[Ia, Fv, Fc, offset]` per movable joint.
fn standard_parameters(joints: &[armdyn_core::JointSpec], dynamics: &[JointDynamics]) -> Vec<f64> {
    let mut pi = Vec::new();
    for j in joints {
        let (m, c, ic) = (j.mass, j.com, j.inertia);
        let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        let i = |a: usize, b: usize| ic[a][b] + m * (if a == b { cc } else { 0.0 } - c[a] * c[b]);
        pi.extend([m, m * c[0], m * c[1], m * c[2], i(0, 0), i(0, 1), i(1, 1), i(0, 2), i(1, 2), i(2, 2)]);
    }
    for d in dynamics {
        pi.extend([d.armature, d.viscous, d.coulomb, d.offset]);
    }
    pi
}

fn close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    let scale = b.iter().fold(1.0f64, |s, x| s.max(x.abs()));
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(x.is_finite() && (x - y).abs() <= tol * scale, "{what}[{k}]: {x} vs {y}");
    }
}

#[test]
fn regressor_times_parameters_is_rnea() {
    let mut checked = 0;
    for seed in 0..40u64 {
        let mut rng = Rng::new(seed);
        let count = 2 + rng.below(7);
        let joints = random_joints(&mut rng, count, seed % 2 == 1);
        let g = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0), rng.uniform(-10.0, -5.0)];
        let mut model = Model::new(&joints, g).unwrap();
        let n = model.nv;
        if n == 0 {
            continue;
        }
        let dynamics: Vec<JointDynamics> = (0..n)
            .map(|_| JointDynamics {
                armature: rng.uniform(0.0, 1.0),
                viscous: rng.uniform(0.0, 1.0),
                coulomb: rng.uniform(0.0, 1.0),
                offset: rng.uniform(-1.0, 1.0),
            })
            .collect();
        for (b, d) in dynamics.iter().enumerate() {
            model.set_joint_dynamics(b, *d).unwrap();
        }
        let pi = standard_parameters(&joints, &dynamics);
        let cols = algo::regressor_columns(&model);
        assert_eq!(cols, pi.len());
        assert_eq!(joints.iter().filter(|j| j.jtype != JointType::Fixed).count(), n);
        let mut data = Data::new(&model);
        let q = rng.vec(n, -3.0, 3.0);
        let mut qd = rng.vec(n, -2.0, 2.0);
        qd[0] = 0.0; // Coulomb friction at rest
        let qdd = rng.vec(n, -2.0, 2.0);
        let mut y = vec![0.0; n * cols];
        algo::regressor(&model, &mut data, &q, &qd, &qdd, &mut y);
        let ypi: Vec<f64> = (0..n).map(|i| (0..cols).map(|c| y[i * cols + c] * pi[c]).sum()).collect();
        let mut tau = vec![0.0; n];
        algo::rnea(&model, &mut data, &q, &qd, &qdd, &mut tau);
        close(&ypi, &tau, 1e-12, "Y pi vs rnea");
        // the joint terms: rnea = M qdd + rnea(q, qd, 0), with Ia in M
        let mut m = vec![0.0; n * n];
        algo::crba(&model, &mut data, &q, &mut m);
        let mut h = vec![0.0; n];
        algo::bias(&model, &mut data, &q, &qd, &mut h);
        let mqdd: Vec<f64> = (0..n).map(|i| (0..n).map(|j| m[i * n + j] * qdd[j]).sum::<f64>() + h[i]).collect();
        close(&mqdd, &tau, 1e-12, "M qdd + h vs rnea");
        let mut back = vec![0.0; n];
        algo::aba(&model, &mut data, &q, &qd, &tau, &mut back);
        close(&back, &qdd, 1e-9, "aba(rnea)");
        // batch == loop, bit for bit
        let rows = 11;
        let (bq, bqd, bqdd) = (rng.vec(rows * n, -3.0, 3.0), rng.vec(rows * n, -2.0, 2.0), rng.vec(rows * n, -2.0, 2.0));
        let mut out = vec![0.0; rows * n * cols];
        batch::regressor(&model, [&bq, &bqd, &bqdd], &mut out, Some(2));
        for r in 0..rows {
            let s = |a: &[f64]| a[r * n..(r + 1) * n].to_vec();
            let mut one = vec![0.0; n * cols];
            algo::regressor(&model, &mut data, &s(&bq), &s(&bqd), &s(&bqdd), &mut one);
            assert!(one.iter().zip(&out[r * n * cols..(r + 1) * n * cols]).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} models checked");
}

#[test]
fn joint_dynamics_rejects_bad_values() {
    let mut rng = Rng::new(3);
    let joints = random_joints(&mut rng, 4, false);
    let mut model = Model::new(&joints, [0.0, 0.0, -9.81]).unwrap();
    let bad = [
        JointDynamics { armature: -1.0, ..Default::default() },
        JointDynamics { viscous: f64::NAN, ..Default::default() },
        JointDynamics { coulomb: -0.1, ..Default::default() },
        JointDynamics { offset: f64::INFINITY, ..Default::default() },
    ];
    for d in bad {
        assert!(model.set_joint_dynamics(0, d).is_err(), "{d:?} accepted");
    }
    assert!(model.set_joint_dynamics(model.nv, JointDynamics::default()).is_err());
    assert!(!model.has_joint_dynamics);
    model.set_joint_dynamics(0, JointDynamics { offset: -2.0, ..Default::default() }).unwrap();
    assert!(model.has_joint_dynamics);
}

//! The derivative algorithms on random branched trees (revolute, prismatic and fixed
//! joints, arbitrary frames and axes) against central differences of the existing
//! rnea/aba/jacobian, and M Minv = I. (Pinocchio and the NumPy forward-mode oracle are
//! the other opinions, in tests/test_derivatives.py.)

use armdyn_core::algo::{self, ExternalForces, ForceFrame};
use armdyn_core::{batch_derivatives, Data, DerivData, JointDynamics, Model};
use crate::common::*;

fn cases() -> Vec<(Model, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)> {
    let mut rng = Rng::new(11);
    (0..40)
        .map(|trial| {
            let njoints = 1 + rng.below(10);
            let model = random_model(&mut rng, njoints, trial % 3 != 0);
            let n = model.nv;
            let w = rng.vec(6 * model.nlinks(), -3.0, 3.0);
            (rng.vec(n, -3.0, 3.0), rng.vec(n, -2.0, 2.0), rng.vec(n, -2.0, 2.0), w, model)
        })
        .map(|(q, qd, x, w, m)| (m, q, qd, x, w))
        .collect()
}

/// Central differences of `f` along each coordinate: column j of the (m, n) result.
fn central(f: &dyn Fn(&[f64]) -> Vec<f64>, x: &[f64]) -> Vec<f64> {
    let (n, h) = (x.len(), 1e-6);
    let m = f(x).len();
    let mut out = vec![0.0; m * n];
    for j in 0..n {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[j] += h;
        xm[j] -= h;
        let (fp, fm) = (f(&xp), f(&xm));
        for i in 0..m {
            out[i * n + j] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    out
}

#[test]
fn rnea_and_aba_derivatives_match_central_differences() {
    for (model, q, qd, x, w) in cases() {
        for ext in [None, Some(ForceFrame::Local), Some(ForceFrame::World)] {
            let e = ext.map(|frame| ExternalForces { wrenches: &w[..], frame });
            derivatives_match_differences(&model, &q, &qd, &x, e.as_ref());
        }
    }
}

/// `rnea_derivatives` and `aba_derivatives` of `model` at (q, qd, x) against central
/// differences of `rnea` / `aba` (`_ext` with the wrenches `e`), and aba_derivatives'
/// qdd against the body-frame `aba`'s. Returns aba_derivatives' M^-1 (n x n).
fn derivatives_match_differences(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    x: &[f64],
    e: Option<&ExternalForces<f64>>,
) -> Vec<f64> {
    let n = model.nv;
    let rnea = |q: &[f64], qd: &[f64], qdd: &[f64]| {
        let (mut d, mut dd, mut t) = (Data::new(model), DerivData::new(model), vec![0.0; n]);
        match e {
            Some(e) => algo::rnea_ext(model, &mut d, &mut dd, q, qd, qdd, e, &mut t),
            None => algo::rnea(model, &mut d, q, qd, qdd, &mut t),
        }
        t
    };
    let aba = |q: &[f64], qd: &[f64], tau: &[f64]| {
        let (mut d, mut dd, mut t) = (Data::new(model), DerivData::new(model), vec![0.0; n]);
        match e {
            Some(e) => algo::aba_ext(model, &mut d, &mut dd, q, qd, tau, e, &mut t),
            None => algo::aba(model, &mut d, q, qd, tau, &mut t),
        }
        t
    };
    let (mut d, mut dd) = (Data::new(model), DerivData::new(model));
    let (mut a, mut b, mut c) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
    algo::rnea_derivatives(model, &mut d, &mut dd, q, qd, x, e, &mut a, &mut b, &mut c);
    assert_close(&a, &central(&|y| rnea(y, qd, x), q), 1e-6, "dtau_dq");
    assert_close(&b, &central(&|y| rnea(q, y, x), qd), 1e-6, "dtau_dqd");
    assert_close(&c, &central(&|y| rnea(q, qd, y), x), 1e-6, "M");
    algo::aba_derivatives(model, &mut d, &mut dd, q, qd, x, e, &mut a, &mut b, &mut c);
    assert_close(&dd.qdd, &aba(q, qd, x), 1e-10, "qdd, base vs body coordinates");
    assert_close(&a, &central(&|y| aba(y, qd, x), q), 1e-6, "dqdd_dq");
    assert_close(&b, &central(&|y| aba(q, y, x), qd), 1e-6, "dqdd_dqd");
    assert_close(&c, &central(&|y| aba(q, qd, y), x), 1e-6, "Minv");
    c
}

/// Joint friction, rotor inertia and offset on every joint, with and without wrenches in
/// each frame: the articulated-body passes run in body frames (`aba`, `aba_ext`, the
/// wrenches as generalized forces) and in base coordinates (`aba_derivatives`, the
/// wrenches in the bias forces; `minverse`, no bias). Second opinions: the body-frame
/// `qdd` for the base-frame one, central differences of `rnea`/`aba` (which carry the
/// terms: `diag(Ia)` in M, `diag(Fv)` in `dtau/dqd`) for the derivatives, `crba` for M^-1.
/// Every `|qd_k| >= 0.2`, so no difference crosses the Coulomb jump at `qd_k = 0`.
#[test]
fn joint_dynamics_and_wrenches_through_both_coordinate_systems() {
    let mut rng = Rng::new(31);
    for (mut model, q, _, x, w) in cases().into_iter().step_by(2) {
        let n = model.nv;
        for b in 0..n {
            let jd = JointDynamics {
                armature: rng.uniform(0.05, 1.0),
                viscous: rng.uniform(0.05, 1.0),
                coulomb: rng.uniform(0.05, 1.0),
                offset: rng.uniform(-1.0, 1.0),
            };
            model.set_joint_dynamics(b, jd).expect("valid joint dynamics");
        }
        assert!(model.has_joint_dynamics);
        let qd: Vec<f64> = (0..n).map(|_| rng.uniform(0.2, 2.0) * if rng.below(2) == 0 { -1.0 } else { 1.0 }).collect();
        let (mut d, mut dd) = (Data::new(&model), DerivData::new(&model));
        let (mut minv, mut m) = (vec![0.0; n * n], vec![0.0; n * n]);
        algo::minverse(&model, &mut d, &mut dd, &q, &mut minv);
        algo::crba(&model, &mut d, &q, &mut m);
        assert_inverse(&m, &minv, n, 1e-10, "(M + diag(Ia)) Minv = I");
        for ext in [None, Some(ForceFrame::Local), Some(ForceFrame::World)] {
            let e = ext.map(|frame| ExternalForces { wrenches: &w[..], frame });
            let c = derivatives_match_differences(&model, &q, &qd, &x, e.as_ref());
            assert_close(&c, &minv, 1e-10, "Minv of aba_derivatives vs minverse");
        }
    }
}

#[test]
fn minverse_inverts_crba_and_gravity_derivatives_match_differences() {
    for (model, q, qd, _, _) in cases() {
        let n = model.nv;
        let (mut d, mut dd) = (Data::new(&model), DerivData::new(&model));
        let (mut minv, mut m) = (vec![0.0; n * n], vec![0.0; n * n]);
        algo::minverse(&model, &mut d, &mut dd, &q, &mut minv);
        algo::crba(&model, &mut d, &q, &mut m);
        assert_inverse(&m, &minv, n, 1e-10, "M Minv = I");
        let mut dg = vec![0.0; n * n];
        algo::gravity_derivatives(&model, &mut d, &mut dd, &q, &mut dg);
        let g = |y: &[f64]| {
            let mut out = vec![0.0; n];
            algo::gravity(&model, &mut Data::new(&model), y, &mut out);
            out
        };
        assert_close(&dg, &central(&g, &q), 1e-6, "dg/dq");
        // dJ/dt = sum_k dJ/dq_k qd_k: central differences along qd
        let link = model.nlinks() - 1;
        let mut jd = vec![0.0; 6 * n];
        algo::jacobian_dot(&model, &mut d, &q, &qd, link, &mut jd);
        let jac = |t: &[f64]| {
            let y: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + t[0] * b).collect();
            let mut out = vec![0.0; 6 * n];
            algo::jacobian(&model, &mut Data::new(&model), &y, link, &mut out);
            out
        };
        assert_close(&jd, &central(&jac, &[0.0]), 1e-6, "jacobian_dot");
    }
}

#[test]
fn batches_equal_single_calls_bitwise_with_every_kernel() {
    let mut rng = Rng::new(5);
    let model = random_model(&mut rng, 8, true);
    let (n, nl, rows) = (model.nv, model.nlinks(), 37);
    let (q, qd, x) = (rng.vec(rows * n, -3.0, 3.0), rng.vec(rows * n, -2.0, 2.0), rng.vec(rows * n, -2.0, 2.0));
    let w = rng.vec(rows * 6 * nl, -2.0, 2.0);
    for kernels in [armdyn_core::batch::Kernels::Baseline, armdyn_core::batch::Kernels::Avx2, armdyn_core::batch::Kernels::Avx512] {
        armdyn_core::batch::set_kernels(Some(kernels));
        for threads in [Some(1), Some(2)] {
            let (mut a, mut b, mut c) = (vec![0.0; rows * n * n], vec![0.0; rows * n * n], vec![0.0; rows * n * n]);
            batch_derivatives::aba_derivatives(&model, [&q, &qd, &x], Some((&w, ForceFrame::World)), [&mut a, &mut b, &mut c], threads);
            let (mut d, mut dd) = (Data::new(&model), DerivData::new(&model));
            for r in 0..rows {
                let (mut a1, mut b1, mut c1) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
                let e = ExternalForces { wrenches: &w[r * 6 * nl..(r + 1) * 6 * nl], frame: ForceFrame::World };
                let s = |v: &[f64]| v[r * n..(r + 1) * n].to_vec();
                algo::aba_derivatives(&model, &mut d, &mut dd, &s(&q), &s(&qd), &s(&x), Some(&e), &mut a1, &mut b1, &mut c1);
                let nn = n * n;
                assert!(a[r * nn..(r + 1) * nn] == a1[..] && b[r * nn..(r + 1) * nn] == b1[..] && c[r * nn..(r + 1) * nn] == c1[..], "row {r}");
            }
        }
    }
    armdyn_core::batch::set_kernels(None);
}

/// Every output entry is written on every call (chains skip the zero fill, trees keep
/// it): outputs start as NaN, the workspace has just served another state, and the
/// result must equal, bit for bit, a call on a fresh workspace into zeroed outputs; and
/// for two joints in different branches (neither supports the other) the torque of one
/// does not depend on the other's q or qd (a zero entry, exactly), nor its M entry
/// (rnea_derivatives; M^-1 couples the branches, so aba_derivatives' entries are not 0).
#[test]
fn every_entry_written_and_unrelated_pairs_zero() {
    let mut rng = Rng::new(23);
    let (mut chains, mut trees) = (0, 0);
    for (model, q, qd, x, _) in cases() {
        let n = model.nv;
        let is_chain = (0..n).all(|i| model.parent[i] == i.checked_sub(1));
        if is_chain { chains += 1 } else { trees += 1 }
        let (q0, qd0, x0) = (rng.vec(n, -3.0, 3.0), rng.vec(n, -2.0, 2.0), rng.vec(n, -2.0, 2.0));
        for aba in [false, true] {
            let run = |d: &mut Data<f64>, dd: &mut DerivData<f64>, s: [&[f64]; 3], init: f64| {
                let mut o = [vec![init; n * n], vec![init; n * n], vec![init; n * n]];
                let [a, b, c] = &mut o;
                if aba {
                    algo::aba_derivatives(&model, d, dd, s[0], s[1], s[2], None, a, b, c);
                } else {
                    algo::rnea_derivatives(&model, d, dd, s[0], s[1], s[2], None, a, b, c);
                }
                o
            };
            let (mut d, mut dd) = (Data::new(&model), DerivData::new(&model));
            run(&mut d, &mut dd, [&q0, &qd0, &x0], f64::NAN);
            let reused = run(&mut d, &mut dd, [&q, &qd, &x], f64::NAN);
            let fresh = run(&mut Data::new(&model), &mut DerivData::new(&model), [&q, &qd, &x], 0.0);
            for (k, (r, f)) in reused.iter().zip(&fresh).enumerate() {
                assert!(r.iter().all(|v| v.is_finite()), "aba {aba}, output {k}: an entry not written");
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(r), bits(f), "aba {aba}, output {k}: reused workspace differs");
                for i in 0..n {
                    for j in 0..n {
                        if !aba && !model.supports(i, j) && !model.supports(j, i) {
                            assert_eq!(r[i * n + j], 0.0, "aba {aba}, output {k}, ({i}, {j}) unrelated");
                        }
                    }
                }
            }
        }
    }
    assert!(chains > 0 && trees > 0, "chains {chains}, trees {trees}");
}

/// The dual-number derivatives (`tangent_derivatives`, written for joints of several
/// coordinates) against the analytical ones on 1-dof trees, where both apply: two
/// different algorithms, the same numbers to rounding.
#[test]
fn dual_number_derivatives_equal_the_analytical_ones() {
    use armdyn_core::algo::tangent_derivatives::{aba_derivatives_tangent, rnea_derivatives_tangent, TangentWork};
    for (model, q, qd, x, _) in cases() {
        let n = model.nv;
        let (mut data, mut dd) = (Data::new(&model), DerivData::new(&model));
        let mut w = TangentWork::new(&model, false);
        let [mut a0, mut a1, mut a2, mut b0, mut b1, mut b2] = std::array::from_fn(|_| vec![0.0; n * n]);
        algo::rnea_derivatives(&model, &mut data, &mut dd, &q, &qd, &x, None, &mut a0, &mut a1, &mut a2);
        rnea_derivatives_tangent(&model, false, &mut w, &q, &qd, &x, &mut b0, &mut b1, &mut b2);
        for (a, b, what) in [(&a0, &b0, "dtau_dq"), (&a1, &b1, "dtau_dqd"), (&a2, &b2, "M")] {
            assert_close(a, b, 1e-9, what);
        }
        algo::aba_derivatives(&model, &mut data, &mut dd, &q, &qd, &x, None, &mut a0, &mut a1, &mut a2);
        aba_derivatives_tangent(&model, false, &mut w, &q, &qd, &x, &mut b0, &mut b1, &mut b2);
        for (a, b, what) in [(&a0, &b0, "dqdd_dq"), (&a1, &b1, "dqdd_dqd"), (&a2, &b2, "Minv")] {
            assert_close(a, b, 1e-7, what);
        }
    }
}

/// The analytical derivatives of models with joints of several coordinates
/// (`multi_derivatives`: the 1-dof sweep on the parts, corrected to the tangent space)
/// against the dual-number ones (`tangent_derivatives`: the RNEA differentiated along
/// `q ⊕ ε e_m`), on random trees mixing every joint kind, fixed and floating bases.
#[test]
fn multi_dof_analytical_derivatives_equal_the_dual_number_ones() {
    use armdyn_core::algo::multi_derivatives::{aba_derivatives_multi, rnea_derivatives_multi, MultiWork};
    use armdyn_core::algo::tangent_derivatives::{aba_derivatives_tangent, rnea_derivatives_tangent, TangentWork};
    use armdyn_core::JointType;
    let mut rng = Rng::new(29);
    for trial in 0..60 {
        let count = 2 + rng.below(6);
        let mut joints = random_joints(&mut rng, count, trial % 2 == 0);
        for j in joints.iter_mut() {
            j.jtype = match rng.below(6) {
                0 => JointType::Spherical,
                1 => JointType::Planar,
                2 => JointType::Free,
                _ => j.jtype,
            };
        }
        let mut model = Model::new(&joints, [0.3, -0.5, -9.81]).expect("valid model");
        if trial % 4 == 1 {
            // rotor inertia and friction on every coordinate, the joints' parts' too
            for b in 0..model.nv {
                let jd = JointDynamics { armature: 0.2, viscous: 0.3, coulomb: 0.1, offset: 0.05 };
                model.set_joint_dynamics(b, jd).expect("valid joint dynamics");
            }
        }
        let floating = trial % 3 == 0;
        if floating {
            // a base of its own mass (without it a ball joint at the base turns with it: M singular)
            let inertia = random_inertia(&mut rng);
            model.add_base_inertia(2.0, [0.1, 0.0, -0.1], inertia).expect("valid base");
        }
        let (qb, vb) = if floating { (7, 6) } else { (0, 0) };
        let (nq, nv) = (model.nq + qb, model.nv + vb);
        let mut q = rng.vec(nq, -1.0, 1.0);
        let unit = |q: &mut [f64]| {
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            q.iter_mut().for_each(|x| *x /= norm);
        };
        if floating {
            unit(&mut q[3..7]);
        }
        for j in &model.multi {
            let (off, len) = j.kind.unit_block();
            unit(&mut q[qb + j.idx_q + off..qb + j.idx_q + off + len]);
        }
        let (v, x) = (rng.vec(nv, -2.0, 2.0), rng.vec(nv, -2.0, 2.0));
        let (mut mw, mut tw) = (MultiWork::new(&model, floating), TangentWork::new(&model, floating));
        let [mut a0, mut a1, mut a2, mut b0, mut b1, mut b2] = std::array::from_fn(|_| vec![0.0; nv * nv]);
        rnea_derivatives_multi(&model, floating, &mut mw, &q, &v, &x, None, &mut a0, &mut a1, &mut a2);
        rnea_derivatives_tangent(&model, floating, &mut tw, &q, &v, &x, &mut b0, &mut b1, &mut b2);
        for (a, b, what) in [(&a0, &b0, "dtau_dq"), (&a1, &b1, "dtau_dv"), (&a2, &b2, "M")] {
            assert_close(a, b, 1e-9, what);
        }
        aba_derivatives_multi(&model, floating, &mut mw, &q, &v, &x, None, &mut a0, &mut a1, &mut a2);
        aba_derivatives_tangent(&model, floating, &mut tw, &q, &v, &x, &mut b0, &mut b1, &mut b2);
        for (a, b, what) in [(&a0, &b0, "da_dq"), (&a1, &b1, "da_dv"), (&a2, &b2, "Minv")] {
            assert_close(a, b, 1e-7, what);
        }
    }
}

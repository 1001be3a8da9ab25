//! M^-1 (`algo/minverse.rs`): the base-frame inertia from the centre of mass against
//! Featherstone's transform of the origin-based inertia, M Minv = I on chains, trees
//! and models with massless bodies (against `crba`, an independent algorithm), the
//! same Minv from `aba_derivatives` (whose inertias come from `rnea_derivatives`'
//! velocity pass), and batches equal to single calls bit for bit on every kernel.

use armdyn_core::model::{JointSpec, JointType};
use armdyn_core::spatial::{RigidInertia, Sym3, Xform, M3, V3};
use armdyn_core::{algo, batch, batch_derivatives, Data, DerivData, Model};
use crate::common::*;

fn v3(a: [f64; 3]) -> V3<f64> {
    V3::new(a[0], a[1], a[2])
}

fn sym(a: [[f64; 3]; 3]) -> Sym3<f64> {
    Sym3 { xx: a[0][0], yy: a[1][1], zz: a[2][2], xy: a[0][1], xz: a[0][2], yz: a[1][2] }
}

fn flat(i: &RigidInertia<f64>) -> Vec<f64> {
    let s = i.ibar;
    vec![i.m, i.h.x, i.h.y, i.h.z, s.xx, s.yy, s.zz, s.xy, s.xz, s.yz]
}

#[test]
fn inertia_from_the_centre_of_mass_equals_featherstones_transform() {
    let mut rng = Rng::new(21);
    for trial in 0..200 {
        // one massless body in ten (c = 0, I_c = ibar)
        let m = if trial % 10 == 0 { 0.0 } else { rng.uniform(0.1, 5.0) };
        let c = v3([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)]);
        let c = if m == 0.0 { V3::zero() } else { c };
        let i_c = sym(random_inertia(&mut rng));
        let r = rng.rotation();
        let rot = M3::from_rows(v3(r[0]), v3(r[1]), v3(r[2]));
        let x = Xform::from_pose(&rot, v3([rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)]));
        let body = RigidInertia::from_mass_com(m, c, i_c);
        // RBDA eq. 2.66: X^T I X with I about the body origin (spatial/inertia.rs)
        let expected = body.tr_transform(&x);
        let got = RigidInertia::from_com_transformed(m, body.com(), &body.rotational_inertia_about_com(), &x);
        assert_close(&flat(&got), &flat(&expected), 1e-13, &format!("trial {trial}"));
        // diagonal i_c: the cheaper rotation
        let d = v3([rng.uniform(0.01, 0.2), rng.uniform(0.01, 0.2), rng.uniform(0.01, 0.2)]);
        let diag = Sym3 { xx: d.x, yy: d.y, zz: d.z, xy: 0.0, xz: 0.0, yz: 0.0 };
        let expected_diag = RigidInertia::from_mass_com(m, c, diag).tr_transform(&x);
        let got_diag = RigidInertia::from_com_transformed_diagonal(m, c, d, &x);
        assert_close(&flat(&got_diag), &flat(&expected_diag), 1e-13, &format!("diagonal, trial {trial}"));
        // the centre-of-mass data read back off the origin-based inertia
        assert_close(&flat(&RigidInertia::from_mass_com(m, body.com(), body.rotational_inertia_about_com())), &flat(&body), 1e-14, "round trip");
    }
}

/// `M(q) Minv(q)` against the identity, and Minv symmetric and finite.
fn check_inverse(model: &Model, q: &[f64], what: &str) {
    let n = model.nv;
    let (mut d, mut dd) = (Data::new(model), DerivData::new(model));
    let (mut minv, mut m) = (vec![f64::NAN; n * n], vec![0.0; n * n]);
    algo::minverse(model, &mut d, &mut dd, q, &mut minv);
    assert!(minv.iter().all(|x| x.is_finite()), "{what}: non-finite entry");
    algo::crba(model, &mut d, q, &mut m);
    for i in 0..n {
        for j in 0..n {
            assert_eq!(minv[i * n + j], minv[j * n + i], "{what}: not symmetric at ({i}, {j})");
        }
    }
    assert_inverse(&m, &minv, n, 1e-10, what);
}

fn link(parent: Option<usize>, jtype: JointType, mass: f64, rng: &mut Rng) -> JointSpec {
    JointSpec {
        parent,
        jtype,
        rotation: rng.rotation(),
        translation: [rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4)],
        axis: rng.unit(),
        mass,
        com: if mass == 0.0 { [0.0; 3] } else { [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)] },
        inertia: if mass == 0.0 { [[0.0; 3]; 3] } else { random_inertia(rng) },
    }
}

#[test]
fn minverse_inverts_crba_on_chains_trees_and_massless_bodies() {
    let mut rng = Rng::new(22);
    check_inverse(&Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap(), &rng.vec(6, -3.0, 3.0), "ur5");
    for trial in 0..30 {
        let nj = 1 + rng.below(12);
        let model = random_model(&mut rng, nj, trial % 2 == 0);
        let q = rng.vec(model.nv, -3.0, 3.0);
        check_inverse(&model, &q, &format!("random model {trial}"));
    }
    // massless bodies inside a chain and in a tree (links without an <inertial>), each
    // with mass below it so that M stays positive definite
    let masses = [2.0, 0.0, 1.5, 0.0, 0.0, 1.0, 0.7];
    let chain: Vec<JointSpec> = (0..7usize).map(|k| link(k.checked_sub(1), JointType::Revolute, masses[k], &mut rng)).collect();
    let model = Model::new(&chain, [0.0, 0.0, -9.81]).unwrap();
    check_inverse(&model, &rng.vec(7, -3.0, 3.0), "chain with massless bodies");
    let parents = [None, Some(0), Some(1), Some(1), Some(0), Some(4), Some(3)];
    let kinds = [JointType::Revolute, JointType::Prismatic, JointType::Revolute, JointType::Revolute, JointType::Revolute, JointType::Prismatic, JointType::Revolute];
    let masses = [1.0, 0.0, 1.2, 0.0, 0.0, 2.0, 0.5];
    let tree: Vec<JointSpec> = (0..7).map(|k| link(parents[k], kinds[k], masses[k], &mut rng)).collect();
    let model = Model::new(&tree, [0.0, 0.0, -9.81]).unwrap();
    check_inverse(&model, &rng.vec(7, -3.0, 3.0), "tree with massless bodies");
}

#[test]
fn minverse_equals_the_minv_of_aba_derivatives() {
    let mut rng = Rng::new(23);
    for trial in 0..20 {
        let nj = 1 + rng.below(10);
        let model = random_model(&mut rng, nj, trial % 2 == 1);
        let n = model.nv;
        let (q, qd, tau) = (rng.vec(n, -3.0, 3.0), rng.vec(n, -2.0, 2.0), rng.vec(n, -2.0, 2.0));
        let (mut d, mut dd) = (Data::new(&model), DerivData::new(&model));
        let (mut a, mut b, mut c, mut minv) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
        algo::aba_derivatives(&model, &mut d, &mut dd, &q, &qd, &tau, None, &mut a, &mut b, &mut c);
        algo::minverse(&model, &mut d, &mut dd, &q, &mut minv);
        assert_close(&minv, &c, 1e-12, &format!("trial {trial}"));
    }
}

#[test]
fn minverse_batches_equal_single_calls_bitwise_on_every_kernel() {
    let mut rng = Rng::new(24);
    let mut models = vec![Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap()];
    models.push(random_model(&mut rng, 9, false));
    models.push(random_model(&mut rng, 9, true));
    for model in &models {
        let (n, rows) = (model.nv, 137); // two threads above 64 rows; 137 = 17 x 8 + 1
        let q = rng.vec(rows * n, -4.0, 4.0);
        let (mut d, mut dd) = (Data::new(model), DerivData::new(model));
        let mut single = vec![0.0; rows * n * n];
        for (r, o) in single.chunks_exact_mut(n * n).enumerate() {
            algo::minverse(model, &mut d, &mut dd, &q[r * n..(r + 1) * n], o);
        }
        assert!(single.iter().all(|x| x.is_finite()));
        for kernels in [batch::Kernels::Baseline, batch::Kernels::Avx2, batch::Kernels::Avx512] {
            batch::set_kernels(Some(kernels));
            for threads in [Some(1), Some(2)] {
                let mut out = vec![f64::NAN; rows * n * n];
                batch_derivatives::minverse(model, &q, &mut out, threads);
                let bits = |a: &[f64]| a.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
                assert_eq!(bits(&out), bits(&single), "{kernels:?} {threads:?}");
            }
        }
    }
    batch::set_kernels(None);
}

#[test]
fn diagonal_inertias_are_recognised_after_the_round_trip_through_the_model() {
    // ur5_joints gives diagonal tensors about the centre of mass; the model stores them
    // about the body origin, and DerivData reads them back (off-diagonal residue ~eps)
    let ur5 = Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    let dd = DerivData::<f64>::new(&ur5);
    assert_eq!(dd.i_com_diagonal, vec![true; 6]);
    for (i, body) in ur5.inertia.iter().enumerate() {
        let spec = ur5_joints()[i].inertia;
        let i_c = dd.i_com[i];
        assert_close(&[i_c.xx, i_c.yy, i_c.zz], &[spec[0][0], spec[1][1], spec[2][2]], 1e-12, "diagonal");
        assert_close(&[dd.com[i].x, dd.com[i].y, dd.com[i].z], &ur5_joints()[i].com, 1e-14, "com");
        assert!(body.m > 0.0);
    }
    // random rotated tensors are not diagonal
    let mut rng = Rng::new(25);
    let model = random_model(&mut rng, 6, false);
    let dd = DerivData::<f64>::new(&model);
    assert!(dd.i_com_diagonal.iter().all(|&d| !d), "{:?}", dd.i_com_diagonal);
}

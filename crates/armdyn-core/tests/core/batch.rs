//! Batched results equal a loop of single calls bit for bit (SIMD lanes, leftover rows,
//! one or several threads).

use armdyn_core::{algo, algo::coriolis::CoriolisWork, batch, Data, Model};
use crate::common::*;

fn bits(a: &[f64]) -> Vec<u64> {
    a.iter().map(|x| x.to_bits()).collect()
}

/// `f(row)` for every row of the batch, concatenated.
fn looped(rows: usize, per: usize, mut f: impl FnMut(usize, &mut [f64])) -> Vec<f64> {
    let mut out = vec![0.0; rows * per];
    for (r, o) in out.chunks_exact_mut(per).enumerate() {
        f(r, o);
    }
    out
}

fn check_model(model: &Model, rows: usize, seed: u64) {
    let n = model.nv;
    let mut rng = Rng::new(seed);
    let q = rng.vec(rows * n, -4.0, 4.0);
    let qd = rng.vec(rows * n, -3.0, 3.0);
    let qdd = rng.vec(rows * n, -3.0, 3.0);
    let row = |a: &[f64], r: usize| a[r * n..(r + 1) * n].to_vec();
    let mut d = Data::new(model);
    let mut cw = CoriolisWork::new(model);

    let tau_loop = looped(rows, n, |r, o| algo::rnea(model, &mut d, &row(&q, r), &row(&qd, r), &row(&qdd, r), o));
    let qdd_loop = looped(rows, n, |r, o| algo::aba(model, &mut d, &row(&q, r), &row(&qd, r), &row(&tau_loop, r), o));
    let m_loop = looped(rows, n * n, |r, o| algo::crba(model, &mut d, &row(&q, r), o));
    let g_loop = looped(rows, n, |r, o| algo::gravity(model, &mut d, &row(&q, r), o));
    let h_loop = looped(rows, n, |r, o| algo::bias(model, &mut d, &row(&q, r), &row(&qd, r), o));
    let c_loop = looped(rows, n * n, |r, o| algo::coriolis_matrix(model, &mut d, &mut cw, &row(&q, r), &row(&qd, r), o));
    let t_loop = looped(rows, 1, |r, o| o[0] = algo::kinetic_energy(model, &mut d, &row(&q, r), &row(&qd, r)));
    let v_loop = looped(rows, 1, |r, o| o[0] = algo::potential_energy(model, &mut d, &row(&q, r)));
    let x_loop = looped(rows, model.nlinks() * 16, |r, o| algo::forward_kinematics(model, &mut d, &row(&q, r), o));
    let link = model.nlinks() - 1;
    let j_loop = looped(rows, 6 * n, |r, o| algo::jacobian(model, &mut d, &row(&q, r), link, o));

    for threads in [Some(1), Some(2), None] {
        let mut out = vec![0.0; rows * n];
        batch::rnea(model, [&q, &qd, &qdd], &mut out, threads);
        assert_eq!(bits(&out), bits(&tau_loop), "rnea {threads:?}");
        batch::aba(model, [&q, &qd, &tau_loop], &mut out, threads);
        assert_eq!(bits(&out), bits(&qdd_loop), "aba {threads:?}");
        batch::gravity(model, [&q], &mut out, threads);
        assert_eq!(bits(&out), bits(&g_loop), "gravity");
        batch::bias(model, [&q, &qd], &mut out, threads);
        assert_eq!(bits(&out), bits(&h_loop), "bias");
        let mut out = vec![0.0; rows * n * n];
        batch::crba(model, [&q], &mut out, threads);
        assert_eq!(bits(&out), bits(&m_loop), "crba");
        batch::coriolis_matrix(model, &q, &qd, &mut out, threads);
        assert_eq!(bits(&out), bits(&c_loop), "coriolis");
        let mut out = vec![0.0; rows];
        batch::kinetic_energy(model, &q, &qd, &mut out, threads);
        assert_eq!(bits(&out), bits(&t_loop), "kinetic");
        batch::potential_energy(model, &q, &mut out, threads);
        assert_eq!(bits(&out), bits(&v_loop), "potential");
        let mut out = vec![0.0; rows * model.nlinks() * 16];
        batch::forward_kinematics(model, &q, &mut out, threads);
        assert_eq!(bits(&out), bits(&x_loop), "fk");
        let mut out = vec![0.0; rows * 6 * n];
        batch::jacobian(model, &q, link, &mut out, threads);
        assert_eq!(bits(&out), bits(&j_loop), "jacobian");
    }
}

#[test]
fn batch_equals_single_calls_bitwise() {
    // Every kernel the CPU runs (AVX-512, AVX2, baseline). Other tests running
    // meanwhile may see any of them: their results must not change.
    for cap in [batch::Kernels::Avx512, batch::Kernels::Avx2, batch::Kernels::Baseline] {
        batch::set_kernels(Some(cap));
        check_all();
    }
    batch::set_kernels(None);
}

fn check_all() {
    let ur5 = Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    for rows in [0, 1, 3, 4, 7, 9, 130, 517] {
        check_model(&ur5, rows, rows as u64 + 1);
    }
    let mut rng = Rng::new(5);
    for k in 0..8 {
        let nj = 1 + rng.below(10);
        let model = random_model(&mut rng, nj, k % 2 == 0);
        check_model(&model, 301, k);
    }
}

#[test]
fn huge_angles_use_the_same_sine_in_lanes_and_alone() {
    // |q| > 1e8 takes libm's sin/cos in both paths.
    let ur5 = Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    let q: Vec<f64> = (0..24).map(|k| if k % 5 == 0 { 3.0e9 + k as f64 } else { 0.1 * k as f64 }).collect();
    let z = vec![0.0; 24];
    let mut out = vec![0.0; 24];
    batch::rnea(&ur5, [&q, &z, &z], &mut out, Some(1));
    let mut d = Data::new(&ur5);
    for r in 0..4 {
        let mut tau = vec![0.0; 6];
        algo::rnea(&ur5, &mut d, &q[6 * r..6 * r + 6], &z[..6], &z[..6], &mut tau);
        assert_eq!(bits(&tau), bits(&out[6 * r..6 * r + 6]));
    }
}

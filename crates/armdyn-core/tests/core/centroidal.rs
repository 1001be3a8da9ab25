//! Centre of mass and centroidal momentum (`algo::centroidal`) and the world-frame
//! kinematics (`algo::floating_kinematics`) against other algorithms of the core on random
//! floating trees: the CRBA's base rows are the robot's spatial momentum in the base frame,
//! so `A_G` is them turned to world axes and moved to the centre of mass; a robot flying
//! freely (the ABA with no base wrench) changes its momentum by gravity alone.

use crate::common::*;
use crate::floating::{floating_model, state};
use armdyn_core::algo::centroidal::{
    center_of_mass, centroidal_map, centroidal_map_rate, centroidal_momentum, centroidal_momentum_rate, com_jacobian,
};
use armdyn_core::algo::floating::{aba_floating, crba_floating, quaternion_rotation};
use armdyn_core::algo::floating_kinematics::{jacobian_world, kinetic_energy_world};
use armdyn_core::spatial::V3;
use armdyn_core::Data;

/// `a x b` of plain arrays.
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[test]
fn centroidal_map_is_the_crba_base_rows_moved() {
    let mut rng = Rng::new(5);
    for njoints in [1, 4, 8] {
        let model = floating_model(&mut rng, njoints);
        let nv = model.nv + 6;
        let mut data = Data::new(&model);
        for _ in 0..3 {
            let (q, v, _) = state(&mut rng, model.nv);
            let mut ag = vec![0.0; 6 * nv];
            let m = centroidal_map(&model, &mut data, &q, true, &mut ag);
            let mut mm = vec![0.0; nv * nv];
            crba_floating(&model, &mut data, &q, &mut mm);
            let r = quaternion_rotation(q[3], q[4], q[5], q[6]);
            let mut c = [0.0; 3];
            center_of_mass(&model, &mut data, &q, true, &mut c);
            // the centre of mass in base coordinates
            let cb = r.tr_mul_v(V3::new(c[0] - q[0], c[1] - q[1], c[2] - q[2])).to_array();
            let mut want = vec![0.0; 6 * nv];
            for k in 0..nv {
                let f = [mm[k], mm[nv + k], mm[2 * nv + k]];
                let n = [mm[3 * nv + k], mm[4 * nv + k], mm[5 * nv + k]];
                let cf = cross(cb, f);
                let ng = [n[0] - cf[0], n[1] - cf[1], n[2] - cf[2]];
                let (fw, nw) = (r.mul_v(V3::from_array(f)).to_array(), r.mul_v(V3::from_array(ng)).to_array());
                for i in 0..3 {
                    want[i * nv + k] = fw[i];
                    want[(3 + i) * nv + k] = nw[i];
                }
            }
            assert_close(&ag, &want, 1e-12, "A_G from the CRBA's base rows");
            let mut h = [0.0; 6];
            centroidal_momentum(&model, &mut data, &q, &v, true, &mut h);
            let agv: Vec<f64> = (0..6).map(|i| (0..nv).map(|k| ag[i * nv + k] * v[k]).sum()).collect();
            assert_close(&h, &agv, 1e-12, "h_G = A_G v");
            let mut jc = vec![0.0; 3 * nv];
            assert_eq!(com_jacobian(&model, &mut data, &q, true, &mut jc), m);
            let top: Vec<f64> = ag[..3 * nv].iter().map(|x| x / m).collect();
            assert_close(&jc, &top, 1e-12, "J_c = A_G[:3] / m");
            let t = kinetic_energy_world(&model, &mut data, &q, &v, true);
            let vmv: f64 = (0..nv).map(|i| v[i] * (0..nv).map(|k| mm[i * nv + k] * v[k]).sum::<f64>()).sum();
            assert_close(&[t], &[0.5 * vmv], 1e-12, "T = 1/2 v^T M v");
        }
    }
}

#[test]
fn free_flight_changes_momentum_by_gravity() {
    let mut rng = Rng::new(9);
    let model = floating_model(&mut rng, 6);
    let nv = model.nv + 6;
    let mut data = Data::new(&model);
    let (q, v, _) = state(&mut rng, model.nv);
    let mut tau = rng.vec(nv, -5.0, 5.0);
    tau[..6].fill(0.0);
    let mut a = vec![0.0; nv];
    aba_floating(&model, &mut data, &q, &v, &tau, &mut a);
    let mut rate = [0.0; 6];
    let m = centroidal_momentum_rate(&model, &mut data, &q, &v, &a, true, &mut rate);
    let g = model.gravity.to_array();
    assert_close(&rate, &[m * g[0], m * g[1], m * g[2], 0.0, 0.0, 0.0], 1e-9, "h_G' = [m g; 0]");
}

#[test]
fn the_base_links_jacobian_is_the_base_rotation() {
    let mut rng = Rng::new(3);
    let model = floating_model(&mut rng, 3);
    let nv = model.nv + 6;
    let (q, _, _) = state(&mut rng, model.nv);
    let mut j = vec![0.0; 6 * nv];
    jacobian_world(&model, &mut Data::new(&model), &q, true, 0, &mut j);
    let r = quaternion_rotation(q[3], q[4], q[5], q[6]);
    let mut want = vec![0.0; 6 * nv];
    for i in 0..3 {
        for k in 0..3 {
            want[i * nv + k] = r.at(i, k);
            want[(3 + i) * nv + 3 + k] = r.at(i, k);
        }
    }
    assert_close(&j, &want, 1e-15, "[R_B 0; 0 R_B], joint columns 0");
}

#[test]
fn the_map_rate_times_v_is_the_momentum_rate_at_rest() {
    let mut rng = Rng::new(13);
    for (njoints, floating) in [(5, true), (7, false)] {
        let model = floating_model(&mut rng, njoints);
        let (mut q, mut v, _) = state(&mut rng, model.nv);
        if !floating {
            q.drain(..7);
            v.drain(..6);
        }
        let nv = v.len();
        let mut data = Data::new(&model);
        let mut da = vec![0.0; 6 * nv];
        centroidal_map_rate(&model, &mut data, &q, &v, floating, &mut da);
        let mut rate = [0.0; 6];
        centroidal_momentum_rate(&model, &mut data, &q, &v, &vec![0.0; nv], floating, &mut rate);
        let dav: Vec<f64> = (0..6).map(|i| (0..nv).map(|k| da[i * nv + k] * v[k]).sum()).collect();
        assert_close(&dav, &rate, 1e-12, "A_G' v = h_G'(a = 0)");
    }
}

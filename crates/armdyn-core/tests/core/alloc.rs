//! No allocation per state: a counting global allocator around the single-state
//! algorithms (with a preallocated workspace) and the batch path.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, size: usize) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f` on this thread.
fn count(f: impl FnOnce()) -> usize {
    let before = ALLOCS.with(|c| c.get());
    f();
    ALLOCS.with(|c| c.get()) - before
}

use armdyn_core::{algo, algo::coriolis::CoriolisWork, batch, batch_derivatives, Data, DerivData, Model};
use crate::common::*;

#[test]
fn single_state_algorithms_do_not_allocate() {
    let mut rng = Rng::new(2);
    let model = random_model(&mut rng, 9, true);
    let n = model.nv;
    let (q, qd, qdd) = (rng.vec(n, -1.0, 1.0), rng.vec(n, -1.0, 1.0), rng.vec(n, -1.0, 1.0));
    let mut d = Data::new(&model);
    let mut cw = CoriolisWork::new(&model);
    let (mut v, mut m, mut x, mut j) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; 16 * model.nlinks()], vec![0.0; 6 * n]);
    let allocs = count(|| {
        for _ in 0..100 {
            algo::rnea(&model, &mut d, &q, &qd, &qdd, &mut v);
            algo::aba(&model, &mut d, &q, &qd, &qdd, &mut v);
            algo::crba(&model, &mut d, &q, &mut m);
            algo::gravity(&model, &mut d, &q, &mut v);
            algo::bias(&model, &mut d, &q, &qd, &mut v);
            algo::coriolis_matrix(&model, &mut d, &mut cw, &q, &qd, &mut m);
            std::hint::black_box(algo::kinetic_energy(&model, &mut d, &q, &qd));
            std::hint::black_box(algo::potential_energy(&model, &mut d, &q));
            algo::forward_kinematics(&model, &mut d, &q, &mut x);
            algo::jacobian(&model, &mut d, &q, model.nlinks() - 1, &mut j);
        }
    });
    assert_eq!(allocs, 0);
}

#[test]
fn batch_allocations_do_not_grow_with_the_number_of_states() {
    let model = Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    let n = model.nv;
    let run = |rows: usize| {
        let mut rng = Rng::new(1);
        let (q, qd, qdd) = (rng.vec(rows * n, -1.0, 1.0), rng.vec(rows * n, -1.0, 1.0), rng.vec(rows * n, -1.0, 1.0));
        let (mut out, mut m) = (vec![0.0; rows * n], vec![0.0; rows * n * n]);
        count(|| {
            batch::rnea(&model, [&q, &qd, &qdd], &mut out, Some(1));
            batch::aba(&model, [&q, &qd, &qdd], &mut out, Some(1));
            batch::crba(&model, [&q], &mut m, Some(1));
        })
    };
    let (small, large) = (run(5), run(5000));
    assert_eq!(small, large, "allocations: {small} for 5 states, {large} for 5000");
    // per batch call: two Data workspaces (15 vectors each) and the argument/result buffers
    assert!(small <= 3 * 32, "{small} allocations (workspaces only)");
}

#[test]
fn derivative_algorithms_do_not_allocate() {
    let mut rng = Rng::new(3);
    let model = random_model(&mut rng, 9, true);
    let (n, nl) = (model.nv, model.nlinks());
    let (q, qd, qdd) = (rng.vec(n, -1.0, 1.0), rng.vec(n, -1.0, 1.0), rng.vec(n, -1.0, 1.0));
    let w = rng.vec(6 * nl, -1.0, 1.0);
    let mut d = Data::new(&model);
    let mut dd = DerivData::new(&model);
    let (mut a, mut b, mut c, mut v, mut j) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n], vec![0.0; 6 * n]);
    let allocs = count(|| {
        for frame in [algo::ForceFrame::Local, algo::ForceFrame::World] {
            let ext = algo::ExternalForces { wrenches: &w, frame };
            for _ in 0..50 {
                algo::rnea_derivatives(&model, &mut d, &mut dd, &q, &qd, &qdd, None, &mut a, &mut b, &mut c);
                algo::rnea_derivatives(&model, &mut d, &mut dd, &q, &qd, &qdd, Some(&ext), &mut a, &mut b, &mut c);
                algo::aba_derivatives(&model, &mut d, &mut dd, &q, &qd, &qdd, None, &mut a, &mut b, &mut c);
                algo::aba_derivatives(&model, &mut d, &mut dd, &q, &qd, &qdd, Some(&ext), &mut a, &mut b, &mut c);
                algo::minverse(&model, &mut d, &mut dd, &q, &mut a);
                algo::gravity_derivatives(&model, &mut d, &mut dd, &q, &mut a);
                algo::rnea_ext(&model, &mut d, &mut dd, &q, &qd, &qdd, &ext, &mut v);
                algo::aba_ext(&model, &mut d, &mut dd, &q, &qd, &qdd, &ext, &mut v);
                algo::jacobian_dot(&model, &mut d, &q, &qd, nl - 1, &mut j);
            }
        }
    });
    assert_eq!(allocs, 0);
    // a floating base: q (7 + nv), v, a (6 + nv), (6 + nv)^2 outputs
    let s = n + 6;
    let mut qf = rng.vec(7 + n, -1.0, 1.0);
    qf[3..7].copy_from_slice(&[0.0, 0.6, 0.0, 0.8]);
    let (vf, af) = (rng.vec(s, -1.0, 1.0), rng.vec(s, -1.0, 1.0));
    let (mut a, mut b, mut c) = (vec![0.0; s * s], vec![0.0; s * s], vec![0.0; s * s]);
    let local = algo::ExternalForces { wrenches: &w, frame: algo::ForceFrame::Local };
    let allocs = count(|| {
        for _ in 0..50 {
            algo::rnea_derivatives_floating(&model, &mut d, &mut dd, &qf, &vf, &af, None, &mut a, &mut b, &mut c);
            algo::aba_derivatives_floating(&model, &mut d, &mut dd, &qf, &vf, &af, None, &mut a, &mut b, &mut c);
            let e = Some(&local);
            algo::rnea_derivatives_floating(&model, &mut d, &mut dd, &qf, &vf, &af, e, &mut a, &mut b, &mut c);
            algo::aba_derivatives_floating(&model, &mut d, &mut dd, &qf, &vf, &af, e, &mut a, &mut b, &mut c);
            algo::minverse_floating(&model, &mut d, &mut dd, &qf, &mut a);
        }
    });
    assert_eq!(allocs, 0, "floating base");
}

#[test]
fn derivative_batch_allocations_do_not_grow_with_the_number_of_states() {
    let model = Model::new(&ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    let (n, nl) = (model.nv, model.nlinks());
    let run = |rows: usize| {
        let mut rng = Rng::new(1);
        let (q, qd, qdd) = (rng.vec(rows * n, -1.0, 1.0), rng.vec(rows * n, -1.0, 1.0), rng.vec(rows * n, -1.0, 1.0));
        let w = rng.vec(rows * 6 * nl, -1.0, 1.0);
        let (mut a, mut b, mut c, mut v, mut j) =
            (vec![0.0; rows * n * n], vec![0.0; rows * n * n], vec![0.0; rows * n * n], vec![0.0; rows * n], vec![0.0; rows * 6 * n]);
        let ext = Some((&w[..], algo::ForceFrame::Local));
        count(|| {
            batch_derivatives::rnea_derivatives(&model, [&q, &qd, &qdd], None, [&mut a, &mut b, &mut c], Some(1));
            batch_derivatives::aba_derivatives(&model, [&q, &qd, &qdd], ext, [&mut a, &mut b, &mut c], Some(1));
            batch_derivatives::minverse(&model, &q, &mut a, Some(1));
            batch_derivatives::gravity_derivatives(&model, &q, &mut a, Some(1));
            batch_derivatives::rnea_ext(&model, [&q, &qd, &qdd], ext.unwrap(), &mut v, Some(1));
            batch_derivatives::jacobian_dot(&model, &q, &qd, nl - 1, &mut j, Some(1));
        })
    };
    let (small, large) = (run(5), run(5000));
    assert_eq!(small, large, "allocations: {small} for 5 states, {large} for 5000");
}

#[test]
fn world_and_centroidal_algorithms_do_not_allocate() {
    use algo::{centroidal, floating_kinematics as fk};
    let model = crate::floating::floating_model(&mut Rng::new(4), 7);
    let (q, v, a) = crate::floating::state(&mut Rng::new(5), model.nv);
    let nv = v.len();
    let mut d = Data::new(&model);
    let (mut x, mut j, mut c) = (vec![0.0; 16 * model.nlinks()], vec![0.0; 6 * nv], [0.0; 6]);
    let allocs = count(|| {
        for floating in [true, false] {
            let (q, v, a) = if floating { (&q[..], &v[..], &a[..]) } else { (&q[7..], &v[6..], &a[6..]) };
            let j = &mut j[..6 * v.len()];
            fk::forward_kinematics_world(&model, &mut d, q, floating, &mut x);
            fk::jacobian_world(&model, &mut d, q, floating, model.nlinks() - 1, j);
            std::hint::black_box(fk::kinetic_energy_world(&model, &mut d, q, v, floating));
            centroidal::center_of_mass(&model, &mut d, q, floating, &mut c[..3]);
            centroidal::com_jacobian(&model, &mut d, q, floating, &mut j[..3 * v.len()]);
            centroidal::centroidal_map(&model, &mut d, q, floating, j);
            centroidal::centroidal_map_rate(&model, &mut d, q, v, floating, j);
            centroidal::centroidal_momentum(&model, &mut d, q, v, floating, &mut c);
            centroidal::centroidal_momentum_rate(&model, &mut d, q, v, a, floating, &mut c);
        }
        std::hint::black_box(fk::potential_energy_floating(&model, &mut d, &q));
    });
    assert_eq!(allocs, 0, "the world-frame and centroidal algorithms allocate");
}

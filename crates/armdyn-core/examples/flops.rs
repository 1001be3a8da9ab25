//! Floating-point operations per call of the algorithms, counted exactly by running them
//! on a number type that counts its own arithmetic (the algorithms are generic over
//! [`Real`]), and the time per call of the same algorithms on `f64` (one state, no Python,
//! median of 15 runs of 20 000 calls). `cargo run --release --example flops` prints one
//! table for a 6 R chain with the UR5's DH frames (`tests/core/common`'s `ur5_joints`: the
//! structure, hence the counts, of the benchmark UR5) and a random 7-joint chain.
//!
//! Counted: `+ - * /` and negation (one each; no FMA is ever used), `sin_cos` apart.
//!
//! `cargo run --release --example flops -- loop KERNEL SECONDS` instead runs one batch
//! kernel (`rnea_derivatives`, `aba_derivatives`, `minverse`, `gravity_derivatives`;
//! UR5, N = 20 000, one thread) over and over for about SECONDS seconds and prints its
//! rate: a target for `perf record` / `perf stat`.

#[path = "../tests/core/common/mod.rs"]
mod common;

use armdyn_core::algo;
use armdyn_core::{Data, DerivData, Model, Real};
use std::cell::Cell;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

thread_local! {
    static FLOPS: Cell<u64> = const { Cell::new(0) };
    static SINCOS: Cell<u64> = const { Cell::new(0) };
}

fn tick() {
    FLOPS.with(|c| c.set(c.get() + 1));
}

/// An f64 that counts the operations done on it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Counted(f64);

macro_rules! op {
    ($tr:ident, $f:ident, $op:tt, $tra:ident, $fa:ident) => {
        impl $tr for Counted {
            type Output = Counted;
            fn $f(self, o: Counted) -> Counted {
                tick();
                Counted(self.0 $op o.0)
            }
        }
        impl $tra for Counted {
            fn $fa(&mut self, o: Counted) {
                *self = *self $op o;
            }
        }
    };
}
op!(Add, add, +, AddAssign, add_assign);
op!(Sub, sub, -, SubAssign, sub_assign);
op!(Mul, mul, *, MulAssign, mul_assign);
impl Div for Counted {
    type Output = Counted;
    fn div(self, o: Counted) -> Counted {
        tick();
        Counted(self.0 / o.0)
    }
}
impl Neg for Counted {
    type Output = Counted;
    fn neg(self) -> Counted {
        tick();
        Counted(-self.0)
    }
}
impl Real for Counted {
    const LANES: usize = 1;
    fn splat(x: f64) -> Self {
        Counted(x)
    }
    fn sin_cos(self) -> (Self, Self) {
        SINCOS.with(|c| c.set(c.get() + 1));
        let (s, c) = self.0.sin_cos();
        (Counted(s), Counted(c))
    }
    fn lane(self, _: usize) -> f64 {
        self.0
    }
    fn set_lane(&mut self, _: usize, x: f64) {
        self.0 = x
    }
}

/// (flops, sin_cos calls) of `f`.
fn count(f: impl FnOnce()) -> (u64, u64) {
    FLOPS.with(|c| c.set(0));
    SINCOS.with(|c| c.set(0));
    f();
    (FLOPS.with(|c| c.get()), SINCOS.with(|c| c.get()))
}

fn table(name: &str, model: &Model) {
    let n = model.nv;
    let mut rng = common::Rng::new(1);
    let v = |rng: &mut common::Rng| rng.vec(n, -1.0, 1.0).into_iter().map(Counted).collect::<Vec<_>>();
    let (q, qd, qdd) = (v(&mut rng), v(&mut rng), v(&mut rng));
    let mut d = Data::<Counted>::new(model);
    let mut dd = DerivData::<Counted>::new(model);
    let (mut a, mut b, mut c, mut t) = (vec![Counted(0.0); n * n], vec![Counted(0.0); n * n], vec![Counted(0.0); n * n], vec![Counted(0.0); n]);
    let time = |f: &mut dyn FnMut()| {
        let mut runs: Vec<f64> = (0..15)
            .map(|_| {
                let t0 = std::time::Instant::now();
                for _ in 0..20_000 {
                    f();
                }
                t0.elapsed().as_secs_f64() / 20_000.0
            })
            .collect();
        runs.sort_by(f64::total_cmp);
        runs[7]
    };
    let f = |x: &[Counted]| x.iter().map(|c| c.0).collect::<Vec<f64>>();
    let (q1, qd1, qdd1) = (f(&q), f(&qd), f(&qdd));
    let mut d1 = Data::<f64>::new(model);
    let mut dd1 = DerivData::<f64>::new(model);
    let (mut a1, mut b1, mut c1, mut t1) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n]);
    let bb = std::hint::black_box;
    let times = [
        time(&mut || algo::rnea(model, &mut d1, bb(&q1), &qd1, &qdd1, &mut t1)),
        time(&mut || algo::aba(model, &mut d1, bb(&q1), &qd1, &qdd1, &mut t1)),
        time(&mut || algo::crba(model, &mut d1, bb(&q1), &mut a1)),
        time(&mut || algo::rnea_derivatives(model, &mut d1, &mut dd1, bb(&q1), &qd1, &qdd1, None, &mut a1, &mut b1, &mut c1)),
        time(&mut || algo::aba_derivatives(model, &mut d1, &mut dd1, bb(&q1), &qd1, &qdd1, None, &mut a1, &mut b1, &mut c1)),
        time(&mut || algo::minverse(model, &mut d1, &mut dd1, bb(&q1), &mut a1)),
        time(&mut || algo::gravity_derivatives(model, &mut d1, &mut dd1, bb(&q1), &mut a1)),
    ];
    let rows: Vec<(&str, (u64, u64))> = vec![
        ("rnea", count(|| algo::rnea(model, &mut d, &q, &qd, &qdd, &mut t))),
        ("aba", count(|| algo::aba(model, &mut d, &q, &qd, &qdd, &mut t))),
        ("crba", count(|| algo::crba(model, &mut d, &q, &mut a))),
        ("rnea_derivatives", count(|| algo::rnea_derivatives(model, &mut d, &mut dd, &q, &qd, &qdd, None, &mut a, &mut b, &mut c))),
        ("aba_derivatives", count(|| algo::aba_derivatives(model, &mut d, &mut dd, &q, &qd, &qdd, None, &mut a, &mut b, &mut c))),
        ("minverse", count(|| algo::minverse(model, &mut d, &mut dd, &q, &mut a))),
        ("gravity_derivatives", count(|| algo::gravity_derivatives(model, &mut d, &mut dd, &q, &mut a))),
    ];
    println!("{name} (nv = {n}): flops per call; time per call (f64, one state, no Python)");
    for ((what, (flops, sc)), t) in rows.into_iter().zip(times) {
        println!("  {what:20} {flops:6} flops  {sc:2} sin_cos  {:8.3} us  {:5.2} Gflop/s", t * 1e6, flops as f64 / t / 1e9);
    }
}

/// Batch rate on one thread (SIMD lanes, no Python): N = 20 000 states, median of 7 runs.
fn batch_table(name: &str, model: &Model) {
    use armdyn_core::batch_derivatives as bd;
    let (n, rows) = (model.nv, 20_000);
    let mut rng = common::Rng::new(2);
    let (q, qd, x) = (rng.vec(rows * n, -3.0, 3.0), rng.vec(rows * n, -1.0, 1.0), rng.vec(rows * n, -1.0, 1.0));
    let (mut a, mut b, mut c) = (vec![0.0; rows * n * n], vec![0.0; rows * n * n], vec![0.0; rows * n * n]);
    let mut time = |f: &mut dyn FnMut(&mut [f64], &mut [f64], &mut [f64])| {
        let mut runs: Vec<f64> = (0..7)
            .map(|_| {
                let t0 = std::time::Instant::now();
                f(&mut a, &mut b, &mut c);
                t0.elapsed().as_secs_f64()
            })
            .collect();
        runs.sort_by(f64::total_cmp);
        rows as f64 / runs[3] / 1e6
    };
    println!("{name}: batch of {rows} states, 1 thread, M states/s (median of 7)");
    let r = time(&mut |a, b, c| bd::rnea_derivatives(model, [&q, &qd, &x], None, [a, b, c], Some(1)));
    println!("  rnea_derivatives     {r:6.2}");
    let r = time(&mut |a, b, c| bd::aba_derivatives(model, [&q, &qd, &x], None, [a, b, c], Some(1)));
    println!("  aba_derivatives      {r:6.2}");
    let r = time(&mut |a, _, _| bd::minverse(model, &q, a, Some(1)));
    println!("  minverse             {r:6.2}");
    let r = time(&mut |a, _, _| bd::gravity_derivatives(model, &q, a, Some(1)));
    println!("  gravity_derivatives  {r:6.2}");
}

/// The `loop KERNEL SECONDS` mode (see the module docs).
fn batch_loop(kernel: &str, seconds: f64) {
    use armdyn_core::batch_derivatives as bd;
    let model = Model::new(&common::ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    let (n, rows) = (model.nv, 20_000);
    let mut rng = common::Rng::new(2);
    let (q, qd, x) = (rng.vec(rows * n, -3.0, 3.0), rng.vec(rows * n, -1.0, 1.0), rng.vec(rows * n, -1.0, 1.0));
    let (mut a, mut b, mut c) = (vec![0.0; rows * n * n], vec![0.0; rows * n * n], vec![0.0; rows * n * n]);
    let mut run: Box<dyn FnMut()> = match kernel {
        "rnea_derivatives" => Box::new(|| bd::rnea_derivatives(&model, [&q, &qd, &x], None, [&mut a, &mut b, &mut c], Some(1))),
        "aba_derivatives" => Box::new(|| bd::aba_derivatives(&model, [&q, &qd, &x], None, [&mut a, &mut b, &mut c], Some(1))),
        "minverse" => Box::new(|| bd::minverse(&model, &q, &mut a, Some(1))),
        "gravity_derivatives" => Box::new(|| bd::gravity_derivatives(&model, &q, &mut a, Some(1))),
        _ => {
            eprintln!("flops: unknown kernel {kernel:?}");
            std::process::exit(2);
        }
    };
    let t0 = std::time::Instant::now();
    let mut calls = 0;
    while t0.elapsed().as_secs_f64() < seconds {
        run();
        calls += 1;
    }
    let rate = (calls * rows) as f64 / t0.elapsed().as_secs_f64() / 1e6;
    println!("UR5 {kernel}: {calls} batches of {rows}, 1 thread, {rate:.2} M states/s");
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 4 && args[1] == "loop" {
        let seconds = args[3].parse().unwrap_or_else(|_| {
            eprintln!("flops: SECONDS must be a number, got {:?}", args[3]);
            std::process::exit(2)
        });
        batch_loop(&args[2], seconds);
        return;
    }
    let ur5 = Model::new(&common::ur5_joints(), [0.0, 0.0, -9.81]).unwrap();
    table("UR5", &ur5);
    batch_table("UR5", &ur5);
    let mut rng = common::Rng::new(4);
    let chain = common::random_model(&mut rng, 7, false);
    table("random 7-joint chain", &chain);
}

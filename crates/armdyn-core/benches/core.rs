//! Timing of the core without Python: `cargo bench -p armdyn-core` (a plain harness:
//! best of several repeats, ns per state). UR5 from standard DH parameters.

use armdyn_core::algo::kinematics::update_xup;
use armdyn_core::{algo, batch, Data, F64x4, JointSpec, JointType, Model, Real};
use std::hint::black_box;
use std::time::Instant;

fn ur5() -> Model {
    let d = [0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823];
    let a = [0.0, -0.425, -0.39225, 0.0, 0.0, 0.0];
    let alpha = [std::f64::consts::FRAC_PI_2, 0.0, 0.0, std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2, 0.0];
    let mass = [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879];
    let joints: Vec<JointSpec> = (0..6)
        .map(|i| {
            let (tr, al) = if i == 0 { ([0.0; 3], 0.0) } else { ([a[i - 1], 0.0, d[i - 1]], alpha[i - 1]) };
            let (s, c) = f64::sin_cos(al);
            let (m, r) = (mass[i], 0.05 + 0.01 * i as f64);
            JointSpec {
                parent: if i == 0 { None } else { Some(i - 1) },
                jtype: JointType::Revolute,
                rotation: [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
                translation: tr,
                axis: [0.0, 0.0, 1.0],
                mass: m,
                com: [0.01 * i as f64, -0.02, 0.03],
                inertia: [[m * r * r, 0.0, 0.0], [0.0, m * r * r, 0.0], [0.0, 0.0, 0.5 * m * r * r]],
            }
        })
        .collect();
    Model::new(&joints, [0.0, 0.0, -9.81]).unwrap()
}

/// Time this thread has spent on a CPU (ns), from Linux's schedstat; `None` elsewhere.
/// On a shared machine it is steadier than wall time for single-threaded runs.
fn on_cpu_ns() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Best time per repetition over 7 runs of `reps` repetitions, in ns: on-CPU time of
/// this thread when `cpu` (single-threaded code), else wall time.
fn best_ns_of(cpu: bool, reps: usize, mut f: impl FnMut()) -> f64 {
    (0..7)
        .map(|_| {
            let (t, c) = (Instant::now(), on_cpu_ns());
            for _ in 0..reps {
                f();
            }
            match (cpu, c, on_cpu_ns()) {
                (true, Some(c0), Some(c1)) => (c1 - c0) / reps as f64,
                _ => t.elapsed().as_nanos() as f64 / reps as f64,
            }
        })
        .fold(f64::INFINITY, f64::min)
}

fn best_ns(reps: usize, f: impl FnMut()) -> f64 {
    best_ns_of(true, reps, f)
}

fn main() {
    let model = ur5();
    let n = model.nv;
    let mut d = Data::new(&model);
    let (q, qd, qdd) = (vec![0.3; n], vec![-0.2; n], vec![0.5; n]);
    let (mut out, mut m) = (vec![0.0; n], vec![0.0; n * n]);
    println!("UR5, one state (ns/call, on-CPU time)");
    let t = best_ns(200_000, || algo::rnea(&model, &mut d, black_box(&q), &qd, &qdd, &mut out));
    println!("  rnea {t:8.1}");
    let t = best_ns(200_000, || algo::crba(&model, &mut d, black_box(&q), &mut m));
    println!("  crba {t:8.1}");
    let t = best_ns(200_000, || algo::aba(&model, &mut d, black_box(&q), &qd, &qdd, &mut out));
    println!("  aba  {t:8.1}");

    // Where the time of a 4-lane step goes (baseline SSE2 build of the lane code; the
    // batch kernels themselves may run AVX2): the joint transforms (sin/cos included)
    // against whole algorithms.
    let mut d4 = Data::<F64x4>::new(&model);
    let q4 = vec![F64x4([0.3, -1.2, 2.0, 0.7]); n];
    let (mut o4, mut m4) = (vec![F64x4::default(); n], vec![F64x4::default(); n * n]);
    println!("UR5, four states in lanes, baseline build (ns per 4 states, on-CPU time)");
    let t = best_ns(200_000, || {
        for x in black_box(&q4) {
            black_box(x.sin_cos());
        }
    });
    println!("  sin_cos x nv    {t:8.1}");
    let t = best_ns(200_000, || update_xup(&model, &mut d4, black_box(&q4)));
    println!("  xup (all)       {t:8.1}");
    let t = best_ns(200_000, || algo::rnea(&model, &mut d4, black_box(&q4), &q4, &q4, &mut o4));
    println!("  rnea            {t:8.1}");
    let t = best_ns(200_000, || algo::crba(&model, &mut d4, black_box(&q4), &mut m4));
    println!("  crba            {t:8.1}");
    let t = best_ns(200_000, || algo::aba(&model, &mut d4, black_box(&q4), &q4, &q4, &mut o4));
    println!("  aba             {t:8.1}");

    let rows = 100_000;
    let gen = |seed: u64| -> Vec<f64> {
        let mut x = seed;
        (0..rows * n)
            .map(|_| {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((x >> 11) as f64 / (1u64 << 53) as f64) * 6.0 - 3.0
            })
            .collect()
    };
    let (bq, bqd, bqdd) = (gen(1), gen(2), gen(3));
    let mut bout = vec![0.0; rows * n];
    let mut bm = vec![0.0; rows * n * n];
    for cap in [batch::Kernels::Baseline, batch::Kernels::Avx2, batch::Kernels::Avx512] {
        batch::set_kernels(Some(cap));
        let what = format!("{:?}", batch::kernels());
        let t = best_ns_of(true, 3, || batch::rnea(&model, [&bq, &bqd, &bqdd], &mut bout, Some(1))) / rows as f64;
        let t2 = best_ns_of(true, 3, || batch::aba(&model, [&bq, &bqd, &bqdd], &mut bout, Some(1))) / rows as f64;
        let t3 = best_ns_of(true, 3, || batch::crba(&model, [&bq], &mut bm, Some(1))) / rows as f64;
        println!("UR5 batch, 1 thread, {what} kernels (ns/state): rnea {t:6.1}, aba {t2:6.1}, crba {t3:6.1}");
    }
    batch::set_kernels(None);
    for threads in [1, 2] {
        let what = if threads == 1 { "on-CPU time" } else { "wall time" };
        println!("UR5, batch of {rows}, {threads} thread(s) (ns/state, M states/s; {what})");
        let t = best_ns_of(threads == 1, 3, || batch::rnea(&model, [&bq, &bqd, &bqdd], &mut bout, Some(threads))) / rows as f64;
        println!("  rnea {t:8.1} {:8.2}", 1e3 / t);
        let t = best_ns_of(threads == 1, 3, || batch::crba(&model, [&bq], &mut bm, Some(threads))) / rows as f64;
        println!("  crba {t:8.1} {:8.2}", 1e3 / t);
        let t = best_ns_of(threads == 1, 3, || batch::aba(&model, [&bq, &bqd, &bqdd], &mut bout, Some(threads))) / rows as f64;
        println!("  aba  {t:8.1} {:8.2}", 1e3 / t);
    }
}

//! M^-1 alone, on the UR5 (6 R) and the iiwa14 (7 R, the frames and inertias of
//! `python/armdyn/robots/iiwa14.urdf`): time per call on one `f64` state (median of 15 x
//! 20 000 calls) and the one-thread batch rate (N = 20 000 states into a preallocated
//! output, SIMD lanes; median of 15 runs), for before/after comparisons of
//! `algo/minverse.rs`. `cargo run --release -p armdyn-core --example minverse_rate`
//! (`examples/flops.rs` counts the flops). An argument `batch ARM` (ARM: ur5 or
//! iiwa14) runs only that arm's batch loop, 100 x 20 000 states, for `perf record`
//! (`batch ARM ROWS`: 2e6 / ROWS batches of ROWS states).

#[path = "../tests/core/common/mod.rs"]
mod common;

use armdyn_core::model::{JointSpec, JointType};
use armdyn_core::{algo, batch_derivatives, Data, DerivData, Model};

/// URDF `rpy` as a rotation matrix `Rz(yaw) Ry(pitch) Rx(roll)` (row-major).
fn rpy(r: f64, p: f64, y: f64) -> [[f64; 3]; 3] {
    let (sr, cr) = r.sin_cos();
    let (sp, cp) = p.sin_cos();
    let (sy, cy) = y.sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// The iiwa14's 7 revolute joints, copied from `python/armdyn/robots/iiwa14.urdf`
/// (base link and fixed tool frame left out: they do not change M^-1).
fn iiwa14_joints() -> Vec<JointSpec> {
    use std::f64::consts::{FRAC_PI_2 as H, PI};
    // (origin rpy, origin xyz, mass, com, diagonal inertia) per joint / child link
    type Row = ([f64; 3], [f64; 3], f64, [f64; 3], [f64; 3]);
    let rows: [Row; 7] = [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 0.1575], 5.76, [0.0, -0.03, 0.12], [0.033, 0.0333, 0.0123]),
        ([H, 0.0, PI], [0.0, 0.0, 0.2025], 6.35, [0.0003, 0.059, 0.042], [0.0305, 0.0304, 0.011]),
        ([H, 0.0, PI], [0.0, 0.2045, 0.0], 3.5, [0.0, 0.03, 0.13], [0.025, 0.0238, 0.0076]),
        ([H, 0.0, 0.0], [0.0, 0.0, 0.2155], 3.5, [0.0, 0.067, 0.034], [0.017, 0.0164, 0.006]),
        ([-H, PI, 0.0], [0.0, 0.1845, 0.0], 3.5, [0.0001, 0.021, 0.076], [0.01, 0.0087, 0.00449]),
        ([H, 0.0, 0.0], [0.0, 0.0, 0.2155], 1.8, [0.0, 0.0006, 0.0004], [0.0049, 0.0047, 0.0036]),
        ([-H, PI, 0.0], [0.0, 0.081, 0.0], 1.2, [0.0, 0.0, 0.02], [0.001, 0.001, 0.001]),
    ];
    rows.iter()
        .enumerate()
        .map(|(i, &(o, t, mass, com, d))| JointSpec {
            parent: i.checked_sub(1),
            jtype: JointType::Revolute,
            rotation: rpy(o[0], o[1], o[2]),
            translation: t,
            axis: [0.0, 0.0, 1.0],
            mass,
            com,
            inertia: [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]],
        })
        .collect()
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn report(name: &str, model: &Model) {
    let n = model.nv;
    let mut rng = common::Rng::new(3);
    let q1 = rng.vec(n, -3.0, 3.0);
    let (mut d, mut dd, mut m) = (Data::new(model), DerivData::new(model), vec![0.0; n * n]);
    let per_call = median(
        (0..15)
            .map(|_| {
                let t0 = std::time::Instant::now();
                for _ in 0..20_000 {
                    algo::minverse(model, &mut d, &mut dd, std::hint::black_box(&q1), &mut m);
                }
                t0.elapsed().as_secs_f64() / 20_000.0
            })
            .collect(),
    );
    let rows = 20_000;
    let q = rng.vec(rows * n, -3.0, 3.0);
    let mut out = vec![0.0; rows * n * n];
    let rate = median(
        (0..15)
            .map(|_| {
                let t0 = std::time::Instant::now();
                batch_derivatives::minverse(model, &q, &mut out, Some(1));
                rows as f64 / t0.elapsed().as_secs_f64() / 1e6
            })
            .collect(),
    );
    assert!(out.iter().all(|x| x.is_finite()), "non-finite M^-1 entry");
    println!("{name:8} nv = {n}  minverse  {:7.3} us per call (f64)  batch 1 thread {rate:6.2} M states/s", per_call * 1e6);
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() >= 3 && args[1] == "batch" {
        let joints = if args[2] == "ur5" { common::ur5_joints() } else { iiwa14_joints() };
        let model = Model::new(&joints, [0.0, 0.0, -9.81]).unwrap();
        // optional third argument: rows per batch (2e6 states in all)
        let rows: usize = args.get(3).map_or(20_000, |r| r.parse().expect("rows"));
        let n = model.nv;
        let q = common::Rng::new(3).vec(rows * n, -3.0, 3.0);
        let mut out = vec![0.0; rows * n * n];
        for _ in 0..2_000_000 / rows {
            batch_derivatives::minverse(&model, &q, &mut out, Some(1));
        }
        assert!(out.iter().all(|x| x.is_finite()), "non-finite M^-1 entry");
        return;
    }
    report("UR5", &Model::new(&common::ur5_joints(), [0.0, 0.0, -9.81]).unwrap());
    report("iiwa14", &Model::new(&iiwa14_joints(), [0.0, 0.0, -9.81]).unwrap());
}

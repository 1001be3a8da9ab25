//! Many states at once: row `k` of each `(N, nv)` input is one state, row `k` of the
//! output its result (same order as a loop of single calls, and bit-for-bit equal).
//!
//! Rows are split into chunks that rayon spreads over the threads; each chunk gets its
//! own workspace (allocated once per chunk, never per state). Inside a chunk `rnea`,
//! `aba`, `crba`, `gravity` and `bias` run several states per step in SIMD lanes: the
//! algorithms are generic over the lane type ([`Real`]), so a lane performs exactly the
//! operations of a single call. Which kernels run is decided at run time ([`kernels`]):
//!
//! * AVX-512F CPUs: 8 states per step ([`F64x8`], one 512-bit register);
//! * AVX2 CPUs: 4 states per step ([`F64x4`], one 256-bit register);
//! * any other x86-64: one state per step (the scalar path, see [`BaselineLanes`]);
//! * other architectures: 4 states per step compiled for the baseline ([`F64x4`]).
//!
//! FMA is never used (Rust does not contract `a * b + c`), which keeps every kernel's
//! bits identical to the scalar path. No `-C target-cpu` is needed: the shipped build
//! runs on any x86-64 and picks the widest kernels the CPU runs.

use crate::algo;
use crate::algo::coriolis::CoriolisWork;
use crate::data::Data;
use crate::model::Model;
use crate::real::{F64x4, F64x8, Real};
use rayon::prelude::*;
use std::any::Any;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, Mutex};

/// The SIMD kernels of the batch path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernels {
    /// 4 lanes, compiled for the target's baseline features.
    Baseline,
    /// 4 lanes, compiled for AVX2.
    Avx2,
    /// 8 lanes, compiled for AVX-512F.
    Avx512,
}

/// The lane type of the baseline kernels.
///
/// On x86-64 one state at a time: every x86-64 CPU since 2013 has AVX2, and a third
/// copy of every lane kernel (`F64x4` in SSE2 registers) would cost compile time and
/// binary size for CPUs that hardly exist. `f64` is the scalar path, compiled
/// anyway (the leftover rows of every batch), so this adds no code. Elsewhere
/// (aarch64: NEON) four lanes, the only lane kernels compiled there.
#[cfg(target_arch = "x86_64")]
pub(crate) type BaselineLanes = f64;
#[cfg(not(target_arch = "x86_64"))]
pub(crate) type BaselineLanes = F64x4;

/// 0: not decided yet, else `1 + Kernels as u8`.
static KERNELS: AtomicU8 = AtomicU8::new(0);

/// The kernels that run: the widest the CPU supports, capped by the environment
/// variable `ARMDYN_SIMD` (`baseline`, `avx2`, `avx512`) or by [`set_kernels`].
pub fn kernels() -> Kernels {
    const ALL: [Kernels; 3] = [Kernels::Baseline, Kernels::Avx2, Kernels::Avx512];
    match KERNELS.load(Ordering::Relaxed) {
        k @ 1..=3 => ALL[k as usize - 1],
        _ => {
            #[cfg(target_arch = "x86_64")]
            let best = if std::is_x86_feature_detected!("avx512f") {
                Kernels::Avx512
            } else if std::is_x86_feature_detected!("avx2") {
                Kernels::Avx2
            } else {
                Kernels::Baseline
            };
            #[cfg(not(target_arch = "x86_64"))]
            let best = Kernels::Baseline;
            let cap = match std::env::var("ARMDYN_SIMD").as_deref() {
                Ok("baseline") => Kernels::Baseline,
                Ok("avx2") => Kernels::Avx2,
                _ => Kernels::Avx512,
            };
            let k = best.min_with(cap);
            KERNELS.store(1 + k as u8, Ordering::Relaxed);
            k
        }
    }
}

impl Kernels {
    fn min_with(self, cap: Kernels) -> Kernels {
        if (cap as u8) < (self as u8) {
            cap
        } else {
            self
        }
    }
}

/// Use at most `cap` (`None`: detect again). Results are bit-for-bit the same with any
/// kernels; this exists to test and time that.
pub fn set_kernels(cap: Option<Kernels>) {
    KERNELS.store(0, Ordering::Relaxed);
    if let Some(cap) = cap {
        let k = kernels().min_with(cap);
        KERNELS.store(1 + k as u8, Ordering::Relaxed);
    }
}

/// Rows below which a batch runs on the calling thread (spawning costs more).
const MIN_PARALLEL_ROWS: usize = 64;

/// The largest thread count a batch accepts: `threads = Some(n)` runs on
/// `min(n, MAX_THREADS)` threads (the Python bindings refuse larger counts).
pub const MAX_THREADS: usize = 256;

/// The one extra rayon pool, for counts above the global pool's size: built when a
/// larger count than it has is first asked for, grown (replaced) only then, so the
/// number of threads ever started is bounded by the largest count asked for plus the
/// global pool, whatever mix of counts is requested. `None` if the pool cannot be
/// built (e.g. the OS refuses threads): the caller falls back to the global pool.
fn pool_of_at_least(n: usize) -> Option<Arc<rayon::ThreadPool>> {
    static POOL: Mutex<Option<Arc<rayon::ThreadPool>>> = Mutex::new(None);
    let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(p) = pool.as_ref().filter(|p| p.current_num_threads() >= n) {
        return Some(p.clone());
    }
    let built = Arc::new(rayon::ThreadPoolBuilder::new().num_threads(n).build().ok()?);
    *pool = Some(built.clone());
    Some(built)
}

/// Run `run` with `n` threads' worth of pool: rayon's global pool when it is big enough,
/// else the shared larger pool of [`pool_of_at_least`]; the global pool if no pool can be
/// built (never a panic). The batch drivers that split work themselves
/// (derivatives, integration) use this. `run` is a trait object so that rayon's
/// `install` is compiled once, not once per caller.
pub(crate) fn install(n: usize, run: &mut (dyn FnMut() + Send)) {
    let pool = if n <= rayon::current_num_threads() { None } else { pool_of_at_least(n) };
    match pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
}

/// The number of threads `threads` means: `None` = all cores (rayon's global pool),
/// `Some(n)` = `n` clamped to `1..=MAX_THREADS`.
pub fn thread_count(threads: Option<usize>) -> usize {
    threads.unwrap_or_else(rayon::current_num_threads).clamp(1, MAX_THREADS)
}

/// Run `body(workspace, first_row, out_chunks)` over chunks of `rows` rows. Output `k`
/// has `per_row[k]` values per row (0 for an unused slot); each chunk gets the same rows
/// of every output. Chunks start at multiples of 8 rows (whole SIMD groups of 4 or 8),
/// one workspace per task, never per state. The one driver of every batch here and in
/// `batch_derivatives.rs`, whatever the number of outputs `R`.
///
/// `threads = None`: the chunks go to rayon's global pool (work stealing). `Some(n)`:
/// the chunks are dealt round-robin to `n` tasks, each running its chunks in turn, so at
/// most `n` threads work whatever pool runs them (the global pool when it is big enough,
/// else [`pool_of_at_least`]).
pub(crate) fn par_rows<const R: usize, W, M, B>(
    rows: usize,
    outs: [&mut [f64]; R],
    per_row: [usize; R],
    threads: Option<usize>,
    make: M,
    body: B,
) where
    W: Send + 'static,
    M: Fn() -> W + Sync + Send,
    B: Fn(&mut W, usize, [&mut [f64]; R]) + Sync + Send,
{
    for k in 0..R {
        assert_eq!(outs[k].len(), rows * per_row[k], "output size");
    }
    let nthreads = thread_count(threads);
    if nthreads == 1 || rows < MIN_PARALLEL_ROWS || per_row.iter().all(|&p| p == 0) {
        body(&mut make(), 0, outs);
        return;
    }
    schedule(rows, outs, per_row, threads, nthreads, &Job { make, body });
}

/// A batch's work with its workspace type erased: what [`schedule`] runs.
trait Chunks<const R: usize>: Sync {
    fn workspace(&self) -> Box<dyn Any + Send>;
    fn run(&self, w: &mut (dyn Any + Send), first: usize, outs: [&mut [f64]; R]);
}

struct Job<M, B> {
    make: M,
    body: B,
}

impl<const R: usize, W, M, B> Chunks<R> for Job<M, B>
where
    W: Send + 'static,
    M: Fn() -> W + Sync,
    B: Fn(&mut W, usize, [&mut [f64]; R]) + Sync,
{
    fn workspace(&self) -> Box<dyn Any + Send> {
        Box::new((self.make)())
    }

    fn run(&self, w: &mut (dyn Any + Send), first: usize, outs: [&mut [f64]; R]) {
        let w = w.downcast_mut::<W>().expect("the workspace of this job");
        (self.body)(w, first, outs)
    }
}

/// The parallel part of [`par_rows`]. Generic only over the number of outputs: rayon's
/// iterator and job types, instantiated here once per `R`, were half of the core's
/// LLVM IR when every kernel and lane width instantiated them for its own closures.
fn schedule<const R: usize>(
    rows: usize,
    outs: [&mut [f64]; R],
    per_row: [usize; R],
    threads: Option<usize>,
    nthreads: usize,
    job: &dyn Chunks<R>,
) {
    // ~8 chunks per thread balance the load when cores are shared.
    let chunk_rows = rows.div_ceil(8 * nthreads).max(32).next_multiple_of(8);
    let mut rest = outs;
    let mut pieces = Vec::with_capacity(rows.div_ceil(chunk_rows));
    let mut first = 0;
    while first < rows {
        let take = chunk_rows.min(rows - first);
        let heads: [&mut [f64]; R] = std::array::from_fn(|k| {
            let (h, t) = std::mem::take(&mut rest[k]).split_at_mut(take * per_row[k]);
            rest[k] = t;
            h
        });
        pieces.push((first, heads));
        first += take;
    }
    if threads.is_none() {
        pieces.into_par_iter().for_each_init(|| job.workspace(), |w, (first, o)| job.run(&mut **w, first, o));
        return;
    }
    let mut tasks: Vec<Vec<_>> = (0..nthreads).map(|_| Vec::new()).collect();
    for (k, piece) in pieces.into_iter().enumerate() {
        tasks[k % nthreads].push(piece);
    }
    let mut tasks = Some(tasks);
    install(nthreads, &mut || {
        tasks.take().expect("install runs this once").into_par_iter().for_each(|task| {
            let mut w = job.workspace();
            for (first, o) in task {
                job.run(&mut *w, first, o);
            }
        })
    });
}

/// Workspace of a chunk: a scalar one for the leftover rows, an `L`-lane one, and the
/// lane-transposed arguments/results of one group of rows.
pub struct Work<L> {
    pub d1: Data<f64>,
    pub dl: Data<L>,
    args: [Vec<L>; 3],
    res: Vec<L>,
}

impl<L: Real> Work<L> {
    pub fn new(model: &Model) -> Self {
        let n = model.nv;
        // the longest argument: a floating base's q (7 + nq)
        let arg = model.nq.max(n) + algo::floating::NQ_BASE;
        let nv = n + algo::floating::NV_BASE;
        Work {
            d1: Data::new(model),
            dl: Data::new(model),
            args: [vec![L::zero(); arg], vec![L::zero(); arg], vec![L::zero(); arg]],
            // the largest per-state output: M (n x n, or nv x nv with a floating base) or
            // the regressor (n x columns)
            res: vec![L::zero(); (nv * nv).max(n * algo::regressor_columns(model))],
        }
    }
}

/// Defines a batched lane kernel `$name` from a call `$call` generic over the lane type
/// `T` (`f64` for one state, `F64x4`/`F64x8` for a group), and its AVX2/AVX-512
/// instantiations. Each argument row is `nv` long unless `widths` says otherwise (a
/// floating base's q and v).
macro_rules! lanes_kernel {
    ($(#[$doc:meta])* $name:ident, nargs = $nargs:literal, out = |$m:ident| $out:expr,
     |$model:ident, $data:ident, $a:ident, $o:ident| $call:expr) => {
        lanes_kernel!($(#[$doc])* $name, nargs = $nargs, widths = |m| [m.nq, m.nv, m.nv], out = |$m| $out,
                      |$model, $data, $a, $o| $call);
    };
    ($(#[$doc:meta])* $name:ident, nargs = $nargs:literal, widths = |$wm:ident| $widths:expr,
     out = |$m:ident| $out:expr, |$model:ident, $data:ident, $a:ident, $o:ident| $call:expr) => {
        $(#[$doc])*
        pub fn $name(model: &Model, args: [&[f64]; $nargs], out: &mut [f64], threads: Option<usize>) {
            fn kernel<T: Real>($model: &Model, $data: &mut Data<T>, $a: [&[T]; 3], $o: &mut [T]) {
                $call
            }

            /// The rows `first..first + out.len() / per_row` of the batch.
            #[inline(always)]
            fn rows<L: Real>(model: &Model, w: &mut Work<L>, args: [&[f64]; 3], first: usize, out: &mut [f64]) {
                let widths: [usize; 3] = { let $wm = model; $widths };
                let per_row = { let $m = model; $out };
                let rows = out.len() / per_row;
                let mut r = 0;
                // Groups of L::LANES rows: transpose into lanes, run, transpose back.
                while r + L::LANES <= rows {
                    for ((slot, arg), &n) in w.args.iter_mut().zip(args).zip(&widths).take($nargs) {
                        for j in 0..n {
                            for k in 0..L::LANES {
                                slot[j].set_lane(k, arg[(first + r + k) * n + j]);
                            }
                        }
                    }
                    let [a0, a1, a2] = &w.args;
                    let lanes = [&a0[..widths[0]], &a1[..widths[1]], &a2[..widths[2]]];
                    kernel(model, &mut w.dl, lanes, &mut w.res[..per_row]);
                    for j in 0..per_row {
                        for k in 0..L::LANES {
                            out[(r + k) * per_row + j] = w.res[j].lane(k);
                        }
                    }
                    r += L::LANES;
                }
                // Leftover rows one by one.
                for r in r..rows {
                    let a: [&[f64]; 3] =
                        std::array::from_fn(|k| if args[k].is_empty() { args[k] } else { row(args[k], widths[k], first + r) });
                    kernel(model, &mut w.d1, a, &mut out[r * per_row..(r + 1) * per_row]);
                }
            }

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            unsafe fn rows_avx2(model: &Model, w: &mut Work<F64x4>, args: [&[f64]; 3], first: usize, out: &mut [f64]) {
                rows(model, w, args, first, out)
            }

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f")]
            unsafe fn rows_avx512(model: &Model, w: &mut Work<F64x8>, args: [&[f64]; 3], first: usize, out: &mut [f64]) {
                rows(model, w, args, first, out)
            }

            let widths: [usize; 3] = { let $wm = model; $widths };
            let per_row = { let $m = model; $out };
            let nrows = if per_row == 0 { 0 } else { out.len() / per_row };
            for (a, n) in args.iter().zip(widths) {
                assert_eq!(a.len(), nrows * n, "argument size");
            }
            let mut all: [&[f64]; 3] = [&[], &[], &[]];
            all[..$nargs].copy_from_slice(&args);
            match kernels() {
                #[cfg(target_arch = "x86_64")]
                Kernels::Avx512 => par_rows(nrows, [out], [per_row], threads, || Work::new(model), |w, first, [chunk]| {
                    // SAFETY: the CPU supports AVX-512F (checked by `kernels`).
                    unsafe { rows_avx512(model, w, all, first, chunk) }
                }),
                #[cfg(target_arch = "x86_64")]
                Kernels::Avx2 => par_rows(nrows, [out], [per_row], threads, || Work::new(model), |w, first, [chunk]| {
                    // SAFETY: the CPU supports AVX2 (checked by `kernels`).
                    unsafe { rows_avx2(model, w, all, first, chunk) }
                }),
                _ => par_rows(nrows, [out], [per_row], threads, || Work::<BaselineLanes>::new(model), |w, first, [chunk]| {
                    rows(model, w, all, first, chunk)
                }),
            }
        }
    };
}

lanes_kernel!(
    /// Batched [`algo::rnea`]: `args = [q, qd, qdd]` (N, nv) each, `out` = tau (N, nv).
    rnea, nargs = 3, out = |m| m.nv,
    |model, data, a, o| algo::rnea(model, data, a[0], a[1], a[2], o)
);
lanes_kernel!(
    /// Batched [`algo::aba`]: `args = [q, qd, tau]` (N, nv) each, `out` = qdd (N, nv).
    aba, nargs = 3, out = |m| m.nv,
    |model, data, a, o| algo::aba(model, data, a[0], a[1], a[2], o)
);
lanes_kernel!(
    /// Batched [`algo::crba`]: `args = [q]` (N, nv), `out` = M (N, nv, nv).
    crba, nargs = 1, out = |m| m.nv * m.nv,
    |model, data, a, o| algo::crba(model, data, a[0], o)
);
lanes_kernel!(
    /// Batched [`algo::rnea_floating`]: `args = [q (N, 7 + nv), v, a (N, 6 + nv)]`, `out` =
    /// tau (N, 6 + nv) (a floating base, `algo::floating`).
    rnea_floating, nargs = 3, widths = |m| [m.nq + 7, m.nv + 6, m.nv + 6], out = |m| m.nv + 6,
    |model, data, a, o| algo::rnea_floating(model, data, a[0], a[1], a[2], o)
);
lanes_kernel!(
    /// Batched [`algo::aba_floating`]: `args = [q (N, 7 + nv), v, tau (N, 6 + nv)]`, `out` =
    /// the accelerations (N, 6 + nv) (a floating base, `algo::floating`).
    aba_floating, nargs = 3, widths = |m| [m.nq + 7, m.nv + 6, m.nv + 6], out = |m| m.nv + 6,
    |model, data, a, o| algo::aba_floating(model, data, a[0], a[1], a[2], o)
);
lanes_kernel!(
    /// Batched [`algo::crba_floating`]: `args = [q (N, 7 + nv)]`, `out` = M (N, 6 + nv, 6 + nv)
    /// (a floating base, `algo::floating`).
    crba_floating, nargs = 1, widths = |m| [m.nq + 7, 0, 0], out = |m| (m.nv + 6) * (m.nv + 6),
    |model, data, a, o| algo::crba_floating(model, data, a[0], o)
);
lanes_kernel!(
    /// Batched [`algo::gravity`]: `args = [q]` (N, nv), `out` = g (N, nv).
    gravity, nargs = 1, out = |m| m.nv,
    |model, data, a, o| algo::gravity(model, data, a[0], o)
);
lanes_kernel!(
    /// Batched [`algo::bias`]: `args = [q, qd]` (N, nv) each, `out` = h (N, nv).
    bias, nargs = 2, out = |m| m.nv,
    |model, data, a, o| algo::bias(model, data, a[0], a[1], o)
);

lanes_kernel!(
    /// Batched [`algo::regressor`]: `args = [q, qd, qdd]` (N, nv) each, `out` = Y
    /// (N, nv, [`algo::regressor_columns`]).
    regressor, nargs = 3, out = |m| m.nv * algo::regressor_columns(m),
    |model, data, a, o| algo::regressor(model, data, a[0], a[1], a[2], o)
);

/// Row `r` of an (N, n) array.
fn row(a: &[f64], n: usize, r: usize) -> &[f64] {
    &a[r * n..(r + 1) * n]
}

/// Batched [`algo::coriolis_matrix`]: `q`, `qd` (N, nv), `out` = C (N, nv, nv).
pub fn coriolis_matrix(model: &Model, q: &[f64], qd: &[f64], out: &mut [f64], threads: Option<usize>) {
    let (n, nq) = (model.nv, model.nq);
    let make = || (Data::new(model), CoriolisWork::new(model));
    par_rows(q.len() / nq.max(1), [out], [n * n], threads, make, |(d, cw), first, [chunk]| {
        for (k, o) in chunk.chunks_exact_mut(n * n).enumerate() {
            let r = first + k;
            algo::coriolis_matrix(model, d, cw, row(q, nq, r), row(qd, n, r), o);
        }
    });
}

/// Batched [`algo::kinetic_energy`]: `q`, `qd` (N, nv), `out` (N,).
pub fn kinetic_energy(model: &Model, q: &[f64], qd: &[f64], out: &mut [f64], threads: Option<usize>) {
    let (n, nq) = (model.nv, model.nq);
    assert!(q.len() == out.len() * nq && qd.len() == out.len() * n, "argument size");
    par_rows(
        out.len(),
        [out],
        [1],
        threads,
        || Data::new(model),
        |d, first, [chunk]| {
            for (k, o) in chunk.iter_mut().enumerate() {
                *o = algo::kinetic_energy(model, d, row(q, nq, first + k), row(qd, n, first + k));
            }
        },
    );
}

/// Batched [`algo::potential_energy`]: `q` (N, nv), `out` (N,).
pub fn potential_energy(model: &Model, q: &[f64], out: &mut [f64], threads: Option<usize>) {
    let nq = model.nq;
    assert!(q.len() == out.len() * nq, "argument size");
    par_rows(
        out.len(),
        [out],
        [1],
        threads,
        || Data::new(model),
        |d, first, [chunk]| {
            for (k, o) in chunk.iter_mut().enumerate() {
                *o = algo::potential_energy(model, d, row(q, nq, first + k));
            }
        },
    );
}

/// Batched [`algo::forward_kinematics`]: `q` (N, nv), `out` (N, nlinks, 4, 4).
pub fn forward_kinematics(model: &Model, q: &[f64], out: &mut [f64], threads: Option<usize>) {
    let (n, per) = (model.nq, model.nlinks() * 16);
    assert!(q.len() * per == out.len() * n || n == 0, "argument size");
    par_rows(
        out.len() / per,
        [out],
        [per],
        threads,
        || Data::new(model),
        |d, first, [chunk]| {
            for (k, o) in chunk.chunks_exact_mut(per).enumerate() {
                algo::forward_kinematics(model, d, row(q, n, first + k), o);
            }
        },
    );
}

/// Batched [`algo::jacobian`] of link `link`: `q` (N, nv), `out` (N, 6, nv).
pub fn jacobian(model: &Model, q: &[f64], link: usize, out: &mut [f64], threads: Option<usize>) {
    let (n, nq) = (model.nv, model.nq);
    let per = 6 * n;
    par_rows(
        q.len() / nq.max(1),
        [out],
        [per],
        threads,
        || Data::new(model),
        |d, first, [chunk]| {
            for (k, o) in chunk.chunks_exact_mut(per).enumerate() {
                algo::jacobian(model, d, row(q, nq, first + k), link, o);
            }
        },
    );
}

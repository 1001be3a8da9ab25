//! Batches of the derivative algorithms, M^-1 and the external-force variants: row `k`
//! of each `(N, nv)` input is one state; each output is its own array with `N` rows
//! (`(N, nv, nv)` matrices, `(N, nv)` vectors, `(N, 6, nv)` Jacobians). External
//! wrenches are `(N, nlinks, 6)`. A floating base's rows are wider (`algo::floating`):
//! `q` `(N, 7 + nv)`, velocities `(N, 6 + nv)`, matrices `(N, 6 + nv, 6 + nv)`.
//!
//! As in `batch.rs`: rayon over chunks of rows, one workspace per chunk (never per
//! state), and inside a chunk groups of 4 or 8 states in SIMD lanes (the algorithms are
//! generic over [`Real`]), so a state computed in a batch is bit-for-bit the state
//! computed alone. `jacobian_dot` runs one state at a time.

use crate::algo;
use crate::algo::{ExternalForces, ForceFrame};
use crate::batch::{kernels, par_rows, Kernels};
use crate::data::Data;
use crate::deriv_data::DerivData;
use crate::model::Model;
use crate::real::{F64x4, F64x8, Real};

/// One algorithm as a batch kernel, generic over the lane type.
trait Kernel: Sync {
    /// Number of (N, nv) arguments.
    const NARGS: usize;
    /// Number of outputs and their sizes per state.
    const NOUT: usize;
    fn out_len(model: &Model) -> usize;
    /// Values per state of each argument: `nv`, or a floating base's `7 + nv`, `6 + nv`.
    fn widths(model: &Model) -> [usize; 3] {
        [model.nq, model.nv, model.nv]
    }
    #[allow(clippy::too_many_arguments)]
    fn run<T: Real>(
        &self,
        model: &Model,
        data: &mut Data<T>,
        dd: &mut DerivData<T>,
        args: [&[T]; 3],
        ext: Option<&ExternalForces<T>>,
        outs: [&mut [T]; 3],
    );
}

/// Workspace of a chunk for one state at a time.
struct One {
    d: Data<f64>,
    dd: DerivData<f64>,
    res: [Vec<f64>; 3],
}

impl One {
    fn new(model: &Model, out_len: usize) -> Self {
        One { d: Data::new(model), dd: DerivData::new(model), res: std::array::from_fn(|_| vec![0.0; out_len]) }
    }
}

/// Workspace of a chunk: `L`-lane data and the lane-transposed arguments/results of one
/// group of rows, and a scalar workspace for the leftover rows.
struct Work<L> {
    one: One,
    dl: Data<L>,
    ddl: DerivData<L>,
    args: [Vec<L>; 3],
    ext: Vec<L>,
    res: [Vec<L>; 3],
}

impl<L: Real> Work<L> {
    fn new(model: &Model, out_len: usize, widths: [usize; 3]) -> Self {
        Work {
            one: One::new(model, out_len),
            dl: Data::new(model),
            ddl: DerivData::new(model),
            args: std::array::from_fn(|k| vec![L::zero(); widths[k]]),
            ext: vec![L::zero(); 6 * model.nlinks()],
            res: std::array::from_fn(|_| vec![L::zero(); out_len]),
        }
    }
}

/// Transposes `L::LANES` rows of `len` values (`rows`, row-major: one state per row)
/// into `len` lane vectors (`lanes[j]` holds value `j` of every state).
///
/// Each state's row is read contiguously; the lane loop has a constant trip count
/// (`L::LANES`), so it unrolls and every `set_lane` has a constant lane index.
#[doc(hidden)] // public for tests/transposition.rs
#[inline(always)]
pub fn rows_to_lanes<L: Real>(rows: &[f64], lanes: &mut [L], len: usize) {
    for l in 0..L::LANES {
        let row = &rows[l * len..(l + 1) * len];
        for (v, &x) in lanes[..len].iter_mut().zip(row) {
            v.set_lane(l, x);
        }
    }
}

/// The inverse of [`rows_to_lanes`]: `len` lane vectors (`lanes`) into `L::LANES`
/// rows of `len` values (`rows`, row-major, one state per row).
///
/// Blocks of `L::LANES` values are square `LANES x LANES` transposes with constant
/// indices (both loops unroll): whole-vector loads and contiguous stores of each
/// state's row segment, instead of `LANES` stores strided by a whole output per value.
///
/// With 8 lanes on an AVX-512 CPU the blocks go through [`blocks_to_rows_avx512`]
/// (the same values, moved by shuffles).
#[doc(hidden)] // public for tests/transposition.rs
#[inline(always)]
pub fn lanes_to_rows<L: Real>(lanes: &[L], rows: &mut [f64], len: usize) {
    let w = L::LANES;
    let full = len / w * w;
    if !blocks_shuffled(lanes, rows, len) {
        for jb in (0..full).step_by(w) {
            let block = &lanes[jb..jb + w];
            for l in 0..w {
                let row = &mut rows[l * len + jb..l * len + jb + w];
                for jj in 0..w {
                    row[jj] = L::lane_of(&block[jj], l);
                }
            }
        }
    }
    for j in full..len {
        for l in 0..w {
            rows[l * len + j] = L::lane_of(&lanes[j], l);
        }
    }
}

/// The full blocks of [`lanes_to_rows`] by [`blocks_to_rows_avx512`] when `L` is
/// [`F64x8`] and the CPU has AVX-512F; false (nothing written) otherwise.
#[inline(always)]
fn blocks_shuffled<L: Real>(lanes: &[L], rows: &mut [f64], len: usize) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::any::TypeId::of::<L>() == std::any::TypeId::of::<F64x8>() && std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: L is F64x8 (same type, so the cast is the identity); the CPU has AVX-512F.
        let lanes = unsafe { std::slice::from_raw_parts(lanes.as_ptr() as *const F64x8, lanes.len()) };
        unsafe { blocks_to_rows_avx512(lanes, rows, len) };
        return true;
    }
    let _ = (lanes, rows, len);
    false
}

/// The full 8 x 8 blocks of [`lanes_to_rows`] (values `0..len / 8 * 8`; the caller writes
/// the rest) for 8 lanes with AVX-512 shuffles. Each 8 x 8 block is 8 vector
/// loads, the three-stage register transpose (`unpacklo/hi` of value pairs, then
/// `permutex2var` across 128-bit and then 256-bit halves: 24 shuffles) and 8 row stores.
/// What LLVM makes of the generic loop here is one `vgatherdpd` per row segment, which
/// `perf annotate` showed holding about a quarter of the cycles of the M^-1 batch on
/// the iiwa14 (AMD Zen 4, where gathers are slow).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn blocks_to_rows_avx512(lanes: &[F64x8], rows: &mut [f64], len: usize) {
    use std::arch::x86_64::*;
    assert!(lanes.len() >= len && rows.len() >= 8 * len, "lanes_to_rows sizes");
    let full = len / 8 * 8;
    // a: first operand, b: second (indices 8..15)
    let pairs_lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
    let pairs_hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
    let halves_lo = _mm512_setr_epi64(0, 1, 2, 3, 8, 9, 10, 11);
    let halves_hi = _mm512_setr_epi64(4, 5, 6, 7, 12, 13, 14, 15);
    for jb in (0..full).step_by(8) {
        // r[j]: value jb + j of the 8 states (lane l = state l)
        let mut r = [_mm512_setzero_pd(); 8];
        for j in 0..8 {
            // SAFETY: jb + j < full <= lanes.len(); F64x8 is 64-byte aligned.
            r[j] = unsafe { _mm512_load_pd(lanes[jb + j].0.as_ptr()) };
        }
        // t[2k] = (r[2k][0], r[2k+1][0], r[2k][2], r[2k+1][2], ...), t[2k+1] the odd lanes
        let mut t = [_mm512_setzero_pd(); 8];
        for k in 0..4 {
            t[2 * k] = _mm512_unpacklo_pd(r[2 * k], r[2 * k + 1]);
            t[2 * k + 1] = _mm512_unpackhi_pd(r[2 * k], r[2 * k + 1]);
        }
        // u[k]: lanes k and k + 4 of values 0..4 (from t[0..4]); u[4 + k]: of values 4..8
        let mut u = [_mm512_setzero_pd(); 8];
        for g in [0, 4] {
            u[g] = _mm512_permutex2var_pd(t[g], pairs_lo, t[g + 2]);
            u[g + 1] = _mm512_permutex2var_pd(t[g + 1], pairs_lo, t[g + 3]);
            u[g + 2] = _mm512_permutex2var_pd(t[g], pairs_hi, t[g + 2]);
            u[g + 3] = _mm512_permutex2var_pd(t[g + 1], pairs_hi, t[g + 3]);
        }
        for k in 0..4 {
            let row_k = _mm512_permutex2var_pd(u[k], halves_lo, u[4 + k]);
            let row_k4 = _mm512_permutex2var_pd(u[k], halves_hi, u[4 + k]);
            // SAFETY: (k + 4) * len + jb + 8 <= 8 * len <= rows.len()
            unsafe {
                _mm512_storeu_pd(rows.as_mut_ptr().add(k * len + jb), row_k);
                _mm512_storeu_pd(rows.as_mut_ptr().add((k + 4) * len + jb), row_k4);
            }
        }
    }
}

/// The rows `first..first + rows` of the batch, `L::LANES` at a time, then one by one.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn rows<L: Real, K: Kernel>(
    k: &K,
    model: &Model,
    w: &mut Work<L>,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    first: usize,
    mut outs: [&mut [f64]; 3],
) {
    let widths = K::widths(model);
    let per = K::out_len(model);
    let ne = 6 * model.nlinks();
    let rows = if per == 0 { 0 } else { outs[0].len() / per };
    let mut r = 0;
    while r + L::LANES <= rows {
        let group = first + r..first + r + L::LANES;
        for ((slot, arg), n) in w.args.iter_mut().zip(args).zip(widths).take(K::NARGS) {
            rows_to_lanes(&arg[group.start * n..group.end * n], slot, n);
        }
        if let Some((e, _)) = ext {
            rows_to_lanes(&e[group.start * ne..group.end * ne], &mut w.ext, ne);
        }
        let e = ext.map(|(_, frame)| ExternalForces { wrenches: &w.ext[..], frame });
        let [a0, a1, a2] = &w.args;
        let [r0, r1, r2] = &mut w.res;
        k.run(model, &mut w.dl, &mut w.ddl, [a0, a1, a2], e.as_ref(), [r0, r1, r2]);
        for (o, res) in outs.iter_mut().zip(&w.res).take(K::NOUT) {
            lanes_to_rows(res, &mut o[r * per..(r + L::LANES) * per], per);
        }
        r += L::LANES;
    }
    one_by_one(k, model, &mut w.one, args, ext, first, r, outs);
}

/// The rows `first + from..` of the chunk one state at a time: the leftover rows of
/// every lane width, and every row of the x86-64 baseline kernels.
///
/// Out of line on purpose: one copy of the scalar algorithm per kernel, shared by all
/// callers, instead of one inlined into each lane width's `rows` (the scalar path is
/// not the hot one, and every copy of an algorithm costs compile time).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn one_by_one<K: Kernel>(
    k: &K,
    model: &Model,
    w: &mut One,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    first: usize,
    from: usize,
    mut outs: [&mut [f64]; 3],
) {
    let widths = K::widths(model);
    let per = K::out_len(model);
    let ne = 6 * model.nlinks();
    let rows = if per == 0 { 0 } else { outs[0].len() / per };
    for r in from..rows {
        let a: [&[f64]; 3] = std::array::from_fn(|j| {
            let (a, n) = (args[j], widths[j]);
            if a.is_empty() { a } else { &a[(first + r) * n..(first + r + 1) * n] }
        });
        let e = ext.map(|(e, frame)| ExternalForces { wrenches: &e[(first + r) * ne..(first + r + 1) * ne], frame });
        let [r0, r1, r2] = &mut w.res;
        k.run(model, &mut w.d, &mut w.dd, a, e.as_ref(), [r0, r1, r2]);
        for (o, res) in outs.iter_mut().zip(&w.res).take(K::NOUT) {
            o[r * per..(r + 1) * per].copy_from_slice(res);
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn rows_avx2<K: Kernel>(
    k: &K,
    model: &Model,
    w: &mut Work<F64x4>,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    first: usize,
    outs: [&mut [f64]; 3],
) {
    rows(k, model, w, args, ext, first, outs)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn rows_avx512<K: Kernel>(
    k: &K,
    model: &Model,
    w: &mut Work<F64x8>,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    first: usize,
    outs: [&mut [f64]; 3],
) {
    rows(k, model, w, args, ext, first, outs)
}

/// Check sizes and run kernel `k` over the batch with the CPU's widest lanes.
fn drive<K: Kernel>(
    k: &K,
    model: &Model,
    args: &[&[f64]],
    ext: Option<(&[f64], ForceFrame)>,
    outs: [&mut [f64]; 3],
    threads: Option<usize>,
) {
    assert_eq!(args.len(), K::NARGS, "argument count");
    let (widths, per) = (K::widths(model), K::out_len(model));
    let nrows = if per == 0 { 0 } else { outs[0].len() / per };
    for (a, n) in args.iter().zip(widths) {
        assert_eq!(a.len(), nrows * n, "argument size");
    }
    if let Some((e, _)) = ext {
        assert_eq!(e.len(), nrows * 6 * model.nlinks(), "f_ext size");
    }
    let mut all: [&[f64]; 3] = [&[], &[], &[]];
    all[..K::NARGS].copy_from_slice(args);
    // unused output slots are empty slices
    let per_row: [usize; 3] = std::array::from_fn(|j| if j < K::NOUT { per } else { 0 });
    match kernels() {
        #[cfg(target_arch = "x86_64")]
        Kernels::Avx512 => par_rows(nrows, outs, per_row, threads, || Work::<F64x8>::new(model, per, widths), |w, first, o| {
            // SAFETY: the CPU supports AVX-512F (checked by `kernels`).
            unsafe { rows_avx512(k, model, w, all, ext, first, o) }
        }),
        #[cfg(target_arch = "x86_64")]
        Kernels::Avx2 => par_rows(nrows, outs, per_row, threads, || Work::<F64x4>::new(model, per, widths), |w, first, o| {
            // SAFETY: the CPU supports AVX2 (checked by `kernels`).
            unsafe { rows_avx2(k, model, w, all, ext, first, o) }
        }),
        // x86-64 without AVX2: one state at a time (see `batch::BaselineLanes`).
        #[cfg(target_arch = "x86_64")]
        _ => par_rows(nrows, outs, per_row, threads, || One::new(model, per), |w, first, o| {
            one_by_one(k, model, w, all, ext, first, 0, o)
        }),
        #[cfg(not(target_arch = "x86_64"))]
        _ => par_rows(nrows, outs, per_row, threads, || Work::<F64x4>::new(model, per, widths), |w, first, o| {
            rows(k, model, w, all, ext, first, o)
        }),
    }
}

/// Defines a [`Kernel`] `$name` with `$nargs` (N, nv) arguments and `$nout` outputs of
/// `$out_len` values per state, running `$call` (generic over the lane type `T`).
macro_rules! kernel {
    ($name:ident, nargs = $nargs:literal, nout = $nout:literal, out_len = |$m:ident| $out_len:expr,
     $(widths = |$wm:ident| $widths:expr,)?
     |$model:ident, $d:ident, $dd:ident, $a:ident, $e:pat_param, $o:pat_param| $call:expr) => {
        struct $name;
        impl Kernel for $name {
            const NARGS: usize = $nargs;
            const NOUT: usize = $nout;
            fn out_len($m: &Model) -> usize {
                $out_len
            }
            $(fn widths($wm: &Model) -> [usize; 3] {
                $widths
            })?
            #[inline(always)]
            fn run<T: Real>(
                &self,
                $model: &Model,
                $d: &mut Data<T>,
                $dd: &mut DerivData<T>,
                $a: [&[T]; 3],
                $e: Option<&ExternalForces<T>>,
                $o: [&mut [T]; 3],
            ) {
                $call
            }
        }
    };
}

kernel!(RneaDerivatives, nargs = 3, nout = 3, out_len = |m| m.nv * m.nv, |m, d, dd, a, e, [o0, o1, o2]| {
    algo::rnea_derivatives(m, d, dd, a[0], a[1], a[2], e, o0, o1, o2)
});
kernel!(AbaDerivatives, nargs = 3, nout = 3, out_len = |m| m.nv * m.nv, |m, d, dd, a, e, [o0, o1, o2]| {
    algo::aba_derivatives(m, d, dd, a[0], a[1], a[2], e, o0, o1, o2)
});
kernel!(Minverse, nargs = 1, nout = 1, out_len = |m| m.nv * m.nv, |m, d, dd, a, _, [o0, _, _]| {
    algo::minverse(m, d, dd, a[0], o0)
});
kernel!(GravityDerivatives, nargs = 1, nout = 1, out_len = |m| m.nv * m.nv, |m, d, dd, a, _, [o0, _, _]| {
    algo::gravity_derivatives(m, d, dd, a[0], o0)
});
kernel!(RneaExt, nargs = 3, nout = 1, out_len = |m| m.nv, |m, d, dd, a, e, [o0, _, _]| {
    algo::rnea_ext(m, d, dd, a[0], a[1], a[2], e.expect("external forces"), o0)
});
kernel!(AbaExt, nargs = 3, nout = 1, out_len = |m| m.nv, |m, d, dd, a, e, [o0, _, _]| {
    algo::aba_ext(m, d, dd, a[0], a[1], a[2], e.expect("external forces"), o0)
});

kernel!(RneaDerivativesFloating, nargs = 3, nout = 3, out_len = |m| (m.nv + 6) * (m.nv + 6),
    widths = |m| [m.nq + 7, m.nv + 6, m.nv + 6], |m, d, dd, a, e, [o0, o1, o2]| {
    algo::rnea_derivatives_floating(m, d, dd, a[0], a[1], a[2], e, o0, o1, o2)
});
kernel!(AbaDerivativesFloating, nargs = 3, nout = 3, out_len = |m| (m.nv + 6) * (m.nv + 6),
    widths = |m| [m.nq + 7, m.nv + 6, m.nv + 6], |m, d, dd, a, e, [o0, o1, o2]| {
    algo::aba_derivatives_floating(m, d, dd, a[0], a[1], a[2], e, o0, o1, o2)
});
kernel!(MinverseFloating, nargs = 1, nout = 1, out_len = |m| (m.nv + 6) * (m.nv + 6),
    widths = |m| [m.nq + 7, 0, 0], |m, d, dd, a, _, [o0, _, _]| {
    algo::minverse_floating(m, d, dd, a[0], o0)
});

/// Batched [`algo::rnea_derivatives`]: `args = [q, qd, qdd]` (N, nv) each; `ext`:
/// wrenches (N, nlinks, 6) and their frame; `outs = [dtau_dq, dtau_dqd, M]` (N, nv, nv) each.
pub fn rnea_derivatives(model: &Model, args: [&[f64]; 3], ext: Option<(&[f64], ForceFrame)>, outs: [&mut [f64]; 3], threads: Option<usize>) {
    drive(&RneaDerivatives, model, &args, ext, outs, threads)
}

/// Batched [`algo::aba_derivatives`]: `args = [q, qd, tau]` (N, nv) each; `ext` as for
/// `rnea_derivatives`; `outs = [dqdd_dq, dqdd_dqd, Minv]` (N, nv, nv) each.
pub fn aba_derivatives(model: &Model, args: [&[f64]; 3], ext: Option<(&[f64], ForceFrame)>, outs: [&mut [f64]; 3], threads: Option<usize>) {
    drive(&AbaDerivatives, model, &args, ext, outs, threads)
}

/// Batched [`algo::minverse`]: `q` (N, nv), `out` = M^-1 (N, nv, nv).
pub fn minverse(model: &Model, q: &[f64], out: &mut [f64], threads: Option<usize>) {
    drive(&Minverse, model, &[q], None, [out, &mut [], &mut []], threads)
}

/// Batched [`algo::gravity_derivatives`]: `q` (N, nv), `out` = dg/dq (N, nv, nv).
pub fn gravity_derivatives(model: &Model, q: &[f64], out: &mut [f64], threads: Option<usize>) {
    drive(&GravityDerivatives, model, &[q], None, [out, &mut [], &mut []], threads)
}

/// Batched [`algo::rnea_ext`]: `args = [q, qd, qdd]` (N, nv), `ext` (N, nlinks, 6), `out` tau (N, nv).
pub fn rnea_ext(model: &Model, args: [&[f64]; 3], ext: (&[f64], ForceFrame), out: &mut [f64], threads: Option<usize>) {
    drive(&RneaExt, model, &args, Some(ext), [out, &mut [], &mut []], threads)
}

/// Batched [`algo::aba_ext`]: `args = [q, qd, tau]` (N, nv), `ext` (N, nlinks, 6), `out` qdd (N, nv).
pub fn aba_ext(model: &Model, args: [&[f64]; 3], ext: (&[f64], ForceFrame), out: &mut [f64], threads: Option<usize>) {
    drive(&AbaExt, model, &args, Some(ext), [out, &mut [], &mut []], threads)
}

/// Batched [`algo::jacobian_dot`] of link `link`: `q`, `qd` (N, nv), `out` (N, 6, nv).
pub fn jacobian_dot(model: &Model, q: &[f64], qd: &[f64], link: usize, out: &mut [f64], threads: Option<usize>) {
    let (n, nq, per) = (model.nv, model.nq, 6 * model.nv);
    let rows = if per == 0 { 0 } else { out.len() / per };
    assert!(q.len() == rows * nq && qd.len() == rows * n, "argument size");
    par_rows(rows, [out], [per], threads, || Data::new(model), |d, first, [o]| {
        for (k, o) in o.chunks_exact_mut(per).enumerate() {
            let r = first + k;
            algo::jacobian_dot(model, d, &q[r * nq..(r + 1) * nq], &qd[r * n..(r + 1) * n], link, o);
        }
    });
}

/// Batched [`algo::rnea_derivatives_floating`] (a floating base, `algo::floating`):
/// `args = [q (N, 7 + nv), v, a (N, 6 + nv)]`; `ext` as for `rnea_derivatives` (link
/// frames only); `outs = [dtau_dq, dtau_dv, M]` (N, 6 + nv, 6 + nv) each.
pub fn rnea_derivatives_floating(
    model: &Model,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    outs: [&mut [f64]; 3],
    threads: Option<usize>,
) {
    drive(&RneaDerivativesFloating, model, &args, ext, outs, threads)
}

/// Batched [`algo::aba_derivatives_floating`]: `args = [q (N, 7 + nv), v, tau (N, 6 + nv)]`;
/// `ext` as for `rnea_derivatives_floating`; `outs = [da_dq, da_dv, Minv]` (N, 6 + nv, 6 + nv) each.
pub fn aba_derivatives_floating(
    model: &Model,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    outs: [&mut [f64]; 3],
    threads: Option<usize>,
) {
    drive(&AbaDerivativesFloating, model, &args, ext, outs, threads)
}

/// Batched [`algo::minverse_floating`]: `q` (N, 7 + nv), `out` = M^-1 (N, 6 + nv, 6 + nv).
pub fn minverse_floating(model: &Model, q: &[f64], out: &mut [f64], threads: Option<usize>) {
    drive(&MinverseFloating, model, &[q], None, [out, &mut [], &mut []], threads)
}

/// Batched [`algo::multi_derivatives`] (joints of several coordinates, fixed or floating
/// base), one state at a time on each thread (the algorithm is `f64` only): `rnea` picks
/// the RNEA's derivatives (`args = [q, v, a]`) or the ABA's (`[q, v, tau]`); `q` (N, nq),
/// the others (N, nv), `nq`/`nv` with a floating base's 7/6; `ext` (N, nlinks, 6) as for
/// the single call; `outs` (N, nv, nv) each.
pub fn multi_derivatives(
    model: &Model,
    floating: bool,
    rnea: bool,
    args: [&[f64]; 3],
    ext: Option<(&[f64], ForceFrame)>,
    outs: [&mut [f64]; 3],
    threads: Option<usize>,
) {
    use algo::multi_derivatives::{tangent_derivatives, MultiWork};
    let (qb, vb) = algo::floating_kinematics::base_widths(floating);
    let (nq, nv, ne) = (model.nq + qb, model.nv + vb, 6 * model.nlinks());
    let per = nv * nv;
    let rows = if per == 0 { 0 } else { outs[0].len() / per };
    assert!(args[0].len() == rows * nq && args[1].len() == rows * nv && args[2].len() == rows * nv, "argument size");
    let make = || MultiWork::new(model, floating);
    par_rows(rows, outs, [per; 3], threads, make, |w, first, [o0, o1, o2]| {
        let outs = o0.chunks_exact_mut(per).zip(o1.chunks_exact_mut(per)).zip(o2.chunks_exact_mut(per));
        for (k, ((a, b), c)) in outs.enumerate() {
            let r = first + k;
            let row = [&args[0][r * nq..][..nq], &args[1][r * nv..][..nv], &args[2][r * nv..][..nv]];
            let e = ext.map(|(e, frame)| ExternalForces { wrenches: &e[r * ne..][..ne], frame });
            tangent_derivatives(model, floating, rnea, w, row, e.as_ref(), [a, b, c]);
        }
    });
}

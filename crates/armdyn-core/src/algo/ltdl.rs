//! Solving with the joint-space inertia matrix by its sparse factors (RBDA 6.3, the LTDL
//! factorisation): `M = L^T D L`, `L` with the sparsity of the kinematic tree, so that a
//! factorisation costs `O(nv d^2)` and a solve `O(nv d)` per right-hand side (`d` the
//! tree's depth) instead of the dense `O(nv^3)`. `VB` is the number of base velocities
//! before the joints' (0 for a fixed base, 6 for a floating one).

use crate::model::Model;
use crate::real::Real;

pub(crate) fn identity<T: Real>(x: &mut [T], s: usize) {
    x.fill(T::zero());
    for k in 0..s {
        x[k * s + k] = T::splat(1.0);
    }
}

/// The parent of velocity `k` in M's sparsity tree, with `VB` base velocities first
/// (0 for a fixed base; a floating base's six form a chain, its 6x6 block being dense,
/// and the root joints hang from the last of them).
#[inline(always)]
fn parent<const VB: usize>(model: &Model, k: usize) -> Option<usize> {
    if VB == 0 {
        model.parent[k]
    } else if k < VB {
        k.checked_sub(1)
    } else {
        Some(model.parent[k - VB].map_or(VB - 1, |p| p + VB))
    }
}

/// `M = L^T D L` in place (RBDA Table 6.3, the LTDL factorisation): `L` unit lower
/// triangular with the tree's sparsity (row k nonzero at k's ancestors only) below the
/// diagonal of `h`, `D` on it. Reads and writes only the lower triangle of `h`.
#[inline(always)]
pub(crate) fn factorize<T: Real, const VB: usize>(model: &Model, h: &mut [T]) {
    let s = model.nv + VB;
    for k in (0..s).rev() {
        let inv = T::splat(1.0) / h[k * s + k];
        let mut i = parent::<VB>(model, k);
        while let Some(ii) = i {
            let a = h[k * s + ii] * inv;
            let mut j = Some(ii);
            while let Some(jj) = j {
                let x = h[k * s + jj];
                h[ii * s + jj] -= a * x;
                j = parent::<VB>(model, jj);
            }
            h[k * s + ii] = a;
            i = parent::<VB>(model, ii);
        }
    }
}

/// `x_r <- sign_r * M^-1 x_r` for each of the `R` matrices `x_r`, (VB + nv) x (VB + nv)
/// row-major, with M's factors `h` from [`factorize`]: `L^T y = x`, `z = D^-1 y`,
/// `L x = z`, each a sweep of whole-row updates along the tree, all `R` matrices in the
/// same sweep. For one state (`f64`) the rows are compiled for AVX2 when the CPU has it
/// (wider vectors on contiguous rows; the same operations, so the same bits).
#[inline(always)]
pub(crate) fn solve<T: Real, const R: usize, const VB: usize>(
    model: &Model,
    h: &[T],
    xs: [&mut [T]; R],
    signs: [T; R],
) {
    #[cfg(target_arch = "x86_64")]
    if std::any::TypeId::of::<T>() == std::any::TypeId::of::<f64>() && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { solve_avx2::<T, R, VB>(model, h, xs, signs) };
    }
    solve_rows::<T, R, VB>(model, h, xs, signs)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn solve_avx2<T: Real, const R: usize, const VB: usize>(
    model: &Model,
    h: &[T],
    xs: [&mut [T]; R],
    signs: [T; R],
) {
    solve_rows::<T, R, VB>(model, h, xs, signs)
}

#[inline(always)]
fn solve_rows<T: Real, const R: usize, const VB: usize>(model: &Model, h: &[T], mut xs: [&mut [T]; R], signs: [T; R]) {
    let s = model.nv + VB;
    for k in (0..s).rev() {
        let mut j = parent::<VB>(model, k);
        while let Some(jj) = j {
            // row jj -= L_k,jj row k (jj < k)
            let l = h[k * s + jj];
            for x in xs.iter_mut() {
                let (head, tail) = x.split_at_mut(k * s);
                for (d, &r) in head[jj * s..(jj + 1) * s].iter_mut().zip(&tail[..s]) {
                    *d -= l * r;
                }
            }
            j = parent::<VB>(model, jj);
        }
    }
    for k in 0..s {
        let d = T::splat(1.0) / h[k * s + k];
        for (x, &sign) in xs.iter_mut().zip(&signs) {
            let ds = sign * d;
            x[k * s..(k + 1) * s].iter_mut().for_each(|e| *e *= ds);
        }
    }
    for k in 0..s {
        let mut j = parent::<VB>(model, k);
        while let Some(jj) = j {
            // row k -= L_k,jj row jj
            let l = h[k * s + jj];
            for x in xs.iter_mut() {
                let (head, tail) = x.split_at_mut(k * s);
                for (d, &r) in tail[..s].iter_mut().zip(&head[jj * s..(jj + 1) * s]) {
                    *d -= l * r;
                }
            }
            j = parent::<VB>(model, jj);
        }
    }
}

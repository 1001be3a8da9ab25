//! The scalar type the algorithms are written over.
//!
//! Every algorithm is written once, generic over [`Real`], and instantiated twice:
//!
//! * `f64` — one state (the single-call path);
//! * [`F64x4`], [`F64x8`] — 4 or 8 states side by side, one per lane (the batch path).
//!   Each arithmetic operation acts lane-wise on plain `[f64; N]` arrays, which LLVM
//!   turns into SIMD instructions (SSE2, AVX2 or AVX-512 registers depending on what
//!   the batch kernel is compiled for, see `batch.rs`).
//!
//! Both instantiations perform exactly the same IEEE operations in the same order (no
//! fused multiply-add: Rust never contracts `a * b + c`), so a state computed in a lane
//! of a batch is bit-for-bit the state computed alone. The sine and cosine are ours
//! ([`sin_cos`]) for the same reason: one polynomial evaluated lane-wise or alone gives
//! the same bits, and it vectorises where a libm call would not.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real number, or several evaluated in lock-step (one per SIMD lane).
pub trait Real:
    Copy
    + Send
    + Sync
    + Default
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + 'static
{
    /// Number of lanes (states) held.
    const LANES: usize;
    /// The same value in every lane.
    fn splat(x: f64) -> Self;
    /// Sine and cosine, lane-wise ([`sin_cos`]).
    fn sin_cos(self) -> (Self, Self);
    /// Lane `k` as f64.
    fn lane(self, k: usize) -> f64;
    /// Set lane `k`.
    fn set_lane(&mut self, k: usize, x: f64);
    /// Lane `k` of `*v`, read in place. Same value as `v.lane(k)`; the SIMD types
    /// override it so that a variable `k` is one scalar load from `v`'s memory instead
    /// of a copy of the whole vector to the stack first (the batch transposition).
    #[inline(always)]
    fn lane_of(v: &Self, k: usize) -> f64 {
        v.lane(k)
    }

    #[inline(always)]
    fn zero() -> Self {
        Self::splat(0.0)
    }

    /// Sign, lane-wise: -1, 0 or 1 (sign(0) = 0, as Coulomb friction at rest).
    #[inline(always)]
    fn sign0(self) -> Self {
        let mut out = self;
        for k in 0..Self::LANES {
            let x = self.lane(k);
            out.set_lane(k, if x > 0.0 { 1.0 } else if x < 0.0 { -1.0 } else { 0.0 });
        }
        out
    }
}

impl Real for f64 {
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        sin_cos(self)
    }
    #[inline(always)]
    fn lane(self, _k: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn set_lane(&mut self, _k: usize, x: f64) {
        *self = x
    }
}

/// Defines a lane type: `N` f64 values, one per state, operated on lane-wise with plain
/// loops over arrays that LLVM turns into SIMD instructions.
macro_rules! lanes_type {
    ($(#[$doc:meta])* $name:ident, $n:literal, $align:literal, [$($i:literal)*]) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        #[repr(C, align($align))]
        pub struct $name(pub [f64; $n]);

        impl Default for $name {
            #[inline(always)]
            fn default() -> Self {
                $name([0.0; $n])
            }
        }

        lanewise!($name, [$($i)*], Add, add, +, AddAssign, add_assign);
        lanewise!($name, [$($i)*], Sub, sub, -, SubAssign, sub_assign);
        lanewise!($name, [$($i)*], Mul, mul, *, MulAssign, mul_assign);
        lanewise!($name, [$($i)*], Div, div, /);

        impl Neg for $name {
            type Output = $name;
            #[inline(always)]
            fn neg(self) -> $name {
                $name([$(-self.0[$i]),*])
            }
        }

        impl Real for $name {
            const LANES: usize = $n;
            #[inline(always)]
            fn splat(x: f64) -> Self {
                $name([x; $n])
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                let x = self.0;
                // The polynomial in every lane (straight-line code that vectorises, see
                // `sin_cos_kernel`), then libm for any lane out of its range.
                let (mut s, mut c) = ([0.0; $n], [0.0; $n]);
                for k in 0..$n {
                    (s[k], c[k]) = sin_cos_kernel(x[k]);
                }
                if x.iter().any(|&v| beyond_kernel(v)) {
                    for k in 0..$n {
                        if beyond_kernel(x[k]) {
                            (s[k], c[k]) = x[k].sin_cos();
                        }
                    }
                }
                ($name(s), $name(c))
            }
            #[inline(always)]
            fn lane(self, k: usize) -> f64 {
                self.0[k]
            }
            #[inline(always)]
            fn set_lane(&mut self, k: usize, x: f64) {
                self.0[k] = x
            }
            #[inline(always)]
            fn lane_of(v: &Self, k: usize) -> f64 {
                v.0[k]
            }
        }
    };
}

/// The operator `$op` lane by lane, written out lane by lane (`[$i]` lists the lanes):
/// a `for` loop per operation left thousands of tiny loops in each batch kernel, and
/// LLVM's loop passes over them were most of the core's compile time.
macro_rules! lanewise {
    ($name:ident, [$($i:literal)*], $tr:ident, $f:ident, $op:tt $(, $tra:ident, $fa:ident)?) => {
        impl $tr for $name {
            type Output = $name;
            #[inline(always)]
            fn $f(self, o: $name) -> $name {
                $name([$(self.0[$i] $op o.0[$i]),*])
            }
        }
        $(impl $tra for $name {
            #[inline(always)]
            fn $fa(&mut self, o: $name) {
                *self = *self $op o;
            }
        })?
    };
}

lanes_type!(
    /// Four states: one AVX register, or two SSE2 registers.
    F64x4, 4, 32, [0 1 2 3]
);
lanes_type!(
    /// Eight states: one AVX-512 register.
    F64x8, 8, 64, [0 1 2 3 4 5 6 7]
);

/// Whether `x` is outside the range of `sin_cos_kernel` (NaN included).
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn beyond_kernel(x: f64) -> bool {
    !(x.abs() <= SIN_COS_MAX_ARG)
}

/// Largest |x| for which [`sin_cos`] uses its own polynomial (beyond, libm's).
/// The reduction below is exact while |j| = |x| / (pi/2) < 2^29.
pub const SIN_COS_MAX_ARG: f64 = 1.0e8;

/// `(sin x, cos x)` to about 1 ulp.
///
/// Reduce `x = j pi/2 + r` with the nearest integer `j` and a three-part Cody-Waite
/// split of pi/2 (each part has at most 24 significant bits, so `j * DP1` and `j * DP2`
/// are exact for |j| < 2^29), evaluate the Taylor polynomials of sine (degree 17) and
/// cosine (degree 16) on |r| <= pi/4 (truncation error < 1e-19), and pick and sign them
/// by `j mod 4`. For |x| > 1e8 (or not finite) libm's `sin_cos` is used instead, in the
/// scalar and lane-wise paths alike.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= SIN_COS_MAX_ARG {
        sin_cos_kernel(x)
    } else {
        x.sin_cos()
    }
}

/// The polynomial part of [`sin_cos`], valid for |x| <= `SIN_COS_MAX_ARG`.
/// Branch-free (the selects compile to blends) so that the lane-wise loop vectorises.
#[inline(always)]
fn sin_cos_kernel(x: f64) -> (f64, f64) {
    const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
    const DP1: f64 = 1.570796251296997;
    const DP2: f64 = 7.549789415861596e-08;
    const DP3: f64 = 5.390302858158119e-15;
    // 1.5 * 2^52: adding and subtracting it rounds to the nearest integer (ties to even)
    // with plain additions, and leaves that integer in the low mantissa bits.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let t = x * TWO_OVER_PI + ROUND;
    let quadrant = t.to_bits(); // low bits: j mod 2^k (two's complement)
    let j = t - ROUND;
    let r = ((x - j * DP1) - j * DP2) - j * DP3;
    let z = r * r;
    // (-1)^k / (2k+1)! and (-1)^k / (2k)!
    let ps = r
        + r * z
            * (-0.16666666666666666
                + z * (0.008333333333333333
                    + z * (-0.0001984126984126984
                        + z * (2.7557319223985893e-06
                            + z * (-2.505210838544172e-08
                                + z * (1.6059043836821613e-10
                                    + z * (-7.647163731819816e-13 + z * 2.8114572543455206e-15)))))));
    let pc = (1.0 - 0.5 * z)
        + z * z
            * (0.041666666666666664
                + z * (-0.001388888888888889
                    + z * (2.48015873015873e-05
                        + z * (-2.755731922398589e-07
                            + z * (2.08767569878681e-09
                                + z * (-1.1470745597729725e-11 + z * 4.779477332387385e-14))))));
    // sin x = [s, c, -s, -c][j mod 4], cos x = [c, -s, -c, s][j mod 4].
    let swap = quadrant & 1 == 1;
    let (s, c) = if swap { (pc, ps) } else { (ps, pc) };
    let sin_sign = (quadrant & 2) << 62;
    let cos_sign = (quadrant.wrapping_add(1) & 2) << 62;
    (f64::from_bits(s.to_bits() ^ sin_sign), f64::from_bits(c.to_bits() ^ cos_sign))
}

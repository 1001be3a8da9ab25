//! Featherstone's spatial algebra (Featherstone, *Rigid Body Dynamics Algorithms*, 2008,
//! ch. 2; "RBDA" below), on small fixed-size structs.
//!
//! Spatial vectors are `[angular; linear]`: a motion is `[w; v]` (angular velocity, and
//! the linear velocity of the body-fixed point at the frame's origin), a force is
//! `[n; f]` (moment about the frame's origin, and the resultant force).
//!
//! Why hand-written structs rather than nalgebra: the algorithms touch 3-vectors,
//! 3x3 rotations and 6x6 symmetric blocks only, always of the same sizes; writing the
//! few operations out (cross products, `E^T S E`, Featherstone's inertia transforms)
//! keeps them readable next to the book's formulas, lets them be generic over the
//! lane type [`Real`] (one state, or 4 or 8 in SIMD lanes) and exploits structure
//! (symmetric blocks, axis-aligned joints) that a general matrix type would not.

mod force;
mod inertia;
mod motion;
mod transform;

pub use force::Force;
pub use inertia::{ArticulatedInertia, RigidInertia};
pub use motion::Motion;
pub use transform::Xform;

use crate::real::Real;
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// A 3-vector.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct V3<T> {
    pub x: T,
    pub y: T,
    pub z: T,
}

impl<T: Real> V3<T> {
    #[inline(always)]
    pub fn new(x: T, y: T, z: T) -> Self {
        V3 { x, y, z }
    }
    #[inline(always)]
    pub fn zero() -> Self {
        V3::new(T::zero(), T::zero(), T::zero())
    }
    /// Broadcast an f64 vector to every lane.
    #[inline(always)]
    pub fn splat(v: V3<f64>) -> Self {
        V3::new(T::splat(v.x), T::splat(v.y), T::splat(v.z))
    }
    #[inline(always)]
    pub fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// `self x o`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        V3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    #[inline(always)]
    pub fn scale(self, s: T) -> Self {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
    #[inline(always)]
    pub fn to_array(self) -> [T; 3] {
        [self.x, self.y, self.z]
    }
    #[inline(always)]
    pub fn from_array(a: [T; 3]) -> Self {
        V3::new(a[0], a[1], a[2])
    }
}

impl<T: Real> Add for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl<T: Real> Sub for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl<T: Real> Neg for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3::new(-self.x, -self.y, -self.z)
    }
}
impl<T: Real> AddAssign for V3<T> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<T: Real> SubAssign for V3<T> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}

/// A 3x3 matrix, stored by rows.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct M3<T> {
    pub rows: [V3<T>; 3],
}

impl<T: Real> M3<T> {
    #[inline(always)]
    pub fn from_rows(r0: V3<T>, r1: V3<T>, r2: V3<T>) -> Self {
        M3 { rows: [r0, r1, r2] }
    }
    #[inline(always)]
    pub fn identity() -> Self {
        let (o, z) = (T::splat(1.0), T::zero());
        M3::from_rows(V3::new(o, z, z), V3::new(z, o, z), V3::new(z, z, o))
    }
    #[inline(always)]
    pub fn zero() -> Self {
        M3::from_rows(V3::zero(), V3::zero(), V3::zero())
    }
    #[inline(always)]
    pub fn splat(m: M3<f64>) -> Self {
        M3::from_rows(V3::splat(m.rows[0]), V3::splat(m.rows[1]), V3::splat(m.rows[2]))
    }
    /// Element `(i, j)`.
    #[inline(always)]
    pub fn at(&self, i: usize, j: usize) -> T {
        self.rows[i].to_array()[j]
    }
    #[inline(always)]
    pub fn from_fn(f: impl Fn(usize, usize) -> T) -> Self {
        M3::from_rows(
            V3::new(f(0, 0), f(0, 1), f(0, 2)),
            V3::new(f(1, 0), f(1, 1), f(1, 2)),
            V3::new(f(2, 0), f(2, 1), f(2, 2)),
        )
    }
    #[inline(always)]
    pub fn col(&self, j: usize) -> V3<T> {
        V3::new(self.at(0, j), self.at(1, j), self.at(2, j))
    }
    #[inline(always)]
    pub fn transpose(&self) -> Self {
        M3::from_rows(self.col(0), self.col(1), self.col(2))
    }
    /// `self * v`.
    #[inline(always)]
    pub fn mul_v(&self, v: V3<T>) -> V3<T> {
        V3::new(self.rows[0].dot(v), self.rows[1].dot(v), self.rows[2].dot(v))
    }
    /// `self^T * v`.
    #[inline(always)]
    pub fn tr_mul_v(&self, v: V3<T>) -> V3<T> {
        let [r0, r1, r2] = self.rows;
        r0.scale(v.x) + r1.scale(v.y) + r2.scale(v.z)
    }
    /// `self * o`.
    #[inline(always)]
    pub fn mul_m(&self, o: &Self) -> Self {
        M3::from_rows(o.tr_mul_v(self.rows[0]), o.tr_mul_v(self.rows[1]), o.tr_mul_v(self.rows[2]))
    }
    /// The cross-product matrix: `skew(v) * w == v x w`.
    #[inline(always)]
    pub fn skew(v: V3<T>) -> Self {
        let z = T::zero();
        M3::from_rows(V3::new(z, -v.z, v.y), V3::new(v.z, z, -v.x), V3::new(-v.y, v.x, z))
    }
    /// `a b^T`.
    #[inline(always)]
    pub fn outer(a: V3<T>, b: V3<T>) -> Self {
        M3::from_rows(b.scale(a.x), b.scale(a.y), b.scale(a.z))
    }
    #[inline(always)]
    pub fn scale(&self, s: T) -> Self {
        M3::from_rows(self.rows[0].scale(s), self.rows[1].scale(s), self.rows[2].scale(s))
    }
}

impl<T: Real> Add for M3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        M3::from_rows(self.rows[0] + o.rows[0], self.rows[1] + o.rows[1], self.rows[2] + o.rows[2])
    }
}
impl<T: Real> Sub for M3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        M3::from_rows(self.rows[0] - o.rows[0], self.rows[1] - o.rows[1], self.rows[2] - o.rows[2])
    }
}
impl<T: Real> Mul<V3<T>> for M3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn mul(self, v: V3<T>) -> V3<T> {
        self.mul_v(v)
    }
}

/// A symmetric 3x3 matrix, its 6 distinct elements.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
pub struct Sym3<T> {
    pub xx: T,
    pub yy: T,
    pub zz: T,
    pub xy: T,
    pub xz: T,
    pub yz: T,
}

impl<T: Real> Sym3<T> {
    #[inline(always)]
    pub fn zero() -> Self {
        let z = T::zero();
        Sym3 { xx: z, yy: z, zz: z, xy: z, xz: z, yz: z }
    }
    #[inline(always)]
    pub fn splat(s: Sym3<f64>) -> Self {
        Sym3 {
            xx: T::splat(s.xx),
            yy: T::splat(s.yy),
            zz: T::splat(s.zz),
            xy: T::splat(s.xy),
            xz: T::splat(s.xz),
            yz: T::splat(s.yz),
        }
    }
    /// The upper triangle of `m` (assumed symmetric).
    #[inline(always)]
    pub fn from_m3(m: &M3<T>) -> Self {
        Sym3 { xx: m.at(0, 0), yy: m.at(1, 1), zz: m.at(2, 2), xy: m.at(0, 1), xz: m.at(0, 2), yz: m.at(1, 2) }
    }
    #[inline(always)]
    pub fn to_m3(&self) -> M3<T> {
        M3::from_rows(
            V3::new(self.xx, self.xy, self.xz),
            V3::new(self.xy, self.yy, self.yz),
            V3::new(self.xz, self.yz, self.zz),
        )
    }
    #[inline(always)]
    pub fn mul_v(&self, v: V3<T>) -> V3<T> {
        V3::new(
            self.xx * v.x + self.xy * v.y + self.xz * v.z,
            self.xy * v.x + self.yy * v.y + self.yz * v.z,
            self.xz * v.x + self.yz * v.y + self.zz * v.z,
        )
    }
    /// Column (= row) `j`.
    #[inline(always)]
    pub fn col(&self, j: usize) -> V3<T> {
        match j {
            0 => V3::new(self.xx, self.xy, self.xz),
            1 => V3::new(self.xy, self.yy, self.yz),
            _ => V3::new(self.xz, self.yz, self.zz),
        }
    }
    /// `E^T S E`: for `E` taking A coordinates to B coordinates and `S` in B's axes,
    /// the same tensor in A's axes.
    #[inline(always)]
    pub fn rotate_tr(&self, e: &M3<T>) -> Self {
        // (S E) column by column, then E^T (S E), upper triangle only.
        let se = [self.mul_v(e.col(0)), self.mul_v(e.col(1)), self.mul_v(e.col(2))];
        let ec = [e.col(0), e.col(1), e.col(2)];
        Sym3 {
            xx: ec[0].dot(se[0]),
            yy: ec[1].dot(se[1]),
            zz: ec[2].dot(se[2]),
            xy: ec[0].dot(se[1]),
            xz: ec[0].dot(se[2]),
            yz: ec[1].dot(se[2]),
        }
    }
    /// `a b^T + b a^T`.
    #[inline(always)]
    pub fn sym_outer(a: V3<T>, b: V3<T>) -> Self {
        Sym3 {
            xx: a.x * b.x + a.x * b.x,
            yy: a.y * b.y + a.y * b.y,
            zz: a.z * b.z + a.z * b.z,
            xy: a.x * b.y + b.x * a.y,
            xz: a.x * b.z + b.x * a.z,
            yz: a.y * b.z + b.y * a.z,
        }
    }
    /// `a a^T * s`.
    #[inline(always)]
    pub fn outer_scaled(a: V3<T>, s: T) -> Self {
        let sa = a.scale(s);
        Sym3 { xx: sa.x * a.x, yy: sa.y * a.y, zz: sa.z * a.z, xy: sa.x * a.y, xz: sa.x * a.z, yz: sa.y * a.z }
    }
    /// `self + d I`.
    #[inline(always)]
    pub fn add_diag(&self, d: T) -> Self {
        Sym3 { xx: self.xx + d, yy: self.yy + d, zz: self.zz + d, ..*self }
    }
}

impl<T: Real> Add for Sym3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Sym3 {
            xx: self.xx + o.xx,
            yy: self.yy + o.yy,
            zz: self.zz + o.zz,
            xy: self.xy + o.xy,
            xz: self.xz + o.xz,
            yz: self.yz + o.yz,
        }
    }
}
impl<T: Real> Sub for Sym3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Sym3 {
            xx: self.xx - o.xx,
            yy: self.yy - o.yy,
            zz: self.zz - o.zz,
            xy: self.xy - o.xy,
            xz: self.xz - o.xz,
            yz: self.yz - o.yz,
        }
    }
}

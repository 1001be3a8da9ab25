//! The configuration manifold of a model: how `q` moves along a velocity `xi`
//! (`q (+) xi`, Pinocchio's `integrate`), the velocity between two configurations
//! (`q1 (-) q0 = log(q0^-1 q1)`, Pinocchio's `difference`) and the brackets of its Lie
//! algebra, for the integrators and controllers of [`crate::algo::integrate_floating`].
//!
//! `q` is a product of groups, one *block* per non-flat piece, the rest flat:
//! * a floating base and free joints on SE(3): position then unit quaternion (7),
//!   twist (linear, angular) in the moving frame (6); `M' = M exp(xi)`;
//! * spherical joints on SO(3): unit quaternion (4), angular velocity in the moving
//!   frame (3); `quat' = quat exp(w)`;
//! * planar joints on SE(2): `x, y, cos, sin` (4), `vx, vy, wz` in the moving frame (3);
//!   `M' = M exp(xi)` (as Pinocchio's `JointModelPlanar`);
//! * 1-dof joints add: `q' = q + xi`.
//!
//! Quaternions are renormalised and kept on the side (sign) of the one they start from;
//! a planar joint's `(cos, sin)` is renormalised. The same maps as
//! `armdyn.configuration.integrate`.
//!
//! so(3) and se(2) are subalgebras of se(3) (`(0, w)` and `(vx, vy, 0, 0, 0, wz)`):
//! their brackets are se(3)'s restricted, so one bracket serves every block.

use crate::joint_multi::MultiKind;
use crate::model::{BodyMotion, Model};
use crate::real::Real;
use std::ops::Range;

/// Below this rotation angle (rad) the series of the exponentials are used (their closed
/// forms divide 0 by 0 at 0), as in `armdyn.configuration`.
const SMALL: f64 = 1e-4;

type V3 = [f64; 3];

fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Hamilton product of quaternions `x, y, z, w`.
fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let c = cross([a[0], a[1], a[2]], [b[0], b[1], b[2]]);
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    [
        a[3] * b[0] + b[3] * a[0] + c[0],
        a[3] * b[1] + b[3] * a[1] + c[1],
        a[3] * b[2] + b[3] * a[2] + c[2],
        a[3] * b[3] - dot,
    ]
}

/// `R(quat) x` for a unit quaternion `x, y, z, w`.
fn rotate(quat: [f64; 4], x: V3) -> V3 {
    let v = [quat[0], quat[1], quat[2]];
    let t = cross(v, x).map(|c| 2.0 * c);
    let vt = cross(v, t);
    [0, 1, 2].map(|k| x[k] + quat[3] * t[k] + vt[k])
}

/// `quat0 exp(w)` with `exp(w) = (sin(t/2) w / t, cos(t/2))`, `t = |w|`, given `s =
/// sin(t/2) / t`: renormalised, on `quat0`'s side.
#[inline(always)]
fn turn(quat0: [f64; 4], w: V3, theta: f64, s: f64) -> [f64; 4] {
    let e = [w[0] * s, w[1] * s, w[2] * s, (0.5 * theta).cos()];
    let quat = quat_mul(quat0, e);
    let side: f64 = (0..4).map(|k| quat[k] * quat0[k]).sum();
    let norm = (0..4).map(|k| quat[k] * quat[k]).sum::<f64>().sqrt();
    let scale = if side < 0.0 { -1.0 / norm } else { 1.0 / norm };
    quat.map(|c| c * scale)
}

/// SE(3): `out[..7]` = the pose `q[..7]` (position, quaternion) times `exp(xi[..6])`.
#[inline(always)]
pub(crate) fn se3_exp(q: &[f64], xi: &[f64], out: &mut [f64]) {
    let lin = [xi[0], xi[1], xi[2]];
    let w = [xi[3], xi[4], xi[5]];
    let theta = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let t2 = theta * theta;
    // V(w) = 1 + a [w]x + b [w]x^2: the translation of exp(xi) is V(w) lin
    let (a, b, s) = if theta < SMALL {
        (0.5 - t2 / 24.0 + t2 * t2 / 720.0, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, 0.5 - t2 / 48.0)
    } else {
        ((1.0 - theta.cos()) / t2, (theta - theta.sin()) / (t2 * theta), (0.5 * theta).sin() / theta)
    };
    let wl = cross(w, lin);
    let wwl = cross(w, wl);
    let p = [0, 1, 2].map(|k| lin[k] + a * wl[k] + b * wwl[k]);
    let quat0 = [q[3], q[4], q[5], q[6]];
    let quat = turn(quat0, w, theta, s);
    let d = rotate(quat0, p);
    for k in 0..3 {
        out[k] = q[k] + d[k];
    }
    out[3..7].copy_from_slice(&quat);
}

/// SO(3): `out[..4]` = the quaternion `q[..4]` times `exp(xi[..3])`.
#[inline(always)]
fn so3_exp(q: &[f64], xi: &[f64], out: &mut [f64]) {
    let w = [xi[0], xi[1], xi[2]];
    let theta = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let s = if theta < SMALL { 0.5 - theta * theta / 48.0 } else { (0.5 * theta).sin() / theta };
    out[..4].copy_from_slice(&turn([q[0], q[1], q[2], q[3]], w, theta, s));
}

/// SE(2): `out[..4]` = the planar pose `q[..4]` (`x, y, cos, sin`) times
/// `exp(xi[..3])` (`vx, vy, wz`), `(cos, sin)` renormalised.
#[inline(always)]
fn se2_exp(q: &[f64], xi: &[f64], out: &mut [f64]) {
    let (c0, s0, th) = (q[2], q[3], xi[2]);
    let t2 = th * th;
    // V(th) = [[a, -b], [b, a]]: the translation of exp(xi) is V (vx, vy)
    let (a, b) = if th.abs() < SMALL {
        (1.0 - t2 / 6.0 + t2 * t2 / 120.0, th * (0.5 - t2 / 24.0 + t2 * t2 / 720.0))
    } else {
        (th.sin() / th, (1.0 - th.cos()) / th)
    };
    let (tx, ty) = (a * xi[0] - b * xi[1], b * xi[0] + a * xi[1]);
    let (c1, s1) = (th.cos(), th.sin());
    let (c, s) = (c0 * c1 - s0 * s1, s0 * c1 + c0 * s1);
    let norm = (c * c + s * s).sqrt();
    out[0] = q[0] + c0 * tx - s0 * ty;
    out[1] = q[1] + s0 * tx + c0 * ty;
    out[2] = c / norm;
    out[3] = s / norm;
}

/// `w` with `exp([w]x) = R(quat)` for a unit quaternion `x, y, z, w`, `|w|` in `[0, pi]`
/// (the shorter way round).
fn log_quaternion(quat: [f64; 4]) -> V3 {
    let quat = if quat[3] < 0.0 { quat.map(|c| -c) } else { quat };
    let s = (quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2]).sqrt();
    let scale = if s < 1e-8 { 2.0 / quat[3] } else { 2.0 * s.atan2(quat[3]) / s };
    [quat[0] * scale, quat[1] * scale, quat[2] * scale]
}

/// The conjugate (inverse) of a unit quaternion.
fn conjugate(quat: [f64; 4]) -> [f64; 4] {
    [-quat[0], -quat[1], -quat[2], quat[3]]
}

/// SO(3): `out[..3] = log(q0^-1 q1)` for quaternions `q0[..4]`, `q1[..4]`.
fn so3_log(q0: &[f64], q1: &[f64], out: &mut [f64]) {
    let rel = quat_mul(conjugate([q0[0], q0[1], q0[2], q0[3]]), [q1[0], q1[1], q1[2], q1[3]]);
    out[..3].copy_from_slice(&log_quaternion(rel));
}

/// SE(3): `out[..6] = log(M0^-1 M1)` (linear, angular) for poses `q0[..7]`, `q1[..7]`.
fn se3_log(q0: &[f64], q1: &[f64], out: &mut [f64]) {
    let inv0 = conjugate([q0[3], q0[4], q0[5], q0[6]]);
    let p = rotate(inv0, [q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]]);
    let w = log_quaternion(quat_mul(inv0, [q1[3], q1[4], q1[5], q1[6]]));
    let theta = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    // V(w)^-1 = 1 - [w]x / 2 + c [w]x^2, c = (1 - (t/2) cot(t/2)) / t^2
    let c = if theta < SMALL {
        1.0 / 12.0 + theta * theta / 720.0
    } else {
        (1.0 - 0.5 * theta / (0.5 * theta).tan()) / (theta * theta)
    };
    let wp = cross(w, p);
    let wwp = cross(w, wp);
    for k in 0..3 {
        out[k] = p[k] - 0.5 * wp[k] + c * wwp[k];
        out[3 + k] = w[k];
    }
}

/// SE(2): `out[..3] = log(M0^-1 M1)` (`vx, vy, wz`) for planar poses `q0[..4]`,
/// `q1[..4]`; the turn in `(-pi, pi]`.
fn se2_log(q0: &[f64], q1: &[f64], out: &mut [f64]) {
    let (c0, s0, c1, s1) = (q0[2], q0[3], q1[2], q1[3]);
    let th = (c0 * s1 - s0 * c1).atan2(c0 * c1 + s0 * s1);
    let (dx, dy) = (q1[0] - q0[0], q1[1] - q0[1]);
    let (tx, ty) = (c0 * dx + s0 * dy, c0 * dy - s0 * dx);
    // V(th)^-1 = [[e, th / 2], [-th / 2, e]], e = (th / 2) cot(th / 2)
    let t2 = th * th;
    let e = if th.abs() < SMALL { 1.0 - t2 / 12.0 - t2 * t2 / 720.0 } else { 0.5 * th / (0.5 * th).tan() };
    out[0] = e * tx + 0.5 * th * ty;
    out[1] = e * ty - 0.5 * th * tx;
    out[2] = th;
}

/// The group of a block of `q`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    Se3,
    So3,
    Se2,
}

impl Group {
    fn of(kind: MultiKind) -> Group {
        match kind {
            MultiKind::Free => Group::Se3,
            MultiKind::Spherical => Group::So3,
            MultiKind::Planar => Group::Se2,
        }
    }

    /// The block's configuration and velocity widths.
    fn widths(self) -> (usize, usize) {
        match self {
            Group::Se3 => (7, 6),
            Group::So3 | Group::Se2 => (4, 3),
        }
    }

    /// Where the block's velocity coordinates sit in se(3)'s (linear, angular).
    fn embedding(self) -> &'static [usize] {
        match self {
            Group::Se3 => &[0, 1, 2, 3, 4, 5],
            Group::So3 => &[3, 4, 5],
            Group::Se2 => &[0, 1, 5],
        }
    }

    /// `out = q exp(xi)` on the block (`q`, `out` its configuration, `xi` its velocity).
    #[inline(always)]
    fn exp(self, q: &[f64], xi: &[f64], out: &mut [f64]) {
        match self {
            Group::Se3 => se3_exp(q, xi, out),
            Group::So3 => so3_exp(q, xi, out),
            Group::Se2 => se2_exp(q, xi, out),
        }
    }

    /// `out = log(q0^-1 q1)` on the block (`q0`, `q1` its configurations, `out` its
    /// velocity).
    fn log(self, q0: &[f64], q1: &[f64], out: &mut [f64]) {
        match self {
            Group::Se3 => se3_log(q0, q1, out),
            Group::So3 => so3_log(q0, q1, out),
            Group::Se2 => se2_log(q0, q1, out),
        }
    }

    /// The velocity coordinates' ranges of the block's `q` (relative): what each is read
    /// from, for the finite checks.
    fn q_of_v(self, m: usize) -> Range<usize> {
        match (self, m) {
            (Group::Se3, 0..=2) | (Group::Se2, 0..=1) => m..m + 1,
            (Group::Se3, _) => 3..7,
            (Group::So3, _) => 0..4,
            (Group::Se2, _) => 2..4,
        }
    }
}

/// A block of `q` on a group: its group and first indices in `q` and in `v`.
#[derive(Clone, Copy, Debug)]
struct Block {
    group: Group,
    iq: usize,
    iv: usize,
}

/// The configuration manifold of a model, with or without a floating base (its block
/// first): widths `(nq, nv)`, the blocks and the flat coordinates.
#[derive(Clone, Debug)]
pub struct Manifold {
    pub nq: usize,
    pub nv: usize,
    blocks: Vec<Block>,
    /// The 1-dof coordinates: `(index in q, index in v)`.
    flat: Vec<(usize, usize)>,
    /// Per velocity coordinate, the coordinates of `q` it moves.
    q_of_v: Vec<Range<usize>>,
}

impl Manifold {
    /// The manifold of `model`'s `q` (`floating`: with a floating base's 7 first).
    pub fn new(model: &Model, floating: bool) -> Manifold {
        let (bq, bv) = if floating { (7, 6) } else { (0, 0) };
        let mut m = Manifold { nq: model.nq + bq, nv: model.nv + bv, blocks: vec![], flat: vec![], q_of_v: vec![] };
        if floating {
            m.blocks.push(Block { group: Group::Se3, iq: 0, iv: 0 });
        }
        for j in &model.multi {
            m.blocks.push(Block { group: Group::of(j.kind), iq: bq + j.idx_q, iv: bv + j.body });
        }
        for (i, motion) in model.motion.iter().enumerate() {
            if *motion == BodyMotion::Axis {
                m.flat.push((bq + model.idx_q[i], bv + i));
            }
        }
        m.q_of_v = vec![0..0; m.nv];
        for b in &m.blocks {
            for k in 0..b.group.widths().1 {
                let r = b.group.q_of_v(k);
                m.q_of_v[b.iv + k] = b.iq + r.start..b.iq + r.end;
            }
        }
        for &(iq, iv) in &m.flat {
            m.q_of_v[iv] = iq..iq + 1;
        }
        m
    }

    /// The 1-dof coordinates `(index in q, index in v)`.
    pub fn flat(&self) -> &[(usize, usize)] {
        &self.flat
    }

    /// The coordinates of `q` that velocity coordinate `j` moves.
    pub fn q_of_v(&self, j: usize) -> Range<usize> {
        self.q_of_v[j].clone()
    }

    /// `out = q (+) xi` (the module doc).
    pub fn integrate(&self, q: &[f64], xi: &[f64], out: &mut [f64]) {
        self.integrate_lanes(q, xi, out)
    }

    /// [`Self::integrate`] on lanes: the blocks lane by lane in `f64` (square roots and
    /// sines), the flat coordinates on the lanes.
    #[inline(always)]
    pub fn integrate_lanes<T: Real>(&self, q: &[T], xi: &[T], out: &mut [T]) {
        let (mut qa, mut xa, mut oa) = ([0.0; 7], [0.0; 6], [0.0; 7]);
        for b in &self.blocks {
            let (nq, nv) = b.group.widths();
            for l in 0..T::LANES {
                for k in 0..nq {
                    qa[k] = T::lane_of(&q[b.iq + k], l);
                }
                for k in 0..nv {
                    xa[k] = T::lane_of(&xi[b.iv + k], l);
                }
                b.group.exp(&qa, &xa, &mut oa);
                for k in 0..nq {
                    out[b.iq + k].set_lane(l, oa[k]);
                }
            }
        }
        for &(iq, iv) in &self.flat {
            out[iq] = q[iq] + xi[iv];
        }
    }

    /// `out = q1 (-) q0`: the velocity that moves `q0` to `q1` in unit time, `q0 (+) out
    /// = q1` (Pinocchio's `difference(q0, q1)`): `log(q0^-1 q1)` on every block (in
    /// `q0`'s frame), `q1 - q0` on the flat coordinates. Blocks lane by lane in `f64`.
    #[inline(always)]
    pub fn difference_lanes<T: Real>(&self, q0: &[T], q1: &[T], out: &mut [T]) {
        let (mut a, mut b, mut o) = ([0.0; 7], [0.0; 7], [0.0; 6]);
        for blk in &self.blocks {
            let (nq, nv) = blk.group.widths();
            for l in 0..T::LANES {
                for k in 0..nq {
                    a[k] = T::lane_of(&q0[blk.iq + k], l);
                    b[k] = T::lane_of(&q1[blk.iq + k], l);
                }
                blk.group.log(&a, &b, &mut o);
                for k in 0..nv {
                    out[blk.iv + k].set_lane(l, o[k]);
                }
            }
        }
        for &(iq, iv) in &self.flat {
            out[iv] = q1[iq] - q0[iq];
        }
    }

    /// RK-Munthe-Kaas's rate of the local coordinate, `k = dexp^-1_{-theta}(v) = v +
    /// [theta, v] / 2 + [theta, [theta, v]] / 12` (to fourth order) on every block
    /// with its bracket; `k = v` on the flat coordinates.
    #[inline(always)]
    pub fn local_rate<T: Real>(&self, theta: &[T], v: &[T], k: &mut [T]) {
        let (half, twelfth) = (T::splat(0.5), T::splat(1.0 / 12.0));
        for b in &self.blocks {
            let e = b.group.embedding();
            let (mut x, mut y) = ([T::zero(); 6], [T::zero(); 6]);
            for (m, &c) in e.iter().enumerate() {
                x[c] = theta[b.iv + m];
                y[c] = v[b.iv + m];
            }
            let b1 = bracket(&x, &y);
            let b2 = bracket(&x, &b1);
            for (m, &c) in e.iter().enumerate() {
                k[b.iv + m] = v[b.iv + m] + half * b1[c] + b2[c] * twelfth;
            }
        }
        for &(_, iv) in &self.flat {
            k[iv] = v[iv];
        }
    }
}

/// `a x b` on lanes.
#[inline(always)]
fn cross_lanes<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `[x, y]` in se(3), twists as (linear, angular).
#[inline(always)]
fn bracket<T: Real>(x: &[T], y: &[T]) -> [T; 6] {
    let (rho, om) = ([x[0], x[1], x[2]], [x[3], x[4], x[5]]);
    let (u, w) = ([y[0], y[1], y[2]], [y[3], y[4], y[5]]);
    let (a, b, c) = (cross_lanes(om, u), cross_lanes(rho, w), cross_lanes(om, w));
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], c[0], c[1], c[2]]
}

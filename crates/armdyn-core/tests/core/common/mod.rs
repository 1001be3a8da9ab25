//! Random models and states for the property tests (deterministic xorshift generator).
#![allow(dead_code)]

use armdyn_core::{JointSpec, JointType, Model};

pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(lo, hi)).collect()
    }
    pub fn unit(&mut self) -> [f64; 3] {
        loop {
            let v = [self.uniform(-1.0, 1.0), self.uniform(-1.0, 1.0), self.uniform(-1.0, 1.0)];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.1 && n < 1.0 {
                return [v[0] / n, v[1] / n, v[2] / n];
            }
        }
    }
    /// A random rotation (Rodrigues about a random axis).
    pub fn rotation(&mut self) -> [[f64; 3]; 3] {
        let a = self.unit();
        let t = self.uniform(-3.1, 3.1);
        rodrigues(a, t)
    }
}

pub fn rodrigues(a: [f64; 3], t: f64) -> [[f64; 3]; 3] {
    let (s, c) = t.sin_cos();
    let k = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let kk: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            r[i][j] = if i == j { 1.0 } else { 0.0 } + s * k[i][j] + (1.0 - c) * kk;
        }
    }
    r
}

pub fn matmul3(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// A physically valid inertia tensor about the centre of mass: principal moments
/// satisfying the triangle inequality, rotated randomly.
pub fn random_inertia(rng: &mut Rng) -> [[f64; 3]; 3] {
    let (a, b) = (rng.uniform(0.01, 0.2), rng.uniform(0.01, 0.2));
    let c = rng.uniform((a - b).abs() + 0.005, a + b);
    let r = rng.rotation();
    let mut out = [[0.0; 3]; 3];
    let d = [a, b, c];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
        }
    }
    out
}

/// A random tree of `njoints` joints (some fixed, some prismatic, the rest revolute),
/// with random placements, axes (coordinate or general) and inertias. Every movable
/// joint's subtree has mass, so M is positive definite.
pub fn random_joints(rng: &mut Rng, njoints: usize, branched: bool) -> Vec<JointSpec> {
    let mut joints: Vec<JointSpec> = Vec::new();
    for k in 0..njoints {
        let parent = match (k, branched) {
            (0, _) => None,
            (_, false) => Some(k - 1),
            // any earlier joint's child, or the base
            (_, true) => Some(rng.below(k + 1)).filter(|&p| p < k),
        };
        let jtype = match rng.below(10) {
            0 | 1 => JointType::Fixed,
            2 | 3 => JointType::Prismatic,
            _ => JointType::Revolute,
        };
        let axis = match rng.below(4) {
            0 => [0.0, 0.0, 1.0],
            1 => [1.0, 0.0, 0.0],
            2 => [0.0, -1.0, 0.0],
            _ => rng.unit(),
        };
        joints.push(JointSpec {
            parent,
            jtype,
            rotation: if rng.below(3) == 0 { [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] } else { rng.rotation() },
            translation: [rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)],
            axis,
            mass: rng.uniform(0.5, 3.0),
            com: [rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)],
            inertia: random_inertia(rng),
        });
    }
    joints
}

pub fn random_model(rng: &mut Rng, njoints: usize, branched: bool) -> Model {
    let joints = random_joints(rng, njoints, branched);
    let g = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0), rng.uniform(-10.0, -5.0)];
    Model::new(&joints, g).expect("valid random model")
}

/// Standard DH row (a, alpha, d, theta offset 0) as a revolute joint placement:
/// placement = Rot_x(alpha_{i-1}) style is avoided; we use the form
/// child = Rz(theta) * Tz(d) * Tx(a) * Rx(alpha) split as: placement of joint i+1 in
/// link i = Tz(d_i) Tx(a_i) Rx(alpha_i) (after the z rotation of joint i).
pub fn ur5_joints() -> Vec<JointSpec> {
    let d = [0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823];
    let a = [0.0, -0.425, -0.39225, 0.0, 0.0, 0.0];
    let alpha = [std::f64::consts::FRAC_PI_2, 0.0, 0.0, std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_2, 0.0];
    let mass = [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879];
    let com = [[0.0, -0.02561, 0.00193], [0.2125, 0.0, 0.11336], [0.15, 0.0, 0.0265], [0.0, -0.0018, 0.01634], [0.0, 0.0018, 0.01634], [0.0, 0.0, -0.001159]];
    let mut joints = Vec::new();
    for i in 0..6 {
        // joint i sits at the previous link's DH output frame: placement = Tz(d_{i-1}) Tx(a_{i-1}) Rx(alpha_{i-1})
        let (tr, rot) = if i == 0 {
            ([0.0, 0.0, 0.0], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
        } else {
            let (s, c) = alpha[i - 1].sin_cos();
            ([a[i - 1], 0.0, d[i - 1]], [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
        };
        let m = mass[i];
        let r = 0.05 + 0.01 * i as f64;
        joints.push(JointSpec {
            parent: if i == 0 { None } else { Some(i - 1) },
            jtype: JointType::Revolute,
            rotation: rot,
            translation: tr,
            axis: [0.0, 0.0, 1.0],
            mass: m,
            com: com[i],
            inertia: [[m * r * r, 0.0, 0.0], [0.0, m * r * r, 0.0], [0.0, 0.0, 0.5 * m * r * r]],
        });
    }
    joints
}

/// Largest of `xs`, NaN if any is NaN (`f64::max` would drop a NaN silently).
fn nan_max(xs: impl Iterator<Item = f64>) -> f64 {
    xs.fold(0.0, |m, x| if x.is_nan() || m.is_nan() { f64::NAN } else { m.max(x) })
}

pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    nan_max(a.iter().zip(b).map(|(x, y)| (x - y).abs()))
}

pub fn max_abs(a: &[f64]) -> f64 {
    nan_max(a.iter().map(|x| x.abs()))
}

/// Assert |a - b| <= tol * (1 + max|b|), every entry of both finite. NaN or inf on
/// either side fails: a comparison must never pass on a non-number.
pub fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert!(a.iter().chain(b).all(|x| x.is_finite()), "{what}: non-finite value\n  got {a:?}\n  want {b:?}");
    let err = max_abs_diff(a, b);
    let scale = 1.0 + max_abs(b);
    assert!(err <= tol * scale, "{what}: max error {err:e} (scale {scale:e})\n  got {a:?}\n  want {b:?}");
}

/// `M Minv = I` (n x n, row-major) to `tol` in the max norm.
pub fn assert_inverse(m: &[f64], minv: &[f64], n: usize, tol: f64, what: &str) {
    let mut prod = vec![0.0; n * n];
    let mut eye = vec![0.0; n * n];
    for i in 0..n {
        eye[i * n + i] = 1.0;
        for j in 0..n {
            prod[i * n + j] = (0..n).map(|k| m[i * n + k] * minv[k * n + j]).sum();
        }
    }
    assert_close(&prod, &eye, tol, what);
}

//! Our sine and cosine: within 2 ulp of libm, and lane-wise bit for bit the scalar one.

use armdyn_core::real::*;

fn ulps(a: f64, b: f64) -> f64 {
    ((a - b) / f64::EPSILON).abs()
}

#[test]
fn sin_cos_matches_libm() {
    let mut worst = 0.0f64;
    let mut x = -50.0;
    while x < 50.0 {
        let (s, c) = sin_cos(x);
        let (s0, c0) = x.sin_cos();
        worst = worst.max(ulps(s, s0)).max(ulps(c, c0));
        x += 0.000_731;
    }
    // absolute error in units of 2^-52: values are <= 1
    assert!(worst <= 2.0, "worst {worst}");
    for &x in &[0.0, -0.0, 1e-300, 1e7, -3e7, 9.99e7, 2e8, 1e20] {
        let (s, c) = sin_cos(x);
        let (s0, c0) = x.sin_cos();
        assert!((s - s0).abs() < 1e-7 && (c - c0).abs() < 1e-7, "{x}: {s} {s0} {c} {c0}");
    }
    assert!(sin_cos(f64::NAN).0.is_nan());
    assert!(sin_cos(f64::INFINITY).1.is_nan());
}

#[test]
fn lanes_equal_scalar_bitwise() {
    let xs = [0.3, -2.0, 1e10, 7.5];
    let (s, c) = F64x4(xs).sin_cos();
    for k in 0..4 {
        let (s0, c0) = sin_cos(xs[k]);
        assert_eq!(s.0[k].to_bits(), s0.to_bits());
        assert_eq!(c.0[k].to_bits(), c0.to_bits());
    }
}

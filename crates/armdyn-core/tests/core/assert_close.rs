//! The comparison every identity test relies on must be able to fail: NaN and inf
//! never pass, on either side, wherever they sit in the vector.

use crate::common::assert_close;

#[test]
fn equal_finite_values_pass() {
    assert_close(&[1.0, 2.0, -3.0], &[1.0, 2.0, -3.0], 1e-12, "equal");
}

#[test]
#[should_panic(expected = "non-finite")]
fn nan_in_result_fails() {
    // before: f64::max(0, NaN) = 0, so this passed
    assert_close(&[1.0, f64::NAN, 3.0], &[1.0, 2.0, 3.0], 1e-12, "nan in got");
}

#[test]
#[should_panic(expected = "non-finite")]
fn nan_in_expected_fails() {
    assert_close(&[1.0, 2.0], &[f64::NAN, 2.0], 1e-12, "nan in want");
}

#[test]
#[should_panic(expected = "non-finite")]
fn nan_on_both_sides_fails() {
    assert_close(&[f64::NAN], &[f64::NAN], 1e-12, "nan both");
}

#[test]
#[should_panic(expected = "non-finite")]
fn inf_fails() {
    assert_close(&[f64::INFINITY], &[f64::INFINITY], 1e-12, "inf both");
}

#[test]
#[should_panic(expected = "max error")]
fn a_real_difference_fails() {
    assert_close(&[1.0, 2.0], &[1.0, 2.1], 1e-6, "difference");
}

#[test]
fn max_abs_diff_propagates_nan() {
    assert!(crate::common::max_abs_diff(&[0.0, f64::NAN], &[0.0, 0.0]).is_nan());
    assert!(crate::common::max_abs(&[f64::NAN, 1.0]).is_nan());
}

//! The batch transposition between rows (one state each) and lane vectors.

use armdyn_core::batch_derivatives::{lanes_to_rows, rows_to_lanes};
use armdyn_core::real::{F64x4, F64x8, Real};

/// `rows_to_lanes` against the definition (value `j` of state `l` in lane `l` of
/// vector `j`), and `lanes_to_rows` back to the original rows, for lengths below,
/// at and above a multiple of the lane count (the block transpose and its tail).
fn round_trip<L: Real>() {
    for len in [1, 5, 8, 13, 36, 49] {
        let rows: Vec<f64> = (0..L::LANES * len).map(|i| i as f64 * 0.5 - 3.0).collect();
        let mut lanes = vec![L::zero(); len];
        rows_to_lanes(&rows, &mut lanes, len);
        for l in 0..L::LANES {
            for j in 0..len {
                assert_eq!(lanes[j].lane(l), rows[l * len + j], "len {len}, lane {l}, value {j}");
                assert_eq!(L::lane_of(&lanes[j], l), lanes[j].lane(l));
            }
        }
        // NaN start: an entry left unwritten fails the comparison
        let mut back = vec![f64::NAN; L::LANES * len];
        lanes_to_rows(&lanes, &mut back, len);
        assert_eq!(back, rows, "len {len}");
    }
}

#[test]
fn transposition_f64x8() {
    round_trip::<F64x8>()
}

#[test]
fn transposition_f64x4() {
    round_trip::<F64x4>()
}

#[test]
fn transposition_f64() {
    round_trip::<f64>()
}

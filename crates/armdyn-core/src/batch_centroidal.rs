//! Batches of the world-frame kinematics and centroidal quantities
//! (`algo::floating_kinematics`, `algo::centroidal`): one state per row, rows spread over
//! threads by [`crate::batch`]'s driver, one `f64` workspace per chunk (these algorithms
//! have no SIMD lane version).

use crate::batch::par_rows;
use crate::data::Data;
use crate::model::Model;

/// `f(data, row args, row out)` for every row of a batch: argument `k` has rows of
/// `widths[k]` values, the output rows of `per_row` values; every argument has as many
/// rows as the output.
pub fn rows<const K: usize>(
    model: &Model,
    args: [&[f64]; K],
    widths: [usize; K],
    out: &mut [f64],
    per_row: usize,
    threads: Option<usize>,
    f: impl Fn(&mut Data<f64>, [&[f64]; K], &mut [f64]) + Sync + Send,
) {
    assert!(per_row > 0 && out.len().is_multiple_of(per_row), "output size");
    let n = out.len() / per_row;
    for k in 0..K {
        assert_eq!(args[k].len(), n * widths[k], "argument size");
    }
    par_rows(
        n,
        [out],
        [per_row],
        threads,
        || Data::new(model),
        |d, first, [chunk]| {
            for (r, o) in chunk.chunks_exact_mut(per_row).enumerate() {
                let row = first + r;
                let a: [&[f64]; K] = std::array::from_fn(|k| &args[k][row * widths[k]..(row + 1) * widths[k]]);
                f(d, a, o);
            }
        },
    );
}

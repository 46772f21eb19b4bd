//! Small dense matrix-vector products for the stepper's inner loop (pure): y = M x with M stored
//! column by column, each column padded to `np` rows (a multiple of 4, see [`pad`]).
//!
//! Column-major on purpose: y is a few registers wide (12 DOFs: three AVX registers), each column is
//! scaled by one broadcast x_c and added, so there is no horizontal sum per row (the row-major dot
//! products this replaces ended every row with one) and each loaded matrix entry feeds one
//! multiply-add. Two independent sets of accumulators keep two multiply-add chains per row in flight. The
//! common paddings (4 to 24 rows) are compiled with the row count known, so the accumulators live in
//! registers; larger ones take a plain loop.
//!
//! Each size is its own function compiled for AVX2 + FMA as well as the baseline and chosen at run
//! time (`multiversion`). The accumulators stay in registers only when every loop over them has the
//! compile-time length: a final loop bounded by y's length made LLVM keep them in scalars and shuffle
//! them at every column (three times slower than the row-major products this replaces; measured).

use multiversion::multiversion;
use multiversion::target::target_cfg_f;
use nalgebra::DMatrix;

/// Rows of a padded column: `n` rounded up to a multiple of 4.
pub fn pad(n: usize) -> usize {
    n.div_ceil(4) * 4
}

/// `m`'s columns, each padded with zeros to [`pad`]`(m.nrows())` entries.
pub fn columns(m: &DMatrix<f64>) -> Vec<f64> {
    let np = pad(m.nrows());
    let mut out = vec![0.0; np * m.ncols()];
    for (c, col) in m.column_iter().enumerate() {
        out[c * np..c * np + m.nrows()].copy_from_slice(col.as_slice());
    }
    out
}

/// a b + c, fused when the version is compiled with FMA (shared with [`crate::radiation::modal`]'s kernels).
#[inline(always)]
pub(crate) fn madd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// y[0..y.len()] = (M x)[0..y.len()], M = `cols` (`x.len()` columns of `np` rows), y.len() <= np.
pub fn gemv(np: usize, cols: &[f64], x: &[f64], y: &mut [f64]) {
    match np {
        4 => gemv_np::<4, 8>(cols, x, y),
        8 => gemv_np::<8, 16>(cols, x, y),
        12 => gemv_np::<12, 24>(cols, x, y),
        16 => gemv_np::<16, 32>(cols, x, y),
        20 => gemv_np::<20, 40>(cols, x, y),
        24 => gemv_np::<24, 48>(cols, x, y),
        _ => gemv_any(np, cols, x, y),
    }
}

/// `W` = 2 `NP` accumulators: two independent sets of one column's length, in one array.
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn gemv_np<const NP: usize, const W: usize>(cols: &[f64], x: &[f64], y: &mut [f64]) {
    const FMA: bool = target_cfg_f!(target_feature = "fma");
    let mut acc = [0.0f64; W];
    let m = x.len().min(cols.len() / NP);
    let (cols, x) = (&cols[..m * NP], &x[..m]);
    let (cc, xc) = (cols.chunks_exact(W), x.chunks_exact(W / NP));
    let (cr, xr) = (cc.remainder(), xc.remainder());
    for (cs, xs) in cc.zip(xc) {
        for s in 0..W / NP {
            let xv = xs[s];
            for q in 0..NP {
                acc[s * NP + q] = madd::<FMA>(cs[s * NP + q], xv, acc[s * NP + q]);
            }
        }
    }
    // summed into a whole column first: a loop bounded by y's length made LLVM keep `acc` in scalars
    let mut sum = [0.0f64; NP];
    for (q, sq) in sum.iter_mut().enumerate() {
        *sq = (NP..W).step_by(NP).fold(acc[q], |t, w| t + acc[w + q]);
    }
    let rows = y.len().min(NP);
    y[..rows].copy_from_slice(&sum[..rows]);
    // the odd column, on y itself: folded into the accumulators' loop it spoilt their registers
    for (col, xv) in cr.chunks_exact(NP).zip(xr) {
        for (yq, cq) in y.iter_mut().zip(col) {
            *yq = madd::<FMA>(*cq, *xv, *yq);
        }
    }
}

#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn gemv_any(np: usize, cols: &[f64], x: &[f64], y: &mut [f64]) {
    const FMA: bool = target_cfg_f!(target_feature = "fma");
    let rows = y.len().min(np);
    y.iter_mut().for_each(|v| *v = 0.0);
    for (col, xv) in cols.chunks_exact(np).zip(x) {
        for (yq, cq) in y[..rows].iter_mut().zip(col) {
            *yq = madd::<FMA>(*cq, *xv, *yq);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every padding (the compiled sizes and the plain loop) and column count (whole groups of four and
    /// a remainder) gives M x.
    #[test]
    fn gemv_equals_the_matrix_product() {
        for rows in [1, 3, 4, 6, 7, 12, 13, 24, 25, 31] {
            for ncols in [1, 4, 5, 12, 24, 27] {
                let m = DMatrix::from_fn(rows, ncols, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0 + 0.1 * j as f64);
                let x: Vec<f64> = (0..ncols).map(|j| (j as f64 * 0.7).sin()).collect();
                let want = &m * nalgebra::DVector::from_column_slice(&x);
                let cols = columns(&m);
                let mut y = vec![f64::NAN; rows];
                gemv(pad(rows), &cols, &x, &mut y);
                for i in 0..rows {
                    assert!(
                        (y[i] - want[i]).abs() <= 1e-12 * (1.0 + want[i].abs()),
                        "{rows} x {ncols}, row {i}: {} vs {}",
                        y[i],
                        want[i]
                    );
                }
            }
        }
    }
}

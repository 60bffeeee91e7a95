//! Dense kernels on row-major `p × p` matrices (no allocation).
//!
//! The normal matrix `A = S + λI` is kept as an **upper** Cholesky factor
//! `R` with `A = RᵀR`, stored row-major so that every inner loop below runs
//! along a row (contiguous memory).

/// `R = chol(A + shift·diag(pen))` from the upper triangle of `a` (the
/// lower one is not read); the lower triangle of `r` is zeroed. Returns
/// `false`, leaving `r` unspecified, when a pivot is not positive and finite
/// (then the matrix is not positive definite in floating point).
pub(crate) fn cholesky_upper(a: &[f64], shift: f64, pen: &[f64], r: &mut [f64], p: usize) -> bool {
    for i in 0..p {
        let row = &mut r[i * p..(i + 1) * p];
        row[..i].fill(0.0);
        row[i..].copy_from_slice(&a[i * p + i..(i + 1) * p]);
        row[i] += shift * pen[i];
    }
    // Right-looking (outer-product) form: after step k, row k of R is final
    // and the trailing block holds the Schur complement.
    for k in 0..p {
        let pivot = r[k * p + k];
        if !(pivot > 0.0 && pivot.is_finite()) {
            return false;
        }
        let d = pivot.sqrt();
        let inv = 1.0 / d;
        r[k * p + k] = d;
        for j in k + 1..p {
            r[k * p + j] *= inv;
        }
        let (head, tail) = r.split_at_mut((k + 1) * p);
        let rk = &head[k * p..];
        for i in k + 1..p {
            let rki = rk[i];
            if rki == 0.0 {
                continue;
            }
            let row = &mut tail[(i - k - 1) * p..(i - k) * p];
            for j in i..p {
                row[j] -= rki * rk[j];
            }
        }
    }
    true
}

/// Rank-one update: `R'ᵀR' = RᵀR + uuᵀ`, in O(p²), by Givens rotations of
/// the rows of `[R; uᵀ]` (LINPACK's `dchud`): for each k, the rotation with
/// c = r_kk/h, s = u_k/h, h = hypot(r_kk, u_k), zeroes u_k. |c|, |s| ≤ 1, so
/// nothing is amplified, and the diagonal only grows (r'_kk = h ≥ r_kk): the
/// update never fails and stays backward stable however ill-conditioned `A`
/// is. `u` is overwritten.
pub(crate) fn cholesky_update(r: &mut [f64], u: &mut [f64], p: usize) {
    for k in 0..p {
        let uk = u[k];
        if uk == 0.0 {
            continue;
        }
        let row = &mut r[k * p..(k + 1) * p];
        let rkk = row[k];
        let mut h = (rkk * rkk + uk * uk).sqrt();
        if !(h.is_finite() && h > 0.0) {
            h = rkk.hypot(uk); // only for values beyond 1e154 or below 1e-154
        }
        let c = rkk / h;
        let s = uk / h;
        row[k] = h;
        for j in k + 1..p {
            let rj = row[j];
            let uj = u[j];
            row[j] = c * rj + s * uj;
            u[j] = c * uj - s * rj;
        }
    }
}

/// Solves `Rᵀz = b` in place (forward substitution, row-oriented).
pub(crate) fn solve_rt(r: &[f64], b: &mut [f64], p: usize) {
    for j in 0..p {
        let row = &r[j * p..(j + 1) * p];
        let zj = b[j] / row[j];
        b[j] = zj;
        if zj != 0.0 {
            for k in j + 1..p {
                b[k] -= row[k] * zj;
            }
        }
    }
}

/// Solves `Rx = z` in place (back substitution).
pub(crate) fn solve_r(r: &[f64], z: &mut [f64], p: usize) {
    for k in (0..p).rev() {
        let row = &r[k * p..(k + 1) * p];
        let mut s = z[k];
        for j in k + 1..p {
            s -= row[j] * z[j];
        }
        z[k] = s / row[k];
    }
}

/// Solves `RᵀR x = b` in place.
pub(crate) fn solve(r: &[f64], b: &mut [f64], p: usize) {
    solve_rt(r, b, p);
    solve_r(r, b, p);
}

/// `W = (RᵀR)⁻¹ C` for the `m` columns of the row-major `p × m` matrix `c`,
/// using `col` (p values) as scratch.
pub(crate) fn solve_columns(
    r: &[f64],
    c: &[f64],
    w: &mut [f64],
    col: &mut [f64],
    p: usize,
    m: usize,
) {
    for o in 0..m {
        for i in 0..p {
            col[i] = c[i * m + o];
        }
        solve(r, col, p);
        for i in 0..p {
            w[i * m + o] = col[i];
        }
    }
}

/// Upper triangle of `A ← βA + c·uuᵀ`.
pub(crate) fn sym_update(a: &mut [f64], beta: f64, c: f64, u: &[f64], p: usize) {
    for i in 0..p {
        let cu = c * u[i];
        let row = &mut a[i * p..(i + 1) * p];
        if beta == 1.0 {
            if cu != 0.0 {
                for j in i..p {
                    row[j] += cu * u[j];
                }
            }
        } else {
            for j in i..p {
                row[j] = beta * row[j] + cu * u[j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spd(p: usize, seed: u64) -> Vec<f64> {
        // A = BᵀB + I with a deterministic B.
        let mut s = seed;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % 2000) as f64 / 1000.0 - 1.0
        };
        let b: Vec<f64> = (0..p * p).map(|_| next()).collect();
        let mut a = vec![0.0; p * p];
        for i in 0..p {
            for j in 0..p {
                a[i * p + j] = (0..p).map(|k| b[k * p + i] * b[k * p + j]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 };
            }
        }
        a
    }

    fn rtr(r: &[f64], p: usize) -> Vec<f64> {
        let mut a = vec![0.0; p * p];
        for i in 0..p {
            for j in 0..p {
                a[i * p + j] = (0..p).map(|k| r[k * p + i] * r[k * p + j]).sum();
            }
        }
        a
    }

    fn max_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn factor_update_and_solve() {
        let p = 7;
        let a = spd(p, 99);
        let mut r = vec![0.0; p * p];
        assert!(cholesky_upper(&a, 0.0, &[1.0; 7], &mut r, p));
        assert!(max_diff(&rtr(&r, p), &a) < 1e-12);
        for i in 0..p {
            for j in 0..i {
                assert_eq!(r[i * p + j], 0.0);
            }
        }

        let u: Vec<f64> = (0..p).map(|i| (i as f64 * 0.7).sin()).collect();
        let mut a2 = a.clone();
        for i in 0..p {
            for j in 0..p {
                a2[i * p + j] += u[i] * u[j];
            }
        }
        let mut uu = u.clone();
        cholesky_update(&mut r, &mut uu, p);
        assert!(max_diff(&rtr(&r, p), &a2) < 1e-12);

        let b: Vec<f64> = (0..p).map(|i| i as f64 - 2.0).collect();
        let mut x = b.clone();
        solve(&r, &mut x, p);
        let ax: Vec<f64> = (0..p)
            .map(|i| (0..p).map(|j| a2[i * p + j] * x[j]).sum())
            .collect();
        assert!(max_diff(&ax, &b) < 1e-11);
    }

    #[test]
    fn refuses_an_indefinite_matrix() {
        let a = [1.0, 2.0, 2.0, 1.0];
        let mut r = [0.0; 4];
        assert!(!cholesky_upper(&a, 0.0, &[1.0; 2], &mut r, 2));
        assert!(cholesky_upper(&a, 2.0, &[1.0; 2], &mut r, 2));
        assert!(!cholesky_upper(&a, 2.0, &[1.0, 0.1], &mut r, 2));
    }
}

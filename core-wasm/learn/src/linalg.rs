//! Dense kernels on row-major `p × p` matrices (no allocation).
//!
//! The normal matrix `A = S + λI` is kept as an **upper** Cholesky factor
//! `R` with `A = RᵀR`, stored row-major so that every inner loop below runs
//! along a row (contiguous memory).
//!
//! The inner loops are the kernels at the end of this file ([`add_scaled`],
//! [`sub_scaled`], [`axpby`], [`rotate`], [`add_scaled_rotate`], [`dot`]).
//! In the wasm build (`simd128`) each has a SIMD128 path, two values per
//! instruction, chosen by [`mosaic_dsp::simd_enabled`]; it gives
//! bit-identical results to the scalar path: the same IEEE operations per
//! element in the same order (no fused multiply-add). [`dot`] sums in four
//! interleaved partial sums in both paths (element `t` goes to sum `t mod 4`,
//! then `(s₀ + s₂) + (s₁ + s₃)`, then the tail in order), so that the back
//! substitution is not one chain of dependent additions; native and wasm
//! builds round alike. (LLVM vectorises the scalar loops too; the explicit
//! paths were 4–6 % faster in V8 at p = 256 and 1024.)

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
            sub_scaled(&mut row[i..], rki, &rk[i..p]);
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
///
/// Also writes `z = R'⁻ᵀu` (p values) in O(p), the forward substitution the
/// gain `A'⁻¹u = R'⁻¹z` needs: the same rotations applied to the extra
/// column `[0; 1]` of `[R 0; uᵀ 1]` give `[R' z; 0 γ]`, and since they are
/// orthogonal, `R'ᵀz = u` (the QR-RLS gain; γ² = 1/(1 + uᵀA⁻¹u)). Rotation k
/// sets z_k = s·γ and γ ← c·γ, from γ = 1.
pub(crate) fn cholesky_update(r: &mut [f64], u: &mut [f64], z: &mut [f64], p: usize) {
    let mut gamma = 1.0;
    for k in 0..p {
        let uk = u[k];
        if uk == 0.0 {
            z[k] = 0.0;
            continue;
        }
        let row = &mut r[k * p..(k + 1) * p];
        let (c, s) = givens(&mut row[k], uk, &mut z[k], &mut gamma);
        rotate(&mut row[k + 1..], &mut u[k + 1..p], c, s);
    }
}

/// The rotation `(c, s)` that zeroes `u_k` against `r_kk`: `r_kk ← h`, and
/// the extra column's `z_k = s·γ`, `γ ← c·γ` (see [`cholesky_update`]).
#[inline(always)]
fn givens(rkk: &mut f64, uk: f64, zk: &mut f64, gamma: &mut f64) -> (f64, f64) {
    let mut h = (*rkk * *rkk + uk * uk).sqrt();
    if !(h.is_finite() && h > 0.0) {
        h = rkk.hypot(uk); // only for values beyond 1e154 or below 1e-154
    }
    let c = *rkk / h;
    let s = uk / h;
    *rkk = h;
    *zk = s * *gamma;
    *gamma *= c;
    (c, s)
}

/// [`sym_update`] with β = 1 and [`cholesky_update`] in one pass over the
/// rows (bit-identical to calling both): row k of the scatter `a` gains
/// `c·δ_k·δ` and row k of `r` is rotated against `u`, in one loop over the
/// columns where both apply.
pub(crate) fn sym_and_cholesky_update(
    a: &mut [f64],
    c: f64,
    delta: &[f64],
    r: &mut [f64],
    u: &mut [f64],
    z: &mut [f64],
    p: usize,
) {
    let mut gamma = 1.0;
    for k in 0..p {
        let cu = c * delta[k];
        let arow = &mut a[k * p + k..(k + 1) * p];
        let uk = u[k];
        if uk == 0.0 {
            z[k] = 0.0;
            if cu != 0.0 {
                add_scaled(arow, cu, &delta[k..p]);
            }
            continue;
        }
        let row = &mut r[k * p..(k + 1) * p];
        let (cr, s) = givens(&mut row[k], uk, &mut z[k], &mut gamma);
        if cu != 0.0 {
            arow[0] += cu * delta[k];
            add_scaled_rotate(
                &mut arow[1..],
                cu,
                &delta[k + 1..p],
                &mut row[k + 1..],
                &mut u[k + 1..p],
                cr,
                s,
            );
        } else {
            rotate(&mut row[k + 1..], &mut u[k + 1..p], cr, s);
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
            sub_scaled(&mut b[j + 1..p], zj, &row[j + 1..]);
        }
    }
}

/// Solves `Rx = z` in place (back substitution; each row's sum by [`dot`]).
pub(crate) fn solve_r(r: &[f64], z: &mut [f64], p: usize) {
    let z = &mut z[..p];
    for k in (0..p).rev() {
        let row = &r[k * p..(k + 1) * p];
        let (head, tail) = z.split_at_mut(k + 1);
        head[k] = (head[k] - dot(&row[k + 1..], tail)) / row[k];
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
        let row = &mut a[i * p + i..(i + 1) * p];
        if beta == 1.0 {
            if cu != 0.0 {
                add_scaled(row, cu, &u[i..p]);
            }
        } else {
            axpby(row, beta, cu, &u[i..p]);
        }
    }
}

/// The most updates [`sym_update_queued`] takes at once.
pub(crate) const SYM_QUEUE: usize = 8;

/// Values of a queue of `δ` vectors for `p` inputs (see [`queue_at`]).
pub(crate) fn queue_size(p: usize) -> usize {
    p.div_ceil(2) * 2 * SYM_QUEUE
}

/// Where `δ_q[j]` of queued update `q` is kept: by pairs of columns, each
/// pair's updates side by side (`δ_0[j], δ_0[j+1], δ_1[j], δ_1[j+1], …` for
/// an even `j`), so that one pass over S reads them in order.
#[inline(always)]
pub(crate) fn queue_at(q: usize, j: usize) -> usize {
    (j / 2) * 2 * SYM_QUEUE + 2 * q + j % 2
}

/// `n = coef.len()` calls of [`sym_update`] in one pass over `a`: update `q`
/// is `A ← β_q A + c_q·δ_qδ_qᵀ`, with `(β_q, c_q) = coef[q]` and `δ_q` in
/// `deltas` ([`queue_at`]). Each element gets the updates in queue order
/// by the same operations (bit-identical), but is loaded and stored once.
///
/// [`sym_update`] skips a row when β = 1 and `c·δ_i = 0`; here such an
/// update adds `±0`, which leaves every value but `−0` as it is. S holds no
/// `−0` unless one was loaded (from +0, sums and products by β > 0 give +0),
/// so `neg_zero` (S may hold one) selects the exact per-element path.
pub(crate) fn sym_update_queued(
    a: &mut [f64],
    coef: &[(f64, f64)],
    deltas: &[f64],
    p: usize,
    neg_zero: bool,
) {
    let n = coef.len();
    let plain = coef.iter().all(|&(beta, _)| beta == 1.0);
    let (mut b, mut cu) = ([1.0; SYM_QUEUE], [0.0; SYM_QUEUE]);
    for (q, &(beta, _)) in coef.iter().enumerate() {
        b[q] = beta;
    }
    if neg_zero {
        for i in 0..p {
            for (j, v) in (i..p).zip(a[i * p + i..(i + 1) * p].iter_mut()) {
                *v = queued_element(*v, coef, deltas, i, j);
            }
        }
        return;
    }
    // By blocks of columns, so that the block's δ (16 KiB) stay in L1 over the rows.
    const BLOCK: usize = 256;
    for j0 in (0..p).step_by(BLOCK) {
        let j1 = (j0 + BLOCK).min(p);
        for i in 0..j1 {
            for (q, &(_, c)) in coef.iter().enumerate() {
                cu[q] = c * deltas[queue_at(q, i)];
            }
            let mut j = i.max(j0);
            let row = &mut a[i * p + j..i * p + j1];
            // An odd first column alone: the rest starts at a pair.
            let row = if j % 2 == 1 {
                let mut v = row[0];
                for q in 0..n {
                    let d = deltas[queue_at(q, j)];
                    v = if plain {
                        v + cu[q] * d
                    } else {
                        b[q] * v + cu[q] * d
                    };
                }
                row[0] = v;
                j += 1;
                &mut row[1..]
            } else {
                row
            };
            let dt = &deltas[queue_at(0, j)..];
            macro_rules! by_count {
                ($($k:literal)*) => {
                    match (n, plain) {
                        $(($k, true) => queued_rows::<$k, true>(row, dt, &b, &cu),
                          ($k, false) => queued_rows::<$k, false>(row, dt, &b, &cu),)*
                        _ => {}
                    }
                };
            }
            by_count!(1 2 3 4 5 6 7 8);
        }
    }
}

/// The `N` queued updates of [`sym_update_queued`] on the part of a row
/// that starts at an even column (`dt`: that column's pair onwards):
/// `v ← v + cu_q·δ_q` (`PLAIN`, all β = 1) or `v ← β_q·v + cu_q·δ_q`.
#[inline(always)]
fn queued_rows<const N: usize, const PLAIN: bool>(
    row: &mut [f64],
    dt: &[f64],
    b: &[f64; SYM_QUEUE],
    cu: &[f64; SYM_QUEUE],
) {
    let done = simd::queued_rows::<N, PLAIN>(row, dt, b, cu);
    for (rc, dc) in row[done..]
        .chunks_mut(2)
        .zip(dt[done * SYM_QUEUE..].chunks_exact(2 * SYM_QUEUE))
    {
        for (l, v) in rc.iter_mut().enumerate() {
            let mut x = *v;
            for q in 0..N {
                let d = dc[2 * q + l];
                x = if PLAIN {
                    x + cu[q] * d
                } else {
                    b[q] * x + cu[q] * d
                };
            }
            *v = x;
        }
    }
}

/// Element `(i, j)`, `i ≤ j`, of `a` after the queued updates of
/// [`sym_update_queued`], by [`sym_update`]'s operations (with its skips).
pub(crate) fn queued_element(
    mut v: f64,
    coef: &[(f64, f64)],
    deltas: &[f64],
    i: usize,
    j: usize,
) -> f64 {
    for (q, &(beta, c)) in coef.iter().enumerate() {
        let cu = c * deltas[queue_at(q, i)];
        let d = deltas[queue_at(q, j)];
        if beta == 1.0 {
            if cu != 0.0 {
                v += cu * d;
            }
        } else {
            v = beta * v + cu * d;
        }
    }
    v
}

/// `y ← y + a·x` (`x` at least as long as `y`).
#[inline]
fn add_scaled(y: &mut [f64], a: f64, x: &[f64]) {
    let x = &x[..y.len()];
    let done = simd::add_scaled(y, a, x);
    for (yj, &xj) in y[done..].iter_mut().zip(&x[done..]) {
        *yj += a * xj;
    }
}

/// `y ← y − a·x` (`x` at least as long as `y`).
#[inline]
fn sub_scaled(y: &mut [f64], a: f64, x: &[f64]) {
    let x = &x[..y.len()];
    let done = simd::sub_scaled(y, a, x);
    for (yj, &xj) in y[done..].iter_mut().zip(&x[done..]) {
        *yj -= a * xj;
    }
}

/// `y ← b·y + a·x` (`x` at least as long as `y`).
#[inline]
fn axpby(y: &mut [f64], b: f64, a: f64, x: &[f64]) {
    let x = &x[..y.len()];
    let done = simd::axpby(y, b, a, x);
    for (yj, &xj) in y[done..].iter_mut().zip(&x[done..]) {
        *yj = b * *yj + a * xj;
    }
}

/// The plane rotation `(x, y) ← (c·x + s·y, c·y − s·x)`, elementwise (`y` at
/// least as long as `x`).
#[inline]
fn rotate(x: &mut [f64], y: &mut [f64], c: f64, s: f64) {
    let y = &mut y[..x.len()];
    let done = simd::rotate(x, y, c, s);
    for (xj, yj) in x[done..].iter_mut().zip(&mut y[done..]) {
        let (a, b) = (*xj, *yj);
        *xj = c * a + s * b;
        *yj = c * b - s * a;
    }
}

/// [`add_scaled`]`(y, a, d)` and [`rotate`]`(x, w, c, s)` in one loop (all
/// of `y`'s length).
#[inline]
fn add_scaled_rotate(
    y: &mut [f64],
    a: f64,
    d: &[f64],
    x: &mut [f64],
    w: &mut [f64],
    c: f64,
    s: f64,
) {
    let n = y.len();
    let (d, x, w) = (&d[..n], &mut x[..n], &mut w[..n]);
    let done = simd::add_scaled_rotate(y, a, d, x, w, c, s);
    for j in done..n {
        y[j] += a * d[j];
        let (xa, wb) = (x[j], w[j]);
        x[j] = c * xa + s * wb;
        w[j] = c * wb - s * xa;
    }
}

/// `Σ xⱼyⱼ` (`y` at least as long as `x`) in four interleaved partial sums,
/// `(s₀ + s₂) + (s₁ + s₃)`, then the `len mod 4` last products in order: the
/// SIMD path holds s₀, s₁ and s₂, s₃ in two registers and rounds identically.
#[inline]
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let y = &y[..x.len()];
    let n4 = x.len() - x.len() % 4;
    let mut t = match simd::dot4(&x[..n4], &y[..n4]) {
        Some(t) => t,
        None => {
            let mut s = [0.0; 4];
            for (xc, yc) in x[..n4].chunks_exact(4).zip(y[..n4].chunks_exact(4)) {
                for l in 0..4 {
                    s[l] += xc[l] * yc[l];
                }
            }
            (s[0] + s[2]) + (s[1] + s[3])
        }
    };
    for (&xj, &yj) in x[n4..].iter().zip(&y[n4..]) {
        t += xj * yj;
    }
    t
}

/// SIMD128 paths of the kernels (wasm32 with `simd128`, while
/// [`mosaic_dsp::simd_enabled`]): two values per `f64x2` instruction, the
/// scalar path's operations per element. Each returns how many leading
/// values it did (an even number; 0 when disabled), the caller does the rest.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod simd {
    use core::arch::wasm32::{
        f64x2, f64x2_add, f64x2_extract_lane, f64x2_mul, f64x2_splat, f64x2_sub, v128,
    };

    /// `s[0]`, `s[1]` (a `v128.load`).
    #[inline(always)]
    fn ld(s: &[f64]) -> v128 {
        f64x2(s[0], s[1])
    }

    /// `s[0]`, `s[1]` ← `v` (a `v128.store`).
    #[inline(always)]
    fn st(s: &mut [f64], v: v128) {
        s[0] = f64x2_extract_lane::<0>(v);
        s[1] = f64x2_extract_lane::<1>(v);
    }

    /// Applies `f` to the pairs of `y` and `x` (equal lengths); values done.
    #[inline(always)]
    fn pairs(y: &mut [f64], x: &[f64], f: impl Fn(v128, v128) -> v128) -> usize {
        if !mosaic_dsp::simd_enabled() {
            return 0;
        }
        for (yc, xc) in y.chunks_exact_mut(2).zip(x.chunks_exact(2)) {
            st(yc, f(ld(yc), ld(xc)));
        }
        y.len() - y.len() % 2
    }

    #[inline]
    pub(super) fn add_scaled(y: &mut [f64], a: f64, x: &[f64]) -> usize {
        let av = f64x2_splat(a);
        pairs(y, x, |yv, xv| f64x2_add(yv, f64x2_mul(av, xv)))
    }

    #[inline]
    pub(super) fn sub_scaled(y: &mut [f64], a: f64, x: &[f64]) -> usize {
        let av = f64x2_splat(a);
        pairs(y, x, |yv, xv| f64x2_sub(yv, f64x2_mul(av, xv)))
    }

    #[inline]
    pub(super) fn axpby(y: &mut [f64], b: f64, a: f64, x: &[f64]) -> usize {
        let (av, bv) = (f64x2_splat(a), f64x2_splat(b));
        pairs(y, x, |yv, xv| {
            f64x2_add(f64x2_mul(bv, yv), f64x2_mul(av, xv))
        })
    }

    #[inline]
    pub(super) fn rotate(x: &mut [f64], y: &mut [f64], c: f64, s: f64) -> usize {
        if !mosaic_dsp::simd_enabled() {
            return 0;
        }
        let (cv, sv) = (f64x2_splat(c), f64x2_splat(s));
        for (xc, yc) in x.chunks_exact_mut(2).zip(y.chunks_exact_mut(2)) {
            let (a, b) = (ld(xc), ld(yc));
            st(xc, f64x2_add(f64x2_mul(cv, a), f64x2_mul(sv, b)));
            st(yc, f64x2_sub(f64x2_mul(cv, b), f64x2_mul(sv, a)));
        }
        x.len() - x.len() % 2
    }

    #[inline]
    pub(super) fn add_scaled_rotate(
        y: &mut [f64],
        a: f64,
        d: &[f64],
        x: &mut [f64],
        w: &mut [f64],
        c: f64,
        s: f64,
    ) -> usize {
        if !mosaic_dsp::simd_enabled() {
            return 0;
        }
        let (av, cv, sv) = (f64x2_splat(a), f64x2_splat(c), f64x2_splat(s));
        for (((yc, dc), xc), wc) in y
            .chunks_exact_mut(2)
            .zip(d.chunks_exact(2))
            .zip(x.chunks_exact_mut(2))
            .zip(w.chunks_exact_mut(2))
        {
            st(yc, f64x2_add(ld(yc), f64x2_mul(av, ld(dc))));
            let (xa, wb) = (ld(xc), ld(wc));
            st(xc, f64x2_add(f64x2_mul(cv, xa), f64x2_mul(sv, wb)));
            st(wc, f64x2_sub(f64x2_mul(cv, wb), f64x2_mul(sv, xa)));
        }
        y.len() - y.len() % 2
    }

    /// [`super::queued_rows`] on the pairs of `row`.
    #[inline(always)]
    pub(super) fn queued_rows<const N: usize, const PLAIN: bool>(
        row: &mut [f64],
        dt: &[f64],
        b: &[f64; super::SYM_QUEUE],
        cu: &[f64; super::SYM_QUEUE],
    ) -> usize {
        if !mosaic_dsp::simd_enabled() {
            return 0;
        }
        let bv: [v128; N] = core::array::from_fn(|q| f64x2_splat(b[q]));
        let cv: [v128; N] = core::array::from_fn(|q| f64x2_splat(cu[q]));
        for (rc, dc) in row
            .chunks_exact_mut(2)
            .zip(dt.chunks_exact(2 * super::SYM_QUEUE))
        {
            let mut v = ld(rc);
            for q in 0..N {
                let d = f64x2_mul(cv[q], ld(&dc[2 * q..]));
                v = if PLAIN {
                    f64x2_add(v, d)
                } else {
                    f64x2_add(f64x2_mul(bv[q], v), d)
                };
            }
            st(rc, v);
        }
        row.len() - row.len() % 2
    }

    /// The four partial sums of [`super::dot`] over `x`, `y` (lengths a
    /// multiple of 4), combined; `None` when disabled.
    #[inline]
    pub(super) fn dot4(x: &[f64], y: &[f64]) -> Option<f64> {
        if !mosaic_dsp::simd_enabled() {
            return None;
        }
        let (mut s01, mut s23) = (f64x2_splat(0.0), f64x2_splat(0.0));
        for (xc, yc) in x.chunks_exact(4).zip(y.chunks_exact(4)) {
            s01 = f64x2_add(s01, f64x2_mul(ld(&xc[..2]), ld(&yc[..2])));
            s23 = f64x2_add(s23, f64x2_mul(ld(&xc[2..]), ld(&yc[2..])));
        }
        let s = f64x2_add(s01, s23);
        Some(f64x2_extract_lane::<0>(s) + f64x2_extract_lane::<1>(s))
    }
}

/// Builds without SIMD128: every kernel runs its scalar path.
#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
mod simd {
    #[inline(always)]
    pub(super) fn add_scaled(_: &mut [f64], _: f64, _: &[f64]) -> usize {
        0
    }

    #[inline(always)]
    pub(super) fn sub_scaled(_: &mut [f64], _: f64, _: &[f64]) -> usize {
        0
    }

    #[inline(always)]
    pub(super) fn axpby(_: &mut [f64], _: f64, _: f64, _: &[f64]) -> usize {
        0
    }

    #[inline(always)]
    pub(super) fn rotate(_: &mut [f64], _: &mut [f64], _: f64, _: f64) -> usize {
        0
    }

    #[inline(always)]
    pub(super) fn add_scaled_rotate(
        _: &mut [f64],
        _: f64,
        _: &[f64],
        _: &mut [f64],
        _: &mut [f64],
        _: f64,
        _: f64,
    ) -> usize {
        0
    }

    #[inline(always)]
    pub(super) fn queued_rows<const N: usize, const PLAIN: bool>(
        _: &mut [f64],
        _: &[f64],
        _: &[f64; super::SYM_QUEUE],
        _: &[f64; super::SYM_QUEUE],
    ) -> usize {
        0
    }

    #[inline(always)]
    pub(super) fn dot4(_: &[f64], _: &[f64]) -> Option<f64> {
        None
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
        let mut z = vec![f64::NAN; p];
        cholesky_update(&mut r, &mut uu, &mut z, p);
        assert!(max_diff(&rtr(&r, p), &a2) < 1e-12);
        // z = R'⁻ᵀu: R'ᵀz reproduces u.
        let rtz: Vec<f64> = (0..p)
            .map(|i| (0..=i).map(|k| r[k * p + i] * z[k]).sum())
            .collect();
        assert!(max_diff(&rtz, &u) < 1e-14);

        let b: Vec<f64> = (0..p).map(|i| i as f64 - 2.0).collect();
        let mut x = b.clone();
        solve(&r, &mut x, p);
        let ax: Vec<f64> = (0..p)
            .map(|i| (0..p).map(|j| a2[i * p + j] * x[j]).sum())
            .collect();
        assert!(max_diff(&ax, &b) < 1e-11);
    }

    #[test]
    fn fused_update_is_the_two_updates() {
        let p = 9;
        let a = spd(p, 7);
        let mut r = vec![0.0; p * p];
        assert!(cholesky_upper(&a, 0.5, &[1.0; 9], &mut r, p));
        // Zeros exercise the rows where only one of the two updates applies.
        let delta: Vec<f64> = (0..p)
            .map(|i| {
                if i % 4 == 2 {
                    0.0
                } else {
                    (i as f64 * 1.3).cos()
                }
            })
            .collect();
        let c: f64 = 0.75;
        let sc = c.sqrt();
        let (mut s1, mut r1) = (a.clone(), r.clone());
        let mut u1: Vec<f64> = delta.iter().map(|d| sc * d).collect();
        let mut z1 = vec![f64::NAN; p];
        sym_update(&mut s1, 1.0, c, &delta, p);
        cholesky_update(&mut r1, &mut u1, &mut z1, p);
        let (mut s2, mut r2) = (a.clone(), r.clone());
        let mut u2: Vec<f64> = delta.iter().map(|d| sc * d).collect();
        let mut z2 = vec![f64::NAN; p];
        sym_and_cholesky_update(&mut s2, c, &delta, &mut r2, &mut u2, &mut z2, p);
        assert_eq!((s1, r1, z1), (s2, r2, z2));
    }

    #[test]
    fn dot_sums_in_four_partial_sums() {
        // Element t goes to partial sum t mod 4, so 1e16 and −1e16 cancel before the 1s are
        // added (in order, 1e16 + 1 would round back to 1e16); a tail shorter than 4 is in order.
        let x = [1e16, 1.0, -1e16, 1.0, 1.0, 1.0];
        let y = [1.0; 6];
        assert_eq!(dot(&x, &y), 4.0);
        assert_eq!(dot(&x[..3], &y), 0.0);
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

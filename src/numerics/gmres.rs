//! GMRES (Saad & Schultz) for A x = b with A known only through products
//! A v, right-preconditioned: it minimises |b − A x| over
//! x ∈ M⁻¹ K_k(A M⁻¹, b), x₀ = 0. The 3-D collocation's Newton–Krylov
//! steps use it with A v a finite difference of the fixed-point sweep
//! and M⁻¹ the factors of an older Jacobian of the same system.
//!
//! The basis is orthogonalised by modified Gram–Schmidt, the small least
//! squares problem by Givens rotations; the preconditioned vectors are
//! kept (flexible GMRES), so the preconditioner is applied once per
//! iteration and may even vary. No restarts: the caller bounds the
//! iterations and falls back on a direct solve when they are spent.
//!
//! Written here rather than taken from a crate: the operator is a
//! fallible closure that runs the solver's own sweep on its state, which
//! the Krylov crates' operator traits (immutable, infallible) do not allow.

/// How a [`gmres`] call ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmresOutcome {
    /// Products A v taken (Krylov iterations).
    pub iterations: usize,
    /// |b − A x| / |b| at the returned x, as the recurrence tracks it
    /// (exact in exact arithmetic; the operator's own errors aside).
    pub relative_residual: f64,
}

/// Solves A x = b to |b − A x| ≤ `tolerance` |b| in at most
/// `max_iterations` products: `operator(v, out)` writes A v into `out`,
/// `precondition(v)` replaces v by M⁻¹ v. Writes the best x found into
/// `x` (also when the tolerance is not reached: see the outcome's
/// residual); an error of the operator ends the call with that error.
pub fn gmres<E>(
    b: &[f64],
    max_iterations: usize,
    tolerance: f64,
    mut operator: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    mut precondition: impl FnMut(&mut [f64]),
    x: &mut [f64],
) -> Result<GmresOutcome, E> {
    let n = b.len();
    x.iter_mut().for_each(|v| *v = 0.0);
    let beta = norm(b);
    if beta == 0.0 || !beta.is_finite() || max_iterations == 0 {
        return Ok(GmresOutcome { iterations: 0, relative_residual: if beta == 0.0 { 0.0 } else { 1.0 } });
    }
    let k_max = max_iterations.min(n);
    // Orthonormal basis of the Krylov space, and its preconditioned vectors.
    let mut v: Vec<Vec<f64>> = vec![b.iter().map(|b| b / beta).collect()];
    let mut z: Vec<Vec<f64>> = Vec::with_capacity(k_max);
    // Hessenberg columns (rotated into upper-triangular form), the rotations and the rotated right side.
    let mut h: Vec<Vec<f64>> = Vec::with_capacity(k_max);
    let mut rotations: Vec<(f64, f64)> = Vec::with_capacity(k_max);
    let mut g = vec![beta];
    let mut w = vec![0.0; n];
    let mut residual = beta;
    let mut k = 0;
    while k < k_max {
        let mut zk = v[k].clone();
        precondition(&mut zk);
        operator(&zk, &mut w)?;
        z.push(zk);
        let mut column = Vec::with_capacity(k + 2);
        for vi in &v {
            let d = dot(&w, vi);
            w.iter_mut().zip(vi).for_each(|(w, v)| *w -= d * v);
            column.push(d);
        }
        let next_norm = norm(&w);
        column.push(next_norm);
        for (i, &(c, s)) in rotations.iter().enumerate() {
            let (a, b) = (column[i], column[i + 1]);
            column[i] = c * a + s * b;
            column[i + 1] = -s * a + c * b;
        }
        let (a, b) = (column[k], column[k + 1]);
        let r = a.hypot(b);
        let (c, s) = if r == 0.0 { (1.0, 0.0) } else { (a / r, b / r) };
        column[k] = r;
        column[k + 1] = 0.0;
        rotations.push((c, s));
        g.push(-s * g[k]);
        g[k] *= c;
        column.truncate(k + 1);
        h.push(column);
        k += 1;
        residual = g[k].abs();
        if !residual.is_finite() || residual <= tolerance * beta || next_norm <= 1e-14 * beta {
            break;
        }
        v.push(w.iter().map(|w| w / next_norm).collect());
    }
    // Back substitution of the rotated Hessenberg system, then x = Σ y_i z_i.
    let mut y = vec![0.0; k];
    for i in (0..k).rev() {
        let s: f64 = ((i + 1)..k).map(|j| h[j][i] * y[j]).sum();
        y[i] = if h[i][i] != 0.0 { (g[i] - s) / h[i][i] } else { 0.0 };
    }
    for (yi, zi) in y.iter().zip(&z) {
        x.iter_mut().zip(zi).for_each(|(x, z)| *x += yi * z);
    }
    Ok(GmresOutcome { iterations: k, relative_residual: residual / beta })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A nonsymmetric, well-conditioned test matrix with a few outlying
    /// eigenvalues (like the fixed-point map's I − G').
    fn matrix(n: usize) -> DMatrix<f64> {
        let mut state = 12345u64;
        let mut random = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        DMatrix::from_fn(n, n, |i, j| if i == j { 2.0 + i as f64 / n as f64 } else { 0.3 * random() / (n as f64).sqrt() })
    }

    fn apply(a: &DMatrix<f64>) -> impl FnMut(&[f64], &mut [f64]) -> Result<(), ()> + '_ {
        move |v, out| {
            out.copy_from_slice((a * DVector::from_column_slice(v)).as_slice());
            Ok(())
        }
    }

    #[test]
    fn it_agrees_with_a_dense_solve() {
        let n = 40;
        let a = matrix(n);
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let exact = a.clone().lu().solve(&DVector::from_column_slice(&b)).unwrap();
        let mut x = vec![0.0; n];
        let outcome = gmres(&b, n, 1e-12, apply(&a), |_| {}, &mut x).unwrap();
        assert!(outcome.relative_residual <= 1e-12, "{outcome:?}");
        assert!(outcome.iterations < n, "{outcome:?}");
        let error = x.iter().zip(exact.iter()).map(|(x, e)| (x - e).abs()).fold(0.0, f64::max);
        assert!(error < 1e-10, "error {error}");
        // The tracked residual is the true one.
        let true_residual = (&a * DVector::from_column_slice(&x) - DVector::from_column_slice(&b)).norm() / DVector::from_column_slice(&b).norm();
        assert!((true_residual - outcome.relative_residual).abs() < 1e-12, "{true_residual} against {outcome:?}");
    }

    #[test]
    fn a_close_preconditioner_converges_in_few_iterations() {
        let n = 60;
        let a = matrix(n);
        // An older operator's factors: A perturbed by 1 %.
        let old = a.map(|v| v * 1.01) + DMatrix::from_fn(n, n, |i, j| if (i + 2 * j) % 7 == 0 { 1e-3 } else { 0.0 });
        let lu = old.lu();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).cos()).collect();
        let exact = a.clone().lu().solve(&DVector::from_column_slice(&b)).unwrap();
        let mut x = vec![0.0; n];
        let precondition = |v: &mut [f64]| {
            let solved = lu.solve(&DVector::from_column_slice(v)).unwrap();
            v.copy_from_slice(solved.as_slice());
        };
        let outcome = gmres(&b, n, 1e-10, apply(&a), precondition, &mut x).unwrap();
        assert!(outcome.iterations <= 5, "{outcome:?}");
        let error = x.iter().zip(exact.iter()).map(|(x, e)| (x - e).abs()).fold(0.0, f64::max);
        assert!(error < 1e-9, "error {error}");
        // Without it the same tolerance takes more products.
        let plain = gmres(&b, n, 1e-10, apply(&a), |_| {}, &mut x).unwrap();
        assert!(plain.iterations > outcome.iterations, "{plain:?} against {outcome:?}");
    }

    #[test]
    fn spent_iterations_return_the_best_iterate_and_errors_pass_through() {
        let n = 30;
        let a = matrix(n);
        let b = vec![1.0; n];
        let mut x = vec![0.0; n];
        let outcome = gmres(&b, 2, 1e-14, apply(&a), |_| {}, &mut x).unwrap();
        assert_eq!(outcome.iterations, 2);
        assert!(outcome.relative_residual > 1e-14 && outcome.relative_residual < 1.0, "{outcome:?}");
        let true_residual = (&a * DVector::from_column_slice(&x) - DVector::from_column_slice(&b)).norm() / (n as f64).sqrt();
        assert!((true_residual - outcome.relative_residual).abs() < 1e-12);
        // A zero right side is solved by zero without a product.
        let outcome = gmres(&vec![0.0; n], 5, 1e-8, |_: &[f64], _: &mut [f64]| Err("called"), |_| {}, &mut x).unwrap();
        assert_eq!(outcome.iterations, 0);
        assert!(x.iter().all(|&v| v == 0.0));
        // The operator's error ends the call.
        let failed = gmres(&b, 5, 1e-8, |_: &[f64], _: &mut [f64]| Err("sweep failed"), |_| {}, &mut x);
        assert_eq!(failed, Err("sweep failed"));
    }
}

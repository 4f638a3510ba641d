//! Chebyshev–Lobatto collocation on one span [−1, 1]: the nodes, the
//! integration and differentiation matrices, barycentric interpolation and
//! the tail of the discrete Chebyshev transform (the a posteriori error
//! estimate). Both collocation solvers (planar and 3-D) place m + 1 of these
//! nodes on each knot span of the routing; this file holds the numbers once.
//!
//! Written here rather than taken from a crate: what is needed is a handful
//! of fixed (m+1)×(m+1) matrices built once per solver, and no maintained
//! Rust crate provides the Lobatto integration matrix or the transform's
//! tail rows.

/// How many of the highest Chebyshev coefficients the error estimate reads:
/// more than one, so that a function whose samples alias onto a low mode
/// (an under-resolved oscillation) is not taken for a resolved one.
pub const TAIL_COEFFICIENTS: usize = 4;

/// The interpolants' error at the nodes, integrated over a span, is about
/// the span's length times the first coefficient past the last over m²
/// (measured: on 150 random bodies, routings and tensions at 6–16
/// intervals against 64, the estimate of the tip, and of a_k up to the
/// highest order the table allows at m, was at least 2.3 times the error,
/// and 40–130 times it at the median); this factor adds half again.
pub const ESTIMATE_SAFETY: f64 = 1.5;

/// The Chebyshev–Lobatto nodes x_j = −cos(π j/m), j = 0 … m, on [−1, 1].
pub fn lobatto_nodes(m: usize) -> Vec<f64> {
    (0..=m).map(|j| -(std::f64::consts::PI * j as f64 / m as f64).cos()).collect()
}

/// ∫_{−1}^{x_j} ℓ_k(x) dx for the Lagrange basis ℓ_k on the Chebyshev–Lobatto
/// nodes x_j = −cos(π j/m), via the discrete Chebyshev expansion of ℓ_k;
/// row-major, (m+1)×(m+1). Row m holds the Clenshaw–Curtis weights.
pub fn integration_matrix(m: usize) -> Vec<f64> {
    let np = m + 1;
    let mf = m as f64;
    let theta = |j: usize| std::f64::consts::PI * (m - j) as f64 / mf; // x_j = cos θ_j
    let cheb = |n: usize, j: usize| (n as f64 * theta(j)).cos();
    let gamma = |i: usize| if i == 0 || i == m { 2.0 } else { 1.0 };
    // ∫_{−1}^{x_j} T_n.
    let int_t = |n: usize, j: usize| -> f64 {
        let x = theta(j).cos();
        match n {
            0 => x + 1.0,
            1 => (x * x - 1.0) / 2.0,
            _ => {
                let nf = n as f64;
                let at = |t_next: f64, t_prev: f64| t_next / (2.0 * (nf + 1.0)) - t_prev / (2.0 * (nf - 1.0));
                let sign = |p: usize| if p % 2 == 0 { 1.0 } else { -1.0 };
                at(cheb(n + 1, j), cheb(n - 1, j)) - at(sign(n + 1), sign(n - 1))
            }
        }
    };
    let mut q = vec![0.0; np * np];
    for j in 0..np {
        for k in 0..np {
            let mut v = 0.0;
            for n in 0..np {
                v += 2.0 / (mf * gamma(k) * gamma(n)) * cheb(n, k) * int_t(n, j);
            }
            q[j * np + k] = v;
        }
    }
    // Row 0 integrates over an empty interval.
    q[..np].iter_mut().for_each(|v| *v = 0.0);
    q
}

/// The differentiation matrix on the Chebyshev–Lobatto nodes x_j =
/// −cos(π j/m): (D f)_j = Σ_k D[j][k] f_k is the derivative at x_j of the
/// interpolant of f (row-major; diagonal by the negative row sum, which
/// keeps constants exact to rounding).
pub fn differentiation_matrix(m: usize) -> Vec<f64> {
    let np = m + 1;
    let x = lobatto_nodes(m);
    let c = |j: usize| (if j == 0 || j == m { 2.0 } else { 1.0 }) * if j % 2 == 0 { 1.0 } else { -1.0 };
    let mut d = vec![0.0; np * np];
    for j in 0..np {
        let mut row_sum = 0.0;
        for k in 0..np {
            if j != k {
                let v = c(j) / c(k) / (x[j] - x[k]);
                d[j * np + k] = v;
                row_sum += v;
            }
        }
        d[j * np + j] = -row_sum;
    }
    d
}

/// Barycentric weights of the Lobatto nodes (up to a common factor):
/// (−1)^j, halved at both ends.
#[inline]
fn barycentric_weight(j: usize, np: usize) -> f64 {
    let w = if j % 2 == 0 { 1.0 } else { -1.0 };
    if j == 0 || j == np - 1 {
        0.5 * w
    } else {
        w
    }
}

/// Barycentric interpolation of node values `f` (one span, on the Lobatto
/// nodes `x`) at `at` ∈ [−1, 1].
pub fn interpolate(x: &[f64], f: &[f64], at: f64) -> f64 {
    let np = x.len();
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..np {
        let d = at - x[j];
        if d == 0.0 {
            return f[j];
        }
        let w = barycentric_weight(j, np) / d;
        num += w * f[j];
        den += w;
    }
    num / den
}

/// The weights of [`interpolate`] at `at`: the interpolant there is
/// Σ_j weights[j] f_j (for fixed points, computed once).
pub fn interpolation_weights(x: &[f64], at: f64, weights: &mut [f64]) {
    let np = x.len();
    if let Some(j) = x.iter().position(|&xj| xj == at) {
        weights.iter_mut().for_each(|w| *w = 0.0);
        weights[j] = 1.0;
        return;
    }
    let mut den = 0.0;
    for j in 0..np {
        let w = barycentric_weight(j, np) / (at - x[j]);
        weights[j] = w;
        den += w;
    }
    weights.iter_mut().for_each(|w| *w /= den);
}

/// The rows of the discrete Chebyshev transform for the highest
/// [`TAIL_COEFFICIENTS`] coefficients: c_n = (2/m) Σ''_j f_j T_n(x_j) (Σ''
/// halves the end terms; c_m is halved); row-major, TAIL_COEFFICIENTS × (m+1).
pub fn tail_rows(m: usize) -> Vec<f64> {
    let np = m + 1;
    let mf = m as f64;
    let mut rows = Vec::with_capacity(TAIL_COEFFICIENTS * np);
    for n in m + 1 - TAIL_COEFFICIENTS.min(m)..=m {
        let scale = if n == m { 1.0 / mf } else { 2.0 / mf };
        for j in 0..np {
            let end = if j == 0 || j == m { 0.5 } else { 1.0 };
            // x_j = −cos(π j/m) = cos(π (m − j)/m), so T_n(x_j) = cos(n π (m − j)/m).
            rows.push(scale * end * (n as f64 * std::f64::consts::PI * (m - j) as f64 / mf).cos());
        }
    }
    rows
}

/// The size of the first Chebyshev coefficient past a span's highest,
/// extrapolated from its highest four `tail` (c_{m−3} … c_m): the last
/// pair's size times their decay per degree, measured against the pair
/// before (pairs, because an even or odd function has every other
/// coefficient zero). A tail that does not decay is taken as it is.
pub fn next_coefficient(tail: [f64; TAIL_COEFFICIENTS]) -> f64 {
    let last = tail[2].abs().max(tail[3].abs());
    let before = tail[0].abs().max(tail[1].abs());
    let decay = if before > 0.0 { (last / before).sqrt().min(1.0) } else { 1.0 };
    last * decay
}

/// The highest [`TAIL_COEFFICIENTS`] Chebyshev coefficients of each of `K`
/// functions' node values on one span (`fs`), from the rows of [`tail_rows`].
#[inline]
pub fn tails_of<const K: usize>(rows: &[f64], np: usize, fs: [&[f64]; K]) -> [[f64; TAIL_COEFFICIENTS]; K] {
    let mut out = [[0.0; TAIL_COEFFICIENTS]; K];
    for (r, row) in rows.chunks_exact(np).enumerate() {
        for (j, w) in row.iter().enumerate() {
            for (o, f) in out.iter_mut().zip(&fs) {
                o[r] += w * f[j];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integration_and_differentiation_are_exact_for_polynomials() {
        for m in [4, 7, 12, 20] {
            let np = m + 1;
            let x = lobatto_nodes(m);
            let q = integration_matrix(m);
            let d = differentiation_matrix(m);
            for degree in 0..=m {
                let f: Vec<f64> = x.iter().map(|x| x.powi(degree as i32)).collect();
                for j in 0..np {
                    let exact = (x[j].powi(degree as i32 + 1) - (-1.0f64).powi(degree as i32 + 1)) / (degree + 1) as f64;
                    let got: f64 = (0..np).map(|k| q[j * np + k] * f[k]).sum();
                    assert!((got - exact).abs() < 1e-13, "m={m} degree={degree} j={j}: {got} vs {exact}");
                    let slope = if degree == 0 { 0.0 } else { degree as f64 * x[j].powi(degree as i32 - 1) };
                    let got: f64 = (0..np).map(|k| d[j * np + k] * f[k]).sum();
                    assert!((got - slope).abs() < 1e-10 * (1.0 + slope.abs()) * (m * m) as f64, "m={m} degree={degree} j={j}: {got} vs {slope}");
                }
            }
            let f: Vec<f64> = x.iter().map(|x| 1.0 + x - 2.0 * x * x).collect();
            assert!((interpolate(&x, &f, 0.3) - (1.0 + 0.3 - 0.18)).abs() < 1e-13);
            let mut w = vec![0.0; np];
            interpolation_weights(&x, 0.3, &mut w);
            let via: f64 = w.iter().zip(&f).map(|(a, b)| a * b).sum();
            assert!((via - (1.0 + 0.3 - 0.18)).abs() < 1e-13);
        }
    }
}

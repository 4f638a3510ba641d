//! Configuration expression: Legendre curvature coefficients (thesis Ch. 3,
//! model-notes §4).
//!
//! With θ(σ) the tangent angle along the deformed centreline of length ℓ and
//! t = 2σ/ℓ − 1, the curvature κ(t) = dθ/dσ = Σ a_i^def P_i(t), so
//! a_i^def = (2i + 1)/ℓ ∫ P_i dθ: the deformed-length basis. The thesis's
//! basis (the default everywhere, [`LengthBasis::Rest`]) normalises by the
//! rest length L instead, a_i = a_i^def · ℓ/L (see [`LengthBasis`]).
//! Integrating by parts,
//! a_i = (2i + 1)/ℓ [θ_e − (−1)^i θ_0 − ∫_{−1}^{1} θ P_i'(t) dt],
//! which needs tangent angles but no second derivatives: that is the exact
//! route used here. The thesis's own route (§3.3: tangent angles resampled at
//! n_d equal arc-length intervals, discrete Legendre vectors, eq. 3.12) is
//! [`thesis_coefficients`].
//!
//! Everything works from sampled centrelines (points only), so simulated and
//! measured shapes are treated alike.

use serde::{Deserialize, Serialize};

/// The length that normalises the curvature coefficients: κ = Σ a_i P_i(t)
/// per unit of which length.
///
/// The thesis writes t = (2s − L)/L with s ∈ [0, L] the rod's own length
/// parameter (eqs. 3.2, 3.5) and converts with L/2 in eq. 3.12, so its a_i
/// are per unit **rest** length: a_i = (2i + 1)/L ∫ P_i dθ, a_0 = (θ_e − θ_0)/L.
/// Evidence: in this basis thesis Table 5.1's Target I is met exactly (all
/// five components, τ = 2.00 N), in the deformed basis neither target is
/// reachable (docs/model.md). The deformed-length basis (a_i^def, per unit of
/// the deformed length ℓ) stays available as an option: a_i = a_i^def · ℓ/L.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LengthBasis {
    /// Per unit rest length L: the thesis's basis and the default.
    #[default]
    Rest,
    /// Per unit deformed centreline length ℓ.
    Deformed,
}

impl LengthBasis {
    /// Both bases, default first.
    pub const ALL: [LengthBasis; 2] = [LengthBasis::Rest, LengthBasis::Deformed];

    /// The name used in files, JSON and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            LengthBasis::Rest => "rest",
            LengthBasis::Deformed => "deformed",
        }
    }

    /// One line saying what the coefficients are, for captions and reports.
    pub fn describe(self) -> &'static str {
        match self {
            LengthBasis::Rest => "per unit rest length L (the thesis's basis)",
            LengthBasis::Deformed => "per unit deformed length ℓ",
        }
    }

    /// Factor that turns deformed-length coefficients into this basis:
    /// ℓ/L for the rest basis, 1 for the deformed one.
    #[inline]
    pub fn factor_from_deformed(self, deformed_length_mm: f64, rest_length_mm: f64) -> f64 {
        match self {
            LengthBasis::Rest => deformed_length_mm / rest_length_mm,
            LengthBasis::Deformed => 1.0,
        }
    }

    /// Converts deformed-length coefficients `a` into this basis in place.
    #[inline]
    pub fn convert_from_deformed(self, a: &mut [f64], deformed_length_mm: f64, rest_length_mm: f64) {
        let factor = self.factor_from_deformed(deformed_length_mm, rest_length_mm);
        if factor != 1.0 {
            a.iter_mut().for_each(|v| *v *= factor);
        }
    }
}

impl std::fmt::Display for LengthBasis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A basis name that is neither `rest` (alias `thesis`) nor `deformed`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("unknown length basis '{given}': use 'rest' (the thesis's basis, per unit rest length; alias 'thesis') or 'deformed' (per unit deformed length)")]
pub struct UnknownLengthBasis {
    /// The name given.
    pub given: String,
}

impl std::str::FromStr for LengthBasis {
    type Err = UnknownLengthBasis;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        match text.trim().to_ascii_lowercase().as_str() {
            "rest" | "thesis" => Ok(LengthBasis::Rest),
            "deformed" => Ok(LengthBasis::Deformed),
            _ => Err(UnknownLengthBasis { given: text.to_string() }),
        }
    }
}

/// Why coefficients could not be computed from a centreline.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// Too few points to differentiate.
    #[error("a centreline needs at least {needed} points, got {got}")]
    TooFewPoints { needed: usize, got: usize },
    /// A point is NaN or infinite.
    #[error("centreline point {index} is not finite")]
    NotFinite { index: usize },
    /// Two consecutive points coincide (no tangent between them).
    #[error("centreline points {index} and {} coincide: remove repeated points", index + 1)]
    RepeatedPoint { index: usize },
}

/// Geometric description of a centreline: length, end angles, coefficients.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShapeCoefficients {
    /// Deformed arc length ℓ, mm.
    pub length_mm: f64,
    /// Tangent angle at the first point from +x, rad.
    pub base_angle_rad: f64,
    /// Tangent angle at the last point, rad (continuous, not wrapped).
    pub tip_angle_rad: f64,
    /// a_0 … a_n, mm⁻¹ (every a_i is a curvature: t is dimensionless), in
    /// `length_basis`.
    pub a: Vec<f64>,
    /// The length the coefficients are per unit of.
    pub length_basis: LengthBasis,
}

impl ShapeCoefficients {
    /// The same shape with its coefficients in `basis`; `rest_length_mm` is
    /// the rod's rest length L (for a measured shape, the rod's known length).
    pub fn in_basis(mut self, basis: LengthBasis, rest_length_mm: f64) -> Self {
        if basis != self.length_basis {
            // Back to the deformed basis, then into `basis`.
            let to_deformed = 1.0 / self.length_basis.factor_from_deformed(self.length_mm, rest_length_mm);
            let factor = to_deformed * basis.factor_from_deformed(self.length_mm, rest_length_mm);
            self.a.iter_mut().for_each(|v| *v *= factor);
            self.length_basis = basis;
        }
        self
    }
}

/// ((2k + 1)/(k + 1), k/(k + 1)): the factors of
/// [`LegendreSeries::advance`]'s recurrence at order k.
const fn legendre_factors(k: usize) -> (f64, f64) {
    let kf = k as f64;
    ((2.0 * kf + 1.0) / (kf + 1.0), kf / (kf + 1.0))
}

/// [`legendre_factors`] for k = 0 … 15, the orders in use.
const LEGENDRE_FACTORS: [(f64, f64); 16] = {
    let mut table = [(0.0, 0.0); 16];
    let mut k = 0;
    while k < 16 {
        table[k] = legendre_factors(k);
        k += 1;
    }
    table
};

/// Legendre polynomials P_0, P_1, … and their derivatives at one point t,
/// one order after the other by the three-term recurrence
/// (k + 1) P_{k+1} = (2k + 1) t P_k − k P_{k−1} and
/// P'_{k+1} = P'_{k−1} + (2k + 1) P_k. The one Legendre recurrence of the
/// crate: quadratures over all orders at a sample advance it in their loop
/// over orders (no allocation), [`legendre`] runs it to one order.
#[derive(Debug, Clone, Copy)]
pub struct LegendreSeries {
    t: f64,
    /// The current order k.
    order: usize,
    p_prev: f64,
    p: f64,
    dp_prev: f64,
    dp: f64,
}

impl LegendreSeries {
    /// P_0(t) = 1, P_0'(t) = 0.
    #[inline]
    pub fn new(t: f64) -> Self {
        Self { t, order: 0, p_prev: 0.0, p: 1.0, dp_prev: 0.0, dp: 0.0 }
    }

    /// Moves from order k to k + 1.
    #[inline]
    pub fn advance(&mut self) {
        let kf = self.order as f64;
        // The recurrence's factors (2k + 1)/(k + 1) and k/(k + 1) from a
        // table for the orders in use: a division per order is the
        // quadratures' slowest step.
        let (a, b) = LEGENDRE_FACTORS.get(self.order).copied().unwrap_or_else(|| legendre_factors(self.order));
        let p_next = a * self.t * self.p - b * self.p_prev;
        let dp_next = self.dp_prev + (2.0 * kf + 1.0) * self.p;
        (self.p_prev, self.p, self.dp_prev, self.dp) = (self.p, p_next, self.dp, dp_next);
        self.order += 1;
    }

    /// P_k(t) at the current order k.
    #[inline]
    pub fn value(&self) -> f64 {
        self.p
    }

    /// P_k'(t) at the current order k.
    #[inline]
    pub fn derivative(&self) -> f64 {
        self.dp
    }
}

/// Composite Simpson weight of sample `i` of `n` (3/8 rule on the last three
/// intervals when the interval count is odd; trapezoid for n < 4).
#[inline]
fn quadrature_weight(i: usize, n: usize) -> f64 {
    let intervals = n - 1;
    if n < 4 {
        return if i == 0 || i == n - 1 { 0.5 } else { 1.0 };
    }
    let simpson_end = if intervals.is_multiple_of(2) { intervals } else { intervals - 3 };
    let mut w = 0.0;
    if i <= simpson_end && simpson_end > 0 {
        w += if i == 0 || i == simpson_end {
            1.0 / 3.0
        } else if i % 2 == 1 {
            4.0 / 3.0
        } else {
            2.0 / 3.0
        };
    }
    if simpson_end < intervals && i >= simpson_end {
        let j = i - simpson_end;
        w += [3.0 / 8.0, 9.0 / 8.0, 9.0 / 8.0, 3.0 / 8.0][j];
    }
    w
}

/// Exact-route coefficients from tangent samples taken at an even spacing
/// `h` of any curve parameter: `theta` (tangent angle, continuous),
/// `sigma` (arc length at each sample) and `speed` (dσ/d parameter).
/// Writes a_0 … a_{out.len()−1}. Allocation-free: this runs inside sweeps.
pub fn legendre_from_tangent(theta: &[f64], sigma: &[f64], speed: &[f64], h: f64, out: &mut [f64]) {
    let n = theta.len();
    assert!(n >= 2 && sigma.len() == n && speed.len() == n, "mismatched tangent samples");
    out.iter_mut().for_each(|a| *a = 0.0);
    if out.is_empty() {
        return;
    }
    let length = sigma[n - 1] - sigma[0];
    // ∫ θ P_i'(t) dt with dt = (2/ℓ) speed d(parameter).
    for k in 0..n {
        let t = 2.0 * (sigma[k] - sigma[0]) / length - 1.0;
        let weight = quadrature_weight(k, n) * h * theta[k] * 2.0 * speed[k] / length;
        let mut legendre = LegendreSeries::new(t);
        for (i, a) in out.iter_mut().enumerate() {
            if i > 0 {
                legendre.advance();
            }
            *a += weight * legendre.derivative();
        }
    }
    let (theta0, theta_e) = (theta[0], theta[n - 1]);
    for (i, a) in out.iter_mut().enumerate() {
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        *a = (2 * i + 1) as f64 / length * (theta_e - sign * theta0 - *a);
    }
}

/// Checks a centreline and returns its point count.
fn check_points(points: &[[f64; 2]], needed: usize) -> Result<(), ShapeError> {
    if points.len() < needed {
        return Err(ShapeError::TooFewPoints { needed, got: points.len() });
    }
    for (index, p) in points.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(ShapeError::NotFinite { index });
        }
    }
    for (index, w) in points.windows(2).enumerate() {
        if w[0] == w[1] {
            return Err(ShapeError::RepeatedPoint { index });
        }
    }
    Ok(())
}

/// Fourth-order finite-difference derivative of `f` at sample `i` (unit
/// spacing): central where possible, one-sided near the ends.
fn derivative_4th(f: impl Fn(usize) -> f64, i: usize, n: usize) -> f64 {
    const ONE_SIDED: [f64; 5] = [-25.0 / 12.0, 4.0, -3.0, 4.0 / 3.0, -1.0 / 4.0];
    const SHIFTED: [f64; 5] = [-1.0 / 4.0, -5.0 / 6.0, 3.0 / 2.0, -1.0 / 2.0, 1.0 / 12.0];
    if i >= 2 && i + 2 < n {
        (f(i - 2) - 8.0 * f(i - 1) + 8.0 * f(i + 1) - f(i + 2)) / 12.0
    } else if i == 0 {
        (0..5).map(|j| ONE_SIDED[j] * f(j)).sum()
    } else if i == 1 {
        (0..5).map(|j| SHIFTED[j] * f(j)).sum()
    } else if i == n - 1 {
        -(0..5).map(|j| ONE_SIDED[j] * f(n - 1 - j)).sum::<f64>()
    } else {
        -(0..5).map(|j| SHIFTED[j] * f(n - 1 - j)).sum::<f64>()
    }
}

/// Exact-route coefficients a_0 … a_order (deformed-length basis: convert
/// with [`ShapeCoefficients::in_basis`]) from centreline points alone
/// (clamp first). The point index is the curve parameter: tangents and
/// speeds come from fourth-order finite differences, arc length from a
/// fourth-order cumulative rule, so smoothly spaced points (simulated or
/// measured) need not be evenly spaced in arc length.
pub fn coefficients_from_points(points: &[[f64; 2]], order: usize) -> Result<ShapeCoefficients, ShapeError> {
    check_points(points, 5)?;
    let n = points.len();
    let mut theta = Vec::with_capacity(n);
    let mut speed = Vec::with_capacity(n);
    for i in 0..n {
        let dx = derivative_4th(|j| points[j][0], i, n);
        let dy = derivative_4th(|j| points[j][1], i, n);
        let raw = dy.atan2(dx);
        // Keep θ continuous from the clamp (no wrapping to ±π).
        let angle = match theta.last() {
            Some(&prev) => prev + wrap_pi(raw - prev),
            None => raw,
        };
        theta.push(angle);
        speed.push(dx.hypot(dy));
    }
    // Arc length: ∫_k^{k+1} f ≈ (−f_{k−1} + 13 f_k + 13 f_{k+1} − f_{k+2})/24,
    // shifted to a one-sided cubic at the ends.
    let mut sigma = vec![0.0; n];
    for k in 0..n - 1 {
        let f = |j: usize| speed[j];
        let inc = if k >= 1 && k + 2 < n {
            (-f(k - 1) + 13.0 * f(k) + 13.0 * f(k + 1) - f(k + 2)) / 24.0
        } else if k == 0 {
            (9.0 * f(0) + 19.0 * f(1) - 5.0 * f(2) + f(3)) / 24.0
        } else {
            (9.0 * f(k + 1) + 19.0 * f(k) - 5.0 * f(k - 1) + f(k - 2)) / 24.0
        };
        sigma[k + 1] = sigma[k] + inc;
    }
    let mut a = vec![0.0; order + 1];
    legendre_from_tangent(&theta, &sigma, &speed, 1.0, &mut a);
    Ok(ShapeCoefficients {
        length_mm: sigma[n - 1],
        base_angle_rad: theta[0],
        tip_angle_rad: theta[n - 1],
        a,
        length_basis: LengthBasis::Deformed,
    })
}

fn wrap_pi(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    a - two_pi * (a / two_pi).round()
}

/// The thesis's discrete route (§3.3): resample the centreline at `n_d`
/// equal arc-length intervals (linear interpolation of the points), take the
/// tangent angle of each interval, project onto discrete Legendre vectors
/// (sampled P_i, orthogonalised on the n_d interval midpoints) for b_0 …
/// b_{order+1}, and invert eq. (3.12) with a_i = 0 beyond `order`. The
/// result is in the deformed-length basis (ℓ/2 in eq. 3.12); the thesis's
/// own numbers are that times ℓ/L ([`ShapeCoefficients::in_basis`]).
pub fn thesis_coefficients(points: &[[f64; 2]], order: usize, n_d: usize) -> Result<ShapeCoefficients, ShapeError> {
    check_points(points, 2)?;
    if n_d < order + 2 {
        return Err(ShapeError::TooFewPoints { needed: order + 2, got: n_d });
    }
    // Cumulative chord length.
    let mut chord = vec![0.0; points.len()];
    for k in 1..points.len() {
        let (a, b) = (points[k - 1], points[k]);
        chord[k] = chord[k - 1] + (b[0] - a[0]).hypot(b[1] - a[1]);
    }
    let length = chord[points.len() - 1];
    let at = |target: f64| -> [f64; 2] {
        let k = chord.partition_point(|&c| c < target).clamp(1, points.len() - 1);
        let frac = (target - chord[k - 1]) / (chord[k] - chord[k - 1]);
        let (a, b) = (points[k - 1], points[k]);
        [a[0] + frac * (b[0] - a[0]), a[1] + frac * (b[1] - a[1])]
    };
    let resampled: Vec<[f64; 2]> = (0..=n_d).map(|j| at(length * j as f64 / n_d as f64)).collect();
    let mut theta = Vec::with_capacity(n_d);
    for w in resampled.windows(2) {
        let raw = (w[1][1] - w[0][1]).atan2(w[1][0] - w[0][0]);
        let angle = match theta.last() {
            Some(&prev) => prev + wrap_pi(raw - prev),
            None => raw,
        };
        theta.push(angle);
    }
    // Discrete Legendre vectors Π_i on the interval midpoints: sampled P_i,
    // Gram–Schmidt orthogonalised so that projections are exact on the grid.
    let nb = order + 2;
    let t: Vec<f64> = (0..n_d).map(|j| (2 * j + 1) as f64 / n_d as f64 - 1.0).collect();
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(nb);
    for i in 0..nb {
        let mut v: Vec<f64> = t.iter().map(|&tj| legendre(i, tj)).collect();
        for prev in &basis {
            let c = dot(&v, prev) / dot(prev, prev);
            v.iter_mut().zip(prev).for_each(|(x, p)| *x -= c * p);
        }
        basis.push(v);
    }
    // c_i / v_i: the projection coefficient onto Π_i normalised so that a
    // sampled P_i maps to 1 (the thesis's normalisation factor v_i).
    let b: Vec<f64> = basis.iter().map(|pi| dot(&theta, pi) / dot(pi, pi)).collect();
    // Invert eq. (3.12): b_i = ℓ/2 (a_{i−1}/(2i−1) − a_{i+1}/(2i+3)).
    let mut a = vec![0.0; order + 2];
    for i in (1..=order + 1).rev() {
        let above = if i < order { a[i + 1] / (2 * i + 3) as f64 } else { 0.0 };
        a[i - 1] = (2 * i - 1) as f64 * (2.0 * b[i] / length + above);
    }
    a.truncate(order + 1);
    let a1 = if order >= 1 { a[1] } else { 0.0 };
    let base = b[0] - length / 2.0 * (a[0] - a1 / 3.0);
    let tip = base + length * a[0];
    Ok(ShapeCoefficients { length_mm: length, base_angle_rad: base, tip_angle_rad: tip, a, length_basis: LengthBasis::Deformed })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Legendre polynomial P_i(t).
pub fn legendre(i: usize, t: f64) -> f64 {
    let mut series = LegendreSeries::new(t);
    for _ in 0..i {
        series.advance();
    }
    series.value()
}

/// The shifted Legendre polynomials P_i(2x − 1), i = 0 … `order`, in powers
/// of x: row i holds the coefficients of x^0 … x^i. From the same
/// three-term recurrence as [`legendre`], on coefficient vectors:
/// (k + 1) P_{k+1} = (2k + 1)(2x − 1) P_k − k P_{k−1}. The coefficients are
/// integers, (−1)^(i+j) C(i, j) C(i + j, j), and come out exact in f64
/// (checked to order 20).
/// For quadratures that accumulate ∫ x^j f before the interval's length is
/// known (the 3-D solver's coefficient moments).
pub fn shifted_legendre_powers(order: usize) -> Vec<Vec<f64>> {
    let mut rows: Vec<Vec<f64>> = Vec::with_capacity(order + 1);
    for i in 0..=order {
        let row = match i {
            0 => vec![1.0],
            _ => {
                let k = (i - 1) as f64;
                let p = &rows[i - 1];
                let mut next = vec![0.0; i + 1];
                // (2k + 1)(2x − 1) P_k
                for (j, &c) in p.iter().enumerate() {
                    next[j + 1] += (2.0 * k + 1.0) * 2.0 * c;
                    next[j] -= (2.0 * k + 1.0) * c;
                }
                if i >= 2 {
                    for (n, &c) in next.iter_mut().zip(&rows[i - 2]) {
                        *n -= k * c;
                    }
                }
                next.iter_mut().for_each(|n| *n /= k + 1.0);
                next
            }
        };
        rows.push(row);
    }
    rows
}

/// Builds a centreline with curvature κ(t) = Σ a_i P_i(t) over length ℓ from
/// base angle θ_0, sampled at `points` points evenly in arc length. Used to
/// make known shapes (tests, synthetic data); positions are integrated with
/// 5-point Gauss–Legendre per interval, θ in closed form.
pub fn centreline_from_coefficients(a: &[f64], length_mm: f64, base_angle_rad: f64, points: usize) -> Vec<[f64; 2]> {
    // θ(t) = θ_0 + ℓ/2 ∫_{−1}^{t} Σ a_i P_i; ∫ P_i = (P_{i+1} − P_{i−1})/(2i+1), ∫ P_0 = t + 1.
    let theta = |t: f64| -> f64 {
        let mut acc = 0.0;
        for (i, &ai) in a.iter().enumerate() {
            let integral = if i == 0 {
                t + 1.0
            } else {
                (legendre(i + 1, t) - legendre(i - 1, t)) / (2 * i + 1) as f64
            };
            acc += ai * integral;
        }
        base_angle_rad + 0.5 * length_mm * acc
    };
    const GL_X: [f64; 5] = [0.0, -0.538_469_310_105_683, 0.538_469_310_105_683, -0.906_179_845_938_664, 0.906_179_845_938_664];
    const GL_W: [f64; 5] = [
        0.568_888_888_888_889,
        0.478_628_670_499_366,
        0.478_628_670_499_366,
        0.236_926_885_056_189,
        0.236_926_885_056_189,
    ];
    let mut out = Vec::with_capacity(points);
    let (mut x, mut y) = (0.0, 0.0);
    out.push([x, y]);
    for k in 1..points {
        let (s0, s1) = ((k - 1) as f64 / (points - 1) as f64, k as f64 / (points - 1) as f64);
        let (mid, half) = (0.5 * (s0 + s1), 0.5 * (s1 - s0));
        for (xi, wi) in GL_X.iter().zip(GL_W) {
            let t = 2.0 * (mid + half * xi) - 1.0;
            let th = theta(t);
            x += wi * half * length_mm * th.cos();
            y += wi * half * length_mm * th.sin();
        }
        out.push([x, y]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifted_legendre_powers_are_the_closed_form_and_the_polynomials() {
        let binom = |n: usize, k: usize| (0..k).fold(1u128, |acc, m| acc * (n - m) as u128 / (m + 1) as u128);
        let rows = shifted_legendre_powers(20);
        assert_eq!(rows.len(), 21);
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), i + 1);
            for (j, &c) in row.iter().enumerate() {
                let magnitude = (binom(i, j) * binom(i + j, j)) as f64;
                assert_eq!(c, if (i + j) % 2 == 0 { magnitude } else { -magnitude }, "P_{i}, x^{j}");
            }
            if i <= 8 {
                for k in 0..=20 {
                    let x = k as f64 / 20.0;
                    let poly: f64 = row.iter().enumerate().map(|(j, c)| c * x.powi(j as i32)).sum();
                    assert!((poly - legendre(i, 2.0 * x - 1.0)).abs() < 1e-9, "P_{i}({x})");
                }
            }
        }
    }

    #[test]
    fn rest_basis_is_the_default_and_scales_by_deformed_over_rest_length() {
        assert_eq!(LengthBasis::default(), LengthBasis::Rest);
        let mut a = [0.02, -0.01, 0.005];
        LengthBasis::Deformed.convert_from_deformed(&mut a, 60.0, 65.0);
        assert_eq!(a, [0.02, -0.01, 0.005]);
        LengthBasis::Rest.convert_from_deformed(&mut a, 60.0, 65.0);
        let s = 60.0 / 65.0;
        assert_eq!(a, [0.02 * s, -0.01 * s, 0.005 * s]);
        assert_eq!("thesis".parse::<LengthBasis>().unwrap(), LengthBasis::Rest);
        assert_eq!(" Deformed ".parse::<LengthBasis>().unwrap(), LengthBasis::Deformed);
        assert!("rst".parse::<LengthBasis>().unwrap_err().to_string().contains("'rest'"));
        for b in LengthBasis::ALL {
            assert_eq!(b.as_str().parse::<LengthBasis>().unwrap(), b);
            assert_eq!(serde_json::to_string(&b).unwrap(), format!("\"{b}\""));
        }
    }

    #[test]
    fn rest_basis_a0_is_the_turning_angle_over_the_rest_length() {
        // A known shape of deformed length 60 mm on a rod of rest length 65 mm.
        let pts = centreline_from_coefficients(&[0.02, -0.01], 60.0, 0.05, 1001);
        let c = coefficients_from_points(&pts, 2).unwrap().in_basis(LengthBasis::Rest, 65.0);
        assert_eq!(c.length_basis, LengthBasis::Rest);
        assert!((c.a[0] - (c.tip_angle_rad - c.base_angle_rad) / 65.0).abs() < 1e-12);
        let back = c.clone().in_basis(LengthBasis::Deformed, 65.0);
        assert!((back.a[0] - 0.02).abs() < 1e-9 && (back.a[1] + 0.01).abs() < 1e-9);
        assert_eq!(c.clone().in_basis(LengthBasis::Rest, 65.0), c);
    }

    #[test]
    fn quadrature_weights_integrate_cubics_exactly() {
        for n in [4usize, 5, 6, 7, 10, 11] {
            let sum: f64 = (0..n).map(|i| quadrature_weight(i, n) * (i as f64).powi(3)).sum();
            let exact = ((n - 1) as f64).powi(4) / 4.0;
            assert!((sum - exact).abs() < 1e-9 * exact, "n={n}: {sum} vs {exact}");
        }
    }

    #[test]
    fn known_polynomial_curvature_is_recovered_by_the_exact_route() {
        let a_true = [0.021, -0.034, 0.012, -0.007, 0.003];
        let theta0 = 0.07;
        let pts = centreline_from_coefficients(&a_true, 62.0, theta0, 2001);
        let c = coefficients_from_points(&pts, 6).unwrap();
        assert!((c.length_mm - 62.0).abs() < 1e-9, "length {}", c.length_mm);
        assert!((c.base_angle_rad - theta0).abs() < 1e-9);
        for i in 0..7 {
            let want = a_true.get(i).copied().unwrap_or(0.0);
            assert!((c.a[i] - want).abs() < 1e-9, "a_{i}: {} vs {want}", c.a[i]);
        }
    }

    #[test]
    fn curled_shape_keeps_angles_continuous() {
        // Constant curvature through 1.5 turns: θ_e − θ_0 = 3π.
        let kappa = 3.0 * std::f64::consts::PI / 65.0;
        let pts = centreline_from_coefficients(&[kappa], 65.0, 0.0, 801);
        let c = coefficients_from_points(&pts, 2).unwrap();
        assert!((c.tip_angle_rad - 3.0 * std::f64::consts::PI).abs() < 1e-8);
        assert!((c.a[0] - kappa).abs() < 1e-9);
    }

    /// The thesis's discrete route against the exact one: its error is the
    /// truncation of eq. (3.12) at `order` plus the n_d = 40 resampling. On
    /// thesis-like shapes (|a_i| ≲ 0.05 mm⁻¹) it stays within 2e-3 mm⁻¹ and
    /// converges to the exact value as n_d grows for a curvature polynomial of
    /// the requested order.
    #[test]
    fn thesis_route_error_is_bounded_and_vanishes_with_refinement() {
        let a_true = [0.021, -0.034, 0.012];
        let pts = centreline_from_coefficients(&a_true, 62.0, 0.05, 4001);
        let exact = coefficients_from_points(&pts, 2).unwrap();
        let thesis = thesis_coefficients(&pts, 2, 40).unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..3 {
            worst = worst.max((thesis.a[i] - exact.a[i]).abs());
        }
        eprintln!("thesis route (n_d = 40) vs exact, max |Δa_i| = {worst:.3e} mm⁻¹");
        assert!(worst < 2e-3, "thesis route error {worst}");
        let fine = thesis_coefficients(&pts, 2, 1000).unwrap();
        let worst_fine = (0..3).map(|i| (fine.a[i] - exact.a[i]).abs()).fold(0.0, f64::max);
        assert!(worst_fine < worst / 10.0, "refined {worst_fine} vs {worst}");
    }

    #[test]
    fn bad_centrelines_are_rejected() {
        assert!(matches!(coefficients_from_points(&[[0.0, 0.0]; 3], 2), Err(ShapeError::TooFewPoints { .. })));
        let mut pts = centreline_from_coefficients(&[0.01], 60.0, 0.0, 10);
        pts[4] = pts[3];
        assert!(matches!(coefficients_from_points(&pts, 2), Err(ShapeError::RepeatedPoint { index: 3 })));
        pts[4] = [f64::NAN, 0.0];
        assert!(matches!(coefficients_from_points(&pts, 2), Err(ShapeError::NotFinite { index: 4 })));
    }
}

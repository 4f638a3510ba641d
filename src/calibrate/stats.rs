//! The chi-square test the diagnosis states: P(χ²_k ≥ x) from the
//! regularised upper incomplete gamma function Q(k/2, x/2).

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; relative error below 1e-13).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        return std::f64::consts::PI.ln() - (std::f64::consts::PI * x).sin().ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma Q(a, x) = Γ(a, x)/Γ(a): the series
/// below a + 1, Lentz's continued fraction above (Numerical Recipes §6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let ln_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        let (mut ap, mut sum, mut del) = (a, 1.0 / a, 1.0 / a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        (1.0 - sum * ln_prefactor.exp()).clamp(0.0, 1.0)
    } else {
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (ln_prefactor.exp() * h).clamp(0.0, 1.0)
    }
}

/// P(χ²_dof ≥ chi2): the chance that noise alone gives a χ² this large.
pub fn chi2_p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return f64::NAN;
    }
    gamma_q(0.5 * dof as f64, 0.5 * chi2.max(0.0))
}

/// A p-value in a table column headed p: `0.031`, `2.4e-7`, or `< 1e-99`
/// below what the χ² tail resolves.
pub fn p_cell(p: f64) -> String {
    if !p.is_finite() {
        "—".into()
    } else if p < 1e-99 {
        "< 1e-99".into()
    } else {
        crate::io::fmt_sig(p, 2)
    }
}

/// A p-value in a sentence: `p = 0.031`, `p = 2.4e-7`, or `p < 1e-99`
/// (never `p = < 1e-99`).
pub fn p_text(p: f64) -> String {
    let value = p_cell(p);
    if value.starts_with('<') {
        format!("p {value}")
    } else {
        format!("p = {value}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_tails_match_tables() {
        // χ² critical values (p = 0.05 and 1e-3) from standard tables.
        for (chi2, dof, p) in [(3.841_459, 1, 0.05), (18.307_04, 10, 0.05), (29.588_30, 10, 1e-3), (124.342_1, 100, 0.05), (149.449_3, 100, 1e-3)] {
            let got = chi2_p_value(chi2, dof);
            assert!((got - p).abs() < 1e-5 * p.max(1e-3) * 10.0, "χ² {chi2}, {dof} dof: {got} vs {p}");
        }
        // Two degrees of freedom: exactly exp(−x/2).
        assert!((chi2_p_value(7.0, 2) - (-3.5f64).exp()).abs() < 1e-13);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        assert_eq!(chi2_p_value(0.0, 5), 1.0);
    }
}

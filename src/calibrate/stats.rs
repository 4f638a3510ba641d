//! The chi-square test the diagnosis states: P(χ²_k ≥ x), the regularised
//! upper incomplete gamma function Q(k/2, x/2) (statrs).

/// P(χ²_dof ≥ chi2): the chance that noise alone gives a χ² this large.
pub fn chi2_p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return f64::NAN;
    }
    let x = 0.5 * chi2.max(0.0);
    if x == 0.0 {
        return 1.0;
    }
    statrs::function::gamma::gamma_ur(0.5 * dof as f64, x)
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
        assert_eq!(chi2_p_value(0.0, 5), 1.0);
    }
}

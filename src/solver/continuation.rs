//! Warm starts of RK4's shooting across a continuation in tension: the
//! predictor of gravity's base moment and of the shooting slope.

/// Warm-start memory of a continuation in tension.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Continuation {
    /// Previous converged (tension, base moment) pairs, newest first.
    history: [(f64, f64); 3],
    solved: usize,
    /// Secant slopes dM(L)/dM(0) of the last two solves, newest first.
    slopes: [f64; 2],
}

impl Continuation {
    /// Predicts the base moment M(0) (N·mm) and the shooting slope
    /// dM(L)/dM(0) at `tension` from the previous solves.
    pub(super) fn predict(&self, tension: f64) -> (f64, f64) {
        // The Lagrange polynomial through up to three previous
        // (tension, moment) pairs.
        let known = &self.history[..self.solved.min(3)];
        let mut m0 = 0.0;
        for (i, &(ti, mi)) in known.iter().enumerate() {
            let mut weight = 1.0;
            for (j, &(tj, _)) in known.iter().enumerate() {
                if i != j {
                    weight *= (tension - tj) / (ti - tj);
                }
            }
            m0 += weight * mi;
        }
        if !m0.is_finite() {
            // Repeated tensions: fall back to the newest solution.
            m0 = known.first().map_or(0.0, |h| h.1);
        }
        // dM(L)/dM(0) is near 1 (the weight's moment hardly depends on
        // it) and drifts slowly with tension: extrapolate it linearly.
        let mut slope = match self.solved {
            0 => 1.0,
            1 => self.slopes[0],
            _ => {
                let (t1, t2) = (self.history[0].0, self.history[1].0);
                self.slopes[0] + (self.slopes[0] - self.slopes[1]) / (t1 - t2) * (tension - t1)
            }
        };
        if !(slope.is_finite() && slope.abs() > 1e-3) {
            slope = 1.0;
        }
        (m0, slope)
    }

    /// Records a converged solve: base moment `m0` and final slope at `tension`.
    pub(super) fn record(&mut self, tension: f64, m0: f64, slope: f64) {
        self.history.rotate_right(1);
        self.history[0] = (tension, m0);
        self.solved += 1;
        self.slopes = [slope, self.slopes[0]];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_predictor_extrapolates_over_three_solves() {
        let mut c = Continuation::default();
        assert_eq!(c.predict(1.0), (0.0, 1.0));
        let moment = |t: f64| 0.5 + 2.0 * t - 0.3 * t * t;
        c.record(1.0, moment(1.0), 0.9);
        assert_eq!(c.predict(1.5), (moment(1.0), 0.9));
        c.record(1.25, moment(1.25), 0.8);
        c.record(1.5, moment(1.5), 0.7);
        let (m0, slope) = c.predict(1.75);
        // Exact for a quadratic moment; the slope linear in the last two.
        assert!((m0 - moment(1.75)).abs() < 1e-12, "{m0}");
        assert!((slope - 0.6).abs() < 1e-12, "{slope}");
        // A repeated tension falls back to the newest solve; a vanishing
        // slope to 1.
        c.record(1.5, moment(1.5), 0.0);
        let (m0, slope) = c.predict(1.5);
        assert_eq!(m0, moment(1.5));
        assert_eq!(slope, 1.0);
    }
}

//! Newton–Krylov on the whole state: the outer solve of one tension set (fixed-point sweeps first, then Newton with a Krylov inner solve and continuation in the weight for heavy rods).

use super::*;

impl SpatialCollocation {
    pub(super) fn solve_inner(&mut self, tensions: &[f64]) -> Result<u32, SolveFailure> {
        let has_weight = self.has_weight && self.weight_fraction > 0.0;
        let has_friction = self.friction && tensions.iter().any(|&t| t > 0.0);
        if !has_weight && !has_friction {
            self.sweep(tensions, true)?;
            std::mem::swap(&mut self.state, &mut self.next);
            return Ok(1);
        }
        let mut passes = 0u32;
        // The changes of the last two sweeps (newest first).
        let mut previous = [f64::INFINITY; 2];
        self.anderson.restart();
        // The prediction, for Newton to start from if the sweeps stall.
        let predicted = (self.state.clone(), self.local.clone());
        let outcome = {
            loop {
            self.anderson.input_mut().copy_from_slice(&self.state);
            let change = match self.sweep(tensions, true) {
                Ok(c) => c,
                Err(e) => break Err(e),
            };
            passes += 1;
            let k = self.tolerance_scale;
            let settled = change.0 <= k * SWEEP_ANGLE_TOLERANCE_RAD && change.1 <= k * self.options.spatial_moment_tolerance_n_mm * self.m_scale && change.2 < k * FRICTION_TOLERANCE;
            let change = change.0.max(change.1).max(change.2);
            if settled && (passes == 1 || change <= 0.5 * previous[0] || !has_weight) {
                std::mem::swap(&mut self.state, &mut self.next);
                break Ok(());
            }
            let most = if has_weight { MAX_SWEEPS } else { FRICTION_MAX_PASSES as u32 };
            if !has_weight && passes >= most {
                break Err(SolveFailure::FrictionNotConverged);
            }
            // Stalled (a heavy rod, where the sweeps do not contract): less
            // than a third off over two sweeps (Anderson's changes are not
            // monotone from one sweep to the next).
            if passes >= most || (has_weight && passes >= 3 && change > 0.67 * previous[1]) {
                break Err(SolveFailure::GravityNotConverged { passes, residual_n_mm: change / self.m_scale });
            }
            previous = [change, previous[0]];
            self.anderson.output_mut().copy_from_slice(&self.next);
            match self.anderson.step() {
                Some(z) => self.state.copy_from_slice(z),
                None => std::mem::swap(&mut self.state, &mut self.next),
            }
            }
        };
        match outcome {
            Ok(()) => Ok(passes),
            Err(SolveFailure::FrictionNotConverged) => Err(SolveFailure::FrictionNotConverged),
            Err(_) => {
                self.anderson.clear();
                self.state.copy_from_slice(&predicted.0);
                self.local.copy_from_slice(&predicted.1);
                Ok(passes + self.newton_continued(tensions)?)
            }
        }
    }

    /// Newton from the current state; if it fails, continuation in the
    /// weight from a weightless rod. Returns the Newton iterations.
    pub(super) fn newton_continued(&mut self, tensions: &[f64]) -> Result<u32, SolveFailure> {
        let saved = self.state.clone();
        let saved_local = self.local.clone();
        if let Ok(n) = self.newton(tensions) {
            return Ok(n);
        }
        self.state.copy_from_slice(&saved);
        self.local.copy_from_slice(&saved_local);
        let full = self.weight_fraction;
        self.weight_fraction = 0.0;
        let mut iterations = 0;
        let result = (|| -> Result<(), SolveFailure> {
            // Weightless: one sweep from any start.
            self.sweep(tensions, true)?;
            std::mem::swap(&mut self.state, &mut self.next);
            let (mut reached, mut step) = (0.0f64, FIRST_WEIGHT_STEP);
            while reached < 1.0 {
                let next = (reached + step).min(1.0);
                let (state, local) = (self.state.clone(), self.local.clone());
                self.weight_fraction = full * next;
                match self.newton(tensions) {
                    Ok(n) => {
                        iterations += n;
                        reached = next;
                        step = (step * 2.0).min(MAX_WEIGHT_STEP);
                    }
                    Err(_) => {
                        self.state.copy_from_slice(&state);
                        self.local.copy_from_slice(&local);
                        step /= 2.0;
                        if step < MIN_WEIGHT_STEP {
                            return Err(SolveFailure::GravityNotConverged { passes: iterations, residual_n_mm: f64::NAN });
                        }
                    }
                }
            }
            Ok(())
        })();
        self.weight_fraction = full;
        if let Err(e) = result {
            self.state.copy_from_slice(&saved);
            self.local.copy_from_slice(&saved_local);
            return Err(e);
        }
        Ok(iterations)
    }

    /// Newton's method on F(z) = z − G(z) (G: one sweep), with backtracking
    /// on |F|. The steps are Newton–Krylov: GMRES on J δ = −F to
    /// [`KRYLOV_TOLERANCE`], J v by one finite-difference sweep (the
    /// fixed-point map's non-contracting modes, the heavy rod's low bending
    /// modes, are few: about four sweeps a step instead of a Jacobian's one
    /// per unknown and its LU). Only when GMRES does not reach its
    /// tolerance in [`KRYLOV_MAX_ITERATIONS`] or a Krylov step fails its
    /// line search is the Jacobian made by finite differences and
    /// factored; its factors are kept across iterations and solves for
    /// chord steps while those contract by half or better, and then serve
    /// as GMRES's right preconditioner.
    pub(super) fn newton(&mut self, tensions: &[f64]) -> Result<u32, SolveFailure> {
        let n = self.state.len();
        let residual = |this: &mut Self| -> Result<DVector<f64>, SolveFailure> {
            this.sweep(tensions, true)?;
            Ok(DVector::from_iterator(n, this.state.iter().zip(&this.next).map(|(z, g)| z - g)))
        };
        let mut f = residual(self)?;
        let mut norm = f.amax();
        let mut factors = self.newton_factors.take();
        let mut krylov = factors.is_none();
        for it in 0..NEWTON_MAX_ITERATIONS {
            if norm <= NEWTON_TOLERANCE {
                self.newton_factors = factors;
                return Ok(it);
            }
            let failed = SolveFailure::GravityNotConverged { passes: it, residual_n_mm: norm / self.m_scale };
            let mut delta = None;
            let mut step = Step::Chord;
            if krylov {
                step = Step::Krylov;
                delta = self.krylov_step(tensions, &f, factors.as_ref())?;
                if delta.is_none() {
                    factors = None;
                }
            } else if let Some(lu) = factors.as_ref() {
                delta = lu.solve(&(-&f));
                if delta.is_none() {
                    factors = None;
                }
            }
            if delta.is_none() {
                step = Step::Fresh;
                let lu = self.jacobian(tensions)?.lu();
                delta = lu.solve(&(-&f));
                factors = Some(lu);
                krylov = false;
                if delta.is_none() {
                    return Err(failed);
                }
            }
            let delta = delta.expect("set above");
            let base = self.state.clone();
            let mut lambda = 1.0;
            let accepted = loop {
                for i in 0..n {
                    self.state[i] = base[i] + lambda * delta[i];
                }
                match residual(self) {
                    Ok(trial) if trial.amax().is_finite() && trial.amax() < (1.0 - NEWTON_SUFFICIENT_DECREASE * lambda) * norm => break Some(trial),
                    _ => {
                        lambda /= 2.0;
                        if lambda < NEWTON_MIN_DAMPING || (step == Step::Chord && lambda < 0.25) {
                            break None;
                        }
                    }
                }
            };
            match accepted {
                Some(trial) => {
                    let contraction = trial.amax() / norm;
                    norm = trial.amax();
                    f = trial;
                    if step == Step::Chord && contraction > 0.5 {
                        krylov = true;
                    }
                }
                None => {
                    self.state.copy_from_slice(&base);
                    match step {
                        Step::Fresh => return Err(failed),
                        Step::Chord => krylov = true,
                        _ => {
                            factors = None;
                            krylov = false;
                        }
                    }
                    f = residual(self)?;
                    norm = f.amax();
                }
            }
        }
        if norm <= 1e3 * NEWTON_TOLERANCE {
            self.newton_factors = factors;
            return Ok(NEWTON_MAX_ITERATIONS);
        }
        Err(SolveFailure::GravityNotConverged { passes: NEWTON_MAX_ITERATIONS, residual_n_mm: norm / self.m_scale })
    }

    /// A Newton–Krylov step at the current state (F(z) = `f`, G(z) in
    /// `next`, the local solutions committed): GMRES on J δ = −F to
    /// [`KRYLOV_TOLERANCE`], J v = (F(z + εv) − F(z))/ε by one sweep,
    /// right-preconditioned by `factors` when given. `None` when GMRES
    /// does not reach its tolerance.
    pub(super) fn krylov_step(&mut self, tensions: &[f64], f: &DVector<f64>, factors: Option<&Factors>) -> Result<Option<DVector<f64>>, SolveFailure> {
        let n = self.state.len();
        let base = self.state.clone();
        let g0 = self.next.clone();
        let scale = 1e-7 * (1.0 + base.iter().fold(0.0f64, |a, v| a.max(v.abs())));
        let b: Vec<f64> = f.iter().map(|v| -v).collect();
        let mut x = vec![0.0; n];
        let outcome = crate::numerics::gmres::gmres(
            &b,
            KRYLOV_MAX_ITERATIONS,
            KRYLOV_TOLERANCE,
            |v: &[f64], out: &mut [f64]| {
                let eps = scale / v.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
                for i in 0..n {
                    self.state[i] = base[i] + eps * v[i];
                }
                let result = self.sweep(tensions, false);
                if result.is_ok() {
                    for i in 0..n {
                        out[i] = ((self.state[i] - self.next[i]) - f[i]) / eps;
                    }
                }
                self.state.copy_from_slice(&base);
                result.map(|_| ())
            },
            |v: &mut [f64]| {
                if let Some(lu) = factors {
                    let mut w = DVector::from_column_slice(v);
                    if lu.solve_mut(&mut w) {
                        v.copy_from_slice(w.as_slice());
                    }
                }
            },
            &mut x,
        );
        self.next.copy_from_slice(&g0);
        let outcome = outcome?;
        if outcome.relative_residual > KRYLOV_TOLERANCE {
            return Ok(None);
        }
        Ok(Some(DVector::from_vec(x)))
    }

    /// The Jacobian of F(z) = z − G(z) at the current state by forward
    /// differences of sweeps (each from the committed local solutions).
    pub(super) fn jacobian(&mut self, tensions: &[f64]) -> Result<DMatrix<f64>, SolveFailure> {
        let n = self.state.len();
        let base = self.state.clone();
        let g0 = self.next.clone();
        let mut jac = DMatrix::<f64>::zeros(n, n);
        for k in 0..n {
            let eps = 1e-7 * (1.0 + base[k].abs());
            self.state[k] = base[k] + eps;
            let result = self.sweep(tensions, false);
            if result.is_ok() {
                for i in 0..n {
                    jac[(i, k)] = ((self.state[i] - self.next[i]) - (base[i] - g0[i])) / eps;
                }
            }
            self.state[k] = base[k];
            result?;
        }
        self.next.copy_from_slice(&g0);
        Ok(jac)
    }
}

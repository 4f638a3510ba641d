//! Viscoelastic creep in bending (model-notes §6, standard linear solid).
//!
//! The moment is m = EI (u − f q) with an internal curvature q obeying
//! T q̇ = u − q. Each solve is one step of a protocol: the tension jumps,
//! then is held for the dwell time d with m(s) taken as constant over the
//! hold. That makes the law at the end of the hold local and linear,
//! u = m/EI · (1 + f (1 − E)/(1 − f)) + f E q₀,  E = exp(−(1 − f) d / T),
//! so the integrators add [`Creep::gain`]·m + [`Creep::offset`] to the
//! elastic curvature, record the moment at each point
//! ([`Creep::record_moment`]), and q is advanced in closed form after the
//! solve ([`Creep::end_solve`]).

use crate::model::rod::Effects;

/// The creep state of a simulator: the material law, the current hold and
/// the history q(s) at every point of the integrator.
#[derive(Debug, Clone)]
pub(crate) struct Creep {
    /// Creep fraction f (0: no creep).
    fraction: f64,
    /// Creep time T, s.
    time_s: f64,
    /// Bending rigidity EI at each point in the last pass, N·mm² (it
    /// varies along a non-uniform body).
    ei_n_mm2: Vec<f64>,
    /// Internal curvature q at each point, 1/mm.
    q: Vec<f64>,
    /// Bending moment at each point in the last pass, N·mm.
    moment: Vec<f64>,
    /// Dwell before the reading of the next solves, s.
    dwell_s: f64,
    /// E = exp(−(1 − f) d / T) for the current dwell.
    decay: f64,
    /// Extra compliance of the held step times EI, f (1 − E) (the gain at a
    /// point is this over (1 − f) EI).
    gain_times_ei: f64,
    /// Whether every solve starts from a rod with no load history (the
    /// default, held `effects.creep_hold_s`), or follows a protocol set by
    /// `PlanarSolver::set_hold`.
    virgin_holds: bool,
}

impl Creep {
    /// A virgin rod at each of `points` points, every solve held from it
    /// with no dwell until [`Creep::set_dwell`].
    pub(crate) fn new(effects: &Effects, ei_n_mm2: f64, points: usize) -> Self {
        Self {
            fraction: effects.creep_fraction,
            time_s: effects.creep_time_s,
            ei_n_mm2: vec![ei_n_mm2; points],
            q: vec![0.0; points],
            moment: vec![0.0; points],
            dwell_s: 0.0,
            decay: 1.0,
            gain_times_ei: 0.0,
            virgin_holds: true,
        }
    }

    /// Whether the actuator creeps at all.
    #[inline]
    pub(crate) fn is_on(&self) -> bool {
        self.fraction > 0.0
    }

    /// Sets the dwell `dwell_s` (s, checked by the caller) of the next solves.
    pub(crate) fn set_dwell(&mut self, dwell_s: f64) {
        self.dwell_s = dwell_s;
        let f = self.fraction;
        if f > 0.0 {
            self.decay = (-(1.0 - f) * dwell_s / self.time_s).exp();
            self.gain_times_ei = f * (1.0 - self.decay);
        } else {
            self.decay = 1.0;
            self.gain_times_ei = 0.0;
        }
    }

    /// From now on the history carries over from solve to solve.
    pub(crate) fn follow_protocol(&mut self) {
        self.virgin_holds = false;
    }

    /// From now on every solve starts from a rod with no load history
    /// (independent captures), as before [`Creep::follow_protocol`].
    pub(crate) fn start_each_solve_virgin(&mut self) {
        self.virgin_holds = true;
    }

    /// Before a solve: outside a protocol the rod starts as new.
    pub(crate) fn begin_solve(&mut self) {
        if self.virgin_holds && self.fraction > 0.0 {
            self.forget();
        }
    }

    /// After a successful solve: advances q over the hold just solved,
    /// q ← q∞ + (q − q∞) E with q∞ = m/(EI (1 − f)) (only in a protocol:
    /// a virgin hold leaves no history to keep).
    pub(crate) fn end_solve(&mut self) {
        if self.fraction > 0.0 && self.dwell_s > 0.0 && !self.virgin_holds {
            let f = self.fraction;
            let e = self.decay;
            for ((q, &m), &ei) in self.q.iter_mut().zip(&self.moment).zip(&self.ei_n_mm2) {
                let scale = 1.0 / (ei * (1.0 - f));
                let q_inf = m * scale;
                *q = q_inf + (*q - q_inf) * e;
            }
        }
    }

    /// Forgets the load history: the material is as new, unloaded.
    pub(crate) fn forget(&mut self) {
        self.q.iter_mut().for_each(|q| *q = 0.0);
    }

    /// du/dm added to the elastic compliance over the hold at a point of
    /// bending rigidity `ei_n_mm2`, f (1 − E)/((1 − f) EI), 1/(N·mm²).
    #[inline]
    pub(crate) fn gain(&self, ei_n_mm2: f64) -> f64 {
        let f = self.fraction;
        if f > 0.0 {
            self.gain_times_ei / ((1.0 - f) * ei_n_mm2)
        } else {
            0.0
        }
    }

    /// The held curvature f E q₀ at point `k`, 1/mm.
    #[inline]
    pub(crate) fn offset(&self, k: usize) -> f64 {
        let f = self.fraction;
        if f == 0.0 {
            0.0
        } else {
            f * self.decay * self.q[k]
        }
    }

    /// Records the bending moment `m` (N·mm) and the bending rigidity
    /// `ei_n_mm2` at point `k` in this pass.
    #[inline]
    pub(crate) fn record_moment(&mut self, k: usize, m: f64, ei_n_mm2: f64) {
        self.moment[k] = m;
        self.ei_n_mm2[k] = ei_n_mm2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn creep(f: f64, t_s: f64) -> Creep {
        let effects = Effects { creep_fraction: f, creep_time_s: t_s, ..Effects::default() };
        Creep::new(&effects, 100.0, 2)
    }

    #[test]
    fn a_held_step_follows_the_standard_linear_solid() {
        let (f, t_s, d, ei, m) = (0.3, 10.0, 7.0, 100.0, 2.0);
        let mut c = creep(f, t_s);
        c.follow_protocol();
        c.set_dwell(d);
        let e = (-(1.0 - f) * d / t_s).exp();
        assert!((c.gain(ei) - f * (1.0 - e) / ((1.0 - f) * ei)).abs() < 1e-18);
        assert_eq!(c.offset(0), 0.0);
        c.begin_solve();
        c.record_moment(0, m, ei);
        c.end_solve();
        // q after the hold, and the held curvature it leaves for the next step.
        let q1 = m / (ei * (1.0 - f)) * (1.0 - e);
        assert!((c.offset(0) - f * e * q1).abs() < 1e-15);
        assert_eq!(c.offset(1), 0.0);
        // No dwell: the history stays as it is.
        c.set_dwell(0.0);
        assert_eq!(c.gain(ei), 0.0);
        c.record_moment(0, 5.0, ei);
        c.end_solve();
        assert!((c.offset(0) - f * q1).abs() < 1e-15);
    }

    #[test]
    fn outside_a_protocol_every_solve_starts_from_a_virgin_rod() {
        let mut c = creep(0.3, 10.0);
        c.set_dwell(5.0);
        c.record_moment(0, 2.0, 100.0);
        c.end_solve();
        assert_eq!(c.offset(0), 0.0, "a virgin hold keeps no history");
        c.q[0] = 1.0;
        c.begin_solve();
        assert_eq!(c.offset(0), 0.0);
        // Without creep nothing happens at all.
        let mut off = creep(0.0, 10.0);
        off.set_dwell(5.0);
        assert!(!off.is_on() && off.gain(100.0) == 0.0 && off.offset(0) == 0.0);
    }
}

//! Checking a rod ([`Rod::validate`]): its own parameters against their
//! plausible ranges, each effect parameter by its registry entry, and its
//! body along s. Apart from the rod, the registry and the body, so that
//! none of them needs the others to check itself.

use super::effects;
use super::parameter::ParameterError;
use super::rod::{
    Rod, PLAUSIBLE_DENSITY_G_CM3, PLAUSIBLE_EI_N_MM2, PLAUSIBLE_FORCE_N, PLAUSIBLE_G_M_S2, PLAUSIBLE_LENGTH_MM, PLAUSIBLE_RADIUS_MM,
};

impl Rod {
    /// Checks every parameter; the solver calls this before it starts.
    pub fn validate(&self) -> Result<(), ParameterError> {
        let positive = [
            ("length_mm", self.length_mm),
            ("radius_mm", self.radius_mm),
            ("ea_n", self.ea_n),
            ("ga_n", self.ga_n),
            ("ei_n_mm2", self.ei_n_mm2),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(ParameterError::NotPositive { name, value });
            }
        }
        // Absurd sizes (a subnormal rigidity, a kilometre-long rod) are
        // refused here with a plausible range: the solver's products of them
        // would overflow or vanish into non-finite results. Within these
        // ranges every product the solver forms stays finite.
        for (name, value, range) in [
            ("length_mm", self.length_mm, PLAUSIBLE_LENGTH_MM),
            ("radius_mm", self.radius_mm, PLAUSIBLE_RADIUS_MM),
            ("ea_n", self.ea_n, PLAUSIBLE_FORCE_N),
            ("ga_n", self.ga_n, PLAUSIBLE_FORCE_N),
            ("ei_n_mm2", self.ei_n_mm2, PLAUSIBLE_EI_N_MM2),
        ] {
            range.check(name, value)?;
        }
        for (name, value, range) in [
            ("density_g_cm3", self.density_g_cm3, PLAUSIBLE_DENSITY_G_CM3),
            ("gravity.g_m_s2", self.gravity.g_m_s2, PLAUSIBLE_G_M_S2),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ParameterError::OutOfRange { name, value, expected: "a finite number ≥ 0" });
            }
            range.check(name, value)?;
        }
        if !self.rest_curvature_per_mm.is_finite() {
            return Err(ParameterError::OutOfRange {
                name: "rest_curvature_per_mm",
                value: self.rest_curvature_per_mm,
                expected: "a finite curvature in 1/mm (0: straight at rest)",
            });
        }
        // Every effect parameter by its registry entry.
        effects::validate(self)?;
        self.body()?;
        Ok(())
    }
}

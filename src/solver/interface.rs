//! The one solver interface: every backend (planar collocation and its RK4
//! reference, spatial collocation and its RK4 reference) is a struct with
//! its own state implementing [`Solver`] — set up for one actuator, then
//! solved repeatedly, each solve warm-started from the last. The actuation
//! (tensions and displacements), the continuation ladder and a whole
//! simulation are written once here, over the backends' warm-started
//! tension solve. Hot loops take a generic `S: Solver`: no dynamic dispatch.

use super::actuation::{meet_displacements, DisplacementNotMet};
use super::ladder;
use super::{Backend, CentrelinePoint, Hold, Simulation, TipPose};
use crate::model::{Actuation, Actuator, Cable, MAX_CABLES};
use crate::shape::LengthBasis;

/// A backend's repeated, warm-started solves of one actuator.
pub trait Solver {
    /// Why a solve failed.
    type Error: From<DisplacementNotMet>;

    /// Which backend this is.
    fn backend(&self) -> Backend;

    /// Solves at `tensions_n` (one per cable, N), warm-started from the last solve.
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, Self::Error>;

    /// Holds the next solves so ([`Hold`]: friction's load direction,
    /// creep's dwell), the solves from then on following a protocol; a
    /// backend that models neither ignores it. `hold` is checked
    /// ([`Hold::check`]).
    fn hold_next(&mut self, hold: Hold);

    /// The centreline of the last successful solve, clamp to tip.
    fn centreline(&self) -> Vec<CentrelinePoint>;

    /// The last successful solve's curvature coefficients a_0 … a_order in
    /// `basis`: twist, bending about body y, bending about body z.
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], Self::Error>;

    /// Solves one actuation (one per cable): the tension-driven cables at
    /// theirs, the displacement-driven ones' tensions found starting from
    /// `tensions_n` (which receives every cable's tension).
    fn solve(&mut self, actuation: &[Actuation], tensions_n: &mut [f64]) -> Result<TipPose, Self::Error>
    where
        Self: Sized,
    {
        let mut targets = [None; MAX_CABLES];
        for (i, a) in actuation.iter().enumerate() {
            match *a {
                Actuation::Tension(t) => tensions_n[i] = t,
                Actuation::Displacement(d) => targets[i] = Some(d),
            }
        }
        meet_displacements(|t| self.solve_tensions(t), &targets[..actuation.len()], tensions_n)
    }

    /// Reaches `actuation` from the straight rod up the continuation ladder
    /// ([`ladder::rungs`]), the last rung held by `hold` if given.
    fn climb(&mut self, actuation: &[Actuation], hold: Option<Hold>) -> Result<TipPose, Self::Error>
    where
        Self: Sized,
    {
        let rungs = ladder::rungs(actuation);
        let mut tensions = vec![0.0; actuation.len()];
        let mut rung = Vec::with_capacity(actuation.len());
        let mut pose = None;
        for k in 1..=rungs {
            if let (true, Some(h)) = (k == rungs, hold) {
                self.hold_next(h);
            }
            let f = k as f64 / rungs as f64;
            rung.clear();
            rung.extend(actuation.iter().map(|a| a.scaled(f)));
            pose = Some(self.solve(&rung, &mut tensions)?);
        }
        Ok(pose.expect("at least one rung"))
    }

    /// One simulation of `actuator`: up the ladder to its cables'
    /// actuation, then the coefficients a_0 … a_order in `basis` and the
    /// centreline; the result's cables carry the tensions found.
    fn simulate(&mut self, actuator: &Actuator, hold: Option<Hold>, order: usize, basis: LengthBasis) -> Result<Simulation, Self::Error>
    where
        Self: Sized,
    {
        let actuation: Vec<Actuation> = actuator.cables.iter().map(Cable::actuation).collect();
        let pose = self.climb(&actuation, hold)?;
        let [a_twist, a_bend_y, a_bend_z] = self.coefficients(order, basis)?;
        let mut actuator = actuator.clone();
        for (c, t) in actuator.cables.iter_mut().zip(pose.tensions_n.iter()) {
            c.tension_n = *t;
        }
        Ok(Simulation { actuator, backend: self.backend(), pose, a_bend_z, a_bend_y, a_twist, length_basis: basis, centreline: self.centreline() })
    }
}

/// Repeats `attempt` at a finer discretisation while it fails as
/// `unresolved`: `finer` raises the options' resolution one step and says
/// whether there was one to raise (else the failure stands).
pub fn until_resolved<O: Clone, T, E>(
    options: &O,
    mut attempt: impl FnMut(&O) -> Result<T, E>,
    unresolved: impl Fn(&E) -> bool,
    finer: impl Fn(&mut O) -> bool,
) -> Result<T, E> {
    let mut options = options.clone();
    loop {
        match attempt(&options) {
            Err(e) if unresolved(&e) && finer(&mut options) => continue,
            result => return result,
        }
    }
}

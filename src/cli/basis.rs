//! The length the curvature coefficients are per unit of, as a flag.

use cablemap::shape::LengthBasis;
use clap::Args;

/// The length the curvature coefficients a_i are per unit of, shared by
/// every command that prints or compares coefficients.
#[derive(Debug, Clone, Copy, Args)]
pub struct LengthBasisArgs {
    /// Curvature coefficients a_i per unit `rest` length L (the thesis's basis, eq. 3.2: the
    /// default) or per unit `deformed` length ℓ (a_i·L/ℓ) [default: rest].
    #[arg(long, value_name = "rest|deformed", default_value = "rest")]
    pub length_basis: LengthBasis,
}

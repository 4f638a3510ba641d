//! Numerical methods shared by several layers: the one classical RK4 step
//! of the integrators along the rod ([`rk4`]), the Chebyshev–Lobatto
//! collocation matrices of both collocation solvers ([`chebyshev`]), the
//! Anderson acceleration of their sweeps ([`anderson`]), the GMRES of the
//! 3-D collocation's Newton–Krylov steps ([`gmres`]) and the bounded
//! Levenberg–Marquardt minimiser of calibrate's fits and design's search
//! ([`lm`]). Linear algebra is nalgebra's and Legendre polynomials are
//! [`crate::shape`]'s.

pub mod anderson;
pub mod chebyshev;
pub mod gmres;
pub mod lm;
pub mod rk4;

pub use rk4::{rk4_step, Rk4Scratch};

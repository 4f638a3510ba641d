//! Shared numerical kernels: the one classical Runge–Kutta step both
//! integrators along the rod use (the planar RK4 reference method and the
//! 3-D solver). Linear algebra is nalgebra's and Legendre polynomials are
//! [`crate::shape`]'s; `tests/layering.rs` checks that no second copy of any
//! of the three appears in `src/`.
//!
//! The step is generic over a state of fixed size and takes its derivative
//! as a closure, so that each caller keeps its own bookkeeping per stage
//! (warm starts, recorded nodes, quadrature of the stage values) inside the
//! closure while the tableau lives here once. It never allocates: it runs
//! inside sweeps, a few million times per map.

/// Fractions c_i of the step at which the four stages are evaluated.
const STAGE_FRACTIONS: [f64; 4] = [0.0, 0.5, 0.5, 1.0];

/// The same in half steps, for callers that sample their data on a grid of
/// half steps.
const STAGE_HALF_STEPS: [usize; 4] = [0, 1, 1, 2];

/// The stages' weights b_i in sixths.
const STAGE_WEIGHTS_SIXTHS: [f64; 4] = [1.0, 2.0, 2.0, 1.0];

/// One stage of a classical RK4 step, as the derivative closure sees it.
#[derive(Debug)]
pub struct Rk4Stage<'a, const N: usize> {
    /// Stage number, 0 … 3 (weights 1, 2, 2, 1).
    pub index: usize,
    /// c_i h: the stage's distance from the start of the step, in the
    /// integration variable's unit (0, h/2, h/2, h).
    pub offset: f64,
    /// The same in half steps (0, 1, 1, 2).
    pub half_steps: usize,
    /// The stage's weight b_i in sixths (1, 2, 2, 1): h/6 Σ weight·g(stage)
    /// is the step's quadrature of a quantity g, consistent with the step.
    pub weight_sixths: f64,
    /// The state at the stage: y + c_i h k_{i−1} (y itself at stage 0).
    pub state: &'a [f64; N],
    /// k_{i−1}, the derivative the stage state was stepped along (zeros at
    /// stage 0): a caller that carries a quantity outside the state (the
    /// planar solver's sin/cos of the frame angle) advances it by
    /// `offset * slope` exactly as the state was advanced.
    pub slope: &'a [f64; N],
}

/// Working storage of [`rk4_step`]: the four stage derivatives and the
/// stage state. Kept by the caller so a pass of many steps reuses it.
#[derive(Debug, Clone, Copy)]
pub struct Rk4Scratch<const N: usize> {
    k: [[f64; N]; 4],
    stage: [f64; N],
}

impl<const N: usize> Default for Rk4Scratch<N> {
    fn default() -> Self {
        Self { k: [[0.0; N]; 4], stage: [0.0; N] }
    }
}

/// Advances `y` by one classical RK4 step of length `h`:
/// y ← y + h/6 (k_0 + 2 k_1 + 2 k_2 + k_3), with k_i written by
/// `derivative(stage, k_i)` at the stage state y + c_i h k_{i−1}. The stages
/// are evaluated in order 0 … 3; the first error the closure returns stops
/// the step and leaves `y` unchanged.
pub fn rk4_step<const N: usize, E>(
    y: &mut [f64; N],
    h: f64,
    scratch: &mut Rk4Scratch<N>,
    mut derivative: impl FnMut(&Rk4Stage<'_, N>, &mut [f64; N]) -> Result<(), E>,
) -> Result<(), E> {
    let zero = [0.0; N];
    let Rk4Scratch { k, stage } = scratch;
    for (index, &fraction) in STAGE_FRACTIONS.iter().enumerate() {
        let offset = fraction * h;
        let (done, rest) = k.split_at_mut(index);
        let slope = match done.last() {
            Some(previous) => previous,
            None => &zero,
        };
        if index == 0 {
            *stage = *y;
        } else {
            for ((s, &y0), &d) in stage.iter_mut().zip(y.iter()).zip(slope.iter()) {
                *s = y0 + offset * d;
            }
        }
        let stage = Rk4Stage {
            index,
            offset,
            half_steps: STAGE_HALF_STEPS[index],
            weight_sixths: STAGE_WEIGHTS_SIXTHS[index],
            state: stage,
            slope,
        };
        derivative(&stage, &mut rest[0])?;
    }
    let w = STAGE_WEIGHTS_SIXTHS;
    for (j, value) in y.iter_mut().enumerate() {
        *value += h / 6.0 * (w[0] * k[0][j] + w[1] * k[1][j] + w[2] * k[2][j] + w[3] * k[3][j]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = (y_1, −y_0) from (0, 1): y = (sin x, cos x). RK4's global error
    /// falls as h⁴, and the stages see the offsets and slopes of the tableau.
    #[test]
    fn integrates_a_rotation_to_fourth_order() {
        let error = |steps: usize| {
            let h = 1.0 / steps as f64;
            let mut y = [0.0, 1.0];
            let mut scratch = Rk4Scratch::default();
            for _ in 0..steps {
                rk4_step(&mut y, h, &mut scratch, |stage, dy| {
                    assert_eq!(stage.offset, [0.0, 0.5, 0.5, 1.0][stage.index] * h);
                    assert_eq!(stage.offset, stage.half_steps as f64 * 0.5 * h);
                    assert_eq!(stage.weight_sixths, [1.0, 2.0, 2.0, 1.0][stage.index]);
                    if stage.index == 0 {
                        assert_eq!(stage.slope, &[0.0; 2]);
                    }
                    *dy = [stage.state[1], -stage.state[0]];
                    Ok::<(), ()>(())
                })
                .unwrap();
            }
            (y[0] - 1f64.sin()).hypot(y[1] - 1f64.cos())
        };
        let (coarse, fine) = (error(10), error(20));
        assert!(coarse < 1e-6, "{coarse:e}");
        let order = (coarse / fine).log2();
        assert!((order - 4.0).abs() < 0.2, "order {order}");
    }

    /// An error from a stage stops the step and leaves the state as it was.
    #[test]
    fn a_failing_stage_leaves_the_state() {
        let mut y = [1.0, 2.0, 3.0];
        let result = rk4_step(&mut y, 0.1, &mut Rk4Scratch::default(), |stage, dy| {
            *dy = [1.0; 3];
            if stage.index == 2 {
                Err("stage 2")
            } else {
                Ok(())
            }
        });
        assert_eq!(result, Err("stage 2"));
        assert_eq!(y, [1.0, 2.0, 3.0]);
    }
}

//! Anderson acceleration (type II, depth 2) of a fixed point z = G(z), as
//! both collocation solvers use it on their sweeps: z_next = G_k − Σ γ_i
//! ΔG_i with γ minimising |f_k − Σ γ_i Δf_i|, f = G(z) − z, over the
//! differences of the last three sweeps.
//!
//! Written here rather than taken from a crate: the solvers need a
//! fixed-size, allocation-free depth-2 step inside their sweeps, with the
//! history kept across solves of neighbouring tensions; the crates that
//! offer Anderson mixing (argmin's) own the iteration loop instead.

/// The accelerator's memory for states of a fixed length.
#[derive(Debug, Clone)]
pub struct Anderson {
    /// Input z of the current sweep, and its output G(z).
    z: Vec<f64>,
    g: Vec<f64>,
    /// Previous f and G.
    f_prev: Vec<f64>,
    g_prev: Vec<f64>,
    /// Differences Δf, ΔG of the last two steps, newest first.
    df: [Vec<f64>; 2],
    dg: [Vec<f64>; 2],
    count: usize,
    /// Difference pairs held (0–2).
    pairs: usize,
    next: Vec<f64>,
}

impl Anderson {
    /// An accelerator for states of `n` numbers.
    pub fn new(n: usize) -> Self {
        Self {
            z: vec![0.0; n],
            g: vec![0.0; n],
            f_prev: vec![0.0; n],
            g_prev: vec![0.0; n],
            df: [vec![0.0; n], vec![0.0; n]],
            dg: [vec![0.0; n], vec![0.0; n]],
            count: 0,
            pairs: 0,
            next: vec![0.0; n],
        }
    }

    /// Forgets everything (new routing or a failed solve).
    pub fn clear(&mut self) {
        self.count = 0;
        self.pairs = 0;
    }

    /// Starts a new solve: the difference pairs of the previous one are kept
    /// (the map's Jacobian drifts slowly with tension, so they accelerate
    /// the first sweep already); the last f, G are not.
    pub fn restart(&mut self) {
        self.count = 0;
    }

    /// The input z of the next sweep, to be filled by the caller.
    pub fn input_mut(&mut self) -> &mut [f64] {
        &mut self.z
    }

    /// The output G(z) of the sweep, to be filled by the caller before [`Anderson::step`].
    pub fn output_mut(&mut self) -> &mut [f64] {
        &mut self.g
    }

    /// With G(z) in the output: the accelerated next input, or `None` for plain G(z).
    pub fn step(&mut self) -> Option<&[f64]> {
        let n = self.z.len();
        if self.count > 0 {
            self.df.swap(0, 1);
            self.dg.swap(0, 1);
            for i in 0..n {
                let f = self.g[i] - self.z[i];
                self.df[0][i] = f - self.f_prev[i];
                self.dg[0][i] = self.g[i] - self.g_prev[i];
            }
            self.pairs = (self.pairs + 1).min(2);
        }
        for i in 0..n {
            self.f_prev[i] = self.g[i] - self.z[i];
            self.g_prev[i] = self.g[i];
        }
        self.count += 1;
        if self.pairs == 0 {
            return None;
        }
        let depth = self.pairs;
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let f = &self.f_prev;
        let (a00, b0) = (dot(&self.df[0], &self.df[0]), dot(&self.df[0], f));
        let mut gamma = [0.0; 2];
        if a00 <= 0.0 {
            return None;
        }
        if depth == 2 {
            let (a01, a11, b1) = (dot(&self.df[0], &self.df[1]), dot(&self.df[1], &self.df[1]), dot(&self.df[1], f));
            let det = a00 * a11 - a01 * a01;
            if det > 1e-10 * a00 * a11 {
                gamma = [(b0 * a11 - b1 * a01) / det, (a00 * b1 - a01 * b0) / det];
            } else {
                gamma[0] = b0 / a00;
            }
        } else {
            gamma[0] = b0 / a00;
        }
        if !gamma.iter().all(|g| g.is_finite()) {
            return None;
        }
        for i in 0..n {
            self.next[i] = self.g[i] - gamma[0] * self.dg[0][i] - gamma[1] * self.dg[1][i];
        }
        Some(&self.next)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accelerates_a_slowly_contracting_linear_map() {
        // z = A z + b with A's spectral radius 0.9: plain iteration needs
        // ~200 steps for 1e-9; depth-2 Anderson on a 2-D map is exact after
        // a few.
        let (a, b) = ([[0.9, 0.05], [0.0, 0.8]], [1.0, 2.0]);
        let map = |z: &[f64]| [a[0][0] * z[0] + a[0][1] * z[1] + b[0], a[1][0] * z[0] + a[1][1] * z[1] + b[1]];
        let mut acc = Anderson::new(2);
        let mut z = [0.0, 0.0];
        let mut steps = 0;
        loop {
            acc.input_mut().copy_from_slice(&z);
            let g = map(&z);
            if (g[0] - z[0]).abs().max((g[1] - z[1]).abs()) < 1e-9 {
                break;
            }
            acc.output_mut().copy_from_slice(&g);
            z = match acc.step() {
                Some(next) => [next[0], next[1]],
                None => g,
            };
            steps += 1;
            assert!(steps < 20, "no convergence");
        }
        let exact_1 = 2.0 / 0.2;
        assert!((z[1] - exact_1).abs() < 1e-8);
    }
}

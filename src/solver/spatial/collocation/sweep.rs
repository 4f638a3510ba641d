//! One pass along the rod: the cut loads from the tip, the local solve at each node, the frames (sixth-order Magnus) and positions from the clamp.

use super::*;

impl SpatialCollocation {
    /// The tension of cable `c` at node `i`, N.
    #[inline]
    pub(super) fn tension_at(&self, tensions: &[f64], i: usize, c: usize) -> f64 {
        let k = i * self.cables + c;
        if !self.active[k] {
            0.0
        } else if self.friction {
            tensions[c] * self.state[self.ratio_at + k]
        } else {
            tensions[c]
        }
    }

    /// One sweep G(z) of the state in `self.state` into `self.next`: local
    /// solves with the state's distal loads (body frame), then θ₀, the
    /// frames, positions and M_W from the new strains, and the distal loads
    /// in the new frames. With `commit` the local solutions, frames and
    /// positions become the solver's (a finite-difference sweep of Newton's
    /// Jacobian leaves them). Returns the largest changes of the distal
    /// force and moment (in angle units: N_b·L²/EI, M_b·L/EI, at the weight
    /// on) and of the friction profiles.
    pub(super) fn sweep(&mut self, tensions: &[f64], commit: bool) -> Result<(f64, f64, f64), SolveFailure> {
        let nn = self.nodes_count();
        let mut ubuf = std::mem::take(&mut self.ubuf);
        let w_scale = if self.has_weight { self.weight_fraction } else { 0.0 };
        let mut clamp_moment = V3::zeros();
        let mut failed = None;
        let mut inverse = std::mem::take(&mut self.inverse);
        for i in 0..nn {
            let (nw, mw) = if w_scale > 0.0 { (self.state_n(i) * w_scale, self.state_m(i) * w_scale) } else { (V3::zeros(), V3::zeros()) };
            match self.local_solve(i, tensions, nw, mw, &mut inverse[i], commit) {
                Ok(x) => {
                    ubuf[i] = V3::new(x[3], x[4], x[5]);
                    self.vbuf[i] = V3::new(x[0], x[1], x[2]);
                    if i == 0 {
                        clamp_moment = self.moment_of_curvature(&ubuf[0], 0);
                    }
                    if commit {
                        self.local[i] = x;
                    }
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        self.inverse = inverse;
        if let Some(e) = failed {
            self.ubuf = ubuf;
            return Err(e);
        }
        // θ₀ from the clamp's moment (a rotational spring about both bending axes).
        let theta0 = match self.clamp_stiffness {
            Some(k) => V3::new(0.0, clamp_moment[1] / k, clamp_moment[2] / k),
            None => V3::zeros(),
        };
        let mut rot = if commit { std::mem::take(&mut self.rot) } else { std::mem::take(&mut self.rot_alt) };
        self.frames(&ubuf, exp_so3(&theta0), &mut rot);
        for i in 0..nn {
            self.dp[i] = rot[i] * self.vbuf[i];
        }
        // The distal loads of the full weight in the new frames: W and
        // M_W (from its rate −p' × W, backward from M_W(L) = 0). A weightless
        // sweep of a heavy rod (the weight continuation's start) leaves them too.
        let (mut change_n, mut change_m) = (0.0f64, 0.0f64);
        if self.has_weight {
            let mut mom = std::mem::take(&mut self.mbuf);
            for i in 0..nn {
                self.dmom[i] = -self.dp[i].cross(&(self.gravity_unit * self.distal_weight[i]));
            }
            self.integrate_backward(&mut mom);
            for i in 0..nn {
                let rt = rot[i].transpose();
                let n = rt * (self.gravity_unit * (self.distal_weight[i] * self.n_scale));
                let m = rt * (mom[i] * self.m_scale);
                let at = 6 * i;
                change_n = change_n.max((n - V3::new(self.state[at], self.state[at + 1], self.state[at + 2])).amax());
                change_m = change_m.max((m - V3::new(self.state[at + 3], self.state[at + 4], self.state[at + 5])).amax());
                self.next[at..at + 3].copy_from_slice(n.as_slice());
                self.next[at + 3..at + 6].copy_from_slice(m.as_slice());
            }
            self.mbuf = mom;
        } else {
            self.next[..6 * nn].iter_mut().for_each(|z| *z = 0.0);
        }
        if commit {
            self.rot = rot;
        } else {
            self.rot_alt = rot;
        }
        self.ubuf = ubuf;
        let change_ratio = if self.friction { self.friction_profiles(commit) } else { 0.0 };
        let (change_n, change_m) = (change_n * w_scale, change_m * w_scale);
        if !(change_n + change_m + change_ratio).is_finite() {
            return Err(SolveFailure::NonFinite { s_mm: None });
        }
        Ok((change_n, change_m, change_ratio))
    }

    /// The distal weight's force at node `i` in the state (body frame, full weight), N.
    #[inline]
    pub(super) fn state_n(&self, i: usize) -> V3 {
        V3::new(self.state[6 * i], self.state[6 * i + 1], self.state[6 * i + 2]) / self.n_scale
    }

    /// The distal weight's moment at node `i` in the state (body frame, full weight), N·mm.
    #[inline]
    pub(super) fn state_m(&self, i: usize) -> V3 {
        V3::new(self.state[6 * i + 3], self.state[6 * i + 4], self.state[6 * i + 5]) / self.m_scale
    }

    /// Frames at the nodes from the curvatures `u` and the clamp frame `r0`:
    /// sixth-order Magnus steps between nodes (Blanes, Casas & Ros, with
    /// u at the interval's three Gauss points) whose first term, ∫u, is the
    /// exact integral of u's interpolant.
    pub(super) fn frames(&self, u: &[V3], r0: M3, out: &mut [M3]) {
        let np = self.np;
        let sqrt15 = 15f64.sqrt();
        let mut r = r0;
        for span in 0..self.spans() {
            let base = span * np;
            let h = self.half[span];
            out[base] = r;
            let us = &u[base..base + np];
            for j in 1..np {
                // The four functionals of u, node by node (twelve
                // independent sums).
                let mut acc = [[0.0f64; 3]; 4];
                for (w, uk) in self.grid.magnus[(j - 1) * np..j * np].iter().zip(us) {
                    for (sum, wr) in acc.iter_mut().zip(w) {
                        sum[0] += wr * uk[0];
                        sum[1] += wr * uk[1];
                        sum[2] += wr * uk[2];
                    }
                }
                let g = acc.map(V3::from);
                let step = h * (self.grid.xn[j] - self.grid.xn[j - 1]);
                let integral = g[0] * h;
                let a1 = g[1] * step;
                let a2 = g[2] * (sqrt15 * step / 3.0);
                let a3 = g[3] * (10.0 * step / 3.0);
                let c1 = a1.cross(&a2);
                let c2 = a1.cross(&(c1 - a3 * 2.0)) / 60.0;
                let omega = integral + (a1 * 20.0 + a3 + c1).cross(&(a2 - c2)) / 240.0;
                r *= exp_so3(&omega);
                out[base + j] = r;
            }
        }
    }

    /// What a converged solve leaves besides the state: |v|, the positions
    /// and deformed arc length (from the last committed sweep's `dp`), and
    /// the bending moments creep keeps.
    pub(super) fn settle_outputs(&mut self) {
        let nn = self.nodes_count();
        for i in 0..nn {
            let x = &self.local[i];
            self.speed[i] = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        }
        self.positions();
        if self.creep.is_on() {
            for i in 0..nn {
                let x = self.local[i];
                let m = self.moment_of_curvature(&V3::new(x[3], x[4], x[5]), i);
                let ei = self.section[i].ei;
                self.creep.record_moment(2 * i, m[1], ei);
                self.creep.record_moment(2 * i + 1, m[2], ei);
            }
        }
    }

    /// Positions and deformed arc length from `self.dp` and the local v.
    pub(super) fn positions(&mut self) {
        let np = self.np;
        let (mut p0, mut s0) = (V3::zeros(), 0.0);
        for span in 0..self.spans() {
            let base = span * np;
            let h = self.half[span];
            for j in 0..np {
                let row = &self.grid.q[j * np..(j + 1) * np];
                let (mut ap, mut asg) = (V3::zeros(), 0.0);
                for k in 0..np {
                    ap += self.dp[base + k] * row[k];
                    asg += row[k] * self.speed[base + k];
                }
                self.pos[base + j] = p0 + ap * h;
                self.sigma[base + j] = s0 + h * asg;
            }
            p0 = self.pos[base + np - 1];
            s0 = self.sigma[base + np - 1];
        }
    }

    /// M_W at the nodes from its rate in `self.dmom`, backward from M_W(L) = 0.
    pub(super) fn integrate_backward(&self, out: &mut [V3]) {
        let np = self.np;
        let mut end = V3::zeros();
        for span in (0..self.spans()).rev() {
            let base = span * np;
            let h = self.half[span];
            let last = &self.grid.q[(np - 1) * np..np * np];
            for j in 0..np {
                let row = &self.grid.q[j * np..(j + 1) * np];
                let mut acc = V3::zeros();
                for k in 0..np {
                    acc += self.dmom[base + k] * (last[k] - row[k]);
                }
                out[base + j] = end - acc * h;
            }
            end = out[base];
        }
    }
}

//! The constitutive law: bending and twist from the moment (material stiffening, creep), and friction's tension profiles along each cable.

use super::*;

impl SpatialCollocation {
    /// The curvature u from the internal moment `m` (body frame) and, when
    /// asked, du/dm: torsion u₁ = m₁/GJ; bending linear, m_b = EI u_b, or
    /// with material stiffening m_b = EI u_b (1 + α r² |u_b|²) (isotropic:
    /// u_b along m_b).
    ///
    /// The linear law is inlined into the local residual (its hot loop);
    /// stiffening's Newton is not.
    #[inline(always)]
    pub(super) fn curvature_law(&self, i: usize, m: &V3, sec: &NodeCompliance, derivative: bool) -> (V3, M3) {
        let rest = self.rod.rest_curvature_per_mm;
        if self.stiffening == 0.0 && !self.creep.is_on() {
            // The elastic linear law (most solves) without adding creep's
            // zero terms: measured 3–4 % of a 3-D solve without gravity.
            let u = V3::new(m[0] * sec.inv_gj, m[1] * sec.inv_ei, m[2] * sec.inv_ei + rest);
            let d = if derivative { M3::from_diagonal(&V3::new(sec.inv_gj, sec.inv_ei, sec.inv_ei)) } else { M3::zeros() };
            return (u, d);
        }
        let (gain, off) = self.creep_terms(i, sec);
        if self.stiffening == 0.0 {
            let b = sec.inv_ei + gain;
            let u = V3::new(m[0] * sec.inv_gj, m[1] * b + off[1], m[2] * b + rest + off[2]);
            let d = if derivative { M3::from_diagonal(&V3::new(sec.inv_gj, b, b)) } else { M3::zeros() };
            return (u, d);
        }
        self.stiffened_curvature_law(m, sec, (gain, off), derivative)
    }

    /// [`SpatialCollocation::curvature_law`] with material stiffening, given
    /// creep's terms at the node.
    #[inline(never)]
    pub(super) fn stiffened_curvature_law(&self, m: &V3, sec: &NodeCompliance, (gain, off): (f64, V3), derivative: bool) -> (V3, M3) {
        let alpha = self.stiffening;
        let rest = self.rod.rest_curvature_per_mm;
        let mb = (m[1] * m[1] + m[2] * m[2]).sqrt();
        let c = alpha * sec.radius * sec.radius;
        // Monotone cubic EI (k + c k³) = |m_b| for the bending magnitude k.
        let mut k = mb / sec.ei;
        for _ in 0..STIFFENING_MAX_ITERATIONS {
            let f = sec.ei * (k + c * k * k * k) - mb;
            let step = f / (sec.ei * (1.0 + 3.0 * c * k * k));
            k -= step;
            if step.abs() <= STIFFENING_TOLERANCE * (1.0 + k.abs()) {
                break;
            }
        }
        let ratio = if mb > 0.0 { k / mb } else { 1.0 / sec.ei };
        let u = V3::new(m[0] / sec.gj, m[1] * (ratio + gain) + off[1], m[2] * (ratio + gain) + rest + off[2]);
        let mut d = M3::zeros();
        if derivative {
            d[(0, 0)] = 1.0 / sec.gj;
            let dk = 1.0 / (sec.ei * (1.0 + 3.0 * c * k * k));
            if mb > 0.0 {
                let (e1, e2) = (m[1] / mb, m[2] / mb);
                // d(k m̂) = dk/d|m| m̂ m̂ᵀ + k/|m| (I − m̂ m̂ᵀ).
                d[(1, 1)] = dk * e1 * e1 + ratio * (1.0 - e1 * e1);
                d[(1, 2)] = dk * e1 * e2 - ratio * e1 * e2;
                d[(2, 1)] = d[(1, 2)];
                d[(2, 2)] = dk * e2 * e2 + ratio * (1.0 - e2 * e2);
            } else {
                d[(1, 1)] = dk;
                d[(2, 2)] = dk;
            }
            d[(1, 1)] += gain;
            d[(2, 2)] += gain;
        }
        (u, d)
    }

    /// The internal moment (body frame, N·mm) whose curvature by the law
    /// of [`SpatialCollocation::curvature_law`] at node `i` is `u`: the
    /// law's inverse (bending: m_b ∥ u_b − offset, its size from a scalar
    /// cubic with stiffening and creep).
    pub(super) fn moment_of_curvature(&self, u: &V3, i: usize) -> V3 {
        let sec = &self.section[i];
        let rest = self.rod.rest_curvature_per_mm;
        let (gain, off) = self.creep_terms(i, sec);
        let ub = V3::new(0.0, u[1] - off[1], u[2] - rest - off[2]);
        let size = ub.norm();
        let c = self.stiffening * sec.radius * sec.radius;
        let ge = gain * sec.ei;
        // The elastic law's curvature k, with k + g EI (k + c k³) = |u_b|
        // (explicit without creep); then m_b = EI (k + c k³).
        let mut k = size / (1.0 + ge);
        if c > 0.0 && ge > 0.0 {
            for _ in 0..STIFFENING_MAX_ITERATIONS {
                let f = (1.0 + ge) * k + ge * c * k * k * k - size;
                let step = f / (1.0 + ge + 3.0 * ge * c * k * k);
                k -= step;
                if step.abs() <= STIFFENING_TOLERANCE * (1.0 + k.abs()) {
                    break;
                }
            }
        }
        let mb = sec.ei * (k + c * k * k * k);
        let scale = if size > 0.0 { mb / size } else { 0.0 };
        V3::new(sec.gj * u[0], ub[1] * scale, ub[2] * scale)
    }

    /// Creep's extra compliance over the hold and its held curvature at
    /// node `i` (components about body y and z in 1 and 2).
    #[inline]
    pub(super) fn creep_terms(&self, i: usize, sec: &NodeCompliance) -> (f64, V3) {
        if !self.creep.is_on() {
            return (0.0, V3::zeros());
        }
        (self.creep.gain(sec.ei), V3::new(0.0, self.creep.offset(2 * i), self.creep.offset(2 * i + 1)))
    }

    /// Friction: each cable's tension profile τ_c(s)/τ_c(0) = exp(−μ η Θ_c(s))
    /// from the turning Θ_c of its global direction R t_c, summed over a
    /// fine grid of the direction's interpolant (exact where it turns in a
    /// plane between grid points); written into the next state. Returns
    /// the largest change.
    pub(super) fn friction_profiles(&mut self, commit: bool) -> f64 {
        let np = self.np;
        let nc = self.cables;
        let nn = self.nodes_count();
        let rot = if commit { &self.rot } else { &self.rot_alt };
        for i in 0..nn {
            let v = self.vbuf[i];
            let u = self.ubuf[i];
            for c in 0..nc {
                let ch = &self.chan[i * nc + c];
                let q = v + u.cross(&ch.r) + ch.dr;
                self.global_dir[i * nc + c] = rot[i] * q.normalize();
            }
        }
        let mut change = 0.0f64;
        for c in 0..nc {
            let mut turning = 0.0;
            for span in 0..self.spans() {
                let base = span * np;
                for j in 0..np {
                    let i = base + j;
                    if j > 0 && self.active[i * nc + c] {
                        let mut prev = self.global_dir[(i - 1) * nc + c];
                        for k in 1..=FRICTION_SUBSTEPS {
                            let g = if k == FRICTION_SUBSTEPS {
                                self.global_dir[i * nc + c]
                            } else {
                                let row = &self.grid.fine[((j - 1) * (FRICTION_SUBSTEPS - 1) + (k - 1)) * np..][..np];
                                let mut g = V3::zeros();
                                for (w, jj) in row.iter().zip(0..np) {
                                    g += self.global_dir[(base + jj) * nc + c] * *w;
                                }
                                g
                            };
                            turning += prev.cross(&g).norm().atan2(prev.dot(&g));
                            prev = g;
                        }
                    }
                    let at = self.ratio_at + i * nc + c;
                    let ratio = (-self.signed_mu * turning).exp();
                    change = change.max((ratio - self.state[at]).abs());
                    self.next[at] = ratio;
                }
            }
        }
        change
    }
}

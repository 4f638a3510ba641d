//! What a solve reports and how well it is resolved: the pose, the a posteriori error estimates, the coefficients and their error.

use super::*;

impl SpatialCollocation {
    /// The pose of the converged state.
    pub(super) fn pose_of_state(&self, passes: u32, tensions: &[f64]) -> TipPose {
        let tip = self.nodes_count() - 1;
        let r = &self.rot[tip];
        let x = &self.local[tip];
        let t = (r * V3::new(x[0], x[1], x[2])).normalize();
        let base_v = self.rot[0] * V3::new(self.local[0][0], self.local[0][1], self.local[0][2]);
        let mut tensions_n = PerCable::filled(self.cables, 0.0);
        tensions_n.copy_from_slice(tensions);
        let mut displacements_mm = PerCable::filled(self.cables, 0.0);
        self.displacements_into(tensions, &mut displacements_mm);
        TipPose {
            tensions_n,
            displacements_mm,
            tip_x_mm: self.pos[tip][0],
            tip_y_mm: self.pos[tip][1],
            tip_z_mm: self.pos[tip][2],
            // The angles of the projections on the x–y plane.
            tip_angle_rad: t[1].atan2(t[0]),
            tip_frame_angle_rad: r[(1, 0)].atan2(r[(0, 0)]),
            base_angle_rad: base_v[1].atan2(base_v[0]),
            length_mm: self.sigma[tip],
            iterations: passes,
            frame_3d: Some(TipFrame { tangent: [t[0], t[1], t[2]], body_y_axis: [r[(0, 1)], r[(1, 1)], r[(2, 1)]] }),
        }
    }

    /// Refuses a pose whose estimated tip error is above
    /// [`crate::solver::tip_tolerance_mm`], or whose tip lies farther
    /// from the clamp than the stretched rod is long (no curve can).
    pub(super) fn check_resolved(&self, pose: &TipPose) -> Result<(), crate::solver::Unresolved> {
        let tolerance = crate::solver::tip_tolerance_mm(self.rod.length_mm);
        let [x, y, z] = pose.tip_mm();
        let reach = (x * x + y * y + z * z).sqrt();
        if reach > pose.length_mm + tolerance {
            let what = format!(
                "the tip (|tip| = {} mm is more than the stretched length ℓ = {} mm)",
                crate::io::fmt_num(reach),
                crate::io::fmt_num(pose.length_mm)
            );
            return Err(self.unresolved(what, reach - pose.length_mm, tolerance, "mm"));
        }
        let (_, tip_error) = self.estimate;
        if !(tip_error <= tolerance) {
            return Err(self.unresolved("the tip position".into(), tip_error, tolerance, "mm"));
        }
        Ok(())
    }

    /// The centreline of the last solve at 2·steps_per_span + 1 evenly
    /// spaced points (the option's centreline resolution) and at every
    /// span boundary (each anchor among them, where its cable ends).
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        self.nodes(2 * self.options.spatial_steps_per_span + 1)
    }

    /// The pose of the last successful solve.
    pub fn pose(&self) -> Option<TipPose> {
        self.last
    }

    /// The tangent angle's and the tip's estimated errors of the last
    /// solve (rad, mm): what the interpolants of u, p' and M_W' miss on each
    /// span, about the size of their highest Chebyshev coefficients
    /// (computed once per solve).
    pub fn error_estimate(&self) -> (f64, f64) {
        self.estimate
    }

    /// [`SpatialCollocation::error_estimate`] of the state just solved.
    pub(super) fn estimate_errors(&self) -> (f64, f64) {
        let np = self.np;
        let (mut angle, mut moment, mut position) = (0.0, 0.0, 0.0);
        let mut comps = [0.0; 9 * (MAX_NODES + 1)];
        for span in 0..self.spans() {
            let base = span * np;
            let length = 2.0 * self.half[span];
            for j in 0..np {
                let x = &self.local[base + j];
                let dp = self.dp[base + j];
                let dm = if self.has_weight { -dp.cross(&(self.gravity_unit * self.distal_weight[base + j])) } else { V3::zeros() };
                for c in 0..3 {
                    comps[c * np + j] = x[3 + c];
                    comps[(3 + c) * np + j] = dp[c];
                    comps[(6 + c) * np + j] = dm[c];
                }
            }
            let slice = |k: usize| &comps[k * np..(k + 1) * np];
            let tails = chebyshev::tails_of(&self.grid.tail, np, [slice(0), slice(1), slice(2), slice(3), slice(4), slice(5)]);
            let next = tails.map(next_coefficient);
            angle += length * next[0].max(next[1]).max(next[2]);
            position += length * next[3].max(next[4]).max(next[5]);
            if self.has_weight {
                // M_W' (zero without weight).
                let next = chebyshev::tails_of(&self.grid.tail, np, [slice(6), slice(7), slice(8)]).map(next_coefficient);
                moment += length * next[0].max(next[1]).max(next[2]);
            }
        }
        let ei_min = self.section.iter().map(|s| s.ei.min(s.gj)).fold(f64::INFINITY, f64::min);
        let scale = ESTIMATE_SAFETY / (self.m * self.m) as f64;
        let theta = scale * (angle + moment * self.rod.length_mm / ei_min);
        let ell = self.sigma[self.nodes_count() - 1];
        (theta, scale * position + ell * theta)
    }

    /// Legendre coefficients of the last solve, order `order`, in `basis`:
    /// `[twist, bending about body y, bending about body z]`, each
    /// a_0 … a_order in 1/mm (see the module comment). Refused as unresolved
    /// when their estimated error is above
    /// [`crate::solver::resolution::ORDER_TOLERANCE_PER_MM`] (the message
    /// names the setting to raise).
    pub fn coefficients(&self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        let (a, error) = self.coefficients_with_error(order, basis)?;
        let tolerance = crate::solver::resolution::ORDER_TOLERANCE_PER_MM;
        if !(error <= tolerance) {
            return Err(SolveFailure::Unresolved(self.unresolved(format!("a_0 … a_{order}"), error, tolerance, "mm⁻¹")).into());
        }
        Ok(a)
    }

    /// [`SpatialCollocation::unresolved`]'s failure at this solver's resolution.
    pub(super) fn unresolved(&self, what: String, estimate: f64, tolerance: f64, unit: &'static str) -> crate::solver::Unresolved {
        let advice = format!(
            "raise --nodes-per-span above {} (spec: [solver] nodes_per_span; at most {}), or lower the tensions",
            self.m,
            crate::solver::MAX_NODES_PER_SPAN
        );
        crate::solver::Unresolved { what, estimate, tolerance, unit, advice }
    }

    /// [`SpatialCollocation::coefficients`] without the check, with the estimated
    /// error of the largest coefficient, 1/mm.
    pub fn coefficients_with_error(&self, order: usize, basis: LengthBasis) -> Result<([Vec<f64>; 3], f64), SpatialError> {
        if order > MAX_SPATIAL_ORDER {
            return Err(SpatialError::OrderAbove { order, max: MAX_SPATIAL_ORDER });
        }
        assert!(self.last.is_some(), "coefficients needs a successful solve");
        let np = self.np;
        let nn = self.nodes_count();
        let length = self.rod.length_mm;
        let ell = self.sigma[nn - 1];
        let (theta_error, _) = self.error_estimate();
        let unit_v = |i: usize| {
            let x = &self.local[i];
            V3::new(x[0], x[1], x[2]).normalize()
        };
        let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; order + 1]);
        let mut quadrature_error = [0.0f64; MAX_SPATIAL_ORDER + 1];
        // Per span (stack buffers: this runs once per solve of a sweep):
        // v̂ at its nodes, and the highest Chebyshev coefficients of each
        // P_n κ_k, accumulated node by node.
        let mut vhat = [V3::zeros(); MAX_NODES + 1];
        let tail_rows = self.grid.tail.len() / np;
        let to_legendre = 2.0 / ell;
        for span in 0..self.spans() {
            let base = span * np;
            let h = self.half[span];
            let inv_h = 1.0 / h;
            for (j, v) in vhat[..np].iter_mut().enumerate() {
                *v = unit_v(base + j);
            }
            let mut tails = [[[0.0f64; chebyshev::TAIL_COEFFICIENTS]; 3]; MAX_SPATIAL_ORDER + 1];
            for j in 0..np {
                // κ at the node (body frame): u − (u·v̂) v̂ + v̂ × v̂'.
                let row = &self.grid.diff[j * np..(j + 1) * np];
                let mut d = V3::zeros();
                for k in 0..np {
                    d += vhat[k] * row[k];
                }
                let dv = d * inv_h;
                let x = &self.local[base + j];
                let u = V3::new(x[3], x[4], x[5]);
                let vh = vhat[j];
                let mut kappa = u - vh * u.dot(&vh) + vh.cross(&dv);
                kappa[0] = u[0];
                let t = to_legendre * self.sigma[base + j] - 1.0;
                let mut legendre = LegendreSeries::new(t);
                let w = h * self.grid.q[(np - 1) * np + j];
                for (n, tail) in tails[..=order].iter_mut().enumerate() {
                    if n > 0 {
                        legendre.advance();
                    }
                    let p = legendre.value();
                    for k in 0..3 {
                        let value = p * kappa[k];
                        out[k][n] += w * value;
                        for r in 0..tail_rows {
                            tail[k][r] += self.grid.tail[r * np + j] * value;
                        }
                    }
                }
            }
            for (n, tail) in tails[..=order].iter().enumerate() {
                let worst = tail.iter().map(|t| next_coefficient(*t)).fold(0.0, f64::max);
                quadrature_error[n] += 2.0 * h * worst;
            }
            // The tangent's jump to the next span (where v jumps).
            if span + 1 < self.spans() {
                let (a, b) = (vhat[np - 1], unit_v(base + np));
                let axis = a.cross(&b);
                let sin = axis.norm();
                if sin > 0.0 {
                    let jump = axis * (sin.atan2(a.dot(&b)) / sin);
                    let t = 2.0 * self.sigma[base + np - 1] / ell - 1.0;
                    let mut legendre = LegendreSeries::new(t);
                    for n in 0..=order {
                        if n > 0 {
                            legendre.advance();
                        }
                        for k in 1..3 {
                            out[k][n] += legendre.value() * jump[k];
                        }
                    }
                }
            }
        }
        let factor = match basis {
            LengthBasis::Rest => 1.0,
            LengthBasis::Deformed => length / ell,
        };
        for series in out.iter_mut() {
            for (n, a) in series.iter_mut().enumerate() {
                *a *= factor * (2 * n + 1) as f64 / length;
            }
        }
        let scale = ESTIMATE_SAFETY / (self.m * self.m) as f64;
        let error = (0..=order)
            .map(|n| {
                let nf = n as f64;
                let angles = theta_error * (2.0 + (2.0 * nf * (nf + 1.0)).sqrt());
                factor * (2.0 * nf + 1.0) / length * (scale * quadrature_error[n] + angles)
            })
            .fold(0.0, f64::max);
        Ok((out, error))
    }
}

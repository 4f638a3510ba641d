//! The local 6×6 solve at one node: the cut's residual, its Jacobian, and Broyden-accelerated Newton on the strains.

use super::*;

impl SpatialCollocation {
    /// Newton on the cut equations at node `i` (body-frame distal loads
    /// `nw`, `mw`), warm-started from the last (or predicted) local
    /// solution there. Steps use the inverse Jacobian kept from an earlier
    /// solve (chord steps) while they contract fast, and a fresh one
    /// otherwise; a step below [`LOCAL_STEP_TOLERANCE`] ends it (what is
    /// left is about the contraction factor times that step).
    pub(super) fn local_solve(&self, i: usize, tensions: &[f64], nw: V3, mw: V3, kept: &mut Option<Matrix6<f64>>, commit: bool) -> Result<[f64; 6], SolveFailure> {
        let mut x = self.local[i];
        // The kept inverse is updated in place by a committed sweep, on a
        // copy by a finite-difference sweep.
        let mut copy;
        let inverse = if commit {
            kept
        } else {
            copy = *kept;
            &mut copy
        };
        let mut previous = f64::INFINITY;
        // The last step taken and the residual before it (Broyden's update).
        let mut last: Option<([f64; 6], [f64; 6])> = None;
        for _ in 0..LOCAL_MAX_ITERATIONS {
            let fresh = inverse.is_none();
            let f = if fresh {
                let (f, j) = self.residual_and_jacobian(i, tensions, &x, nw, mw);
                *inverse = j.try_inverse();
                f
            } else {
                let f = self.residual(i, tensions, &x, nw, mw);
                if let (Some((step, f_old)), Some(h)) = (&last, inverse.as_mut()) {
                    broyden_update(h, step, &f, f_old);
                }
                f
            };
            let Some(h) = inverse.as_ref() else { break };
            let mut dx = mul6(h, &f);
            dx.iter_mut().for_each(|d| *d = -*d);
            let big = dx.iter().fold(0.0f64, |a, d| a.max(d.abs()));
            if !big.is_finite() {
                if fresh {
                    break;
                }
                *inverse = None;
                last = None;
                continue;
            }
            // Keep the axial stretch positive: a step through v1 = 0 would
            // fold the rod onto itself.
            let mut lambda = 1.0;
            while x[0] + lambda * dx[0] < 0.05 && lambda > 1e-3 {
                lambda *= 0.5;
            }
            // Far from the solution (a cold start, a large tension step),
            // backtrack until the residual falls, so that Newton cannot
            // jump to another branch of t = q/|q|.
            if big > 0.02 {
                let f0 = norm_squared6(&f);
                while lambda > 1e-3 {
                    let trial: [f64; 6] = std::array::from_fn(|k| x[k] + lambda * dx[k]);
                    let ft = norm_squared6(&self.residual(i, tensions, &trial, nw, mw));
                    if ft.is_finite() && ft < f0 {
                        break;
                    }
                    lambda *= 0.5;
                }
            }
            for k in 0..6 {
                dx[k] *= lambda;
                x[k] += dx[k];
            }
            if big < self.tolerance_scale * LOCAL_STEP_TOLERANCE && lambda == 1.0 && x[0] > 0.0 {
                return Ok(x);
            }
            last = Some((dx, f));
            // Steps that contract slowly: take a fresh Jacobian.
            if !fresh && big > CHORD_CONTRACTION * previous {
                *inverse = None;
                last = None;
            }
            previous = big;
        }
        *inverse = None;
        Err(SolveFailure::CutEquationsNotConverged { s_mm: self.s[i] })
    }

    /// The internal force and moment (body frame) at node `i` for the
    /// strains `x` and the distal loads `nw`, `mw`: n = N_b − Σ τ t,
    /// m = M_b − Σ τ r × t.
    #[inline(always)]
    pub(super) fn cut_loads(&self, i: usize, tensions: &[f64], x: &[f64; 6], nw: V3, mw: V3) -> (V3, V3) {
        let v = V3::new(x[0], x[1], x[2]);
        let u = V3::new(x[3], x[4], x[5]);
        let (mut n, mut m) = (nw, mw);
        let nc = self.cables;
        for c in 0..nc {
            let tau = self.tension_at(tensions, i, c);
            if tau == 0.0 {
                continue;
            }
            let ch = &self.chan[i * nc + c];
            let q = v + u.cross(&ch.r) + ch.dr;
            let pull = q * (tau / q.norm());
            n -= pull;
            m -= ch.r.cross(&pull);
        }
        (n, m)
    }

    /// The residual F(x) = x − x* − C(f(x)) of the cut equations at node `i`
    /// (compliance form: f the internal force and moment, C the
    /// constitutive law).
    #[inline]
    pub(super) fn residual(&self, i: usize, tensions: &[f64], x: &[f64; 6], nw: V3, mw: V3) -> [f64; 6] {
        let (n, m) = self.cut_loads(i, tensions, x, nw, mw);
        let u = self.curvature_law(i, &m, &self.section[i], false).0;
        self.residual_of(i, x, &n, &u)
    }

    /// F(x) from the internal force `n` and the law's curvature `u` at node `i`.
    #[inline(always)]
    pub(super) fn residual_of(&self, i: usize, x: &[f64; 6], n: &V3, u: &V3) -> [f64; 6] {
        let sec = &self.section[i];
        [x[0] - 1.0 - n[0] * sec.inv_ea, x[1] - n[1] * sec.inv_ga, x[2] - n[2] * sec.inv_ga, x[3] - u[0], x[4] - u[1], x[5] - u[2]]
    }

    /// [`SpatialCollocation::residual`] and its Jacobian, I + C S with C =
    /// blockdiag(K_se⁻¹, du/dm) and S the cables' stiffness (only a fresh
    /// local step needs it).
    pub(super) fn residual_and_jacobian(&self, i: usize, tensions: &[f64], x: &[f64; 6], nw: V3, mw: V3) -> ([f64; 6], Matrix6<f64>) {
        let sec = &self.section[i];
        let (n, m) = self.cut_loads(i, tensions, x, nw, mw);
        let (u_law, c_prime) = self.curvature_law(i, &m, sec, true);
        let f = self.residual_of(i, x, &n, &u_law);
        let v = V3::new(x[0], x[1], x[2]);
        let u = V3::new(x[3], x[4], x[5]);
        let (mut svv, mut svu, mut suv, mut suu) = (M3::zeros(), M3::zeros(), M3::zeros(), M3::zeros());
        let nc = self.cables;
        for c in 0..nc {
            let tau = self.tension_at(tensions, i, c);
            if tau == 0.0 {
                continue;
            }
            let ch = self.chan[i * nc + c];
            let q = v + u.cross(&ch.r) + ch.dr;
            let len = q.norm();
            let t = q / len;
            let p = (M3::identity() - t * t.transpose()) * (tau / len);
            let rh = ch.r.cross_matrix();
            let rp = rh * p;
            svv += p;
            svu -= p * rh;
            suv += rp;
            suu -= rp * rh;
        }
        let kv = M3::from_diagonal(&V3::new(sec.inv_ea, sec.inv_ga, sec.inv_ga));
        let mut j = Matrix6::identity();
        let jvv = M3::identity() + kv * svv;
        let jvu = kv * svu;
        let juv = c_prime * suv;
        let juu = M3::identity() + c_prime * suu;
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&jvv);
        j.fixed_view_mut::<3, 3>(0, 3).copy_from(&jvu);
        j.fixed_view_mut::<3, 3>(3, 0).copy_from(&juv);
        j.fixed_view_mut::<3, 3>(3, 3).copy_from(&juu);
        (f, j)
    }
}

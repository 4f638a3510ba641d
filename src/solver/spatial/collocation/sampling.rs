//! The solved state sampled: the centreline at given points or nodes, and each cable's displacement.

use super::*;

impl SpatialCollocation {
    /// The centreline of the last solve at `count` evenly spaced points
    /// and at each span boundary, interpolated from the nodes (spectrally
    /// accurate on each span); a boundary's point is taken from the span
    /// before it, so that a cable anchored there still runs through it.
    pub fn nodes(&self, count: usize) -> Vec<CentrelinePoint> {
        let length = self.rod.length_mm;
        let count = count.max(2);
        let mut samples: Vec<f64> = (0..count).map(|k| length * k as f64 / (count - 1) as f64).collect();
        for &b in &self.start[1..] {
            if !samples.contains(&b) {
                samples.insert(samples.partition_point(|&s| s < b), b);
            }
        }
        self.points_at(&samples)
    }

    /// The centreline of the last solve at the rest arc lengths `s_mm`
    /// (each clamped into [0, L]), interpolated from the nodes (spectrally
    /// accurate on each span); a span boundary's point is taken from the
    /// span before it. Body-fixed points (markers) are evaluated here.
    ///
    /// # Panics
    /// Before a successful solve.
    pub fn points_at(&self, s_mm: &[f64]) -> Vec<CentrelinePoint> {
        assert!(self.last.is_some(), "points_at needs a successful solve");
        let np = self.np;
        let nc = self.cables;
        let length = self.rod.length_mm;
        let samples = s_mm.iter().map(|s| s.clamp(0.0, length));
        // Quaternions of the node frames, sign-continuous.
        let mut quats: Vec<[f64; 4]> = Vec::with_capacity(self.rot.len());
        let mut prev: Option<UnitQuaternion<f64>> = None;
        for r in &self.rot {
            let mut q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
            if let Some(p) = prev {
                if p.coords.dot(&q.coords) < 0.0 {
                    q = UnitQuaternion::new_unchecked(-q.into_inner());
                }
            }
            prev = Some(q);
            quats.push([q.w, q.i, q.j, q.k]);
        }
        let tensions = self.tensions_n();
        samples
            .into_iter()
            .map(|s| {
                let span = self.start[1..].iter().take_while(|&&b| s > b).count().min(self.spans() - 1);
                let x = ((s - self.start[span]) / self.half[span] - 1.0).clamp(-1.0, 1.0);
                let base = span * np;
                let mut vals = [0.0; MAX_NODES + 1];
                let mut at = |f: &dyn Fn(usize) -> f64| {
                    for (j, v) in vals[..np].iter_mut().enumerate() {
                        *v = f(base + j);
                    }
                    chebyshev::interpolate(&self.grid.xn, &vals[..np], x)
                };
                let p = [at(&|i| self.pos[i][0]), at(&|i| self.pos[i][1]), at(&|i| self.pos[i][2])];
                let qv: [f64; 4] = std::array::from_fn(|c| at(&|i| quats[i][c]));
                let r = UnitQuaternion::from_quaternion(Quaternion::new(qv[0], qv[1], qv[2], qv[3])).to_rotation_matrix().into_inner();
                let v: [f64; 3] = std::array::from_fn(|c| at(&|i| self.local[i][c]));
                let u: [f64; 3] = std::array::from_fn(|c| at(&|i| self.local[i][3 + c]));
                let sigma = at(&|i| self.sigma[i]);
                let ratios: Vec<f64> = (0..nc).map(|c| if self.friction { at(&|i| self.state[self.ratio_at + i * nc + c]) } else { 1.0 }).collect();
                let tangent = r * V3::new(v[0], v[1], v[2]);
                let mut node = CentrelinePoint {
                    s_mm: s,
                    x_mm: p[0],
                    y_mm: p[1],
                    z_mm: p[2],
                    rotation: std::array::from_fn(|a| std::array::from_fn(|b| r[(a, b)])),
                    frame_angle_rad: r[(1, 0)].atan2(r[(0, 0)]),
                    tangent_angle_rad: tangent[1].atan2(tangent[0]),
                    arc_length_mm: sigma,
                    v,
                    u_per_mm: u,
                    cables: PerCable::filled(nc, CableAtNode::NONE),
                };
                for c in 0..nc {
                    // The cable runs through the nodes of the spans it pulls in.
                    if self.active[base * nc + c] {
                        let ch = self.channels[c].at(s);
                        let (y, z) = (ch.r_mm[0] + self.rod.effects.channel_offset_mm, ch.r_mm[1]);
                        node.cables[c] = CableAtNode { channel_mm: [y, z], position_mm: node.body_point_mm(y, z), tension_n: tensions[c] * ratios[c] };
                    }
                }
                node
            })
            .collect()
    }

    /// Each cable's displacement at the base, mm: its rest path length less
    /// the deformed one, ∫ |q| ds by the span quadrature, plus its stretch
    /// ∫ τ(s)/EA |q| ds (`tensions`: at the base; friction's profile from
    /// the state).
    pub(super) fn displacements_into(&self, tensions: &[f64], out: &mut [f64]) {
        let np = self.np;
        let nc = self.cables;
        for (c, d) in out.iter_mut().enumerate() {
            let (mut path, mut pulled) = (0.0, 0.0);
            for span in 0..self.spans() {
                let base = span * np;
                if !self.active[base * nc + c] {
                    continue;
                }
                for j in 0..np {
                    let i = base + j;
                    let x = &self.local[i];
                    let ch = &self.chan[i * nc + c];
                    let dl = (V3::new(x[0], x[1], x[2]) + V3::new(x[3], x[4], x[5]).cross(&ch.r) + ch.dr).norm();
                    let w = self.half[span] * self.grid.q[(np - 1) * np + j];
                    path += w * dl;
                    pulled += w * dl * self.tension_at(tensions, i, c);
                }
            }
            *d = self.rest_length_mm[c] - path + self.cable_ea_n[c].map_or(0.0, |ea| pulled / ea);
        }
    }
}

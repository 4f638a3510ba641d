//! Triangle meshes built by hand: a welding builder, a closed 2-manifold
//! check, volumes, and the heightfield solid every mould part is made of.
//!
//! Why by hand: the moulds are open-top trays and plates, i.e. solids under
//! a height function z = h(x, y) with vertical steps. Sampling that function
//! on a structured grid gives the channel's surface exactly where we want it
//! (y_c(s) at every station) and a mesh that is watertight by construction.
//! Rust's mesh-boolean crates (csgrs, the manifold bindings) would pull in a
//! second geometry stack or a C++ build for what is a few extrusions here.

use std::collections::HashMap;

/// A point in mm.
pub type Point = [f64; 3];

/// An indexed triangle mesh, counter-clockwise seen from outside, in mm.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, mm.
    pub vertices: Vec<Point>,
    /// Triangles as vertex indices, outward normals by the right-hand rule.
    pub triangles: Vec<[u32; 3]>,
}

/// Quantum of the vertex welding, mm: points closer than this on every
/// axis are one vertex (they are computed by the same formulas).
const WELD_MM: f64 = 1e-6;

/// Builds a mesh from triangles given by coordinates: equal points are
/// welded into one vertex, and triangles that collapse (two equal corners,
/// e.g. a vertical step of zero height) are dropped.
#[derive(Debug, Default)]
pub struct MeshBuilder {
    mesh: Mesh,
    index: HashMap<[i64; 3], u32>,
}

impl MeshBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    fn vertex(&mut self, p: Point) -> u32 {
        let key = p.map(|v| (v / WELD_MM).round() as i64);
        let next = self.mesh.vertices.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.mesh.vertices.push(p);
            next
        })
    }

    /// Adds triangle a, b, c (counter-clockwise seen from outside).
    pub fn triangle(&mut self, a: Point, b: Point, c: Point) {
        let t = [self.vertex(a), self.vertex(b), self.vertex(c)];
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            self.mesh.triangles.push(t);
        }
    }

    /// Adds quad a, b, c, d (counter-clockwise seen from outside) as two
    /// triangles. The diagonal runs through the corner nearest the plane
    /// y = 0 (then lowest x, then z): a rule the mirror y → −y keeps, so a
    /// mirrored routing gives exactly the mirrored triangles.
    pub fn quad(&mut self, a: Point, b: Point, c: Point, d: Point) {
        let key = |p: &Point| (p[1].abs(), p[0], p[2]);
        let less = |p: &Point, q: &Point| {
            let (kp, kq) = (key(p), key(q));
            kp.0.total_cmp(&kq.0).then(kp.1.total_cmp(&kq.1)).then(kp.2.total_cmp(&kq.2)).is_lt()
        };
        let corners = [a, b, c, d];
        let first = (1..4).fold(0, |best, k| if less(&corners[k], &corners[best]) { k } else { best });
        if first % 2 == 0 {
            self.triangle(a, b, c);
            self.triangle(a, c, d);
        } else {
            self.triangle(a, b, d);
            self.triangle(b, c, d);
        }
    }

    /// The mesh built so far.
    pub fn finish(self) -> Mesh {
        self.mesh
    }
}

impl Mesh {
    /// Enclosed volume, mm³ (divergence theorem; positive for a closed mesh
    /// with outward normals).
    pub fn volume_mm3(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
            })
            .sum::<f64>()
            / 6.0
    }

    /// Axis-aligned bounds (min, max), mm.
    pub fn bounds_mm(&self) -> (Point, Point) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// The mesh moved by `offset_mm`.
    pub fn translated(&self, offset_mm: Point) -> Mesh {
        Mesh {
            vertices: self.vertices.iter().map(|p| [p[0] + offset_mm[0], p[1] + offset_mm[1], p[2] + offset_mm[2]]).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The mirror image in the plane y = 0 (triangles reversed so the
    /// normals stay outward).
    pub fn mirrored_y(&self) -> Mesh {
        Mesh {
            vertices: self.vertices.iter().map(|p| [p[0], -p[1], p[2]]).collect(),
            triangles: self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        }
    }

    /// The segments in which the plane x = `x_mm` cuts the triangles, as
    /// (y, z) pairs (a cross-section, for checks and drawings).
    pub fn slice_x(&self, x_mm: f64) -> Vec<[(f64, f64); 2]> {
        let mut out = Vec::new();
        for t in &self.triangles {
            let mut pts = Vec::new();
            for k in 0..3 {
                let (a, b) = (self.vertices[t[k] as usize], self.vertices[t[(k + 1) % 3] as usize]);
                if (a[0] - x_mm) * (b[0] - x_mm) < 0.0 {
                    let f = (x_mm - a[0]) / (b[0] - a[0]);
                    pts.push((a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])));
                }
            }
            if pts.len() == 2 {
                out.push([pts[0], pts[1]]);
            }
        }
        out
    }

    /// Appends `other` as further shells of this mesh.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// Checks that the mesh is a closed, consistently oriented 2-manifold
    /// with positive volume per shell (see [`MeshReport`]).
    pub fn check(&self) -> MeshReport {
        // Directed edge → how often it occurs.
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        let (mut boundary, mut non_manifold, mut inconsistent, mut edges) = (0, 0, 0, 0);
        for (&(a, b), &n) in &directed {
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if a < b || back == 0 {
                edges += 1;
                match (n, back) {
                    (1, 1) => {}
                    (1, 0) => boundary += 1,
                    (_, 0) if n == 2 => inconsistent += 1,
                    _ => non_manifold += 1,
                }
            }
        }
        let degenerate = self
            .triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
                (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() < 1e-10
            })
            .count();
        let shells = self.shells();
        let shell_volumes_mm3 = shells.iter().map(|m| m.volume_mm3()).collect();
        MeshReport {
            vertices: self.vertices.len(),
            triangles: self.triangles.len(),
            edges,
            boundary_edges: boundary,
            non_manifold_edges: non_manifold,
            inconsistent_edges: inconsistent,
            degenerate_triangles: degenerate,
            shell_volumes_mm3,
            volume_mm3: self.volume_mm3(),
        }
    }

    /// The connected pieces (triangles sharing a vertex), each as its own mesh.
    pub fn shells(&self) -> Vec<Mesh> {
        let mut parent: Vec<u32> = (0..self.vertices.len() as u32).collect();
        fn find(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                parent[i as usize] = parent[parent[i as usize] as usize];
                i = parent[i as usize];
            }
            i
        }
        for t in &self.triangles {
            let r0 = find(&mut parent, t[0]);
            for &v in &t[1..] {
                let r = find(&mut parent, v);
                parent[r as usize] = r0;
            }
        }
        let mut by_root: HashMap<u32, usize> = HashMap::new();
        let mut out: Vec<(Mesh, HashMap<u32, u32>)> = Vec::new();
        for t in &self.triangles {
            let root = find(&mut parent, t[0]);
            let k = *by_root.entry(root).or_insert_with(|| {
                out.push((Mesh::default(), HashMap::new()));
                out.len() - 1
            });
            let (mesh, map) = &mut out[k];
            let tri = t.map(|v| {
                *map.entry(v).or_insert_with(|| {
                    mesh.vertices.push(self.vertices[v as usize]);
                    mesh.vertices.len() as u32 - 1
                })
            });
            mesh.triangles.push(tri);
        }
        out.into_iter().map(|(m, _)| m).collect()
    }
}

/// What [`Mesh::check`] found.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MeshReport {
    /// Number of vertices.
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of distinct edges.
    pub edges: usize,
    /// Edges with one triangle (holes).
    pub boundary_edges: usize,
    /// Edges with more than two triangles, or two in one direction and more.
    pub non_manifold_edges: usize,
    /// Edges whose two triangles run the same way (flipped normals).
    pub inconsistent_edges: usize,
    /// Triangles of (near) zero area.
    pub degenerate_triangles: usize,
    /// Volume of each connected shell, mm³.
    pub shell_volumes_mm3: Vec<f64>,
    /// Total volume, mm³.
    pub volume_mm3: f64,
}

impl MeshReport {
    /// Closed, 2-manifold, consistently oriented, no degenerate triangles,
    /// and every shell encloses a positive volume.
    pub fn is_watertight(&self) -> bool {
        self.triangles > 0
            && self.boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.inconsistent_edges == 0
            && self.degenerate_triangles == 0
            && self.shell_volumes_mm3.iter().all(|v| *v > 0.0)
    }
}

/// A station or sample position with the side of a step it belongs to:
/// −1 the limit from below, +1 from above, 0 a smooth place.
pub type Sided = (f64, i8);

/// Offset used to evaluate one-sided limits at a step, mm.
const SIDE_MM: f64 = 1e-7;

/// The position a sided coordinate is evaluated at.
pub fn sided(v: Sided) -> f64 {
    v.0 + f64::from(v.1) * SIDE_MM
}

/// A solid between a flat bottom z = `z_bottom_mm` and a top z = h(x, y)
/// over the rectangle spanned by the stations and samples.
///
/// `stations` are x positions in increasing order (a step in x is a station
/// given twice, with sides −1 and +1). `samples(x)` gives the y positions at
/// one station, increasing, the same count at every station, the first and
/// last equal to the rectangle's edges (a step in y is a sample given twice).
/// `height(x, y)` is evaluated at the sided positions. The top surface is the
/// grid of samples; walls join its edges to the bottom. Vertical steps come
/// out as vertical faces; steps of zero height weld away.
pub fn heightfield_solid(
    stations: &[Sided],
    samples: &dyn Fn(Sided) -> Vec<Sided>,
    height: &dyn Fn(Sided, Sided) -> f64,
    z_bottom_mm: f64,
) -> Mesh {
    let grid: Vec<Vec<Point>> = stations
        .iter()
        .map(|&x| samples(x).into_iter().map(|y| [x.0, y.0, height(x, y)]).collect())
        .collect();
    let m = grid[0].len();
    assert!(grid.iter().all(|row| row.len() == m), "every station needs the same number of samples");
    let n = grid.len();
    let mut b = MeshBuilder::new();
    let low = |p: Point| [p[0], p[1], z_bottom_mm];
    for i in 0..n - 1 {
        for j in 0..m - 1 {
            b.quad(grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]);
        }
        // Side walls at the first (−y) and last (+y) samples.
        let (t0, t1) = (grid[i][0], grid[i + 1][0]);
        b.quad(low(t0), low(t1), t1, t0);
        let (t0, t1) = (grid[i][m - 1], grid[i + 1][m - 1]);
        b.quad(low(t0), t0, t1, low(t1));
    }
    for j in 0..m - 1 {
        // End walls at the first (−x) and last (+x) stations.
        let (p0, p1) = (grid[0][j], grid[0][j + 1]);
        b.quad(low(p0), p0, p1, low(p1));
        let (p0, p1) = (grid[n - 1][j], grid[n - 1][j + 1]);
        b.quad(low(p0), low(p1), p1, p0);
    }
    // Bottom: a fan from its centre over the boundary loop (a convex polygon
    // with the walls' points on its edges), clockwise seen from above.
    let mut ring: Vec<Point> = Vec::new();
    ring.extend((0..n).map(|i| low(grid[i][0])));
    ring.extend((1..m).map(|j| low(grid[n - 1][j])));
    ring.extend((0..n - 1).rev().map(|i| low(grid[i][m - 1])));
    ring.extend((1..m - 1).rev().map(|j| low(grid[0][j])));
    let (lo, hi) = (ring.iter().fold([f64::INFINITY; 2], |a, p| [a[0].min(p[0]), a[1].min(p[1])]), ring
        .iter()
        .fold([f64::NEG_INFINITY; 2], |a, p| [a[0].max(p[0]), a[1].max(p[1])]));
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, z_bottom_mm];
    for k in 0..ring.len() {
        b.triangle(centre, ring[(k + 1) % ring.len()], ring[k]);
    }
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(a: f64, b: f64, n: usize) -> Vec<Sided> {
        (0..=n).map(|k| (a + (b - a) * k as f64 / n as f64, 0)).collect()
    }

    #[test]
    fn a_box_is_watertight_with_its_volume() {
        let xs = uniform(0.0, 4.0, 4);
        let m = heightfield_solid(&xs, &|_| uniform(0.0, 3.0, 3), &|_, _| 2.0, 0.0);
        let r = m.check();
        assert!(r.is_watertight(), "{r:?}");
        assert!((r.volume_mm3 - 24.0).abs() < 1e-9, "{r:?}");
    }

    #[test]
    fn steps_and_pockets_stay_closed() {
        // A 10 × 10 × 2 block with a 2 mm pin on [2,4]² and a 1 mm pocket on [6,8]².
        let mut xs = vec![(0.0, 0), (2.0, -1), (2.0, 1), (4.0, -1), (4.0, 1), (6.0, -1), (6.0, 1), (8.0, -1), (8.0, 1), (10.0, 0)];
        xs.insert(5, (5.0, 0));
        let ys = xs.clone();
        let inside = |v: Sided, lo: f64, hi: f64| lo < sided(v) && sided(v) < hi;
        let h = |x: Sided, y: Sided| {
            if inside(x, 2.0, 4.0) && inside(y, 2.0, 4.0) {
                4.0
            } else if inside(x, 6.0, 8.0) && inside(y, 6.0, 8.0) {
                1.0
            } else {
                2.0
            }
        };
        let m = heightfield_solid(&xs, &|_| ys.clone(), &h, 0.0);
        let r = m.check();
        assert!(r.is_watertight(), "{r:?}");
        assert!((r.volume_mm3 - (200.0 + 8.0 - 4.0)).abs() < 1e-6, "{r:?}");
        assert_eq!(r.shell_volumes_mm3.len(), 1);
        // Mirroring keeps it watertight with the same volume.
        let mm = m.mirrored_y().check();
        assert!(mm.is_watertight() && (mm.volume_mm3 - r.volume_mm3).abs() < 1e-9);
    }

    #[test]
    fn the_checker_finds_holes_and_flips() {
        let xs = uniform(0.0, 1.0, 1);
        let m = heightfield_solid(&xs, &|_| uniform(0.0, 1.0, 1), &|_, _| 1.0, 0.0);
        let mut holed = m.clone();
        holed.triangles.pop();
        let r = holed.check();
        assert!(!r.is_watertight() && r.boundary_edges == 3, "{r:?}");
        let mut flipped = m.clone();
        let t = flipped.triangles[0];
        flipped.triangles[0] = [t[0], t[2], t[1]];
        let r = flipped.check();
        assert!(!r.is_watertight() && r.inconsistent_edges == 3, "{r:?}");
        let mut doubled = m.clone();
        doubled.append(&m);
        // Two separate copies are two closed shells (vertices not shared).
        assert!(doubled.check().is_watertight());
        let mut shared = m.clone();
        shared.triangles.push(m.triangles[0]);
        shared.triangles.push([m.triangles[0][0], m.triangles[0][2], m.triangles[0][1]]);
        assert!(shared.check().non_manifold_edges > 0);
    }
}

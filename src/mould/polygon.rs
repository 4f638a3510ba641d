//! Triangulation of a plane polygon with holes (the end faces of a body
//! with lumens): holes bridged into the outline, then ear clipping.
//!
//! Written by hand for the same reason as the meshes (`mesh.rs`): the faces
//! are a disc with a few well separated ellipses, a few hundred corners,
//! where O(n²) ear clipping is instant and a crate would be a dependency
//! for forty lines of use.

/// A point of the plane.
pub type P2 = [f64; 2];

fn cross(o: P2, a: P2, b: P2) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Twice the signed area of a closed polygon (positive counter-clockwise).
pub fn signed_area2(points: &[P2]) -> f64 {
    (0..points.len()).map(|i| {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        a[0] * b[1] - a[1] * b[0]
    }).sum()
}

/// Whether `p` lies inside or on triangle a, b, c (counter-clockwise).
fn in_triangle(p: P2, a: P2, b: P2, c: P2) -> bool {
    cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0
}

/// Why a polygon could not be triangulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Ear clipping found no ear: the outline crosses itself or a hole.
    #[error("the face polygon crosses itself or a hole ({left} corners left without an ear)")]
    NoEar {
        /// Corners left when no ear was found.
        left: usize,
    },
    /// A hole could not be bridged to the outline.
    #[error("a hole of the face polygon lies outside the outline or on another hole")]
    NoBridge,
}

/// Triangulates the region inside `outer` (counter-clockwise) and outside
/// every hole (each counter-clockwise as well; they must lie inside `outer`
/// and apart). Returns triangles as indices into the concatenation
/// `outer ++ holes[0] ++ holes[1] ++ …`, counter-clockwise.
pub fn triangulate(outer: &[P2], holes: &[Vec<P2>]) -> Result<Vec<[usize; 3]>, PolygonError> {
    let mut pts: Vec<P2> = outer.to_vec();
    let mut starts = Vec::new();
    for h in holes {
        starts.push(pts.len());
        pts.extend_from_slice(h);
    }
    // The merged loop, as indices: the outline, then each hole spliced in
    // (clockwise) by a bridge from its rightmost corner, rightmost hole first.
    let mut ring: Vec<usize> = (0..outer.len()).collect();
    let mut order: Vec<usize> = (0..holes.len()).collect();
    let rightmost = |h: usize| -> usize {
        let s = starts[h];
        (s..s + holes[h].len()).max_by(|a, b| pts[*a][0].total_cmp(&pts[*b][0]).then(pts[*b][1].total_cmp(&pts[*a][1]))).expect("a hole has corners")
    };
    order.sort_by(|a, b| pts[rightmost(*b)][0].total_cmp(&pts[rightmost(*a)][0]));
    for h in order {
        let m = rightmost(h);
        let mp = pts[m];
        // Nearest crossing of the ray from M towards +x with the loop's edges.
        let mut best: Option<(f64, usize)> = None;
        for k in 0..ring.len() {
            let (a, b) = (pts[ring[k]], pts[ring[(k + 1) % ring.len()]]);
            if (a[1] - mp[1]) * (b[1] - mp[1]) > 0.0 || a[1] == b[1] {
                continue;
            }
            let x = a[0] + (mp[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x >= mp[0] && best.is_none_or(|(bx, _)| x < bx) {
                best = Some((x, k));
            }
        }
        let (ix, k) = best.ok_or(PolygonError::NoBridge)?;
        let (ka, kb) = (k, (k + 1) % ring.len());
        // The edge's end farther right; then any loop corner inside the
        // triangle M, I, P with the smallest angle to the ray replaces it.
        let mut pick = if pts[ring[ka]][0] > pts[ring[kb]][0] { ka } else { kb };
        let (i_pt, p_pt) = ([ix, mp[1]], pts[ring[pick]]);
        let tri = if cross(mp, i_pt, p_pt) >= 0.0 { [mp, i_pt, p_pt] } else { [mp, p_pt, i_pt] };
        let mut best_angle = f64::INFINITY;
        for (j, &v) in ring.iter().enumerate() {
            let q = pts[v];
            if j == pick || q == p_pt || !in_triangle(q, tri[0], tri[1], tri[2]) || q[0] <= mp[0] {
                continue;
            }
            let angle = ((q[1] - mp[1]).abs()).atan2(q[0] - mp[0]);
            if angle < best_angle {
                best_angle = angle;
                pick = j;
            }
        }
        let s = starts[h];
        let n = holes[h].len();
        // Hole corners clockwise from M back to M.
        let mut splice: Vec<usize> = (0..=n).map(|i| s + (m - s + n - i) % n).collect();
        splice.push(ring[pick]);
        ring.splice(pick + 1..pick + 1, splice);
    }
    clip_ears(&pts, ring)
}

/// Ear clipping of one loop (counter-clockwise, bridges allowed: repeated
/// points are skipped in the containment test).
fn clip_ears(pts: &[P2], mut ring: Vec<usize>) -> Result<Vec<[usize; 3]>, PolygonError> {
    let mut out = Vec::with_capacity(ring.len());
    let mut i = 0;
    let mut stalled = 0;
    while ring.len() > 3 {
        let n = ring.len();
        let (ia, ib, ic) = (ring[(i + n - 1) % n], ring[i % n], ring[(i + 1) % n]);
        let (a, b, c) = (pts[ia], pts[ib], pts[ic]);
        let convex = cross(a, b, c) > 0.0;
        let ear = convex
            && ring.iter().all(|&v| {
                let q = pts[v];
                v == ia || v == ib || v == ic || q == a || q == b || q == c || !in_triangle(q, a, b, c)
            });
        if ear {
            out.push([ia, ib, ic]);
            ring.remove(i % n);
            stalled = 0;
            if i > 0 {
                i -= 1;
            }
        } else {
            i = (i + 1) % n;
            stalled += 1;
            if stalled > n {
                return Err(PolygonError::NoEar { left: n });
            }
        }
    }
    if ring.len() == 3 {
        if cross(pts[ring[0]], pts[ring[1]], pts[ring[2]]) > 0.0 {
            out.push([ring[0], ring[1], ring[2]]);
        } else if cross(pts[ring[0]], pts[ring[1]], pts[ring[2]]) < 0.0 {
            return Err(PolygonError::NoEar { left: 3 });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(cx: f64, cy: f64, r: f64, n: usize) -> Vec<P2> {
        (0..n).map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            [cx + r * a.cos(), cy + r * a.sin()]
        }).collect()
    }

    fn area(pts: &[P2], tris: &[[usize; 3]]) -> f64 {
        tris.iter().map(|t| cross(pts[t[0]], pts[t[1]], pts[t[2]]) / 2.0).sum()
    }

    #[test]
    fn a_disc_with_holes_is_covered_once() {
        let outer = circle(0.0, 0.0, 5.0, 96);
        for holes in [
            vec![],
            vec![circle(1.0, 0.5, 0.5, 32)],
            vec![circle(-3.0, 0.0, 0.6, 32), circle(3.0, 0.0, 0.6, 32), circle(0.0, 3.0, 0.6, 32), circle(0.0, -3.0, 0.6, 32)],
            // Holes in one row along the ray: each bridge must pass by the others.
            vec![circle(-2.0, 0.0, 0.5, 24), circle(0.0, 0.0, 0.5, 24), circle(2.0, 0.0, 0.5, 24), circle(3.8, 0.0, 0.5, 24)],
        ] {
            let tris = triangulate(&outer, &holes).unwrap();
            let mut pts = outer.clone();
            holes.iter().for_each(|h| pts.extend_from_slice(h));
            let expected = (signed_area2(&outer) - holes.iter().map(|h| signed_area2(h)).sum::<f64>()) / 2.0;
            assert!((area(&pts, &tris) - expected).abs() < 1e-9 * expected, "{} vs {expected}", area(&pts, &tris));
            assert!(tris.iter().all(|t| cross(pts[t[0]], pts[t[1]], pts[t[2]]) > 0.0));
            // Every boundary edge once, every inner edge twice (opposite ways).
            let mut edges = std::collections::HashMap::new();
            for t in &tris {
                for k in 0..3 {
                    *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
                }
            }
            let total = outer.len() + holes.iter().map(Vec::len).sum::<usize>();
            assert_eq!(tris.len(), total - 2 + 2 * holes.len());
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "edge {a}-{b} used {n} times the same way");
            }
        }
    }
}

//! Binary STL, the file format of the moulds (owned by this module).
//!
//! Written by hand: the format is an 80-byte header, a triangle count and
//! 50 bytes per triangle (normal, three corners as little-endian f32, a
//! zero attribute word). That is shorter than adopting a crate for it.
//! STL has no unit field; the header says "units mm", which slicers assume.

use super::mesh::{Mesh, Point};
use std::io::{self, Write};

/// The 80-byte header: `text` cut or padded with spaces.
fn header(text: &str) -> [u8; 80] {
    let mut h = [b' '; 80];
    let bytes = text.as_bytes();
    let n = bytes.len().min(80);
    h[..n].copy_from_slice(&bytes[..n]);
    h
}

fn normal(a: Point, b: Point, c: Point) -> [f64; 3] {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 {
        n.map(|v| v / len)
    } else {
        [0.0; 3]
    }
}

/// The mesh as binary STL bytes with `title` in the header (ASCII, starts
/// with "cablemap" so no reader mistakes it for ASCII STL, which starts with "solid").
pub fn to_bytes(mesh: &Mesh, title: &str) -> Vec<u8> {
    let mut out = Vec::with_capacity(84 + 50 * mesh.triangles.len());
    out.extend_from_slice(&header(title));
    out.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        for v in normal(a, b, c).iter().chain(a.iter()).chain(b.iter()).chain(c.iter()) {
            out.extend_from_slice(&(*v as f32).to_le_bytes());
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// Writes binary STL to `w`.
pub fn write(mut w: impl Write, mesh: &Mesh, title: &str) -> io::Result<()> {
    w.write_all(&to_bytes(mesh, title))
}

/// Why bytes are not binary STL.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StlError {
    /// Fewer bytes than the header.
    #[error("{bytes} bytes is too short for binary STL (84-byte header)")]
    TooShort {
        /// Bytes given.
        bytes: usize,
    },
    /// The triangle count disagrees with the length.
    #[error("header says {triangles} triangles ({expected} bytes) but the file has {bytes} bytes")]
    WrongLength {
        /// Triangles in the header.
        triangles: usize,
        /// Bytes that count needs.
        expected: usize,
        /// Bytes given.
        bytes: usize,
    },
}

/// Reads binary STL: the header text and the mesh, corners welded where
/// they are bit-identical (as written).
pub fn read(bytes: &[u8]) -> Result<(String, Mesh), StlError> {
    if bytes.len() < 84 {
        return Err(StlError::TooShort { bytes: bytes.len() });
    }
    let count = u32::from_le_bytes(bytes[80..84].try_into().expect("4 bytes")) as usize;
    if bytes.len() != 84 + 50 * count {
        return Err(StlError::WrongLength { triangles: count, expected: 84 + 50 * count, bytes: bytes.len() });
    }
    let title = String::from_utf8_lossy(&bytes[..80]).trim_end().to_string();
    let mut mesh = Mesh::default();
    let mut index = std::collections::HashMap::new();
    for k in 0..count {
        let rec = &bytes[84 + 50 * k..84 + 50 * (k + 1)];
        let f = |i: usize| f32::from_le_bytes(rec[4 * i..4 * i + 4].try_into().expect("4 bytes"));
        let mut tri = [0u32; 3];
        for (c, slot) in tri.iter_mut().enumerate() {
            let p = [f(3 + 3 * c), f(4 + 3 * c), f(5 + 3 * c)];
            let key = p.map(f32::to_bits);
            let next = mesh.vertices.len() as u32;
            *slot = *index.entry(key).or_insert_with(|| {
                mesh.vertices.push(p.map(f64::from));
                next
            });
        }
        mesh.triangles.push(tri);
    }
    Ok((title, mesh))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mould::mesh::heightfield_solid;

    #[test]
    fn round_trip_keeps_the_solid() {
        let xs: Vec<_> = (0..=3).map(|k| (k as f64, 0)).collect();
        let m = heightfield_solid(&xs, &|_| vec![(0.0, 0), (2.0, 0)], &|x, _| 1.0 + x.0 * 0.5, 0.0);
        let bytes = to_bytes(&m, "cablemap test, units mm");
        assert_eq!(bytes.len(), 84 + 50 * m.triangles.len());
        let (title, back) = read(&bytes).unwrap();
        assert_eq!(title, "cablemap test, units mm");
        let r = back.check();
        assert!(r.is_watertight(), "{r:?}");
        assert!((r.volume_mm3 - m.volume_mm3()).abs() < 1e-4);
        assert!(read(&bytes[..100]).is_err());
    }
}

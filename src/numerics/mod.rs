//! Numerical methods shared by several layers: the bounded
//! Levenberg–Marquardt minimiser of calibrate's fits and design's search.

pub mod lm;

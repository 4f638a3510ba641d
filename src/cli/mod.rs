//! Command-line front ends (binary only): each command's file turns its
//! flags into a library request, runs it and prints the report; `main.rs`
//! only parses and dispatches.
//!
//! - [`actuator`], [`basis`]: the rod, solver and coefficient flags that
//!   every command which simulates shares.
//! - [`parse`]: reading the command line (a nearer suggestion for a
//!   mistyped flag; lists of numbers).
//! - [`output`]: where reports and progress lines go; [`errors`]: how an
//!   error is printed.
//! - one file per command (or pair of commands).

pub mod actuator;
pub mod basis;
pub mod errors;
pub mod output;
pub mod parse;

pub mod bench;
pub mod calibrate;
pub mod design;
pub mod diagnose;
pub mod feasible;
pub mod mould;
pub mod predict;
pub mod reduce;
pub mod simulate;
pub mod study;
pub mod sweep;
pub mod synth;

pub use actuator::ActuatorArgs;
pub use basis::LengthBasisArgs;
pub use errors::error_text;
pub use parse::{parse_args, parse_list};

//! Rig dynamics as plain Rust (no FFI, no unsafe): the mechanical side of a
//! friction co-simulation. Sign convention of MODELS.md: the friction block
//! outputs F resisting positive slip, and the rig applies −F.
#![forbid(unsafe_code)]

pub mod rig1d;

//! Monolithic reference solutions for the friction co-simulations.
#![forbid(unsafe_code)]

pub mod radau;

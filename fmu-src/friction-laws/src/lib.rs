//! Friction laws as plain Rust: no FFI, no `unsafe`, no I/O.
//!
//! Every law here is a state machine advanced over a time interval with
//! inputs that vary linearly inside it (`u(τ) = u0 + du·τ`, the first-order
//! input interpolation of FMI 2.0 co-simulation). The equations and their
//! sources are in `docs/models.md`; each module cites its papers by author
//! and year.
//!
//! Sign convention (docs/models.md): `v` is the sliding velocity of the body
//! relative to the surface, `F` the friction force resisting positive motion,
//! so in steady sliding `F` has the sign of `v` and the rig applies `−F`.
#![forbid(unsafe_code)]

pub mod bliman_sorine;
pub mod bristle;
pub mod bristle2d;
pub mod classical;
pub mod dahl;
pub mod elasto_plastic;
pub mod error;
mod interval;
pub mod lugre;
pub mod maxwell_slip;
pub mod reset_integrator;
pub mod rng;
mod state;

pub use error::ParamError;

/// A signal that varies linearly over a step: `u(τ) = value + slope·τ`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ramp {
    pub value: f64,
    pub slope: f64,
}

impl Ramp {
    pub const fn constant(value: f64) -> Self {
        Ramp { value, slope: 0.0 }
    }
    pub const fn new(value: f64, slope: f64) -> Self {
        Ramp { value, slope }
    }
    /// Value at `τ` seconds into the step.
    pub fn at(&self, tau: f64) -> f64 {
        self.value + self.slope * tau
    }
}

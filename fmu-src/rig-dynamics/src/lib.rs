//! Rig dynamics as plain Rust (no FFI, no unsafe): the mechanical side of a
//! friction co-simulation. Sign convention of docs/models.md: the friction
//! block outputs F resisting positive slip, and the rig applies −F.
//!
//! - [`rig1d`]: one axis — mass, damper, spring to an actuator point
//!   (ramp, sinusoid or input), built-in drive force, PD/PI controller with
//!   saturation, moving and dithered surface, quasi-static mode m = 0.
//! - [`rig2d`]: the planar oscillator of Wijata et al. 2016 with surface
//!   dither.
#![forbid(unsafe_code)]

#[cfg(test)]
mod closed_form;
mod exact;
mod gauss_legendre;
pub mod rig1d;
pub mod rig2d;
pub mod signals;

/// `invalid parameter <name> = <value>: must be finite`.
pub(crate) fn check_finite(name: &str, value: f64) -> Result<(), String> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(format!(
            "invalid parameter {name} = {value}: must be finite"
        ))
    }
}

/// Finite and >= 0, else an error naming the parameter and value.
pub(crate) fn check_non_negative(name: &str, value: f64) -> Result<(), String> {
    check_finite(name, value)?;
    if value < 0.0 {
        return Err(format!("invalid parameter {name} = {value}: must be >= 0"));
    }
    Ok(())
}

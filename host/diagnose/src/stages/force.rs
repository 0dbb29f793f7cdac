//! Stage 2, the force estimate or the output-error set-up: the friction
//! force the data imply (measured as `friction.F`, or by the inverse
//! dynamics of the Rig1D the friction acts on,
//! [`Setup::friction_data`]), or, for any other plant, the law's states
//! along the nominal co-simulation
//! ([`crate::sim::friction_data_simulated`]), every fit then by output
//! error.
//!
//! Takes the [`super::load::Loaded`] parts; gives a [`ForceEvidence`] for the data
//! records and the held-out records.

use crate::problem::{FrictionData, Measured, Setup};
use crate::sim;
use crate::ssp::SystemFile;
use crate::system::System;

/// The friction data of the records, and how they were obtained.
pub(crate) struct ForceEvidence {
    /// Why the force cannot be estimated from the data, when it cannot:
    /// then every fit is by output error.
    pub(crate) output_error_only: Option<String>,
    /// The friction data of the data records.
    pub(crate) data: FrictionData,
    /// The friction data of the held-out records, when given.
    pub(crate) heldout: Option<FrictionData>,
}

/// The friction data of `data` and of `heldout_records`, from the force
/// the data imply when it can be estimated ([`Setup::force_estimable`]),
/// else along co-simulations of the nominal system (`smooth`: the
/// Savitzky–Golay window of the inverse dynamics, s).
pub(crate) fn estimate_force(
    file: &SystemFile,
    setup: &Setup,
    system: &mut System,
    data: &Measured,
    heldout_records: Option<&Measured>,
    smooth: f64,
) -> Result<ForceEvidence, String> {
    let output_error_only = setup.force_estimable(data).err();
    let friction_data = |system: &mut System, records: &Measured| {
        match &output_error_only {
        None => setup.friction_data(system, records, smooth),
        Some(why) => sim::friction_data_simulated(setup, file, system, records, why).map_err(|e| {
            format!(
                "{}: the friction force cannot be estimated from the data ({why}), and the nominal system could not be co-simulated along it to fit by output error: {e}",
                records.label
            )
        }),
    }
    };
    let data_friction = friction_data(system, data)?;
    let heldout_friction = match heldout_records {
        Some(h) => Some(friction_data(system, h)?),
        None => None,
    };
    Ok(ForceEvidence {
        output_error_only,
        data: data_friction,
        heldout: heldout_friction,
    })
}

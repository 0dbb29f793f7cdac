//! Stage 1, the data read and inspected: the system built, the data
//! records and the held-out records read ([`Measured::read`], which
//! inspects each file for spikes, dropouts, gaps and saturation,
//! [`crate::quality`]) and joined, and the set-up around the friction
//! component found ([`Setup`]).
//!
//! Takes the system file, the paths of the data and held-out records and
//! the options; gives a [`Loaded`].

use crate::problem::{Measured, Setup};
use crate::ssp::SystemFile;
use crate::system::System;
use crate::{diagnosis_master, quality, Options};
use std::path::PathBuf;

/// What the data files hold and the system they drive.
pub(crate) struct Loaded {
    /// The nominal system, built once (each co-simulation restarts it).
    pub(crate) system: System,
    /// The data records, joined ([`Measured::join`]): the models are
    /// fitted on them (and scored on parts of them, without held-out
    /// records).
    pub(crate) data: Measured,
    /// The held-out records (`--heldout`), joined, when given: the models
    /// are scored on them.
    pub(crate) heldout_records: Option<Measured>,
    /// The friction component, its rig, the master and step.
    pub(crate) setup: Setup,
}

/// Read and inspect the records of `data_paths` and `heldout_paths` for
/// the system of `file`: an error names a file that cannot be read or
/// held-out records that measure other channels than the data records.
pub(crate) fn load(
    file: &SystemFile,
    data_paths: &[PathBuf],
    heldout_paths: &[PathBuf],
    options: &Options,
) -> Result<Loaded, String> {
    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
    let data = read_joined(data_paths, &system)?;
    let heldout_records = match heldout_paths.is_empty() {
        false => {
            let h = read_joined(heldout_paths, &system)?;
            let a: Vec<&String> = data.outputs.iter().map(|(n, _)| n).collect();
            let b: Vec<&String> = h.outputs.iter().map(|(n, _)| n).collect();
            if a != b {
                return Err(format!(
                    "{}: measures {:?}, but {} measures {:?}; both files must measure the same channels",
                    h.label, b, data.label, a
                ));
            }
            Some(h)
        }
        true => None,
    };
    let step = step_of(file, &data);
    let master = diagnosis_master(
        &file.settings.master_or_default(),
        options.master.as_deref(),
    );
    let setup = Setup::new(file, &mut system, step, &master)?;
    Ok(Loaded {
        system,
        data,
        heldout_records,
        setup,
    })
}

/// The records of `paths`, each read and inspected, joined into one.
fn read_joined(paths: &[PathBuf], system: &System) -> Result<Measured, String> {
    paths
        .iter()
        .map(|p| Measured::read(p, system))
        .collect::<Result<Vec<_>, _>>()
        .and_then(Measured::join)
}

/// The co-simulation step: the system file's, else the data's median
/// sample spacing.
pub(crate) fn step_of(file: &SystemFile, data: &Measured) -> f64 {
    match file.settings.step_size {
        Some(h) => h,
        None => quality::median_spacing(&data.time),
    }
}

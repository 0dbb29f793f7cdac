//! Building a checked system file into a [`System`]: its FMUs
//! instantiated with the file's parameter values (then any overrides),
//! connected, and the annotated signals recorded. Uses the definitions of
//! [`super`], [`super::check`] and [`crate::system`].

use super::{error, CheckedSystem, SspError, SystemFile, Value};
use crate::system::{Experiment, ParameterValue, System};

impl SystemFile {
    /// Check, then instantiate the system with its parameters and
    /// connections, set up to start at `start`.
    pub fn build(&self, start: f64) -> Result<System, SspError> {
        self.build_with(start, &[])
    }

    /// [`SystemFile::build`] with `overrides` (`component.variable`, value)
    /// set after the file's own parameter values, so that they win: one
    /// point of a parameter sweep (`fricsim sweep`).
    pub fn build_with(
        &self,
        experiment: impl Into<Experiment>,
        overrides: &[(String, ParameterValue)],
    ) -> Result<System, SspError> {
        self.instantiate(&self.check()?, experiment, overrides)
    }

    /// [`SystemFile::build_with`] on FMUs already opened and checked by
    /// [`SystemFile::check`]: new instances of the same loaded FMUs, so
    /// that repeated runs (`fricsim sweep`) unpack and load nothing again.
    pub fn instantiate(
        &self,
        checked: &CheckedSystem,
        experiment: impl Into<Experiment>,
        overrides: &[(String, ParameterValue)],
    ) -> Result<System, SspError> {
        let parameters: Vec<(String, ParameterValue)> = self
            .parameters
            .iter()
            .map(|p| {
                let v = match &p.value {
                    Value::Real(x) => ParameterValue::Number(*x),
                    Value::Integer(i) => ParameterValue::Number(*i as f64),
                    Value::Boolean(b) => ParameterValue::Number(if *b { 1.0 } else { 0.0 }),
                    Value::String(s) => ParameterValue::Text(s.clone()),
                };
                (format!("{}.{}", p.component, p.variable), v)
            })
            .chain(overrides.iter().cloned())
            .collect();
        let connections: Vec<(String, String)> = checked
            .connections
            .iter()
            .map(|c| (c.from.clone(), c.to.clone()))
            .collect();
        let mut system =
            System::from_fmus(checked.fmus.clone(), &parameters, &connections, experiment)
                .map_err(|e| error(&self.ssd, e.to_string()))?;
        for s in self.settings.record.iter().chain(&self.settings.plot) {
            system.record(s).map_err(|e| {
                error(
                    self.settings.location.as_deref().unwrap_or(&self.ssd),
                    e.to_string(),
                )
            })?;
        }
        Ok(system)
    }
}

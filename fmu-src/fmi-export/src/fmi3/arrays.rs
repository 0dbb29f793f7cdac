//! FMI 3.0 arrays over the variable table's numbered scalars.
//!
//! The table (and FMI 2.0) writes an array as scalars named `x_table[1]`,
//! `x_table[2]`, … with consecutive value references; FMI 3.0 declares it
//! as one variable with a `<Dimension>` (FMI 3.0 section 2.4.7.4), whose
//! value reference is that of its first element, read and written as a
//! whole: `fmi3GetFloat64` of the array's value reference gives all its
//! values. [`Layout`] groups the table into the variables FMI 3.0 sees and
//! turns a list of FMI 3.0 value references into the table's, element by
//! element.
//!
//! A run of scalars becomes an array when their names are `base[1]` …
//! `base[n]` (or `der(base[1])` …, the derivatives of an array of states,
//! which become `der(base)`), n ≥ 2, with consecutive value references and
//! the same type, causality, variability, unit, bounds and nominal.

use crate::variables::{ModelInfo, Variable};
use std::sync::{Mutex, OnceLock};

/// One variable as FMI 3.0 sees it: a scalar of the table, or an array of
/// `len` scalars from value reference `vr` on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fmi3Variable {
    /// The FMI 3.0 value reference: the table's, of the first element.
    pub vr: u32,
    /// The number of elements; 1 for a scalar.
    pub len: u32,
    /// The FMI 3.0 name: the table's for a scalar, `base` (or
    /// `der(base)`) for an array.
    pub name: String,
    /// Declared with a `<Dimension>`.
    pub is_array: bool,
}

/// The FMI 3.0 variables of one model, in table order.
#[derive(Debug)]
pub struct Layout {
    pub variables: Vec<Fmi3Variable>,
    /// Per table value reference, the index of its FMI 3.0 variable.
    variable_of: Vec<u32>,
    /// Whether any variable is an array (else every list of value
    /// references is the table's as it is).
    pub has_arrays: bool,
}

/// `(base, index)` of an element name: `x[3]` is `("x", 3)`, `der(x[3])`
/// is `("der(x)", 3)`.
fn element(name: &str) -> Option<(String, u32)> {
    if let Some(inner) = name.strip_prefix("der(").and_then(|n| n.strip_suffix(')')) {
        let (base, index) = element(inner)?;
        return Some((format!("der({base})"), index));
    }
    let open = name.rfind('[')?;
    let index = name.strip_suffix(']')?[open + 1..].parse().ok()?;
    Some((name[..open].to_string(), index))
}

/// Whether `b` can be an element of the same array as `a` (everything but
/// the name, start and description equal).
fn same_kind(a: &Variable, b: &Variable) -> bool {
    a.var_type == b.var_type
        && a.causality == b.causality
        && a.variability == b.variability
        && a.unit == b.unit
        && a.min.map(f64::to_bits) == b.min.map(f64::to_bits)
        && a.max.map(f64::to_bits) == b.max.map(f64::to_bits)
        && a.nominal.map(f64::to_bits) == b.nominal.map(f64::to_bits)
        && a.start.is_some() == b.start.is_some()
}

impl Layout {
    /// The layout of `info`'s table.
    pub fn new(info: &ModelInfo) -> Layout {
        let vars = info.variables;
        let mut variables = Vec::new();
        let mut variable_of = vec![0; vars.len()];
        let mut i = 0;
        while i < vars.len() {
            let first = &vars[i];
            let mut len = 1;
            let mut name = first.name.to_string();
            if let Some((base, 1)) = element(first.name) {
                while i + len < vars.len() {
                    let next = &vars[i + len];
                    let fits = element(next.name) == Some((base.clone(), len as u32 + 1))
                        && next.vr == first.vr + len as u32
                        && same_kind(first, next);
                    if !fits {
                        break;
                    }
                    len += 1;
                }
                if len >= 2 {
                    name = base;
                }
            }
            for k in 0..len {
                variable_of[i + k] = variables.len() as u32;
            }
            variables.push(Fmi3Variable {
                vr: first.vr,
                len: len as u32,
                name,
                is_array: len >= 2,
            });
            i += len;
        }
        let has_arrays = variables.iter().any(|v| v.is_array);
        Layout {
            variables,
            variable_of,
            has_arrays,
        }
    }

    /// The layout of `info`, made once per model and kept.
    pub fn of(info: &'static ModelInfo) -> &'static Layout {
        static MADE: OnceLock<Mutex<Vec<(usize, &'static Layout)>>> = OnceLock::new();
        let made = MADE.get_or_init(|| Mutex::new(Vec::new()));
        let mut made = made.lock().unwrap_or_else(|e| e.into_inner());
        let key = info as *const ModelInfo as usize;
        if let Some((_, layout)) = made.iter().find(|(k, _)| *k == key) {
            return layout;
        }
        let layout: &'static Layout = Box::leak(Box::new(Layout::new(info)));
        made.push((key, layout));
        layout
    }

    /// The FMI 3.0 variable a table value reference belongs to.
    pub fn variable_of(&self, vr: u32) -> Option<&Fmi3Variable> {
        let k = *self.variable_of.get(vr as usize)?;
        Some(&self.variables[k as usize])
    }

    /// The FMI 3.0 value reference of the variable holding table value
    /// reference `vr` (itself for a scalar, its array's for an element).
    pub fn head_of(&self, vr: u32) -> u32 {
        self.variable_of(vr).map_or(vr, |v| v.vr)
    }

    /// The table's value references of the FMI 3.0 value references
    /// `vrs`, each array as its elements, appended to `out`. A value
    /// reference past the table (`time`, the event indicators) is kept as
    /// it is; one inside an array that is not the array's is refused,
    /// naming the array.
    pub fn expand(&self, vrs: &[u32], out: &mut Vec<u32>) -> Result<(), String> {
        for &vr in vrs {
            match self.variable_of(vr) {
                Some(v) if v.vr == vr => out.extend(vr..vr + v.len),
                Some(v) => {
                    return Err(format!(
                        "value reference {vr} is not a variable of FMI 3.0: it is element {} of the array {} (value reference {}), which is read and written as a whole",
                        vr - v.vr + 1,
                        v.name,
                        v.vr
                    ))
                }
                None => out.push(vr),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_names_are_split_into_base_and_index() {
        assert_eq!(element("x_table[12]"), Some(("x_table".into(), 12)));
        assert_eq!(
            element("der(F_element[3])"),
            Some(("der(F_element)".into(), 3))
        );
        assert_eq!(element("F"), None);
        assert_eq!(element("x[a]"), None);
        assert_eq!(element("der(v)"), None);
    }

    #[test]
    fn numbered_scalars_become_arrays_and_expand_back() {
        let vars: Vec<Variable> = vec![
            Variable::input(0, "v", 0.0, "m/s", 1.0, "velocity"),
            Variable::parameter(1, "k[1]", 1.0, "N/m", "stiffness"),
            Variable::parameter(2, "k[2]", 2.0, "N/m", "stiffness"),
            Variable::parameter(3, "k[3]", 3.0, "N/m", "stiffness"),
            // a lone element stays a scalar
            Variable::parameter(4, "c[1]", 1.0, "N.s/m", "damping"),
            // another unit: not the same array
            Variable::parameter(5, "w[1]", 1.0, "N", "level"),
            Variable::parameter(6, "w[2]", 1.0, "m", "level"),
        ];
        let info = ModelInfo {
            model_name: "T",
            model_identifier: "T",
            guid: "{t}",
            description: "",
            source: "",
            variables: Box::leak(vars.into_boxed_slice()),
            default_experiment: crate::DefaultExperiment {
                start_time: 0.0,
                stop_time: 1.0,
                step_size: 0.1,
            },
            capabilities: crate::Capabilities::FULL,
            co_simulation_states: &[],
            model_exchange: None,
        };
        let layout = Layout::new(&info);
        let names: Vec<(&str, u32, u32)> = layout
            .variables
            .iter()
            .map(|v| (v.name.as_str(), v.vr, v.len))
            .collect();
        assert_eq!(
            names,
            [
                ("v", 0, 1),
                ("k", 1, 3),
                ("c[1]", 4, 1),
                ("w[1]", 5, 1),
                ("w[2]", 6, 1)
            ]
        );
        let mut out = Vec::new();
        layout.expand(&[1, 0, 7], &mut out).unwrap();
        assert_eq!(out, [1, 2, 3, 0, 7]);
        let e = layout.expand(&[2], &mut out).unwrap_err();
        assert!(
            e.contains("element 2 of the array k (value reference 1)"),
            "{e}"
        );
        assert_eq!(layout.head_of(3), 1);
    }
}

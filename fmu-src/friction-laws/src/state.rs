//! The state of a law whose state is one value (Dahl's `F_dahl`, the `z` of
//! LuGre and of the reset integrator): the methods the FMU layer saves and
//! restores it with, written once.

/// The state methods of a law whose state is the one value in field
/// `$field`: `state_len` (1), `write_state_into`, `state_is_finite`,
/// `state_to_vec` and `state_from_slice` (any finite value), inside the law's `impl`. `$law`
/// and `$name` are the law and the variable as the messages name them:
/// `one_value_state!("Dahl", "F_dahl", f)` refuses with
/// "Dahl state F_dahl = inf is not finite" or "Dahl state has 1 value, got 2".
macro_rules! one_value_state {
    ($law:literal, $name:literal, $field:ident) => {
        /// The number of values of the state (1).
        #[inline]
        pub fn state_len(&self) -> usize {
            1
        }

        #[doc = concat!("The state `[", $name, "]` into `out`, of [`Self::state_len`] values.")]
        #[inline]
        pub fn write_state_into(&self, out: &mut [f64]) {
            out.copy_from_slice(&[self.$field]);
        }

        #[doc = concat!("Whether `", $name, "` is finite (a scan of [`Self::write_state_into`]).")]
        #[inline]
        pub fn state_is_finite(&self) -> bool {
            self.$field.is_finite()
        }

        /// The same state as a new vector.
        pub fn state_to_vec(&self) -> Vec<f64> {
            let mut v = vec![0.0; self.state_len()];
            self.write_state_into(&mut v);
            v
        }

        #[doc = concat!("Restores `[", $name, "]` (any finite value).")]
        /// (Inlined into a caller, the messages out of line.)
        #[inline]
        pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
            self.$field = $crate::state::one_finite_value(s, $law, $name)?;
            Ok(())
        }
    };
}
pub(crate) use one_value_state;

/// The value of the one-value state `s` when it is finite; otherwise why
/// not, for law `law` with state variable `name`.
#[inline]
pub(crate) fn one_finite_value(s: &[f64], law: &str, name: &str) -> Result<f64, String> {
    match s {
        [x] if x.is_finite() => Ok(*x),
        _ => Err(refused(s, law, name)),
    }
}

/// Why [`one_finite_value`] refused `s`.
#[cold]
#[inline(never)]
fn refused(s: &[f64], law: &str, name: &str) -> String {
    match s {
        [x] => format!("{law} state {name} = {x} is not finite"),
        _ => format!("{law} state has 1 value, got {}", s.len()),
    }
}

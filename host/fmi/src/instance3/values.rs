//! How the variables of an FMI 3.0 model description reach the FMU: the
//! value references the rest of fricsim uses are those of the description
//! ([`crate::model_description`]), where an array is its elements, each
//! with a value reference of fricsim's, and where every variable is one of
//! the core's kinds (Real `f64`, Integer `i32`, Boolean). Here each is
//! sent to where the FMU holds it ([`Layout`], made at instantiation):
//!
//! - a scalar whose FMI 3.0 type is its kind's own (`Float64` for Real,
//!   `Int32` for Integer, `Boolean`): passed on as it is, the whole call
//!   in one FMI call when every value reference is such a scalar (the
//!   only case of an FMU without arrays and other types, which thus pays
//!   one test per value reference);
//! - a scalar of another type (`Float32`, `Int8` … `UInt64`, and
//!   `Enumeration`, which FMI 3.0 reads and writes as `Int64`): through
//!   the getter or setter of its type, one call per type, converted, and
//!   refused with the variable's name and the value where the two types
//!   do not hold the same number ([`FmuError::ValueConversion`]);
//! - an array element: the array is read whole (`fmi3Get<Type>` of the
//!   array's value reference, `nValues` its size) once per call and the
//!   elements picked; a set writes the whole array from a copy kept here
//!   ([`ArrayCopy`]), which starts as the start values, is refreshed by
//!   every read, and is read from the FMU before a set that changes only
//!   some elements, where the FMU allows reading (from initialization mode
//!   on): what the FMU holds in the other elements is written back
//!   unchanged.
//!
//! Directional derivatives map the same way: an element among the knowns
//! is its array with the element's seed (zero for the others), an element
//! among the unknowns is picked out of its array's sensitivities.

use super::Fmi3Instance;
use crate::error::FmuError;
use crate::fmi3::{fmi3Instance, fmi3Status, Functions};
use crate::guard::{not_supported, same_length};
use crate::model_description::{Fmi3Type, ModelDescription, ValueReference, VariableKind};
use crate::Status;
use std::collections::HashMap;
use std::fmt;

/// A C value type of FMI 3.0's getters and setters.
pub(crate) trait Native: Copy + Default + fmt::Display {
    /// `fmi3Get<Type>`, `fmi3Set<Type>`.
    const GET: &'static str;
    const SET: &'static str;
    /// What the type holds, for a message.
    const HOLDS: &'static str;

    /// `fmi3Get<Type>` of the binary.
    ///
    /// # Safety
    /// As the FMI function: `vrs` holds `n_vrs` value references and
    /// `values` room for `n_values` values.
    unsafe fn get(
        f: &Functions,
        instance: fmi3Instance,
        vrs: *const ValueReference,
        n_vrs: usize,
        values: *mut Self,
        n_values: usize,
    ) -> fmi3Status;

    /// `fmi3Set<Type>` of the binary.
    ///
    /// # Safety
    /// As [`Native::get`].
    unsafe fn set(
        f: &Functions,
        instance: fmi3Instance,
        vrs: *const ValueReference,
        n_vrs: usize,
        values: *const Self,
        n_values: usize,
    ) -> fmi3Status;

    /// The value as an `f64`, if that holds it exactly (a 64-bit integer
    /// beyond 2⁵³ may not be).
    fn to_f64(self) -> Option<f64>;

    /// `x` as this type, if it holds it (a float is rounded to the
    /// nearest `f32` within its range; an integer must be whole and in
    /// range).
    fn from_f64(x: f64) -> Option<Self>;
}

/// An `fmi3Boolean` as the FMU writes it: a byte (any non-zero byte is
/// true), never read as a Rust `bool` (see `fmi3-types`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(transparent)]
pub(crate) struct Byte(pub u8);

impl fmt::Display for Byte {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0 != 0 { "true" } else { "false" })
    }
}

macro_rules! native_calls {
    ($get:ident, $set:ident, $name:literal) => {
        const GET: &'static str = concat!("fmi3Get", $name);
        const SET: &'static str = concat!("fmi3Set", $name);

        unsafe fn get(
            f: &Functions,
            instance: fmi3Instance,
            vrs: *const ValueReference,
            n_vrs: usize,
            values: *mut Self,
            n_values: usize,
        ) -> fmi3Status {
            // SAFETY: the caller's contract.
            unsafe { (f.$get)(instance, vrs, n_vrs, values.cast(), n_values) }
        }

        unsafe fn set(
            f: &Functions,
            instance: fmi3Instance,
            vrs: *const ValueReference,
            n_vrs: usize,
            values: *const Self,
            n_values: usize,
        ) -> fmi3Status {
            // SAFETY: the caller's contract.
            unsafe { (f.$set)(instance, vrs, n_vrs, values.cast(), n_values) }
        }
    };
}

macro_rules! integer_native {
    ($t:ty, $get:ident, $set:ident, $name:literal, $holds:literal) => {
        impl Native for $t {
            native_calls!($get, $set, $name);
            const HOLDS: &'static str = $holds;

            fn to_f64(self) -> Option<f64> {
                let x = self as f64;
                (x as i128 == self as i128).then_some(x)
            }

            fn from_f64(x: f64) -> Option<Self> {
                // (NaN and ±∞ have no zero fraction)
                if x.fract() != 0.0 || x.abs() >= 2f64.powi(100) {
                    return None;
                }
                <$t>::try_from(x as i128).ok()
            }
        }
    };
}

integer_native!(
    i8,
    get_int8,
    set_int8,
    "Int8",
    "whole numbers from -128 to 127"
);
integer_native!(
    u8,
    get_uint8,
    set_uint8,
    "UInt8",
    "whole numbers from 0 to 255"
);
integer_native!(
    i16,
    get_int16,
    set_int16,
    "Int16",
    "whole numbers from -32768 to 32767"
);
integer_native!(
    u16,
    get_uint16,
    set_uint16,
    "UInt16",
    "whole numbers from 0 to 65535"
);
integer_native!(
    i32,
    get_int32,
    set_int32,
    "Int32",
    "whole numbers from -2147483648 to 2147483647"
);
integer_native!(
    u32,
    get_uint32,
    set_uint32,
    "UInt32",
    "whole numbers from 0 to 4294967295"
);
integer_native!(
    i64,
    get_int64,
    set_int64,
    "Int64",
    "whole numbers from -9223372036854775808 to 9223372036854775807"
);
integer_native!(
    u64,
    get_uint64,
    set_uint64,
    "UInt64",
    "whole numbers from 0 to 18446744073709551615"
);

impl Native for f64 {
    native_calls!(get_float64, set_float64, "Float64");
    const HOLDS: &'static str = "any 64-bit float";

    fn to_f64(self) -> Option<f64> {
        Some(self)
    }

    fn from_f64(x: f64) -> Option<Self> {
        Some(x)
    }
}

impl Native for f32 {
    native_calls!(get_float32, set_float32, "Float32");
    const HOLDS: &'static str = "numbers up to ±3.4028235e38";

    fn to_f64(self) -> Option<f64> {
        Some(f64::from(self))
    }

    fn from_f64(x: f64) -> Option<Self> {
        let y = x as f32; // rounds to nearest; beyond the range: ±∞
        (y.is_finite() || !x.is_finite()).then_some(y)
    }
}

impl Native for Byte {
    native_calls!(get_boolean, set_boolean, "Boolean");
    const HOLDS: &'static str = "true and false";

    fn to_f64(self) -> Option<f64> {
        Some(if self.0 != 0 { 1.0 } else { 0.0 })
    }

    fn from_f64(x: f64) -> Option<Self> {
        Some(Byte(u8::from(x != 0.0)))
    }
}

/// `$body` with `$T` the [`Native`] type of the FMI 3.0 type `$t`
/// (`Enumeration`: `Int64`, as FMI 3.0 reads and writes it). A `String`
/// never gets here: it is always passed on as it is.
macro_rules! with_native {
    ($t:expr, $T:ident => $body:expr) => {
        match $t {
            Fmi3Type::Float32 => {
                type $T = f32;
                $body
            }
            Fmi3Type::Float64 => {
                type $T = f64;
                $body
            }
            Fmi3Type::Int8 => {
                type $T = i8;
                $body
            }
            Fmi3Type::UInt8 => {
                type $T = u8;
                $body
            }
            Fmi3Type::Int16 => {
                type $T = i16;
                $body
            }
            Fmi3Type::UInt16 => {
                type $T = u16;
                $body
            }
            Fmi3Type::Int32 => {
                type $T = i32;
                $body
            }
            Fmi3Type::UInt32 => {
                type $T = u32;
                $body
            }
            Fmi3Type::Int64 | Fmi3Type::Enumeration => {
                type $T = i64;
                $body
            }
            Fmi3Type::UInt64 => {
                type $T = u64;
                $body
            }
            Fmi3Type::Boolean => {
                type $T = Byte;
                $body
            }
            Fmi3Type::String => unreachable!("a String is passed on as it is"),
        }
    };
}

/// The values of one array, of its type.
#[derive(Clone, Debug)]
pub(crate) enum Values {
    Float32(Vec<f32>),
    Float64(Vec<f64>),
    Int8(Vec<i8>),
    UInt8(Vec<u8>),
    Int16(Vec<i16>),
    UInt16(Vec<u16>),
    Int32(Vec<i32>),
    UInt32(Vec<u32>),
    Int64(Vec<i64>),
    UInt64(Vec<u64>),
    Boolean(Vec<Byte>),
}

impl Default for Values {
    fn default() -> Self {
        Values::Float64(Vec::new())
    }
}

/// `$body` with `$v` the vector of `$values` (of whichever type).
macro_rules! with_values {
    ($values:expr, $v:ident => $body:expr) => {
        match $values {
            Values::Float32($v) => $body,
            Values::Float64($v) => $body,
            Values::Int8($v) => $body,
            Values::UInt8($v) => $body,
            Values::Int16($v) => $body,
            Values::UInt16($v) => $body,
            Values::Int32($v) => $body,
            Values::UInt32($v) => $body,
            Values::Int64($v) => $body,
            Values::UInt64($v) => $body,
            Values::Boolean($v) => $body,
        }
    };
}

impl Values {
    /// The values `starts` as the type `t` holds them (0 where a start
    /// does not fit, which the model description reader has refused).
    fn new(t: Fmi3Type, starts: impl Iterator<Item = f64>) -> Values {
        fn of<T: Native>(starts: impl Iterator<Item = f64>) -> Vec<T> {
            starts.map(|x| T::from_f64(x).unwrap_or_default()).collect()
        }
        match t {
            Fmi3Type::Float32 => Values::Float32(of(starts)),
            Fmi3Type::Float64 => Values::Float64(of(starts)),
            Fmi3Type::Int8 => Values::Int8(of(starts)),
            Fmi3Type::UInt8 => Values::UInt8(of(starts)),
            Fmi3Type::Int16 => Values::Int16(of(starts)),
            Fmi3Type::UInt16 => Values::UInt16(of(starts)),
            Fmi3Type::Int32 => Values::Int32(of(starts)),
            Fmi3Type::UInt32 => Values::UInt32(of(starts)),
            Fmi3Type::Int64 | Fmi3Type::Enumeration => Values::Int64(of(starts)),
            Fmi3Type::UInt64 => Values::UInt64(of(starts)),
            Fmi3Type::Boolean => Values::Boolean(of(starts)),
            Fmi3Type::String => unreachable!("no String arrays are read"),
        }
    }
}

/// One array of the FMU, and the copy of its values kept here.
#[derive(Debug)]
pub(crate) struct ArrayCopy {
    /// The FMU's value reference of the array.
    value_reference: ValueReference,
    value_type: Fmi3Type,
    /// The value reference of the first element (fricsim's).
    first_element: ValueReference,
    len: usize,
    /// The start values, which the FMU holds after instantiation and
    /// after a reset.
    start: Values,
    /// What the FMU holds, as last read or written here.
    values: Values,
}

/// Where the FMU holds the value of a value reference of the description.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    /// A scalar of its kind's own type: passed on as it is.
    Direct,
    /// A scalar of another type.
    Converted(Fmi3Type),
    /// Element `position` of array `array` (into [`Layout::arrays`]).
    Element { array: usize, position: usize },
}

/// Where each value reference of an FMI 3.0 description is in its FMU (see
/// the module).
#[derive(Debug, Default)]
pub(crate) struct Layout {
    /// The FMU's scalars whose type is not their kind's own.
    converted: HashMap<ValueReference, Fmi3Type>,
    /// The arrays with elements, by first element.
    arrays: Vec<ArrayCopy>,
}

impl Layout {
    pub(crate) fn new(d: &ModelDescription) -> Layout {
        let converted = d
            .variables
            .iter()
            .filter(|v| v.element.is_none())
            .filter_map(|v| {
                let t = v.fmi3_type?;
                (!t.is_kind_native()).then_some((v.value_reference, t))
            })
            .collect();
        let arrays = d
            .arrays
            .iter()
            .filter(|a| !a.is_empty())
            .map(|a| {
                let elements = &d.variables[a.first_index - 1..][..a.len()];
                let start = Values::new(a.value_type, elements.iter().map(|v| start(&v.kind)));
                ArrayCopy {
                    value_reference: a.value_reference,
                    value_type: a.value_type,
                    first_element: a.first_element,
                    len: a.len(),
                    values: start.clone(),
                    start,
                }
            })
            .collect();
        Layout { converted, arrays }
    }

    fn place(&self, vr: ValueReference) -> Place {
        if let Some(first) = self.arrays.first() {
            if vr >= first.first_element {
                let array = self.arrays.partition_point(|a| a.first_element <= vr) - 1;
                let position = (vr - self.arrays[array].first_element) as usize;
                if position < self.arrays[array].len {
                    return Place::Element { array, position };
                }
            }
        }
        if !self.converted.is_empty() {
            if let Some(&t) = self.converted.get(&vr) {
                return Place::Converted(t);
            }
        }
        Place::Direct
    }

    /// Whether every one of `vrs` is passed on as it is (always, for an
    /// FMU without arrays and other types).
    #[inline]
    fn all_direct(&self, vrs: &[ValueReference]) -> bool {
        (self.arrays.is_empty() && self.converted.is_empty())
            || vrs.iter().all(|&vr| self.place(vr) == Place::Direct)
    }

    /// The copies back to the start values (after a reset).
    pub(crate) fn restart(&mut self) {
        for a in &mut self.arrays {
            a.values = a.start.clone();
        }
    }
}

/// A start value as an `f64` (0 without one).
fn start(kind: &VariableKind) -> f64 {
    match kind {
        VariableKind::Real { start, .. } => start.unwrap_or(0.0),
        VariableKind::Integer { start, .. } | VariableKind::Enumeration { start, .. } => {
            start.map_or(0.0, f64::from)
        }
        VariableKind::Boolean { start } => f64::from(u8::from(start.unwrap_or(false))),
        VariableKind::String { .. } => 0.0,
    }
}

/// One of the core's kinds, for the calls that take its values.
#[derive(Clone, Copy)]
struct Kind {
    name: &'static str,
    /// The FMI call of the kind's own type, which the lengths of a call
    /// are checked for.
    get: &'static str,
    set: &'static str,
}

const REAL: Kind = Kind {
    name: "Real",
    get: "fmi3GetFloat64",
    set: "fmi3SetFloat64",
};
const INTEGER: Kind = Kind {
    name: "Integer",
    get: "fmi3GetInt32",
    set: "fmi3SetInt32",
};
const BOOLEAN: Kind = Kind {
    name: "Boolean",
    get: "fmi3GetBoolean",
    set: "fmi3SetBoolean",
};

/// A value as the core holds it: Real `f64`, Integer `i32` (and a Boolean
/// read as an `i32`, 0 or 1), Boolean `bool`.
pub(crate) trait Held: Copy + Default + fmt::Display {
    /// What holds it, for a message.
    const WHAT: &'static str;
    fn to_f64(self) -> f64;
    fn from_f64(x: f64) -> Option<Self>;

    /// The value in a message.
    fn shown(self) -> String {
        self.to_string()
    }
}

impl Held for f64 {
    const WHAT: &'static str = "a 64-bit float";

    fn to_f64(self) -> f64 {
        self
    }

    fn from_f64(x: f64) -> Option<Self> {
        Some(x)
    }

    /// `300`, `3.5`, and `1e39` (not its forty digits).
    fn shown(self) -> String {
        if self.abs() < 1e16 {
            self.to_string()
        } else {
            format!("{self:?}")
        }
    }
}

impl Held for i32 {
    const WHAT: &'static str = "a 32-bit integer";

    fn to_f64(self) -> f64 {
        f64::from(self)
    }

    fn from_f64(x: f64) -> Option<Self> {
        <i32 as Native>::from_f64(x)
    }
}

impl Held for bool {
    const WHAT: &'static str = "a Boolean";

    fn to_f64(self) -> f64 {
        f64::from(u8::from(self))
    }

    fn from_f64(x: f64) -> Option<Self> {
        Some(x != 0.0)
    }
}

/// The worse of two statuses of calls that succeeded (`Warning` over `Ok`).
fn worse(a: Status, b: Status) -> Status {
    if b == Status::Warning {
        b
    } else {
        a
    }
}

/// A call of the core's values with the FMU's own scalars only.
type DirectGet<H> = fn(&mut Fmi3Instance, &[ValueReference], &mut [H]) -> Result<Status, FmuError>;
type DirectSet<H> = fn(&mut Fmi3Instance, &[ValueReference], &[H]) -> Result<Status, FmuError>;

impl Fmi3Instance {
    /// The Real values of the description's variables `vrs` (FMI 3.0's
    /// `Float64` and `Float32`, and `UInt32`, `Int64`, `UInt64`, which an
    /// `f64` holds, scalars or array elements): `values[i]` = value of
    /// `vrs[i]` (see the module for the calls this makes).
    #[inline]
    pub fn get_real(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [f64],
    ) -> Result<Status, FmuError> {
        if self.layout.all_direct(vrs) {
            return self.get_float64(vrs, values);
        }
        self.get_mapped(REAL, vrs, values, Fmi3Instance::get_float64)
    }

    /// Set the Real values of the description's variables `vrs` (as
    /// [`Fmi3Instance::get_real`]); a value the variable's type cannot
    /// hold (3.5 for a `UInt32`) is refused before anything is set.
    #[inline]
    pub fn set_real(&mut self, vrs: &[ValueReference], values: &[f64]) -> Result<Status, FmuError> {
        if self.layout.all_direct(vrs) {
            return self.set_float64(vrs, values);
        }
        self.set_mapped(REAL, vrs, values, Fmi3Instance::set_float64)
    }

    /// The Integer values of the description's variables `vrs` (`Int8` …
    /// `Int32` and `Enumeration`, scalars or array elements).
    #[inline]
    pub fn get_integer(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<Status, FmuError> {
        if self.layout.all_direct(vrs) {
            return self.get_int32(vrs, values);
        }
        self.get_mapped(INTEGER, vrs, values, Fmi3Instance::get_int32)
    }

    /// Set the Integer values of the description's variables `vrs` (as
    /// [`Fmi3Instance::get_integer`]); a value out of a variable's range
    /// (300 for a `UInt8`) is refused before anything is set.
    pub fn set_integer(
        &mut self,
        vrs: &[ValueReference],
        values: &[i32],
    ) -> Result<Status, FmuError> {
        if self.layout.all_direct(vrs) {
            return self.set_int32(vrs, values);
        }
        self.set_mapped(INTEGER, vrs, values, Fmi3Instance::set_int32)
    }

    /// The Boolean values of the description's variables `vrs` (scalars
    /// or array elements), each as a C int (0 false, 1 true), the form
    /// FMI 2.0's Booleans take ([`crate::Instance::get_boolean_raw`]).
    /// Does not allocate for scalars: the FMU writes bytes into a stack
    /// buffer.
    #[inline]
    pub fn get_boolean_raw(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<Status, FmuError> {
        if self.layout.all_direct(vrs) {
            return self.get_boolean_bytes(vrs, values);
        }
        self.get_mapped(BOOLEAN, vrs, values, Fmi3Instance::get_boolean_bytes)
    }

    /// Set the Boolean values of the description's variables `vrs`
    /// (scalars or array elements).
    pub fn set_boolean(
        &mut self,
        vrs: &[ValueReference],
        values: &[bool],
    ) -> Result<Status, FmuError> {
        if self.layout.all_direct(vrs) {
            return self.set_boolean_scalars(vrs, values);
        }
        self.set_mapped(BOOLEAN, vrs, values, Fmi3Instance::set_boolean_scalars)
    }

    /// `fmi3Get<Type>` of `vrs` into `values` (`nValues` is
    /// `values.len()`: an array's value reference takes all its elements).
    fn get_native<T: Native>(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [T],
    ) -> Result<Status, FmuError> {
        let f = self.functions;
        // SAFETY: `vrs` and `values` hold as many elements as passed.
        self.call(T::GET, |i| {
            Ok(unsafe {
                T::get(
                    &f,
                    i,
                    vrs.as_ptr(),
                    vrs.len(),
                    values.as_mut_ptr(),
                    values.len(),
                )
            })
        })
    }

    /// `fmi3Set<Type>` of `vrs` from `values` (as [`Fmi3Instance::get_native`]).
    fn set_native<T: Native>(
        &mut self,
        vrs: &[ValueReference],
        values: &[T],
    ) -> Result<Status, FmuError> {
        let f = self.functions;
        // SAFETY: `vrs` and `values` hold as many elements as passed.
        self.call(T::SET, |i| {
            Ok(unsafe {
                T::set(
                    &f,
                    i,
                    vrs.as_ptr(),
                    vrs.len(),
                    values.as_ptr(),
                    values.len(),
                )
            })
        })
    }

    /// Read array `array` whole into its copy.
    fn read_array(&mut self, array: usize) -> Result<Status, FmuError> {
        let vr = self.layout.arrays[array].value_reference;
        let mut values = std::mem::take(&mut self.layout.arrays[array].values);
        let result = with_values!(&mut values, v => self.get_native(&[vr], v));
        self.layout.arrays[array].values = values;
        result
    }

    /// Write array `array` whole from its copy.
    fn write_array(&mut self, array: usize) -> Result<Status, FmuError> {
        let vr = self.layout.arrays[array].value_reference;
        let values = std::mem::take(&mut self.layout.arrays[array].values);
        let result = with_values!(&values, v => self.set_native(&[vr], v));
        self.layout.arrays[array].values = values;
        result
    }

    /// [`Fmi3Instance::get_real`] and its kin when some value reference is
    /// not passed on as it is (`kind`: the core's kind, for messages).
    #[cold]
    fn get_mapped<H: Held>(
        &mut self,
        kind: Kind,
        vrs: &[ValueReference],
        values: &mut [H],
        direct: DirectGet<H>,
    ) -> Result<Status, FmuError> {
        same_length(kind.get, "values", vrs.len(), values.len())?;
        let places: Vec<Place> = vrs.iter().map(|&vr| self.layout.place(vr)).collect();
        let mut status = Status::Ok;

        // the scalars of the kind's own type, in one call
        let direct_at: Vec<usize> = (0..vrs.len())
            .filter(|&k| places[k] == Place::Direct)
            .collect();
        if !direct_at.is_empty() {
            let direct_vrs: Vec<ValueReference> = direct_at.iter().map(|&k| vrs[k]).collect();
            let mut got = vec![H::default(); direct_at.len()];
            status = worse(status, direct(self, &direct_vrs, &mut got)?);
            for (&k, x) in direct_at.iter().zip(got) {
                values[k] = x;
            }
        }

        // the scalars of other types, one call per type
        for t in distinct(places.iter().filter_map(|p| match p {
            Place::Converted(t) => Some(*t),
            _ => None,
        })) {
            let at: Vec<usize> = (0..vrs.len())
                .filter(|&k| places[k] == Place::Converted(t))
                .collect();
            let typed_vrs: Vec<ValueReference> = at.iter().map(|&k| vrs[k]).collect();
            with_native!(t, T => {
                let mut got = vec![T::default(); at.len()];
                status = worse(status, self.get_native(&typed_vrs, &mut got)?);
                for (&k, x) in at.iter().zip(got) {
                    values[k] = self.held(kind, vrs[k], x)?;
                }
            });
        }

        // the elements: each array read once, whole
        for array in distinct(places.iter().filter_map(|p| match p {
            Place::Element { array, .. } => Some(*array),
            _ => None,
        })) {
            status = worse(status, self.read_array(array)?);
            for (k, place) in places.iter().enumerate() {
                if let Place::Element { array: a, position } = *place {
                    if a == array {
                        values[k] = with_values!(&self.layout.arrays[array].values, v =>
                            self.held(kind, vrs[k], v[position]))?;
                    }
                }
            }
        }
        Ok(status)
    }

    /// [`Fmi3Instance::set_real`] and its kin when some value reference is
    /// not passed on as it is.
    #[cold]
    fn set_mapped<H: Held>(
        &mut self,
        kind: Kind,
        vrs: &[ValueReference],
        values: &[H],
        direct: DirectSet<H>,
    ) -> Result<Status, FmuError> {
        same_length(kind.set, "values", vrs.len(), values.len())?;
        let places: Vec<Place> = vrs.iter().map(|&vr| self.layout.place(vr)).collect();
        // every value must fit its variable's type before anything is set
        for (k, place) in places.iter().enumerate() {
            let t = match *place {
                Place::Direct => continue,
                Place::Converted(t) => t,
                Place::Element { array, .. } => self.layout.arrays[array].value_type,
            };
            with_native!(t, T => { self.native::<T, H>(vrs[k], values[k])?; });
        }
        let mut status = Status::Ok;

        let direct_at: Vec<usize> = (0..vrs.len())
            .filter(|&k| places[k] == Place::Direct)
            .collect();
        if !direct_at.is_empty() {
            let direct_vrs: Vec<ValueReference> = direct_at.iter().map(|&k| vrs[k]).collect();
            let direct_values: Vec<H> = direct_at.iter().map(|&k| values[k]).collect();
            status = worse(status, direct(self, &direct_vrs, &direct_values)?);
        }

        for t in distinct(places.iter().filter_map(|p| match p {
            Place::Converted(t) => Some(*t),
            _ => None,
        })) {
            let at: Vec<usize> = (0..vrs.len())
                .filter(|&k| places[k] == Place::Converted(t))
                .collect();
            let typed_vrs: Vec<ValueReference> = at.iter().map(|&k| vrs[k]).collect();
            with_native!(t, T => {
                let typed = at
                    .iter()
                    .map(|&k| self.native::<T, H>(vrs[k], values[k]))
                    .collect::<Result<Vec<T>, _>>()?;
                status = worse(status, self.set_native(&typed_vrs, &typed)?);
            });
        }

        for array in distinct(places.iter().filter_map(|p| match p {
            Place::Element { array, .. } => Some(*array),
            _ => None,
        })) {
            let mut covered = vec![false; self.layout.arrays[array].len];
            for place in &places {
                if let Place::Element { array: a, position } = *place {
                    covered[position] |= a == array;
                }
            }
            // the other elements as the FMU holds them, where it may be asked
            if self.values_readable && covered.contains(&false) {
                status = worse(status, self.read_array(array)?);
            }
            let mut copy = std::mem::take(&mut self.layout.arrays[array].values);
            let patched = with_values!(&mut copy, v => {
                let mut patched = Ok(());
                for (k, place) in places.iter().enumerate() {
                    if let Place::Element { array: a, position } = *place {
                        if a == array {
                            match self.native(vrs[k], values[k]) {
                                Ok(x) => v[position] = x,
                                Err(e) => patched = Err(e),
                            }
                        }
                    }
                }
                patched
            });
            self.layout.arrays[array].values = copy;
            patched?;
            status = worse(status, self.write_array(array)?);
        }
        Ok(status)
    }

    /// The FMU's value `x` of `vr` as the core holds it, or the error that
    /// says why it cannot be.
    fn held<T: Native, H: Held>(
        &self,
        kind: Kind,
        vr: ValueReference,
        x: T,
    ) -> Result<H, FmuError> {
        let type_name = &T::GET["fmi3Get".len()..];
        let f = x.to_f64().ok_or_else(|| {
            self.conversion(
                T::GET,
                vr,
                format!(
                    "has the value {x}, which fricsim cannot hold exactly: it holds {type_name} \
                     values as {} values (64-bit floats)",
                    kind.name
                ),
            )
        })?;
        H::from_f64(f).ok_or_else(|| {
            self.conversion(
                T::GET,
                vr,
                format!(
                    "has the value {x}, which fricsim cannot hold: it holds {type_name} values \
                     as {} values ({})",
                    kind.name,
                    H::WHAT
                ),
            )
        })
    }

    /// The core's value `x` for `vr` as the FMU's type `T` holds it, or
    /// the error that says why it cannot be.
    fn native<T: Native, H: Held>(&self, vr: ValueReference, x: H) -> Result<T, FmuError> {
        T::from_f64(x.to_f64()).ok_or_else(|| {
            self.conversion(
                T::SET,
                vr,
                format!(
                    "cannot be set to {}: its type holds {}",
                    x.shown(),
                    T::HOLDS
                ),
            )
        })
    }

    #[cold]
    fn conversion(&self, function: &'static str, vr: ValueReference, problem: String) -> FmuError {
        let variable = self.fmu().description().variable_by_value_reference(vr);
        FmuError::ValueConversion {
            function,
            instance: self.name().to_string(),
            variable: variable.map_or(format!("with value reference {vr}"), |v| {
                format!("\"{}\"", v.name)
            }),
            type_name: variable.map_or("?", |v| v.type_name()),
            problem,
        }
    }

    /// `fmi3GetDirectionalDerivative` (§2.3.11): `out` = ∂unknowns/∂knowns ·
    /// `seed`, the unknowns and knowns value references of the
    /// description (an array element among them as the module says).
    #[inline]
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[ValueReference],
        knowns: &[ValueReference],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3GetDirectionalDerivative";
        if !self.declared.directional_derivative {
            return Err(not_supported(F, "providesDirectionalDerivatives=\"true\""));
        }
        same_length(F, "seed", knowns.len(), seed.len())?;
        same_length(F, "out", unknowns.len(), out.len())?;
        if self.layout.arrays.is_empty()
            || (unknowns
                .iter()
                .chain(knowns)
                .all(|&vr| !matches!(self.layout.place(vr), Place::Element { .. })))
        {
            return self.directional_derivative_of(unknowns, knowns, seed, out);
        }
        // each array among the knowns once, with the seed of its elements
        let (mut fmu_knowns, mut fmu_seed) = (Vec::new(), Vec::new());
        let mut seed_at: HashMap<usize, usize> = HashMap::new();
        for (&vr, &s) in knowns.iter().zip(seed) {
            match self.layout.place(vr) {
                Place::Element { array, position } => {
                    let a = &self.layout.arrays[array];
                    let at = *seed_at.entry(array).or_insert_with(|| {
                        fmu_knowns.push(a.value_reference);
                        fmu_seed.resize(fmu_seed.len() + a.len, 0.0);
                        fmu_seed.len() - a.len
                    });
                    fmu_seed[at + position] += s;
                }
                _ => {
                    fmu_knowns.push(vr);
                    fmu_seed.push(s);
                }
            }
        }
        // each array among the unknowns once; where each unknown is in
        // the sensitivities
        let (mut fmu_unknowns, mut picks, mut n) = (Vec::new(), Vec::new(), 0);
        let mut sensitivity_at: HashMap<usize, usize> = HashMap::new();
        for &vr in unknowns {
            match self.layout.place(vr) {
                Place::Element { array, position } => {
                    let a = &self.layout.arrays[array];
                    let at = *sensitivity_at.entry(array).or_insert_with(|| {
                        fmu_unknowns.push(a.value_reference);
                        n += a.len;
                        n - a.len
                    });
                    picks.push(at + position);
                }
                _ => {
                    fmu_unknowns.push(vr);
                    picks.push(n);
                    n += 1;
                }
            }
        }
        let mut sensitivities = vec![0.0; n];
        let status = self.directional_derivative_of(
            &fmu_unknowns,
            &fmu_knowns,
            &fmu_seed,
            &mut sensitivities,
        )?;
        for (o, &at) in out.iter_mut().zip(&picks) {
            *o = sensitivities[at];
        }
        Ok(status)
    }
}

/// The distinct items of `items`, in the order first met (few: the types
/// or the arrays of one call).
fn distinct<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut seen = Vec::new();
    for item in items {
        if !seen.contains(&item) {
            seen.push(item);
        }
    }
    seen
}

/// The getter and setter of an FMI 3.0 type that the binary need not
/// export for fricsim unless the model description has a variable of the
/// type (the optional ones of [`Functions`]); `None` for the types whose
/// functions every binary must export.
pub(crate) fn optional_functions(t: Fmi3Type) -> Option<(&'static str, [&'static str; 2])> {
    fn of<T: Native>(what: &'static str) -> Option<(&'static str, [&'static str; 2])> {
        Some((what, [T::GET, T::SET]))
    }
    match t {
        Fmi3Type::Float32 => of::<f32>("variables of type Float32"),
        Fmi3Type::Int8 => of::<i8>("variables of type Int8"),
        Fmi3Type::UInt8 => of::<u8>("variables of type UInt8"),
        Fmi3Type::Int16 => of::<i16>("variables of type Int16"),
        Fmi3Type::UInt16 => of::<u16>("variables of type UInt16"),
        Fmi3Type::UInt32 => of::<u32>("variables of type UInt32"),
        Fmi3Type::Int64 => of::<i64>("variables of type Int64"),
        Fmi3Type::Enumeration => of::<i64>("variables of type Enumeration (read as Int64)"),
        Fmi3Type::UInt64 => of::<u64>("variables of type UInt64"),
        Fmi3Type::Float64 | Fmi3Type::Int32 | Fmi3Type::Boolean | Fmi3Type::String => None,
    }
}

//! The shape of a raw function table, [`function_table!`], shared by
//! FMI 2.0's ([`crate::fmi2`]) and FMI 3.0's ([`crate::fmi3`]): the two
//! tables name different functions with different types, but are looked
//! up, checked and stood in for the same way. A stand-in for an optional
//! function that is not exported returns 3, which is `fmi2Error` and
//! `fmi3Error` alike.

/// A table of FMI functions: `required` ones must all be exported,
/// `optional` ones (each with its argument types, for its stand-in) may
/// be missing.
macro_rules! function_table {
    (
        $(#[$doc:meta])*
        $name:ident;
        required { $($field:ident: $ty:ty = $symbol:ident,)* }
        optional { $($ofield:ident: $oty:ty = $osymbol:ident($($arg:ty),*),)* }
    ) => {
        $(#[$doc])*
        #[derive(Clone, Copy)]
        pub struct $name {
            $(#[doc = concat!("`", stringify!($symbol), "`")] pub $field: $ty,)*
            $(#[doc = concat!("`", stringify!($osymbol), "` (optional)")] pub $ofield: $oty,)*
            /// Bit `i` set: `OPTIONAL[i]` is not exported.
            absent: u32,
        }

        impl $name {
            /// The symbols that must be exported, in the order of the table.
            pub const REQUIRED: &'static [&'static str] = &[$(stringify!($symbol)),*];
            /// The symbols that may be missing, in the order of the table.
            pub const OPTIONAL: &'static [&'static str] = &[$(stringify!($osymbol)),*];

            /// Every function from `lookup` (symbol name → address, null
            /// when not exported), or the names of the required ones that
            /// are missing, in the order of the table.
            ///
            /// # Safety
            /// Each non-null address must be the function the standard
            /// gives that name, and stay valid as long as the table is used.
            pub unsafe fn from_lookup(
                mut lookup: impl FnMut(&'static str) -> *const std::ffi::c_void,
            ) -> Result<$name, Vec<&'static str>> {
                let mut missing = Vec::new();
                #[allow(unused_mut)] // (a table without optional functions)
                let mut absent = 0u32;
                // SAFETY (every transmute): the caller's contract; the
                // address is not null.
                $(let $field: Option<$ty> = {
                    let address = lookup(stringify!($symbol));
                    if address.is_null() {
                        missing.push(stringify!($symbol));
                        None
                    } else {
                        Some(unsafe { std::mem::transmute::<*const std::ffi::c_void, $ty>(address) })
                    }
                };)*
                #[allow(unused_mut)]
                let mut bit = 1u32;
                $(let $ofield: $oty = {
                    let address = lookup(stringify!($osymbol));
                    let this = bit;
                    bit <<= 1;
                    if address.is_null() {
                        absent |= this;
                        /// Stands in for a function the binary does not export.
                        unsafe extern "C" fn $ofield($(_: $arg),*) -> std::os::raw::c_int {
                            3 // fmi2Error, fmi3Error
                        }
                        $ofield as $oty
                    } else {
                        unsafe { std::mem::transmute::<*const std::ffi::c_void, $oty>(address) }
                    }
                };)*
                let _ = bit;
                if !missing.is_empty() {
                    return Err(missing);
                }
                Ok($name {
                    $($field: $field.expect("not missing"),)*
                    $($ofield,)*
                    absent,
                })
            }

            /// Every function of `library`, looked up by name (`dlsym`).
            ///
            /// # Safety
            /// `library` is a binary of the table's FMI version (its symbols have the
            /// standard's signatures), and stays loaded as long as the
            /// table is used.
            pub unsafe fn load(library: &libloading::Library) -> Result<$name, Vec<&'static str>> {
                // SAFETY: the caller's contract.
                unsafe {
                    $name::from_lookup(|symbol| {
                        library
                            .get::<*const std::ffi::c_void>(symbol.as_bytes())
                            .map_or(std::ptr::null(), |s| *s)
                    })
                }
            }

            /// Whether the binary exports `symbol` (false for a name not in
            /// the table).
            pub fn exports(&self, symbol: &str) -> bool {
                if Self::REQUIRED.contains(&symbol) {
                    return true;
                }
                Self::OPTIONAL
                    .iter()
                    .position(|s| *s == symbol)
                    .is_some_and(|i| self.absent & (1 << i) == 0)
            }
        }
    };
}

//! The subcommands of the `fricsim` binary (not part of the library).

pub mod compare;
pub mod cosim;
pub mod info;
pub mod reference;
pub mod run;

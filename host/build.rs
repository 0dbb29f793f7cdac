//! Compiles the variadic FMI logger callback (`src/fmu/logger.c`): stable
//! Rust cannot define a C-variadic function, so this one lives in C.

fn main() {
    println!("cargo:rerun-if-changed=src/fmu/logger.c");
    cc::Build::new()
        .file("src/fmu/logger.c")
        .warnings(true)
        .extra_warnings(true)
        .compile("fricsim_logger");
}

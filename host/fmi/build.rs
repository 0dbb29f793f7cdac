//! Compiles the variadic FMI logger callback (`src/logger.c`): stable
//! Rust cannot define a C-variadic function, so this one lives in C.

fn main() {
    println!("cargo:rerun-if-changed=src/logger.c");
    cc::Build::new()
        .file("src/logger.c")
        .warnings(true)
        .extra_warnings(true)
        .compile("fricsim_logger");
}

//! The FMI 2.0 logger shim (c/fmi2_logger.c): a variadic C callback, which Rust cannot define.
fn main() {
    println!("cargo:rerun-if-changed=c/fmi2_logger.c");
    cc::Build::new()
        .file("c/fmi2_logger.c")
        .warnings(true)
        .compile("uio_fmi2_logger");
}

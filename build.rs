//! Tells the tests whether a Python interpreter for the Python tests is at hand: with `RINS_PYTHON`
//! set (to the venv `python/setup-venv` makes) they are built with `cfg(rins_python)` and run;
//! without it they are built ignored, so that they show as skipped rather than passed.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=RINS_PYTHON");
    println!("cargo:rustc-check-cfg=cfg(rins_python)");
    if std::env::var_os("RINS_PYTHON").is_some_and(|p| !p.is_empty()) {
        println!("cargo:rustc-cfg=rins_python");
    }
}

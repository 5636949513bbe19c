//! Build script: tells the tests whether QEMU's user-mode emulator (`qemu-x86_64`, Debian's
//! qemu-user) is on the PATH, as the `rtis_qemu` cfg, so that the emulated test of
//! `tests/integration/cpu_dispatch.rs` is listed as ignored, with its reason, where it cannot run (instead
//! of passing without testing anything). With `RTIS_REQUIRE_QEMU=1` (set by `.ci/run`) a
//! missing emulator fails the build.
//!
//! The PATH is read when this script runs: on a fresh build, or when `RTIS_REQUIRE_QEMU`
//! changes. (Rerunning on every PATH change would rebuild the crate each time a shell's PATH
//! differs; after installing qemu-user, `touch build.rs` picks it up.)

fn main() {
    println!("cargo::rustc-check-cfg=cfg(rtis_qemu)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=RTIS_REQUIRE_QEMU");
    let found = std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| dir.join("qemu-x86_64").is_file())
    });
    let required = std::env::var_os("RTIS_REQUIRE_QEMU").is_some_and(|v| v == "1");
    if required && !found {
        panic!("RTIS_REQUIRE_QEMU=1 but no qemu-x86_64 on the PATH");
    }
    if found {
        println!("cargo::rustc-cfg=rtis_qemu");
    }
}

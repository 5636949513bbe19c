//! The binary on CPUs older than this one (src/accel/simd/): run under QEMU's user-mode
//! emulator as its baseline x86-64 CPU (`-cpu qemu64`: SSE2 and SSE3, no AVX, no SSE4, no
//! POPCNT) and as an AVX2 CPU without AVX-512 (`-cpu Haswell`), which stop a process with
//! SIGILL at its first instruction the CPU lacks. There the binary must pick the baseline (or
//! AVX2) instruction set, render a mesh scene (closest-hit and shadow queries through the BVH)
//! and the course's box under the Global shader (batches of rays in four SSE or eight AVX2
//! lanes instead of the native run's) to the same pixels, bit for bit, as the native run
//! (AVX2 or AVX-512 on a CI machine), and refuse an instruction set it lacks (`--isa`) with an
//! error instead of crashing.
//!
//! Needs `qemu-x86_64` (Debian's qemu-user), which `.ci/run` installs; without it (at build
//! time: `build.rs` sets the `rtis_qemu` cfg) the test is listed as ignored with that reason,
//! and `RTIS_REQUIRE_QEMU=1` (set by `.ci/run`) makes its absence an error.

#![cfg(all(target_arch = "x86_64", target_os = "linux"))]

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const RTIS: &str = env!("CARGO_BIN_EXE_rtis");

/// `qemu-x86_64` on the PATH, if there.
fn qemu() -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|dir| dir.join("qemu-x86_64"))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        let required = std::env::var_os("RTIS_REQUIRE_QEMU").is_some_and(|v| v == "1");
        assert!(
            !required,
            "RTIS_REQUIRE_QEMU=1 but no qemu-x86_64 on the PATH"
        );
        eprintln!("no qemu-x86_64 (Debian's qemu-user): the older CPU is not tested here");
    }
    found
}

/// `rtis args`, natively or under `qemu-x86_64 -cpu CPU` (`emulated`: QEMU and the CPU).
fn rtis(emulated: Option<(&Path, &str)>, args: &[&str]) -> Output {
    let mut cmd = match emulated {
        Some((qemu, cpu)) => {
            let mut c = Command::new(qemu);
            c.args(["-cpu", cpu, RTIS]);
            c
        }
        None => Command::new(RTIS),
    };
    // Under emulation a render takes tens of seconds; a hang fails after ten minutes.
    common::output_within(cmd.args(args), 600)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh folder for this test's images, removed when dropped (also when the test fails).
struct TempDir(PathBuf);

impl TempDir {
    fn new() -> TempDir {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos();
        let dir =
            std::env::temp_dir().join(format!("rtis-cpu-dispatch-{}-{nanos}", std::process::id()));
        std::fs::create_dir(&dir).expect("a fresh temporary folder");
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The two renders of `scene` have the same pixels, bit for bit.
fn same_pixels(scene: &str, native: &[u32], old: &[u32]) {
    assert!(
        native.len() > 4 * 96 * 70,
        "{scene}: {} channels",
        native.len()
    );
    assert_eq!(native.len(), old.len(), "{scene}");
    if let Some(i) = (0..native.len()).find(|&i| native[i] != old[i]) {
        let differ = native.iter().zip(old).filter(|(a, b)| a != b).count();
        panic!(
            "{scene}: another instruction set rendered another image: {differ} channels differ, \
             the first at {i} ({} against {})",
            f32::from_bits(native[i]),
            f32::from_bits(old[i])
        );
    }
}

/// `rtis render scene` into `dir/name` (with `--isa isa` unless `isa` is empty), natively or
/// emulated: the pixels, to the bit (the file's compressed bytes may differ: the compressor
/// picks its own code path by CPU), and the log.
fn render_in(
    dir: &Path,
    emulated: Option<(&Path, &str)>,
    scene: &str,
    name: &str,
    isa: &str,
) -> (Vec<u32>, String) {
    let scene = format!("{}/scenes/{scene}", env!("CARGO_MANIFEST_DIR"));
    let path = dir.join(name);
    let mut args = vec![
        "render",
        &scene,
        "--width",
        "96",
        "--threads",
        "2",
        "-o",
        path.to_str().unwrap(),
    ];
    if !isa.is_empty() {
        args.extend(["--isa", isa]);
    }
    let out = rtis(emulated, &args);
    assert!(
        out.status.success(),
        "{name}: {:?}\n{}",
        out.status,
        stderr(&out)
    );
    let image = image::open(&path).unwrap().into_rgba32f();
    let bits: Vec<u32> = image.pixels().flat_map(|p| p.0.map(f32::to_bits)).collect();
    (bits, stderr(&out))
}

/// The log names `isa` as the instruction set of the batches.
fn says(log: &str, isa: rtis::accel::Isa) {
    let simd = format!("SIMD: {}, {} rays per batch", isa.name(), isa.lanes());
    assert!(log.contains(&simd), "{simd}?\n{log}");
}

/// Natively, `render --isa` picks each instruction set this CPU runs (no emulator needed), and
/// each renders the course's box to the same pixels.
#[test]
fn each_native_instruction_set_renders_the_same_image() {
    rtis::accel::require_all_isas();
    let tmp = TempDir::new();
    let (auto, log) = render_in(&tmp.0, None, "cornell-two-bounce.ron", "auto.exr", "");
    says(&log, rtis::accel::Isa::detect());
    for isa in rtis::accel::Isa::all_available() {
        let name = format!("{}.exr", isa.name());
        let (chosen, log) = render_in(&tmp.0, None, "cornell-two-bounce.ron", &name, isa.name());
        says(&log, isa);
        same_pixels(&format!("--isa {}", isa.name()), &auto, &chosen);
    }
}

#[test]
#[cfg_attr(
    not(rtis_qemu),
    ignore = "needs qemu-x86_64 (Debian's qemu-user) on the PATH when built; .ci/run installs it"
)]
fn older_cpus_render_the_same_images_in_their_own_instruction_sets() {
    // The native run must be the other instruction set where CI asks for it.
    rtis::accel::require_all_isas();
    // Built where qemu was (or run with --include-ignored): it must be here now.
    let Some(qemu) = qemu() else {
        panic!("no qemu-x86_64 on the PATH (built where it was? `touch build.rs` to rebuild)")
    };
    let tmp = TempDir::new();
    let dir = &tmp.0;
    let render = |emulated, scene: &str, name: &str| render_in(dir, emulated, scene, name, "");
    let native_isa = rtis::accel::Isa::detect();
    let (mesh, mesh_log) = render(None, "mesh.ron", "native.exr");
    let (cornell, cornell_log) = render(None, "cornell-two-bounce.ron", "box-native.exr");
    says(&cornell_log, native_isa);
    let node = format!("node test in {}", native_isa.node_test().name());
    assert!(mesh_log.contains(&node), "{node}?\n{mesh_log}");
    for (cpu, isa, lacks) in [
        ("qemu64", rtis::accel::Isa::Baseline, "avx2"),
        ("Haswell", rtis::accel::Isa::Avx2, "avx512"),
    ] {
        let emulated = Some((qemu.as_path(), cpu));
        let (old, old_log) = render(emulated, "mesh.ron", &format!("{cpu}.exr"));
        says(&old_log, isa);
        let node = format!("node test in {}", isa.name());
        assert!(old_log.contains(&node), "{cpu}: {node}?\n{old_log}");
        same_pixels(&format!("mesh.ron on {cpu}"), &mesh, &old);
        // No BVH: the Global shader's batches of rays, in the emulated CPU's lanes.
        let (old, old_log) = render(
            emulated,
            "cornell-two-bounce.ron",
            &format!("box-{cpu}.exr"),
        );
        says(&old_log, isa);
        same_pixels(&format!("cornell-two-bounce.ron on {cpu}"), &cornell, &old);
        // Asked for an instruction set it lacks, the bench refuses by name.
        let refused = rtis(
            emulated,
            &[
                "bench",
                "--section",
                "meshes",
                "--triangles",
                "1000",
                "--isa",
                lacks,
            ],
        );
        assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
        let message = format!("--isa {lacks}: this CPU does not run it");
        assert!(stderr(&refused).contains(&message), "{}", stderr(&refused));
        // And so does the renderer.
        let out = dir.join("refused.png");
        let args = [
            "render",
            "--width",
            "8",
            "-o",
            out.to_str().unwrap(),
            "--isa",
            lacks,
        ];
        let refused = rtis(emulated, &args);
        assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
        assert!(stderr(&refused).contains(&message), "{}", stderr(&refused));
        // Refused before the scene is read: no estimate, no file.
        assert!(
            !stderr(&refused).contains("estimate"),
            "{}",
            stderr(&refused)
        );
        assert!(!out.exists(), "a refused render wrote {out:?}");
    }
}

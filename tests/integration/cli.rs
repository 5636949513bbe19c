//! The command line: renders, checks, and fails cleanly (message, location, non-zero exit, no
//! panic, no half-written file).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run the binary; one that runs past 300 s is killed and fails the test.
fn rtis(args: &[&str]) -> Output {
    common::output_within(
        Command::new(env!("CARGO_BIN_EXE_rtis"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR")),
        300,
    )
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtis-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn render_default_scene_writes_png_and_summary() {
    let d = tmp("default");
    let out = d.join("cornell.png");
    let o = rtis(&[
        "render",
        "--width",
        "40",
        "--height",
        "32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (40, 32));
    let e = stderr(&o);
    assert!(
        e.contains("Mrays/s") && e.contains("rays (camera 1280"),
        "{e}"
    );
    // Nothing but the image is left in the folder (the temporary file was renamed).
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn render_exr_and_stats_json() {
    let d = tmp("exr");
    let (out, stats) = (d.join("s.exr"), d.join("s.json"));
    let o = rtis(&[
        "render",
        "scenes/spheres.ron",
        "--width",
        "24",
        "--height",
        "16",
        "--spp",
        "4",
        "-o",
        out.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb32f();
    assert_eq!(img.dimensions(), (24, 16));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(json["rays"]["camera"], 24 * 16 * 4);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn same_image_for_any_thread_count() {
    let d = tmp("threads");
    let mut bytes = Vec::new();
    for t in ["1", "2", "3"] {
        let out = d.join(format!("t{t}.exr"));
        let o = rtis(&[
            "render",
            "scenes/cornell-n-bounce.ron",
            "--width",
            "36",
            "--height",
            "29",
            "--spp",
            "2",
            "--threads",
            t,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        bytes.push(std::fs::read(&out).unwrap());
    }
    assert!(
        bytes.windows(2).all(|w| w[0] == w[1]),
        "images differ between thread counts"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn check_prints_the_scene_in_its_own_terms() {
    let o = rtis(&["check", "scenes/cornell.ron"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = String::from_utf8_lossy(&o.stdout);
    for line in [
        "    shader: Global(samples: 64, max_depth: 2, ambient: (0.3, 0.3, 0.3), max_specular: 32, light_samples: 1),",
        "        \"glass\": Transmissive(ior: 1.1, color: (1, 1, 1)),",
        "        (name: \"floor\", shape: InfinitePlane(point: (0, -3, 0), normal: (0, 1, 0)), material: Named(\"grey wall\")),",
        "        (name: \"light far\", light: Point(position: (0, 2, 6), intensity: (7, 7, 7))),",
    ] {
        assert!(s.lines().any(|l| l == line), "no line {line:?} in\n{s}");
    }
    // Rust's debug forms never show.
    for debug in ["Vec3A(", "DVec3(", "Count(", "UpTo(", "Rgb(", " { "] {
        assert!(!s.contains(debug), "{debug} in\n{s}");
    }
    // The cost estimate: the course's rule for n = 64, D = 2, three lights is 4 (1 + 64 * 3).
    assert!(s.contains("(772 by the shader's rule)"), "{s}");
}

/// What `check` prints is a scene file: checked again, it prints the same scene, for every
/// scene in `scenes/` (extends resolved, meshes inline, transforms kept) and the textured
/// scenes of `tests/data` (textured roughness, normal maps, a textured emitter).
#[test]
fn check_output_reads_back_as_the_same_scene() {
    let d = tmp("roundtrip");
    let body = |out: &[u8]| {
        String::from_utf8_lossy(out)
            .lines()
            .filter(|l| !l.starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let scenes = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path());
    let textured = ["texture.ron", "texture_rough.ron"].map(|f| Path::new("tests/data").join(f));
    // A film of Sobol' points, which no scene in `scenes/` asks for.
    std::fs::create_dir_all(d.join("own")).unwrap();
    let sobol = d.join("own").join("sobol.ron");
    std::fs::write(
        &sobol,
        "Scene(film: (width: 8, height: 6, spp: 4, sampler: Sobol), entities: [])",
    )
    .unwrap();
    let first = rtis(&["check", sobol.to_str().unwrap()]);
    assert!(
        body(&first.stdout).contains("spp: 4, transfer: Srgb, sampler: Sobol)"),
        "{}",
        body(&first.stdout)
    );
    for path in scenes.chain(textured).chain([sobol]) {
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let first = rtis(&["check", path.to_str().unwrap()]);
        assert!(first.status.success(), "{}", stderr(&first));
        let copy = d.join(path.file_name().unwrap());
        std::fs::write(&copy, &first.stdout).unwrap();
        let second = rtis(&["check", copy.to_str().unwrap()]);
        assert!(
            second.status.success(),
            "{}: {}",
            path.display(),
            stderr(&second)
        );
        assert_eq!(
            body(&first.stdout),
            body(&second.stdout),
            "{}",
            path.display()
        );
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn broken_scene_is_located_with_nonzero_exit() {
    let d = tmp("broken");
    let f = d.join("broken.ron");
    std::fs::write(&f, "Scene(\n  entities: [\n    (shape: Sphere(center: (0, 0, 5), radius: -1), material: Mirror()),\n  ],\n)\n").unwrap();
    for cmd in ["check", "render"] {
        let o = rtis(
            &[
                cmd,
                f.to_str().unwrap(),
                "-o",
                d.join("x.png").to_str().unwrap(),
            ][..if cmd == "check" { 2 } else { 4 }],
        );
        assert_eq!(o.status.code(), Some(1));
        let e = stderr(&o);
        assert!(
            e.contains(
                "broken.ron:3:47: `radius` must be a length from 1e-9 to 1e9 scene units, got -1"
            ),
            "{e}"
        );
        assert!(!e.contains("panicked"), "{e}");
    }
    assert!(!d.join("x.png").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn unwritable_or_unknown_output_fails_before_rendering() {
    let o = rtis(&["render", "-o", "/nonexistent-dir/x.png"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("/nonexistent-dir/x.png: cannot write output"),
        "{e}"
    );
    // Refused before the estimate, before any rendering.
    assert!(!e.contains("panicked") && !e.contains("estimate:"), "{e}");
    let o = rtis(&["render", "-o", "x.bmp"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("unsupported output format"));
    assert!(!stderr(&o).contains("estimate:"));
    // Each side within range, but too many pixels together.
    let o = rtis(&["render", "--width", "30000", "--height", "30000"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("at most 67108864 pixels"),
        "{}",
        stderr(&o)
    );
    let o = rtis(&["check", "no/such/scene.ron"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot read scene file"));
}

/// The embedded default is the course's Cornell box: the Global shader, five walls, three
/// spheres and three lights, exactly as `scenes/cornell.ron` loads.
#[test]
fn embedded_default_scene_is_the_course_cornell_box() {
    let d = rtis::scene::load_default();
    let f = rtis::scene::load_path(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron"),
    )
    .unwrap();
    assert_eq!(d.settings, f.settings);
    assert!(matches!(d.settings.shader, rtis::shader::Shader::Global(_)));
    let p = rtis::extract(&d);
    use rtis::shape::ShapeKind::*;
    assert_eq!(
        (
            p.geometry.count(Plane),
            p.geometry.count(Sphere),
            p.lights.len()
        ),
        (5, 3, 3)
    );
}

#[test]
fn ruinous_estimate_is_refused_without_force() {
    let d = tmp("ruinous");
    let s = d.join("deep.ron");
    let cornell = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    std::fs::write(
        &s,
        format!("Scene(extends: {cornell:?}, shader: Global(samples: 64, max_depth: 16))"),
    )
    .unwrap();
    let out = d.join("deep.png");
    let o = rtis(&["render", s.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("estimate: 6.6"), "{e}");
    assert!(e.contains("--force"), "{e}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn force_and_threads_cap_are_accepted() {
    let d = tmp("threads");
    let out = d.join("c.png");
    let o = rtis(&[
        "render",
        "--width",
        "16",
        "--height",
        "12",
        "--threads",
        "100000",
        "--force",
        "-o",
        out.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("warning: --threads 100000 is more than 4 per core"),
        "{e}"
    );
    assert!(out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn width_alone_keeps_the_aspect_ratio() {
    let d = tmp("aspect");
    for (args, size) in [
        (["--width", "90"], (90, 72)),
        (["--height", "36"], (45, 36)),
    ] {
        let out = d.join("a.png");
        let o = rtis(&["render", args[0], args[1], "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        let img = image::open(&out).unwrap();
        assert_eq!((img.width(), img.height()), size);
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn stats_path_is_checked_before_rendering() {
    let d = tmp("stats");
    let out = d.join("c.png");
    let stats = d.join("missing-folder").join("s.json");
    let o = rtis(&[
        "render",
        "-o",
        out.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("s.json: cannot write output"), "{e}");
    // It failed before the render: no estimate, no image.
    assert!(!e.contains("estimate:") && !out.exists(), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Numbers out of range are refused by the argument parser with the range they must be in,
/// and a negative number is read as a number, not as a flag.
#[test]
fn out_of_range_arguments_are_refused_with_their_range() {
    for (args, says) in [
        (&["render", "--width", "-5"][..], "-5 is not in 1..=32768"),
        (&["render", "--spp", "0"][..], "0 is not in 1..=1048576"),
        (&["bench", "--runs", "0"][..], "0 is not in 1.."),
        (
            &["bench", "--shrink", "100000"][..],
            "100000 is not in 1..=288",
        ),
        (&["converge", "--runs", "0"][..], "0 is not in 1.."),
        (&["converge", "--width", "0"][..], "0 is not in 1..=32768"),
        (
            &["bench", "--section", "disks"][..],
            "possible values: all, cornell, effects, meshes",
        ),
        (
            &["render", "--isa", "sse"][..],
            "possible values: auto, baseline, avx2, avx512",
        ),
    ] {
        let o = rtis(args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(says), "{args:?}: {e}");
        assert!(!e.contains("tip:"), "{args:?}: {e}");
    }
}

/// `rtis bench --json | head -1`: a closed pipe ends the process quietly, as with any Unix
/// filter, instead of a panic on the next print.
#[test]
fn closed_pipe_ends_quietly() {
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "{} bench --json --section cornell --shrink 72 --runs 1 | head -1",
            env!("CARGO_BIN_EXE_rtis")
        ))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(out.starts_with("{\"cores\":"), "{out}");
    assert!(!err.contains("panicked"), "{err}");
}

/// `rtis diff` on images whose differences are known: a uniform 0.5 against a uniform 0.25
/// (linear EXR) has RMSE and largest error 0.25 and relMSE 0.0625 / (0.0625 + 0.01); an image
/// against itself has every figure 0; images of two sizes are refused.
#[test]
fn diff_prints_exact_figures_and_writes_the_heatmap() {
    let d = tmp("diff");
    let exr = |name: &str, v: f32, w: u32| {
        let p = d.join(name);
        image::Rgb32FImage::from_pixel(w, 8, image::Rgb([v, v, v]))
            .save(&p)
            .unwrap();
        p
    };
    let (a, b, c) = (
        exr("a.exr", 0.5, 8),
        exr("b.exr", 0.25, 8),
        exr("c.exr", 0.5, 9),
    );
    let heat = d.join("heat.png");
    let o = rtis(&[
        "diff",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "-o",
        heat.to_str().unwrap(),
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    for line in [
        "  RMSE        0.250000",
        "  relMSE      0.862069",
        "  max error   0.250000",
        "  pixels that differ  64 of 64",
    ] {
        assert!(out.lines().any(|l| l == line), "{line:?} in\n{out}");
    }
    assert!(out.contains("mean FLIP"), "{out}");
    assert_eq!(image::open(&heat).unwrap().width(), 8);
    let o = rtis(&["diff", a.to_str().unwrap(), a.to_str().unwrap()]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("  RMSE        0.000000") && out.contains("  mean FLIP   0.000000"),
        "{out}"
    );
    let o = rtis(&["diff", a.to_str().unwrap(), c.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("is 8x8 but"), "{}", stderr(&o));
    std::fs::remove_dir_all(&d).unwrap();
}

/// The tests' time limit on a child process holds: one that runs past it is killed at once
/// (well before the 30 s it would run) and the test fails with the limit in its message, as a
/// binary caught in an endless loop would.
#[test]
fn a_child_past_its_time_limit_is_killed() {
    let start = std::time::Instant::now();
    let failed = std::panic::catch_unwind(|| {
        common::output_within(Command::new("sleep").arg("30"), 1);
    })
    .expect_err("the call fails");
    let message = failed.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(
        message.contains("ran past its limit of 1 s and was killed"),
        "{message}"
    );
    assert!(start.elapsed().as_secs() < 10, "{:?}", start.elapsed());
}

/// `check` and `render` estimate one scene alike: the same rays (the shader's rule and the
/// calibration's count, which are deterministic) on the same threads. The seconds come from
/// timing the calibration and vary from run to run with the machine; they are not compared.
#[test]
fn check_and_render_estimate_the_same_rays() {
    let d = tmp("estimate");
    let scene = d.join("small.ron");
    let cornell = common::scenes_dir().join("cornell.ron");
    std::fs::write(
        &scene,
        format!("Scene(extends: {cornell:?}, film: (width: 40, height: 32, spp: 2))\n"),
    )
    .unwrap();
    let s = scene.to_str().unwrap();
    let check = rtis(&["check", s]);
    let out = String::from_utf8_lossy(&check.stdout).into_owned();
    let from_check = out
        .lines()
        .find_map(|l| {
            l.strip_prefix("// cost: ")?
                .rsplit_once("), ")
                .map(|(_, t)| t.to_string())
        })
        .unwrap_or_else(|| panic!("no cost line: {out}"));
    let png = d.join("small.png");
    let render = rtis(&["render", s, "--threads", "2", "-o", png.to_str().unwrap()]);
    let err = stderr(&render);
    let from_render = err
        .lines()
        .find_map(|l| l.strip_prefix("estimate: "))
        .unwrap_or_else(|| panic!("no estimate line: {err}"));
    // "3.746e4 rays in all, about ... on 2 threads" against "3.746e4 rays, about ... on 2 threads".
    let rays = |t: &str| t.split(" rays").next().unwrap().to_string();
    let threads = |t: &str| {
        t.split(" on ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(rays(&from_check), rays(from_render), "{out}\n{err}");
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if cores == 2 {
        assert_eq!(threads(&from_check), threads(from_render), "{out}\n{err}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// `--sampler sobol` renders what a film of `sampler: Sobol` renders, to the byte, and not what
/// the independent sampler renders.
#[test]
fn sampler_override_is_the_films_sampler() {
    let d = tmp("sampler");
    let scene = d.join("sobol.ron");
    std::fs::write(
        &scene,
        format!(
            "Scene(extends: {:?}, film: (width: 24, height: 20, spp: 16, sampler: Sobol))",
            common::scenes_dir().join("mitsuba-cornell.ron")
        ),
    )
    .unwrap();
    let plain = common::scenes_dir().join("mitsuba-cornell.ron");
    let render = |name: &str, args: &[&str]| {
        let out = d.join(name);
        let mut all = vec!["render", "-o", out.to_str().unwrap()];
        all.extend_from_slice(args);
        let o = rtis(&all);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(&out).unwrap()
    };
    let film = render("film.exr", &[scene.to_str().unwrap()]);
    let size = ["--width", "24", "--height", "20", "--spp", "16"];
    let mut args = vec![plain.to_str().unwrap()];
    args.extend_from_slice(&size);
    let independent = render("independent.exr", &args);
    args.extend_from_slice(&["--sampler", "sobol"]);
    let flag = render("flag.exr", &args);
    assert_eq!(film, flag, "--sampler sobol against the film's sampler");
    assert_ne!(film, independent);
    // And back: `--sampler independent` on the Sobol' film.
    let back = render(
        "back.exr",
        &[scene.to_str().unwrap(), "--sampler", "independent"],
    );
    assert_eq!(
        back, independent,
        "--sampler independent on a film of Sobol' points"
    );
    let o = rtis(&["render", plain.to_str().unwrap(), "--sampler", "halton"]);
    assert!(
        !o.status.success() && stderr(&o).contains("halton"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&d).unwrap();
}

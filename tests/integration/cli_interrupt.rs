//! Ctrl-C and SIGTERM (src/cli/interrupt.rs): the first Ctrl-C keeps a long render's image so
//! far, a second one or SIGTERM quits at once, and no temporary file is ever left behind, even
//! when the signal comes while the image is being written.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtis-int-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene(dir: &Path, shader: &str) -> PathBuf {
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let p = dir.join("scene.ron");
    let text = format!("Scene(extends: {:?}, shader: {shader})\n", cornell);
    std::fs::write(&p, text).unwrap();
    p
}

/// Start `rtis render`; the receiver gets each stderr line (progress redraws split at '\r').
fn start(args: &[&str]) -> (Child, mpsc::Receiver<String>) {
    start_command("render", args)
}

/// Start `rtis COMMAND ARGS`, as [`start`].
fn start_command(command: &str, args: &[&str]) -> (Child, mpsc::Receiver<String>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtis"))
        .arg(command)
        .args(args)
        .stderr(Stdio::piped())
        .spawn()
        .expect("run rtis");
    let err = child.stderr.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(err).split(b'\n') {
            let Ok(line) = line else { break };
            for part in String::from_utf8_lossy(&line).split('\r') {
                let _ = tx.send(part.to_string());
            }
        }
    });
    (child, rx)
}

/// Wait for a stderr line containing `needle`.
fn wait_for(rx: &mpsc::Receiver<String>, needle: &str) -> Vec<String> {
    let mut seen = Vec::new();
    loop {
        match rx.recv_timeout(Duration::from_secs(120)) {
            Ok(l) => {
                let hit = l.contains(needle);
                seen.push(l);
                if hit {
                    return seen;
                }
            }
            Err(e) => panic!("no `{needle}` on stderr ({e}); saw {seen:?}"),
        }
    }
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "scene.ron")
        .collect();
    v.sort();
    v
}

fn rest(rx: &mpsc::Receiver<String>) -> String {
    rx.iter().collect::<Vec<_>>().join("\n")
}

/// A scene of one spp stopped in its only round keeps the tiles finished.
#[test]
fn first_ctrl_c_writes_the_partial_image_and_exits_130() {
    let d = tmp("partial");
    let s = scene(&d, "Global(samples: 64, max_depth: 3)");
    let out = d.join("box.png");
    // The signal must come after a tile is finished: on a loaded machine (the other tests run
    // beside this one) none may be after 300 ms, and then the render says so and writes
    // nothing, which is right; wait longer and try again (the whole render takes 5 s alone).
    let mut err = String::new();
    for wait in [300, 1500, 4000] {
        let (mut child, rx) = start(&[s.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        // The render has started (and Ctrl-C keeps its image) once it says so.
        wait_for(&rx, "Ctrl-C keeps");
        std::thread::sleep(Duration::from_millis(wait));
        signal(&child, "-INT");
        let status = child.wait().unwrap();
        err = rest(&rx);
        assert_eq!(status.code(), Some(130), "{err}");
        if !err.contains("interrupted before a tile was finished: no image written") {
            break;
        }
        assert!(files(&d).is_empty(), "{:?}", files(&d));
    }
    // One round of one spp: the tiles it finished are kept.
    assert!(
        err.contains("in the first round") && err.contains("tiles rendered"),
        "{err}"
    );
    assert!(err.contains("box.partial.png"), "{err}");
    // Only the partial image, whole, under its own name.
    assert_eq!(files(&d), vec!["box.partial.png".to_string()]);
    let img = image::open(d.join("box.partial.png")).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (720, 576));
    // Rendered tiles are not black, the ones never started are.
    assert!(img.pixels().any(|p| p.0 != [0, 0, 0]));
    assert_eq!(img.get_pixel(719, 575).0, [0, 0, 0], "{err}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn sigterm_quits_at_once_with_143_and_leaves_nothing() {
    let d = tmp("term");
    let s = scene(&d, "Global(samples: 64, max_depth: 3)");
    let out = d.join("box.png");
    let (mut child, rx) = start(&[s.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    wait_for(&rx, "estimate:");
    signal(&child, "-TERM");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(143), "{}", rest(&rx));
    assert!(files(&d).is_empty(), "{:?}", files(&d));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn second_ctrl_c_quits_at_once() {
    let d = tmp("twice");
    let s = scene(&d, "Global(samples: 64, max_depth: 3)");
    let out = d.join("box.png");
    let (mut child, rx) = start(&[s.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    wait_for(&rx, "Ctrl-C keeps");
    signal(&child, "-INT");
    wait_for(&rx, "press Ctrl-C again");
    signal(&child, "-INT");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{}", rest(&rx));
    // No full image, no temporary file; a partial image only if it was written whole first.
    for f in files(&d) {
        assert_eq!(f, "box.partial.png");
        image::open(d.join(&f)).expect("a whole image");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// SIGTERM at moments spread over a short render and its write: the output is absent or
/// whole, and no temporary file is ever left.
#[test]
fn signal_during_the_write_leaves_no_temporary_file() {
    let d = tmp("write");
    let s = scene(&d, "Normal");
    let out = d.join("n.exr");
    for delay_ms in (0..=300).step_by(25) {
        let (mut child, rx) = start(&[
            s.to_str().unwrap(),
            "--width",
            "2000",
            "--height",
            "2000",
            "-o",
            out.to_str().unwrap(),
        ]);
        wait_for(&rx, "estimate:");
        std::thread::sleep(Duration::from_millis(delay_ms));
        signal(&child, "-TERM");
        let status = child.wait().unwrap();
        assert!(
            matches!(status.code(), Some(0 | 143)),
            "{status:?} {}",
            rest(&rx)
        );
        for f in files(&d) {
            assert_eq!(f, "n.exr", "left behind after {delay_ms} ms");
            let img = image::open(&out).expect("a whole image");
            assert_eq!((img.width(), img.height()), (2000, 2000));
            std::fs::remove_file(&out).unwrap();
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// SIGTERM while the temporary file of the image exists (held by the test hook
/// `RTIS_TEST_WRITE_PAUSE_MS`): the signal waits for the write to finish, so the image is whole
/// and no temporary file is left (exit 143, or 0 when the finished render exits first).
#[test]
fn sigterm_during_the_write_waits_for_it() {
    let d = tmp("pause");
    let s = scene(&d, "Normal");
    let out = d.join("n.png");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtis"))
        .args([
            "render",
            s.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "48",
            "-o",
        ])
        .arg(&out)
        .env("RTIS_TEST_WRITE_PAUSE_MS", "1500")
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Wait for the written temporary file (the empty one of the start-up folder check does
    // not count).
    let start = std::time::Instant::now();
    let written =
        |f: &String| f.ends_with(".tmp") && std::fs::metadata(d.join(f)).is_ok_and(|m| m.len() > 0);
    while !files(&d).iter().any(written) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary file appeared"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    signal(&child, "-TERM");
    let status = child.wait().unwrap();
    assert!(matches!(status.code(), Some(0 | 143)), "{status:?}");
    assert_eq!(files(&d), vec!["n.png".to_string()]);
    let img = image::open(&out).expect("a whole image");
    assert_eq!((img.width(), img.height()), (64, 48));
    std::fs::remove_dir_all(&d).unwrap();
}

/// Ctrl-C during `rtis converge` finishes the rung in flight and writes the rungs done
/// (converge.csv and converge.md, beside the reference), then exits 130; no rung after it runs.
#[test]
fn ctrl_c_during_converge_keeps_the_rungs_done() {
    let d = tmp("converge");
    let s = scene(&d, "Global(samples: 4, max_depth: 1)");
    let out = d.join("out");
    let (mut child, rx) = start_command(
        "converge",
        &[
            s.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--width",
            "48",
            "--runs",
            "1",
            "--seeds",
            "1",
            "--reference-spp",
            "8",
        ],
    );
    // The first rung's line: the ladder is running.
    wait_for(&rx, "direct");
    signal(&child, "-INT");
    let status = child.wait().unwrap();
    let err = rest(&rx);
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted: wrote the"), "{err}");
    let csv = std::fs::read_to_string(out.join("converge.csv")).unwrap();
    let rows = csv.lines().count() - 1;
    assert!(rows >= 1, "{csv}");
    // The ladder of a Global scene has 15 rungs; far fewer ran.
    assert!(rows < 15, "{csv}");
    assert!(out.join("converge.md").exists() && out.join("reference.exr").exists());
    assert!(!out.join("report.html").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

/// The linear pixels of an EXR, as bits.
fn exr_bits(path: &Path) -> Vec<u32> {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb32f();
    img.pixels().flat_map(|p| p.0.map(f32::to_bits)).collect()
}

/// A render of many spp is progressive: Ctrl-C after a round writes the whole frame at the
/// spp of the rounds done (a PNG that says so, and its pass NAME.partial.exr), and `--resume`
/// from it ends with the bits of a render never stopped. `--time` stops after the round that
/// fits, writes the image with its spp, and resumes the same way.
#[test]
fn progressive_render_stops_resumes_and_keeps_its_bits() {
    let d = tmp("progressive");
    let s = scene(&d, "Path(max_depth: 3)");
    let s = s.to_str().unwrap();
    let size = ["--width", "64", "--height", "48", "--spp", "4096"];
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_rtis"))
            .arg("render")
            .arg(s)
            .args(size)
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{args:?}: {err}");
        err
    };
    let full = d.join("full.exr");
    run(&["-o", full.to_str().unwrap()]);
    let want = exr_bits(&full);

    // Ctrl-C after a round.
    let out = d.join("box.png");
    let mut args = vec![s];
    args.extend(size);
    args.extend(["-o", out.to_str().unwrap()]);
    let (mut child, rx) = start(&args);
    wait_for(&rx, "round: samples 1..2");
    signal(&child, "-INT");
    let status = child.wait().unwrap();
    let err = rest(&rx);
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("the whole frame at"), "{err}");
    let mut names = files(&d);
    names.retain(|n| n != "full.exr");
    assert_eq!(names, vec!["box.partial.exr", "box.partial.png"], "{err}");
    // The preview is a whole frame: no black pixel in the lit box.
    let png = image::open(d.join("box.partial.png")).unwrap().to_rgb8();
    assert!(
        png.pixels().filter(|p| p.0 == [0, 0, 0]).count() < 64,
        "{err}"
    );
    // It says its spp.
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(d.join("box.partial.png")).unwrap(),
    ));
    let reader = decoder.read_info().unwrap();
    let note = &reader.info().uncompressed_latin1_text[0];
    assert_eq!(note.keyword, "Comment");
    assert!(
        note.text.contains("samples per pixel") && note.text.contains("of 4096"),
        "{}",
        note.text
    );
    let resumed = d.join("resumed.exr");
    let partial = d.join("box.partial.exr");
    let err = run(&[
        "--resume",
        partial.to_str().unwrap(),
        "-o",
        resumed.to_str().unwrap(),
    ]);
    assert!(err.contains("resuming from"), "{err}");
    assert!(
        exr_bits(&resumed) == want,
        "resumed after Ctrl-C: other bits\n{err}"
    );

    // A time budget too short for more than the first round.
    let timed = d.join("timed.png");
    let err = run(&["--time", "1ms", "-o", timed.to_str().unwrap()]);
    assert!(
        err.contains("time budget spent: the whole frame at 1 of 4096 spp"),
        "{err}"
    );
    assert!(
        timed.exists() && d.join("timed.partial.exr").exists(),
        "{err}"
    );
    let finished = d.join("finished.exr");
    run(&[
        "--resume",
        d.join("timed.partial.exr").to_str().unwrap(),
        "-o",
        finished.to_str().unwrap(),
    ]);
    assert!(
        exr_bits(&finished) == want,
        "resumed after --time: other bits"
    );

    // A pass of another render is refused, located at the file.
    let other = Command::new(env!("CARGO_BIN_EXE_rtis"))
        .args([
            "render", s, "--width", "64", "--height", "48", "--spp", "8", "--resume",
        ])
        .arg(&partial)
        .arg("-o")
        .arg(d.join("never.png"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(!other.status.success());
    assert!(
        err.contains("box.partial.exr: cannot resume") && err.contains("another spp"),
        "{err}"
    );
    assert!(!d.join("never.png").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

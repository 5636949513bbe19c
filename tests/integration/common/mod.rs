//! Helpers shared by the integration tests.
#![allow(dead_code)]

use glam::Vec3A;
use rtis::render;
use rtis::render::Rendered;
use rtis::scene::{self, Scene};
use std::path::{Path, PathBuf};

/// The repository's `scenes/` folder.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Parse a scene from text (panics with the located error on failure).
pub fn scene(text: &str) -> Scene {
    scene::load_str(text, "test.ron", Some(&scenes_dir())).unwrap_or_else(|e| panic!("{e}"))
}

/// Extract and render a loaded scene on the global pool; asserts that no sample was dropped
/// as NaN, infinite or negative, and that every pixel is finite and non-negative. A render that
/// runs past 300 s fails the test binary ([`deadline`]): the tests' renders take seconds.
pub fn render_scene(s: &Scene) -> Rendered {
    let _limit = deadline(300);
    let r = render(&rtis::extract(s), &|| {});
    assert_eq!(
        r.stats.dropped, 0,
        "samples dropped as non-finite or negative"
    );
    assert!(
        r.image
            .pixels
            .iter()
            .all(|p| p.is_finite() && p.min_element() >= 0.0),
        "a pixel is NaN, infinite or negative"
    );
    r
}

/// Parse and render scene text.
pub fn render_str(text: &str) -> Rendered {
    render_scene(&scene(text))
}

/// An image's pixels as bits, to compare renders bit for bit.
pub fn bits(img: &rtis::render::film::Image) -> Vec<[u32; 3]> {
    img.pixels
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// Relative closeness of two colours.
pub fn close(a: Vec3A, b: Vec3A, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * b.abs().max_element().max(1e-6)
}

/// The mean of the 4x4 block `(bx, by)` of `img`.
pub fn block(img: &rtis::render::film::Image, bx: u32, by: u32) -> Vec3A {
    let mut s = Vec3A::ZERO;
    for y in 0..4 {
        for x in 0..4 {
            s += img.get(bx * 4 + x, by * 4 + y);
        }
    }
    s / 16.0
}

/// Two renders `a` and `b` of one scene with different seeds against an independent reference
/// `r` whose per-pixel noise RMSE is `ref_noise`, on 4 x 4 blocks (blocks where `skip` holds
/// are left out): returns the block MSE of `(a + b) / 2` against `r`, and what noise alone
/// explains, `var_ours / 2 + var_ref` (our block variance estimated from `a - b`). If both
/// estimate the same image, the first is about the second.
pub fn block_mse(
    a: &rtis::render::film::Image,
    b: &rtis::render::film::Image,
    r: &rtis::render::film::Image,
    ref_noise: f64,
    skip: &dyn Fn(u32, u32) -> bool,
) -> (f64, f64) {
    assert_eq!((a.width, a.height), (r.width, r.height));
    let (mut d_ab, mut d_ref, mut n) = (0.0f64, 0.0f64, 0.0f64);
    for by in 0..a.height / 4 {
        for bx in 0..a.width / 4 {
            if skip(bx, by) {
                continue;
            }
            let (pa, pb, pr) = (block(a, bx, by), block(b, bx, by), block(r, bx, by));
            let ab = pa - pb;
            let m = 0.5 * (pa + pb) - pr;
            d_ab += ab.dot(ab) as f64 / 3.0;
            d_ref += m.dot(m) as f64 / 3.0;
            n += 1.0;
        }
    }
    let var_ours = d_ab / n / 2.0;
    let var_ref = ref_noise * ref_noise / 16.0;
    (d_ref / n, var_ours / 2.0 + var_ref)
}

/// Mean of the first channel over an image's pixels and its standard error (pixels are
/// independent estimates of the same value when the camera sees one point).
pub fn mean_and_se(r: &Rendered) -> (f64, f64) {
    let v: Vec<f64> = r.image.pixels.iter().map(|p| p.x as f64).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// A Mitsuba reference image from `tests/data/`, mirrored left-right into rtis's camera
/// convention (Mitsuba's camera is right-handed).
pub fn mitsuba_reference(file: &str) -> rtis::render::film::Image {
    rtis::render::output::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(file),
    )
    .unwrap_or_else(|e| panic!("{file}: {e}"))
    .flipped_horizontally()
}

/// Two renders of 64 spp of `scene` (in tests/data), and their block MSE against Mitsuba's
/// `reference` of noise `noise`, with what noise explains; the mean of the renders.
pub fn against_mitsuba(scene: &str, reference: &str, noise: f64) -> (f64, f64, Vec3A) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(scene);
    let mut s = rtis::scene::load_path(&path).unwrap_or_else(|e| panic!("{e}"));
    s.settings.film.spp = 64;
    let a = render_scene(&s);
    s.settings.seed = 4321;
    let b = render_scene(&s);
    let r = mitsuba_reference(reference);
    let (mse, explained) = block_mse(&a.image, &b.image, &r, noise, &|_, _| false);
    (mse, explained, (a.image.mean() + b.image.mean()) * 0.5)
}

/// The nearest hit among `prims` by testing each in order, a later one winning at equal
/// distance (the loop a BVH leaf and a block stand for): its index in `prims` and distance.
pub fn nearest(prims: &[rtis::accel::Prim], ray: &rtis::geometry::Ray) -> Option<(u32, f32)> {
    let mut r = *ray;
    let mut best = None;
    for (k, p) in prims.iter().enumerate() {
        if let Some(t) = p.shape.intersect(&r) {
            r.t_max = t;
            best = Some((k as u32, t));
        }
    }
    best
}

/// Mark every point light of `scene` as outside the planes' room, so that its shadow rays test
/// the planes too (the renderer skips them for lights in the room).
pub fn lights_out_of_room(scene: &mut rtis::RenderScene) {
    for light in &mut scene.lights {
        match light {
            rtis::light::Light::Point(p) => p.in_room = false,
            rtis::light::Light::Spot(s) => s.in_room = false,
            // Never in a room: its shadow rays test the planes already.
            rtis::light::Light::Directional(_) => {}
        }
    }
}

/// A time limit on the test that holds it: if the guard is still alive `seconds` after it was
/// made, the test binary prints the test's name and exits with a failure, so a bug that makes a
/// loop run forever fails the suite instead of hanging it (`cargo test` has no per-test limit).
/// Dropping the guard (the test ends, or panics) lifts the limit.
#[must_use = "the limit holds while the guard lives"]
pub struct Deadline(u64);

/// The live deadlines: guard number, when it expires, the test's name and its limit.
type Deadlines = std::collections::HashMap<u64, (std::time::Instant, String, u64)>;

fn deadlines() -> &'static std::sync::Mutex<Deadlines> {
    static LIVE: std::sync::OnceLock<std::sync::Mutex<Deadlines>> = std::sync::OnceLock::new();
    LIVE.get_or_init(|| {
        // One watchdog per test binary, started with the first deadline.
        std::thread::spawn(|| {
            loop {
                std::thread::sleep(std::time::Duration::from_millis(200));
                let now = std::time::Instant::now();
                let live = deadlines().lock().unwrap_or_else(|e| e.into_inner());
                if let Some((_, name, limit)) = live.values().find(|(at, ..)| *at <= now) {
                    // Straight to the standard error: `eprintln!` would go to the test's
                    // captured output, which is lost when the process exits.
                    use std::io::Write;
                    let _ = writeln!(
                        std::io::stderr(),
                        "test `{name}` ran past its limit of {limit} s: a loop that does not end? \
                         Failing the test binary."
                    );
                    // The children still running would outlive the binary: kill them first.
                    for &pid in children().lock().unwrap_or_else(|e| e.into_inner()).iter() {
                        // SAFETY: `kill` on a pid whose process `output_within` has not reaped
                        // (it reaps only with the list locked, and takes the pid off at once).
                        unsafe { libc::kill(pid as libc::pid_t, libc::SIGKILL) };
                    }
                    std::process::exit(3);
                }
            }
        });
        Default::default()
    })
}

/// Put a limit of `seconds` on the running test ([`Deadline`]).
pub fn deadline(seconds: u64) -> Deadline {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = std::thread::current()
        .name()
        .unwrap_or("(unnamed)")
        .to_string();
    let at = std::time::Instant::now() + std::time::Duration::from_secs(seconds);
    deadlines()
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(id, (at, name, seconds));
    Deadline(id)
}

impl Drop for Deadline {
    fn drop(&mut self) {
        deadlines()
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&self.0);
    }
}

/// Run `cmd` to its end and return what it printed, but kill it and fail the test if it runs
/// longer than `seconds` (a child process that loops forever would otherwise hang the suite).
/// While it runs it is on the watchdog's list ([`deadline`]), which kills it before failing
/// the binary, so no child outlives the tests.
pub fn output_within(cmd: &mut std::process::Command, seconds: u64) -> std::process::Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    let pid = child.id();
    children()
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(pid);
    // Read both pipes as the child writes, so that it never blocks on a full pipe.
    let reader = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let out = reader(Box::new(child.stdout.take().expect("piped")));
    let err = reader(Box::new(child.stderr.take().expect("piped")));
    let end = std::time::Instant::now() + std::time::Duration::from_secs(seconds);
    // The child is reaped only with the list locked, and taken off it at once, so the
    // watchdog (which kills what is on the list, holding the lock) never signals a pid that
    // may have been given to another process.
    let status = loop {
        {
            let mut live = children().lock().unwrap_or_else(|e| e.into_inner());
            let timed_out = std::time::Instant::now() >= end;
            if timed_out {
                let _ = child.kill();
            }
            if let Some(status) = child.try_wait().expect("wait for the child") {
                live.retain(|&p| p != pid);
                break (!timed_out).then_some(status);
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let Some(status) = status else {
        panic!(
            "{cmd:?} ran past its limit of {seconds} s and was killed: a loop that does not end?"
        )
    };
    std::process::Output {
        status,
        stdout: out.join().expect("stdout reader"),
        stderr: err.join().expect("stderr reader"),
    }
}

/// The child processes [`output_within`] is waiting for, which the watchdog kills before it
/// fails the test binary.
fn children() -> &'static std::sync::Mutex<Vec<u32>> {
    static LIVE: std::sync::OnceLock<std::sync::Mutex<Vec<u32>>> = std::sync::OnceLock::new();
    LIVE.get_or_init(Default::default)
}

thread_local! {
    /// The rays the audit saw on this thread ([`rays_traced`]).
    static SEEN: std::cell::RefCell<Vec<(rtis::geometry::Ray, rtis::stats::RayKind)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// The audit of [`rays_traced`]: keep every ray.
fn record(ray: &rtis::geometry::Ray, kind: rtis::stats::RayKind) {
    SEEN.with_borrow_mut(|v| v.push((*ray, kind)));
}

/// Every ray `run` traces through a copy of `rs` with the tracer's audit on
/// (`rtis::shader::RayAudit`), with its kind, in order. `run` must trace on this thread.
pub fn rays_traced(
    rs: &rtis::RenderScene,
    run: impl FnOnce(&rtis::RenderScene),
) -> Vec<(rtis::geometry::Ray, rtis::stats::RayKind)> {
    let mut audited = rs.clone();
    audited.audit = Some(record);
    SEEN.with_borrow_mut(Vec::clear);
    run(&audited);
    SEEN.with_borrow_mut(std::mem::take)
}

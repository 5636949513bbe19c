//! `rtis watch`: a live preview that follows the scene file.
//!
//! Three threads share one [`State`]:
//! - the **renderer** loads the scene, renders it progressively ([`progressive::refine`]) and
//!   publishes the image after every round; a change stops the round in flight and starts
//!   again from the new scene;
//! - the **watcher** (the `notify` crate) follows the folders of the files the scene was read
//!   from (the scene, the bases it extends, its meshes) and reports a change to any of them;
//!   folders, not files, so an editor that saves by writing a new file and renaming it is seen;
//! - the **server** (the `tiny_http` crate) answers the page and its two requests: `/state`
//!   (JSON) and `/image` (the linear image, little-endian `f32` R, G, B per pixel, row-major).
//!
//! It serves nothing else: no file is ever read for a request, so nothing outside (or inside)
//! the scene's folder is reachable. It binds to 127.0.0.1 unless `--bind` says otherwise.

use super::CliError;
use clap::Args;
use notify::{EventKind, RecursiveMode, Watcher};
use rtis::render::estimate::{self, human_seconds};
use rtis::render::pass::Pass;
use rtis::render::progressive::{self, Round};
use rtis::stats::RayStats;
use std::collections::BTreeSet;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

/// The page: its script polls `/state` and fetches `/image` when the image changed.
const PAGE: &str = include_str!("watch.html");

/// How long after a change further changes are gathered into one restart (an editor's save
/// can touch a file several times).
const SETTLE: Duration = Duration::from_millis(40);

/// Arguments of `rtis watch`.
#[derive(Args, Debug)]
pub struct WatchArgs {
    /// The scene file (RON, or a Mitsuba `.xml`) to render and follow.
    scene: PathBuf,
    /// The port to serve on (0: any free port; the URL printed says which).
    #[arg(long, default_value_t = 8137)]
    port: u16,
    /// The address to bind to. Only this machine can connect to the default; another address
    /// (as 0.0.0.0) shows the preview to the network.
    #[arg(long, default_value = "127.0.0.1")]
    bind: std::net::IpAddr,
    /// Worker threads for rendering (default: one per core).
    #[arg(long, allow_negative_numbers = true)]
    threads: Option<usize>,
}

/// What the page shows; the renderer writes it, the server reads it.
#[derive(Default)]
struct State {
    /// Bumped whenever the image changes.
    version: u64,
    /// Bumped whenever the scene is loaded again.
    generation: u64,
    /// The image of the last completed round of the last good scene.
    image: Option<Arc<Image>>,
    /// The located message of the scene's error, while the file is broken.
    error: Option<String>,
    /// Warnings of the last good scene.
    warnings: Vec<String>,
    /// What the renderer is doing.
    status: Status,
    /// Samples per pixel the scene asks for.
    target_spp: u32,
    /// The cost estimate, as `render` prints it.
    estimate: String,
    /// The effects simulated, as `render` prints them.
    effects: String,
    /// Rays traced for the image shown, by kind.
    rays: RayStats,
    /// Seconds spent tracing the image shown.
    seconds: f64,
}

/// What the renderer is doing, as `/state` says it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
enum Status {
    /// Reading the scene (and building its BVH).
    #[default]
    Loading,
    /// Rendering rounds.
    Rendering,
    /// Every sample is in the image.
    Done,
    /// The scene has an error; the image is the last good one.
    Error,
}

/// An image as the page receives it.
struct Image {
    width: u32,
    height: u32,
    /// Samples per pixel it holds.
    spp: u64,
    /// Little-endian `f32` R, G, B per pixel.
    bytes: Vec<u8>,
}

fn lock(state: &Mutex<State>) -> MutexGuard<'_, State> {
    state.lock().unwrap_or_else(|e| e.into_inner())
}

/// The files the watcher follows and the flag that stops the round in flight.
struct Follow {
    /// Canonical paths of the files whose change restarts the render.
    files: Mutex<BTreeSet<PathBuf>>,
    /// Set on a change: the renderer drops its round and loads the scene again.
    changed: AtomicBool,
    /// Set while the scene has an error: then any change in the folders followed reloads
    /// it, since the error may name a file not read yet (a missing base or mesh).
    broken: AtomicBool,
}

/// The canonical form of `path` (its folder canonicalised, so a file being replaced still
/// matches).
fn canonical(path: &Path) -> PathBuf {
    let name = path.file_name().map(PathBuf::from).unwrap_or_default();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    dir.canonicalize()
        .map_or_else(|_| path.to_path_buf(), |d| d.join(name))
}

/// Run `rtis watch`.
pub fn run(a: WatchArgs) -> Result<(), CliError> {
    let threads = super::render::thread_count(a.threads)?;
    if !a.scene.is_file() {
        return Err(format!("{}: no such scene file", a.scene.display()).into());
    }
    let address = SocketAddr::new(a.bind, a.port);
    let server = tiny_http::Server::http(address)
        .map_err(|e| format!("cannot serve on {address}: {e} (choose another with --port)"))?;
    let bound = server
        .server_addr()
        .to_ip()
        .ok_or("the server is not on an IP address")?;
    let state = Arc::new(Mutex::new(State::default()));
    let follow = Arc::new(Follow {
        files: Mutex::new(BTreeSet::from([canonical(&a.scene)])),
        changed: AtomicBool::new(false),
        broken: AtomicBool::new(false),
    });
    let (tx, rx) = mpsc::channel();
    let watcher = start_watcher(&follow, tx)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    {
        let (state, follow, scene) = (state.clone(), follow.clone(), a.scene.clone());
        std::thread::Builder::new()
            .name("renderer".into())
            .spawn(move || renderer(&scene, &state, &follow, watcher, &rx, &pool))?;
    }
    eprintln!(
        "watching {}: open http://{bound}/ (Ctrl-C quits)",
        a.scene.display()
    );
    for request in server.incoming_requests() {
        let response = answer(&request, &state, bound);
        // A page closed while its answer is sent is not an error of ours.
        let _ = request.respond(response);
    }
    Ok(())
}

/// Follow the folders of `follow.files`: any event but a read on one of the files sets
/// `follow.changed` and sends on `tx`.
fn start_watcher(
    follow: &Arc<Follow>,
    tx: Sender<()>,
) -> Result<notify::RecommendedWatcher, CliError> {
    let follow = follow.clone();
    let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
        let Ok(event) = event else { return };
        if matches!(event.kind, EventKind::Access(_)) {
            return;
        }
        let relevant = follow.broken.load(Ordering::SeqCst) || {
            let files = follow.files.lock().unwrap_or_else(|e| e.into_inner());
            event.paths.iter().any(|p| files.contains(&canonical(p)))
        };
        if relevant {
            follow.changed.store(true, Ordering::SeqCst);
            let _ = tx.send(());
        }
    })?;
    Ok(watcher)
}

/// Watch the folders of `files` (each once) with `watcher`; `watched` holds those watched.
fn watch_folders(
    watcher: &mut notify::RecommendedWatcher,
    files: &BTreeSet<PathBuf>,
    watched: &mut BTreeSet<PathBuf>,
) {
    for f in files {
        let Some(dir) = f.parent() else { continue };
        if watched.contains(dir) {
            continue;
        }
        match watcher.watch(dir, RecursiveMode::NonRecursive) {
            Ok(()) => {
                watched.insert(dir.to_path_buf());
            }
            Err(e) => eprintln!(
                "warning: cannot follow {}: {e}; a change there will not restart the render",
                dir.display()
            ),
        }
    }
}

/// The renderer's loop: load, render round by round until done or changed, wait for a change.
fn renderer(
    scene_path: &Path,
    state: &Mutex<State>,
    follow: &Follow,
    mut watcher: notify::RecommendedWatcher,
    changes: &Receiver<()>,
    pool: &rayon::ThreadPool,
) {
    let mut watched = BTreeSet::new();
    loop {
        follow.changed.store(false, Ordering::SeqCst);
        while changes.try_recv().is_ok() {}
        {
            let mut s = lock(state);
            s.generation += 1;
            s.status = Status::Loading;
        }
        match rtis::import::load_scene(scene_path) {
            Err(e) => {
                // Keep the last good image; follow the file the error is in as well, and
                // reload on any change in the folders followed.
                follow.broken.store(true, Ordering::SeqCst);
                let files = {
                    let mut files = follow.files.lock().unwrap_or_else(|e| e.into_inner());
                    files.insert(canonical(Path::new(&e.file)));
                    files.clone()
                };
                watch_folders(&mut watcher, &files, &mut watched);
                let mut s = lock(state);
                s.error = Some(e.to_string());
                s.status = Status::Error;
            }
            Ok(scene) => {
                follow.broken.store(false, Ordering::SeqCst);
                let mut files: BTreeSet<PathBuf> =
                    scene.files.iter().map(|f| canonical(f)).collect();
                files.insert(canonical(scene_path));
                // The watcher's thread runs the event handler, which takes this lock: it is
                // never held while the watcher is asked to follow a folder.
                *follow.files.lock().unwrap_or_else(|e| e.into_inner()) = files.clone();
                watch_folders(&mut watcher, &files, &mut watched);
                pool.install(|| render(&scene, state, follow));
            }
        }
        // Wait for a change (unless one came during the render), then let it settle.
        if !follow.changed.load(Ordering::SeqCst) && changes.recv().is_err() {
            return;
        }
        loop {
            match changes.recv_timeout(SETTLE) {
                Ok(()) => continue,
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => return,
            }
        }
    }
}

/// Render `scene` progressively into `state` until done or a change sets `follow.changed`.
fn render(scene: &rtis::scene::Scene, state: &Mutex<State>, follow: &Follow) {
    let film = scene.settings.film;
    if film.width as u64 * film.height as u64 > progressive::MAX_PIXELS {
        let mut s = lock(state);
        s.error = Some(format!(
            "{}: a film of {}x{} is too large to preview (watch renders progressively, at most \
             {} pixels): lower its width and height while you edit",
            scene.origin,
            film.width,
            film.height,
            progressive::MAX_PIXELS
        ));
        s.status = Status::Error;
        return;
    }
    let prepared = rtis::extract(scene);
    let est = estimate::estimate(&prepared);
    let threads = rayon::current_num_threads();
    {
        let mut s = lock(state);
        s.error = None;
        s.warnings = scene
            .warnings
            .iter()
            .chain(&prepared.warnings)
            .cloned()
            .collect();
        s.status = Status::Rendering;
        s.target_spp = prepared.film.spp;
        s.effects = prepared.effects.to_string();
        s.estimate = format!(
            "{:.3e} rays, about {} on {threads} threads",
            est.rays(),
            human_seconds(est.seconds(threads))
        );
    }
    let film = prepared.film;
    let mut on_round = |pass: &Pass, r: &Round| {
        let image = pass.image();
        let bytes = image
            .pixels
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let mut s = lock(state);
        s.version += 1;
        s.image = Some(Arc::new(Image {
            width: film.width,
            height: film.height,
            spp: r.held,
            bytes,
        }));
        s.rays = r.stats;
        s.seconds = r.seconds;
        // Under the same lock as the image, so the page never sees the last image as
        // "rendering".
        if pass.is_complete() {
            s.status = Status::Done;
        }
        true
    };
    // `on_round` marks the image done with its last round; a stop means a change.
    progressive::refine(
        &prepared,
        Pass::empty(&prepared),
        None,
        &|_| {},
        &follow.changed,
        &mut on_round,
    );
}

/// Whether a request's `Host` header names this server: its address and port, or
/// `localhost` with its port.
fn host_allowed(host: &str, bound: SocketAddr) -> bool {
    let port = bound.port().to_string();
    host == bound.to_string() || host.strip_prefix("localhost:").is_some_and(|p| p == port)
}

/// The response to one request.
fn answer(
    request: &tiny_http::Request,
    state: &Mutex<State>,
    bound: SocketAddr,
) -> tiny_http::Response<std::io::Cursor<Vec<u8>>> {
    let header = |k: &str, v: &str| {
        tiny_http::Header::from_bytes(k.as_bytes(), v.as_bytes()).expect("valid header")
    };
    let respond = |code: u16, kind: &str, body: Vec<u8>| {
        tiny_http::Response::from_data(body)
            .with_status_code(code)
            .with_header(header("Content-Type", kind))
            .with_header(header("Cache-Control", "no-store"))
    };
    if *request.method() != tiny_http::Method::Get {
        return respond(405, "text/plain", b"only GET\n".to_vec());
    }
    // A page on another site that a DNS trick points at this port names its own host: only
    // the address served on, or localhost, is answered.
    let host = request
        .headers()
        .iter()
        .find(|h| h.field.equiv("Host"))
        .map(|h| h.value.as_str().to_string());
    if !host.as_deref().is_some_and(|h| host_allowed(h, bound)) {
        return respond(403, "text/plain", b"unknown Host\n".to_vec());
    }
    let path = request.url().split('?').next().unwrap_or("");
    match path {
        "/" => respond(200, "text/html; charset=utf-8", PAGE.as_bytes().to_vec()),
        "/state" => {
            let s = lock(state);
            let json = serde_json::json!({
                "version": s.version,
                "generation": s.generation,
                "status": s.status,
                "error": s.error,
                "warnings": s.warnings,
                "spp": s.image.as_ref().map(|i| i.spp),
                "target_spp": s.target_spp,
                "width": s.image.as_ref().map(|i| i.width),
                "height": s.image.as_ref().map(|i| i.height),
                "estimate": s.estimate,
                "effects": s.effects,
                "rays": s.rays,
                "seconds": s.seconds,
            });
            respond(200, "application/json", json.to_string().into_bytes())
        }
        "/image" => {
            let (version, image) = {
                let s = lock(state);
                (s.version, s.image.clone())
            };
            match image {
                None => respond(404, "text/plain", b"no image yet\n".to_vec()),
                Some(i) => respond(200, "application/octet-stream", i.bytes.clone())
                    .with_header(header("X-Rtis-Version", &version.to_string()))
                    .with_header(header("X-Rtis-Width", &i.width.to_string()))
                    .with_header(header("X-Rtis-Height", &i.height.to_string()))
                    .with_header(header("X-Rtis-Spp", &i.spp.to_string())),
            }
        }
        _ => respond(404, "text/plain", b"not found\n".to_vec()),
    }
}

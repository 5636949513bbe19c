//! `rtis watch` (src/cli/watch.rs) over HTTP, without a browser (tests/browser/test_watch.py
//! drives its page in Chromium): the render refines, a saved change restarts it, a broken file
//! shows its located error and keeps the last image, a fixed one clears it; a change to a base
//! scene it extends restarts it too; only the page, `/state` and `/image` are served.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The watch process, killed when dropped.
struct Watch(Child);

impl Drop for Watch {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// GET `path` from `addr`: the status code, the headers and the body.
fn get(addr: &str, path: &str) -> (u16, String, Vec<u8>) {
    get_as(addr, path, addr)
}

/// GET `path` from `addr` with the `Host` header `host`.
fn get_as(addr: &str, path: &str, host: &str) -> (u16, String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    let code = head.split(' ').nth(1).unwrap().parse().unwrap();
    (code, head, raw[split + 4..].to_vec())
}

fn state(addr: &str) -> serde_json::Value {
    let (code, _, body) = get(addr, "/state");
    assert_eq!(code, 200);
    serde_json::from_slice(&body).unwrap()
}

/// Poll `/state` until `ok` holds (or fail after 60 s, showing the last state).
fn wait_until(
    addr: &str,
    what: &str,
    ok: impl Fn(&serde_json::Value) -> bool,
) -> serde_json::Value {
    let start = Instant::now();
    loop {
        let s = state(addr);
        if ok(&s) {
            return s;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "{what}: {s}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn write_scene(path: &Path, base: &Path, depth: u32) {
    // Written whole and renamed, as editors save.
    let tmp = path.with_extension("tmp");
    std::fs::write(
        &tmp,
        format!(
            "Scene(extends: {base:?}, film: (width: 32, height: 24, spp: 16),\n      \
             shader: Path(max_depth: {depth}))\n"
        ),
    )
    .unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

fn start(scene: &Path) -> (Watch, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtis"))
        .args(["watch", "--port", "0"])
        .arg(scene)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    // Keep reading, so that a later message never meets a closed pipe.
    std::thread::spawn(move || std::io::copy(&mut err, &mut std::io::sink()));
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|r| r.split('/').next())
        .unwrap_or_else(|| panic!("no URL in {line:?}"))
        .to_string();
    (Watch(child), addr)
}

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtis-watch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn watch_follows_the_scene_and_its_base() {
    let d = folder("follow");
    // A base in the folder, extending the repository's box, so that its change is seen.
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let base = d.join("base.ron");
    std::fs::write(&base, format!("Scene(extends: {cornell:?})\n")).unwrap();
    let scene = d.join("scene.ron");
    write_scene(&scene, &base, 3);
    let (_watch, addr) = start(&scene);
    assert!(addr.starts_with("127.0.0.1:"), "{addr}");

    // The render completes, round by round, to the scene's spp.
    let done = wait_until(&addr, "first render", |s| s["status"] == "done");
    assert_eq!(
        (done["spp"].as_u64(), done["target_spp"].as_u64()),
        (Some(16), Some(16))
    );
    assert_eq!(
        done["version"].as_u64(),
        Some(5),
        "rounds of 1, 1, 2, 4, 8 spp: {done}"
    );
    assert!(done["estimate"].as_str().unwrap().contains("rays"));
    assert!(done["effects"].as_str().unwrap().contains("shadows"));
    assert!(done["rays"]["camera"].as_u64().unwrap() == 32 * 24 * 16);
    let (code, head, first) = get(&addr, "/image");
    assert_eq!(code, 200);
    assert!(head.contains("X-Rtis-Spp: 16"), "{head}");
    assert_eq!(first.len(), 32 * 24 * 3 * 4);

    // A saved change restarts the render: a new generation, and a new image.
    let generation = done["generation"].as_u64().unwrap();
    write_scene(&scene, &base, 1);
    let again = wait_until(&addr, "restart", |s| {
        s["generation"].as_u64().unwrap() > generation && s["status"] == "done"
    });
    let (_, _, second) = get(&addr, "/image");
    assert_ne!(first, second, "depth 1 and depth 3 give other images");

    // A broken file: its located error, and the last image stays.
    std::fs::write(&scene, "Scene(film: (width: 32, height: -4))\n").unwrap();
    let broken = wait_until(&addr, "error", |s| s["status"] == "error");
    let message = broken["error"].as_str().unwrap();
    assert!(
        message.contains("scene.ron:1:") && message.contains("height"),
        "{message}"
    );
    let (code, _, kept) = get(&addr, "/image");
    assert_eq!((code, &kept), (200, &second));
    assert_eq!(broken["version"], again["version"]);

    // Fixed: the error goes and the render runs again.
    write_scene(&scene, &base, 3);
    let fixed = wait_until(&addr, "fixed", |s| {
        s["status"] == "done" && s["error"].is_null()
    });
    assert!(fixed["version"].as_u64() > again["version"].as_u64());
    let (_, _, third) = get(&addr, "/image");
    assert_eq!(third, first, "the same scene and seed give the same bits");

    // A change to the base it extends restarts it too.
    let generation = fixed["generation"].as_u64().unwrap();
    std::fs::write(&base, format!("Scene(extends: {cornell:?}, seed: 9)\n")).unwrap();
    wait_until(&addr, "base changed", |s| {
        s["generation"].as_u64().unwrap() > generation && s["status"] == "done"
    });
    let (_, _, fourth) = get(&addr, "/image");
    assert_ne!(fourth, first, "another seed");

    // Another host name (a DNS-rebinding page) is refused; localhost is answered.
    let port = addr.split(':').nth(1).unwrap();
    assert_eq!(get_as(&addr, "/state", "evil.example:80").0, 403);
    assert_eq!(get_as(&addr, "/state", &format!("localhost:{port}")).0, 200);

    // Nothing but the page and its two requests is served.
    let (code, head, page) = get(&addr, "/");
    assert_eq!(code, 200);
    assert!(head.contains("text/html"));
    assert!(String::from_utf8_lossy(&page).contains("rtis watch"));
    for path in [
        "/scene.ron",
        "/../scene.ron",
        "/%2e%2e/scene.ron",
        "/base.ron",
        "/etc/passwd",
    ] {
        assert_eq!(get(&addr, path).0, 404, "{path}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A port already taken is refused with a clear message and a non-zero exit.
#[test]
fn a_taken_port_is_refused() {
    let d = folder("port");
    let scene = d.join("scene.ron");
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    write_scene(&scene, &cornell, 1);
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = Command::new(env!("CARGO_BIN_EXE_rtis"))
        .args(["watch", "--port", &port])
        .arg(&scene)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot serve on 127.0.0.1:") && err.contains("--port"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

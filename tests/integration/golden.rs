//! Golden images: every scene in `scenes/` is its own test, rendered at 120 pixels wide. The
//! insta snapshot `snapshots/NAME.snap` holds a hash of the 8-bit image, the channel means and
//! a luminance grid (relative to the brightest cell, so a change shows wherever it is), and
//! names the images beside it:
//!
//! - `NAME.png`: the accepted image. It changes only when its snapshot is accepted.
//! - `NAME.new.png`, `NAME.diff.png`: written when the render no longer matches the accepted
//!   snapshot: the new image, and the FLIP heatmap of new against accepted.
//!
//! After `cargo insta accept` (or `review`), the next test run finds the render matching the
//! snapshot again: it promotes `NAME.new.png` to `NAME.png` and removes the diff. After a
//! rejection and a revert, the next run removes the stale new and diff images.

use crate::common::{render_scene, scenes_dir};
use image::RgbImage;
use rtis::converge::metrics::{flip_rgb8, fnv1a};
use rtis::render::output::to_rgb8;
use rtis::scene::load_path;
use rtis::shader::Shader;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Width of the golden renders; the height keeps the scene's aspect ratio.
const WIDTH: u32 = 120;
/// Grid of the luminance summary.
const GRID: (u32, u32) = (8, 6);

/// What a snapshot records of one golden render.
#[derive(Serialize)]
struct Golden {
    scene: String,
    size: (u32, u32),
    spp: u32,
    shader: String,
    /// FNV-1a 64 of the 8-bit sRGB pixels.
    hash: String,
    mean_rgb: [f32; 3],
    /// Mean luminance of the brightest grid cell.
    luminance_max: f32,
    /// Mean luminance per cell in thousandths of `luminance_max` (0-1000), one row per string.
    luminance: Vec<String>,
    /// The images beside the snapshot, for the reviewer.
    images: String,
}

/// The shader's name and its main parameters, as the snapshot shows them.
fn describe(shader: &Shader) -> String {
    match shader {
        Shader::Global(g) => format!("Global(samples: {}, max_depth: {})", g.samples, g.max_depth),
        Shader::Path(p) => format!(
            "Path {{ max_depth: {:?}, rr_depth: {}, sampling: {:?}, lights: {:?} }}",
            p.max_depth, p.rr_depth, p.sampling, p.lights
        ),
        s => format!("{s:?}"),
    }
}

fn round4(v: f32) -> f32 {
    (v * 1e4).round() / 1e4
}

/// Render the scene at `path` as the golden test does: its 8-bit image and its summary.
fn render_golden(path: &Path) -> (RgbImage, Golden) {
    let name = path.file_stem().unwrap().to_string_lossy().into_owned();
    let mut scene = load_path(path).unwrap_or_else(|e| panic!("{e}"));
    let film = &mut scene.settings.film;
    film.height = (WIDTH as f64 * film.height as f64 / film.width as f64).round() as u32;
    film.width = WIDTH;
    film.spp = film.spp.min(4);
    let r = render_scene(&scene);
    let rgb8 = to_rgb8(&r.image, scene.settings.film.transfer);
    let (w, h) = (r.image.width, r.image.height);
    let cells: Vec<Vec<f32>> = (0..GRID.1)
        .map(|gy| {
            (0..GRID.0)
                .map(|gx| {
                    let (x0, x1) = (gx * w / GRID.0, (gx + 1) * w / GRID.0);
                    let (y0, y1) = (gy * h / GRID.1, (gy + 1) * h / GRID.1);
                    let mut sum = 0.0;
                    for y in y0..y1 {
                        for x in x0..x1 {
                            let p = r.image.get(x, y);
                            sum += 0.2126 * p.x + 0.7152 * p.y + 0.0722 * p.z;
                        }
                    }
                    sum / ((x1 - x0) * (y1 - y0)) as f32
                })
                .collect()
        })
        .collect();
    let max = cells.iter().flatten().fold(0.0f32, |m, &l| m.max(l));
    let luminance = cells
        .iter()
        .map(|row| {
            row.iter()
                .map(|l| format!("{:4}", (1000.0 * l / max.max(1e-12)).round() as i64))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect();
    let mean = r.image.mean();
    let golden = Golden {
        scene: format!("{name}.ron"),
        size: (w, h),
        spp: scene.settings.film.spp,
        shader: describe(&scene.settings.shader),
        hash: format!("{:016x}", fnv1a(rgb8.as_raw())),
        mean_rgb: [round4(mean.x), round4(mean.y), round4(mean.z)],
        luminance_max: round4(max),
        luminance,
        images: format!(
            "snapshots/{name}.png is the accepted image; on a change, {name}.new.png (new) and \
             {name}.diff.png (FLIP heatmap, new against accepted) are beside it"
        ),
    };
    (rgb8, golden)
}

/// The hash recorded in the accepted snapshot `NAME.snap`, if there is one.
fn accepted_hash(snap_dir: &Path, name: &str) -> Option<String> {
    let text = std::fs::read_to_string(snap_dir.join(format!("{name}.snap"))).ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix("hash: "))
        .map(str::to_string)
}

fn png_bytes(img: &RgbImage) -> Vec<u8> {
    let mut v = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut v), image::ImageFormat::Png)
        .unwrap();
    v
}

/// The images of one golden scene, following insta's flow (see the module documentation).
/// Returns whether the render matches the accepted snapshot.
fn update_images(snap_dir: &Path, name: &str, rgb8: &RgbImage, hash: &str) -> bool {
    let path = |suffix: &str| snap_dir.join(format!("{name}{suffix}"));
    let (accepted, new, diff) = (path(".png"), path(".new.png"), path(".diff.png"));
    let encoded = png_bytes(rgb8);
    let matches = accepted_hash(snap_dir, name).as_deref() == Some(hash);
    if matches {
        // Accepted (or never changed): the accepted image is this render.
        if std::fs::read(&accepted).ok().as_deref() != Some(encoded.as_slice()) {
            std::fs::write(&accepted, &encoded).unwrap();
        }
        let _ = std::fs::remove_file(&new);
        let _ = std::fs::remove_file(&diff);
    } else {
        std::fs::write(&new, &encoded).unwrap();
        match image::open(&accepted).map(|i| i.to_rgb8()) {
            Ok(old) if old.dimensions() == rgb8.dimensions() => {
                let f = flip_rgb8(rgb8, &old);
                std::fs::write(&diff, png_bytes(&f.heatmap)).unwrap();
            }
            _ => {
                let _ = std::fs::remove_file(&diff);
            }
        }
    }
    matches
}

/// The golden test of one scene: render, images, snapshot. Mutation runs set
/// `RTIS_SKIP_GOLDEN=1` to measure what the other tests catch without the image hashes
/// (docs/testing.md).
fn golden(scene_file: &str) {
    if std::env::var_os("RTIS_SKIP_GOLDEN").is_some() {
        return;
    }
    let path = scenes_dir().join(scene_file);
    let name = path.file_stem().unwrap().to_string_lossy().into_owned();
    let snap_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots");
    let (rgb8, golden) = render_golden(&path);
    update_images(&snap_dir, &name, &rgb8, &golden.hash);
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path(&snap_dir);
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| insta::assert_yaml_snapshot!(name, golden));
}

/// One `#[test]` per scene file, so that plain `cargo test` lists every scene that changed.
macro_rules! golden_tests {
    ($($test:ident => $file:literal),* $(,)?) => {
        $(
            #[test]
            fn $test() {
                golden($file);
            }
        )*
        /// Every scene in `scenes/` has its golden test above.
        const GOLDEN_FILES: &[&str] = &[$($file),*];
    };
}

golden_tests! {
    cornell => "cornell.ron",
    cornell_ambient => "cornell-ambient.ron",
    cornell_area => "cornell-area.ron",
    cornell_direct => "cornell-direct.ron",
    cornell_lens => "cornell-lens.ron",
    cornell_n_bounce => "cornell-n-bounce.ron",
    cornell_physical => "cornell-physical.ron",
    checkerboard => "checkerboard.ron",
    cornell_two_bounce => "cornell-two-bounce.ron",
    materials => "materials.ron",
    materials_beckmann => "materials-beckmann.ron",
    mesh => "mesh.ron",
    mis => "mis.ron",
    outdoor => "outdoor.ron",
    mitsuba_cornell => "mitsuba-cornell.ron",
    spheres => "spheres.ron",
    triangles => "triangles.ron",
}

#[test]
fn every_scene_has_a_golden_test() {
    let mut files: Vec<String> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut listed: Vec<&str> = GOLDEN_FILES.to_vec();
    listed.sort();
    assert_eq!(
        files, listed,
        "add the new scene to golden_tests! in tests/integration/golden.rs"
    );
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dir(&p, &dest);
        } else {
            std::fs::copy(&p, dest).unwrap();
        }
    }
}

/// The review flow as a user meets it, in a temporary copy: change the red wall of the
/// course's box, run the golden check: the new and diff images appear and the accepted image
/// is untouched; accept (the snapshot takes the new hash): the next run promotes the new image
/// and removes the diff; change back without accepting: the next run cleans up.
#[test]
fn review_flow_keeps_the_accepted_image_until_accepted() {
    let root = std::env::temp_dir().join(format!("rtis-golden-flow-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let (scenes, snaps): (PathBuf, PathBuf) = (root.join("scenes"), root.join("snapshots"));
    copy_dir(&scenes_dir(), &scenes);
    std::fs::create_dir_all(&snaps).unwrap();
    let real = Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots");
    let name = "cornell-direct";
    for f in [".snap", ".png"] {
        std::fs::copy(
            real.join(format!("{name}{f}")),
            snaps.join(format!("{name}{f}")),
        )
        .unwrap();
    }
    let accepted_png = std::fs::read(snaps.join(format!("{name}.png"))).unwrap();
    let exists = |suffix: &str| snaps.join(format!("{name}{suffix}")).exists();

    // Unchanged: nothing new.
    let (img, g) = render_golden(&scenes.join(format!("{name}.ron")));
    assert!(update_images(&snaps, name, &img, &g.hash));
    assert!(!exists(".new.png") && !exists(".diff.png"));

    // Change the red wall (in cornell.ron, which cornell-direct.ron extends).
    let box_file = scenes.join("cornell.ron");
    let original = std::fs::read_to_string(&box_file).unwrap();
    let changed = original.replace(
        "\"red wall\":   Phong(kd: (0.7, 0.2, 0.3)",
        "\"red wall\":   Phong(kd: (0.2, 0.2, 0.7)",
    );
    assert_ne!(
        original, changed,
        "the red wall is where the test expects it"
    );
    std::fs::write(&box_file, &changed).unwrap();
    let (img2, g2) = render_golden(&scenes.join(format!("{name}.ron")));
    assert_ne!(g.hash, g2.hash);
    assert!(!update_images(&snaps, name, &img2, &g2.hash));
    assert!(exists(".new.png") && exists(".diff.png"));
    assert_eq!(
        std::fs::read(snaps.join(format!("{name}.png"))).unwrap(),
        accepted_png
    );
    // The heatmap is black away from the change and lit on the red wall (left of the image).
    let diff = image::open(snaps.join(format!("{name}.diff.png")))
        .unwrap()
        .to_rgb8();
    let lit = |x: u32, y: u32| {
        diff.get_pixel(x, y)
            .0
            .iter()
            .map(|&c| c as u32)
            .sum::<u32>()
    };
    assert!(
        lit(3, 48) > lit(60, 48),
        "{} vs {}",
        lit(3, 48),
        lit(60, 48)
    );

    // Reject and revert: the next run cleans up, the accepted image never changed.
    std::fs::write(&box_file, &original).unwrap();
    assert!(update_images(&snaps, name, &img, &g.hash));
    assert!(!exists(".new.png") && !exists(".diff.png"));
    assert_eq!(
        std::fs::read(snaps.join(format!("{name}.png"))).unwrap(),
        accepted_png
    );

    // Change again and accept: the snapshot takes the new hash, as `cargo insta accept` does.
    std::fs::write(&box_file, &changed).unwrap();
    assert!(!update_images(&snaps, name, &img2, &g2.hash));
    let snap = snaps.join(format!("{name}.snap"));
    let text = std::fs::read_to_string(&snap).unwrap();
    std::fs::write(&snap, text.replace(&g.hash, &g2.hash)).unwrap();
    assert!(update_images(&snaps, name, &img2, &g2.hash));
    assert!(!exists(".new.png") && !exists(".diff.png"));
    assert_eq!(
        std::fs::read(snaps.join(format!("{name}.png"))).unwrap(),
        png_bytes(&img2)
    );
    std::fs::remove_dir_all(&root).unwrap();
}

//! Golden images: every scene in `scenes/` renders at a reduced size; the insta snapshot holds
//! a hash of the 8-bit image, per-channel means and a coarse luminance grid, so
//! `cargo insta review` shows where an image changed. The PNG behind each snapshot is kept in
//! `snapshots/` for a person to look at (rewritten when it changes).

mod common;

use common::{render_scene, scenes_dir};
use rtis::render::output::to_rgb8;
use rtis::scene::load_path;
use rtis::shader::Shader;
use serde::Serialize;
use std::path::Path;

/// Width of the golden renders; the height keeps the scene's aspect ratio.
const WIDTH: u32 = 120;
/// Grid of the luminance summary.
const GRID: (u32, u32) = (8, 6);

#[derive(Serialize)]
struct Golden {
    scene: String,
    size: (u32, u32),
    spp: u32,
    shader: String,
    /// FNV-1a 64 of the 8-bit sRGB pixels.
    hash: String,
    mean_rgb: [f32; 3],
    /// Mean luminance per cell, in percent (0-99), one row of cells per string.
    luminance: Vec<String>,
}

/// The shader's name and its main parameters, as the snapshot shows them.
fn describe(shader: &Shader) -> String {
    match shader {
        Shader::Global(g) => format!("Global(samples: {}, max_depth: {})", g.samples, g.max_depth),
        Shader::Path(p) => format!(
            "Path {{ max_depth: {:?}, rr_depth: {}, sampling: {:?} }}",
            p.max_depth, p.rr_depth, p.sampling
        ),
        s => format!("{s:?}"),
    }
}

fn round4(v: f32) -> f32 {
    (v * 1e4).round() / 1e4
}

#[test]
fn golden_scenes() {
    let mut names: Vec<_> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    names.sort();
    assert!(names.len() >= 7, "scenes/ holds the course's scenes");
    let snap_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots");
    for path in names {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let mut scene = load_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let film = &mut scene.settings.film;
        film.height = (WIDTH as f64 * film.height as f64 / film.width as f64).round() as u32;
        film.width = WIDTH;
        film.spp = film.spp.min(4);
        let r = render_scene(&scene);
        assert!(r.image.all_finite(), "{name}: NaN or Inf");
        let rgb8 = to_rgb8(&r.image, scene.settings.film.transfer);
        let (w, h) = (r.image.width, r.image.height);
        let luminance = (0..GRID.1)
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
                        let l = sum / ((x1 - x0) * (y1 - y0)) as f32;
                        format!("{:2}", ((l * 100.0).round() as i64).clamp(0, 99))
                    })
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
            hash: format!("{:016x}", rtis::converge::metrics::fnv1a(rgb8.as_raw())),
            mean_rgb: [round4(mean.x), round4(mean.y), round4(mean.z)],
            luminance,
        };
        // Keep the picture beside the snapshot, rewritten only when it changes.
        let png = snap_dir.join(format!("{name}.png"));
        let mut encoded = std::io::Cursor::new(Vec::new());
        rgb8.write_to(&mut encoded, image::ImageFormat::Png)
            .unwrap();
        if std::fs::read(&png).ok().as_deref() != Some(encoded.get_ref().as_slice()) {
            std::fs::write(&png, encoded.get_ref()).unwrap();
        }
        let mut settings = insta::Settings::clone_current();
        settings.set_snapshot_path(&snap_dir);
        settings.set_prepend_module_to_snapshot(false);
        settings.bind(|| insta::assert_yaml_snapshot!(name, golden));
    }
}

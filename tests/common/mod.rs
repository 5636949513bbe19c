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
/// as NaN, infinite or negative, and that every pixel is finite and non-negative.
pub fn render_scene(s: &Scene) -> Rendered {
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

/// Relative closeness of two colours.
pub fn close(a: Vec3A, b: Vec3A, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * b.abs().max_element().max(1e-6)
}

//! README.md cannot drift: every measured figure sits in a block that
//! `bench/readme_figures.py` regenerates and stamps with the machine, date and commit; this
//! checks that every block is there with its stamp, and that the README's two commands are the
//! ones the project promises.

use crate::common;

use std::process::Command;

#[test]
fn readme_figure_blocks_are_generated() {
    let root = env!("CARGO_MANIFEST_DIR");
    let o = Command::new("python3")
        .args(["bench/readme_figures.py", "--check"])
        .current_dir(root)
        .output()
        .expect("python3 runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn readme_keeps_its_two_commands() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    assert!(
        text.contains("cargo run --release -- render "),
        "the render command"
    );
    assert!(text.contains("\ncargo test --release "), "the test command");
    let ci = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/.ci/run")).unwrap();
    assert!(
        ci.contains("\ncargo test --release\n"),
        ".ci/run runs the README's test command"
    );
}

/// The README's example of a located error is what rtis prints for tests/data/broken.ron.
#[test]
fn readme_error_example_is_real() {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let start = text
        .find("error: tests/data/broken.ron")
        .expect("the example");
    let example = &text[start..start + text[start..].find("```").unwrap()];
    let o = common::output_within(
        Command::new(env!("CARGO_BIN_EXE_rtis"))
            .args(["check", "tests/data/broken.ron"])
            .current_dir(root),
        120,
    );
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim_end(),
        example.trim_end()
    );
}

/// The README's first scene loads as written, and renders without a dropped sample.
#[test]
fn readme_first_scene_loads() {
    let readme = std::fs::read_to_string("README.md").unwrap();
    let section = &readme[readme
        .find("### Your first scene")
        .expect("the walk-through")..];
    let start = section.find("```ron\n").expect("its scene") + "```ron\n".len();
    let end = start + section[start..].find("```").unwrap();
    let mut scene = rtis::scene::load_str(&section[start..end], "first.ron", None)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    scene.settings.film.width = 32;
    scene.settings.film.height = 24;
    scene.settings.film.spp = 2;
    let r = rtis::render::render(&rtis::extract(&scene), &|| {});
    assert_eq!(r.stats.dropped, 0);
}

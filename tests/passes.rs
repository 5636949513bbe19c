//! Passes and merging (src/render/pass.rs, src/render/exact.rs, `rtis merge`): passes merged
//! in any number and order give the bits of one render; parts that do not belong together, or
//! do not hold every sample exactly once, are refused with a message that names them.

mod common;

use common::scene;
use rtis::render::pass::{Pass, pass_range};
use rtis::render::{render, render_pass};
use std::process::Command;
use std::sync::atomic::AtomicBool;

fn small_box(spp: u32) -> rtis::RenderScene {
    let s = scene(&format!(
        "Scene(extends: \"cornell.ron\", film: (width: 40, height: 32, spp: {spp}))"
    ));
    rtis::extract(&s)
}

fn passes(s: &rtis::RenderScene, n: u32) -> Vec<(String, Pass)> {
    (0..n)
        .map(|i| {
            let r = pass_range(i, n, s.film.spp).unwrap();
            let sums = render_pass(s, r.clone(), &|| {}, &AtomicBool::new(false));
            (format!("pass{i}"), Pass::from_render(s, r, sums.pixels))
        })
        .collect()
}

fn bits(img: &rtis::render::film::Image) -> Vec<[u32; 3]> {
    img.pixels
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// 1, 2, 3 and 7 passes, merged in reverse order, give the bits of one render.
#[test]
fn merged_passes_equal_one_render_bit_for_bit() {
    let s = small_box(14);
    let single = bits(&render(&s, &|| {}).image);
    for n in [1, 2, 3, 7] {
        let mut parts = passes(&s, n);
        parts.reverse();
        let merged = Pass::merge(parts).unwrap();
        assert!(merged.is_complete());
        assert_eq!(bits(&merged.image()), single, "{n} passes");
    }
}

/// Pass ranges tile the samples: contiguous, in order, none empty while n <= spp.
#[test]
fn pass_ranges_tile_the_samples() {
    for spp in [1, 2, 7, 14, 1000] {
        for n in 1..=spp.min(20) {
            let rs: Vec<_> = (0..n).map(|i| pass_range(i, n, spp).unwrap()).collect();
            assert_eq!(rs[0].start, 0);
            assert_eq!(rs[n as usize - 1].end, spp);
            assert!(rs.windows(2).all(|w| w[0].end == w[1].start));
            assert!(rs.iter().all(|r| !r.is_empty()));
        }
    }
    assert!(pass_range(0, 5, 4).is_err());
}

#[test]
fn merge_refuses_gaps_overlaps_and_strangers() {
    let s = small_box(6);
    let p = passes(&s, 3);
    // A gap: pass 1 of 3 missing.
    let m = Pass::merge(vec![p[0].clone(), p[2].clone()]).unwrap();
    assert!(!m.is_complete());
    assert_eq!(m.missing(), vec![2..4]);
    // An overlap names both files.
    let e = Pass::merge(vec![
        p[0].clone(),
        p[1].clone(),
        ("again".into(), p[1].1.clone()),
    ])
    .unwrap_err();
    assert!(
        e.contains("samples 2..4 are in both pass1 and again"),
        "{e}"
    );
    // Another seed, another scene.
    let mut other = p[1].clone();
    other.1.seed += 1;
    let e = Pass::merge(vec![p[0].clone(), other]).unwrap_err();
    assert!(e.contains("different renders: seeds"), "{e}");
    let t = small_box(6);
    let mut moved = t.clone();
    moved.lights.pop();
    let q = passes(&moved, 3);
    let e = Pass::merge(vec![p[0].clone(), q[1].clone()]).unwrap_err();
    assert!(e.contains("different renders: scene fingerprints"), "{e}");
}

/// Through the command line: three pass files merged equal the plain render's EXR bytes; a
/// missing pass and an overlap are located errors with a non-zero exit.
#[test]
fn cli_passes_and_merge() {
    let d = std::env::temp_dir().join(format!("rtis-passes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let rtis = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_rtis"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap()
    };
    let p = |n: &str| d.join(n).to_str().unwrap().to_string();
    let size = ["--width", "40", "--height", "32", "--spp", "5"];
    let o = rtis(
        &[
            &["render", "scenes/cornell.ron", "-o", &p("single.exr")][..],
            &size,
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for i in 0..3 {
        let pass = format!("{i}/3");
        let out = p(&format!("p{i}.exr"));
        let o = rtis(
            &[
                &["render", "scenes/cornell.ron", "--pass", &pass, "-o", &out][..],
                &size,
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = rtis(&[
        "merge",
        &p("p2.exr"),
        &p("p0.exr"),
        &p("p1.exr"),
        "-o",
        &p("merged.exr"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(p("merged.exr")).unwrap(),
        std::fs::read(p("single.exr")).unwrap()
    );
    let o = rtis(&["merge", &p("p0.exr"), &p("p2.exr"), "-o", &p("m.png")]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("samples 1..3 of 5 spp are in no part"), "{e}");
    let o = rtis(&[
        "merge",
        &p("p0.exr"),
        &p("p0.exr"),
        &p("p1.exr"),
        &p("p2.exr"),
        "-o",
        &p("m.png"),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("are in both"), "{e}");
    let o = rtis(&["merge", &p("single.exr"), "-o", &p("m.png")]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("not an rtis pass"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

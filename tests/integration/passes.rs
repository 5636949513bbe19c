//! Passes and merging (src/render/pass.rs, src/render/exact.rs, `rtis merge`): passes merged
//! in any number and order give the bits of one render; parts that do not belong together, or
//! do not hold every sample exactly once, are refused with a message that names them.

use crate::common;

use crate::common::{bits, scene};
use rtis::render::pass::{Pass, pass_range};
use rtis::render::{render, render_pass};
use rtis::sampling::SamplerKind;
use std::process::Command;
use std::sync::atomic::AtomicBool;

fn small_box(spp: u32) -> rtis::RenderScene {
    let s = scene(&format!(
        "Scene(extends: \"cornell.ron\", film: (width: 40, height: 32, spp: {spp}))"
    ));
    rtis::extract(&s)
}

/// The `n` passes of `s`, each rendered under a time limit ([`common::deadline`]): a range bug
/// fails the test rather than hanging it.
fn passes(s: &rtis::RenderScene, n: u32) -> Vec<(String, Pass)> {
    let _limit = common::deadline(120);
    (0..n)
        .map(|i| {
            let r = pass_range(i, n, s.film.spp).unwrap();
            let sums = render_pass(s, r.clone(), &|| {}, &AtomicBool::new(false));
            (format!("pass{i}"), Pass::from_render(s, r, sums.pixels))
        })
        .collect()
}

/// 1, 2, 3 and 7 passes, merged in reverse order, give the bits of one render, with either
/// sampler (a Sobol' point depends on its sample's index, not on the pass that draws it).
#[test]
fn merged_passes_equal_one_render_bit_for_bit() {
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        let mut s = small_box(14);
        s.film.sampler = sampler;
        let single = bits(&render(&s, &|| {}).image);
        for n in [1, 2, 3, 7] {
            let mut parts = passes(&s, n);
            parts.reverse();
            let merged = Pass::merge(parts).unwrap();
            assert!(merged.is_complete());
            assert_eq!(bits(&merged.image()), single, "{sampler:?}, {n} passes");
        }
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
    // Another sampler: the same scene drawing Sobol' points.
    let mut sobol = t.clone();
    sobol.film.sampler = SamplerKind::Sobol;
    let q = passes(&sobol, 3);
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
        common::output_within(
            Command::new(env!("CARGO_BIN_EXE_rtis"))
                .args(args)
                .current_dir(env!("CARGO_MANIFEST_DIR")),
            120,
        )
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

/// The R, G and B channels of a pass file: the preview a person looks at.
fn preview_channels(path: &std::path::Path) -> Vec<[u32; 3]> {
    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap();
    let channel = |name: &str| -> Vec<f32> {
        let ch = image
            .layer_data
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no channel {name}"));
        match &ch.sample_data {
            FlatSamples::F32(v) => v.clone(),
            other => panic!("channel {name} is not f32: {other:?}"),
        }
    };
    let (r, g, b) = (channel("R"), channel("G"), channel("B"));
    (0..r.len())
        .map(|i| [r[i].to_bits(), g[i].to_bits(), b[i].to_bits()])
        .collect()
}

/// Partial merges, adjacent or not: for every non-empty subset of four passes (of 7 spp, so the
/// passes hold 1, 2, 2 and 2 samples), the merged preview, in memory and in the file it writes,
/// is each pixel's mean over exactly the samples it holds: their exact sum, rendered here one
/// sample at a time, divided by their count. A mean over the render's spp, or over the passes'
/// count, or over the last range alone, fails it.
#[test]
fn partial_merges_preview_the_mean_of_exactly_their_samples() {
    let _limit = common::deadline(120);
    let s = rtis::extract(&scene(
        "Scene(extends: \"cornell.ron\", film: (width: 9, height: 7, spp: 7),
               shader: Path(max_depth: 3))",
    ));
    let parts = passes(&s, 4);
    let d = std::env::temp_dir().join(format!("rtis-partial-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for subset in 1u32..16 {
        let chosen: Vec<(String, Pass)> = (0..4)
            .filter(|i| subset & (1 << i) != 0)
            .map(|i| parts[i].clone())
            .collect();
        let held: Vec<u32> = (0..4u32)
            .filter(|i| subset & (1 << i) != 0)
            .flat_map(|i| pass_range(i, 4, 7).unwrap())
            .collect();
        let merged = Pass::merge(chosen).unwrap();
        assert_eq!(merged.samples(), held.len() as u64, "subset {subset:04b}");
        // Each pixel's samples, rendered one at a time and summed exactly.
        let mut want = Vec::new();
        for row in 0..s.film.height {
            for col in 0..s.film.width {
                let mut sum = rtis::render::exact::RgbSum::default();
                let mut stats = rtis::stats::RayStats::default();
                for &k in &held {
                    sum += rtis::render::render_sample(&s, col, row, k, &mut stats);
                }
                let m = sum.mean(held.len() as u64);
                want.push([m.x.to_bits(), m.y.to_bits(), m.z.to_bits()]);
            }
        }
        assert_eq!(bits(&merged.image()), want, "subset {subset:04b}");
        let file = d.join(format!("partial-{subset}.exr"));
        merged.write(&file).unwrap();
        assert_eq!(preview_channels(&file), want, "subset {subset:04b}: file");
        // The file read back holds the same samples and gives the same preview.
        let back = Pass::read(&file).unwrap();
        assert_eq!(back.ranges, merged.ranges);
        assert_eq!(bits(&back.image()), want, "subset {subset:04b}: read back");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A pass whose range runs past the render's samples is refused with its figures, at once
/// (before the check, such an index sent the pixel-sample permutation into an endless loop).
#[test]
#[should_panic(expected = "samples 4..8 of a render of 7 spp")]
fn a_range_past_the_samples_is_refused() {
    let _limit = common::deadline(60);
    let s = small_box(7);
    render_pass(&s, 4..8, &|| {}, &AtomicBool::new(false));
}

/// One sample past the end, asked of a single pixel, is refused by the pixel sampler.
#[test]
#[should_panic(expected = "sample index 7 is out of range: a pixel has the samples 0..7")]
fn a_sample_index_past_the_end_is_refused() {
    let _limit = common::deadline(60);
    let s = small_box(7);
    let mut stats = rtis::stats::RayStats::default();
    rtis::render::render_sample(&s, 3, 3, 7, &mut stats);
}

/// A pass file whose header names an empty sample range is refused on reading (a range holds
/// at least one sample), as is one past the spp, and ranges out of order or overlapping (which
/// would count samples twice).
#[test]
fn pass_files_with_empty_or_outlying_ranges_are_refused() {
    let _limit = common::deadline(60);
    let s = small_box(6);
    let d = std::env::temp_dir().join(format!("rtis-ranges-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let (_, good) = passes(&s, 3).remove(0);
    for (name, ranges) in [
        ("empty", vec![0..2, 4..4]),
        ("outlying", vec![0..2, 5..7]),
        ("unsorted", vec![4..6, 0..2]),
        ("overlapping", vec![0..4, 2..6]),
    ] {
        let bad = Pass {
            ranges,
            ..good.clone()
        };
        let file = d.join(format!("{name}.exr"));
        bad.write(&file).unwrap();
        let e = Pass::read(&file).unwrap_err();
        assert!(
            e.contains("not a sorted list of disjoint sample ranges within spp"),
            "{name}: {e}"
        );
    }
    let file = d.join("good.exr");
    good.write(&file).unwrap();
    assert_eq!(Pass::read(&file).unwrap().ranges, good.ranges);
    std::fs::remove_dir_all(&d).unwrap();
}

//! Progressive rendering (src/render/progressive.rs): rounds of doubling spp over the whole
//! frame, each a valid render at fewer samples; the last has the bits of a one-go render, and a
//! render stopped after any round and resumed from its pass file ends with the same bits.

use crate::common;

use crate::common::{bits, scene};
use rtis::render::pass::Pass;
use rtis::render::progressive::{Ending, check_resumable, next_round, refine};
use rtis::render::render;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

fn small_box(spp: u32, seed: u64) -> rtis::RenderScene {
    rtis::extract(&scene(&format!(
        "Scene(extends: \"cornell.ron\", film: (width: 24, height: 20, spp: {spp}), seed: {seed},
               shader: Path(max_depth: 3))"
    )))
}

/// The rounds of 14 spp hold 1, 2, 4, 8 and 14 samples, each a prefix of the sample indices;
/// the image after the last has the bits of one render, and after each round it is each
/// pixel's mean over exactly the samples held.
#[test]
fn rounds_double_and_end_with_the_bits_of_one_render() {
    let _limit = common::deadline(120);
    let s = small_box(14, 7);
    let one_go = bits(&render(&s, &|| {}).image);
    let mut held = Vec::new();
    let mut previews = Vec::new();
    let p = refine(
        &s,
        Pass::empty(&s),
        None,
        &|_| {},
        &AtomicBool::new(false),
        &mut |pass, round| {
            assert_eq!(pass.ranges, vec![0..round.held as u32]);
            held.push(round.held);
            previews.push(pass.clone());
            true
        },
    );
    assert!(p.ending.is_complete());
    assert_eq!(held, vec![1, 2, 4, 8, 14]);
    assert_eq!(p.rounds, 5);
    assert_eq!(bits(&p.pass.image()), one_go);
    // After round 3 (4 spp) the preview is the mean of samples 0..4, as a pass of them gives.
    let sums = rtis::render::render_pass(&s, 0..4, &|| {}, &AtomicBool::new(false));
    let want = Pass::from_render(&s, 0..4, sums.pixels);
    assert_eq!(bits(&previews[2].image()), bits(&want.image()));
}

/// Stopped after each possible round, written to a pass file, read back and resumed: the end
/// has the bits of one render.
#[test]
fn a_render_resumed_after_any_round_has_the_same_bits() {
    let _limit = common::deadline(180);
    let s = small_box(6, 3);
    let one_go = bits(&render(&s, &|| {}).image);
    let d = std::env::temp_dir().join(format!("rtis-progressive-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for stop_after in 1..=3 {
        let mut rounds = 0;
        let first = refine(
            &s,
            Pass::empty(&s),
            None,
            &|_| {},
            &AtomicBool::new(false),
            &mut |_, _| {
                rounds += 1;
                rounds < stop_after
            },
        );
        assert!(
            matches!(first.ending, Ending::Declined),
            "after {stop_after}"
        );
        let file = d.join(format!("partial-{stop_after}.exr"));
        first.pass.write(&file).unwrap();
        let back = Pass::read(&file).unwrap();
        check_resumable(&s, &back).unwrap();
        let rest = refine(
            &s,
            back,
            None,
            &|_| {},
            &AtomicBool::new(false),
            &mut |_, _| true,
        );
        assert!(rest.ending.is_complete());
        assert_eq!(
            bits(&rest.pass.image()),
            one_go,
            "stopped after {stop_after}"
        );
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// A pass holding a gap (samples 2..4 of 8, from `--pass 1/4`) resumes by filling the gaps:
/// first 0..2, then 4..8, to the bits of one render.
#[test]
fn a_pass_with_gaps_resumes_by_filling_them() {
    let _limit = common::deadline(120);
    let s = small_box(8, 5);
    let one_go = bits(&render(&s, &|| {}).image);
    let sums = rtis::render::render_pass(&s, 2..4, &|| {}, &AtomicBool::new(false));
    let start = Pass::from_render(&s, 2..4, sums.pixels);
    assert_eq!(next_round(&start), Some(0..2));
    let mut seen = Vec::new();
    let p = refine(
        &s,
        start,
        None,
        &|_| {},
        &AtomicBool::new(false),
        &mut |_, r| {
            seen.push(r.samples.clone());
            true
        },
    );
    assert_eq!(seen, vec![0..2, 4..8]);
    assert_eq!(bits(&p.pass.image()), one_go);
}

/// A budget too short for a second round ends after the first (which always runs), with
/// `OutOfTime`; a stop set before the start renders nothing and says so; every tile call
/// reports the round's samples.
#[test]
fn budget_and_stop_end_the_rounds() {
    let _limit = common::deadline(120);
    let s = small_box(16, 1);
    let p = refine(
        &s,
        Pass::empty(&s),
        Some(Duration::ZERO),
        &|n| assert_eq!(n, 1),
        &AtomicBool::new(false),
        &mut |_, _| true,
    );
    assert!(matches!(p.ending, Ending::OutOfTime), "{:?}", p.ending);
    assert_eq!((p.rounds, p.pass.samples()), (1, 1));
    // Resumed under a budget, the first round is one sample (to measure the rate), not as
    // many as are held.
    let resumed = refine(
        &s,
        all_but_last(&s),
        Some(Duration::ZERO),
        &|_| {},
        &AtomicBool::new(false),
        &mut |_, r| {
            assert_eq!(r.samples, 8..9);
            true
        },
    );
    assert_eq!((resumed.rounds, resumed.pass.samples()), (1, 9));
    let stopped = refine(
        &s,
        Pass::empty(&s),
        None,
        &|_| {},
        &AtomicBool::new(true),
        &mut |_, _| panic!("no round completes"),
    );
    assert_eq!(stopped.pass.samples(), 0);
    let Ending::Stopped {
        dropped: (samples, tiles),
    } = stopped.ending
    else {
        panic!("stopped: {:?}", stopped.ending);
    };
    assert_eq!((samples, tiles.tiles_done), (0..1, 0));
    // A generous budget completes.
    let all = refine(
        &s,
        Pass::empty(&s),
        Some(Duration::from_secs(3600)),
        &|_| {},
        &AtomicBool::new(false),
        &mut |_, _| true,
    );
    assert!(all.ending.is_complete());
    assert_eq!(all.pass.samples(), 16);
}

/// A pass of `s` holding samples 0..8.
fn all_but_last(s: &rtis::RenderScene) -> Pass {
    let sums = rtis::render::render_pass(s, 0..8, &|| {}, &AtomicBool::new(false));
    Pass::from_render(s, 0..8, sums.pixels)
}

/// A pass of another seed, spp, size or scene is refused, naming what differs.
#[test]
fn resuming_another_render_is_refused() {
    let s = small_box(4, 1);
    let of = |t: &rtis::RenderScene| Pass::empty(t);
    let cases = [
        (small_box(4, 2), "seed"),
        (small_box(8, 1), "spp"),
        (
            rtis::extract(&scene(
                "Scene(extends: \"cornell.ron\", film: (width: 20, height: 20, spp: 4), seed: 1,
                       shader: Path(max_depth: 3))",
            )),
            "film size",
        ),
        (
            rtis::extract(&scene(
                "Scene(extends: \"cornell.ron\", film: (width: 24, height: 20, spp: 4), seed: 1,
                       shader: Path(max_depth: 4))",
            )),
            "scene",
        ),
    ];
    for (other, what) in cases {
        let e = check_resumable(&s, &of(&other)).unwrap_err();
        assert!(e.contains(&format!("another {what}")), "{what}: {e}");
    }
    check_resumable(&s, &of(&small_box(4, 1))).unwrap();
}

//! Mutation fuzzing of the scene loader: every scene of `scenes/`, mutated (bytes flipped, text
//! cut short, numbers swapped or replaced by extreme ones, brackets deleted, lines duplicated
//! or deleted, punctuation inserted), loads or fails with a located, bounded message, and never
//! panics. Mutants that are still UTF-8 load as text with the scene's folder as base (so
//! `extends` and mesh paths resolve); the others are written to a file and loaded from it.
//! `RTIS_FUZZ_SHOW=1` prints every mutant's outcome, to read the messages.

use proptest::prelude::*;
use rtis::scene::{MAX_MESSAGE, SceneError, load_path, load_str};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// Proptest cases: `PROPTEST_CASES` when set (for long runs), else `default` (seconds in CI).
pub(crate) fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Every scene file: its name and text.
fn scenes() -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "ron").then(|| {
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                (name, std::fs::read_to_string(&p).unwrap())
            })
        })
        .collect();
    v.sort();
    assert!(v.len() >= 9, "scenes/ holds the example scenes");
    v
}

/// One change to a file's bytes; every index is taken modulo what it indexes.
#[derive(Clone, Debug)]
pub(crate) enum Mutation {
    /// Flip bit `bit` of byte `at`.
    FlipBit { at: usize, bit: u8 },
    /// Cut the file at `at`.
    Truncate { at: usize },
    /// Exchange the `i`-th and `j`-th numbers.
    SwapNumbers { i: usize, j: usize },
    /// Replace the `i`-th number by `with`.
    ReplaceNumber { i: usize, with: &'static str },
    /// Delete the `i`-th bracket or parenthesis.
    DeleteBracket { i: usize },
    /// Write line `i` twice.
    DuplicateLine { i: usize },
    /// Delete line `i`.
    DeleteLine { i: usize },
    /// Insert `what` at byte `at`.
    Insert { at: usize, what: &'static str },
}

const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1.5",
    "-2.5",
    "1e40",
    "1e-40",
    "1e308",
    "-1e308",
    "NaN",
    "inf",
    "-inf",
    "4294967296",
    "99999999999999999999999",
    "0x10",
    "1_000",
    ".5",
    "5.",
    "+3",
    "1e",
];
const INSERTS: &[&str] = &[
    ",",
    ":",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    "\"",
    "'",
    "/*",
    "//",
    "#",
    "\\",
    "Some(",
    "r#\"",
    "\u{e9}",
    "\u{1F600}",
    "\t",
    "\n",
    "\0",
];

pub(crate) fn mutation() -> impl Strategy<Value = Mutation> {
    let any = any::<usize>();
    prop_oneof![
        (any, 0u8..8).prop_map(|(at, bit)| Mutation::FlipBit { at, bit }),
        any.prop_map(|at| Mutation::Truncate { at }),
        (any, any).prop_map(|(i, j)| Mutation::SwapNumbers { i, j }),
        (any, proptest::sample::select(NUMBERS))
            .prop_map(|(i, with)| Mutation::ReplaceNumber { i, with }),
        any.prop_map(|i| Mutation::DeleteBracket { i }),
        any.prop_map(|i| Mutation::DuplicateLine { i }),
        any.prop_map(|i| Mutation::DeleteLine { i }),
        (any, proptest::sample::select(INSERTS))
            .prop_map(|(at, what)| Mutation::Insert { at, what }),
    ]
}

/// Byte ranges of the number literals of `b`.
fn numbers(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !after_word {
            let s = i;
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_digit()
                    || b[i] == b'.'
                    || b[i] == b'e'
                    || (matches!(b[i], b'-' | b'+') && b[i - 1] == b'e'))
            {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

pub(crate) fn apply(b: &mut Vec<u8>, m: &Mutation) {
    let len = b.len().max(1);
    let lines = |b: &[u8]| -> Vec<(usize, usize)> {
        let mut v = Vec::new();
        let mut s = 0;
        for (i, &c) in b.iter().enumerate() {
            if c == b'\n' {
                v.push((s, i + 1));
                s = i + 1;
            }
        }
        if s < b.len() {
            v.push((s, b.len()));
        }
        v
    };
    match *m {
        Mutation::FlipBit { at, bit } => {
            if !b.is_empty() {
                b[at % len] ^= 1 << bit;
            }
        }
        Mutation::Truncate { at } => b.truncate(at % len),
        Mutation::SwapNumbers { i, j } => {
            let n = numbers(b);
            if n.len() >= 2 {
                let (x, y) = (n[i % n.len()], n[j % n.len()]);
                let (x, y) = if x.0 <= y.0 { (x, y) } else { (y, x) };
                if x != y {
                    let (sx, sy) = (b[x.0..x.1].to_vec(), b[y.0..y.1].to_vec());
                    b.splice(y.0..y.1, sx);
                    b.splice(x.0..x.1, sy);
                }
            }
        }
        Mutation::ReplaceNumber { i, with } => {
            let n = numbers(b);
            if !n.is_empty() {
                let (s, e) = n[i % n.len()];
                b.splice(s..e, with.bytes());
            }
        }
        Mutation::DeleteBracket { i } => {
            let at: Vec<usize> = (0..b.len())
                .filter(|&k| b"()[]{}".contains(&b[k]))
                .collect();
            if !at.is_empty() {
                b.remove(at[i % at.len()]);
            }
        }
        Mutation::DuplicateLine { i } => {
            let l = lines(b);
            if !l.is_empty() {
                let (s, e) = l[i % l.len()];
                let line = b[s..e].to_vec();
                b.splice(e..e, line);
            }
        }
        Mutation::DeleteLine { i } => {
            let l = lines(b);
            if !l.is_empty() {
                let (s, e) = l[i % l.len()];
                b.drain(s..e);
            }
        }
        Mutation::Insert { at, what } => {
            let at = at % (b.len() + 1);
            b.splice(at..at, what.bytes());
        }
    }
}

/// Load a mutant: as text from the scenes folder when it is UTF-8, else from a file.
fn load(name: &str, bytes: &[u8], tmp: &Path) -> Result<(), SceneError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => load_str(text, name, Some(&scenes_dir())).map(|_| ()),
        Err(_) => {
            let path = tmp.join(name);
            std::fs::write(&path, bytes).unwrap();
            load_path(&path).map(|_| ())
        }
    }
}

/// The example scenes themselves load.
#[test]
fn every_example_scene_loads() {
    for (name, text) in scenes() {
        load_str(&text, &name, Some(&scenes_dir())).unwrap_or_else(|e| panic!("{e}"));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(4000)))]

    #[test]
    fn mutants_load_or_fail_located_without_panicking(
        which in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 1..4),
    ) {
        let all = scenes();
        let (name, text) = &all[which % all.len()];
        let mut bytes = text.clone().into_bytes();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        let tmp = std::env::temp_dir().join(format!("rtis-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&tmp).unwrap();
        // Removed when the case ends, however it ends.
        let _cleanup = RemoveOnDrop(tmp.clone());
        let shown = String::from_utf8_lossy(&bytes).into_owned();
        let result = catch_unwind(AssertUnwindSafe(|| load(name, &bytes, &tmp)));
        let result = match result {
            Ok(r) => r,
            Err(p) => {
                let why = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                return Err(TestCaseError::fail(format!(
                    "loading panicked ({why}) on {name} mutated by {mutations:?}:\n{shown}"
                )));
            }
        };
        if std::env::var_os("RTIS_FUZZ_SHOW").is_some() {
            match &result {
                Ok(()) => eprintln!("== {name}: ok"),
                Err(e) => eprintln!("== {name}: {e}"),
            }
        }
        if let Err(e) = result {
            let (line, col) = e.at.ok_or_else(|| TestCaseError::fail(format!(
                "no location in `{e}` for {name} mutated by {mutations:?}:\n{shown}"
            )))?;
            let display = e.to_string();
            let head = format!("{}:{line}:{col}: ", e.file);
            prop_assert!(display.starts_with(&head), "{display}");
            prop_assert!(e.line_text.is_some(), "no line shown: {display}");
            prop_assert!(e.message.chars().count() <= MAX_MESSAGE);
            prop_assert!(display.len() < 2000, "{display}");
        }
    }
}

/// Removes a folder when dropped.
struct RemoveOnDrop(std::path::PathBuf);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

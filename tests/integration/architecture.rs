//! The layering of `src/` (docs/architecture.md): every `crate::` path in a module names a
//! module of the same or a lower layer, so imports point one way, from the scene file down to
//! the leaf maths.

use std::path::Path;

/// The layer of each top-level module of `src/`, lowest first.
const LAYERS: &[(&str, u32)] = &[
    ("geometry", 0),
    ("sampling", 0),
    ("mesh", 0),
    ("raster", 0),
    ("effects", 0),
    ("stats", 0),
    ("shape", 1),
    ("material", 1),
    ("light", 1),
    ("texture", 1),
    ("camera", 1),
    ("accel", 2),
    ("shader", 3),
    ("render", 4),
    ("world", 5),
    ("extract", 6),
    ("scene", 7),
    ("import", 7),
    ("converge", 7),
    ("cli", 8),
    ("lib", 9),
    ("main", 9),
];

fn layer(module: &str) -> Option<u32> {
    LAYERS.iter().find(|(m, _)| *m == module).map(|(_, l)| *l)
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn imports_point_down_the_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut violations = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let top = top.trim_end_matches(".rs");
        let own = layer(top).unwrap_or_else(|| panic!("{top}: a module without a layer"));
        let text = std::fs::read_to_string(f).unwrap();
        for (i, _) in text.match_indices("crate::") {
            let name: String = text[i + 7..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if let Some(l) = layer(&name)
                && l > own
            {
                violations.push(format!(
                    "{}: imports {name} (layer {l} > {own})",
                    rel.display()
                ));
            }
        }
    }
    assert!(files.len() > 40, "found {} files", files.len());
    assert!(violations.is_empty(), "{violations:#?}");
}

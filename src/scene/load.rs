//! Reading scene files, resolving `extends`, checking names, and filling the world with its
//! own component types: names resolved, meshes loaded.

use super::SceneError;
use super::file::{
    CameraDesc, EffectsDesc, EntityDesc, FilmDesc, MaterialDesc, Model, SceneFile, ShaderDesc,
    TableMaterial,
};
use super::values::Rgb;
use crate::material::Material;
use crate::world::{MaterialName, Name, Scene, Settings};
use ron::extensions::Extensions;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The course's Cornell box, embedded: what `rtis render` draws when given no scene.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/cornell.ron");

/// Deepest chain of `extends`.
const MAX_EXTENDS: usize = 16;

/// One parsed file: its display name, text and folder (for relative paths).
struct Source {
    name: String,
    text: String,
    dir: Option<PathBuf>,
}

fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME)
}

fn parse(src: &Source) -> Result<SceneFile, SceneError> {
    ron_options().from_str::<SceneFile>(&src.text).map_err(|e| {
        let (line, col) = (e.span.start.line, e.span.start.col);
        SceneError::at(&src.name, &src.text, line, col, e.code.to_string())
    })
}

/// Load the scene file at `path`.
pub fn load_path(path: &Path) -> Result<Scene, SceneError> {
    let src = read(path)?;
    let mut chain: Vec<PathBuf> = path.canonicalize().into_iter().collect();
    resolve(src, &mut chain).and_then(|r| r.into_scene(path.display().to_string()))
}

/// Load a scene from text; `name` labels errors and `dir` resolves `extends` (the current folder
/// when `None`).
pub fn load_str(text: &str, name: &str, dir: Option<&Path>) -> Result<Scene, SceneError> {
    let src = Source {
        name: name.to_string(),
        text: text.to_string(),
        dir: dir.map(Path::to_path_buf),
    };
    resolve(src, &mut Vec::new()).and_then(|r| r.into_scene(name.to_string()))
}

/// The embedded Cornell box ([`DEFAULT_SCENE`]).
pub fn load_default() -> Scene {
    load_str(DEFAULT_SCENE, "<default cornell.ron>", None)
        .expect("the embedded default scene is valid (checked by the tests)")
}

fn read(path: &Path) -> Result<Source, SceneError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::whole_file(&name, format!("cannot read scene file: {e}")))?;
    Ok(Source {
        name,
        text,
        dir: path.parent().map(Path::to_path_buf),
    })
}

/// A scene with every `extends` merged in; entities remember which source they came from.
struct Resolved {
    sources: Vec<Source>,
    film: Option<FilmDesc>,
    camera: Option<CameraDesc>,
    shader: Option<ShaderDesc>,
    background: Option<Rgb>,
    seed: Option<u64>,
    model: Option<Model>,
    effects: Option<EffectsDesc>,
    materials: BTreeMap<String, (Material, usize)>,
    entities: Vec<(EntityDesc, usize)>,
}

fn resolve(src: Source, chain: &mut Vec<PathBuf>) -> Result<Resolved, SceneError> {
    let file = parse(&src)?;
    let mut base = match &file.extends {
        None => Resolved {
            sources: Vec::new(),
            film: None,
            camera: None,
            shader: None,
            background: None,
            seed: None,
            model: None,
            effects: None,
            materials: BTreeMap::new(),
            entities: Vec::new(),
        },
        Some(rel) => {
            let path = src.dir.clone().unwrap_or_default().join(rel);
            let err = |m: String| {
                let off = src.text.find(&format!("\"{rel}\"")).unwrap_or(0);
                SceneError::at_offset(&src.name, &src.text, off, m)
            };
            let canon = path
                .canonicalize()
                .map_err(|e| err(format!("cannot read base scene {}: {e}", path.display())))?;
            if chain.contains(&canon) {
                return Err(err(format!(
                    "`extends` cycle: {} extends itself through its bases",
                    path.display()
                )));
            }
            if chain.len() >= MAX_EXTENDS {
                return Err(err(format!("more than {MAX_EXTENDS} nested `extends`")));
            }
            chain.push(canon);
            let base_src = read(&path)?;
            let r = resolve(base_src, chain)?;
            chain.pop();
            r
        }
    };
    let idx = base.sources.len();
    base.film = file.film.or(base.film);
    base.camera = file.camera.or(base.camera);
    base.shader = file.shader.or(base.shader);
    base.background = file.background.or(base.background);
    base.seed = file.seed.or(base.seed);
    base.model = file.model.or(base.model);
    base.effects = file.effects.or(base.effects);
    for (name, TableMaterial(m)) in file.materials.unwrap_or_default() {
        base.materials.insert(name, (m, idx));
    }
    // An entity named like one of the base's replaces it in place; others are appended.
    for e in file.entities.unwrap_or_default() {
        let slot = e.0.name.as_ref().and_then(|n| {
            base.entities
                .iter()
                .position(|(b, _)| b.0.name.as_ref() == Some(n))
        });
        match slot {
            Some(i) => base.entities[i] = (e, idx),
            None => base.entities.push((e, idx)),
        }
    }
    base.sources.push(src);
    Ok(base)
}

/// Byte offset of `Named("name")` in `text`, for locating a bad reference.
fn find_named(text: &str, name: &str) -> usize {
    let quoted = format!("\"{name}\"");
    let mut from = 0;
    while let Some(i) = text[from..].find(&quoted) {
        let at = from + i;
        let before = text[..at].trim_end();
        if let Some(b) = before.strip_suffix('(')
            && b.trim_end().ends_with("Named")
        {
            return at;
        }
        from = at + quoted.len();
    }
    0
}

impl Resolved {
    fn into_scene(self, origin: String) -> Result<Scene, SceneError> {
        let located = |idx: usize, name: &str, msg: String| {
            let s: &Source = &self.sources[idx];
            SceneError::at_offset(&s.name, &s.text, find_named(&s.text, name), msg)
        };
        let mut world = hecs::World::new();
        let mut warnings = Vec::new();
        for (EntityDesc(e), idx) in &self.entities {
            let src = &self.sources[*idx];
            let mut b = hecs::EntityBuilder::new();
            if let Some(name) = &e.name {
                b.add(Name(name.clone()));
            }
            if let Some(shape) = &e.shape {
                let shape = shape
                    .to_world(|path| {
                        let file = src.dir.clone().unwrap_or_default().join(path);
                        crate::mesh::load_obj(&file)
                    })
                    .map_err(|m| {
                        let path = match shape {
                            super::file::ShapeDesc::Mesh { path } => path.as_str(),
                            _ => "",
                        };
                        let off = src.text.find(&format!("\"{path}\"")).unwrap_or(0);
                        SceneError::at_offset(&src.name, &src.text, off, m)
                    })?;
                b.add(shape);
            }
            if let Some(t) = &e.transform {
                b.add(t.to_world());
            }
            if let Some(light) = &e.light {
                b.add(light.to_world());
            }
            match &e.material {
                Some(MaterialDesc::Named(n)) => match self.materials.get(n) {
                    Some((m, _)) => {
                        b.add(*m);
                        b.add(MaterialName(n.clone()));
                    }
                    None => {
                        let known: Vec<_> =
                            self.materials.keys().map(|k| format!("\"{k}\"")).collect();
                        let list = if known.is_empty() {
                            "the scene declares no materials".to_string()
                        } else {
                            format!("known materials: {}", known.join(", "))
                        };
                        return Err(located(
                            *idx,
                            n,
                            format!("unknown material \"{n}\"; {list}"),
                        ));
                    }
                },
                Some(m) => {
                    if let Some(m) = m.to_world() {
                        b.add(m);
                    }
                }
                None => {}
            }
            world.spawn(b.build());
        }
        if self.entities.is_empty() {
            warnings.push("the scene has no entities: every pixel shows the background".into());
        }
        let d = Settings::default();
        let settings = Settings {
            film: self.film.map_or(d.film, |f| f.0),
            camera: self.camera.map_or(d.camera, |c| c.to_world()),
            shader: self.shader.map_or(d.shader, |s| s.to_world()),
            background: self.background.map_or(d.background, |b| b.0.as_vec3a()),
            seed: self.seed.unwrap_or(d.seed),
            model: self.model.unwrap_or(d.model),
            effects: self.effects.map_or(d.effects, |e| e.to_world()),
        };
        Ok(Scene {
            world,
            settings,
            origin,
            warnings,
        })
    }
}

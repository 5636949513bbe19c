//! Reading scene files, resolving `extends`, checking names, and filling the world with its
//! own component types: names resolved, meshes loaded.

use super::SceneError;
use super::error::{clip, line_col};
use super::file::{
    CameraDesc, EffectsDesc, EntityDesc, FilmDesc, LightComponent, LightDesc, MaterialDesc, Model,
    SceneFile, ShaderDesc, ShapeDesc, TableMaterial,
};
use super::messages::{explain, offset_of};
use super::spans::{self, Node};
use super::values::{MAX_RADIANCE, Rgb};
use crate::light::{Sky, SkyMap};
use crate::material::Material;
use crate::raster::Raster;
use crate::world::{MaterialName, Name, Scene, Settings, Shader};
use ron::extensions::Extensions;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The course's Cornell box, embedded: what `rtis render` draws when given no scene.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/cornell.ron");

/// Most `extends` in a chain: the file loaded and up to this many bases above it.
pub const MAX_EXTENDS: usize = 16;

/// One parsed file: its display name, text, folder (for relative paths), and where its values
/// are (for errors found after parsing).
struct Source {
    name: String,
    text: String,
    dir: Option<PathBuf>,
    tree: Option<Node>,
    /// The file it was read from (none for text given in memory).
    file: Option<PathBuf>,
}

impl Source {
    fn new(name: String, text: String, dir: Option<PathBuf>) -> Self {
        Source {
            name,
            text,
            dir,
            tree: None,
            file: None,
        }
    }

    /// An error at byte `offset` of this file.
    fn error(&self, offset: usize, message: impl Into<String>) -> SceneError {
        SceneError::at_offset(&self.name, &self.text, offset, message)
    }

    /// Entity `i` of this file's `entities` list, as written.
    fn entity(&self, i: usize) -> Option<&Node> {
        let tree = self.tree.as_ref()?;
        tree.get("entities", &self.text)?.items().get(i)
    }

    /// Where the top-level field `name` is written (its value), else the file's start.
    fn top_field(&self, name: &str) -> usize {
        self.tree
            .as_ref()
            .and_then(|t| t.get(name, &self.text))
            .map_or(0, |v| v.start)
    }
}

fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME)
}

/// Parse a file, then check what spans several values: duplicate names and a transform on a
/// light-only entity.
fn parse(src: &mut Source) -> Result<SceneFile, SceneError> {
    let file = ron_options()
        .from_str::<SceneFile>(&src.text)
        .map_err(|e| {
            let mut start = offset_of(&src.text, e.span.start.line, e.span.start.col);
            // A value its type refused is reported at its end: point at its start instead (a
            // tuple's opening bracket), where its field's name is.
            if matches!(e.code, ron::Error::Message(_)) {
                start = super::messages::value_start(&src.text, start);
            }
            let end = offset_of(&src.text, e.span.end.line, e.span.end.col);
            src.error(start, explain(&e.code, &src.text, start, end))
        })?;
    src.tree = spans::parse(&src.text);
    check(src, &file)?;
    Ok(file)
}

/// A degenerate camera (at `look_at` or `up`), duplicate material keys, duplicate entity names,
/// and transforms on entities without a shape, each at the second occurrence (or the
/// transform) and naming the first.
fn check(src: &Source, file: &SceneFile) -> Result<(), SceneError> {
    let text = &src.text;
    let tree = src.tree.as_ref();
    let lc = |off: usize| {
        let (l, c) = line_col(text, off);
        format!("line {l}, column {c}")
    };
    if let Some(map) = tree.and_then(|t| t.get("materials", text)) {
        let mut seen: BTreeMap<String, usize> = BTreeMap::new();
        for (key, _) in map.entries() {
            let Some(name) = key.string(text) else {
                continue;
            };
            if let Some(&first) = seen.get(&name) {
                return Err(src.error(
                    key.start,
                    format!(
                        "material \"{}\" is defined twice in `materials` (first at {}): \
                         rename or remove one",
                        clip(&name, 60),
                        lc(first)
                    ),
                ));
            }
            seen.insert(name, key.start);
        }
    }
    // A camera without a view, at the field to blame (`up` is absent when defaulted: then the
    // camera itself).
    if let Some((field, why)) = file.camera.as_ref().and_then(|c| c.degenerate()) {
        let camera = tree.and_then(|t| t.get("camera", text));
        let at = camera
            .and_then(|c| c.get(field, text))
            .or(camera)
            .map_or(0, |n| n.start);
        return Err(src.error(at, why));
    }
    let entities = file.entities.as_deref().unwrap_or_default();
    let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, EntityDesc(e)) in entities.iter().enumerate() {
        let node = src.entity(i);
        if let Some(name) = &e.name {
            let at = node
                .and_then(|n| n.get("name", text))
                .map_or_else(|| src.top_field("entities"), |v| v.start);
            if let Some(&first) = seen.get(name.as_str()) {
                return Err(src.error(
                    at,
                    format!(
                        "two entities are named \"{}\" (the first at {}): names must be \
                         unique within a file (an entity named like one of the base scene's \
                         replaces it)",
                        clip(name, 60),
                        lc(first)
                    ),
                ));
            }
            seen.insert(name, at);
        }
        if let Some((field, why)) = e.light.as_ref().and_then(|l| l.invalid()) {
            let light = node.and_then(|n| n.get("light", text));
            let at = light
                .and_then(|l| l.get(field, text))
                .or(light)
                .map_or_else(|| src.top_field("entities"), |n| n.start);
            return Err(src.error(at, why));
        }
        if e.shape.is_none() && e.light.is_some() && e.transform.is_some() {
            let at = node
                .and_then(|n| n.field("transform"))
                .map_or_else(|| src.top_field("entities"), |f| f.at);
            let label = e.name.as_deref().map_or("this entity".to_string(), |n| {
                format!("entity \"{}\"", clip(n, 60))
            });
            return Err(src.error(
                at,
                format!(
                    "{label} has a light but no shape, and a `transform` moves only a shape: \
                     remove it and set the light's `position` instead"
                ),
            ));
        }
    }
    Ok(())
}

/// Load the scene file at `path`.
pub fn load_path(path: &Path) -> Result<Scene, SceneError> {
    let name = path.display().to_string();
    let src = read(path).map_err(|e| match e {
        ReadError::Io(e) => SceneError::whole_file(&name, format!("cannot read scene file: {e}")),
        ReadError::Located(e) => e,
    })?;
    let mut chain: Vec<PathBuf> = path.canonicalize().into_iter().collect();
    resolve(src, &mut chain, 0).and_then(|r| r.into_scene(name))
}

/// Load a scene from text; `name` labels errors and `dir` resolves `extends` (the current folder
/// when `None`).
pub fn load_str(text: &str, name: &str, dir: Option<&Path>) -> Result<Scene, SceneError> {
    let src = Source::new(
        name.to_string(),
        text.to_string(),
        dir.map(Path::to_path_buf),
    );
    resolve(src, &mut Vec::new(), 0).and_then(|r| r.into_scene(name.to_string()))
}

/// The embedded Cornell box ([`DEFAULT_SCENE`]).
pub fn load_default() -> Scene {
    load_str(DEFAULT_SCENE, "<default cornell.ron>", None)
        .expect("the embedded default scene is valid (checked by the tests)")
}

/// Why a file could not be read: the system's reason, or text that is not UTF-8 (located).
enum ReadError {
    Io(std::io::Error),
    Located(SceneError),
}

fn read(path: &Path) -> Result<Source, ReadError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(ReadError::Io)?;
    let text = decode(&name, bytes).map_err(ReadError::Located)?;
    let mut src = Source::new(name, text, path.parent().map(Path::to_path_buf));
    src.file = Some(path.to_path_buf());
    Ok(src)
}

/// The text of a file, or an error at the line and column of its first byte that is not UTF-8.
fn decode(name: &str, bytes: Vec<u8>) -> Result<String, SceneError> {
    String::from_utf8(bytes).map_err(|e| {
        let bad = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let shown: Vec<String> = bytes[bad..]
            .iter()
            .take(
                e.utf8_error()
                    .error_len()
                    .unwrap_or(bytes.len() - bad)
                    .min(4),
            )
            .map(|b| format!("0x{b:02X}"))
            .collect();
        // The valid prefix places the error; the line is shown with U+FFFD for bad bytes.
        let lossy = String::from_utf8_lossy(bytes);
        let prefix = std::str::from_utf8(&bytes[..bad]).unwrap_or_default();
        let (line, col) = line_col(prefix, prefix.len());
        SceneError::at(
            name,
            &lossy,
            line,
            col,
            format!(
                "the file is not UTF-8 text: byte{} {} cannot start a character here; save \
                 the file as UTF-8",
                if shown.len() == 1 { "" } else { "s" },
                shown.join(" ")
            ),
        )
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
    /// Each table material, what was written, and the index of its source.
    materials: BTreeMap<String, (Material, MaterialDesc, usize)>,
    /// Each entity, the index of its source, and its index in that file's `entities`.
    entities: Vec<(EntityDesc, usize, usize)>,
}

fn resolve(
    mut src: Source,
    chain: &mut Vec<PathBuf>,
    depth: usize,
) -> Result<Resolved, SceneError> {
    let file = parse(&mut src)?;
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
            let at = src.top_field("extends");
            let err = |m: String| src.error(at, m);
            let shown = clip(&path.display().to_string(), 200);
            if depth >= MAX_EXTENDS {
                return Err(err(format!(
                    "more than {MAX_EXTENDS} nested `extends`: a chain may have at most \
                     {MAX_EXTENDS} base scenes"
                )));
            }
            let canon = path
                .canonicalize()
                .map_err(|e| err(format!("cannot read base scene {shown}: {e}")))?;
            if chain.contains(&canon) {
                return Err(err(format!(
                    "`extends` cycle: {shown} extends itself through its bases"
                )));
            }
            let base_src = read(&path).map_err(|e| match e {
                ReadError::Io(e) => err(format!("cannot read base scene {shown}: {e}")),
                ReadError::Located(e) => e,
            })?;
            chain.push(canon);
            let r = resolve(base_src, chain, depth + 1)?;
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
    for (name, TableMaterial(m, desc)) in file.materials.unwrap_or_default() {
        base.materials.insert(name, (m, desc, idx));
    }
    // An entity named like one of the base's replaces it in place; others are appended.
    for (i, e) in file.entities.unwrap_or_default().into_iter().enumerate() {
        let slot = e.0.name.as_ref().and_then(|n| {
            base.entities
                .iter()
                .position(|(b, _, _)| b.0.name.as_ref() == Some(n))
        });
        match slot {
            Some(j) => base.entities[j] = (e, idx, i),
            None => base.entities.push((e, idx, i)),
        }
    }
    base.sources.push(src);
    Ok(base)
}

impl Resolved {
    /// Warnings, located, for scenes that render but cannot show what was meant:
    ///
    /// - shapes lit by nothing: a shader that shades (Direct, Global, Path), and no point
    ///   light, no emitter, no sky and no Global ambient term (or each switched off in
    ///   `effects`);
    /// - a point light inside a sphere (as written, without a `transform`), where shadows are
    ///   traced: the sphere's outside never sees it.
    ///
    /// Not detected (documented in docs/scene-format.md): a light enclosed by a closed mesh or
    /// by a transformed sphere, and an emitter that faces away from everything the camera sees.
    fn silent_mistakes(&self, settings: &Settings) -> Vec<String> {
        let mut warnings = Vec::new();
        let at = |idx: usize, i: usize, field: &str| {
            let src = &self.sources[idx];
            let node = src.entity(i);
            let off = node
                .and_then(|n| n.get(field, &src.text))
                .or(node)
                .map_or_else(|| src.top_field("entities"), |n| n.start);
            let (line, col) = line_col(&src.text, off);
            format!("{}:{line}:{col}", src.name)
        };
        let on = |switch: Option<bool>| switch != Some(false);
        let fx = &settings.effects;
        let shades = matches!(
            settings.shader,
            Shader::Direct { .. } | Shader::Path(_) | Shader::Global(_)
        );
        let ambient = matches!(settings.shader, Shader::Global(g) if g.ambient != glam::Vec3A::ZERO)
            && on(fx.ambient);
        // An environment light is part of the `emission` effect.
        let lit = self
            .entities
            .iter()
            .any(|(EntityDesc(e), ..)| match &e.light {
                Some(LightDesc::Environment { scale, .. }) => on(fx.emission) && scale.0 > 0.0,
                Some(_) => true,
                None => e.emitter.is_some() && on(fx.emission),
            });
        if let Some((_, idx, i)) = self
            .entities
            .iter()
            .find(|(EntityDesc(e), ..)| e.shape.is_some())
            && shades
            && !lit
            && !ambient
            && (settings.background == glam::Vec3A::ZERO || !on(fx.background))
        {
            warnings.push(format!(
                "{}: the scene has shapes but no light, no emitter and a black background: every \
                 shaded pixel is black; add a `light: Point(...)`, an `emitter` or a `background`",
                at(*idx, *i, "shape")
            ));
        }
        // Shadow rays exist only where the shader shades with shadows on.
        let shadows = shades && on(fx.shadows);
        for (EntityDesc(light), lidx, li) in self.entities.iter().filter(|_| shadows) {
            let position = match &light.light {
                Some(LightDesc::Point { position, .. } | LightDesc::Spot { position, .. }) => {
                    position
                }
                // A sun or a sky is outside everything; no light, nothing to warn of.
                Some(LightDesc::Directional { .. } | LightDesc::Environment { .. }) | None => {
                    continue;
                }
            };
            for (EntityDesc(e), sidx, si) in &self.entities {
                if let (Some(ShapeDesc::Sphere { center, radius }), None) = (&e.shape, &e.transform)
                    && (position.0 - center.0).length() < radius.0
                {
                    warnings.push(format!(
                        "{}: this light is inside the sphere at {}: only the sphere's \
                         inside sees it, and its shadow rays are wasted elsewhere",
                        at(*lidx, *li, "light"),
                        at(*sidx, *si, "shape")
                    ));
                }
            }
        }
        warnings
    }

    fn into_scene(self, origin: String) -> Result<Scene, SceneError> {
        let mut world = hecs::World::new();
        let mut warnings = Vec::new();
        let mut files: Vec<PathBuf> = self.sources.iter().filter_map(|s| s.file.clone()).collect();
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
        // Where the scene's environment light is written, once one is met.
        let mut sky_at: Option<String> = None;
        // Each image textures read, once, by its path and whether it is raw.
        let mut images: BTreeMap<(PathBuf, bool), Arc<Raster>> = BTreeMap::new();
        for (EntityDesc(e), idx, i) in &self.entities {
            let src = &self.sources[*idx];
            // Where a component's value is written: the value of `field`, then `inner` inside
            // it (`Mesh(path: ...)`, `Named("...")`), falling back to the entity, the
            // `entities` list, the file's start.
            let place = |field: &str, inner: Option<&str>| {
                let node = src.entity(*i);
                let value = node.and_then(|n| n.get(field, &src.text));
                let deep = value.and_then(|v| match inner {
                    Some(f) => v.get(f, &src.text),
                    None => v.items().first(),
                });
                deep.or(value)
                    .or(node)
                    .map_or_else(|| src.top_field("entities"), |n| n.start)
            };
            let mut b = hecs::EntityBuilder::new();
            if let Some(name) = &e.name {
                b.add(Name(name.clone()));
            }
            if let Some(shape) = &e.shape {
                let shape = shape
                    .to_world(|path, index| {
                        let file = src.dir.clone().unwrap_or_default().join(path);
                        files.push(file.clone());
                        crate::mesh::load(&file, index)
                    })
                    .map_err(|m| src.error(place("shape", Some("path")), m))?;
                b.add(shape);
            }
            if let Some(t) = &e.transform {
                b.add(t.to_world());
            }
            if let Some(light) = &e.light {
                let light = light
                    .to_world(|path| {
                        let file = src.dir.clone().unwrap_or_default().join(path);
                        files.push(file.clone());
                        // The absolute path, so that `rtis check` prints a scene that reads
                        // back from anywhere.
                        let source = std::path::absolute(&file).unwrap_or(file.clone());
                        let map = Arc::new(SkyMap::new(crate::raster::load(&file)?));
                        Ok(Sky::Map { map, source })
                    })
                    .map_err(|m| src.error(place("light", Some("image")), m))?;
                match light {
                    LightComponent::Light(l) => {
                        b.add(l);
                    }
                    LightComponent::Environment(env) => {
                        // One sky, and no background beside it: both say what escaped rays see.
                        let at = place("light", None);
                        if let Some(first) = &sky_at {
                            return Err(src.error(
                                at,
                                format!(
                                    "a second Environment light (the first at {first}): a scene \
                                     has one sky; remove one"
                                ),
                            ));
                        }
                        if settings.background != glam::Vec3A::ZERO {
                            return Err(src.error(
                                at,
                                format!(
                                    "a scene with an Environment light has a background of \
                                     {:?} (here or in a base scene): the environment is what \
                                     rays leaving the scene see; remove the `background` or make \
                                     it black (a constant sky is `Environment(radiance: ...)`)",
                                    settings.background.to_array()
                                ),
                            ));
                        }
                        // Radiance within the range of every other input.
                        let peak = match &env.sky {
                            Sky::Uniform(l) => l.max_element() as f64,
                            Sky::Map { map, .. } => map.max_radiance(),
                        } * env.scale as f64;
                        if peak > MAX_RADIANCE {
                            return Err(src.error(
                                place("light", Some("scale")),
                                format!(
                                    "this sky's brightest radiance times its scale is {peak:e}, \
                                     above the limit of 1e30: lower the scale"
                                ),
                            ));
                        }
                        let (line, col) = line_col(&src.text, at);
                        sky_at = Some(format!("{}:{line}:{col}", src.name));
                        b.add(env);
                    }
                }
            }
            if let Some(emitter) = &e.emitter {
                b.add(emitter.to_world());
                let dir = src.dir.as_deref();
                let texture = emitter
                    .texture(&mut |path, raw| load_image(&mut images, &mut files, dir, path, raw))
                    .map_err(|why| src.error(place("emitter", Some("radiance")), why))?;
                if let Some(t) = texture {
                    // An image's brightest texel is the light's brightest radiance.
                    if let crate::texture::TextureKind::Image(i) = &t.0.kind {
                        let peak = i
                            .raster
                            .texels
                            .iter()
                            .flatten()
                            .fold(0.0f32, |m, &c| m.max(c));
                        if f64::from(peak) > MAX_RADIANCE {
                            return Err(src.error(
                                place("emitter", Some("radiance")),
                                format!(
                                    "this image's brightest texel is {peak:e}, above the limit \
                                     of 1e30 for a radiance"
                                ),
                            ));
                        }
                    }
                    b.add(t);
                }
            }
            match &e.material {
                Some(MaterialDesc::Named(n)) => match self.materials.get(n) {
                    Some((m, desc, tidx)) => {
                        let at = place("material", Some("Named"));
                        bsdf_allowed(m, &settings).map_err(|why| src.error(at, why))?;
                        // Its images, relative to the file whose table wrote it.
                        let dir = self.sources[*tidx].dir.as_deref();
                        let textures = desc
                            .textures(&mut |path, raw| {
                                load_image(&mut images, &mut files, dir, path, raw)
                            })
                            .map_err(|why| {
                                src.error(at, format!("material \"{}\": {why}", clip(n, 60)))
                            })?;
                        b.add(*m);
                        b.add(MaterialName(n.clone()));
                        if !textures.is_empty() {
                            b.add(textures);
                        }
                    }
                    None => {
                        let known: Vec<_> =
                            self.materials.keys().map(|k| format!("\"{k}\"")).collect();
                        let list = if known.is_empty() {
                            "the scene declares no materials".to_string()
                        } else {
                            format!("known materials: {}", known.join(", "))
                        };
                        return Err(src.error(
                            place("material", None),
                            format!("unknown material \"{}\"; {list}", clip(n, 60)),
                        ));
                    }
                },
                Some(desc) => {
                    let at = place("material", None);
                    if let Some(m) = desc
                        .to_world()
                        .and_then(|m| match m {
                            Some(m) => bsdf_allowed(&m, &settings).map(|()| Some(m)),
                            None => Ok(None),
                        })
                        .map_err(|why| src.error(at, why))?
                    {
                        let dir = src.dir.as_deref();
                        let textures = desc
                            .textures(&mut |path, raw| {
                                load_image(&mut images, &mut files, dir, path, raw)
                            })
                            .map_err(|why| src.error(at, why))?;
                        b.add(m);
                        if !textures.is_empty() {
                            b.add(textures);
                        }
                    }
                }
                // An emitter without a material reflects nothing.
                None if e.emitter.is_some() => {
                    b.add(Material::Phong(crate::material::Phong {
                        kd: glam::Vec3A::ZERO,
                        ks: glam::Vec3A::ZERO,
                        shininess: 1.0,
                    }));
                }
                None => {}
            }
            world.spawn(b.build());
        }
        if self.entities.is_empty() {
            warnings.push("the scene has no entities: every pixel shows the background".into());
        }
        warnings.extend(self.silent_mistakes(&settings));
        Ok(Scene {
            world,
            settings,
            origin,
            warnings,
            files,
        })
    }
}

/// Whether the settings can render `m`: a material given by its BSDF (rough materials and
/// plastics) needs the Physical model, and a shader other than Global, whose Eq. 1-4 are
/// defined for Phong, mirrors and glass only.
fn bsdf_allowed(m: &Material, settings: &Settings) -> Result<(), String> {
    let Material::Bsdf(b) = m else {
        return Ok(());
    };
    let name = b.name();
    if matches!(settings.shader, Shader::Global(_)) {
        return Err(format!(
            "{name} cannot be rendered by the Global shader, whose Eq. 1-4 are defined for \
             Phong, mirrors and glass: use `shader: Path()` or `shader: Direct()`"
        ));
    }
    if settings.model != crate::material::Model::Physical {
        return Err(format!(
            "{name} needs `model: Physical`: the course's model weighs Phong, mirrors and \
             glass only"
        ));
    }
    Ok(())
}

/// The texels of the image at `path` (relative to `dir`), decoded from sRGB unless `raw`: read
/// once per scene, whatever the number of textures that name it (`images` holds those read, and
/// `files` gains each file read, for `rtis watch`).
fn load_image(
    images: &mut BTreeMap<(PathBuf, bool), Arc<Raster>>,
    files: &mut Vec<PathBuf>,
    dir: Option<&Path>,
    path: &str,
    raw: bool,
) -> Result<(Arc<Raster>, PathBuf), String> {
    let file = dir.unwrap_or(Path::new("")).join(path);
    let absolute = std::path::absolute(&file).unwrap_or(file.clone());
    let key = (absolute.clone(), raw);
    if let Some(r) = images.get(&key) {
        return Ok((r.clone(), absolute));
    }
    files.push(file.clone());
    let r = Arc::new(crate::raster::load_with(&file, raw)?);
    images.insert(key, r.clone());
    Ok((r, absolute))
}

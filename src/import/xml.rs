//! Mitsuba 3's XML scene format read into a tree of plugin objects, each property and object
//! with the file, line and column it was written at: `<default>` values and `$name`
//! substitution, `<include>` (a cycle is an error), `<ref id>` to objects declared with an
//! `id`, and nested transforms (`translate`, `rotate`, `scale`, `matrix`, `lookat`), composed
//! as Mitsuba composes them (each applied after the ones above it).

use crate::scene::SceneError;
use glam::{DMat4, DVec3};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Where something is written: the file as the user named it, its text (for the excerpt), and
/// a 1-based line and column.
#[derive(Clone, Debug)]
pub struct Pos {
    /// The file's name.
    pub file: Rc<str>,
    /// Its text.
    pub text: Rc<str>,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub col: usize,
}

impl Pos {
    /// An error here.
    pub fn error(&self, message: impl Into<String>) -> SceneError {
        SceneError::at(&self.file, &self.text, self.line, self.col, message)
    }
}

/// A property's value as written.
#[derive(Clone, Debug)]
pub enum Value {
    /// `<float>`.
    Float(f64),
    /// `<integer>`.
    Integer(i64),
    /// `<boolean>`.
    Boolean(bool),
    /// `<string>`.
    String(String),
    /// `<rgb>`, `<srgb>` (already linear) or `<spectrum>` (converted to linear RGB).
    Color(DVec3),
    /// `<point>` or `<vector>`.
    Vector(DVec3),
    /// `<transform>`: the composed matrix.
    Transform(DMat4),
    /// A nested or referenced object (a texture, a BSDF, ...).
    Object(Rc<Object>),
}

impl Value {
    /// What a property of this kind is called in messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Float(_) => "a float",
            Value::Integer(_) => "an integer",
            Value::Boolean(_) => "a boolean",
            Value::String(_) => "a string",
            Value::Color(_) => "a colour",
            Value::Vector(_) => "a point or vector",
            Value::Transform(_) => "a transform",
            Value::Object(_) => "an object",
        }
    }
}

/// A property: its value and where it is written.
#[derive(Clone, Debug)]
pub struct Property {
    /// The value.
    pub value: Value,
    /// Where.
    pub pos: Pos,
}

/// A plugin object: `<tag type="kind" id="...">` with its properties (by name) and unnamed
/// nested objects, in the order written.
#[derive(Clone, Debug)]
pub struct Object {
    /// The element: `sensor`, `shape`, `bsdf`, `emitter`, `texture`, ...
    pub tag: String,
    /// Its `type` attribute.
    pub kind: String,
    /// Its `id`, if it has one.
    pub id: Option<String>,
    /// Named properties (a nested object with a `name` is one too).
    pub props: BTreeMap<String, Property>,
    /// Nested objects without a name (a shape's BSDF and emitter, a sensor's film).
    pub children: Vec<Rc<Object>>,
    /// Where its element starts.
    pub pos: Pos,
}

/// The scene file's top level: its version and its objects in order.
#[derive(Debug)]
pub struct Document {
    /// The `version` attribute of `<scene>`, as `(major, minor, patch)`.
    pub version: (u32, u32, u32),
    /// Top-level objects (declared ones with an `id` included).
    pub objects: Vec<Rc<Object>>,
    /// The folder of the top file, against which file names resolve.
    pub dir: PathBuf,
}

/// Most nested includes followed before giving up.
const MAX_INCLUDE_DEPTH: usize = 32;
/// Most nested elements read (objects within objects; a scene needs a handful).
const MAX_NESTING: usize = 64;

/// The reading state: defaults, declared objects by id, and the chain of files being read.
struct Reader {
    defaults: BTreeMap<String, String>,
    ids: BTreeMap<String, Rc<Object>>,
    chain: Vec<PathBuf>,
    /// The folder of the file being read (includes are relative to it).
    here: PathBuf,
}

/// Read the Mitsuba scene at `path`.
pub fn read(path: &Path) -> Result<Document, SceneError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::whole_file(&name, format!("cannot read scene file: {e}")))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut reader = Reader {
        defaults: BTreeMap::new(),
        ids: BTreeMap::new(),
        chain: path.canonicalize().into_iter().collect(),
        here: dir.clone(),
    };
    let mut objects = Vec::new();
    let version = reader.file(&name, &text, &mut objects, true)?;
    Ok(Document {
        version,
        objects,
        dir,
    })
}

/// Read the Mitsuba scene in `text` (named `name`, its files relative to `dir`).
pub fn read_str(text: &str, name: &str, dir: &Path) -> Result<Document, SceneError> {
    let mut reader = Reader {
        defaults: BTreeMap::new(),
        ids: BTreeMap::new(),
        chain: Vec::new(),
        here: dir.to_path_buf(),
    };
    let mut objects = Vec::new();
    let version = reader.file(name, text, &mut objects, true)?;
    Ok(Document {
        version,
        objects,
        dir: dir.to_path_buf(),
    })
}

/// The parts of a version string `"3.0.0"` (missing parts 0).
fn version(v: &str) -> Option<(u32, u32, u32)> {
    let mut parts = v.trim().split('.').map(|p| p.parse::<u32>());
    let major = parts.next()?.ok()?;
    let minor = parts.next().unwrap_or(Ok(0)).ok()?;
    let patch = parts.next().unwrap_or(Ok(0)).ok()?;
    Some((major, minor, patch))
}

impl Reader {
    /// Read one file's `<scene>` into `objects`; its version.
    fn file(
        &mut self,
        name: &str,
        text: &str,
        objects: &mut Vec<Rc<Object>>,
        top: bool,
    ) -> Result<(u32, u32, u32), SceneError> {
        let file: Rc<str> = name.into();
        let src: Rc<str> = text.into();
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            let p = e.pos();
            SceneError::at(
                name,
                text,
                p.row as usize,
                p.col as usize,
                format!("malformed XML: {e}"),
            )
        })?;
        let at = |node: roxmltree::Node| {
            let p = doc.text_pos_at(node.range().start);
            Pos {
                file: file.clone(),
                text: src.clone(),
                line: p.row as usize,
                col: p.col as usize,
            }
        };
        let root = doc.root_element();
        if root.tag_name().name() != "scene" {
            return Err(at(root).error(format!(
                "expected `<scene version=\"3.0.0\">`, found `<{}>`",
                root.tag_name().name()
            )));
        }
        let v = match root.attribute("version") {
            Some(v) => version(v).ok_or_else(|| {
                at(root).error(format!(
                    "`version=\"{v}\"` is not a version such as \"3.0.0\""
                ))
            })?,
            None if top => {
                return Err(at(root).error(
                    "`<scene>` needs a `version` attribute, as `<scene version=\"3.0.0\">`",
                ));
            }
            None => (3, 0, 0),
        };
        if v.0 > 3 {
            return Err(at(root).error(format!(
                "version {}.{}.{}: rtis reads Mitsuba scenes up to version 3.x",
                v.0, v.1, v.2
            )));
        }
        // A scene older than 2.0 is upgraded as Mitsuba 3 upgrades it.
        let cx = Cx {
            at: &at,
            upgrade: v.0 < 2,
        };
        for node in root.children().filter(roxmltree::Node::is_element) {
            match node.tag_name().name() {
                "default" => {
                    let (name, value) = (
                        self.need(&cx, node, "name")?,
                        self.need(&cx, node, "value")?,
                    );
                    // A default applies unless one is already set (by an enclosing file).
                    self.defaults.entry(name).or_insert(value);
                }
                "include" => {
                    let f = self.attr(&cx, node, "filename")?.ok_or_else(|| {
                        at(node).error("`<include>` needs a `filename` attribute")
                    })?;
                    // Relative to the including file's folder, as Mitsuba 3 resolves it.
                    let path = self.here.join(&f);
                    let canon = path.canonicalize().map_err(|e| {
                        at(node).error(format!("cannot read included file {f}: {e}"))
                    })?;
                    if self.chain.contains(&canon) {
                        return Err(at(node).error(format!(
                            "{f} includes itself (through {}): an include cycle",
                            self.chain
                                .iter()
                                .map(|p| p.display().to_string())
                                .collect::<Vec<_>>()
                                .join(" -> ")
                        )));
                    }
                    if self.chain.len() >= MAX_INCLUDE_DEPTH {
                        return Err(at(node).error("includes nested more than 32 deep"));
                    }
                    let inner = std::fs::read_to_string(&path).map_err(|e| {
                        at(node).error(format!("cannot read included file {f}: {e}"))
                    })?;
                    self.chain.push(canon);
                    let outer = std::mem::replace(
                        &mut self.here,
                        path.parent().map(Path::to_path_buf).unwrap_or_default(),
                    );
                    let read = self.file(&path.display().to_string(), &inner, objects, false);
                    self.here = outer;
                    read?;
                    self.chain.pop();
                }
                _ => {
                    let object = self.object(&cx, node, "scene")?;
                    match object {
                        Item::Object(o) => objects.push(o),
                        Item::Property(name, p) => {
                            return Err(p.pos.error(format!(
                                "a property (`{name}`) at the top level of the scene: \
                                 properties belong inside an object"
                            )));
                        }
                    }
                }
            }
        }
        Ok(v)
    }

    /// The value of attribute `name` of `node`, `$names` replaced by their defaults.
    fn attr(
        &self,
        cx: &Cx,
        node: roxmltree::Node,
        name: &str,
    ) -> Result<Option<String>, SceneError> {
        let Some(raw) = node.attribute(name) else {
            return Ok(None);
        };
        self.substitute(raw).map(Some).map_err(|v| {
            (cx.at)(node).error(format!(
                "`${v}` in `{name}=\"{raw}\"` has no value: declare it with `<default \
                 name=\"{v}\" value=\"...\"/>`"
            ))
        })
    }

    /// Attribute `name`, required.
    fn need(&self, cx: &Cx, node: roxmltree::Node, name: &str) -> Result<String, SceneError> {
        self.attr(cx, node, name)?.ok_or_else(|| {
            (cx.at)(node).error(format!(
                "`<{}>` needs a `{name}` attribute",
                node.tag_name().name()
            ))
        })
    }

    /// `text` with each `$name` replaced by its default; the first name without one.
    fn substitute(&self, text: &str) -> Result<String, String> {
        let mut out = String::new();
        let mut rest = text;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            match self.defaults.get(name) {
                Some(v) if !name.is_empty() => out.push_str(v),
                _ => return Err(name.to_string()),
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// An object element or a property element.
    fn object(&mut self, cx: &Cx, node: roxmltree::Node, parent: &str) -> Result<Item, SceneError> {
        let tag = node.tag_name().name();
        let pos = (cx.at)(node);
        // Elements nested deeper than any scene needs (and than the stack allows) are refused.
        if node.ancestors().count() > MAX_NESTING {
            return Err(pos.error(format!(
                "`<{tag}>` is nested more than {MAX_NESTING} elements deep"
            )));
        }
        let name = self
            .attr(cx, node, "name")?
            .map(|n| if cx.upgrade { snake_case(&n) } else { n });
        let named = |value: Value| -> Result<Item, SceneError> {
            let name = name
                .clone()
                .ok_or_else(|| pos.error(format!("`<{tag}>` needs a `name` attribute")))?;
            Ok(Item::Property(
                name,
                Property {
                    value,
                    pos: pos.clone(),
                },
            ))
        };
        let value = |me: &Self| me.need(cx, node, "value");
        match tag {
            "float" => named(Value::Float(number(&value(self)?, &pos)?)),
            "integer" => {
                let v = value(self)?;
                let i = v
                    .trim()
                    .parse::<i64>()
                    .map_err(|_| pos.error(format!("`value=\"{v}\"` is not an integer")))?;
                named(Value::Integer(i))
            }
            "boolean" => {
                let v = value(self)?;
                let b = match v.trim().to_ascii_lowercase().as_str() {
                    "true" => true,
                    "false" => false,
                    _ => return Err(pos.error(format!("`value=\"{v}\"` is not `true` or `false`"))),
                };
                named(Value::Boolean(b))
            }
            "string" => named(Value::String(value(self)?)),
            "rgb" | "color" => named(Value::Color(rgb(&value(self)?, &pos)?)),
            "srgb" => {
                let c = rgb(&value(self)?, &pos)?;
                named(Value::Color(
                    c.map(|x| crate::raster::srgb_to_linear(x as f32) as f64),
                ))
            }
            "spectrum" => {
                use super::spectrum::{Role, to_rgb};
                let role = match (parent, name.as_deref()) {
                    ("emitter", _) => Role::Emitter,
                    (_, Some("eta" | "k" | "int_ior" | "ext_ior")) => Role::Unbounded,
                    _ => Role::Bounded,
                };
                let color = to_rgb(&value(self)?, role).map_err(|why| pos.error(why))?;
                named(Value::Color(color))
            }
            "point" | "vector" => named(Value::Vector(self.vector(cx, node, 0.0)?)),
            "transform" => named(Value::Transform(self.transform(cx, node)?)),
            "ref" => {
                let id = self.need(cx, node, "id")?;
                let object = self.ids.get(&id).cloned().ok_or_else(|| {
                    let known: Vec<&str> = self.ids.keys().map(String::as_str).collect();
                    pos.error(format!(
                        "`<ref id=\"{id}\">`: no object has that id (declared before it: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ))
                })?;
                Ok(Item::of(name, object, pos))
            }
            "sensor" | "film" | "sampler" | "rfilter" | "integrator" | "shape" | "bsdf"
            | "emitter" | "texture" | "medium" | "phase" | "volume" => {
                let kind = self.need(cx, node, "type")?;
                let id = self.attr(cx, node, "id")?;
                let mut object = Object {
                    tag: tag.to_string(),
                    kind,
                    id: id.clone(),
                    props: BTreeMap::new(),
                    children: Vec::new(),
                    pos: pos.clone(),
                };
                for child in node.children().filter(roxmltree::Node::is_element) {
                    match self.object(cx, child, tag)? {
                        Item::Property(n, p) => {
                            if let Some(first) = object.props.get(&n) {
                                return Err(p.pos.error(format!(
                                    "`{n}` is given twice in this `<{tag}>` (first at line {})",
                                    first.pos.line
                                )));
                            }
                            object.props.insert(n, p);
                        }
                        Item::Object(o) => object.children.push(o),
                    }
                }
                if cx.upgrade {
                    upgrade(&mut object);
                }
                let object = Rc::new(object);
                if let Some(id) = id {
                    self.ids.insert(id, object.clone());
                }
                Ok(Item::of(name, object, pos))
            }
            other => Err(pos.error(format!(
                "`<{other}>` is not an element of Mitsuba's scene format (objects: sensor, film, \
                 sampler, rfilter, integrator, shape, bsdf, emitter, texture; properties: float, \
                 integer, boolean, string, rgb, srgb, spectrum, point, vector, transform, ref)"
            ))),
        }
    }

    /// A `<point>`, `<vector>` or a transform step's `value="x, y, z"` or `x=`, `y=`, `z=`
    /// (each missing one `missing`).
    fn vector(&self, cx: &Cx, node: roxmltree::Node, missing: f64) -> Result<DVec3, SceneError> {
        let pos = (cx.at)(node);
        if let Some(v) = self.attr(cx, node, "value")? {
            return triple(&v, &pos);
        }
        let mut c = [missing; 3];
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            if let Some(v) = self.attr(cx, node, axis)? {
                c[i] = number(&v, &pos)?;
            }
        }
        Ok(DVec3::from_array(c))
    }

    /// A `<transform>`: its steps composed, each applied after the previous (Mitsuba
    /// left-multiplies each step).
    fn transform(&self, cx: &Cx, node: roxmltree::Node) -> Result<DMat4, SceneError> {
        let mut m = DMat4::IDENTITY;
        for step in node.children().filter(roxmltree::Node::is_element) {
            let pos = (cx.at)(step);
            let s = match step.tag_name().name() {
                "translate" => DMat4::from_translation(self.vector(cx, step, 0.0)?),
                "scale" => {
                    let v = match self.attr(cx, step, "value")? {
                        // One number scales uniformly.
                        Some(v) if !v.contains(',') && !v.trim().contains(' ') => {
                            DVec3::splat(number(&v, &pos)?)
                        }
                        _ => self.vector(cx, step, 1.0)?,
                    };
                    DMat4::from_scale(v)
                }
                "rotate" => {
                    let axis = self.vector(cx, step, 0.0)?;
                    let angle = self
                        .attr(cx, step, "angle")?
                        .map(|a| number(&a, &pos))
                        .transpose()?
                        .unwrap_or(0.0);
                    let axis = axis.try_normalize().ok_or_else(|| {
                        pos.error("`<rotate>` needs an axis: `x=\"1\"`, `y=\"1\"` or `z=\"1\"`")
                    })?;
                    DMat4::from_axis_angle(axis, angle.to_radians())
                }
                "matrix" => {
                    let v = self.need(cx, step, "value")?;
                    let n = numbers(&v, &pos)?;
                    match n.len() {
                        16 => {
                            DMat4::from_cols_array(&n.try_into().unwrap_or([0.0; 16])).transpose()
                        }
                        9 => {
                            let m3 =
                                glam::DMat3::from_cols_array(&n.try_into().unwrap_or([0.0; 9]))
                                    .transpose();
                            DMat4::from_mat3(m3)
                        }
                        k => {
                            return Err(pos.error(format!(
                                "`<matrix>` takes 16 numbers (4x4, row by row) or 9 (3x3), found {k}"
                            )));
                        }
                    }
                }
                "lookat" | "lookAt" => {
                    let o = triple(&self.need(cx, step, "origin")?, &pos)?;
                    let t = triple(&self.need(cx, step, "target")?, &pos)?;
                    // Without `up` (or a zero one), Mitsuba's `coordinate_system` of the view:
                    // Duff et al.'s first tangent.
                    let up = match self.attr(cx, step, "up")? {
                        Some(u) => triple(&u, &pos)?,
                        None => DVec3::ZERO,
                    };
                    let up = if up == DVec3::ZERO {
                        (t - o).normalize_or(DVec3::Z).any_orthonormal_pair().0
                    } else {
                        up
                    };
                    look_at(o, t, up).ok_or_else(|| {
                        pos.error(
                            "`<lookat>`: the target equals the origin, or `up` is parallel to \
                             the view",
                        )
                    })?
                }
                other => {
                    return Err(pos.error(format!(
                        "`<{other}>` is not a transform step (translate, rotate, scale, \
                         matrix, lookat)"
                    )));
                }
            };
            m = s * m;
        }
        if !m.is_finite() {
            return Err((cx.at)(node).error("this transform is not finite"));
        }
        Ok(m)
    }
}

/// What an element is: a property with its name, or an unnamed object.
enum Item {
    Property(String, Property),
    Object(Rc<Object>),
}

impl Item {
    /// An object written at `pos`: a property if it has a `name`, else unnamed.
    fn of(name: Option<String>, object: Rc<Object>, pos: Pos) -> Item {
        match name {
            Some(n) => Item::Property(
                n,
                Property {
                    value: Value::Object(object),
                    pos,
                },
            ),
            None => Item::Object(object),
        }
    }
}

/// Per-file context: the position of a node, and whether the file is older than 2.0 (its
/// properties upgraded as Mitsuba 3's parser upgrades them: `camelCase` names become
/// `snake_case`, a `diffuse` BSDF's `diffuse_reflectance` its `reflectance`, `uoffset`,
/// `voffset`, `uscale` and `vscale` a `to_uv` transform, and `<lookAt>` is `<lookat>`).
struct Cx<'a> {
    at: &'a dyn Fn(roxmltree::Node) -> Pos,
    upgrade: bool,
}

/// Mitsuba's `camel_to_underscore_case`: `intIOR` is `int_ior`, `sampleCount` `sample_count`.
fn snake_case(name: &str) -> String {
    let c: Vec<char> = name.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < c.len() {
        if i > 0 && c[i - 1].is_lowercase() && c[i].is_uppercase() {
            out.push('_');
            out.extend(c[i].to_lowercase());
            while i + 1 < c.len() && c[i + 1].is_uppercase() {
                i += 1;
                out.extend(c[i].to_lowercase());
            }
        } else {
            out.push(c[i]);
        }
        i += 1;
    }
    out
}

/// A 0.x object's properties upgraded (see [`Cx`]).
fn upgrade(object: &mut Object) {
    if object.kind == "diffuse"
        && let Some(p) = object.props.remove("diffuse_reflectance")
    {
        object.props.insert("reflectance".into(), p);
    }
    let mut offset = DVec3::ZERO;
    let mut scale = DVec3::ONE;
    let mut pos = None;
    for (name, axis, is_scale) in [
        ("uoffset", 0, false),
        ("voffset", 1, false),
        ("uscale", 0, true),
        ("vscale", 1, true),
    ] {
        if let Some(p) = object.props.remove(name) {
            let v = match p.value {
                Value::Float(x) => x,
                Value::Integer(i) => i as f64,
                _ => continue,
            };
            if is_scale {
                scale[axis] = v;
            } else {
                offset[axis] = v;
            }
            pos = Some(p.pos);
        }
    }
    if let Some(pos) = pos {
        let m = DMat4::from_scale(scale) * DMat4::from_translation(offset);
        object.props.insert(
            "to_uv".into(),
            Property {
                value: Value::Transform(m),
                pos,
            },
        );
    }
}

/// Mitsuba's `look_at`: camera space to world, its `x` axis `up x dir` (the image's left),
/// `y` the true up, `z` the view direction.
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - origin).try_normalize()?;
    let left = up.cross(dir).try_normalize()?;
    let new_up = dir.cross(left);
    Some(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

/// A number, finite.
pub fn number(v: &str, pos: &Pos) -> Result<f64, SceneError> {
    super::spectrum::number(v).map_err(|why| pos.error(why))
}

/// Numbers separated by commas and/or spaces.
fn numbers(v: &str, pos: &Pos) -> Result<Vec<f64>, SceneError> {
    v.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| number(s, pos))
        .collect()
}

/// Three numbers.
fn triple(v: &str, pos: &Pos) -> Result<DVec3, SceneError> {
    let n = numbers(v, pos)?;
    match n[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(pos.error(format!("`{v}`: expected three numbers `x, y, z`"))),
    }
}

/// An RGB value: three numbers, or one for grey.
fn rgb(v: &str, pos: &Pos) -> Result<DVec3, SceneError> {
    let n = numbers(v, pos)?;
    match n[..] {
        [g] => Ok(DVec3::splat(g)),
        [r, g, b] => Ok(DVec3::new(r, g, b)),
        _ => Err(pos.error(format!(
            "`{v}`: a colour is three numbers `r, g, b` (or one, for grey)"
        ))),
    }
}

//! Mitsuba 3 plugins written as rtis scene text: the sensor and its film and sampler, the
//! integrator, shapes with their BSDFs and area emitters, the other emitters, and textures.
//! A plugin or a property rtis cannot render is refused at its place, naming it and saying
//! what rtis supports; nothing is dropped silently. `docs/import.md` lists the subset.

use super::xml::{Document, Object, Pos, Property, Value};
use crate::scene::SceneError;
use glam::{DMat4, DVec3};
use std::collections::BTreeSet;
use std::fmt::Write;
use std::path::Path;
use std::rc::Rc;

/// The scene as rtis text, and the warnings of the conversion.
pub struct Converted {
    /// The rtis scene file.
    pub text: String,
    /// What was approximated (each names its place).
    pub warnings: Vec<String>,
}

/// A number rounded to 12 significant digits (far below single precision, which renders it;
/// `0.9999999999999999` reads `1.0`), as RON reads it.
fn num(v: f64) -> String {
    let r: f64 = format!("{v:.11e}").parse().unwrap_or(v);
    let r = if r == 0.0 { 0.0 } else { r };
    format!("{r:?}")
}

/// A vector, its components below 1e-12 of its largest rounded to 0 (`1e-16` left by a
/// rotation's cosine).
fn vec3(v: DVec3) -> String {
    let big = v.abs().max_element();
    let c = v
        .to_array()
        .map(|x| if x.abs() < 1e-12 * big { 0.0 } else { x });
    format!("({}, {}, {})", num(c[0]), num(c[1]), num(c[2]))
}

/// A string as RON reads it.
fn string(s: &str) -> String {
    format!("{s:?}")
}

/// An object's properties, each read at most once; those left unread are refused at the end
/// ([`Props::done`]), so that nothing is dropped silently.
struct Props<'a> {
    object: &'a Object,
    read: BTreeSet<&'a str>,
    paths: &'a Paths,
}

impl<'a> Props<'a> {
    fn new(object: &'a Object, paths: &'a Paths) -> Self {
        Props {
            object,
            read: BTreeSet::new(),
            paths,
        }
    }

    fn get(&mut self, name: &'a str) -> Option<&'a Property> {
        let p = self.object.props.get(name)?;
        self.read.insert(name);
        Some(p)
    }

    fn wrong(&self, name: &str, p: &Property, want: &str) -> SceneError {
        p.pos.error(format!(
            "`{name}` of `{}` takes {want}, not {}",
            self.object.kind,
            p.value.kind()
        ))
    }

    fn float(&mut self, name: &'a str, default: f64) -> Result<f64, SceneError> {
        match self.get(name) {
            None => Ok(default),
            Some(Property {
                value: Value::Float(x),
                ..
            }) => Ok(*x),
            Some(Property {
                value: Value::Integer(i),
                ..
            }) => Ok(*i as f64),
            Some(p) => Err(self.wrong(name, p, "a float")),
        }
    }

    fn integer(&mut self, name: &'a str, default: i64) -> Result<i64, SceneError> {
        match self.get(name) {
            None => Ok(default),
            Some(Property {
                value: Value::Integer(i),
                ..
            }) => Ok(*i),
            Some(p) => Err(self.wrong(name, p, "an integer")),
        }
    }

    fn boolean(&mut self, name: &'a str, default: bool) -> Result<bool, SceneError> {
        match self.get(name) {
            None => Ok(default),
            Some(Property {
                value: Value::Boolean(b),
                ..
            }) => Ok(*b),
            Some(p) => Err(self.wrong(name, p, "a boolean")),
        }
    }

    fn string(&mut self, name: &'a str) -> Result<Option<(String, Pos)>, SceneError> {
        match self.get(name) {
            None => Ok(None),
            Some(Property {
                value: Value::String(s),
                pos,
            }) => Ok(Some((s.clone(), pos.clone()))),
            Some(p) => Err(self.wrong(name, p, "a string")),
        }
    }

    /// A string naming one of a closed set, in lower case (Mitsuba's are case-insensitive).
    fn keyword(&mut self, name: &'a str) -> Result<Option<(String, Pos)>, SceneError> {
        Ok(self
            .string(name)?
            .map(|(s, pos)| (s.to_ascii_lowercase(), pos)))
    }

    fn vector(&mut self, name: &'a str) -> Result<Option<DVec3>, SceneError> {
        match self.get(name) {
            None => Ok(None),
            Some(Property {
                value: Value::Vector(v),
                ..
            }) => Ok(Some(*v)),
            Some(p) => Err(self.wrong(name, p, "a point or vector")),
        }
    }

    fn transform(&mut self, name: &'a str) -> Result<DMat4, SceneError> {
        match self.get(name) {
            None => Ok(DMat4::IDENTITY),
            Some(Property {
                value: Value::Transform(m),
                ..
            }) => Ok(*m),
            Some(p) => Err(self.wrong(name, p, "a transform")),
        }
    }

    /// A colour property: a constant colour, or (with `textures`) a texture.
    fn color(
        &mut self,
        name: &'a str,
        default: Option<DVec3>,
        textures: bool,
    ) -> Result<Option<String>, SceneError> {
        match self.get(name) {
            None => Ok(default.map(vec3)),
            Some(Property {
                value: Value::Color(c),
                ..
            }) => Ok(Some(vec3(*c))),
            Some(Property {
                value: Value::Float(x),
                ..
            }) => Ok(Some(vec3(DVec3::splat(*x)))),
            Some(Property {
                value: Value::Object(t),
                ..
            }) if textures && t.tag == "texture" => texture(t, self.paths).map(Some),
            Some(p) => Err(self.wrong(
                name,
                p,
                if textures {
                    "a colour or a texture"
                } else {
                    "a colour"
                },
            )),
        }
    }

    /// A roughness: a float, or a texture.
    fn roughness(&mut self, name: &'a str) -> Result<Option<String>, SceneError> {
        match self.get(name) {
            None => Ok(None),
            Some(Property {
                value: Value::Float(x),
                ..
            }) => Ok(Some(num(*x))),
            Some(Property {
                value: Value::Object(t),
                ..
            }) if t.tag == "texture" => texture(t, self.paths).map(Some),
            Some(p) => Err(self.wrong(name, p, "a float or a texture")),
        }
    }

    /// Refuse any property not read.
    fn done(self) -> Result<(), SceneError> {
        for (name, p) in &self.object.props {
            if !self.read.contains(name.as_str()) {
                let e = p.pos.error(format!(
                    "`{name}` of `<{} type=\"{}\">` is not supported by rtis's import \
                     (docs/import.md lists what is)",
                    self.object.tag, self.object.kind
                ));
                match &self.paths.skipped {
                    Some(skipped) => skipped.borrow_mut().push(format!("skipped: {}", head(&e))),
                    None => return Err(e),
                }
            }
        }
        Ok(())
    }
}

/// The first line of an error: `file:line:col: message`.
fn head(e: &SceneError) -> String {
    e.to_string().lines().next().unwrap_or_default().to_string()
}

/// Refuse `object` as a plugin rtis does not render.
fn unsupported(object: &Object, what: &str) -> SceneError {
    object.pos.error(format!(
        "`<{} type=\"{}\">` is not supported by rtis's import; supported {what} \
         (docs/import.md)",
        object.tag, object.kind
    ))
}

/// A texture object as rtis text.
fn texture(t: &Object, paths: &Paths) -> Result<String, SceneError> {
    let mut p = Props::new(t, paths);
    let uv = uv_transform(&mut p)?;
    let text = match t.kind.as_str() {
        "bitmap" => {
            let (file, _) = p
                .string("filename")?
                .ok_or_else(|| t.pos.error("a `bitmap` needs a `filename`"))?;
            let filter = match p.keyword("filter_type")? {
                None => "Bilinear",
                Some((f, _)) if f == "bilinear" => "Bilinear",
                Some((f, _)) if f == "nearest" => "Nearest",
                Some((f, pos)) => {
                    return Err(pos.error(format!(
                        "`filter_type` \"{f}\": rtis has \"bilinear\" and \"nearest\""
                    )));
                }
            };
            let wrap = match p.keyword("wrap_mode")? {
                None => "Repeat",
                Some((w, _)) if w == "repeat" => "Repeat",
                Some((w, _)) if w == "mirror" => "Mirror",
                Some((w, _)) if w == "clamp" => "Clamp",
                Some((w, pos)) => {
                    return Err(pos.error(format!(
                        "`wrap_mode` \"{w}\": rtis has \"repeat\", \"mirror\" and \"clamp\""
                    )));
                }
            };
            let raw = p.boolean("raw", false)?;
            format!(
                "Image(path: {}, filter: {filter}, wrap: {wrap}, raw: {raw}{uv})",
                string(&paths.path(&file))
            )
        }
        "checkerboard" => {
            let c0 = p.color("color0", Some(DVec3::splat(0.4)), false)?;
            let c1 = p.color("color1", Some(DVec3::splat(0.2)), false)?;
            format!(
                "Checkerboard(color0: {}, color1: {}{uv})",
                c0.unwrap_or_default(),
                c1.unwrap_or_default()
            )
        }
        _ => return Err(unsupported(t, "textures: bitmap, checkerboard")),
    };
    p.done()?;
    Ok(text)
}

/// A texture's `to_uv` as rtis's `uv_transform` (scale, rotation about the origin, offset),
/// or nothing for none.
fn uv_transform(p: &mut Props) -> Result<String, SceneError> {
    let Some(prop) = p.get("to_uv") else {
        return Ok(String::new());
    };
    let Value::Transform(m) = &prop.value else {
        return Err(p.wrong("to_uv", prop, "a transform"));
    };
    // The 2D affine part: u' = a u + b v + e, v' = c u + d v + f.
    let (a, c, b, d) = (m.x_axis.x, m.x_axis.y, m.y_axis.x, m.y_axis.y);
    let (e, f) = (m.w_axis.x, m.w_axis.y);
    // rtis: scale, then rotate by theta: [[cos, -sin], [sin, cos]] * diag(su, sv).
    let su = (a * a + c * c).sqrt();
    let sv = (b * b + d * d).sqrt();
    let theta = c.atan2(a);
    let (s, co) = theta.sin_cos();
    let rebuilt_b = -s * sv;
    let rebuilt_d = co * sv;
    if su == 0.0 || sv == 0.0 || (rebuilt_b - b).abs() > 1e-9 || (rebuilt_d - d).abs() > 1e-9 {
        return Err(prop.pos.error(
            "this `to_uv` shears or mirrors texture coordinates; rtis's uv_transform is a scale, \
             a rotation and an offset",
        ));
    }
    Ok(format!(
        ", uv_transform: (scale: ({}, {}), rotate: {}, offset: ({}, {}))",
        num(su),
        num(sv),
        num(theta.to_degrees()),
        num(e),
        num(f)
    ))
}

/// A BSDF object as an rtis material, and whether it is two-sided.
fn material(b: &Object, paths: &Paths) -> Result<String, SceneError> {
    let mut p = Props::new(b, paths);
    let distribution = |p: &mut Props| -> Result<&'static str, SceneError> {
        Ok(match p.keyword("distribution")? {
            // Mitsuba's default is Beckmann.
            None => "Beckmann",
            Some((d, _)) if d == "beckmann" => "Beckmann",
            Some((d, _)) if d == "ggx" => "Ggx",
            Some((d, pos)) => {
                return Err(pos.error(format!(
                    "`distribution` \"{d}\": rtis has \"beckmann\" and \"ggx\""
                )));
            }
        })
    };
    let sampling = |p: &mut Props| -> Result<&'static str, SceneError> {
        Ok(if p.boolean("sample_visible", true)? {
            "Visible"
        } else {
            "Full"
        })
    };
    let ior = |p: &mut Props, name: &'static str, default: f64| -> Result<f64, SceneError> {
        match p.get(name) {
            None => Ok(default),
            Some(Property {
                value: Value::Float(x),
                ..
            }) => Ok(*x),
            Some(Property {
                value: Value::String(s),
                pos,
            }) => named_ior(&s.to_ascii_lowercase()).ok_or_else(|| {
                pos.error(format!("`{name}` \"{s}\" is not an index Mitsuba names"))
            }),
            Some(prop) => Err(prop.pos.error(format!("`{name}` takes a float or a name"))),
        }
    };
    // A roughness: `alpha`, or `alpha_u` and `alpha_v`.
    let alpha = |p: &mut Props| -> Result<String, SceneError> {
        let a = p.roughness("alpha")?;
        let (u, v) = (p.roughness("alpha_u")?, p.roughness("alpha_v")?);
        Ok(match (a, u, v) {
            (None, Some(u), Some(v)) => format!("alpha_u: {u}, alpha_v: {v}"),
            (Some(a), None, None) => format!("alpha: {a}"),
            (None, None, None) => "alpha: 0.1".to_string(),
            (Some(_), ..) => {
                return Err(b.pos.error("`alpha` or `alpha_u` and `alpha_v`, not both"));
            }
            _ => {
                return Err(b
                    .pos
                    .error("`alpha_u` and `alpha_v` go together: give both"));
            }
        })
    };
    let metal = |p: &mut Props| -> Result<String, SceneError> {
        let named = p.string("material")?;
        let (eta, k) = (p.color("eta", None, false)?, p.color("k", None, false)?);
        Ok(match (named, eta, k) {
            (Some((_, pos)), Some(_), _) | (Some((_, pos)), _, Some(_)) => {
                return Err(
                    pos.error("a conductor takes a named `material` or `eta` and `k`, not both")
                );
            }
            (None, Some(eta), Some(k)) => format!("eta: {eta}, k: {k}"),
            (None, Some(_), None) | (None, None, Some(_)) => {
                return Err(b.pos.error(
                    "a conductor's `eta` and `k` go together here: give both (Mitsuba takes \
                     `k` as 1 when only `eta` is given; write `<rgb name=\"k\" value=\"1\"/>`)",
                ));
            }
            (Some((m, pos)), None, None) => {
                let known = ["Au", "Ag", "Al", "Cu", "Cr", "none"];
                if !known.contains(&m.as_str()) {
                    return Err(pos.error(format!(
                        "conductor `material` \"{m}\": rtis knows \"Au\", \"Ag\", \"Al\", \
                         \"Cu\", \"Cr\" and \"none\" (or give `eta` and `k`)"
                    )));
                }
                format!("material: {}", string(&m))
            }
            // Mitsuba's default conductor is "none", a perfect mirror.
            (None, None, None) => "material: \"none\"".to_string(),
        })
    };
    let text = match b.kind.as_str() {
        "twosided" => {
            // rtis's materials are all two-sided.
            p.done()?;
            let inner = single_child(b, "bsdf")?;
            return material(&inner, paths);
        }
        "diffuse" => {
            let kd = p.color("reflectance", Some(DVec3::splat(0.5)), true)?;
            format!("Phong(kd: {}, ks: (0, 0, 0))", kd.unwrap_or_default())
        }
        "conductor" => {
            let m = metal(&mut p)?;
            let s = p.color("specular_reflectance", Some(DVec3::ONE), true)?;
            format!(
                "Conductor({m}, specular_reflectance: {})",
                s.unwrap_or_default()
            )
        }
        "roughconductor" => {
            let (d, a, m) = (distribution(&mut p)?, alpha(&mut p)?, metal(&mut p)?);
            let s = p.color("specular_reflectance", Some(DVec3::ONE), true)?;
            let smp = sampling(&mut p)?;
            format!(
                "RoughConductor(distribution: {d}, {a}, {m}, specular_reflectance: {}, \
                 sampling: {smp})",
                s.unwrap_or_default()
            )
        }
        "dielectric" => {
            let (int, ext) = (
                ior(&mut p, "int_ior", 1.5046)?,
                ior(&mut p, "ext_ior", 1.000277)?,
            );
            let r = p.color("specular_reflectance", Some(DVec3::ONE), false)?;
            let t = p.color("specular_transmittance", Some(DVec3::ONE), false)?;
            if r != t {
                return Err(b.pos.error(
                    "a `dielectric` with different specular_reflectance and \
                     specular_transmittance: rtis's smooth glass has one tint (use \
                     `roughdielectric` with a small alpha for two)",
                ));
            }
            format!(
                "Transmissive(ior: {}, color: {})",
                num(int / ext),
                r.unwrap_or_default()
            )
        }
        "roughdielectric" => {
            let (d, a) = (distribution(&mut p)?, alpha(&mut p)?);
            let (int, ext) = (
                ior(&mut p, "int_ior", 1.5046)?,
                ior(&mut p, "ext_ior", 1.000277)?,
            );
            let r = p.color("specular_reflectance", Some(DVec3::ONE), true)?;
            let t = p.color("specular_transmittance", Some(DVec3::ONE), true)?;
            let smp = sampling(&mut p)?;
            format!(
                "RoughDielectric(distribution: {d}, {a}, int_ior: {}, ext_ior: {}, \
                 specular_reflectance: {}, specular_transmittance: {}, sampling: {smp})",
                num(int),
                num(ext),
                r.unwrap_or_default(),
                t.unwrap_or_default()
            )
        }
        "plastic" | "roughplastic" => {
            let rough = b.kind == "roughplastic";
            let head = if rough {
                let d = distribution(&mut p)?;
                let a = p.float("alpha", 0.1)?;
                let smp = sampling(&mut p)?;
                format!(
                    "RoughPlastic(distribution: {d}, alpha: {}, sampling: {smp}, ",
                    num(a)
                )
            } else {
                "Plastic(".to_string()
            };
            let (int, ext) = (
                ior(&mut p, "int_ior", 1.49)?,
                ior(&mut p, "ext_ior", 1.000277)?,
            );
            let kd = p.color("diffuse_reflectance", Some(DVec3::splat(0.5)), true)?;
            let ks = p.color("specular_reflectance", Some(DVec3::ONE), true)?;
            let nonlinear = p.boolean("nonlinear", false)?;
            format!(
                "{head}int_ior: {}, ext_ior: {}, diffuse_reflectance: {}, \
                 specular_reflectance: {}, nonlinear: {nonlinear})",
                num(int),
                num(ext),
                kd.unwrap_or_default(),
                ks.unwrap_or_default()
            )
        }
        "normalmap" => {
            let map = match p.get("normalmap") {
                Some(Property {
                    value: Value::Object(t),
                    ..
                }) if t.tag == "texture" => texture(t, paths)?,
                Some(prop) => return Err(p.wrong("normalmap", prop, "a texture")),
                None => return Err(b.pos.error("a `normalmap` needs a `normalmap` texture")),
            };
            let inner = material(&*single_child(b, "bsdf")?, paths)?;
            format!("NormalMap(normal_map: {map}, material: {inner})")
        }
        _ => {
            return Err(unsupported(
                b,
                "BSDFs: diffuse, conductor, roughconductor, dielectric, roughdielectric, \
                 plastic, roughplastic, twosided, normalmap",
            ));
        }
    };
    // An `id` is not a property; a nested BSDF (normalmap's) is read above, no other.
    p.done()?;
    children(
        b,
        if b.kind == "normalmap" {
            &["bsdf"]
        } else {
            &[]
        },
    )?;
    Ok(text)
}

/// Refuse a nested object of `o` that is not one of the `allowed` tags (it would be dropped).
fn children(o: &Object, allowed: &[&str]) -> Result<(), SceneError> {
    match o
        .children
        .iter()
        .find(|c| !allowed.contains(&c.tag.as_str()))
    {
        Some(c) => Err(c.pos.error(format!(
            "`<{} type=\"{}\">` inside `<{} type=\"{}\">` without a name: rtis does not \
             read it there",
            c.tag, c.kind, o.tag, o.kind
        ))),
        None => Ok(()),
    }
}

/// The one nested object of `parent` with tag `tag` (a `twosided`'s BSDF).
fn single_child(parent: &Object, tag: &str) -> Result<Rc<Object>, SceneError> {
    let mut found = parent.children.iter().filter(|c| c.tag == tag);
    match (found.next(), found.next()) {
        (Some(c), None) => Ok(c.clone()),
        (None, _) => Err(parent
            .pos
            .error(format!("`{}` needs a nested `<{tag}>`", parent.kind))),
        (Some(_), Some(second)) => Err(second.pos.error(format!(
            "`{}` takes one nested `<{tag}>`; rtis does not render a different BSDF on each \
             side",
            parent.kind
        ))),
    }
}

/// Indices of refraction Mitsuba names (its `ior.h` table, the common ones).
fn named_ior(name: &str) -> Option<f64> {
    Some(match name {
        "vacuum" => 1.0,
        "helium" => 1.000036,
        "hydrogen" => 1.000132,
        "air" => 1.000277,
        "carbon dioxide" => 1.00045,
        "water" => 1.3330,
        "acetone" => 1.36,
        "ethanol" => 1.361,
        "carbon tetrachloride" => 1.461,
        "glycerol" => 1.4729,
        "benzene" => 1.501,
        "silicone oil" => 1.52045,
        "bromine" => 1.661,
        "water ice" => 1.31,
        "fused quartz" => 1.458,
        "pyrex" => 1.470,
        "acrylic glass" => 1.49,
        "polypropylene" => 1.49,
        "bk7" => 1.5046,
        "sodium chloride" => 1.544,
        "amber" => 1.55,
        "pet" => 1.5750,
        "diamond" => 2.419,
        _ => return None,
    })
}

/// A transform's columns: its origin and the images of the unit axes.
fn apply(m: &DMat4, p: DVec3) -> DVec3 {
    m.transform_point3(p)
}

/// The state of a conversion: the output's parts.
struct Out {
    materials: Vec<String>,
    entities: Vec<String>,
    warnings: Vec<String>,
    paths: Paths,
}

/// Folder of the scene file (meshes and images are relative to it), and the folder the rtis
/// file is read from.
#[derive(Clone)]
struct Paths {
    from: std::path::PathBuf,
    to: std::path::PathBuf,
    /// Under `--lenient`, what was skipped (shared by every clone); `None` when strict.
    skipped: Option<Rc<std::cell::RefCell<Vec<String>>>>,
    /// The ids of the top-level BSDFs: the materials table's names.
    table: BTreeSet<String>,
}

impl Paths {
    /// A file name of the Mitsuba scene as the rtis file must write it.
    fn path(&self, file: &str) -> String {
        // The same folder however it is written (`a/../b`, `.`, an empty path).
        let same = |a: &Path, b: &Path| {
            let dir = |p: &Path| {
                if p.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    p
                }
                .to_path_buf()
            };
            match (dir(a).canonicalize(), dir(b).canonicalize()) {
                (Ok(a), Ok(b)) => a == b,
                _ => a == b,
            }
        };
        if same(&self.from, &self.to) {
            file.to_string()
        } else {
            let p = self.from.join(file);
            p.canonicalize()
                .or_else(|_| std::path::absolute(&p))
                .unwrap_or(p)
                .display()
                .to_string()
        }
    }
}

/// The scene `doc` as rtis text, its files named relative to `to` (the folder the text will be
/// read from).
///
/// With `lenient`, a top-level object that cannot be converted is skipped (a declared BSDF
/// becomes Mitsuba's default, a 0.5 diffuse, so that the shapes that name it stay), and so is a
/// property rtis does not read, each with a warning; otherwise the first is an error.
pub fn convert(
    doc: &Document,
    source: &str,
    to: &Path,
    lenient: bool,
) -> Result<Converted, SceneError> {
    let skipped = lenient.then(|| Rc::new(std::cell::RefCell::new(Vec::new())));
    let mut out = Out {
        materials: Vec::new(),
        entities: Vec::new(),
        warnings: Vec::new(),
        paths: Paths {
            from: doc.dir.clone(),
            to: to.to_path_buf(),
            skipped: skipped.clone(),
            table: doc
                .objects
                .iter()
                .filter(|o| o.tag == "bsdf")
                .filter_map(|o| o.id.clone())
                .collect(),
        },
    };
    // Under `lenient`, an object's error becomes a warning (`Ok(false)`).
    let tolerate = |r: Result<(), SceneError>| -> Result<bool, SceneError> {
        match (r, &skipped) {
            (Ok(()), _) => Ok(true),
            (Err(e), Some(s)) => {
                s.borrow_mut().push(format!("skipped: {}", head(&e)));
                Ok(false)
            }
            (Err(e), None) => Err(e),
        }
    };
    let mut film = String::from("(width: 768, height: 576, spp: 4, filter: Gaussian(stddev: 0.5))");
    let mut camera = None;
    let mut shader = "Path(rr_depth: 5)".to_string();
    let mut sensors = 0;
    for o in &doc.objects {
        match o.tag.as_str() {
            "sensor" => {
                sensors += 1;
                if sensors > 1 {
                    return Err(o.pos.error(
                        "a second `<sensor>`: rtis renders one camera (the first is used by \
                         Mitsuba too; remove the others)",
                    ));
                }
                let mut got = None;
                tolerate(sensor(o, &out.paths).map(|fc| got = Some(fc)))?;
                if let Some((f, c)) = got {
                    film = f;
                    camera = Some(c);
                }
            }
            "integrator" => {
                tolerate(integrator(o, &out.paths).map(|i| shader = i))?;
            }
            "bsdf" => {
                let id = o.id.clone().ok_or_else(|| {
                    o.pos
                        .error("a top-level `<bsdf>` needs an `id` for shapes to refer to")
                })?;
                let mut m = "Phong(kd: (0.5, 0.5, 0.5), ks: (0, 0, 0))".to_string();
                tolerate(material(o, &out.paths).map(|t| m = t))?;
                out.materials.push(format!("        {}: {m},", string(&id)));
            }
            "texture" => {
                // Declared for `<ref>`; converted where it is used.
                if o.id.is_none() {
                    return Err(o.pos.error("a top-level `<texture>` needs an `id`"));
                }
            }
            "shape" => {
                let r = shape(o, &mut out);
                tolerate(r)?;
            }
            "emitter" => {
                let mut light = None;
                tolerate(emitter(o, &out).map(|l| light = Some(l)))?;
                if let Some(light) = light {
                    out.entities.push(format!("        (light: {light}),"));
                }
            }
            _ => {
                tolerate(Err(o.pos.error(format!(
                    "`<{}>` at the top level: rtis imports sensors, integrators, shapes, \
                     BSDFs, textures and emitters",
                    o.tag
                ))))?;
            }
        }
    }
    let camera = camera.unwrap_or_else(|| {
        "Perspective(position: (0, 0, 0), look_at: (0, 0, 1), up: (0, 1, 0), fov: 45, \
         handedness: Right)"
            .to_string()
    });
    let mut text = String::new();
    let _ = writeln!(
        text,
        "// Imported by `rtis import` from {source} (Mitsuba {}.{}.{} scene).",
        doc.version.0, doc.version.1, doc.version.2
    );
    let _ = writeln!(text, "Scene(");
    let _ = writeln!(text, "    film: {film},");
    let _ = writeln!(text, "    camera: {camera},");
    let _ = writeln!(text, "    shader: {shader},");
    let _ = writeln!(text, "    model: Physical,");
    if !out.materials.is_empty() {
        let _ = writeln!(text, "    materials: {{");
        for m in &out.materials {
            let _ = writeln!(text, "{m}");
        }
        let _ = writeln!(text, "    }},");
    }
    let _ = writeln!(text, "    entities: [");
    for e in &out.entities {
        let _ = writeln!(text, "{e}");
    }
    let _ = writeln!(text, "    ],");
    let _ = writeln!(text, ")");
    let mut warnings = out.warnings;
    if let Some(s) = skipped {
        warnings.extend(s.borrow().iter().cloned());
    }
    Ok(Converted { text, warnings })
}

/// The sample count Mitsuba 3's sampler `kind` takes for `sample_count` `n` (measured with its
/// `sample_count()`): `stratified` the next square, `multijitter` a grid of `floor(sqrt(n))`
/// rows and as many columns as `n` needs, `orthogonal` the next square of a prime (at least 4),
/// `ldsampler` the next power of four (at least 4); `n` itself otherwise.
fn mitsuba_sample_count(kind: &str, n: i64) -> i64 {
    let n = n.max(1);
    let root = |n: i64| (1..).find(|r: &i64| r * r >= n).unwrap_or(n);
    match kind {
        "stratified" => root(n).pow(2),
        "multijitter" => {
            let rows = (1..).take_while(|r: &i64| r * r <= n).last().unwrap_or(1);
            rows * ((n + rows - 1) / rows)
        }
        "orthogonal" => {
            let prime = |p: i64| p >= 2 && (2..p).take_while(|d| d * d <= p).all(|d| p % d != 0);
            (root(n).max(2)..).find(|&p| prime(p)).unwrap_or(2).pow(2)
        }
        "ldsampler" => {
            let mut c = 4;
            while c < n {
                c *= 4;
            }
            c
        }
        _ => n,
    }
}

/// A sensor: the film's text and the camera's.
fn sensor(o: &Object, paths: &Paths) -> Result<(String, String), SceneError> {
    let mut p = Props::new(o, paths);
    let lens = match o.kind.as_str() {
        "perspective" => None,
        "thinlens" => Some((
            p.float("aperture_radius", 0.0)?,
            p.float("focus_distance", 0.0)?,
        )),
        _ => return Err(unsupported(o, "sensors: perspective, thinlens")),
    };
    let fov = p.float("fov", 0.0)?;
    let focal = p.string("focal_length")?;
    let fov_axis = p.keyword("fov_axis")?;
    let m = p.transform("to_world")?;
    for near in ["near_clip", "far_clip"] {
        p.float(near, 0.0)?;
    }
    // The film and the sampler.
    let (mut width, mut height, mut filter) = (768i64, 576i64, "Gaussian(stddev: 0.5)".to_string());
    let (mut spp, mut sampler) = (4i64, "");
    for (k, child) in o.children.iter().enumerate() {
        if o.children[..k].iter().any(|c| c.tag == child.tag) {
            return Err(child
                .pos
                .error(format!("a second `<{}>` in this sensor", child.tag)));
        }
        match child.tag.as_str() {
            "film" => {
                if child.kind != "hdrfilm" {
                    return Err(unsupported(child, "films: hdrfilm"));
                }
                let mut f = Props::new(child, paths);
                width = f.integer("width", 768)?;
                height = f.integer("height", 576)?;
                for ignored in ["pixel_format", "component_format", "file_format", "banner"] {
                    f.get(ignored);
                }
                for c in &child.children {
                    if c.tag != "rfilter" {
                        return Err(c.pos.error("a film holds only an `<rfilter>`"));
                    }
                    let mut r = Props::new(c, paths);
                    filter = match c.kind.as_str() {
                        "box" => "Box".to_string(),
                        "gaussian" => {
                            format!("Gaussian(stddev: {})", num(r.float("stddev", 0.5)?))
                        }
                        _ => return Err(unsupported(c, "filters: box, gaussian")),
                    };
                    r.done()?;
                }
                f.done()?;
            }
            "sampler" => {
                let mut s = Props::new(child, paths);
                spp = s.integer("sample_count", 4)?;
                s.integer("seed", 0)?;
                // Mitsuba's stratified and low-discrepancy samplers become rtis's Sobol' one
                // (their `jitter` and `strength` read and left: its points are scrambled),
                // with their sample counts rounded up as Mitsuba 3 rounds them.
                let kind = child.kind.as_str();
                if matches!(kind, "stratified" | "multijitter" | "orthogonal") {
                    s.boolean("jitter", true)?;
                }
                if kind == "orthogonal" {
                    s.integer("strength", 2)?;
                }
                sampler = match kind {
                    "independent" => "",
                    "stratified" | "multijitter" | "orthogonal" | "ldsampler" => {
                        // (A count out of range already is refused below as written.)
                        if (1..=1 << 20).contains(&spp) {
                            let rounded = mitsuba_sample_count(kind, spp);
                            if rounded > 1 << 20 {
                                return Err(child.pos.error(format!(
                                    "`sample_count` {spp}, which Mitsuba's `{kind}` rounds up \
                                     to {rounded}: rtis takes 1 to 1048576"
                                )));
                            }
                            spp = rounded;
                        }
                        ", sampler: Sobol"
                    }
                    _ => {
                        return Err(unsupported(
                            child,
                            "samplers: independent, and stratified, multijitter, orthogonal and \
                             ldsampler (as rtis's Sobol')",
                        ));
                    }
                };
                s.done()?;
            }
            _ => {
                return Err(child.pos.error(format!(
                    "`<{}>` inside a sensor: rtis reads its film and sampler",
                    child.tag
                )));
            }
        }
    }
    if !(1..=32768).contains(&width) || !(1..=32768).contains(&height) {
        return Err(o.pos.error(format!(
            "a film of {width}x{height}: rtis takes 1 to 32768 pixels a side"
        )));
    }
    if !(1..=1 << 20).contains(&spp) {
        return Err(o
            .pos
            .error(format!("`sample_count` {spp}: rtis takes 1 to 1048576")));
    }
    // The field of view, made vertical as rtis's.
    let aspect = width as f64 / height as f64;
    // Without `fov`, Mitsuba's `focal_length` (default 50mm) on a 36 x 24 mm film gives the
    // diagonal field of view (its `parse_fov`).
    let (fov, axis) = match (fov, focal) {
        (f, _) if f > 0.0 && f < 180.0 => (f, fov_axis.map_or("x".to_string(), |(a, _)| a)),
        (f, _) if f != 0.0 => {
            return Err(o
                .pos
                .error(format!("`fov` {f}: a field of view is in (0, 180) degrees")));
        }
        (_, focal) => {
            let mm = match &focal {
                None => 50.0,
                Some((v, pos)) => v
                    .trim()
                    .strip_suffix("mm")
                    .and_then(|n| n.trim().parse::<f64>().ok())
                    .filter(|f| *f > 0.0 && f.is_finite())
                    .ok_or_else(|| {
                        pos.error(format!("`focal_length` \"{v}\" is not such as \"50mm\""))
                    })?,
            };
            let diagonal = 2.0
                * ((36f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm))
                    .atan()
                    .to_degrees();
            (diagonal, "diagonal".to_string())
        }
    };
    let half = (fov.to_radians() / 2.0).tan();
    let vertical = match axis.to_ascii_lowercase().as_str() {
        "x" => half / aspect,
        "y" => half,
        "diagonal" => half / (1.0 + aspect * aspect).sqrt(),
        "smaller" if width < height => half / aspect,
        "smaller" => half,
        "larger" if width > height => half / aspect,
        "larger" => half,
        other => {
            return Err(o.pos.error(format!(
                "`fov_axis` \"{other}\": Mitsuba's are \"x\", \"y\", \"diagonal\", \"smaller\" \
                 and \"larger\""
            )));
        }
    };
    let fov_y = 2.0 * vertical.atan().to_degrees();
    // The frame: Mitsuba's camera looks along +z of `to_world`, +y up, +x to the image's left.
    let position = apply(&m, DVec3::ZERO);
    let forward = m.transform_vector3(DVec3::Z);
    let up = m.transform_vector3(DVec3::Y);
    let left = m.transform_vector3(DVec3::X);
    // The course's image right is up x forward: Mitsuba's left, unless to_world mirrors.
    let handedness = if up.cross(forward).dot(left) > 0.0 {
        "Right"
    } else {
        "Left"
    };
    let lens_text = match lens {
        Some((r, f)) if r > 0.0 => {
            format!(", aperture_radius: {}, focus_distance: {}", num(r), num(f))
        }
        _ => String::new(),
    };
    p.done()?;
    let film = format!("(width: {width}, height: {height}, spp: {spp}, filter: {filter}{sampler})");
    let camera = format!(
        "Perspective(position: {}, look_at: {}, up: {}, fov: {}{lens_text}, handedness: {handedness})",
        vec3(position),
        vec3(position + forward),
        vec3(up),
        num(fov_y)
    );
    Ok((film, camera))
}

/// An integrator as an rtis shader that gives the same image.
fn integrator(o: &Object, paths: &Paths) -> Result<String, SceneError> {
    let mut p = Props::new(o, paths);
    let text = match o.kind.as_str() {
        "path" => {
            let max_depth = p.integer("max_depth", -1)?;
            let rr_depth = p.integer("rr_depth", 5)?;
            if p.boolean("hide_emitters", false)? {
                return Err(o.pos.error("`hide_emitters` is not supported by rtis"));
            }
            if !(1..=1024).contains(&rr_depth) {
                return Err(o
                    .pos
                    .error(format!("`rr_depth` {rr_depth}: rtis takes 1 to 1024")));
            }
            // Mitsuba counts the camera ray's hit as depth 1: rtis's depth counts bounces.
            match max_depth {
                -1 => format!("Path(rr_depth: {rr_depth})"),
                d if (1..=1025).contains(&d) => {
                    format!("Path(max_depth: {}, rr_depth: {rr_depth})", d - 1)
                }
                _ => {
                    return Err(o.pos.error(
                        "`max_depth` is -1 (no limit) or from 1 to 1025 (rtis's 1024 bounces)",
                    ));
                }
            }
        }
        "direct" => {
            // Next-event estimation at the first hit, by light and BSDF sampling with MIS: the
            // image of Path limited to direct light.
            p.integer("emitter_samples", 1)?;
            p.integer("bsdf_samples", 1)?;
            p.integer("shading_samples", 1)?;
            if p.boolean("hide_emitters", false)? {
                return Err(o.pos.error("`hide_emitters` is not supported by rtis"));
            }
            "Path(max_depth: 1)".to_string()
        }
        _ => return Err(unsupported(o, "integrators: path, direct")),
    };
    p.done()?;
    children(o, &[])?;
    Ok(text)
}

/// The rtis material of a shape: its nested BSDF, a declared one by name (`Named`, an entry
/// of the materials table), or Mitsuba's default, a 0.5 diffuse.
fn shape_material(o: &Object, paths: &Paths) -> Result<String, SceneError> {
    let mut bsdfs = o.children.iter().filter(|c| c.tag == "bsdf");
    match (bsdfs.next(), bsdfs.next()) {
        (None, _) => Ok("Phong(kd: (0.5, 0.5, 0.5), ks: (0, 0, 0))".to_string()),
        (Some(b), None) => match &b.id {
            // A declared (top-level) BSDF is an entry of the materials table.
            Some(id) if paths.table.contains(id) => Ok(format!("Named({})", string(id))),
            _ => material(b, paths),
        },
        (Some(_), Some(second)) => Err(second.pos.error("a shape takes one `<bsdf>`")),
    }
}

/// A shape as an entity.
fn shape(o: &Object, out: &mut Out) -> Result<(), SceneError> {
    let paths = out.paths.clone();
    let mut p = Props::new(o, &paths);
    let m = p.transform("to_world")?;
    let flip = p.boolean("flip_normals", false)?;
    let name =
        o.id.as_ref()
            .map_or(String::new(), |id| format!("name: {}, ", string(id)));
    let mut transform = String::new();
    let shape = match o.kind.as_str() {
        "sphere" => {
            let c = p.vector("center")?.unwrap_or(DVec3::ZERO);
            let r = p.float("radius", 1.0)?;
            // A sphere stays round only under a uniform scale.
            let axes = [DVec3::X, DVec3::Y, DVec3::Z].map(|a| m.transform_vector3(a));
            let s = axes[0].length();
            let round = axes
                .iter()
                .all(|a| (a.length() - s).abs() <= 1e-9 * s.max(1.0))
                && axes[0].dot(axes[1]).abs() <= 1e-9 * s * s
                && axes[1].dot(axes[2]).abs() <= 1e-9 * s * s
                && axes[0].dot(axes[2]).abs() <= 1e-9 * s * s;
            if !round {
                return Err(o.pos.error(
                    "this sphere's `to_world` scales it unevenly or shears it: rtis's spheres \
                     are round",
                ));
            }
            if flip {
                return Err(o
                    .pos
                    .error("`flip_normals` on a sphere: rtis's spheres face outward"));
            }
            // A rotation turns Mitsuba's sphere's texture coordinates and frame, not rtis's.
            if (axes[0] / s - DVec3::X).length() > 1e-9 || (axes[1] / s - DVec3::Y).length() > 1e-9
            {
                out.warnings.push(format!(
                    "{}:{}: this sphere's `to_world` turns it: Mitsuba turns its texture \
                     coordinates with it, rtis keeps its poles on z",
                    o.pos.file, o.pos.line
                ));
            }
            format!(
                "Sphere(center: {}, radius: {})",
                vec3(apply(&m, c)),
                num(r * s)
            )
        }
        "rectangle" => {
            // Mitsuba's rectangle is [-1, 1]^2 at z = 0, facing +z, (u, v) from its corner
            // (-1, -1).
            let corner = apply(&m, DVec3::new(-1.0, -1.0, 0.0));
            let u = apply(&m, DVec3::new(1.0, -1.0, 0.0)) - corner;
            let mut v = apply(&m, DVec3::new(-1.0, 1.0, 0.0)) - corner;
            // Its normal is to_world's normal transform of +z; rtis's is u x v.
            let n = (m.inverse().transpose()).transform_vector3(DVec3::Z);
            let mut c = corner;
            if u.cross(v).length_squared() == 0.0 || !u.cross(v).is_finite() {
                return Err(o
                    .pos
                    .error("this rectangle's `to_world` flattens it to a line or a point"));
            }
            if (u.cross(v).dot(n) < 0.0) != flip {
                // The other side: start from the other corner along v's way back.
                c = corner + v;
                v = -v;
                out.warnings.push(format!(
                    "{}:{}: a mirrored or flipped rectangle: its `v` texture coordinate runs \
                     the other way in rtis",
                    o.pos.file, o.pos.line
                ));
            }
            format!(
                "Rectangle(corner: {}, u: {}, v: {})",
                vec3(c),
                vec3(u),
                vec3(v)
            )
        }
        "cube" => {
            let mut verts = Vec::new();
            for i in 0..8 {
                let q = DVec3::new(
                    if i & 1 != 0 { 1.0 } else { -1.0 },
                    if i & 2 != 0 { 1.0 } else { -1.0 },
                    if i & 4 != 0 { 1.0 } else { -1.0 },
                );
                verts.push(vec3(apply(&m, q)));
            }
            // Faces wound so that (b - a) x (c - a) points outward.
            let mut faces: Vec<[u32; 3]> = vec![
                [0, 2, 1],
                [1, 2, 3], // -z
                [4, 5, 6],
                [5, 7, 6], // +z
                [0, 1, 4],
                [1, 5, 4], // -y
                [2, 6, 3],
                [3, 6, 7], // +y
                [0, 4, 2],
                [2, 4, 6], // -x
                [1, 3, 5],
                [3, 7, 5], // +x
            ];
            if (m.determinant() < 0.0) != flip {
                for f in &mut faces {
                    f.swap(1, 2);
                }
            }
            let faces: Vec<String> = faces
                .iter()
                .map(|f| format!("({}, {}, {})", f[0], f[1], f[2]))
                .collect();
            format!(
                "TriangleMesh(vertices: [{}], faces: [{}])",
                verts.join(", "),
                faces.join(", ")
            )
        }
        "disk" => {
            // Mitsuba's disk: radius 1 at z = 0, facing +z, as a fan of DISK_SEGMENTS
            // triangles around its centre (its area short by 1e-4).
            let centre = apply(&m, DVec3::ZERO);
            let mut verts = vec![vec3(centre)];
            for k in 0..DISK_SEGMENTS {
                let phi = std::f64::consts::TAU * k as f64 / DISK_SEGMENTS as f64;
                verts.push(vec3(apply(&m, DVec3::new(phi.cos(), phi.sin(), 0.0))));
            }
            let mirrored = (m.determinant() < 0.0) != flip;
            let faces: Vec<String> = (0..DISK_SEGMENTS)
                .map(|k| {
                    let (a, b) = (1 + k, 1 + (k + 1) % DISK_SEGMENTS);
                    if mirrored {
                        format!("(0, {b}, {a})")
                    } else {
                        format!("(0, {a}, {b})")
                    }
                })
                .collect();
            format!(
                "TriangleMesh(vertices: [{}], faces: [{}])",
                verts.join(", "),
                faces.join(", ")
            )
        }
        "obj" | "ply" | "serialized" => {
            let (file, at) = p.string("filename")?.ok_or_else(|| {
                o.pos
                    .error(format!("a `{}` shape needs a `filename`", o.kind))
            })?;
            // A missing file is named here, at its place in the XML.
            if let Err(e) = std::fs::metadata(paths.from.join(&file)) {
                return Err(at.error(format!("cannot read mesh file {file}: {e}")));
            }
            let index = if o.kind == "serialized" {
                p.integer("shape_index", 0)?
            } else {
                0
            };
            if !(0..=u32::MAX as i64).contains(&index) {
                return Err(o
                    .pos
                    .error(format!("`shape_index` {index} is not a mesh index")));
            }
            let index_text = if index > 0 {
                format!(", shape_index: {index}")
            } else {
                String::new()
            };
            let face_normals = p.boolean("face_normals", false)?;
            let t = srt(&m).ok_or_else(|| {
                o.pos.error(
                    "this `to_world` shears the mesh: rtis's transforms are a scale, a \
                     rotation and a translation",
                )
            })?;
            if !t.is_empty() {
                transform = format!(", transform: {t}");
            }
            // Mitsuba computes smooth normals for a mesh without them, unless face_normals.
            let normals = if face_normals { "Faces" } else { "Smooth" };
            let flip_text = if flip { ", flip_normals: true" } else { "" };
            format!(
                "Mesh(path: {}, normals: {normals}{index_text}{flip_text})",
                string(&paths.path(&file))
            )
        }
        _ => {
            return Err(unsupported(
                o,
                "shapes: sphere, rectangle, cube, disk, obj, ply, serialized",
            ));
        }
    };
    p.done()?;
    let material = shape_material(o, &out.paths)?;
    let textured = ["Image(", "Checkerboard(", "NormalMap("]
        .iter()
        .any(|t| material.contains(t));
    if textured && (o.kind == "cube" || o.kind == "disk") {
        out.warnings.push(format!(
            "{}:{}: a textured `{}`: rtis's mesh of it has no texture coordinates of its own \
             (each face is mapped by its barycentric ones), unlike Mitsuba's",
            o.pos.file, o.pos.line, o.kind
        ));
    }
    let mut emitters = o.children.iter().filter(|c| c.tag == "emitter");
    let emitter = match (emitters.next(), emitters.next()) {
        (None, _) => String::new(),
        (Some(e), None) => {
            if e.kind != "area" {
                return Err(e.pos.error(format!(
                    "a shape's `<emitter type=\"{}\">`: a shape takes an `area` emitter",
                    e.kind
                )));
            }
            let mut ep = Props::new(e, &out.paths);
            let radiance = ep.color("radiance", Some(DVec3::ONE), true)?;
            ep.done()?;
            children(e, &[])?;
            format!(", emitter: (radiance: {})", radiance.unwrap_or_default())
        }
        (Some(_), Some(second)) => return Err(second.pos.error("a shape takes one emitter")),
    };
    for c in &o.children {
        if c.tag != "bsdf" && c.tag != "emitter" {
            return Err(c.pos.error(format!(
                "`<{}>` inside a shape: rtis reads its BSDF and area emitter",
                c.tag
            )));
        }
    }
    out.entities.push(format!(
        "        ({name}shape: {shape}{transform}, material: {material}{emitter}),"
    ));
    Ok(())
}

/// Triangles of an imported disk: its area is `(n / 2 pi) sin(2 pi / n)` of the circle's,
/// 1e-4 short at 256.
const DISK_SEGMENTS: usize = 256;

/// A transform as rtis's scale, rotation (degrees about x, then y, then z) and translation,
/// `(scale: ..., rotate: ..., translate: ...)`, or nothing for the identity; `None` when it
/// shears.
fn srt(m: &DMat4) -> Option<String> {
    if *m == DMat4::IDENTITY {
        return Some(String::new());
    }
    let (scale, rotation, translation) = m.to_scale_rotation_translation();
    let rebuilt = DMat4::from_scale_rotation_translation(scale, rotation, translation);
    if !rebuilt.abs_diff_eq(
        *m,
        1e-9 * m
            .abs()
            .to_cols_array()
            .iter()
            .fold(1.0f64, |a, b| a.max(*b)),
    ) {
        return None;
    }
    let (x, y, z) = euler_xyz(&glam::DMat3::from_quat(rotation));
    Some(format!(
        "(scale: {}, rotate: {}, translate: {})",
        vec3(scale),
        vec3(DVec3::new(x, y, z)),
        vec3(translation)
    ))
}

/// The angles in degrees `(x, y, z)` of a rotation `R = Rz Ry Rx`.
pub fn euler_xyz(r: &glam::DMat3) -> (f64, f64, f64) {
    // R[i][j] is row i, column j: glam's col(j)[i].
    let at = |i: usize, j: usize| r.col(j)[i];
    let y = (-at(2, 0)).clamp(-1.0, 1.0).asin();
    let (x, z) = if at(2, 0).abs() < 1.0 - 1e-12 {
        (at(2, 1).atan2(at(2, 2)), at(1, 0).atan2(at(0, 0)))
    } else {
        // Gimbal lock: put it all in x.
        ((-at(1, 2)).atan2(at(1, 1)), 0.0)
    };
    (x.to_degrees(), y.to_degrees(), z.to_degrees())
}

/// A top-level emitter as an rtis light.
fn emitter(o: &Object, out: &Out) -> Result<String, SceneError> {
    let paths = &out.paths;
    let mut p = Props::new(o, paths);
    let text = match o.kind.as_str() {
        "point" => {
            let has_frame = o.props.contains_key("to_world");
            let m = p.transform("to_world")?;
            let position = match p.vector("position")? {
                Some(_) if has_frame => {
                    return Err(o
                        .pos
                        .error("a point light takes `position` or `to_world`, not both"));
                }
                Some(q) => q,
                None => apply(&m, DVec3::ZERO),
            };
            let i = p.color("intensity", Some(DVec3::ONE), false)?;
            format!(
                "Point(position: {}, intensity: {})",
                vec3(position),
                i.unwrap_or_default()
            )
        }
        "spot" => {
            let m = p.transform("to_world")?;
            let i = p.color("intensity", Some(DVec3::ONE), false)?;
            let cutoff = p.float("cutoff_angle", 20.0)?;
            let beam = p.float("beam_width", cutoff * 0.75)?;
            format!(
                "Spot(position: {}, direction: {}, intensity: {}, cutoff_angle: {}, \
                 beam_width: {})",
                vec3(apply(&m, DVec3::ZERO)),
                vec3(m.transform_vector3(DVec3::Z)),
                i.unwrap_or_default(),
                num(cutoff),
                num(beam)
            )
        }
        "directional" => {
            let m = p.transform("to_world")?;
            let d = p
                .vector("direction")?
                .unwrap_or(m.transform_vector3(DVec3::Z));
            let e = p.color("irradiance", Some(DVec3::ONE), false)?;
            format!(
                "Directional(direction: {}, irradiance: {})",
                vec3(d),
                e.unwrap_or_default()
            )
        }
        "constant" => {
            let l = p.color("radiance", Some(DVec3::ONE), false)?;
            format!("Environment(radiance: {})", l.unwrap_or_default())
        }
        "envmap" => {
            let (file, _) = p
                .string("filename")?
                .ok_or_else(|| o.pos.error("an `envmap` needs a `filename`"))?;
            let scale = p.float("scale", 1.0)?;
            let m = p.transform("to_world")?;
            let r = glam::DMat3::from_mat4(m);
            let orthonormal = (r.transpose() * r).abs_diff_eq(glam::DMat3::IDENTITY, 1e-6)
                && r.determinant() > 0.0;
            if !orthonormal {
                return Err(o.pos.error(
                    "an `envmap`'s `to_world` must be a rotation: rtis turns its sky, no more",
                ));
            }
            let (x, y, z) = euler_xyz(&r);
            format!(
                "Environment(image: {}, scale: {}, rotate: {})",
                string(&paths.path(&file)),
                num(scale),
                vec3(DVec3::new(x, y, z))
            )
        }
        "area" => {
            return Err(o
                .pos
                .error("an `area` emitter at the top level: it belongs inside a `<shape>`"));
        }
        _ => {
            return Err(unsupported(
                o,
                "emitters: area (in a shape), point, spot, directional, constant, envmap",
            ));
        }
    };
    p.done()?;
    children(o, &[])?;
    Ok(text)
}

//! `rtis check`: validate a scene and print it in its own terms.
//!
//! The output is the scene as RON, as it loads: `extends` resolved, every default written out,
//! one line per entity, materials of the `materials` table by name. It can be pasted back as a
//! scene file. Comments (`//`) carry what is not scene syntax: warnings, the effects the render
//! will simulate, and its cost estimate.

use super::CliError;
use glam::{DVec3, Vec3A};
use rtis::camera::Handedness;
use rtis::light::Sky;
use rtis::material::microfacet::Microfacet;
use rtis::material::{Bsdf, Coating};
use rtis::render::estimate::{self, human_seconds};
use rtis::sampling::{PixelFilter, SamplerKind};
use rtis::scene::Scene;
use rtis::shader::Shader;
use rtis::texture::{MaterialTextures, Texture, TextureKind};
use rtis::world::{
    Emitter, Material, MaterialName, Name, Projection, RadianceTexture, Transform,
    WorldEnvironment, WorldLight, WorldShape,
};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

/// A number as RON reads it: the shortest text that reads back as the same value, in
/// scientific notation when very large or small (never 300 digits).
pub fn num<T: Copy + Into<f64> + std::fmt::Display + std::fmt::LowerExp>(v: T) -> String {
    let a = v.into().abs();
    if a != 0.0 && !(1e-4..1e7).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn v3(v: DVec3) -> String {
    format!("({}, {}, {})", num(v.x), num(v.y), num(v.z))
}

fn rgb(v: Vec3A) -> String {
    format!("({}, {}, {})", num(v.x), num(v.y), num(v.z))
}

/// A texture as a scene file writes it (an image by its absolute path).
fn texture(t: &Texture) -> String {
    let tr = &t.transform;
    let uv = format!(
        "uv_transform: (scale: ({}, {}), rotate: {}, offset: ({}, {}))",
        num(tr.scale.x),
        num(tr.scale.y),
        num(tr.rotate),
        num(tr.offset.x),
        num(tr.offset.y)
    );
    match &t.kind {
        TextureKind::Checkerboard(c) => format!(
            "Checkerboard(color0: {}, color1: {}, {uv})",
            rgb(c.color0),
            rgb(c.color1)
        ),
        TextureKind::Image(i) => format!(
            "Image(path: {:?}, filter: {:?}, wrap: {:?}, raw: {}, {uv})",
            i.source.display().to_string(),
            i.filter,
            i.wrap,
            i.raw
        ),
    }
}

fn material(m: &Material, t: Option<&MaterialTextures>) -> String {
    let inner = unmapped(m, t);
    match t.and_then(|t| t.normal_map.as_ref()) {
        Some(map) => format!("NormalMap(normal_map: {}, material: {inner})", texture(map)),
        None => inner,
    }
}

/// The material without its normal map.
fn unmapped(m: &Material, t: Option<&MaterialTextures>) -> String {
    // A parameter's texture, else its constant.
    let paint = |tex: Option<&Texture>, c: Vec3A| tex.map_or_else(|| rgb(c), texture);
    let reflectance = t.and_then(|t| t.reflectance.as_ref());
    let specular = t.and_then(|t| t.specular.as_ref());
    match m {
        Material::Phong(p) => format!(
            "Phong(kd: {}, ks: {}, shininess: {})",
            paint(reflectance, p.kd),
            paint(specular, p.ks),
            num(p.shininess)
        ),
        Material::Mirror(m) => format!("Mirror(color: {})", paint(reflectance, m.color)),
        Material::Conductor(c) => format!(
            "Conductor(eta: {}, k: {}, specular_reflectance: {})",
            rgb(c.eta),
            rgb(c.k),
            paint(specular, c.specular_reflectance)
        ),
        Material::Transmissive(g) => format!(
            "Transmissive(ior: {}, color: {})",
            num(g.ior),
            paint(reflectance, g.color)
        ),
        Material::Bsdf(b) => bsdf(b, t.unwrap_or(&MaterialTextures::default())),
    }
}

fn bsdf(b: &Bsdf, t: &MaterialTextures) -> String {
    // A parameter's texture, else its constant.
    let paint = |tex: &Option<Texture>, c: Vec3A| tex.as_ref().map_or_else(|| rgb(c), texture);
    let coating = |c: &Coating| {
        format!(
            "int_ior: {}, ext_ior: 1, diffuse_reflectance: {}, specular_reflectance: {}, \
             nonlinear: {}",
            num(c.eta),
            paint(&t.reflectance, c.diffuse_reflectance),
            paint(&t.specular, c.specular_reflectance),
            c.nonlinear
        )
    };
    match b {
        Bsdf::RoughConductor(r) => format!(
            "RoughConductor({}, eta: {}, k: {}, specular_reflectance: {})",
            microfacet(&r.microfacet, t),
            rgb(r.metal.eta),
            rgb(r.metal.k),
            paint(&t.specular, r.metal.specular_reflectance)
        ),
        Bsdf::RoughDielectric(r) => format!(
            "RoughDielectric({}, int_ior: {}, ext_ior: 1, specular_reflectance: {}, \
             specular_transmittance: {})",
            microfacet(&r.microfacet, t),
            num(r.eta),
            paint(&t.specular, r.specular_reflectance),
            paint(&t.transmittance, r.specular_transmittance)
        ),
        Bsdf::RoughPlastic(r) => format!(
            "RoughPlastic(distribution: {:?}, alpha: {}, sampling: {:?}, {})",
            r.microfacet.distribution,
            num(r.microfacet.alpha_x),
            r.microfacet.sampling,
            coating(&r.coating)
        ),
        Bsdf::Plastic(p) => format!("Plastic({})", coating(&p.coating)),
    }
}

/// A distribution's fields, each roughness its texture where it has one.
fn microfacet(m: &Microfacet, t: &MaterialTextures) -> String {
    let alpha = |tex: &Option<Texture>, a: f32| tex.as_ref().map_or_else(|| num(a), texture);
    format!(
        "distribution: {:?}, alpha_u: {}, alpha_v: {}, sampling: {:?}",
        m.distribution,
        alpha(&t.alpha_u, m.alpha_x),
        alpha(&t.alpha_v, m.alpha_y),
        m.sampling
    )
}

fn shape(s: &WorldShape) -> String {
    match s {
        WorldShape::Sphere { center, radius } => {
            format!("Sphere(center: {}, radius: {})", v3(*center), num(*radius))
        }
        WorldShape::Plane { point, normal } => {
            format!(
                "InfinitePlane(point: {}, normal: {})",
                v3(*point),
                v3(*normal)
            )
        }
        WorldShape::Triangle { v } => {
            format!(
                "Triangle(a: {}, b: {}, c: {})",
                v3(v[0]),
                v3(v[1]),
                v3(v[2])
            )
        }
        WorldShape::Rectangle { corner, u, v } => {
            format!(
                "Rectangle(corner: {}, u: {}, v: {})",
                v3(*corner),
                v3(*u),
                v3(*v)
            )
        }
        WorldShape::Mesh(m) => {
            let list = |vs: &[DVec3]| vs.iter().map(|v| v3(*v)).collect::<Vec<_>>().join(", ");
            let faces: Vec<String> = m
                .faces
                .iter()
                .map(|f| format!("({}, {}, {})", f[0], f[1], f[2]))
                .collect();
            let normals = if m.normals.is_empty() {
                String::new()
            } else {
                format!(", normals: [{}]", list(&m.normals))
            };
            format!(
                "TriangleMesh(vertices: [{}], faces: [{}]{normals})",
                list(&m.positions),
                faces.join(", ")
            )
        }
    }
}

fn shader(s: &Shader) -> String {
    match s {
        Shader::Intersection { color } => format!("Intersection(color: {})", rgb(*color)),
        Shader::Depth {
            max_distance,
            color,
        } => format!(
            "Depth(max_distance: {}, color: {})",
            num(*max_distance),
            rgb(*color)
        ),
        Shader::Normal => "Normal".into(),
        Shader::Direct {
            max_specular,
            light_samples,
        } => format!("Direct(max_specular: {max_specular}, light_samples: {light_samples})"),
        Shader::Global(g) => format!(
            "Global(samples: {}, max_depth: {}, ambient: {}, max_specular: {}, light_samples: {})",
            g.samples,
            g.max_depth,
            rgb(g.ambient),
            g.max_specular,
            g.light_samples
        ),
        Shader::Path(p) => {
            let depth = p
                .max_depth
                .map_or(String::new(), |d| format!("max_depth: {d}, "));
            format!(
                "Path({depth}rr_depth: {}, sampling: {:?}, lights: {:?}, lights_per_vertex: {:?})",
                p.rr_depth, p.sampling, p.lights, p.lights_per_vertex
            )
        }
    }
}

/// The scene as RON text, every default written out but the box filter and the independent
/// sampler (see the module documentation).
pub fn to_ron(scene: &Scene) -> String {
    let s = &scene.settings;
    let mut out = String::from("Scene(\n");
    let f = &s.film;
    let filter = match f.filter {
        PixelFilter::Box => String::new(),
        PixelFilter::Gaussian { stddev } => format!(", filter: Gaussian(stddev: {})", num(stddev)),
    };
    let sampler = match f.sampler {
        SamplerKind::Independent => "",
        SamplerKind::Sobol => ", sampler: Sobol",
    };
    let _ = writeln!(
        out,
        "    film: (width: {}, height: {}, spp: {}, transfer: {:?}{filter}{sampler}),",
        f.width, f.height, f.spp, f.transfer
    );
    let c = &s.camera;
    let (kind, extent) = match c.projection {
        Projection::Perspective { fov, lens: None } => {
            ("Perspective", format!("fov: {}", num(fov)))
        }
        Projection::Perspective { fov, lens: Some(l) } => (
            "Perspective",
            format!(
                "fov: {}, aperture_radius: {}, focus_distance: {}",
                num(fov),
                num(l.radius),
                num(l.focus_distance)
            ),
        ),
        Projection::Orthographic { height } => ("Orthographic", format!("height: {}", num(height))),
    };
    let hand = match c.handedness {
        Handedness::Left => "",
        Handedness::Right => ", handedness: Right",
    };
    let _ = writeln!(
        out,
        "    camera: {kind}(position: {}, look_at: {}, up: {}, {extent}{hand}),",
        v3(c.position),
        v3(c.look_at),
        v3(c.up)
    );
    let _ = writeln!(out, "    shader: {},", shader(&s.shader));
    let _ = writeln!(out, "    model: {:?},", s.model);
    let _ = writeln!(out, "    background: {},", rgb(s.background));
    let _ = writeln!(out, "    seed: {},", s.seed);
    let e = &s.effects;
    let switches: Vec<String> = [
        ("shadows", e.shadows),
        ("reflection", e.reflection),
        ("refraction", e.refraction),
        ("indirect", e.indirect),
        ("ambient", e.ambient),
        ("background", e.background),
        ("emission", e.emission),
    ]
    .iter()
    .filter_map(|(k, v)| v.map(|v| format!("{k}: {v}")))
    .collect();
    if !switches.is_empty() {
        let _ = writeln!(out, "    effects: ({}),", switches.join(", "));
    }

    // The materials table: each name once, in name order.
    let mut table: BTreeMap<String, String> = BTreeMap::new();
    for (m, t, name) in scene
        .world
        .query::<(&Material, Option<&MaterialTextures>, &MaterialName)>()
        .iter()
    {
        table.insert(name.0.clone(), material(m, t));
    }
    if !table.is_empty() {
        out.push_str("    materials: {\n");
        for (name, m) in &table {
            let _ = writeln!(out, "        {name:?}: {m},");
        }
        out.push_str("    },\n");
    }

    // One line per entity, in the order of the file.
    let mut entities: Vec<(hecs::Entity, String)> = Vec::new();
    for (id, name, sh, m, mname, tex, t, light, env, (emitter, radiance)) in scene
        .world
        .query::<(
            hecs::Entity,
            Option<&Name>,
            Option<&WorldShape>,
            Option<&Material>,
            Option<&MaterialName>,
            Option<&MaterialTextures>,
            Option<&Transform>,
            Option<&WorldLight>,
            Option<&WorldEnvironment>,
            (Option<&Emitter>, Option<&RadianceTexture>),
        )>()
        .iter()
    {
        let mut fields = Vec::new();
        if let Some(n) = name {
            fields.push(format!("name: {:?}", n.0));
        }
        if let Some(sh) = sh {
            fields.push(format!("shape: {}", shape(sh)));
        }
        match (m, mname) {
            (_, Some(n)) => fields.push(format!("material: Named({:?})", n.0)),
            (Some(m), None) => fields.push(format!("material: {}", material(m, tex))),
            (None, None) => {}
        }
        if let Some(t) = t
            && *t != Transform::IDENTITY
        {
            fields.push(format!(
                "transform: (scale: {}, rotate: {}, translate: {})",
                v3(t.scale),
                v3(t.rotate),
                v3(t.translate)
            ));
        }
        match light {
            Some(WorldLight::Point {
                position,
                intensity,
            }) => fields.push(format!(
                "light: Point(position: {}, intensity: {})",
                v3(*position),
                rgb(*intensity)
            )),
            Some(WorldLight::Spot {
                position,
                direction,
                intensity,
                cutoff_angle,
                beam_width,
            }) => fields.push(format!(
                "light: Spot(position: {}, direction: {}, intensity: {}, cutoff_angle: {}, \
                 beam_width: {})",
                v3(*position),
                v3(*direction),
                rgb(*intensity),
                num(*cutoff_angle),
                num(*beam_width)
            )),
            Some(WorldLight::Directional {
                direction,
                irradiance,
            }) => fields.push(format!(
                "light: Directional(direction: {}, irradiance: {})",
                v3(*direction),
                rgb(*irradiance)
            )),
            None => {}
        }
        if let Some(env) = env {
            let sky = match &env.sky {
                Sky::Uniform(l) => format!("radiance: {}", rgb(*l)),
                Sky::Map { source, .. } => format!("image: {:?}", source.display().to_string()),
            };
            fields.push(format!(
                "light: Environment({sky}, scale: {}, rotate: {})",
                num(env.scale),
                v3(env.rotate)
            ));
        }
        if let Some(e) = emitter {
            // A textured radiance is its texture (the constant factor is white).
            let radiance = radiance.map_or_else(|| rgb(e.radiance), |r| texture(&r.0));
            fields.push(format!(
                "emitter: Emitter(radiance: {radiance}, two_sided: {})",
                e.two_sided
            ));
        }
        entities.push((id, format!("        ({}),", fields.join(", "))));
    }
    entities.sort_by_key(|(id, _)| id.id());
    out.push_str("    entities: [\n");
    for (_, line) in entities {
        out.push_str(&line);
        out.push('\n');
    }
    out.push_str("    ],\n)\n");
    out
}

/// Validate the scene and print it, its effects and its cost.
pub fn run(path: &Path) -> Result<(), CliError> {
    let scene = rtis::import::load_scene(path)?;
    println!(
        "// {}: valid. As loaded: extends resolved, defaults written out.",
        scene.origin
    );
    print!("{}", to_ron(&scene));
    let prepared = rtis::extract(&scene);
    for w in scene.warnings.iter().chain(&prepared.warnings) {
        println!("// warning: {w}");
    }
    println!("// effects {}", prepared.effects);
    let est = estimate::estimate(&prepared);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let rule = est
        .rule_per_sample
        .map_or("set by Russian roulette".into(), |r| {
            format!("{} by the shader's rule", num(r))
        });
    println!(
        "// cost: {} camera samples, {:.1} rays each ({rule}), {:.3e} rays in all, about {} on \
         {threads} threads",
        est.samples,
        est.rays_per_sample,
        est.rays(),
        human_seconds(est.seconds(threads))
    );
    Ok(())
}

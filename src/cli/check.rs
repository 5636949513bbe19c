//! `rtis check`.

use super::CliError;
use rtis::scene;
use rtis::world::{Material, MaterialName, Projection, WorldLight, WorldShape};
use std::collections::BTreeMap;
use std::path::Path;

/// Validate the scene and print what it contains.
pub fn run(path: &Path) -> Result<(), CliError> {
    let scene = scene::load_path(path)?;
    let s = &scene.settings;
    println!("scene {}: valid", scene.origin);
    println!(
        "  film        {}x{}, {} spp, PNG transfer {:?}",
        s.film.width, s.film.height, s.film.spp, s.film.transfer
    );
    let (pos, look, up) = (s.camera.position, s.camera.look_at, s.camera.up);
    let kind = match s.camera.projection {
        Projection::Perspective { fov } => format!("perspective, fov {fov} deg"),
        Projection::Orthographic { height } => format!("orthographic, height {height}"),
    };
    println!("  camera      {kind}, at {pos} looking at {look}, up {up}");
    println!("  shader      {:?}", s.shader);
    println!("  model       {:?}", s.model);
    println!("  background  {}", s.background);
    println!("  seed        {}", s.seed);

    let mut shapes: BTreeMap<&str, usize> = BTreeMap::new();
    let mut triangles = 0usize;
    for shape in scene.world.query::<&WorldShape>().iter() {
        let k = match shape {
            WorldShape::Sphere { .. } => "Sphere",
            WorldShape::Plane { .. } => "InfinitePlane",
            WorldShape::Triangle { .. } => "Triangle",
            WorldShape::Mesh(m) => {
                triangles += m.faces.len();
                "Mesh"
            }
        };
        *shapes.entry(k).or_default() += 1;
    }
    println!("  entities    {}", scene.world.len());
    for (k, n) in &shapes {
        println!("    {n:>5} x {k}");
    }
    if triangles > 0 {
        println!("          ({triangles} mesh triangles)");
    }
    let mut materials: BTreeMap<String, (String, usize)> = BTreeMap::new();
    for (m, name) in scene
        .world
        .query::<(&Material, Option<&MaterialName>)>()
        .iter()
    {
        let key = name.map_or_else(|| "(inline)".to_string(), |n| n.0.clone());
        let kind = match m {
            Material::Phong(_) => "Phong",
            Material::Mirror(_) => "Mirror",
            Material::Transmissive(_) => "Transmissive",
        };
        let e = materials
            .entry(format!("{key} [{kind}]"))
            .or_insert((kind.into(), 0));
        e.1 += 1;
    }
    println!("  materials   {} in use", materials.len());
    for (k, (_, n)) in &materials {
        println!("    {k}: {n} entities");
    }
    let lights: Vec<_> = scene.world.query::<&WorldLight>().iter().copied().collect();
    println!("  lights      {}", lights.len());
    for l in lights {
        let WorldLight::Point {
            position,
            intensity,
        } = l;
        println!("    Point at {position} intensity {intensity} W/sr");
    }
    let prepared = rtis::extract(&scene);
    println!("  effects     {}", prepared.effects);
    for w in scene.warnings.iter().chain(&prepared.warnings) {
        println!("warning: {w}");
    }
    Ok(())
}

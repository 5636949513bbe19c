//! `rtis check`.

use super::CliError;
use rtis::scene::{self, LightDesc, MaterialDesc, ShapeDesc, file::CameraFields};
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
    let (pos, look, up) = s.camera.0.frame();
    let kind = match s.camera.0 {
        CameraFields::Perspective { fov, .. } => format!("perspective, fov {} deg", fov.0),
        CameraFields::Orthographic { height, .. } => format!("orthographic, height {}", height.0),
    };
    println!("  camera      {kind}, at {pos} looking at {look}, up {up}");
    println!("  shader      {:?}", s.shader);
    println!("  model       {:?}", s.model);
    println!("  background  {}", s.background.0);
    println!("  seed        {}", s.seed);

    let mut shapes: BTreeMap<&str, usize> = BTreeMap::new();
    let mut triangles = 0usize;
    for (shape, mesh) in scene
        .world
        .query::<(&ShapeDesc, Option<&scene::LoadedMesh>)>()
        .iter()
    {
        let k = match shape {
            ShapeDesc::Sphere { .. } => "Sphere",
            ShapeDesc::InfinitePlane { .. } => "InfinitePlane",
            ShapeDesc::Triangle { .. } => "Triangle",
            ShapeDesc::TriangleMesh { faces, .. } => {
                triangles += faces.len();
                "TriangleMesh"
            }
            ShapeDesc::Mesh { .. } => {
                triangles += mesh.map_or(0, |m| m.0.faces.len());
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
        .query::<(&MaterialDesc, Option<&scene::MaterialName>)>()
        .iter()
    {
        let key = name.map_or_else(|| "(inline)".to_string(), |n| n.0.clone());
        let kind = match m {
            MaterialDesc::Phong { .. } => "Phong",
            MaterialDesc::Mirror { .. } => "Mirror",
            MaterialDesc::Transmissive { .. } => "Transmissive",
            MaterialDesc::Named(_) => "Named",
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
    let lights: Vec<_> = scene.world.query::<&LightDesc>().iter().copied().collect();
    println!("  lights      {}", lights.len());
    for l in lights {
        let LightDesc::Point {
            position,
            intensity,
        } = l;
        println!("    Point at {} intensity {} W/sr", position.0, intensity.0);
    }
    let prepared = rtis::RenderScene::prepare(&scene);
    println!("  effects     {}", prepared.effects);
    for w in scene.warnings.iter().chain(&prepared.warnings) {
        println!("warning: {w}");
    }
    Ok(())
}

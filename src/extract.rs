//! The extraction step, in the spirit of Bevy's extract phase: the only code that knows both
//! the ECS world and the render data. It queries the world once, derives the effects from the
//! parts, and assembles the flat, camera-relative, single-precision [`RenderScene`].
//!
//! Scene coordinates are doubles. Extraction subtracts the camera position (in double precision)
//! before rounding to `f32`, so a scene far from the origin renders as precisely as one at it.

use crate::accel::{FLAT, Geometry, Prim};
use crate::geometry::{Aabb, Placement};
use crate::light::{
    AreaLight, EmissionTexture, Emitter, Emitters, Emitting, Light, NO_LIGHT, PointLight,
    RadianceTexture, SpotLight,
};
use crate::material::{Material, Model};
use crate::render::{RenderScene, effects};
use crate::shader::Shader;
use crate::shape::{Corners, Shape};
use crate::texture::{Footprint, MaterialTextures, Texture};
use crate::world::{Name, Projection, Scene, Transform, WorldEnvironment, WorldLight, WorldShape};
use glam::Vec3A;

/// Build the render data of a loaded scene.
pub fn extract(scene: &Scene) -> RenderScene {
    let s = &scene.settings;
    // The camera is the origin of the render coordinates.
    let origin = s.camera.position;
    let camera = s.camera.extract(s.film.width as f32 / s.film.height as f32);

    // Shapes with their materials (each distinct material stored once).
    let mut warnings = Vec::new();
    let mut materials: Vec<Material> = Vec::new();
    let mut textures: Vec<MaterialTextures> = Vec::new();
    let mut prims = Vec::new();
    let mut normals = Vec::new();
    let mut uvs: Vec<Option<[glam::Vec2; 3]>> = Vec::new();
    let mut area_lights = Vec::new();
    // The textures of emitters whose radiance is textured.
    let mut emission_textures: Vec<Texture> = Vec::new();
    let none = MaterialTextures::default();
    for (entity, shape, m, tex, name, transform, (emitter, radiance)) in scene
        .world
        .query::<(
            hecs::Entity,
            &WorldShape,
            &Material,
            Option<&MaterialTextures>,
            Option<&Name>,
            Option<&Transform>,
            (Option<&Emitter>, Option<&RadianceTexture>),
        )>()
        .iter()
    {
        let tex = tex.unwrap_or(&none);
        let material =
            match (0..materials.len()).position(|i| materials[i] == *m && textures[i] == *tex) {
                Some(i) => i as u32,
                None => {
                    materials.push(*m);
                    textures.push(tex.clone());
                    (materials.len() - 1) as u32
                }
            };
        let place = Placement::new(transform, origin);
        // Texture coordinates are kept only where a texture reads them: other triangles stay
        // flat, shaded as before at no cost.
        let textured = !tex.is_empty() || radiance.is_some();
        if textured
            && let WorldShape::Mesh(mesh) = shape
            && mesh.uvs.is_empty()
        {
            let label = name.map_or_else(|| format!("entity {}", entity.id()), |n| n.0.clone());
            warnings.push(format!(
                "{label}: a textured mesh without texture coordinates (an OBJ file without `vt`, \
                 or a TriangleMesh): each triangle maps the texture by its barycentric \
                 coordinates, (0, 0), (1, 0) and (0, 1) at its corners"
            ));
        }
        // A textured emitter's texture, stored once for all of its primitives.
        let emission = radiance.map(|RadianceTexture(t)| {
            emission_textures.push(t.clone());
            ((emission_textures.len() - 1) as u32, t.mean())
        });
        let dropped = shape.extract(&place, &mut |shape, corners| {
            let corners = Corners {
                uvs: corners.uvs.filter(|_| textured),
                ..corners
            };
            let smooth = match corners {
                Corners::NONE => FLAT,
                Corners { normals: n, uvs: t } => {
                    // A triangle with coordinates but no normals shades with its geometric
                    // normal (zero normals interpolate to nothing).
                    normals.push(n.unwrap_or([Vec3A::ZERO; 3]));
                    uvs.push(t);
                    (normals.len() - 1) as u32
                }
            };
            // Each primitive of an emitting shape is one area light.
            let emitting = match shape {
                Shape::Sphere(sphere) => Some(Emitting::Sphere(sphere)),
                Shape::Triangle(t) => Some(Emitting::Triangle(t)),
                // The loader refuses emitting planes (infinite power).
                Shape::Plane(_) => None,
            };
            let light = match (emitter, emitting) {
                (Some(&emitter), Some(shape)) => {
                    area_lights.push(match emission {
                        Some((index, mean)) => AreaLight::textured(
                            shape,
                            emitter,
                            EmissionTexture {
                                index,
                                // A triangle without coordinates: its barycentric defaults.
                                uvs: corners.uvs.unwrap_or([
                                    glam::Vec2::ZERO,
                                    glam::Vec2::X,
                                    glam::Vec2::Y,
                                ]),
                                mean,
                            },
                        ),
                        None => AreaLight::new(shape, emitter),
                    });
                    (area_lights.len() - 1) as u32
                }
                _ => NO_LIGHT,
            };
            prims.push(Prim {
                shape,
                material,
                smooth,
                light,
            })
        });
        if dropped > 0 {
            let label = name.map_or_else(|| format!("entity {}", entity.id()), |n| n.0.clone());
            warnings.push(format!(
                "{label}: {dropped} zero-area triangle(s) ignored (they can never be hit)"
            ));
        }
    }
    // Under the physically based model a Phong surface reflects at most what it receives.
    if s.model == Model::Physical {
        // A textured one is scaled where its texture is looked up (`MaterialTextures::apply`).
        for (m, _) in materials
            .iter_mut()
            .zip(&textures)
            .filter(|(_, t)| t.is_empty())
        {
            if let Material::Phong(p) = m
                && let Some(scaled) = p.energy_conserving()
            {
                warnings.push(format!(
                    "Phong material with kd {} + ks {} above 1 reflects more light than it \
                     receives: scaled to kd {}, ks {} under the Physical model",
                    p.kd, p.ks, scaled.kd, scaled.ks
                ));
                *p = scaled;
            }
        }
    }
    // Planes that no ray crosses (not glass, smooth or rough) keep every ray on the camera's
    // side; a point light there needs no plane tested on its shadow rays.
    let starts = camera.starts();
    for p in &mut prims {
        if let Shape::Plane(plane) = p.shape
            && !materials[p.material as usize].transmits()
        {
            p.shape = Shape::Plane(plane.oriented(plane.facing(&starts)));
        }
    }
    // Corners without coordinates take the barycentric defaults, when any has coordinates.
    let uvs: Vec<[glam::Vec2; 3]> = if uvs.iter().any(Option::is_some) {
        let bary = [glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y];
        uvs.into_iter().map(|t| t.unwrap_or(bary)).collect()
    } else {
        Vec::new()
    };
    let geometry = Geometry::build_with_uvs(prims, normals, uvs);
    // A ball around the scene's finite parts (shapes but planes, lights, the camera), for a
    // directional light's power.
    let mut bounds = Aabb::EMPTY.grow(Vec3A::ZERO);
    for p in geometry.prims() {
        if let Some(b) = p.shape.bounds() {
            bounds = bounds.union(b);
        }
    }
    for l in scene.world.query::<&WorldLight>().iter() {
        match l {
            WorldLight::Point { position, .. } | WorldLight::Spot { position, .. } => {
                bounds = bounds.grow((*position - origin).as_vec3a());
            }
            // At infinity: not part of the ball.
            WorldLight::Directional { .. } => {}
        }
    }
    let scene_radius = 0.5 * (bounds.max - bounds.min).length();
    let lights: Vec<_> = scene
        .world
        .query::<&WorldLight>()
        .iter()
        .map(|l| match l.extract(origin, scene_radius) {
            Light::Point(p) => Light::Point(PointLight {
                in_room: geometry.in_room(p.position),
                ..p
            }),
            Light::Spot(s) => Light::Spot(SpotLight {
                in_room: geometry.in_room(s.position),
                ..s
            }),
            directional @ Light::Directional(_) => directional,
        })
        .collect();
    let environment = scene
        .world
        .query::<&WorldEnvironment>()
        .iter()
        .next()
        .map(|env| env.extract(scene_radius));
    let emitters = Emitters::with_points(area_lights, emission_textures, environment, &[]);

    // The effects, derived once from the parts, before the render scene is assembled.
    let derived = effects::derive(
        &s.shader,
        &geometry,
        &materials,
        &lights,
        &emitters,
        s.background,
        &s.effects,
    );
    warnings.extend(derived.warnings);
    // Warn when a scene asks for a strategy the Course model cannot use (not for the default,
    // `Mis`, which every Path scene has unless it says otherwise).
    if let Shader::Path(p) = s.shader
        && derived.effects.emission
        && p.lights == crate::sampling::LightSampling::Brdf
        && p.lights_under(s.model) != p.lights
    {
        warnings.push(format!(
            "Path(lights: {:?}) under the Course model: area lights are light-sampled there (the \
             course's Eq. 3; its indirect weights estimate another integral), so the strategy \
             applies only under `model: Physical`",
            p.lights
        ));
    }
    let mut render = RenderScene {
        camera,
        geometry,
        materials,
        footprint: {
            // A pixel's angle (perspective) or height (orthographic).
            let rows = s.film.height as f32;
            match s.camera.projection {
                Projection::Perspective { fov, .. } => Footprint {
                    spread: 2.0 * (fov.to_radians() as f32 / 2.0).tan() / rows,
                    base: 0.0,
                },
                Projection::Orthographic { height } => Footprint {
                    spread: 0.0,
                    base: height as f32 / rows,
                },
            }
        },
        // Kept only when some material is textured: shading then looks them up.
        textures: if textures.iter().all(MaterialTextures::is_empty) {
            Vec::new()
        } else {
            textures
        },
        lights,
        emitters,
        background: s.background,
        shader: s.shader,
        model: s.model,
        film: s.film,
        seed: s.seed,
        origin,
        effects: derived.effects,
        switched_off: derived.switched_off,
        warnings,
        audit: None,
    };
    render.set_effects(derived.effects);
    render.set_shader(s.shader);
    render
}

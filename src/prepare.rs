//! The one place that reads the ECS world: it queries the components once and builds the flat,
//! camera-relative, single-precision [`RenderScene`] that the per-ray code uses.
//!
//! Scene coordinates are doubles. Preparing subtracts the camera position (in double precision)
//! before rounding to `f32`, so a scene far from the origin renders as precisely as one at it.

use crate::accel::{FLAT, Geometry, Prim};
use crate::camera::{Basis, Camera, Orthographic, Perspective};
use crate::effects::{Effects, Kernel, kernel};
use crate::light::{Light, PointLight};
use crate::material::{Material, Mirror, Phong, Transmissive};
use crate::scene::file::{CameraFields, Transfer};
use crate::scene::{LightDesc, LoadedMesh, MaterialDesc, Model, Scene, ShapeDesc, TransformDesc};
use crate::shader::Shader;
use crate::shape::{Plane, Shape, Sphere, Triangle};
use glam::{DAffine3, DMat3, DVec3, Vec3A};

/// Image size, sampling and output transfer of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// PNG transfer curve.
    pub transfer: Transfer,
}

/// Everything a render needs, as flat arrays. Per-ray code reads only this.
#[derive(Clone, Debug)]
pub struct RenderScene {
    /// The camera, at the origin of the prepared coordinates.
    pub camera: Camera,
    /// Primitives and their BVH.
    pub geometry: Geometry,
    /// Materials, indexed by [`Prim::material`].
    pub materials: Vec<Material>,
    /// Lights.
    pub lights: Vec<Light>,
    /// Radiance of escaped rays.
    pub background: Vec3A,
    /// The shader with its parameters.
    pub shader: Shader,
    /// Light-transport model.
    pub model: Model,
    /// Image settings.
    pub film: Film,
    /// Seed of the render's random numbers.
    pub seed: u64,
    /// World position of the prepared origin (the camera).
    pub origin: DVec3,
    /// The effects this render simulates.
    pub effects: Effects,
    /// The render kernel: which effects' code is compiled into the loop that runs.
    pub kernel: Kernel,
    /// Kernel bits of the effects the scene switched off on purpose.
    pub switched_off: Kernel,
    /// Notes from preparing (ignored degenerate triangles...).
    pub warnings: Vec<String>,
}

fn rgb(c: crate::scene::Rgb) -> Vec3A {
    c.0.as_vec3a()
}

/// Convert a material description (never `Named` once loaded).
pub fn material(m: &MaterialDesc) -> Material {
    match m {
        MaterialDesc::Phong { kd, ks, shininess } => Material::Phong(Phong {
            kd: rgb(*kd),
            ks: rgb(*ks),
            shininess: shininess.0 as f32,
        }),
        MaterialDesc::Mirror { color } => Material::Mirror(Mirror { color: rgb(*color) }),
        MaterialDesc::Transmissive { ior, color } => Material::Transmissive(Transmissive {
            ior: ior.0 as f32,
            color: rgb(*color),
        }),
        MaterialDesc::Named(n) => unreachable!("material \"{n}\" was resolved when loading"),
    }
}

impl RenderScene {
    /// Query the world once and build the render data.
    pub fn prepare(scene: &Scene) -> RenderScene {
        let s = &scene.settings;
        let (position, look_at, up) = s.camera.0.frame();
        let origin = position;
        let rel = |p: DVec3| (p - origin).as_vec3a();
        let basis = Basis::look((look_at - position).as_vec3a(), up.as_vec3a());
        let aspect = s.film.width as f32 / s.film.height as f32;
        let camera = match s.camera.0 {
            CameraFields::Perspective { fov, .. } => Camera::Perspective(Perspective {
                origin: Vec3A::ZERO,
                basis,
                tan_half_fov: (fov.0.to_radians() * 0.5).tan() as f32,
                aspect,
            }),
            CameraFields::Orthographic { height, .. } => Camera::Orthographic(Orthographic {
                origin: Vec3A::ZERO,
                basis,
                height: height.0 as f32,
                aspect,
            }),
        };

        let mut warnings = Vec::new();
        let mut materials: Vec<Material> = Vec::new();
        let mut prims = Vec::new();
        let mut normals = Vec::new();
        for (entity, shape, mat, name, transform, mesh) in scene
            .world
            .query::<(
                hecs::Entity,
                &ShapeDesc,
                &MaterialDesc,
                Option<&crate::scene::Name>,
                Option<&TransformDesc>,
                Option<&LoadedMesh>,
            )>()
            .iter()
        {
            let m = material(mat);
            let material = match materials.iter().position(|x| *x == m) {
                Some(i) => i as u32,
                None => {
                    materials.push(m);
                    (materials.len() - 1) as u32
                }
            };
            let label = name.map_or_else(|| format!("entity {}", entity.id()), |n| n.0.clone());
            let place = Placement::new(transform, origin);
            let dropped = flatten(shape, mesh, &place, &mut |shape, vertex_normals| {
                let smooth = match vertex_normals {
                    Some(n) => {
                        normals.push(n);
                        (normals.len() - 1) as u32
                    }
                    None => FLAT,
                };
                prims.push(Prim {
                    shape,
                    material,
                    smooth,
                })
            });
            if dropped > 0 {
                warnings.push(format!(
                    "{label}: {dropped} zero-area triangle(s) ignored (they can never be hit)"
                ));
            }
        }
        let lights = scene
            .world
            .query::<&LightDesc>()
            .iter()
            .map(|l| match l {
                LightDesc::Point {
                    position,
                    intensity,
                } => Light::Point(PointLight {
                    position: rel(position.0),
                    intensity: rgb(*intensity),
                }),
            })
            .collect();
        let mut prepared = RenderScene {
            camera,
            geometry: Geometry::build(prims, normals),
            materials,
            lights,
            background: rgb(s.background),
            shader: Shader::from_desc(&s.shader),
            model: s.model,
            film: Film {
                width: s.film.width,
                height: s.film.height,
                spp: s.film.spp,
                transfer: s.film.transfer,
            },
            seed: s.seed,
            origin,
            effects: Effects::default(),
            kernel: kernel::ALL,
            switched_off: 0,
            warnings,
        };
        let (effects, notes) = Effects::derive(&prepared, &s.effects);
        let (all_on, _) = Effects::derive(&prepared, &Default::default());
        prepared.switched_off = all_on.kernel() & !effects.kernel();
        prepared.warnings.extend(notes);
        prepared.set_effects(effects);
        prepared
    }

    /// Simulate exactly `effects`: choose the kernel, and zero the ambient term and the
    /// background when they are off.
    pub fn set_effects(&mut self, effects: Effects) {
        if !effects.ambient
            && let Shader::Global(g) = &mut self.shader
        {
            g.ambient = Vec3A::ZERO;
        }
        if !effects.background {
            self.background = Vec3A::ZERO;
        }
        self.effects = effects;
        self.kernel = effects.kernel();
    }

    /// Render with the unspecialised kernel (every effect's code present, except those the
    /// scene switched off on purpose), for checking that specialisation changes no pixel and
    /// measuring what it saves.
    pub fn unspecialised(&self) -> RenderScene {
        RenderScene {
            kernel: kernel::ALL & !self.switched_off,
            ..self.clone()
        }
    }
}

/// Where an entity's shape goes: its transform, then the shift to camera-relative coordinates.
struct Placement {
    affine: DAffine3,
    normal_matrix: DMat3,
    origin: DVec3,
    uniform_scale: f64,
}

impl Placement {
    fn new(t: Option<&TransformDesc>, origin: DVec3) -> Self {
        let affine = t.map_or(DAffine3::IDENTITY, TransformDesc::affine);
        Placement {
            affine,
            normal_matrix: affine.matrix3.inverse().transpose(),
            origin,
            uniform_scale: t.map_or(1.0, |t| t.scale.0.x.abs()),
        }
    }

    /// A point, transformed and made camera-relative.
    fn point(&self, p: DVec3) -> Vec3A {
        (self.affine.transform_point3(p) - self.origin).as_vec3a()
    }

    /// A normal, transformed by the inverse transpose and normalised.
    fn normal(&self, n: DVec3) -> Vec3A {
        (self.normal_matrix * n).normalize().as_vec3a()
    }
}

/// Turn one shape description into prepared shapes, each with its vertex normals when smooth;
/// returns how many zero-area triangles were dropped.
fn flatten(
    shape: &ShapeDesc,
    mesh: Option<&LoadedMesh>,
    at: &Placement,
    push: &mut dyn FnMut(Shape, Option<[Vec3A; 3]>),
) -> usize {
    let mut dropped = 0;
    let mut triangle = |v: [Vec3A; 3], n: Option<[Vec3A; 3]>| match Triangle::new(v[0], v[1], v[2])
    {
        Some(t) => push(Shape::Triangle(t), n),
        None => dropped += 1,
    };
    match shape {
        ShapeDesc::Sphere { center, radius } => push(
            Shape::Sphere(Sphere {
                c: at.point(center.0),
                r: (radius.0 * at.uniform_scale) as f32,
            }),
            None,
        ),
        ShapeDesc::InfinitePlane { point, normal } => push(
            Shape::Plane(Plane::through(at.point(point.0), at.normal(normal.0))),
            None,
        ),
        ShapeDesc::Triangle { a, b, c } => {
            triangle([at.point(a.0), at.point(b.0), at.point(c.0)], None)
        }
        ShapeDesc::TriangleMesh {
            vertices,
            faces,
            normals,
        } => {
            let v: Vec<Vec3A> = vertices.iter().map(|p| at.point(p.0)).collect();
            let n: Vec<Vec3A> = normals.iter().map(|d| at.normal(d.0)).collect();
            for &(i, j, k) in faces.iter() {
                let idx = [i as usize, j as usize, k as usize];
                triangle(
                    idx.map(|i| v[i]),
                    (!n.is_empty()).then(|| idx.map(|i| n[i])),
                );
            }
        }
        ShapeDesc::Mesh { .. } => {
            let Some(LoadedMesh(m)) = mesh else {
                unreachable!("meshes are loaded with the scene")
            };
            let v: Vec<Vec3A> = m.positions.iter().map(|p| at.point(p.as_dvec3())).collect();
            let n: Vec<Vec3A> = m.normals.iter().map(|d| at.normal(d.as_dvec3())).collect();
            for f in &m.faces {
                let idx = f.map(|i| i as usize);
                triangle(
                    idx.map(|i| v[i]),
                    (!n.is_empty()).then(|| idx.map(|i| n[i])),
                );
            }
        }
    }
    dropped
}

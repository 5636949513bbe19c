//! The closed set of lights. Each variant lives in its own file; [`Light`] dispatches by `match`.
//!
//! [`WorldLight`] is the ECS component (scene units, double precision); [`WorldLight::extract`]
//! makes the camera-relative [`Light`] that shaders use. Point, spot and directional lights are
//! summed at every shading point (the course's Eq. 3). Emitting shapes ([`Emitter`]) become [`AreaLight`]s, one
//! per primitive, gathered in [`Emitters`] with the environment light ([`EnvironmentLight`], a
//! constant sky or an image), which picks one per light sample in proportion to its power. [`choose_by_importance`] picks one point light at a shading point in proportion
//! to the light it could send there.

mod area;
mod directional;
mod emitters;
mod environment;
mod importance;
mod point;
mod sky_map;
mod spot;

pub use area::{AreaLight, EmissionTexture, Emitter, Emitting, LightSample, RadianceTexture};
pub use directional::DirectionalLight;
pub use emitters::{Chosen, Emitters, NO_LIGHT};
pub use environment::{EnvironmentLight, Sky, WorldEnvironment};
pub use importance::{choose_by_importance, importance};
pub use point::PointLight;
pub use sky_map::{SkyMap, luminance};
pub use spot::SpotLight;

use glam::{DVec3, Vec3A};

/// Light arriving at a point from one light: unit direction towards the light, distance to it,
/// and incident radiance.
#[derive(Clone, Copy, Debug)]
pub struct Incident {
    /// Unit direction from the shaded point towards the light.
    pub wi: Vec3A,
    /// Distance to the light.
    pub dist: f32,
    /// Incident radiance `L_i` (for a point light `I / d^2`).
    pub li: Vec3A,
}

/// A light as the world holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WorldLight {
    /// An isotropic point light.
    Point {
        /// Position, scene units.
        position: DVec3,
        /// Radiant intensity, W/sr per channel.
        intensity: Vec3A,
    },
    /// A spot light (Mitsuba 3's `spot`): intensity within the beam, falling linearly in the
    /// angle to zero at the cutoff.
    Spot {
        /// Position, scene units.
        position: DVec3,
        /// The direction it points along (not zero).
        direction: DVec3,
        /// Radiant intensity on the axis, W/sr per channel.
        intensity: Vec3A,
        /// Half-angle of the cone beyond which it is black, degrees, in (0, 90].
        cutoff_angle: f64,
        /// Half-angle of the full beam, degrees, in (0, cutoff_angle].
        beam_width: f64,
    },
    /// A directional light (a sun at infinity, Mitsuba 3's `directional`).
    Directional {
        /// The direction the light travels in (not zero).
        direction: DVec3,
        /// Irradiance on a surface facing it, W/m^2 per channel.
        irradiance: Vec3A,
    },
}

impl WorldLight {
    /// The light in render coordinates, whose origin is the world point `origin`, in a scene
    /// whose finite parts fit in a ball of radius `scene_radius` (a directional light's power).
    pub fn extract(&self, origin: DVec3, scene_radius: f32) -> Light {
        match *self {
            WorldLight::Point {
                position,
                intensity,
            } => Light::Point(PointLight {
                position: (position - origin).as_vec3a(),
                intensity,
                in_room: false,
            }),
            WorldLight::Spot {
                position,
                direction,
                intensity,
                cutoff_angle,
                beam_width,
            } => Light::Spot(SpotLight {
                position: (position - origin).as_vec3a(),
                axis: direction.normalize().as_vec3a(),
                intensity,
                beam: beam_width.to_radians() as f32,
                cutoff: cutoff_angle.to_radians() as f32,
                in_room: false,
            }),
            WorldLight::Directional {
                direction,
                irradiance,
            } => Light::Directional(DirectionalLight {
                direction: direction.normalize().as_vec3a(),
                irradiance,
                scene_radius,
            }),
        }
    }
}

/// A prepared light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// An isotropic point light.
    Point(PointLight),
    /// A spot light.
    Spot(SpotLight),
    /// A directional light.
    Directional(DirectionalLight),
}

impl Light {
    /// Emitted power, averaged over the channels.
    pub fn power(&self) -> f32 {
        match self {
            Light::Point(l) => l.power(),
            Light::Spot(l) => l.power(),
            Light::Directional(l) => l.power(),
        }
    }

    /// True if no plane can block a shadow ray towards the light ([`PointLight::in_room`]).
    #[inline]
    pub fn in_room(&self) -> bool {
        match self {
            Light::Point(l) => l.in_room,
            Light::Spot(l) => l.in_room,
            // Planes can stand between any point and infinity.
            Light::Directional(_) => false,
        }
    }

    /// Light arriving at `p` from this light, ignoring occlusion; `None` when `p` coincides
    /// with the light.
    #[inline]
    pub fn incident(&self, p: Vec3A) -> Option<Incident> {
        match self {
            Light::Point(l) => l.incident(p),
            Light::Spot(l) => l.incident(p),
            Light::Directional(l) => Some(l.incident()),
        }
    }
}

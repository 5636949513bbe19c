//! Cameras. Follow the course's convention: camera space has +x right, +y up and looks down +z;
//! pixel `(col, row)` has row 0 at the top; image coordinates `(u, v)` in `[0, 1]^2` run right and
//! down; the vertical extent is set by the field of view and the horizontal one by the aspect
//! ratio `width / height`. Looking down +z with +y up, world -x is on the image's left (unless
//! the camera is [`Handedness::Right`], Mitsuba 3's convention, whose images are the mirror).

mod orthographic;
mod perspective;

pub use orthographic::Orthographic;
pub use perspective::{Perspective, ThinLens};

use crate::geometry::Ray;
use glam::{DVec3, Vec3A};

/// Which way the image's right runs in the camera's frame (looking along `forward` with `up`
/// up). The two conventions give mirror images of each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
pub enum Handedness {
    /// The course's: the image's right is `up x forward` (looking down +z with +y up, world +x
    /// is on the right).
    #[default]
    Left,
    /// Mitsuba 3's: the image's right is `forward x up` (world +x on the left in that view),
    /// so that a scene imported from Mitsuba renders as Mitsuba's image, not its mirror.
    Right,
}

/// How a camera projects: the part of a [`WorldCamera`] that is not its frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Perspective with vertical field of view `fov` in degrees, in (0, 180): a pinhole, or a
    /// thin lens.
    Perspective {
        /// Vertical field of view, degrees.
        fov: f64,
        /// The lens: aperture radius and focus distance, scene units, both > 0; `None` for a
        /// pinhole.
        lens: Option<WorldLens>,
    },
    /// Parallel projection of an image rectangle `height` scene units tall.
    Orthographic {
        /// Vertical extent, scene units, > 0.
        height: f64,
    },
}

/// A thin lens as the world holds it (see [`ThinLens`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldLens {
    /// Aperture radius, scene units, > 0.
    pub radius: f64,
    /// Distance to the plane in focus along the viewing direction, scene units, > 0.
    pub focus_distance: f64,
}

/// A camera as the world holds it: scene units, double precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldCamera {
    /// The projection.
    pub projection: Projection,
    /// Centre of projection (perspective) or of the image rectangle (orthographic).
    pub position: DVec3,
    /// A point the camera looks at, not `position`.
    pub look_at: DVec3,
    /// Up hint, not parallel to `look_at - position`.
    pub up: DVec3,
    /// Which way the image's right runs.
    pub handedness: Handedness,
}

impl WorldCamera {
    /// The camera of a render whose origin is this camera's position, for a film of
    /// `aspect = width / height`.
    pub fn extract(&self, aspect: f32) -> Camera {
        let mut basis = Basis::look(
            (self.look_at - self.position).as_vec3a(),
            self.up.as_vec3a(),
        );
        if self.handedness == Handedness::Right {
            basis.right = -basis.right;
        }
        match self.projection {
            Projection::Perspective { fov, lens } => Camera::Perspective(Perspective {
                origin: Vec3A::ZERO,
                basis,
                tan_half_fov: (fov.to_radians() * 0.5).tan() as f32,
                aspect,
                lens: lens.map(|l| ThinLens {
                    radius: l.radius as f32,
                    focus_distance: l.focus_distance as f32,
                }),
            }),
            Projection::Orthographic { height } => Camera::Orthographic(Orthographic {
                origin: Vec3A::ZERO,
                basis,
                height: height as f32,
                aspect,
            }),
        }
    }
}

/// The camera's orthonormal basis: `right x up` is `forward` in a left-handed sense, matching
/// the course (right = up x forward).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basis {
    /// Unit viewing direction.
    pub forward: Vec3A,
    /// Unit image-right direction.
    pub right: Vec3A,
    /// Unit image-up direction.
    pub up: Vec3A,
}

impl Basis {
    /// The basis looking along `forward` with `up_hint` roughly up. Both must be non-zero and
    /// not parallel (scene validation ensures it).
    pub fn look(forward: Vec3A, up_hint: Vec3A) -> Self {
        let forward = forward.normalize();
        let right = up_hint.cross(forward).normalize();
        let up = forward.cross(right);
        Basis { forward, right, up }
    }
}

/// A prepared camera (camera-relative: its position is the origin of the prepared scene).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Camera {
    /// Pinhole perspective projection.
    Perspective(Perspective),
    /// Parallel projection.
    Orthographic(Orthographic),
}

impl Camera {
    /// The corners of the region camera rays start from: every primary ray's origin is a
    /// convex combination of them (the centre of projection, four times, for a pinhole; the
    /// square around the lens for a thin lens).
    pub fn starts(&self) -> [Vec3A; 4] {
        match self {
            Camera::Perspective(c) => match c.lens {
                None => [c.origin; 4],
                Some(l) => [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
                    .map(|(x, y)| c.origin + l.radius * (x * c.basis.right + y * c.basis.up)),
            },
            Camera::Orthographic(c) => {
                [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(u, v)| c.ray(u, v).o)
            }
        }
    }

    /// The primary ray through image point `(u, v)`, both in `[0, 1]`, `(0, 0)` the top-left;
    /// a thin lens draws its point on the lens from `lens_sample` (the others draw nothing).
    #[inline]
    pub fn ray(&self, u: f32, v: f32, lens_sample: impl FnOnce() -> (f32, f32)) -> Ray {
        match self {
            Camera::Perspective(c) => c.ray(u, v, lens_sample),
            Camera::Orthographic(c) => c.ray(u, v),
        }
    }
}

/// Map image coordinates to the image plane: `(2u - 1) * half_w` right, `(1 - 2v) * half_h` up.
#[inline]
pub(crate) fn plane_offset(b: &Basis, u: f32, v: f32, half_w: f32, half_h: f32) -> Vec3A {
    (2.0 * u - 1.0) * half_w * b.right + (1.0 - 2.0 * v) * half_h * b.up
}

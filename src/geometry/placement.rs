//! Where a shape goes: its transform, then the shift to camera-relative single precision.

use glam::{DAffine3, DMat3, DVec3, Vec3A};

/// A transform given as scale, then rotation (degrees about x, then y, then z), then
/// translation, all in double precision scene units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Scale per axis; no component is zero.
    pub scale: DVec3,
    /// Rotation in degrees about x, then y, then z.
    pub rotate: DVec3,
    /// Translation.
    pub translate: DVec3,
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Transform = Transform {
        scale: DVec3::ONE,
        rotate: DVec3::ZERO,
        translate: DVec3::ZERO,
    };

    /// The affine map `translate * Rz * Ry * Rx * scale`.
    pub fn affine(&self) -> DAffine3 {
        let r = self.rotate * (std::f64::consts::PI / 180.0);
        let rot =
            DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x);
        DAffine3 {
            matrix3: rot * DMat3::from_diagonal(self.scale),
            translation: self.translate,
        }
    }
}

/// A transform followed by the shift that puts the camera at the origin, then rounding to
/// `f32`: the map from a shape's scene coordinates to render coordinates. The shift is done in
/// double precision, so a scene far from the origin renders as precisely as one at it.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    affine: DAffine3,
    normal_matrix: DMat3,
    origin: DVec3,
    uniform_scale: f64,
}

impl Placement {
    /// The placement of a shape with transform `t` (none: as written) in a render whose origin
    /// is the world point `origin`.
    pub fn new(t: Option<&Transform>, origin: DVec3) -> Self {
        let affine = t.map_or(DAffine3::IDENTITY, Transform::affine);
        Placement {
            affine,
            normal_matrix: affine.matrix3.inverse().transpose(),
            origin,
            uniform_scale: t.map_or(1.0, |t| t.scale.x.abs()),
        }
    }

    /// A point, transformed and made camera-relative.
    #[inline]
    pub fn point(&self, p: DVec3) -> Vec3A {
        (self.affine.transform_point3(p) - self.origin).as_vec3a()
    }

    /// A point, transformed and made camera-relative, still in double precision.
    #[inline]
    pub fn point_f64(&self, p: DVec3) -> DVec3 {
        self.affine.transform_point3(p) - self.origin
    }

    /// A normal, transformed by the inverse transpose and normalised.
    #[inline]
    pub fn normal(&self, n: DVec3) -> Vec3A {
        (self.normal_matrix * n).normalize().as_vec3a()
    }

    /// True if the transform mirrors (a negative determinant: an odd number of negative
    /// scales). A triangle's winding then reverses, so its vertices are swapped to keep its
    /// normal, and with it the side a one-sided emitter lights, the transformed normal.
    #[inline]
    pub fn mirrors(&self) -> bool {
        self.affine.matrix3.determinant() < 0.0
    }

    /// A length under a uniform scale (the radius of a sphere).
    #[inline]
    pub fn length(&self, l: f64) -> f32 {
        (l * self.uniform_scale) as f32
    }
}

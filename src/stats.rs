//! Ray counts by kind.

use serde::Serialize;
use std::ops::AddAssign;

/// Why a ray was traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RayKind {
    /// From the camera through a pixel.
    Camera,
    /// Towards a light, to test visibility.
    Shadow,
    /// Off a mirror, or glass under total internal reflection.
    Reflection,
    /// Through glass.
    Refraction,
    /// Gathering indirect light at a diffuse or glossy surface.
    Indirect,
}

/// How many rays of each kind a render traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RayStats {
    /// Camera rays.
    pub camera: u64,
    /// Shadow rays.
    pub shadow: u64,
    /// Reflection rays (mirror, total internal reflection).
    pub reflection: u64,
    /// Refraction rays.
    pub refraction: u64,
    /// Indirect rays.
    pub indirect: u64,
    /// Camera samples with a contribution that came out NaN, infinite or negative, or whose
    /// contributions sum beyond the largest `f32`: dropped (counted as zero), never averaged
    /// into a pixel. Zero for every valid scene; not a ray count.
    pub dropped: u64,
}

impl RayStats {
    /// Count one ray of `kind`.
    #[inline]
    pub fn count(&mut self, kind: RayKind) {
        *match kind {
            RayKind::Camera => &mut self.camera,
            RayKind::Shadow => &mut self.shadow,
            RayKind::Reflection => &mut self.reflection,
            RayKind::Refraction => &mut self.refraction,
            RayKind::Indirect => &mut self.indirect,
        } += 1;
    }

    /// All rays.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.reflection + self.refraction + self.indirect
    }
}

impl AddAssign for RayStats {
    fn add_assign(&mut self, o: RayStats) {
        self.camera += o.camera;
        self.shadow += o.shadow;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.indirect += o.indirect;
        self.dropped += o.dropped;
    }
}

//! The effects a render simulates, as flags the shaders test at run time.
//!
//! `render::effects::derive` decides them once per render from the scene's parts; the scene may
//! switch effects off on purpose ([`Switches`]). An effect that is off costs nothing: its rays
//! are never traced. Specialising the code itself on the effects (64 monomorphised kernels)
//! was measured and removed: see `docs/architecture.md`.

use serde::Serialize;
use std::fmt;

/// Effect switches as a scene asks for them: `None` lets rtis decide from the scene, `false`
/// switches an effect off to trade accuracy for time, `true` asks for it (a warning when the
/// scene cannot produce it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Switches {
    /// Shadow rays towards point lights.
    pub shadows: Option<bool>,
    /// Mirror reflection (and glass's total internal and Fresnel reflection).
    pub reflection: Option<bool>,
    /// Refraction through glass.
    pub refraction: Option<bool>,
    /// Traced indirect light.
    pub indirect: Option<bool>,
    /// Global's ambient term (Eq. 2).
    pub ambient: Option<bool>,
    /// Background radiance.
    pub background: Option<bool>,
    /// Light emitted by shapes (area lights).
    pub emission: Option<bool>,
}

/// The effects a render simulates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Effects {
    /// Shadow rays are traced. Off: every light reaches every point facing it.
    pub shadows: bool,
    /// Mirror rays (and glass reflection) are traced. Off: those directions return black.
    pub reflection: bool,
    /// Refraction rays are traced. Off: glass is opaque black (except its reflection).
    pub refraction: bool,
    /// Indirect rays are traced. Off: Global uses the ambient term at every Phong hit; Path
    /// stops after the first Phong vertex's direct light.
    pub indirect: bool,
    /// The ambient term is added.
    pub ambient: bool,
    /// Escaped rays see a non-black background.
    pub background: bool,
    /// Emitting shapes (area lights) are seen by rays and sampled for direct light. Off: they
    /// emit nothing.
    pub emission: bool,
    /// The scene has spheres (informative: no code depends on it).
    pub spheres: bool,
    /// The scene has infinite planes (informative).
    pub planes: bool,
    /// The scene has triangles (informative).
    pub triangles: bool,
}

impl Effects {
    /// Every effect on.
    pub const ALL: Effects = Effects {
        shadows: true,
        reflection: true,
        refraction: true,
        indirect: true,
        ambient: true,
        background: true,
        emission: true,
        spheres: true,
        planes: true,
        triangles: true,
    };

    /// The effects' names and values, in a fixed order.
    pub fn named(&self) -> [(&'static str, bool); 10] {
        [
            ("shadows", self.shadows),
            ("reflection", self.reflection),
            ("refraction", self.refraction),
            ("indirect", self.indirect),
            ("ambient", self.ambient),
            ("background", self.background),
            ("emission", self.emission),
            ("spheres", self.spheres),
            ("planes", self.planes),
            ("triangles", self.triangles),
        ]
    }

    /// These effects less those on in `off`.
    pub fn without(self, off: Effects) -> Effects {
        Effects {
            shadows: self.shadows && !off.shadows,
            reflection: self.reflection && !off.reflection,
            refraction: self.refraction && !off.refraction,
            indirect: self.indirect && !off.indirect,
            ambient: self.ambient && !off.ambient,
            background: self.background && !off.background,
            emission: self.emission && !off.emission,
            spheres: self.spheres && !off.spheres,
            planes: self.planes && !off.planes,
            triangles: self.triangles && !off.triangles,
        }
    }
}

impl fmt::Display for Effects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let all = self.named();
        let on: Vec<&str> = all.iter().filter(|(_, v)| *v).map(|(n, _)| *n).collect();
        let off: Vec<&str> = all.iter().filter(|(_, v)| !*v).map(|(n, _)| *n).collect();
        write!(f, "on: {}; off: {}", join(&on), join(&off))
    }
}

fn join(v: &[&str]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

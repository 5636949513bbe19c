//! Mitsuba 3's `checkerboard`: `color0` where the fractional parts of `u` and `v` are both at
//! most 1/2 or both above it, `color1` elsewhere; one square of each per unit of `u` and `v`.

use glam::{Vec2, Vec3A};

/// Two colours in alternating squares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkerboard {
    /// Where both halves agree (Mitsuba's default 0.4).
    pub color0: Vec3A,
    /// Where they differ (Mitsuba's default 0.2).
    pub color1: Vec3A,
}

impl Checkerboard {
    /// The colour at `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3A {
        let f = uv - uv.floor();
        if (f.x > 0.5) == (f.y > 0.5) {
            self.color0
        } else {
            self.color1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Known points: the squares alternate along u and v, and repeat every unit, negative
    /// coordinates included.
    #[test]
    fn squares_alternate() {
        let c = Checkerboard {
            color0: Vec3A::ONE,
            color1: Vec3A::ZERO,
        };
        let at = |u: f32, v: f32| c.eval(Vec2::new(u, v)).x;
        assert_eq!(at(0.25, 0.25), 1.0);
        assert_eq!(at(0.75, 0.25), 0.0);
        assert_eq!(at(0.25, 0.75), 0.0);
        assert_eq!(at(0.75, 0.75), 1.0);
        assert_eq!(at(3.25, -1.75), 1.0);
        assert_eq!(at(-0.25, 0.25), 0.0);
    }
}

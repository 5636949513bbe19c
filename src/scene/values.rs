//! Validated value types of the scene format. Each rejects bad input while it is parsed, so the
//! error carries the line and column of the offending value.

use glam::DVec3;
use serde::{Deserialize, Serialize};

fn finite3(v: [f64; 3]) -> Result<DVec3, String> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        Err(format!(
            "non-finite number in ({}, {}, {}): every coordinate must be finite",
            v[0], v[1], v[2]
        ))
    }
}

/// A point or offset `(x, y, z)`, in scene units. Every coordinate finite.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Point(pub DVec3);

impl TryFrom<[f64; 3]> for Point {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        finite3(v).map(Point)
    }
}
impl From<Point> for [f64; 3] {
    fn from(p: Point) -> Self {
        p.0.to_array()
    }
}

/// A direction `(x, y, z)`: finite and of non-zero length; it is normalised when used.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Direction(pub DVec3);

impl TryFrom<[f64; 3]> for Direction {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let d = finite3(v)?;
        let len = d.length();
        if len == 0.0 || !len.is_finite() {
            return Err(format!(
                "zero-length direction ({}, {}, {}): a normal or up vector needs a direction",
                v[0], v[1], v[2]
            ));
        }
        Ok(Direction(d))
    }
}
impl From<Direction> for [f64; 3] {
    fn from(p: Direction) -> Self {
        p.0.to_array()
    }
}

/// A linear RGB triple `(r, g, b)`: finite and non-negative. Depending on where it is used it is
/// a reflectance (unitless), a radiance (W/(m^2 sr)) or an intensity (W/sr).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Rgb(pub DVec3);

impl Rgb {
    /// Black.
    pub const BLACK: Rgb = Rgb(DVec3::ZERO);
    /// `(v, v, v)`.
    pub const fn grey(v: f64) -> Rgb {
        Rgb(DVec3::splat(v))
    }
}

impl TryFrom<[f64; 3]> for Rgb {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let c = finite3(v)?;
        if c.min_element() < 0.0 {
            return Err(format!(
                "negative colour ({}, {}, {}): colours and intensities must be >= 0",
                v[0], v[1], v[2]
            ));
        }
        Ok(Rgb(c))
    }
}
impl From<Rgb> for [f64; 3] {
    fn from(p: Rgb) -> Self {
        p.0.to_array()
    }
}

/// A finite number greater than 0.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Positive(pub f64);

impl TryFrom<f64> for Positive {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v > 0.0 {
            Ok(Positive(v))
        } else {
            Err(format!("must be a finite number greater than 0, got {v}"))
        }
    }
}
impl From<Positive> for f64 {
    fn from(p: Positive) -> Self {
        p.0
    }
}

/// A finite number greater than or equal to 0.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct NonNegative(pub f64);

impl TryFrom<f64> for NonNegative {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v >= 0.0 {
            Ok(NonNegative(v))
        } else {
            Err(format!("must be a finite number >= 0, got {v}"))
        }
    }
}
impl From<NonNegative> for f64 {
    fn from(p: NonNegative) -> Self {
        p.0
    }
}

/// A vertical field of view in degrees, strictly between 0 and 180.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Fov(pub f64);

impl TryFrom<f64> for Fov {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v.is_finite() && v > 0.0 && v < 180.0 {
            Ok(Fov(v))
        } else {
            Err(format!(
                "field of view must be between 0 and 180 degrees (exclusive), got {v}"
            ))
        }
    }
}
impl From<Fov> for f64 {
    fn from(p: Fov) -> Self {
        p.0
    }
}

/// A count of at least 1 and at most `MAX` (samples per pixel, hemisphere samples...).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(try_from = "u64", into = "u32")]
pub struct Count<const MAX: u32>(pub u32);

impl<const MAX: u32> TryFrom<u64> for Count<MAX> {
    type Error = String;
    fn try_from(v: u64) -> Result<Self, String> {
        if v == 0 {
            Err("must be at least 1, got 0".into())
        } else if v > MAX as u64 {
            Err(format!("must be at most {MAX}, got {v}"))
        } else {
            Ok(Count(v as u32))
        }
    }
}
impl<const MAX: u32> From<Count<MAX>> for u32 {
    fn from(c: Count<MAX>) -> Self {
        c.0
    }
}

/// A whole number from 0 to `MAX` (depths).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(try_from = "u64", into = "u32")]
pub struct UpTo<const MAX: u32>(pub u32);

impl<const MAX: u32> TryFrom<u64> for UpTo<MAX> {
    type Error = String;
    fn try_from(v: u64) -> Result<Self, String> {
        if v > MAX as u64 {
            Err(format!("must be at most {MAX}, got {v}"))
        } else {
            Ok(UpTo(v as u32))
        }
    }
}
impl<const MAX: u32> From<UpTo<MAX>> for u32 {
    fn from(c: UpTo<MAX>) -> Self {
        c.0
    }
}

/// A scale `(sx, sy, sz)`: finite, no component zero (negative mirrors).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Scale(pub DVec3);

impl TryFrom<[f64; 3]> for Scale {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let s = finite3(v)?;
        if s.x == 0.0 || s.y == 0.0 || s.z == 0.0 {
            return Err(format!(
                "zero scale ({}, {}, {}): every component must be non-zero",
                v[0], v[1], v[2]
            ));
        }
        Ok(Scale(s))
    }
}
impl From<Scale> for [f64; 3] {
    fn from(p: Scale) -> Self {
        p.0.to_array()
    }
}

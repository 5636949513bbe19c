//! Validated value types of the scene format. Each rejects bad input while it is parsed, so the
//! error carries the line and column of the offending value.
//!
//! Every number is checked against the range the renderer computes in: render data is single
//! precision (largest value about 3.4e38), and intersection tests square coordinates and
//! lengths, so coordinates and lengths stay within 1e9 scene units, radiances within 1e30,
//! reflectances within [0, 1]. A value that is finite as a double but would overflow a float
//! is refused here, with its location, rather than turning into NaN pixels later.

use crate::material::conductor::Metal;
use glam::DVec3;
use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};

/// Largest coordinate magnitude, and largest length, in scene units.
pub const MAX_COORD: f64 = 1e9;
/// Smallest length (radius, height, distance) in scene units.
pub const MIN_LENGTH: f64 = 1e-9;
/// Largest radiance or intensity per channel.
pub const MAX_RADIANCE: f64 = 1e30;
/// Smallest and largest index of refraction.
pub const IOR_RANGE: (f64, f64) = (0.01, 100.0);
/// Largest Phong exponent.
pub const MAX_SHININESS: f64 = 1e6;
/// Smallest and largest magnitude of a scale factor.
pub const SCALE_RANGE: (f64, f64) = (1e-6, 1e6);

/// A number as a person would write it: plain in [1e-4, 1e6), scientific beyond.
pub fn show(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e6).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A triple as `(x, y, z)` with [`show`]n numbers.
fn show3(v: [f64; 3]) -> String {
    format!("({}, {}, {})", show(v[0]), show(v[1]), show(v[2]))
}

fn finite3(v: [f64; 3]) -> Result<DVec3, String> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        Err(format!(
            "non-finite number in {}: every coordinate must be finite",
            show3(v)
        ))
    }
}

/// A point or offset `(x, y, z)`, in scene units. Every coordinate finite and at most
/// [`MAX_COORD`] in magnitude.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Point(pub DVec3);

impl TryFrom<[f64; 3]> for Point {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let p = finite3(v)?;
        if p.abs().max_element() > MAX_COORD {
            return Err(format!(
                "coordinate out of range in {}: each must be within +-1e9 scene units",
                show3(v)
            ));
        }
        Ok(Point(p))
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
                "zero-length direction {}: a normal or up vector needs a direction",
                show3(v)
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

/// A linear RGB triple `(r, g, b)` of radiance (W/(m^2 sr)) or intensity (W/sr): each channel
/// in [0, [`MAX_RADIANCE`]].
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
                "negative colour {}: colours and intensities must be >= 0",
                show3(v)
            ));
        }
        if c.max_element() > MAX_RADIANCE {
            return Err(format!(
                "colour {} out of range: radiances and intensities must be at most 1e30",
                show3(v)
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

/// One part of a conductor's complex index of refraction `eta + i k`, per channel `(r, g, b)`:
/// each from 0 to 1000 (unitless; measured metals lie below 10).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct IorPart(pub DVec3);

impl TryFrom<[f64; 3]> for IorPart {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let c = finite3(v)?;
        if c.min_element() < 0.0 || c.max_element() > 1000.0 {
            return Err(format!(
                "{} out of range: a conductor's eta and k must be from 0 to 1000 per channel",
                show3(v)
            ));
        }
        Ok(IorPart(c))
    }
}
impl From<IorPart> for [f64; 3] {
    fn from(p: IorPart) -> Self {
        p.0.to_array()
    }
}

/// A metal written by its name in Mitsuba 3's `material` parameter (`"Au"`...): one of
/// [`Metal::ALL`](crate::material::conductor::Metal::ALL).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "String", into = "String")]
pub struct MetalName(pub Metal);

impl TryFrom<String> for MetalName {
    type Error = String;
    fn try_from(v: String) -> Result<Self, String> {
        Metal::from_name(&v).map(MetalName).ok_or_else(|| {
            format!(
                "unknown metal \"{}\": known metals are {}",
                v.chars().take(40).collect::<String>(),
                Metal::ALL.map(|m| format!("\"{}\"", m.name())).join(", ")
            )
        })
    }
}
impl From<MetalName> for String {
    fn from(m: MetalName) -> Self {
        m.0.name().to_string()
    }
}

/// A reflectance `(r, g, b)`: the fraction of light a surface sends on, each channel in [0, 1]
/// (unitless).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Reflectance(pub DVec3);

impl TryFrom<[f64; 3]> for Reflectance {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let c = finite3(v)?;
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            return Err(format!(
                "reflectance {} out of range: each channel must be in [0, 1]",
                show3(v)
            ));
        }
        Ok(Reflectance(c))
    }
}
impl From<Reflectance> for [f64; 3] {
    fn from(p: Reflectance) -> Self {
        p.0.to_array()
    }
}

/// A length in scene units (radius, image height, distance): from [`MIN_LENGTH`] to
/// [`MAX_COORD`].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Positive(pub f64);

impl TryFrom<f64> for Positive {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if (MIN_LENGTH..=MAX_COORD).contains(&v) {
            Ok(Positive(v))
        } else {
            Err(format!(
                "must be a length from 1e-9 to 1e9 scene units, got {}",
                show(v)
            ))
        }
    }
}

/// A microfacet roughness `alpha` (the RMS slope of the microfacets for Beckmann): from
/// [`MIN_ALPHA`](crate::material::microfacet::MIN_ALPHA), 1e-4, to 1 (unitless).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Roughness(pub f64);

impl TryFrom<f64> for Roughness {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        let min = crate::material::microfacet::MIN_ALPHA as f64;
        if (min..=1.0).contains(&v) {
            Ok(Roughness(v))
        } else {
            Err(format!(
                "roughness alpha must be from 1e-4 to 1, got {} (use Mirror, Conductor, \
                 Transmissive or Plastic for a smooth surface)",
                show(v)
            ))
        }
    }
}
impl From<Roughness> for f64 {
    fn from(p: Roughness) -> Self {
        p.0
    }
}

/// An index of refraction, in [`IOR_RANGE`].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Ior(pub f64);

impl TryFrom<f64> for Ior {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if (IOR_RANGE.0..=IOR_RANGE.1).contains(&v) {
            Ok(Ior(v))
        } else {
            Err(format!(
                "index of refraction must be from 0.01 to 100, got {}",
                show(v)
            ))
        }
    }
}
impl From<Ior> for f64 {
    fn from(p: Ior) -> Self {
        p.0
    }
}
impl From<Positive> for f64 {
    fn from(p: Positive) -> Self {
        p.0
    }
}

/// A lens's aperture radius in scene units: 0 (a pinhole, the default) or from
/// [`MIN_LENGTH`] to [`MAX_COORD`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Aperture(pub f64);

impl TryFrom<f64> for Aperture {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v == 0.0 || (MIN_LENGTH..=MAX_COORD).contains(&v) {
            Ok(Aperture(v))
        } else {
            Err(format!(
                "must be 0 (a pinhole) or a radius from 1e-9 to 1e9 scene units, got {}",
                show(v)
            ))
        }
    }
}
impl From<Aperture> for f64 {
    fn from(a: Aperture) -> Self {
        a.0
    }
}

/// A spot light's half-angle in degrees, in (0, 90].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct SpotAngle(pub f64);

impl TryFrom<f64> for SpotAngle {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if v > 0.0 && v <= 90.0 {
            Ok(SpotAngle(v))
        } else {
            Err(format!(
                "must be a half-angle from the spot's axis in degrees, above 0 and at most 90, \
                 got {}",
                show(v)
            ))
        }
    }
}
impl From<SpotAngle> for f64 {
    fn from(a: SpotAngle) -> Self {
        a.0
    }
}

/// A Phong exponent, from 0 to [`MAX_SHININESS`].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct NonNegative(pub f64);

impl TryFrom<f64> for NonNegative {
    type Error = String;
    fn try_from(v: f64) -> Result<Self, String> {
        if (0.0..=MAX_SHININESS).contains(&v) {
            Ok(NonNegative(v))
        } else {
            Err(format!("must be a number from 0 to 1e6, got {}", show(v)))
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
        if (0.001..=179.999).contains(&v) {
            Ok(Fov(v))
        } else {
            Err(format!(
                "field of view must be from 0.001 to 179.999 degrees, got {}",
                show(v)
            ))
        }
    }
}
impl From<Fov> for f64 {
    fn from(p: Fov) -> Self {
        p.0
    }
}

/// A number written where a whole number is expected: `Ok` with its value when it is whole
/// (`720`, `720.0`, `1e3`), else `Err` with the number as written, for the message.
struct Whole;

impl Visitor<'_> for Whole {
    type Value = Result<i128, String>;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a whole number")
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        Ok(Ok(v.into()))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        Ok(Ok(v.into()))
    }
    fn visit_u128<E: de::Error>(self, v: u128) -> Result<Self::Value, E> {
        Ok(i128::try_from(v).map_err(|_| v.to_string()))
    }
    fn visit_i128<E: de::Error>(self, v: i128) -> Result<Self::Value, E> {
        Ok(Ok(v))
    }
    fn visit_f32<E: de::Error>(self, v: f32) -> Result<Self::Value, E> {
        // Shown as the f32 it was read as, not its f64 widening (0.1, not 0.100000001).
        Ok(self.visit_f64::<E>(v.into())?.map_err(|_| format!("{v}")))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        if v.fract() == 0.0 && v.abs() < 1e18 {
            Ok(Ok(v as i128))
        } else {
            Ok(Err(show(v)))
        }
    }
}

/// A whole number from `min` to `max`, with a message naming the bound it breaks, or the
/// range when it is not whole.
fn whole_in<'de, D: Deserializer<'de>>(d: D, min: u64, max: u64) -> Result<u64, D::Error> {
    let message = match d.deserialize_any(Whole)? {
        Ok(v) if (i128::from(min)..=i128::from(max)).contains(&v) => return Ok(v as u64),
        Ok(v) if v > i128::from(max) => format!("must be at most {max}, got {v}"),
        Ok(v) if min > 0 => format!("must be at least {min}, got {v}"),
        Ok(v) => format!("must be a whole number from {min} to {max}, got {v}"),
        Err(shown) => format!("must be a whole number from {min} to {max}, got {shown}"),
    };
    Err(de::Error::custom(message))
}

/// A count of at least 1 and at most `MAX` (samples per pixel, hemisphere samples...).
/// A number with a fractional part is refused with a message saying a whole number is
/// expected.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(into = "u32")]
pub struct Count<const MAX: u32>(pub u32);

impl<'de, const MAX: u32> Deserialize<'de> for Count<MAX> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        whole_in(d, 1, MAX.into()).map(|v| Count(v as u32))
    }
}
impl<const MAX: u32> From<Count<MAX>> for u32 {
    fn from(c: Count<MAX>) -> Self {
        c.0
    }
}

/// A whole number from 0 to `MAX` (depths).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(into = "u32")]
pub struct UpTo<const MAX: u32>(pub u32);

impl<'de, const MAX: u32> Deserialize<'de> for UpTo<MAX> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        whole_in(d, 0, MAX.into()).map(|v| UpTo(v as u32))
    }
}
impl<const MAX: u32> From<UpTo<MAX>> for u32 {
    fn from(c: UpTo<MAX>) -> Self {
        c.0
    }
}

/// A whole number from 0 to `u64::MAX` (the seed).
struct Any64(u64);

impl<'de> Deserialize<'de> for Any64 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        whole_in(d, 0, u64::MAX).map(Any64)
    }
}

/// Deserialize an optional seed: a whole number from 0 to `u64::MAX`.
pub fn seed<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u64>, D::Error> {
    Ok(Option::<Any64>::deserialize(d)?.map(|s| s.0))
}

/// A vertex index of a face.
struct Index(u32);

impl<'de> Deserialize<'de> for Index {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        whole_in(d, 0, u32::MAX.into()).map(|v| Index(v as u32))
    }
}

/// Deserialize the faces of a triangle mesh: index triples, at least one.
pub fn faces<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(u32, u32, u32)>, D::Error> {
    let f = Vec::<(Index, Index, Index)>::deserialize(d)?;
    if f.is_empty() {
        return Err(de::Error::custom(
            "a TriangleMesh needs at least one face: `faces: [(0, 1, 2)]` makes a triangle \
             of the first three vertices",
        ));
    }
    Ok(f.into_iter().map(|(a, b, c)| (a.0, b.0, c.0)).collect())
}

/// A scale `(sx, sy, sz)`: each component's magnitude in [`SCALE_RANGE`] (negative mirrors).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "[f64; 3]", into = "[f64; 3]")]
pub struct Scale(pub DVec3);

impl TryFrom<[f64; 3]> for Scale {
    type Error = String;
    fn try_from(v: [f64; 3]) -> Result<Self, String> {
        let s = finite3(v)?;
        if s.x == 0.0 || s.y == 0.0 || s.z == 0.0 {
            return Err(format!(
                "zero scale {}: every component must be non-zero",
                show3(v)
            ));
        }
        let m = s.abs();
        if m.min_element() < SCALE_RANGE.0 || m.max_element() > SCALE_RANGE.1 {
            return Err(format!(
                "scale {} out of range: each component's magnitude must be from \
                 1e-6 to 1e6",
                show3(v)
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

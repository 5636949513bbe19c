//! Mitsuba's `<spectrum>` property in RGB, as Mitsuba 3's RGB variants convert it
//! (`properties.cpp`, `spectrum_list_to_srgb`):
//!
//! - a constant `value="v"` is the grey `v`, except on an emitter, where it is `v` times the
//!   sRGB of XYZ (1, 1, 1) (about (1.205, 0.948, 0.909): an equal-energy spectrum is pinkish
//!   against sRGB's D65 white);
//! - wavelength-value pairs `"400:0.1, 500:0.5, ..."` are interpolated linearly, multiplied by
//!   the CIE 1931 matching functions (and the D65 illuminant, except on an emitter), summed at
//!   1000 even wavelengths from 360 to 830 nm, normalised by Mitsuba's `MI_CIE_Y_NORMALIZATION`,
//!   and turned into linear sRGB; negative channels become 0, and channels above 1 become 1 for
//!   a reflectance (not for an emitter's radiance or an index of refraction).

use super::cie;
use glam::DVec3;

/// What a spectrum describes, which decides its conversion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// A reflectance or another value in [0, 1].
    Bounded,
    /// An index of refraction (`eta`, `k`, `int_ior`, `ext_ior`): weighted by D65, not clamped
    /// above.
    Unbounded,
    /// An emitter's radiance, intensity or irradiance: no D65, not clamped above.
    Emitter,
}

/// Linear sRGB of XYZ.
fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    let m = cie::XYZ_TO_SRGB;
    DVec3::from_array(m[0]) * xyz.x
        + DVec3::from_array(m[1]) * xyz.y
        + DVec3::from_array(m[2]) * xyz.z
}

/// A table of [`cie`] at wavelength `w` (nm), interpolated linearly.
fn at(table: &[f64], w: f64) -> f64 {
    let x = (w - cie::MIN).clamp(0.0, cie::MAX - cie::MIN);
    let i = (x as usize).min(table.len() - 2);
    let f = x - i as f64;
    table[i] * (1.0 - f) + table[i + 1] * f
}

/// A finite number, or why `v` is not one (the XML reader's numbers too).
pub fn number(v: &str) -> Result<f64, String> {
    match v.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(format!("`{v}` is not a finite number")),
    }
}

/// The linear RGB of a `<spectrum value="...">` describing `role`, or why it has none.
pub fn to_rgb(value: &str, role: Role) -> Result<DVec3, String> {
    if !value.contains(':') {
        let v = number(value)?;
        return Ok(match role {
            Role::Emitter => xyz_to_srgb(DVec3::ONE) * v,
            _ => DVec3::splat(v),
        });
    }
    // The pairs, by increasing wavelength.
    let mut pairs = Vec::new();
    for item in value.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (w, v) = item.split_once(':').ok_or_else(|| {
            format!("`{item}`: a spectrum's pairs are written `wavelength:value`")
        })?;
        pairs.push((number(w)?, number(v)?));
    }
    if pairs.len() < 2 || pairs.windows(2).any(|p| p[1].0 <= p[0].0) {
        return Err(
            "a spectrum needs two or more `wavelength:value` pairs, by increasing wavelength"
                .into(),
        );
    }
    let (first, last) = (pairs[0].0, pairs[pairs.len() - 1].0);
    const STEPS: usize = 1000;
    let mut xyz = DVec3::ZERO;
    for i in 0..STEPS {
        let w = cie::MIN + (i as f64 / (STEPS - 1) as f64) * (cie::MAX - cie::MIN);
        if w < first || w > last {
            continue;
        }
        // The interval holding w, and the value there.
        let k = pairs
            .partition_point(|p| p.0 <= w)
            .clamp(1, pairs.len() - 1)
            - 1;
        let ((w0, v0), (w1, v1)) = (pairs[k], pairs[k + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let weight = if role == Role::Emitter {
            1.0
        } else {
            at(&cie::D65, w)
        };
        xyz += DVec3::new(at(&cie::X, w), at(&cie::Y, w), at(&cie::Z, w)) * v * weight;
    }
    xyz *= (cie::MAX - cie::MIN) * cie::Y_NORMALIZATION / STEPS as f64;
    let rgb = xyz_to_srgb(xyz).max(DVec3::ZERO);
    Ok(match role {
        Role::Bounded => rgb.min(DVec3::ONE),
        _ => rgb,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3.9.1's `spectrum_list_to_srgb` of two spectra (printed by its Python
    /// bindings): with D65 and clamping, and without.
    #[test]
    fn pairs_convert_as_mitsuba() {
        let s = "400:0.1, 500:0.5, 600:0.8, 700:0.3";
        let bounded = to_rgb(s, Role::Bounded).unwrap();
        let emitter = to_rgb(s, Role::Emitter).unwrap();
        for (got, want) in [
            (bounded, DVec3::new(0.752186, 0.64527, 0.271707)),
            (emitter, DVec3::new(0.883847, 0.618319, 0.236324)),
        ] {
            assert!((got - want).abs().max_element() < 2e-5, "{got} vs {want}");
        }
        let e = to_rgb("400:1, 300:2", Role::Bounded).unwrap_err();
        assert!(e.contains("increasing"), "{e}");
    }

    /// A constant spectrum is grey, but on an emitter the sRGB of equal energy.
    #[test]
    fn constants() {
        assert_eq!(to_rgb("0.5", Role::Bounded).unwrap(), DVec3::splat(0.5));
        let e = to_rgb("1", Role::Emitter).unwrap();
        assert!(
            (e - DVec3::new(1.20479, 0.948291, 0.908916))
                .abs()
                .max_element()
                < 1e-5,
            "{e}"
        );
    }
}

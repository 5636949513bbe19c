//! Mitsuba's `<spectrum>` property in RGB: a constant spectrum is the grey of its value, as
//! Mitsuba's RGB variants take it. Wavelength-value pairs are not converted yet (refused with a
//! located error that says so).

use super::xml::{Pos, number};
use crate::scene::SceneError;
use glam::DVec3;

/// The linear RGB of a `<spectrum value="...">`.
pub fn to_rgb(value: &str, pos: &Pos) -> Result<DVec3, SceneError> {
    if value.contains(':') {
        return Err(pos.error(format!(
            "`<spectrum value=\"{value}\">`: wavelength-value pairs are not converted to RGB \
             yet; give an `<rgb>` value instead, or a constant spectrum"
        )));
    }
    Ok(DVec3::splat(number(value, pos)?))
}

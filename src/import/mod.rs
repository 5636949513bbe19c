//! Mitsuba 3 scenes imported: a front end beside [`crate::scene`] that reads Mitsuba's XML
//! ([`xml`]) and writes the same scene as rtis scene text ([`convert`]), which the scene loader
//! then reads as it reads any RON file, so that everything after it is shared. `rtis import`
//! writes that text; `rtis render` and `rtis check` take a `.xml` file by the same conversion.
//! docs/import.md lists the supported subset and the conventions.

mod cie;
pub mod convert;
pub mod spectrum;
pub mod xml;

use crate::scene::{Scene, SceneError};
use std::path::Path;

/// The rtis scene text of the Mitsuba scene at `path`, its files named relative to the folder
/// `to` (where the text will be read from), and the conversion's warnings.
pub fn import(path: &Path, to: &Path) -> Result<convert::Converted, SceneError> {
    import_with(path, to, false)
}

/// [`import`]; with `lenient`, what cannot be converted is skipped with a warning for each
/// ([`convert::convert`]).
pub fn import_with(
    path: &Path,
    to: &Path,
    lenient: bool,
) -> Result<convert::Converted, SceneError> {
    let doc = xml::read(path)?;
    convert::convert(&doc, &path.display().to_string(), to, lenient)
}

/// True if `path` names a Mitsuba scene (`.xml`).
pub fn is_mitsuba(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// The scene at `path`: a Mitsuba scene converted ([`import`]), or an rtis scene file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    if !is_mitsuba(path) {
        return crate::scene::load_path(path);
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    let converted = import(path, dir)?;
    let name = format!("{} (as imported)", path.display());
    // A check only the loader makes is placed in the converted text: say how to see it.
    let mut scene =
        crate::scene::load_str(&converted.text, &name, Some(dir)).map_err(|mut e| {
            e.message = crate::scene::clip_message(&format!(
                "{} (in the rtis scene converted from {}: `rtis import {}` prints it)",
                e.message,
                path.display(),
                path.display()
            ));
            e
        })?;
    scene.warnings.extend(converted.warnings);
    Ok(scene)
}

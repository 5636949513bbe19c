//! Writing images: PNG (8-bit, sRGB or linear transfer) and OpenEXR (linear float), always
//! through a temporary file renamed into place, so no half-written file is ever left behind.

use super::film::Image;
use image::{ImageFormat, Rgb32FImage, RgbImage};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// Temporary files being written now. A writer holds the lock from creating its file until
/// the file is renamed into place or removed; [`remove_pending`] takes the same lock, so an
/// interrupt either waits for a write to finish or finds nothing to remove, and never leaves a
/// temporary file behind.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Remove every temporary file being written and hold the lock for the rest of the process, so
/// that no write starts again: for an interrupt handler that then exits.
pub fn remove_pending() {
    let guard = pending();
    for p in guard.iter() {
        let _ = std::fs::remove_file(p);
    }
    std::mem::forget(guard);
}

/// A test hook: with `RTIS_TEST_WRITE_PAUSE_MS` set, hold a finished temporary file that long
/// before renaming it, so that `tests/integration/cli_interrupt.rs` can interrupt a write at a known moment.
fn pause_for_tests() {
    if let Some(ms) = std::env::var("RTIS_TEST_WRITE_PAUSE_MS")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
    {
        std::thread::sleep(std::time::Duration::from_millis(ms.min(60_000)));
    }
}

/// Run `write` on the temporary file `tmp` of `path`, registered so that an interrupt removes
/// it, then rename it into place; on any failure the temporary file is removed.
fn write_via_temp(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), OutputError> {
    with_temp(path, |tmp| {
        write(tmp)?;
        pause_for_tests();
        std::fs::rename(tmp, path).map_err(|e| e.to_string())
    })
}

/// Run `f` on the temporary file name of `path`, registered in [`PENDING`] (lock held) for the
/// whole call; the file is removed if `f` fails.
fn with_temp(path: &Path, f: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), OutputError> {
    let tmp = temp_path(path);
    let mut guard = pending();
    guard.push(tmp.clone());
    let result = f(&tmp);
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    guard.retain(|p| p != &tmp);
    drop(guard);
    result.map_err(|e| io_err(path, e))
}

/// How 8-bit PNG values are made from linear radiance (EXR output is always linear float).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum Transfer {
    /// The sRGB curve after clamping to [0, 1]: what screens expect.
    #[default]
    Srgb,
    /// `min(v, 1) * 255`, no curve: the course's BMP output.
    Linear,
}

/// An image that could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension names no format rtis writes.
    #[error("{path}: unsupported output format: use a .png or .exr file name")]
    Format {
        /// The output path.
        path: String,
    },
    /// The file system refused.
    #[error("{path}: cannot write output: {reason}")]
    Io {
        /// The output path.
        path: String,
        /// Why.
        reason: String,
    },
    /// A reference image could not be read.
    #[error("{path}: cannot read image: {reason}")]
    Read {
        /// The input path.
        path: String,
        /// Why.
        reason: String,
    },
}

/// The image format for a path, from its extension.
pub fn format_of(path: &Path) -> Result<ImageFormat, OutputError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(ImageFormat::Png),
        Some("exr") => Ok(ImageFormat::OpenExr),
        _ => Err(OutputError::Format {
            path: path.display().to_string(),
        }),
    }
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> OutputError {
    OutputError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

/// Check before a long render that `path` has a known format and its folder takes new files.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    format_of(path)?;
    check_folder(path)
}

/// Check before a long render that the folder of `path` takes new files (any format).
pub fn check_folder(path: &Path) -> Result<(), OutputError> {
    with_temp(path, |tmp| {
        std::fs::write(tmp, b"")
            .and_then(|()| std::fs::remove_file(tmp))
            .map_err(|e| e.to_string())
    })
}

/// Write `bytes` to `path` through a temporary file and a rename (for text outputs).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_via_temp(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(|e| e.to_string())
    })
}

/// The sRGB transfer curve for a linear value clamped to [0, 1].
#[inline]
pub fn srgb_encode(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// 8-bit values of an image under `transfer`.
pub fn to_rgb8(img: &Image, transfer: Transfer) -> RgbImage {
    let enc = |v: f32| -> u8 {
        let e = match transfer {
            Transfer::Srgb => srgb_encode(v),
            // The course's min(v, 1) * 255.
            Transfer::Linear => v.clamp(0.0, 1.0),
        };
        (e * 255.0).round() as u8
    };
    RgbImage::from_fn(img.width, img.height, |x, y| {
        let p = img.get(x, y);
        image::Rgb([enc(p.x), enc(p.y), enc(p.z)])
    })
}

/// Write `img` to `path` (format by extension) via a temporary file and a rename.
pub fn save(img: &Image, path: &Path, transfer: Transfer) -> Result<(), OutputError> {
    let format = format_of(path)?;
    write_via_temp(path, |tmp| {
        match format {
            ImageFormat::OpenExr => Rgb32FImage::from_fn(img.width, img.height, |x, y| {
                image::Rgb(img.get(x, y).to_array())
            })
            .save_with_format(tmp, format),
            _ => to_rgb8(img, transfer).save_with_format(tmp, format),
        }
        .map_err(|e| e.to_string())
    })
}

/// [`save`], with `note` in the file: a PNG `Comment` text chunk (what `identify -verbose` or
/// `exiftool` shows). For other formats the note is not written.
pub fn save_noted(
    img: &Image,
    path: &Path,
    transfer: Transfer,
    note: &str,
) -> Result<(), OutputError> {
    if format_of(path)? != ImageFormat::Png {
        return save(img, path, transfer);
    }
    let rgb = to_rgb8(img, transfer);
    write_via_temp(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), img.width, img.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder
            .add_text_chunk("Comment".into(), note.into())
            .map_err(|e| e.to_string())?;
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer
            .write_image_data(rgb.as_raw())
            .map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    })
}

/// Read a linear float image (EXR, or PNG taken as sRGB-encoded).
pub fn load(path: &Path) -> Result<Image, OutputError> {
    let err = |e: image::ImageError| OutputError::Read {
        path: path.display().to_string(),
        reason: e.to_string(),
    };
    let dynimg = image::open(path).map_err(err)?;
    let is_exr = matches!(format_of(path), Ok(ImageFormat::OpenExr));
    let rgb = dynimg.to_rgb32f();
    // EXR is linear; PNG values are sRGB-encoded.
    let decode = |v: f32| match (is_exr, v <= 0.040_45) {
        (true, _) => v,
        (false, true) => v / 12.92,
        (false, false) => ((v + 0.055) / 1.055).powf(2.4),
    };
    Ok(Image {
        width: rgb.width(),
        height: rgb.height(),
        pixels: rgb
            .pixels()
            .map(|p| glam::Vec3A::new(decode(p[0]), decode(p[1]), decode(p[2])))
            .collect(),
    })
}

/// Write float channels `layers` (name and row-major values) of a `width` x `height` image as
/// one OpenEXR file, through a temporary file and a rename.
pub fn write_layers(
    path: &Path,
    width: u32,
    height: u32,
    layers: Vec<(String, Vec<f32>)>,
) -> Result<(), OutputError> {
    use exr::prelude::*;
    let channels: Vec<AnyChannel<FlatSamples>> = layers
        .into_iter()
        .map(|(name, v)| AnyChannel::new(name.as_str(), FlatSamples::F32(v)))
        .collect();
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::named("rtis"),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    let bytes = exr_bytes(layer).map_err(|e| io_err(path, e))?;
    write_file(path, &bytes)
}

/// One layer of float or integer channels as the bytes of an OpenEXR file.
pub fn exr_bytes(
    layer: exr::prelude::Layer<exr::prelude::AnyChannels<exr::prelude::FlatSamples>>,
) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let mut bytes = std::io::Cursor::new(Vec::new());
    exr::prelude::Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

//! Writing images (src/render/output.rs): the sRGB curve at its breakpoints and the 8-bit
//! values it gives.

use glam::Vec3A;
use rtis::render::film::Image;
use rtis::render::output::{Transfer, srgb_encode, to_rgb8};

#[test]
fn srgb_encode_is_exact_at_its_breakpoints() {
    assert_eq!(srgb_encode(0.0), 0.0);
    assert!((srgb_encode(1.0) - 1.0).abs() < 1e-7);
    // The linear segment ends at 0.0031308 with slope 12.92: 0.040449936.
    assert!((srgb_encode(0.003_130_8) - 0.040_449_936).abs() < 1e-7);
    // Just above it the power segment continues it (the curve is continuous there).
    assert!((srgb_encode(0.003_131) - 0.040_452).abs() < 2e-6);
    // Mid grey 0.5 encodes to 1.055 * 0.5^(1/2.4) - 0.055 = 0.735356.
    assert!((srgb_encode(0.5) - 0.735_356_6).abs() < 1e-6);
    // 0.18 (18% grey) encodes to 0.461356.
    assert!((srgb_encode(0.18) - 0.461_356).abs() < 1e-5);
    // Out of range clamps.
    assert_eq!(srgb_encode(-1.0), 0.0);
    assert!((srgb_encode(7.0) - 1.0).abs() < 1e-7);
}

#[test]
fn eight_bit_values_under_each_transfer() {
    let img = Image {
        width: 4,
        height: 1,
        pixels: vec![
            Vec3A::splat(0.0),
            Vec3A::splat(0.5),
            Vec3A::splat(0.18),
            Vec3A::splat(2.0),
        ],
    };
    let srgb: Vec<u8> = to_rgb8(&img, Transfer::Srgb)
        .pixels()
        .map(|p| p[0])
        .collect();
    assert_eq!(srgb, vec![0, 188, 118, 255]);
    let linear: Vec<u8> = to_rgb8(&img, Transfer::Linear)
        .pixels()
        .map(|p| p[0])
        .collect();
    // The course's min(v, 1) * 255, rounded.
    assert_eq!(linear, vec![0, 128, 46, 255]);
}

/// Reading a PNG undoes the sRGB curve on both of its segments: 10/255 lies on the linear
/// segment (divide by 12.92), 200/255 on the power segment.
#[test]
fn png_values_decode_through_the_inverse_curve() {
    let dir = std::env::temp_dir().join(format!("rtis-output-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("two.png");
    image::RgbImage::from_fn(2, 1, |x, _| image::Rgb([if x == 0 { 10 } else { 200 }; 3]))
        .save(&path)
        .unwrap();
    let img = rtis::render::output::load(&path).unwrap();
    let dark = 10.0f64 / 255.0 / 12.92;
    let bright = ((200.0f64 / 255.0 + 0.055) / 1.055).powf(2.4);
    assert!(
        (img.pixels[0].x as f64 - dark).abs() < 1e-6,
        "{}",
        img.pixels[0]
    );
    assert!(
        (img.pixels[1].x as f64 - bright).abs() < 1e-5,
        "{}",
        img.pixels[1]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

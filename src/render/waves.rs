//! Path's samples in waves: the paths of up to [`WAVE`] samples advance together, one vertex
//! each per round, the samples of a tile's pixels taken one pixel after another, so that the
//! wave stays full while the tile has samples left, whatever the samples per pixel. Each
//! round traces the paths' rays in chunks of SIMD lanes
//! ([`crate::accel::Geometry::nearest_lanes`] in a scene whose primitives are all packed, each
//! ray through the BVH with the one-ray query in others) and shades the diffuse vertices in
//! those lanes ([`crate::shader::path::lanes`]: the interaction, the point, spot and
//! directional lights and one sample of the area lights and the environment with their shadow
//! rays in lanes, the next direction and Russian roulette) and every other vertex (mirrors,
//! glass, glossy Phong, emitters, escapes, smooth triangles, normal maps, black texels) with
//! the one-ray code ([`crate::shader::path::step`]); the slots of the paths that ended go to
//! the next samples.
//!
//! Each sample draws from its own random stream in the one-ray order and adds the same
//! contributions, each computed by the same operations, and its pixel's sum is exact
//! ([`SampleSum`]), so each pixel is the one-ray render's to the bit, whatever the order of its
//! samples (`tests/integration/path_waves.rs`).

use super::{RenderScene, SampleSum, camera_ray};
use crate::sampling::Sampler;
use crate::shader::Shader;
use crate::shader::path::lanes::{self, PathSlot};
use crate::shader::path::{Path, PathState};
use crate::stats::{RayKind, RayStats};

use super::exact::RgbSum;

/// Paths in flight in a wave.
pub const WAVE: usize = 64;

/// The most primitives a scene's BVH may hold for its paths to go in waves. A wave traces its
/// rays through a BVH one by one, so a BVH scene gains only the shading in lanes, and loses the
/// packets its camera rays take otherwise (`render::pixel_sum`): measured even on Mitsuba's
/// box (36 triangles) and on the course's box with two meshes of 1,848 triangles; larger
/// meshes keep their camera packets.
pub const MAX_BVH_PRIMS: usize = 4096;

/// True if `scene`'s samples go in waves: the path tracer in a scene whose vertices the lanes
/// can shade ([`lanes::applies`]) and whose BVH is small ([`MAX_BVH_PRIMS`]).
pub fn applies(scene: &RenderScene) -> bool {
    let Shader::Path(p) = &scene.shader else {
        return false;
    };
    scene.geometry.in_bvh <= MAX_BVH_PRIMS && lanes::applies(p)
}

/// The exact sum of the samples `samples` of pixel `(col, row)` under the path tracer `p`,
/// traced in waves.
pub fn pixel_sum(
    scene: &RenderScene,
    col: u32,
    row: u32,
    samples: std::ops::Range<u32>,
    p: &Path,
    stats: &mut RayStats,
) -> RgbSum {
    let mut sum = RgbSum::default();
    wave(
        scene,
        &[(col, row)],
        samples,
        p,
        stats,
        std::slice::from_mut(&mut sum),
    );
    sum
}

/// The exact sums of the samples `samples` of each pixel `(col, row)` of `pixels` under the
/// path tracer `p`, traced in one wave that takes the pixels' samples in order, a pixel's
/// after another's, so that it stays full until the last pixel's (a pixel's sum is exact,
/// whatever the order of its samples). A wave per pixel, once used where a round held at
/// least a wave of samples per pixel, ran its last paths in ever fewer lanes at every pixel's
/// end: the whole tile's wave renders Mitsuba's area box 1.08x as fast at 128 spp
/// (progressive) and about 1.13x at 64 spp in one go (`--pass 0/1`), the course's box 1.075x
/// at 256 spp and about 1.06x at 64 spp in one go.
pub fn sums(
    scene: &RenderScene,
    pixels: &[(u32, u32)],
    samples: std::ops::Range<u32>,
    p: &Path,
    stats: &mut RayStats,
) -> Vec<RgbSum> {
    let mut out = vec![RgbSum::default(); pixels.len()];
    wave(scene, pixels, samples, p, stats, &mut out);
    out
}

/// [`sums`] of `pixels` in one wave, added into `out` (one per pixel).
fn wave(
    scene: &RenderScene,
    pixels: &[(u32, u32)],
    samples: std::ops::Range<u32>,
    p: &Path,
    stats: &mut RayStats,
    out: &mut [RgbSum],
) {
    let mut feed = Feed {
        pixel: 0,
        next: samples.start,
    };
    // The paths in flight and each one's pixel.
    let mut slots: Vec<PathSlot<SampleSum>> = Vec::with_capacity(WAVE);
    let mut of = Vec::with_capacity(WAVE);
    let mut alive = Vec::new();
    // One tracer for the wave; a path shaded one ray at a time gets its stream swapped in.
    let mut tr = scene.tracer(Sampler::new(0, 0, 0), stats);
    let diffuse = lanes::Diffuse::table(&tr);
    // The slots take the first samples, their camera rays first.
    while slots.len() < WAVE
        && let Some((pixel, slot)) = feed.start(scene, pixels, &samples, &mut tr)
    {
        slots.push(slot);
        of.push(pixel);
    }
    while !slots.is_empty() {
        // The round: each path's ray traced and its vertex shaded.
        alive.clear();
        alive.resize(slots.len(), false);
        lanes::round(&mut tr, p, &diffuse, &mut slots, &mut alive);
        // The paths that ended give their sums to their pixels and their slots, in place, to
        // the next samples (a slot is not moved: it is large); when none are left the slots
        // close up.
        let mut k = 0;
        while k < slots.len() {
            if alive[k] {
                k += 1;
                continue;
            }
            slots[k].rec.keep_into(&mut out[of[k]], tr.stats);
            match feed.next(pixels, &samples) {
                Some((pixel, (col, row), s)) => {
                    // The slot rewritten in place (built apart and moved in, it was copied
                    // twice: 3% of the time).
                    let slot = &mut slots[k];
                    let (ray, sampler) = camera_ray(scene, col, row, s);
                    tr.count(&ray, RayKind::Camera);
                    slot.st = PathState::new(&ray);
                    slot.sampler = sampler;
                    slot.rec = SampleSum::default();
                    of[k] = pixel;
                    k += 1;
                }
                None => {
                    slots.swap_remove(k);
                    alive.swap_remove(k);
                    of.swap_remove(k);
                }
            }
        }
    }
}

/// The next sample of a wave to start: its pixel's place in the wave's pixels, and its index.
struct Feed {
    pixel: usize,
    next: u32,
}

impl Feed {
    /// The next sample's pixel (its place in `pixels`) and its slot, its camera ray made and
    /// counted; `None` when every sample has started.
    #[inline]
    fn start(
        &mut self,
        scene: &RenderScene,
        pixels: &[(u32, u32)],
        samples: &std::ops::Range<u32>,
        tr: &mut crate::shader::Tracer,
    ) -> Option<(usize, PathSlot<SampleSum>)> {
        let (pixel, (col, row), s) = self.next(pixels, samples)?;
        let (ray, sampler) = camera_ray(scene, col, row, s);
        tr.count(&ray, RayKind::Camera);
        let slot = PathSlot {
            st: PathState::new(&ray),
            sampler,
            rec: SampleSum::default(),
        };
        Some((pixel, slot))
    }

    /// The next sample: its pixel's place in `pixels`, the pixel, and the sample's index;
    /// `None` when every sample has started.
    #[inline]
    fn next(
        &mut self,
        pixels: &[(u32, u32)],
        samples: &std::ops::Range<u32>,
    ) -> Option<(usize, (u32, u32), u32)> {
        loop {
            if self.pixel >= pixels.len() {
                return None;
            }
            if self.next < samples.end {
                break;
            }
            (self.pixel, self.next) = (self.pixel + 1, samples.start);
        }
        self.next += 1;
        Some((self.pixel, pixels[self.pixel], self.next - 1))
    }
}

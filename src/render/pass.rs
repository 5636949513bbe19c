//! Passes: a render split by sample index, rendered anywhere, merged bit-exactly.
//!
//! Pass `I` of `N` renders the sample indices `[I spp / N, (I + 1) spp / N)` of every pixel and
//! keeps their exact sums ([`super::exact`]). A pass file is an OpenEXR image: channels `R`,
//! `G`, `B` hold the mean of the samples it holds (to look at), and channels `sum.C.KK` (`C` in
//! R, G, B; `KK` from 00 to 09) the exact sums as 32-bit words, least significant first. Its
//! header records the scene's fingerprint, the seed, the full spp, the PNG transfer and the
//! sample ranges it holds (`rtis.ranges`, e.g. `0..341,682..1024`).
//!
//! Merging adds the exact sums, which is exact and so independent of the order and grouping of
//! the passes: the merged image has the bits of a single render of all the samples.

use super::RenderScene;
use super::exact::{RgbSum, WORDS};
use super::film::Image;
use super::output::{OutputError, Transfer};
use exr::prelude::*;
use std::ops::Range;
use std::path::Path;

/// FNV-1a, 64 bits: a stable hash for fingerprints and cache keys.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// FNV-1a over text written into it: a hash of `Debug` output without building the string.
struct Fnv(u64);

impl std::fmt::Write for Fnv {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0 = s.bytes().fold(self.0, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
        });
        Ok(())
    }
}

/// A hash of everything that decides a render's samples: camera, geometry (primitives and
/// smooth normals), materials, lights, emitters, the environment light (its map by a hash),
/// background, shader, model, effects and film size.
/// Passes of one render share it. Streamed, so a mesh of a million triangles costs a pass over
/// it, not a string of its size.
pub fn fingerprint(scene: &RenderScene) -> u64 {
    use std::fmt::Write;
    let f = &scene.film;
    let mut h = Fnv(fnv1a(b""));
    let _ = write!(h, "{:?}|", scene.camera);
    for p in scene.geometry.prims() {
        let _ = write!(h, "{p:?}");
    }
    let _ = write!(
        h,
        "|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{}x{}",
        scene.geometry.normals,
        scene.materials,
        scene.lights,
        scene.background,
        scene.shader,
        scene.model,
        scene.effects,
        f.width,
        f.height,
    );
    // Only a scene with an environment, textures or a filter other than the box hashes them,
    // so that earlier passes of other scenes still merge (a scene with an infinite plane hashes
    // the plane's point since textures came: its earlier passes are refused, never mixed).
    if !scene.textures.is_empty() {
        let _ = write!(h, "|{:?}|{:?}", scene.textures, scene.geometry.uvs);
    }
    // Each area light's emission (radiance, sides, texture), run-length: the primitives of one
    // emitter come together. (Before textured emitters the fingerprint left emission out:
    // passes of those versions are refused, never mixed.)
    let mut last = None;
    for l in &scene.emitters.lights {
        if last != Some((l.emitter, l.texture)) {
            let _ = write!(h, "|{:?}{:?}", l.emitter, l.texture);
            last = Some((l.emitter, l.texture));
        }
    }
    if !scene.emitters.textures.is_empty() {
        let _ = write!(h, "|{:?}", scene.emitters.textures);
    }
    if let Some(env) = &scene.emitters.environment {
        let _ = write!(h, "|{env:?}");
    }
    if f.filter != crate::sampling::PixelFilter::Box {
        let _ = write!(h, "|{:?}", f.filter);
    }
    if f.sampler != crate::sampling::SamplerKind::Independent {
        let _ = write!(h, "|{:?}", f.sampler);
    }
    // Path's samples have been exact sums of their contributions since the image split by
    // technique: passes of earlier versions (each sample rounded once) are refused, never
    // mixed.
    if let crate::shader::Shader::Path(_) = scene.shader {
        let _ = write!(h, "|exact contributions");
    }
    h.0
}

/// Parse `I/N` (pass `I`, counting from 0, of `N`).
pub fn parse_pass(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("--pass {s}: write I/N, for example 0/4 (pass I of N, I from 0 to N-1)");
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (u32, u32) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// The sample indices of pass `i` of `n` for `spp` samples per pixel.
pub fn pass_range(i: u32, n: u32, spp: u32) -> std::result::Result<Range<u32>, String> {
    if n > spp {
        return Err(format!(
            "{n} passes of {spp} samples per pixel: at most {spp} passes (one sample each)"
        ));
    }
    let at = |k: u32| (k as u64 * spp as u64 / n as u64) as u32;
    Ok(at(i)..at(i + 1))
}

/// What makes passes parts of one render: film size, scene fingerprint, seed and spp.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderId {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The scene's [`fingerprint`].
    pub fingerprint: u64,
    /// The render's seed.
    pub seed: u64,
    /// Samples per pixel of the whole render.
    pub spp: u32,
}

/// Which part of a [`RenderId`] differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Differs {
    /// The film size.
    Size,
    /// The scene's fingerprint.
    Fingerprint,
    /// The seed.
    Seed,
    /// The samples per pixel.
    Spp,
}

impl RenderId {
    /// The render `scene` makes.
    pub fn of(scene: &RenderScene) -> RenderId {
        RenderId {
            width: scene.film.width,
            height: scene.film.height,
            fingerprint: fingerprint(scene),
            seed: scene.seed,
            spp: scene.film.spp,
        }
    }

    /// The first part (size, fingerprint, seed, spp) in which `other` differs, with this one's
    /// value and `other`'s as text; `None` when they are one render.
    pub fn differs(&self, other: &RenderId) -> Option<(Differs, String, String)> {
        let size = |r: &RenderId| format!("{}x{}", r.width, r.height);
        if (self.width, self.height) != (other.width, other.height) {
            Some((Differs::Size, size(self), size(other)))
        } else if self.fingerprint != other.fingerprint {
            Some((
                Differs::Fingerprint,
                format!("{:016x}", self.fingerprint),
                format!("{:016x}", other.fingerprint),
            ))
        } else if self.seed != other.seed {
            Some((Differs::Seed, self.seed.to_string(), other.seed.to_string()))
        } else if self.spp != other.spp {
            Some((Differs::Spp, self.spp.to_string(), other.spp.to_string()))
        } else {
            None
        }
    }
}

/// A pass, or several merged: exact per-pixel sums of some of a render's samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Pass {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The scene's [`fingerprint`].
    pub fingerprint: u64,
    /// The render's seed.
    pub seed: u64,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// PNG transfer of the scene.
    pub transfer: Transfer,
    /// Sample ranges held, sorted, disjoint.
    pub ranges: Vec<Range<u32>>,
    /// Exact sums, row-major.
    pub sums: Vec<RgbSum>,
}

fn show_ranges(r: &[Range<u32>]) -> String {
    r.iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect::<Vec<_>>()
        .join(",")
}

fn parse_ranges(s: &str) -> Option<Vec<Range<u32>>> {
    s.split(',')
        .map(|r| {
            let (a, b) = r.split_once("..")?;
            let (a, b) = (a.parse().ok()?, b.parse().ok()?);
            (a < b).then_some(a..b)
        })
        .collect()
}

const CHANNELS: [&str; 3] = ["R", "G", "B"];

impl Pass {
    /// The render this pass is part of.
    pub fn render(&self) -> RenderId {
        RenderId {
            width: self.width,
            height: self.height,
            fingerprint: self.fingerprint,
            seed: self.seed,
            spp: self.spp,
        }
    }

    /// Samples each pixel holds.
    pub fn samples(&self) -> u64 {
        self.ranges.iter().map(|r| (r.end - r.start) as u64).sum()
    }

    /// Whether the ranges cover every sample of the render.
    pub fn is_complete(&self) -> bool {
        self.ranges.len() == 1 && self.ranges[0] == (0..self.spp)
    }

    /// The image: each pixel's mean over the samples held (all of them when complete).
    pub fn image(&self) -> Image {
        let n = self.samples();
        Image {
            width: self.width,
            height: self.height,
            pixels: self.sums.iter().map(|s| s.mean(n)).collect(),
        }
    }

    /// The pass as OpenEXR bytes (see the module documentation).
    pub fn to_exr(&self) -> std::result::Result<Vec<u8>, String> {
        let size = (self.width as usize, self.height as usize);
        let mean = self.image();
        let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
        for (c, name) in CHANNELS.iter().enumerate() {
            let v = mean.pixels.iter().map(|p| p[c]).collect();
            channels.push(AnyChannel::new(*name, FlatSamples::F32(v)));
            for k in 0..2 * WORDS {
                let words = self
                    .sums
                    .iter()
                    .map(|s| (s.0[c].words[k / 2] >> (32 * (k % 2))) as u32)
                    .collect();
                channels.push(AnyChannel::new(
                    format!("sum.{name}.{k:02}").as_str(),
                    FlatSamples::U32(words),
                ));
            }
        }
        let mut attributes = LayerAttributes::named("rtis pass");
        let mut put = |k: &str, v: String| {
            attributes
                .other
                .insert(Text::from(k), AttributeValue::Text(Text::from(v.as_str())));
        };
        put("rtis.fingerprint", format!("{:016x}", self.fingerprint));
        put("rtis.seed", self.seed.to_string());
        put("rtis.spp", self.spp.to_string());
        put("rtis.transfer", format!("{:?}", self.transfer));
        put("rtis.ranges", show_ranges(&self.ranges));
        let layer = Layer::new(
            size,
            attributes,
            Encoding::SMALL_LOSSLESS,
            AnyChannels::sort(channels.into()),
        );
        super::output::exr_bytes(layer)
    }

    /// Write the pass to `path` (an .exr name) through a temporary file and a rename.
    pub fn write(&self, path: &Path) -> std::result::Result<(), OutputError> {
        let bytes = self.to_exr().map_err(|reason| OutputError::Io {
            path: path.display().to_string(),
            reason,
        })?;
        super::output::write_file(path, &bytes)
    }

    /// Read a pass file written by [`Pass::write`].
    pub fn read(path: &Path) -> std::result::Result<Pass, String> {
        let at = |e: String| format!("{}: {e}", path.display());
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(|e| at(format!("cannot read pass: {e}")))?;
        let layer = &image.layer_data;
        let attr = |k: &str| -> std::result::Result<String, String> {
            match layer.attributes.other.get(&Text::from(k)) {
                Some(AttributeValue::Text(t)) => Ok(t.to_string()),
                _ => Err(at(format!(
                    "not an rtis pass: no `{k}` in its header (write passes with rtis render --pass)"
                ))),
            }
        };
        let number = |k: &str| -> std::result::Result<u64, String> {
            attr(k)?
                .parse::<u64>()
                .map_err(|_| at(format!("`{k}` is not a number")))
        };
        let fingerprint = u64::from_str_radix(&attr("rtis.fingerprint")?, 16)
            .map_err(|_| at("`rtis.fingerprint` is not a hash".into()))?;
        let spp =
            u32::try_from(number("rtis.spp")?).map_err(|_| at("`rtis.spp` too large".into()))?;
        let transfer = match attr("rtis.transfer")?.as_str() {
            "Linear" => Transfer::Linear,
            _ => Transfer::Srgb,
        };
        let ranges = parse_ranges(&attr("rtis.ranges")?)
            .filter(|r| {
                r.iter().all(|r| r.end <= spp) && r.windows(2).all(|w| w[0].end <= w[1].start)
            })
            .ok_or_else(|| {
                at(
                    "`rtis.ranges` is not a sorted list of disjoint sample ranges within spp"
                        .into(),
                )
            })?;
        let (w, h) = (layer.size.width(), layer.size.height());
        let mut sums = vec![RgbSum::default(); w * h];
        for (c, name) in CHANNELS.iter().enumerate() {
            for k in 0..2 * WORDS {
                let want = format!("sum.{name}.{k:02}");
                let ch = layer
                    .channel_data
                    .list
                    .iter()
                    .find(|ch| ch.name.to_string() == want)
                    .ok_or_else(|| at(format!("not an rtis pass: no channel {want}")))?;
                let FlatSamples::U32(words) = &ch.sample_data else {
                    return Err(at(format!("channel {want} is not 32-bit integer")));
                };
                for (s, &word) in sums.iter_mut().zip(words) {
                    s.0[c].words[k / 2] |= (word as u64) << (32 * (k % 2));
                }
            }
        }
        Ok(Pass {
            width: w as u32,
            height: h as u32,
            fingerprint,
            seed: number("rtis.seed")?,
            spp,
            transfer,
            ranges,
            sums,
        })
    }

    /// Merge passes named by their files: they must come from one scene and seed and hold
    /// disjoint sample ranges; unless `partial`, together they must hold every sample.
    pub fn merge(parts: Vec<(String, Pass)>) -> std::result::Result<Pass, String> {
        let mut it = parts.into_iter();
        let (first_name, mut acc) = it.next().ok_or("no passes to merge")?;
        let mut owner: Vec<(Range<u32>, String)> = acc
            .ranges
            .iter()
            .map(|r| (r.clone(), first_name.clone()))
            .collect();
        for (name, p) in it {
            if let Some((part, a, b)) = acc.render().differs(&p.render()) {
                let what = match part {
                    Differs::Size => "sizes",
                    Differs::Fingerprint => "scene fingerprints",
                    Differs::Seed => "seeds",
                    Differs::Spp => "spp",
                };
                return Err(format!(
                    "{first_name} and {name} are passes of different renders: {what} {a} and {b}"
                ));
            }
            for (a, b) in acc.sums.iter_mut().zip(&p.sums) {
                *a += *b;
            }
            owner.extend(p.ranges.iter().map(|r| (r.clone(), name.clone())));
        }
        owner.sort_by_key(|(r, _)| (r.start, r.end));
        for w in owner.windows(2) {
            let ((a, fa), (b, fb)) = (&w[0], &w[1]);
            if b.start < a.end {
                return Err(format!(
                    "samples {}..{} are in both {fa} and {fb}: each sample range must be merged once",
                    b.start,
                    a.end.min(b.end)
                ));
            }
        }
        // Join adjacent ranges.
        let mut ranges: Vec<Range<u32>> = Vec::new();
        for (r, _) in owner {
            match ranges.last_mut() {
                Some(last) if last.end == r.start => last.end = r.end,
                _ => ranges.push(r),
            }
        }
        acc.ranges = ranges;
        Ok(acc)
    }

    /// The sample ranges of the render this pass does not hold.
    pub fn missing(&self) -> Vec<Range<u32>> {
        let mut gaps = Vec::new();
        let mut at = 0;
        for r in &self.ranges {
            if r.start > at {
                gaps.push(at..r.start);
            }
            at = r.end;
        }
        if at < self.spp {
            gaps.push(at..self.spp);
        }
        gaps
    }

    /// A pass of `scene` holding no sample yet, with its fingerprint: the start of a
    /// progressive render ([`super::progressive`]).
    pub fn empty(scene: &RenderScene) -> Pass {
        Pass::from_render(
            scene,
            0..0,
            vec![RgbSum::default(); scene.film.width as usize * scene.film.height as usize],
        )
    }

    /// Add the exact sums `sums` of the samples `samples`, which this pass must not hold yet.
    ///
    /// # Panics
    /// If `samples` overlaps a range held, reaches past the spp, or `sums` is not one per
    /// pixel (callers' bugs: [`super::progressive`] draws its rounds from [`Pass::missing`]).
    pub fn add(&mut self, samples: Range<u32>, sums: &[RgbSum]) {
        assert!(
            samples.end <= self.spp
                && self
                    .ranges
                    .iter()
                    .all(|r| samples.end <= r.start || r.end <= samples.start)
                && sums.len() == self.sums.len(),
            "samples {samples:?} added to a pass holding {:?} of {} spp",
            self.ranges,
            self.spp
        );
        if samples.is_empty() {
            return;
        }
        for (a, b) in self.sums.iter_mut().zip(sums) {
            *a += *b;
        }
        let at = self.ranges.partition_point(|r| r.end <= samples.start);
        self.ranges.insert(at, samples);
        // Join adjacent ranges.
        let mut joined: Vec<Range<u32>> = Vec::with_capacity(self.ranges.len());
        for r in self.ranges.drain(..) {
            match joined.last_mut() {
                Some(last) if last.end == r.start => last.end = r.end,
                _ => joined.push(r),
            }
        }
        self.ranges = joined;
    }

    /// A pass from the exact sums a render of `samples` made.
    pub fn from_render(scene: &RenderScene, samples: Range<u32>, sums: Vec<RgbSum>) -> Pass {
        Pass {
            width: scene.film.width,
            height: scene.film.height,
            fingerprint: fingerprint(scene),
            seed: scene.seed,
            spp: scene.film.spp,
            transfer: scene.film.transfer,
            ranges: if samples.is_empty() {
                Vec::new()
            } else {
                vec![samples]
            },
            sums,
        }
    }
}

/// The ranges held as text (`0..16,32..48`), for messages.
pub fn describe_held(p: &Pass) -> String {
    show_ranges(&p.ranges)
}

/// The missing ranges as text, for messages.
pub fn describe_missing(p: &Pass) -> String {
    show_ranges(&p.missing())
}

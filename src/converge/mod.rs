//! What accuracy costs in time: sweep a ladder of shader settings on one scene, time each render
//! and measure its error against a reference image.

pub mod metrics;
pub mod plot;
pub mod report;
pub mod warptest;

use crate::material::microfacet::{Microfacet, NormalSampling};
use crate::material::{Material, Model};
use crate::render::inspect::{Firefly, Inspect, inspect};
use crate::render::{RenderScene, film::Image, render};
use crate::sampling::{LightSampling, LightsPerVertex, SamplerKind, Sampling};
use crate::shader::{Global, Path, Shader};
use crate::texture::{TexelFilter, TextureKind, mip_levels};
use std::fmt::Write as _;
use std::sync::atomic::AtomicBool;

/// One setting of the ladder.
#[derive(Clone, Debug)]
pub struct Rung {
    /// The family the curve belongs to (`Direct`, `Global D=2`, `Path`...).
    pub family: String,
    /// Short label of the setting (`n=16`, `spp=64`...).
    pub label: String,
    /// The shader to render with.
    pub shader: Shader,
    /// Samples per pixel.
    pub spp: u32,
    /// The microfacet normals every rough material samples in this rung, if not its own.
    pub normals: Option<NormalSampling>,
    /// The lookup every image texture uses in this rung, if not its own.
    pub texture_filter: Option<TexelFilter>,
    /// The sampler of this rung, if not the film's.
    pub sampler: Option<SamplerKind>,
}

/// The result of one rung.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    /// Curve family.
    pub family: String,
    /// Setting.
    pub label: String,
    /// Median render seconds over the runs.
    pub seconds: f64,
    /// Rays traced by one render.
    pub rays: u64,
    /// Root mean squared error against the reference (linear RGB, all channels), over the
    /// seeds (the square root of their mean MSE).
    pub rmse: f64,
    /// Relative MSE: mean of `(x - r)^2 / (r^2 + 0.01)`, first seed.
    pub rel_mse: f64,
    /// Mean FLIP against the reference, first seed.
    pub flip: f64,
    /// Independent seeds rendered.
    pub seeds: u32,
    /// Variance: the mean over pixels and channels of the per-pixel variance across seeds.
    pub variance: f64,
    /// Squared bias: the MSE of the seed mean against the reference, less `variance / seeds`
    /// and less the reference's own noise variance (an unbiased estimate: it can dip below
    /// zero by noise when the bias is small; [`metrics::bias_and_variance`]).
    pub bias2: f64,
}

/// The reference integrator for a scene: an unbounded path tracer under the scene's model.
pub fn reference_shader() -> Shader {
    Shader::Path(Path {
        max_depth: None,
        rr_depth: 5,
        sampling: Sampling::Brdf,
        lights: LightSampling::Mis,
        lights_per_vertex: LightsPerVertex::All,
    })
}

/// The ladder for the scene's shader. Course-family shaders (Direct, Global) get the cheapest
/// rungs first (Direct, then the ambient-only Global), then Global for n in {4, 16, 64} and
/// D in {1, 2, 3}, then the Path tracer of the same model at growing spp (the unbiased curve the
/// Global shader approximates). A Path scene gets spp and max-depth ladders; with area lights
/// under the Physical model, one spp ladder per light strategy (MIS, light sampling only, BRDF
/// sampling only), so that the plot shows what MIS buys; with point lights only, two or more of
/// them, under the Physical model, one spp ladder per light choice (every light at every
/// vertex, one by power, one by importance), so that the plot shows what each choice costs.
/// One more spp ladder draws the first curve's strategy from the other sampler (Sobol' points
/// for a film of independent numbers, and the reverse). With rough materials, one more spp
/// ladder samples every microfacet distribution's full normals instead of the visible ones.
pub fn ladder(scene: &RenderScene) -> Vec<Rung> {
    let mut rungs = Vec::new();
    let rung = |family: &str, label: String, shader, spp| Rung {
        family: family.into(),
        label,
        shader,
        spp,
        normals: None,
        texture_filter: None,
        sampler: None,
    };
    // Image textures: the scene's shader at growing spp with every image looked up bilinearly
    // (unfiltered) and trilinearly (by the footprint), against the supersampled reference.
    if scene.textures.iter().any(|t| {
        [&t.reflectance, &t.specular]
            .into_iter()
            .flatten()
            .any(|t| matches!(t.kind, TextureKind::Image(_)))
    }) {
        for (family, filter) in [
            ("Texture bilinear", TexelFilter::Bilinear),
            ("Texture trilinear", TexelFilter::Trilinear),
        ] {
            for spp in [1, 4, 16, 64] {
                rungs.push(Rung {
                    texture_filter: Some(filter),
                    ..rung(family, format!("spp={spp}"), scene.shader, spp)
                });
            }
        }
    }
    match scene.shader {
        Shader::Path(p) => {
            let physical = scene.model == Model::Physical;
            let lights = |lights| Path { lights, ..p };
            let per_vertex = |lights_per_vertex| Path {
                lights_per_vertex,
                ..p
            };
            let curves = if scene.effects.emission && physical {
                vec![
                    ("Path MIS", lights(LightSampling::Mis)),
                    ("Path light", lights(LightSampling::Light)),
                    ("Path BRDF", lights(LightSampling::Brdf)),
                ]
            } else if physical && scene.lights.len() > 1 {
                vec![
                    ("Path all lights", per_vertex(LightsPerVertex::All)),
                    ("Path one light", per_vertex(LightsPerVertex::One)),
                    (
                        "Path by importance",
                        per_vertex(LightsPerVertex::Importance),
                    ),
                ]
            } else {
                vec![("Path", p)]
            };
            // The first curve's strategy with the other sampler: what stratified numbers buy
            // (or, where the film asks for Sobol' points, what independent ones cost).
            let (other, which) = match scene.film.sampler {
                SamplerKind::Independent => (SamplerKind::Sobol, "Sobol'"),
                SamplerKind::Sobol => (SamplerKind::Independent, "independent"),
            };
            let (name, first) = (format!("{} {which}", curves[0].0), curves[0].1);
            for (family, path) in curves {
                for spp in [1, 4, 16, 64, 256] {
                    rungs.push(rung(family, format!("spp={spp}"), Shader::Path(path), spp));
                }
            }
            for spp in [1, 4, 16, 64, 256] {
                rungs.push(Rung {
                    sampler: Some(other),
                    ..rung(&name, format!("spp={spp}"), Shader::Path(first), spp)
                });
            }
            // Rough materials: the same spp ladder with every microfacet sampler drawing all
            // normals instead of the visible ones, to show what visible normals buy.
            if scene
                .materials
                .iter()
                .any(|m| matches!(m, Material::Bsdf(b) if b.microfacet().is_some()))
            {
                for spp in [1, 4, 16, 64, 256] {
                    rungs.push(Rung {
                        normals: Some(NormalSampling::Full),
                        ..rung(
                            "Path full normals",
                            format!("spp={spp}"),
                            Shader::Path(p),
                            spp,
                        )
                    });
                }
            }
            for d in [1, 2, 3, 5] {
                let shader = Shader::Path(Path {
                    max_depth: Some(d),
                    ..p
                });
                rungs.push(rung("Path 16 spp", format!("depth={d}"), shader, 16));
            }
        }
        other => {
            let (ambient, max_specular, light_samples) = match other {
                Shader::Global(g) => (g.ambient, g.max_specular, g.light_samples),
                Shader::Direct {
                    max_specular,
                    light_samples,
                } => (glam::Vec3A::splat(0.3), max_specular, light_samples),
                _ => (glam::Vec3A::splat(0.3), 32, 1),
            };
            rungs.push(rung(
                "Direct",
                "direct".into(),
                Shader::Direct {
                    max_specular,
                    light_samples,
                },
                1,
            ));
            let global = |samples, max_depth| {
                Shader::Global(Global {
                    samples,
                    max_depth,
                    ambient,
                    max_specular,
                    light_samples,
                })
            };
            rungs.push(rung("Ambient (D=0)", "D=0".into(), global(1, 0), 1));
            for d in [1, 2, 3] {
                for n in [4, 16, 64] {
                    rungs.push(rung(
                        &format!("Global D={d}"),
                        format!("n={n}"),
                        global(n, d),
                        1,
                    ));
                }
            }
            for spp in [1, 4, 16, 64] {
                rungs.push(rung("Path", format!("spp={spp}"), reference_shader(), spp));
            }
        }
    }
    rungs
}

/// A rough material's distribution of microfacet normals, to change how it is sampled.
fn microfacet_mut(m: &mut Material) -> Option<&mut Microfacet> {
    match m {
        Material::Bsdf(b) => b.microfacet_mut(),
        _ => None,
    }
}

/// Render `scene` with another shader and spp.
pub fn with_settings(scene: &RenderScene, shader: Shader, spp: u32) -> RenderScene {
    let mut s = scene.clone();
    s.set_shader(shader);
    s.film.spp = spp;
    s
}

/// The reference render's seed. Rungs draw from the streams of the scene's seed; the
/// reference draws from streams independent of all of them (a bijective mix of the seed with
/// a tag), so that a rung with as many samples as the reference still measures its own noise.
pub fn reference_seed(seed: u64) -> u64 {
    crate::sampling::mix(seed ^ 0x5245_4645_5245_4e43)
}

/// The reference render of `scene`: Path with unbounded depth, `spp` samples per pixel, its own
/// seed ([`reference_seed`]).
pub fn reference_scene(scene: &RenderScene, spp: u32) -> RenderScene {
    reference_half(scene, spp, 0)
}

/// Half `h` (0 or 1) of the reference: `spp` samples of its own independent seed. The two
/// halves cover the whole pixel footprint each, so their difference measures the reference's
/// noise; their pooled mean is the reference.
pub fn reference_half(scene: &RenderScene, spp: u32, h: u64) -> RenderScene {
    RenderScene {
        seed: reference_seed(scene.seed ^ h.wrapping_mul(0x9e37_79b9_7f4a_7c15)),
        ..with_settings(scene, reference_shader(), spp)
    }
}

/// A key that changes whenever anything that affects the reference image changes.
pub fn reference_key(scene: &RenderScene, spp: u32) -> u64 {
    let text = format!(
        "reference v3 (two independent halves)|{:?}|{:?}|{:?}|{:?}|{:?}|{}x{}|{}|{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
        scene.camera,
        scene.geometry.prims().collect::<Vec<_>>(),
        scene.materials,
        scene.lights,
        scene.background,
        scene.film.width,
        scene.film.height,
        spp,
        scene.seed,
        scene.model,
        scene.film.filter,
        scene.film.sampler,
        scene.textures,
        scene.geometry.uvs,
        scene.emitters.environment,
    );
    metrics::fnv1a(text.as_bytes())
}

/// A measured rung: its row and the image of its first seed.
#[derive(Clone, Debug)]
pub struct Measured {
    /// The figures.
    pub row: Row,
    /// The first seed's image.
    pub image: Image,
    /// Seconds each pixel of the first seed's image took to trace, from an inspected render
    /// of it without counters (row-major).
    pub pixel_seconds: Vec<f32>,
    /// Each pixel's variance (the mean over channels): across the seeds' images, or with one
    /// seed the variance of its estimate from its samples; unknown with one seed at 1 spp.
    pub pixel_variance: Option<Vec<f32>>,
    /// The first seed's samples that stand out most above their pixels, with their paths.
    pub fireflies: Vec<Firefly>,
}

/// The unbiased variance of each pixel across `images` (two or more), the mean over channels.
pub fn pixel_variance(images: &[Image]) -> Vec<f32> {
    let k = images.len() as f64;
    (0..images[0].pixels.len())
        .map(|i| {
            let mean = images
                .iter()
                .map(|im| im.pixels[i].as_dvec3())
                .sum::<glam::DVec3>()
                / k;
            let ss: glam::DVec3 = images
                .iter()
                .map(|im| (im.pixels[i].as_dvec3() - mean).powf(2.0))
                .sum();
            (ss / (k - 1.0)).element_sum() as f32 / 3.0
        })
        .collect()
}

/// Fireflies the report keeps per rung.
pub const REPORT_FIREFLIES: usize = 8;

/// Time and measure every rung: `seeds` independent renders (seeds `scene.seed + k`), the
/// first timed as the median of `runs`. `reference_noise` is the reference's own noise
/// variance per pixel and channel, removed from the bias estimate. `on_rung` sees each row as
/// it is measured and says whether to go on (a Ctrl-C stops after the rung in flight): the
/// result holds the rungs done.
pub fn sweep(
    scene: &RenderScene,
    reference: &Image,
    reference_noise: f64,
    rungs: &[Rung],
    runs: usize,
    seeds: u32,
    on_rung: &mut dyn FnMut(&Row) -> bool,
) -> Vec<Measured> {
    let measure = |r: &Rung| {
        let mut s = with_settings(scene, r.shader, r.spp);
        if let Some(normals) = r.normals {
            for m in s.materials.iter_mut().filter_map(microfacet_mut) {
                m.sampling = normals;
            }
        }
        if let Some(sampler) = r.sampler {
            s.film.sampler = sampler;
        }
        if let Some(filter) = r.texture_filter {
            for t in s.textures.iter_mut() {
                for tex in [&mut t.reflectance, &mut t.specular].into_iter().flatten() {
                    if let TextureKind::Image(i) = &mut tex.kind {
                        if filter == TexelFilter::Trilinear && i.mips.is_empty() {
                            i.mips = std::sync::Arc::new(mip_levels(&i.raster));
                        }
                        i.filter = filter;
                    }
                }
            }
        }
        let mut times = Vec::new();
        let mut first = None;
        for _ in 0..runs.max(1) {
            let out = render(&s, &|| {});
            times.push(out.seconds);
            first.get_or_insert(out);
        }
        times.sort_by(f64::total_cmp);
        let out = first.expect("at least one run");
        let mut images = vec![out.image.clone()];
        for k in 1..seeds.max(1) {
            let other = RenderScene {
                seed: scene.seed.wrapping_add(k as u64),
                ..s.clone()
            };
            images.push(render(&other, &|| {}).image);
        }
        let parts = metrics::bias_and_variance(&images, reference, reference_noise);
        let k = images.len() as f64;
        let mean_mse = images
            .iter()
            .map(|i| metrics::rmse(i, reference).powi(2))
            .sum::<f64>()
            / k;
        let row = Row {
            family: r.family.clone(),
            label: r.label.clone(),
            seconds: times[times.len() / 2],
            rays: out.stats.total(),
            rmse: mean_mse.sqrt(),
            rel_mse: metrics::rel_mse(&out.image, reference),
            flip: metrics::flip(&out.image, reference).mean,
            seeds: images.len() as u32,
            variance: parts.variance,
            bias2: parts.bias2,
        };
        // Where the time went and the largest samples: an inspected render of the first
        // seed, untimed (its image is the same, to the bit).
        let want = Inspect {
            fireflies: REPORT_FIREFLIES,
            counters: false,
            against: Some(reference),
        };
        let inspected = inspect(&s, want, &|| {}, &AtomicBool::new(false));
        debug_assert_eq!(inspected.image, out.image);
        // Each pixel's variance: across the seeds where there are two or more, else the
        // variance of its estimate from its own samples.
        let pixel_variance = if images.len() >= 2 {
            Some(pixel_variance(&images))
        } else if s.film.spp >= 2 {
            let v = inspected.pixels.iter();
            Some(v.map(|p| p.variance.element_sum() / 3.0).collect())
        } else {
            // One image of one sample per pixel: nothing to measure its spread by.
            None
        };
        Measured {
            row,
            image: out.image,
            pixel_seconds: inspected.pixels.iter().map(|p| p.seconds as f32).collect(),
            pixel_variance,
            fireflies: inspected.fireflies,
        }
    };
    let mut done = Vec::new();
    for r in rungs {
        let m = measure(r);
        let go_on = on_rung(&m.row);
        done.push(m);
        if !go_on {
            break;
        }
    }
    done
}

/// The rows as CSV.
pub fn to_csv(rows: &[Row]) -> String {
    let mut s =
        String::from("family,setting,seconds,rays,rmse,rel_mse,flip,seeds,variance,bias2\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:.4},{},{:.6},{:.6},{:.6},{},{:.3e},{:.3e}",
            r.family,
            r.label,
            r.seconds,
            r.rays,
            r.rmse,
            r.rel_mse,
            r.flip,
            r.seeds,
            r.variance,
            r.bias2
        );
    }
    s
}

/// The rows as a Markdown table.
pub fn to_markdown(rows: &[Row], model: Model) -> String {
    let seeds = rows.first().map_or(1, |r| r.seeds);
    let mut s = format!(
        "Error against the {model:?}-model reference (Path, unbounded depth); RMSE over {seeds} \
         seeds, bias^2 and variance from their spread.\n\n\
         | family | setting | seconds | Mrays | RMSE | relMSE | FLIP | bias^2 | variance |\n\
         |---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.1} | {:.4} | {:.4} | {:.4} | {:.2e} | {:.2e} |",
            r.family,
            r.label,
            r.seconds,
            r.rays as f64 / 1e6,
            r.rmse,
            r.rel_mse,
            r.flip,
            r.bias2,
            r.variance
        );
    }
    s
}

/// The light-transport effects a scene can switch off (the first six of `Effects::named`).
pub const TRANSPORT_EFFECTS: usize = 6;

/// `scene` with the transport effect `effect` (a name of `Effects::named`) switched off.
pub fn effect_off(scene: &RenderScene, effect: &str) -> RenderScene {
    let mut off = scene.clone();
    let mut e = scene.effects;
    match effect {
        "shadows" => e.shadows = false,
        "reflection" => e.reflection = false,
        "refraction" => e.refraction = false,
        "indirect" => e.indirect = false,
        "ambient" => e.ambient = false,
        "background" => e.background = false,
        _ => {}
    }
    off.set_effects(e);
    off
}

/// The price of each effect `scene` simulates: the render with all of them, then with each
/// switched off in turn (median seconds of `runs`), each measured against `reference`.
pub fn effect_prices(
    scene: &RenderScene,
    reference: &Image,
    runs: usize,
) -> Vec<report::EffectPrice> {
    let measure = |name: &str, s: &RenderScene| {
        let mut outs: Vec<_> = (0..runs.max(1)).map(|_| render(s, &|| {})).collect();
        outs.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
        let out = &outs[outs.len() / 2];
        report::EffectPrice {
            effect: name.into(),
            seconds: out.seconds,
            rays: out.stats.total(),
            rmse: metrics::rmse(&out.image, reference),
            flip: metrics::flip(&out.image, reference).mean,
        }
    };
    let mut prices = vec![measure("", scene)];
    for (name, on) in scene.effects.named().into_iter().take(TRANSPORT_EFFECTS) {
        if on {
            prices.push(measure(name, &effect_off(scene, name)));
        }
    }
    prices
}

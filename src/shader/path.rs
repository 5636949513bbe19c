//! The reference integrator: an iterative path tracer over throughput and depth.
//!
//! At each Phong vertex it adds the direct light of every point light (next-event estimation,
//! Eq. 3 under the scene's model), then samples one direction and continues; mirrors and glass
//! are followed exactly; Russian roulette ends paths after `rr_depth` bounces; escaped rays see
//! the background or the environment light.
//!
//! Area lights and the environment light are gathered by the strategy `lights`: one light sample per Phong vertex
//! (next-event estimation), the emitters that BRDF-sampled rays hit, or both weighted by the
//! power heuristic (MIS). Under the Course model the indirect weights estimate a different
//! integral from Eq. 3 (`r / (2 pi)^2`), so the two cannot be combined: area lights are then
//! light-sampled only, as the course's Eq. 3 treats point lights.
//!
//! Under each model a bounce estimates an integral over the hemisphere of `L_i(wi) g(wi) dwi`,
//! with weight `g(wi) / pdf(wi)`:
//!
//! - `Course`: `g = r(wi, wo) / (2 pi)^2`. With uniform sampling the weight is `r / (2 pi)`: the
//!   assignment's Eq. 4 with one sample, applied at every bounce. This is the infinite-depth
//!   limit of the Global shader's depth-0 estimator: the ground truth for measuring what the
//!   ambient term and the two-direction rule cost.
//! - `Physical`: `g = f(wi, wo) cos(theta_i)` with the normalised Phong BRDF: the rendering
//!   equation, unbiased; glass reflects with Fresnel probability and scales transmitted radiance
//!   by `eta^2 = (n_wo / n_wi)^2`, as radiance does (`docs/transport.md`).

use super::Tracer;
use super::record::{Event, Record, Technique, arr};
use super::surface::{
    Interaction, Lobe, area_lights, emitted, one_light, point_lights, reflectance, sky,
    specular_bounce,
};
pub use super::surface::{brdf_pdf as pdf, diffuse_probability};

pub mod lanes;
use crate::geometry::{Frame, Ray};
use crate::material::{Material, Model, Phong, fresnel_dielectric, reflect};
use crate::sampling::{LightSampling, LightsPerVertex, Sampling, hemisphere, power_heuristic};
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::TAU;

/// Parameters of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Path {
    /// Largest number of bounces (any surface); `None` for unbounded (Russian roulette ends paths).
    pub max_depth: Option<u32>,
    /// Bounces before Russian roulette starts.
    pub rr_depth: u32,
    /// Direction sampling at Phong vertices.
    pub sampling: Sampling,
    /// How area lights are gathered (the Physical model; the Course model samples lights).
    pub lights: LightSampling,
    /// Every point light and one area-light sample per vertex, or one light of all chosen by
    /// power or by importance (the Physical model; the Course model's Eq. 3 sums its point
    /// lights).
    pub lights_per_vertex: LightsPerVertex,
}

impl Path {
    /// The strategy actually used under `model`: [`LightSampling::Light`] under the Course
    /// model, `lights` under the Physical one.
    pub fn lights_under(&self, model: Model) -> LightSampling {
        match model {
            Model::Course => LightSampling::Light,
            Model::Physical => self.lights,
        }
    }

    /// True if one light of all is chosen per vertex under `model`.
    pub fn one_light_under(&self, model: Model) -> bool {
        model == Model::Physical && self.lights_per_vertex != LightsPerVertex::All
    }
}

/// The Phong vertex a BRDF-sampled ray left: where it was and the density of its direction,
/// for weighting the emitter the ray hits.
#[derive(Clone, Copy, Debug)]
struct Scattered {
    p: Vec3A,
    pdf: f32,
}

/// Hard cap on bounces even without `max_depth` (two perfect mirrors facing each other), and
/// the largest `max_depth` and `rr_depth` a scene may ask for.
pub const MAX_DEPTH: u32 = 1024;

/// A path in flight: the ray to trace next and what the path carries to its next vertex.
#[derive(Clone, Copy, Debug)]
pub struct PathState {
    /// The ray to trace next.
    pub ray: Ray,
    /// Its kind.
    pub kind: RayKind,
    /// Throughput of the path up to the ray's origin.
    beta: Vec3A,
    /// Scattering vertices so far.
    depth: u32,
    /// The product of eta'^2 over the dielectric interfaces crossed: beta * eta_scale is the
    /// throughput without the radiance scaling 1 / eta'^2, which Russian roulette reads, so
    /// that a path inside glass is not ended for its lower radiance (pbrt-v4's `etaScale`).
    eta_scale: f32,
    /// The Phong vertex the ray left, if it was BRDF-sampled there (None for camera rays and
    /// after mirrors and glass).
    scattered: Option<Scattered>,
    /// Whether any vertex so far sampled its direction from a non-delta lobe: light met after
    /// mirrors and glass only is `Emitted`, after such a vertex `Bsdf`.
    sampled: bool,
}

impl PathState {
    /// The path of a camera ray, before its first trace.
    pub fn new(camera_ray: &Ray) -> PathState {
        PathState {
            ray: *camera_ray,
            kind: RayKind::Camera,
            beta: Vec3A::ONE,
            depth: 0,
            eta_scale: 1.0,
            scattered: None,
            sampled: false,
        }
    }

    /// The end of [`step`] at a diffuse Phong vertex at `p` that sampled direction
    /// `ray.d` with density `pdf` and throughput weight making `beta` the path's throughput
    /// (`lanes` computes these): one more vertex, then Russian roulette from depth `rr_depth`
    /// (drawing from `sampler`); false if the path ends there, else it goes on with `ray`.
    #[inline]
    pub fn scatter_diffuse(
        &mut self,
        ray: Ray,
        p: Vec3A,
        pdf: f32,
        beta: Vec3A,
        rr_depth: u32,
        sampler: &mut crate::sampling::Sampler,
    ) -> bool {
        self.scattered = Some(Scattered { p, pdf });
        self.sampled = true;
        self.beta = beta;
        self.depth += 1;
        // Russian roulette: survive with probability q, divide by q to stay unbiased.
        if self.depth >= rr_depth {
            let q = (self.beta * self.eta_scale).max_element().min(0.95);
            if q <= 0.0 || sampler.next_f32() >= q {
                return false;
            }
            self.beta /= q;
        }
        self.ray = ray;
        self.kind = RayKind::Indirect;
        true
    }

    /// The technique of light the ray meets: emitted (seen by the camera or through mirrors
    /// and glass only) or BSDF-sampled.
    fn found(&self) -> Technique {
        match (self.scattered, self.sampled) {
            (None, false) => Technique::Emitted,
            _ => Technique::Bsdf,
        }
    }
}

/// Trace the path of a camera ray, telling `rec` each contribution it finds (with its
/// technique and the path's length) and, if it keeps them, each event. The radiance along the
/// camera ray is the sum of the contributions. Scattering into an effect that is off ends the
/// path.
pub fn radiance<R: Record>(tr: &mut Tracer, camera_ray: &Ray, p: &Path, rec: &mut R) {
    let hit = tr.trace(camera_ray, RayKind::Camera);
    radiance_from(tr, camera_ray, hit, p, rec);
}

/// [`radiance`] of a camera ray whose nearest hit, `hit`, the caller has found and counted
/// (with the camera rays of other samples, in a packet).
#[inline]
pub fn radiance_from<R: Record>(
    tr: &mut Tracer,
    camera_ray: &Ray,
    hit: Option<crate::geometry::Hit>,
    p: &Path,
    rec: &mut R,
) {
    let mut st = PathState::new(camera_ray);
    let mut hit = hit;
    while step(tr, p, &mut st, hit, rec) {
        hit = tr.trace(&st.ray, st.kind);
    }
}

/// One vertex of a path: its ray met `hit` (traced and counted by the caller), or nothing.
/// Add what the vertex finds (emitted light, next-event estimation) and sample the next ray
/// into `st`; false when the path ends.
#[inline(always)]
pub fn step<R: Record>(
    tr: &mut Tracer,
    p: &Path,
    st: &mut PathState,
    hit: Option<crate::geometry::Hit>,
    rec: &mut R,
) -> bool {
    let model = tr.model;
    let lights = p.lights_under(model);
    let max_depth = p.max_depth.unwrap_or(MAX_DEPTH).min(MAX_DEPTH);
    // Escaped rays see the background, or the environment light weighted against the
    // light sample that could have found it.
    let Some(hit) = hit else {
        rec.event(|| Event::Escape { d: arr(st.ray.d) });
        let le = escaped(tr, &st.ray, st.scattered, lights);
        add(rec, st.beta * le, st.found(), st.depth);
        return false;
    };
    let si = Interaction::new(tr, &st.ray, hit);
    rec.event(|| {
        let material = tr.geometry.prim(si.hit.prim).material;
        Event::Hit {
            p: arr(si.hit.p),
            n: arr(si.n),
            material,
            kind: si.material().kind(),
            beta: arr(st.beta),
        }
    });
    // Emitted light L_e, weighted against the light sample that could have found it.
    let le = emitted(tr, &si);
    if le != Vec3A::ZERO {
        let w = match (st.scattered, lights) {
            (None, _) | (Some(_), LightSampling::Brdf) => 1.0,
            (Some(_), LightSampling::Light) => 0.0,
            (Some(v), LightSampling::Mis) => {
                let light = &tr.emitters.lights[si.light as usize];
                let pdf_light =
                    tr.emitters.pmf(si.light as usize) * light.pdf(v.p, si.hit.p, si.hit.n);
                power_heuristic(v.pdf, pdf_light)
            }
        };
        add(rec, st.beta * le * w, st.found(), st.depth);
    }
    if st.depth >= max_depth {
        return false;
    }
    // Scatter: the next ray, its weight g(wi) / pdf(wi), its density (None for a
    // specular direction) and its kind.
    let (next_ray, weight, pdf, next) = match (si.material(), model) {
        (Material::Phong(phong), _) => {
            add(
                rec,
                st.beta * next_event(tr, &si, phong, p),
                Technique::Light,
                st.depth + 1,
            );
            if !tr.effects.indirect {
                return false;
            }
            let Some((wi, weight, pdf)) = sample_phong(tr, phong, &si, model, p.sampling) else {
                return false;
            };
            st.scattered = Some(Scattered { p: si.hit.p, pdf });
            (si.spawn(wi), weight, Some(pdf), RayKind::Indirect)
        }
        // A BSDF: next-event estimation with its eval and pdf, then its own sampler. Its
        // weights are f |cos| / pdf under either model (rough materials ask for the
        // Physical one; see docs/transport.md).
        (Material::Bsdf(bsdf), _) => {
            let shading = si.shading(tr, bsdf);
            let nee = next_event(tr, &si, &shading, p);
            add(rec, st.beta * nee, Technique::Light, st.depth + 1);
            if !tr.effects.indirect {
                return false;
            }
            let frame = shading.frame;
            let uc = tr.sampler.next_f32();
            let (u1, u2) = tr.sampler.next_2d();
            let Some(s) = bsdf.sample(frame.to_local(si.wo), uc, u1, u2) else {
                return false;
            };
            // A delta lobe's direction cannot be found by a light sample: its emitter
            // counts whole, as after a mirror.
            st.scattered = (!s.delta).then_some(Scattered {
                p: si.hit.p,
                pdf: s.pdf,
            });
            st.eta_scale *= s.eta * s.eta;
            let pdf = (!s.delta).then_some(s.pdf);
            (
                si.spawn(frame.to_world(s.wi)),
                s.weight,
                pdf,
                RayKind::Indirect,
            )
        }
        // Fresnel-weighted choice between reflection and refraction.
        (Material::Transmissive(g), Model::Physical) => {
            let r = g.refract(si.wo, si.hit.n);
            let f = fresnel_dielectric(r.cos_i.abs(), r.eta);
            let (wi, weight, kind, on) = if tr.sampler.next_f32() < f {
                let wr = reflect(si.wo, si.n);
                (wr, Vec3A::ONE, RayKind::Reflection, tr.effects.reflection)
            } else {
                // Radiance crossing into the wo side is scaled by (n_wo / n_wi)^2 = eta^2.
                let w = g.color * (r.eta * r.eta);
                st.eta_scale /= r.eta * r.eta;
                (r.wt, w, RayKind::Refraction, tr.effects.refraction)
            };
            // An effect that is off ends the path.
            if !on {
                return false;
            }
            st.scattered = None;
            (si.spawn(wi), weight, None, kind)
        }
        // Mirrors, and the course's glass: the one scattered ray, as in Direct and Global.
        _ => match specular_bounce(&si, tr.effects) {
            Some((ray, weight, kind)) => {
                st.scattered = None;
                (ray, weight, None, kind)
            }
            None => return false,
        },
    };
    // A normal-mapped surface sends no ray through itself (nor reflects one from below).
    if si.leaks(next_ray.d) {
        return false;
    }
    rec.event(|| Event::Scatter {
        wi: arr(next_ray.d),
        pdf,
        weight: arr(weight),
        ray: next,
    });
    st.sampled |= pdf.is_some();
    st.beta *= weight;
    st.depth += 1;
    // Russian roulette: survive with probability q, divide by q to stay unbiased.
    if st.depth >= p.rr_depth {
        let q = (st.beta * st.eta_scale).max_element().min(0.95);
        let survived = !(q <= 0.0 || tr.sampler.next_f32() >= q);
        rec.event(|| Event::Roulette { q, survived });
        if !survived {
            return false;
        }
        st.beta /= q;
    }
    st.ray = next_ray;
    st.kind = next;
    true
}

/// Tell `rec` of contribution `l` (found by `technique` along a path of `vertices` scattering
/// vertices), and of the event when it keeps events; a zero contribution is not told.
#[inline(always)]
fn add<R: Record>(rec: &mut R, l: Vec3A, technique: Technique, vertices: u32) {
    if l != Vec3A::ZERO {
        rec.add(l, technique, vertices);
        rec.event(|| Event::Add {
            technique,
            l: arr(l),
        });
    }
}

/// Radiance a ray that leaves the scene brings back: the background, or the environment's
/// radiance `L_e` with the weight of the strategy that found it (as an emitter's): whole after
/// the camera and mirrors and glass (no light sample finds those directions) and under `Brdf`;
/// none under `Light`; the power heuristic under `Mis`, against the chance
/// `P(env) pdf_env(wi)` that the light sample of the vertex it left picks its direction.
fn escaped(tr: &Tracer, ray: &Ray, scattered: Option<Scattered>, lights: LightSampling) -> Vec3A {
    // What the sky sends back (surface::sky decides between background and environment).
    let le = sky(tr, ray.d, true);
    let Some(env) = tr
        .emitters
        .environment
        .as_ref()
        .filter(|_| tr.effects.emission)
    else {
        return le;
    };
    let w = match (scattered, lights) {
        (None, _) | (Some(_), LightSampling::Brdf) => 1.0,
        (Some(_), LightSampling::Light) => 0.0,
        (Some(v), LightSampling::Mis) => {
            power_heuristic(v.pdf, tr.emitters.pmf_environment() * env.pdf(ray.d))
        }
    };
    le * w
}

/// Next-event estimation at a vertex whose surface reflects as `lobe`: Eq. 3 under the model
/// and one area-light sample, or one light of all. When no ray continues (indirect light off)
/// the light sample carries all of the area lights, whatever the strategy.
fn next_event<L: Lobe>(tr: &mut Tracer, si: &Interaction, lobe: &L, p: &Path) -> Vec3A {
    let lights = p.lights_under(tr.model);
    let mis = (lights == LightSampling::Mis && tr.effects.indirect).then_some(p.sampling);
    let sample_area = lights != LightSampling::Brdf || !tr.effects.indirect;
    if p.one_light_under(tr.model) {
        // One light of all, chosen by power (point lights by importance under `Importance`).
        // Under `Brdf` the area lights are left to the sampled rays, and a chosen area light
        // adds nothing.
        let by_importance = p.lights_per_vertex == LightsPerVertex::Importance;
        one_light(tr, si, lobe, mis, sample_area, by_importance)
    } else {
        let mut l = point_lights(tr, si, lobe);
        if sample_area {
            l += area_lights(tr, si, lobe, 1, mis);
        }
        l
    }
}

/// Sample a direction at a Phong vertex: the direction, its weight `g / pdf` and its density;
/// `None` when it falls below the surface or has no weight.
#[inline(always)]
fn sample_phong(
    tr: &mut Tracer,
    phong: &Phong,
    si: &Interaction,
    model: Model,
    sampling: Sampling,
) -> Option<(Vec3A, Vec3A, f32)> {
    let (wo, n) = (si.wo, si.n);
    let frame = Frame::from_normal(n);
    let (u1, u2) = tr.sampler.next_2d();
    let wi = match sampling {
        Sampling::Uniform => frame.to_world(hemisphere::uniform(u1, u2)),
        Sampling::Cosine => frame.to_world(hemisphere::cosine(u1, u2)),
        Sampling::Brdf => {
            let pd = diffuse_probability(phong);
            if tr.sampler.next_f32() < pd {
                frame.to_world(hemisphere::cosine(u1, u2))
            } else {
                let lobe = Frame::from_normal(reflect(wo, n));
                lobe.to_world(hemisphere::phong_lobe(u1, u2, phong.shininess))
            }
        }
    };
    let cos_i = wi.dot(n);
    if cos_i <= 0.0 {
        return None;
    }
    let pdf = pdf(phong, wo, n, wi, sampling);
    if pdf <= 0.0 {
        return None;
    }
    let g = match model {
        Model::Course => reflectance(model, phong, wi, wo, n) / (TAU * TAU),
        Model::Physical => reflectance(model, phong, wi, wo, n),
    };
    // A direction that carries nothing ends the path (a black surface).
    if g == Vec3A::ZERO {
        return None;
    }
    Some((wi, g / pdf, pdf))
}

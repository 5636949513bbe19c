//! Shading pieces shared by the Direct, Global and Path shaders: the local frame at a hit, the
//! direct light from point and area lights (Eq. 3), the light a surface emits, the reflectance
//! under each model and its sampling densities, the single scattered ray of a mirror or glass,
//! and the loop that follows a chain of them.

use super::Tracer;
use crate::effects::Effects;
use crate::geometry::{Frame, Hit, Origins, Ray};
use crate::light::{
    AreaLight, Chosen, Emitters, EnvironmentLight, Incident, Light, LightSample, NO_LIGHT,
    choose_by_importance,
};
use crate::material::{Bsdf, Material, Model, Phong, reflect};
use crate::sampling::{Sampling, hemisphere, power_heuristic};
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::PI;

/// A hit seen from the ray that found it.
#[derive(Clone, Debug)]
pub struct Interaction<'a> {
    /// The hit.
    pub hit: Hit,
    /// Unit direction back along the incoming ray (towards the viewer).
    pub wo: Vec3A,
    /// Unit shading normal on the side of `wo` (two-sided shading): the geometric normal, or
    /// the interpolated vertex normal of a smooth triangle.
    pub n: Vec3A,
    /// The surface's material as the render's table holds it (an interaction does not copy
    /// it); [`Interaction::material`] is what shades, its textures looked up.
    pub material: &'a Material,
    /// What the hit's textures give, when its material has any (boxed: an untextured hit
    /// carries one empty pointer).
    pub textured: Option<Box<TexturedHit>>,
    /// True if a normal map gave `n`: directions whose side of the shading normal differs from
    /// their side of the geometric surface then carry no light ([`Interaction::leaks`]).
    pub bent: bool,
    /// Where rays leaving the hit start.
    pub origins: Origins,
    /// The surface's area light, or [`NO_LIGHT`].
    pub light: u32,
}

impl<'a> Interaction<'a> {
    /// The interaction of `ray` with its nearest hit.
    #[inline]
    pub fn new(tr: &Tracer<'a>, ray: &Ray, hit: Hit) -> Self {
        let materials: &'a [Material] = tr.materials;
        let wo = -ray.d;
        let prim = tr.geometry.prim(hit.prim);
        let i = prim.material as usize;
        let ng = if hit.n.dot(wo) < 0.0 { -hit.n } else { hit.n };
        // The shading normal stays on the viewer's side of the surface.
        let ns = tr.geometry.shading_normal(&prim, hit.p, ng);
        let mut n = if ns.dot(ng) < 0.0 { -ns } else { ns };
        let (mut textured, mut bent) = (None, false);
        if let Some(t) = tr.textures.get(i).filter(|t| !t.is_empty()) {
            let uv = tr.geometry.uv(&prim, hit.p);
            // The footprint of the sample here, in texture coordinates.
            let width = tr.footprint.width(hit.p, hit.n) * tr.geometry.uv_rate(&prim, hit.p);
            let tangent = tr.geometry.dp_du(&prim, hit.p);
            let physical = tr.model == Model::Physical;
            let material = t
                .has_parameters()
                .then(|| t.apply(&materials[i], uv, width, physical));
            if let Some(local) = t.normal(uv, width) {
                n = normal_mapped(local, n, ng, hit.n, wo, tangent);
                bent = true;
            }
            textured = Some(Box::new(TexturedHit { material, tangent }));
        }
        Interaction {
            hit,
            wo,
            n,
            material: &materials[i],
            textured,
            bent,
            origins: Origins::new(&hit),
            light: prim.light,
        }
    }

    /// The interaction of a ray of direction `d` with its nearest hit, `hit`, on a flat
    /// primitive of `material` that emits nothing and has no normal map: what
    /// [`Interaction::new`] makes there (its shading normal the geometric one on the viewer's
    /// side), without looking the primitive up or its textures (Path's lanes pass the
    /// looked-up Phong to `light_ray` and `light_weighted`, which read nothing else of it).
    #[inline]
    pub fn flat(hit: Hit, d: Vec3A, material: &'a Material) -> Self {
        let wo = -d;
        let n = if hit.n.dot(wo) < 0.0 { -hit.n } else { hit.n };
        Interaction {
            hit,
            wo,
            n,
            material,
            textured: None,
            bent: false,
            origins: Origins::new(&hit),
            light: NO_LIGHT,
        }
    }

    /// True if light along `wi` (unit, leaving the surface) would cross the surface on one
    /// side of the geometric normal and the other of the shading normal: at a normal-mapped
    /// hit such a direction carries nothing, so that no light leaks through the surface and
    /// no ray goes on from the wrong side (pbrt-v3's rule for shading normals, Veach 1997
    /// 5.3). Never at other hits, whose images stay as they were.
    #[inline(always)]
    pub fn leaks(&self, wi: Vec3A) -> bool {
        self.bent && self.crosses(wi)
    }

    /// [`Interaction::leaks`] at a normal-mapped hit.
    #[cold]
    #[inline(never)]
    fn crosses(&self, wi: Vec3A) -> bool {
        let ng = if self.hit.n.dot(self.wo) < 0.0 {
            -self.hit.n
        } else {
            self.hit.n
        };
        (wi.dot(ng) > 0.0) != (wi.dot(self.n) > 0.0)
    }

    /// The material that shades here: the table's, its textured parameters looked up.
    #[inline]
    pub fn material(&self) -> &Material {
        match self.textured.as_deref() {
            Some(TexturedHit {
                material: Some(m), ..
            }) => m,
            _ => self.material,
        }
    }

    /// A ray leaving the surface in unit direction `w`, started off the surface on `w`'s side.
    #[inline]
    pub fn spawn(&self, w: Vec3A) -> Ray {
        self.origins.ray(w, f32::INFINITY)
    }

    /// The BSDF `bsdf` of this surface in its local frame: `z` the shading normal turned to
    /// the outside (the geometric normal's side), `x` the shape's tangent made orthogonal to it.
    #[inline]
    pub fn shading(&self, tr: &Tracer, bsdf: &Bsdf) -> Shading {
        let n = if self.n.dot(self.hit.n) < 0.0 {
            -self.n
        } else {
            self.n
        };
        let tangent = match &self.textured {
            Some(t) => t.tangent,
            None => tr.geometry.prim(self.hit.prim).shape.tangent(self.hit.p),
        };
        let s = tangent - n * n.dot(tangent);
        let frame = match s.try_normalize() {
            Some(s) => Frame {
                s,
                t: n.cross(s),
                n,
            },
            None => Frame::from_normal(n),
        };
        Shading { bsdf: *bsdf, frame }
    }
}

/// The shading normal on the viewer's side that a normal map gives (Mitsuba 3's `normalmap`):
/// the map's `local` normal in the frame of the outward shading normal (`n` turned to the side
/// of the geometric normal `n_out`) and the tangent `dp_du` made orthogonal to it, then bent by
/// [`valid_normal`]. Seen from the back, the map's normal is mirrored through the surface (its
/// tangential part kept, its normal part turned to the viewer, `ng` towards `wo`), as rtis's
/// two-sided materials and Mitsuba's `twosided` mirror every direction there: the back shows
/// the front's bumps.
#[inline]
fn normal_mapped(
    local: Vec3A,
    n: Vec3A,
    ng: Vec3A,
    n_out: Vec3A,
    wo: Vec3A,
    dp_du: Vec3A,
) -> Vec3A {
    let outward = n.dot(n_out) < 0.0;
    let ns = if outward { -n } else { n };
    let frame = match (dp_du - ns * ns.dot(dp_du)).try_normalize() {
        Some(s) => Frame {
            s,
            t: ns.cross(s),
            n: ns,
        },
        None => Frame::from_normal(ns),
    };
    // Unit to rounding: the frame is orthonormal, `local` unit.
    let mapped = local.x * frame.s + local.y * frame.t + local.z * n;
    valid_normal(mapped, ng, wo)
}

/// The shading normal `n` bent, where needed, so that the viewer `wo` is above it and its
/// mirror direction above the geometric surface `ng` (all on the viewer's side; `n` itself
/// above it too): a normal
/// map's normal can lean so far that `wo` is below it (a black pixel) or its reflection goes
/// through the surface. When the mirror direction `r` of `wo` about `n` is lower than `min(0.9
/// wo.ng, 0.01)` above the surface, it is raised to that height in its own plane through `ng`,
/// and `n` becomes the half vector of `wo` and it (Cycles' `ensure_valid_reflection`; Schussler
/// et al. 2017 discuss the problem). Unchanged otherwise.
#[inline]
pub fn valid_normal(n: Vec3A, ng: Vec3A, wo: Vec3A) -> Vec3A {
    let r = 2.0 * wo.dot(n) * n - wo;
    let height = (0.9 * wo.dot(ng)).min(0.01);
    if wo.dot(n) > 0.0 && n.dot(ng) > 0.0 && r.dot(ng) >= height {
        return n;
    }
    // r's direction along the surface (or any, if r is the normal's opposite), lifted.
    let along = (r - ng * r.dot(ng))
        .try_normalize()
        .unwrap_or_else(|| ng.any_orthonormal_vector());
    let lifted = along * (1.0 - height * height).max(0.0).sqrt() + ng * height;
    (wo + lifted).normalize_or(ng)
}

/// What a hit's textures give: its material with the textured parameters looked up (`None`
/// when only the normal is textured: the table's then shades), and the direction of `dp/du`
/// (the tangent of its shading frame, as Mitsuba 3's).
#[derive(Clone, Debug)]
pub struct TexturedHit {
    /// The material, its textured parameters looked up.
    pub material: Option<Material>,
    /// `dp/du` at the hit.
    pub tangent: Vec3A,
}

/// A BSDF at a hit, with the local frame it is evaluated in.
#[derive(Clone, Copy, Debug)]
pub struct Shading {
    /// The material (a copy: a textured one lives only as long as its hit).
    pub bsdf: Bsdf,
    /// Its local frame.
    pub frame: Frame,
}

/// What next-event estimation needs of the surface at a vertex: how it reflects light from
/// a light's direction towards the viewer, and the density with which the path's own sampler
/// would have chosen that direction (for MIS). Phong and the BSDFs answer it.
///
/// A trait over a closed set of two, not an enum: the functions below are generic over it, so
/// that each is compiled once for Phong, exactly the code it was before the BSDFs (same
/// speed, same pixels: `bench/commit_compare.py`), and once for a BSDF in its frame.
pub trait Lobe {
    /// True if the surface reflects nothing (no shadow ray can change that).
    fn is_black(&self) -> bool;
    /// True if light from behind the surface reaches the viewer (a rough dielectric).
    fn transmits(&self) -> bool;
    /// The weight of incident radiance from `wi` towards `wo` under `model`: the course's
    /// reflectance, or `f |cos(theta_i)|`.
    fn reflectance(&self, model: Model, wi: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A;
    /// The density per solid angle of the surface's sampler choosing `wi` under `sampling`.
    fn pdf(&self, wo: Vec3A, n: Vec3A, wi: Vec3A, sampling: Sampling) -> f32;
}

impl Lobe for Phong {
    #[inline]
    fn is_black(&self) -> bool {
        Phong::is_black(self)
    }
    #[inline]
    fn transmits(&self) -> bool {
        false
    }
    #[inline]
    fn reflectance(&self, model: Model, wi: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A {
        reflectance(model, self, wi, wo, n)
    }
    #[inline]
    fn pdf(&self, wo: Vec3A, n: Vec3A, wi: Vec3A, sampling: Sampling) -> f32 {
        brdf_pdf(self, wo, n, wi, sampling)
    }
}

/// A BSDF's weights are `f |cos(theta_i)|` and its own sampler's density under every model and
/// sampling strategy: the strategies and the course's reflectance are Phong's.
impl Lobe for Shading {
    #[inline]
    fn is_black(&self) -> bool {
        false
    }
    #[inline]
    fn transmits(&self) -> bool {
        self.bsdf.transmits()
    }
    #[inline]
    fn reflectance(&self, _: Model, wi: Vec3A, wo: Vec3A, _: Vec3A) -> Vec3A {
        let f = &self.frame;
        self.bsdf.eval(f.to_local(wo), f.to_local(wi))
    }
    #[inline]
    fn pdf(&self, wo: Vec3A, _: Vec3A, wi: Vec3A, _: Sampling) -> f32 {
        let f = &self.frame;
        self.bsdf.pdf(f.to_local(wo), f.to_local(wi))
    }
}

/// The reflectance that weights incident radiance under `model`: the course's `r(wi, wo)`, or the
/// BRDF times the cosine `f(wi, wo) (wi.n)` for the physically based model.
#[inline]
pub fn reflectance(model: Model, phong: &Phong, wi: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A {
    match model {
        Model::Course => phong.course_reflectance(wi, wo, n),
        Model::Physical => phong.brdf(wi, wo, n) * wi.dot(n).max(0.0),
    }
}

/// Radiance the surface of `si` emits towards the viewer, `L_e(p, wo)`: zero unless it is an
/// area light facing `wo` (or two-sided) and emission is on.
#[inline]
pub fn emitted(tr: &Tracer, si: &Interaction) -> Vec3A {
    if si.light == NO_LIGHT || !tr.effects.emission {
        return Vec3A::ZERO;
    }
    let light = &tr.emitters.lights[si.light as usize];
    let le = light.emitted(si.hit.n, si.wo);
    match light.texture {
        None => le,
        Some(_) => textured_emission(tr, si, light, le),
    }
}

/// A textured light's radiance `le` times its texture at the hit of `si`, read at its finest
/// texels as a light sample reads it (so that the two strategies MIS weighs estimate the same
/// integrand; out of line: the untextured path stays small).
#[inline(never)]
fn textured_emission(tr: &Tracer, si: &Interaction, light: &AreaLight, le: Vec3A) -> Vec3A {
    let prim = tr.geometry.prim(si.hit.prim);
    let uv = tr.geometry.uv(&prim, si.hit.p);
    tr.emitters.textured(light, le, uv, 0.0)
}

/// Radiance that a ray of unit direction `d` leaving the scene brings back: the background; or,
/// in a scene with an environment light (whose background is black), the environment's
/// radiance where `seen`. A ray that a light sample could have found instead (an indirect ray
/// of the Direct and Global shaders, straight from the vertex whose light sample counted the
/// environment) sees none of it, as it sees none of an emitter it hits.
#[inline]
pub fn sky(tr: &Tracer, d: Vec3A, seen: bool) -> Vec3A {
    match &tr.emitters.environment {
        Some(env) if tr.effects.emission && seen => env.radiance(d),
        Some(_) if tr.effects.emission => Vec3A::ZERO,
        _ => tr.background,
    }
}

/// Eq. 3 with area lights: the point lights' sum ([`point_lights`]) plus the area lights'
/// integral estimated with `light_samples` samples ([`area_lights`]).
#[inline]
pub fn direct_light<L: Lobe>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    light_samples: u32,
) -> Vec3A {
    point_lights(tr, si, lobe) + area_lights(tr, si, lobe, light_samples, None)
}

/// Eq. 3: `L_dir = sum_s L_i^s r(wi^s, wo) V^s` over the point lights. A light counts only when
/// it is above the surface (`wi.n > 0`) and the shadow ray reaches it.
///
/// Without shadows (`effects: (shadows: false)`) every light facing the point counts.
#[inline]
pub fn point_lights<L: Lobe>(tr: &mut Tracer, si: &Interaction, lobe: &L) -> Vec3A {
    if lobe.is_black() {
        // Reflects nothing: no shadow ray can change that.
        return Vec3A::ZERO;
    }
    let lights = tr.lights;
    // The loop is compiled twice: with the normal map's leak test, and (every other hit)
    // without it.
    if si.bent {
        let each = |light| point_light_by::<L, true>(tr, si, lobe, light);
        lights.iter().map(each).sum()
    } else {
        let each = |light| point_light_by::<L, false>(tr, si, lobe, light);
        lights.iter().map(each).sum()
    }
}

/// One point light's term of Eq. 3: `L_i r(wi, wo) V`.
#[inline]
fn point_light<L: Lobe>(tr: &mut Tracer, si: &Interaction, lobe: &L, light: &Light) -> Vec3A {
    if si.bent {
        point_light_by::<L, true>(tr, si, lobe, light)
    } else {
        point_light_by::<L, false>(tr, si, lobe, light)
    }
}

/// [`point_light`] at a hit whose normal a normal map gave (`BENT`) or not.
#[inline]
fn point_light_by<L: Lobe, const BENT: bool>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    light: &Light,
) -> Vec3A {
    let Some((inc, shadow)) = point_light_ray::<BENT>(si, light, lobe.transmits()) else {
        return Vec3A::ZERO;
    };
    let visible = !tr.effects.shadows
        || match light.in_room() {
            true => tr.unoccluded_in_room(&shadow),
            false => tr.unoccluded(&shadow),
        };
    point_light_term(tr.model, si, lobe, &inc, visible)
}

/// A point light's incident light at `si` and its shadow ray `V^s`, or `None` if the light
/// adds nothing there whatever the visibility (behind the surface unless it `transmits`, or at
/// the point itself).
///
/// The shadow ray stops just short of the light, so that a surface the light sits on does not
/// block it. No plane can block it when the light is in the planes' room
/// ([`Light::in_room`]). At a normal-mapped hit (`BENT`) a light on one side of the shading
/// normal and the other of the surface adds nothing ([`Interaction::leaks`]).
#[inline]
fn point_light_ray<const BENT: bool>(
    si: &Interaction,
    light: &Light,
    transmits: bool,
) -> Option<(Incident, Ray)> {
    let inc = light.incident(si.hit.p)?;
    if (!transmits && inc.wi.dot(si.n) <= 0.0) || (BENT && si.leaks(inc.wi)) {
        return None;
    }
    let shadow = si.origins.ray(inc.wi, inc.dist * SHADOW_END);
    Some((inc, shadow))
}

/// `L_i r(wi, wo) V` for the incident light `inc` of [`point_light_ray`], seen or not.
#[inline]
fn point_light_term<L: Lobe>(
    model: Model,
    si: &Interaction,
    lobe: &L,
    inc: &Incident,
    visible: bool,
) -> Vec3A {
    if visible {
        inc.li * lobe.reflectance(model, inc.wi, si.wo, si.n)
    } else {
        Vec3A::ZERO
    }
}

/// The area lights' share of Eq. 3, `int L_e(wi) r(wi, wo) V(wi) dwi` over the directions that
/// reach an emitter or the environment (`f cos` in place of `r` under the Physical model),
/// estimated with `samples` light samples: each picks one light by power and a point on it (a
/// direction of the environment), and weighs `L_e r V / (P(light) pdf(wi))`.
///
/// With `mis` (the BRDF sampling strategy of a path tracer), each sample is also weighted by the
/// power heuristic against the density with which that strategy would pick `wi`; the path
/// tracer's BRDF-sampled hits on emitters take the complementary weight.
#[inline]
pub fn area_lights<L: Lobe>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    samples: u32,
    mis: Option<Sampling>,
) -> Vec3A {
    if !tr.effects.emission || tr.emitters.is_empty() || samples == 0 || lobe.is_black() {
        return Vec3A::ZERO;
    }
    let mut sum = Vec3A::ZERO;
    for _ in 0..samples {
        // Choose a light by power, then a point on it.
        let u = tr.sampler.next_f64();
        let (u1, u2) = tr.sampler.next_2d();
        match tr.emitters.choose_any(u) {
            Some(Chosen::Area(light, pmf)) => {
                sum += area_sample(tr, si, lobe, light, pmf, (u1, u2), mis);
            }
            Some(Chosen::Environment(env, pmf)) => {
                sum += environment_sample(tr, si, lobe, env, pmf, mis);
            }
            // Point lights are summed apart when they take no part in the choice.
            Some(Chosen::Point(..)) | None => {}
        }
    }
    sum / samples as f32
}

/// One light of all, point, area or environment, chosen in proportion to its power and divided
/// by the chance of choosing it (the path tracer's `lights_per_vertex: One`): one shadow ray.
/// With `area` false a chosen area or environment light adds nothing (BRDF-sampled rays gather
/// them). With
/// `by_importance` (`lights_per_vertex: Importance`) the point lights' share of the choice goes
/// to each in proportion to its unshadowed contribution at the vertex instead.
#[inline]
pub fn one_light<L: Lobe>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    mis: Option<Sampling>,
    area: bool,
    by_importance: bool,
) -> Vec3A {
    if lobe.is_black() {
        return Vec3A::ZERO;
    }
    let u = tr.sampler.next_f64();
    let (u1, u2) = tr.sampler.next_2d();
    match tr.emitters.choose_any(u) {
        Some(Chosen::Point(..)) if by_importance => {
            // The point lights' share, spent again on their contributions here: u's place
            // within the share picks the light.
            let (start, share) = tr.emitters.point_share();
            let v = ((u - start) / share).clamp(0.0, 1.0 - f64::EPSILON / 2.0);
            let lights = tr.lights;
            let Some((j, p)) = choose_by_importance(lights, si.hit.p, si.n, lobe.transmits(), v)
            else {
                return Vec3A::ZERO;
            };
            // A light chosen with a chance below f32's range (about 1e-38) would weigh inf, and
            // inf * 0 is NaN when it is shadowed: such a sample, never drawn in practice, adds 0.
            let weight = (1.0 / (share * p)) as f32;
            if !weight.is_finite() {
                return Vec3A::ZERO;
            }
            point_light(tr, si, lobe, &lights[j]) * weight
        }
        Some(Chosen::Point(j, pmf)) => {
            let light = tr.lights[j];
            point_light(tr, si, lobe, &light) / pmf
        }
        Some(Chosen::Area(light, pmf)) if area && tr.effects.emission => {
            area_sample(tr, si, lobe, light, pmf, (u1, u2), mis)
        }
        Some(Chosen::Environment(env, pmf)) if area && tr.effects.emission => {
            environment_sample(tr, si, lobe, env, pmf, mis)
        }
        _ => Vec3A::ZERO,
    }
}

/// One sample of `light`, chosen with probability `pmf`, from the random numbers `u`:
/// `L_e r V w / (pmf pdf)`, with `w` the power heuristic's weight against BRDF sampling under
/// `mis` (else 1).
#[inline]
fn area_sample<L: Lobe>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    light: &AreaLight,
    pmf: f32,
    (u1, u2): (f32, f32),
    mis: Option<Sampling>,
) -> Vec3A {
    let Some(ls) = sample_area_light(tr.emitters, light, si.hit.p, (u1, u2)) else {
        return Vec3A::ZERO;
    };
    light_term(tr, si, lobe, &ls, pmf, mis)
}

/// A sample of area light `light` (of `emitters`) seen from `p`, from the random numbers `u`,
/// with a textured light's radiance at the sampled point (its finest texels).
#[inline]
pub fn sample_area_light(
    emitters: &Emitters,
    light: &AreaLight,
    p: Vec3A,
    (u1, u2): (f32, f32),
) -> Option<LightSample> {
    let mut ls = light.sample(p, u1, u2)?;
    ls.le = emitters.textured(light, ls.le, ls.uv, 0.0);
    Some(ls)
}

/// One sample of the environment light `env`, chosen with probability `pmf`, from one more 2D
/// point of 53-bit coordinates (`next_2d_f64`: its map's cells can be finer than f32's grid),
/// weighed as
/// [`area_sample`]'s.
#[inline]
fn environment_sample<L: Lobe>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    env: &EnvironmentLight,
    pmf: f32,
    mis: Option<Sampling>,
) -> Vec3A {
    let (v1, v2) = tr.sampler.next_2d_f64();
    let Some(ls) = env.sample(v1, v2) else {
        return Vec3A::ZERO;
    };
    light_term(tr, si, lobe, &ls, pmf, mis)
}

/// A light sample's term, `L_e r V w / (pmf pdf)`: zero below a surface that does not transmit,
/// without density, or shadowed.
#[inline]
fn light_term<L: Lobe>(
    tr: &mut Tracer,
    si: &Interaction,
    lobe: &L,
    ls: &LightSample,
    pmf: f32,
    mis: Option<Sampling>,
) -> Vec3A {
    let Some((shadow, pdf)) = light_ray(si, lobe, ls, pmf) else {
        return Vec3A::ZERO;
    };
    // Shadow ray V: stop just short of the sampled point.
    let visible = !tr.effects.shadows || tr.unoccluded(&shadow);
    if !visible {
        return Vec3A::ZERO;
    }
    light_weighted(tr.model, (si.wo, si.n), lobe, (ls.wi, ls.le, pdf), mis)
}

/// The first half of `light_term`: the shadow ray of light sample `ls` (chosen with
/// probability `pmf`), which stops just short of the sampled point, and the sample's density
/// `pmf pdf`; `None` where the term is zero whatever the ray meets (no radiance, a direction
/// below a surface that does not transmit, no density).
#[inline]
pub fn light_ray<L: Lobe>(
    si: &Interaction,
    lobe: &L,
    ls: &LightSample,
    pmf: f32,
) -> Option<(Ray, f32)> {
    if ls.le == Vec3A::ZERO || (!lobe.transmits() && ls.wi.dot(si.n) <= 0.0) || si.leaks(ls.wi) {
        return None;
    }
    let pdf = pmf * ls.pdf;
    // A density of zero (or NaN) cannot weigh a sample.
    if pdf.is_nan() || pdf <= 0.0 {
        return None;
    }
    Some((si.origins.ray(ls.wi, ls.dist * SHADOW_END), pdf))
}

/// The second half of `light_term`, for a sample whose shadow ray met nothing, at a vertex
/// seen from `wo` with shading normal `n`: `L_e r w / pdf` for the sample's direction `wi`,
/// radiance `le` and density `pdf` ([`light_ray`]'s), `w` the power heuristic's weight against
/// BRDF sampling under `mis` (else 1).
#[inline]
pub fn light_weighted<L: Lobe>(
    model: Model,
    (wo, n): (Vec3A, Vec3A),
    lobe: &L,
    (wi, le, pdf): (Vec3A, Vec3A, f32),
    mis: Option<Sampling>,
) -> Vec3A {
    let w = match mis {
        Some(sampling) => power_heuristic(pdf, lobe.pdf(wo, n, wi, sampling)),
        None => 1.0,
    };
    le * lobe.reflectance(model, wi, wo, n) * (w / pdf)
}

/// Probability of picking the diffuse lobe in BRDF sampling: the lobes' share of `kd + ks`.
pub fn diffuse_probability(phong: &Phong) -> f32 {
    let (d, s) = (phong.kd.element_sum(), phong.ks.element_sum());
    if d + s <= 0.0 { 1.0 } else { d / (d + s) }
}

/// Density per solid angle of direction `wi` at a Phong vertex under each sampling strategy.
pub fn brdf_pdf(phong: &Phong, wo: Vec3A, n: Vec3A, wi: Vec3A, sampling: Sampling) -> f32 {
    let cos_i = wi.dot(n);
    if cos_i <= 0.0 {
        return 0.0;
    }
    match sampling {
        Sampling::Uniform => hemisphere::UNIFORM_PDF,
        Sampling::Cosine => hemisphere::cosine_pdf(cos_i),
        Sampling::Brdf => {
            let pd = diffuse_probability(phong);
            // A diffuse material skips the lobe: its share would add exactly 0.
            if pd == 1.0 {
                return cos_i / PI;
            }
            let cos_a = wi.dot(reflect(wo, n));
            pd * cos_i / PI + (1.0 - pd) * hemisphere::phong_lobe_pdf(cos_a, phong.shininess)
        }
    }
}

/// Shadow rays end at this fraction of the distance to the light.
pub const SHADOW_END: f32 = 1.0 - 1e-4;

/// The one ray a mirror, metal (`Conductor`) or glass surface sends on, its tint, and its kind,
/// in the course's model; `None` for Phong, and for an effect that is off (the surface is then
/// black).
///
/// Mirrors reflect `wo` about the normal. Glass refracts with Snell's law (`eta = 1 / ior`
/// entering, `ior` leaving) and reflects under total internal reflection.
#[inline]
pub fn specular_bounce(si: &Interaction, effects: Effects) -> Option<(Ray, Vec3A, RayKind)> {
    match si.material() {
        Material::Phong(_) | Material::Bsdf(_) => None,
        Material::Mirror(m) => {
            if !effects.reflection {
                return None;
            }
            let wr = m.reflect(si.wo, si.n);
            Some((si.spawn(wr), m.color, RayKind::Reflection))
        }
        // A metal: the mirror direction, weighted by the Fresnel term at its angle.
        Material::Conductor(c) => {
            if !effects.reflection {
                return None;
            }
            let (wr, f) = c.reflect(si.wo, si.n);
            Some((si.spawn(wr), f, RayKind::Reflection))
        }
        Material::Transmissive(g) => {
            let r = g.refract(si.wo, si.hit.n);
            let (kind, on) = if r.total_internal_reflection {
                (RayKind::Reflection, effects.reflection)
            } else {
                (RayKind::Refraction, effects.refraction)
            };
            if !on {
                return None;
            }
            Some((si.spawn(r.wt), g.color, kind))
        }
    }
}

/// Where a chain of mirror and glass bounces ends.
#[derive(Clone, Debug)]
#[allow(
    clippy::large_enum_variant,
    reason = "returned by value and matched at once by the caller; boxing the Phong variant \
              would allocate once per chain"
)]
pub enum ChainEnd<'a> {
    /// At a Phong surface, reached with throughput `beta` (the product of the tints).
    Phong {
        /// The Phong hit.
        si: Interaction<'a>,
        /// Its material.
        phong: Phong,
        /// Throughput of the chain.
        beta: Vec3A,
    },
    /// At a surface with a BSDF, reached with throughput `beta`.
    Bsdf {
        /// The hit.
        si: Interaction<'a>,
        /// Its BSDF and frame.
        shading: Shading,
        /// Throughput of the chain.
        beta: Vec3A,
    },
    /// The chain left the scene with throughput `beta`: it sees the sky ([`sky`]).
    Escaped {
        /// Throughput of the chain.
        beta: Vec3A,
        /// The radiance it brings back from the sky.
        sky: Vec3A,
    },
    /// The chain carries no light: an effect that is off, or longer than its cap.
    Absorbed,
}

/// Trace `ray` (counted as `kind`) and follow mirrors and glass, as a loop carrying the
/// throughput, until a Phong surface, an escape, or `max_specular` consecutive specular
/// bounces (the course's model: mirrors reflect, glass refracts or reflects totally, tinted).
///
/// Also returns the light emitted towards the ray by the surfaces of the chain, weighted by the
/// chain's throughput. The first surface's emission counts only when `see_first` (a camera ray;
/// an indirect ray's emitter is the direct light of the vertex it left, already counted); after
/// a mirror or glass every emitter counts, as no light sample reaches through them. The
/// environment light, where the chain escapes, counts by the same rule.
#[inline]
pub fn follow_specular<'a>(
    tr: &mut Tracer<'a>,
    ray: &Ray,
    kind: RayKind,
    max_specular: u32,
    see_first: bool,
) -> (ChainEnd<'a>, Vec3A) {
    let (mut ray, mut kind, mut beta) = (*ray, kind, Vec3A::ONE);
    let mut le = Vec3A::ZERO;
    // `chain` counts the specular bounces that led to this ray.
    for chain in 0..=max_specular {
        let Some(hit) = tr.trace(&ray, kind) else {
            // The environment counts as an emitter does.
            let sky = sky(tr, ray.d, see_first || chain > 0);
            return (ChainEnd::Escaped { beta, sky }, le);
        };
        let si = Interaction::new(tr, &ray, hit);
        if see_first || chain > 0 {
            le += beta * emitted(tr, &si);
        }
        // Phong or a BSDF as textured here.
        if let Material::Phong(phong) = si.material() {
            let phong = *phong;
            return (ChainEnd::Phong { si, phong, beta }, le);
        }
        if let Material::Bsdf(bsdf) = si.material() {
            let shading = si.shading(tr, bsdf);
            return (ChainEnd::Bsdf { si, shading, beta }, le);
        }
        if chain == max_specular {
            break;
        }
        let Some((next, tint, next_kind)) = specular_bounce(&si, tr.effects) else {
            break;
        };
        beta *= tint;
        (ray, kind) = (next, next_kind);
    }
    (ChainEnd::Absorbed, le)
}

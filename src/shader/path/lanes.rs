//! Path's diffuse vertices shaded in SIMD lanes: the vertices of a wave of paths
//! (`render::waves`) that meet a diffuse Phong surface (no specular lobe; its `kd` constant or
//! textured, looked up at the hit), under either model,
//! a path per lane, from the hit to the next ray: the interaction, next-event estimation
//! over point, spot and directional lights and one sample of the area lights and the
//! environment with the shadow rays tested in lanes
//! ([`Geometry::occluded_lanes`]) and the light sample's MIS weight, the cosine-weighted
//! direction, its weight, and Russian roulette.
//!
//! Every lane computes what [`super::step`] computes for its path, operation for operation
//! (`Interaction::new`, `Origins`, `PointLight::incident`, `Phong::brdf` and
//! `Phong::course_reflectance`, `reflectance`,
//! `Frame::from_normal` (glam's `any_orthonormal_pair`), `hemisphere::cosine`, `brdf_pdf`), and
//! draws its random numbers from its own stream in the same order (drawn in lanes by
//! `sampling::Streams`; the light choice runs lane by lane, `sin_cos_turns` is repeated in
//! lanes by `shader::warps`), so each path adds the same contributions and goes on with the
//! same ray, to the bit (`tests/integration/path_waves.rs`). A spot or directional light's
//! incident light (`Light::incident`) and an area-light or environment sample run the scalar
//! code lane by lane (`surface::sample_area_light` or `EnvironmentLight::sample`, `light_ray` on
//! `Interaction::flat`), except the point on an untextured triangle light (a rectangle's
//! half, a mesh's face), which is sampled in lanes (`AreaLight::sample`'s operations), its
//! shadow ray made in lanes too (`light_ray`'s). Every sample's shadow ray is tested in
//! lanes, and its weight (`light_weighted`: the diffuse reflectance, the power heuristic
//! against `brdf_pdf`) is computed in lanes too.

use super::{Path, PathState};
use crate::accel::lanes::SurfaceLanes;
use crate::accel::lanes::{RayLanes, array, dot, lane_mask, origins, rows};
use crate::accel::{Floats, Geometry, Isa, MAX_LANES, ShearLanes, Tally, record_hit};
use crate::geometry::{Hit, Ray};
use crate::light::{
    AreaLight, Chosen, Emitting, Light, LightSample, NO_LIGHT, choose_by_importance,
};
use crate::material::{Material, Model, Phong};
use crate::sampling::{LightSampling, LightsPerVertex, Sampler, Sampling, Streams, WithStreams};
use crate::shader::Tracer;
use crate::shader::record::{Record, Technique};
use crate::shader::surface::{
    Interaction, SHADOW_END, diffuse_probability, light_ray, sample_area_light,
};
use crate::shader::warps::sin_cos_turns;
use crate::shape::Triangle;
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// A path in a wave: its state, its random stream and what it has added.
pub struct PathSlot<R> {
    /// The path.
    pub st: PathState,
    /// Its sample's random numbers.
    pub sampler: Sampler,
    /// Its contributions.
    pub rec: R,
}

/// True if `p`'s vertices can be shaded in lanes: BRDF or cosine sampling (under either
/// model), with any lights (every point, spot and directional light and one sample of the area
/// lights and the environment per vertex, or under the Physical model one light chosen by
/// power or by importance) and any textures (a diffuse material with a textured `kd` is looked
/// up at each hit; other textured materials go to the one-ray code).
pub fn applies(p: &Path) -> bool {
    matches!(p.sampling, Sampling::Brdf | Sampling::Cosine)
}

/// Each material that the lanes shade: a Phong material that reflects light diffusely only
/// (so its BRDF sampling always picks the cosine lobe), by index. A material whose `kd` alone
/// is textured is one too where its texel is not black: its parameters are looked up at each
/// hit, as `Interaction::new` looks them up.
pub struct Diffuse(Vec<Option<Kd>>);

/// Where a diffuse material's `kd` comes from.
#[derive(Clone, Copy)]
enum Kd {
    /// The material's own parameters.
    Constant(Phong),
    /// Its texture, at each hit.
    Textured,
}

impl Diffuse {
    /// The table of `tr`'s materials.
    pub fn table(tr: &Tracer) -> Diffuse {
        let diffuse = |(i, m): (usize, &Material)| {
            let Material::Phong(phong) = m else {
                return None;
            };
            if phong.ks != Vec3A::ZERO {
                return None;
            }
            match tr.textures.get(i).filter(|t| !t.is_empty()) {
                None => (!phong.is_black() && diffuse_probability(phong) == 1.0)
                    .then_some(Kd::Constant(*phong)),
                Some(t) => t.only_reflectance().then_some(Kd::Textured),
            }
        };
        Diffuse(tr.materials.iter().enumerate().map(diffuse).collect())
    }

    /// The material (index and parameters) of `hit`, if the vertex it makes on path `st` is
    /// shaded in lanes: a flat primitive of a diffuse material that emits nothing, where the
    /// path may scatter.
    #[inline]
    pub fn at(&self, tr: &Tracer, p: &Path, st: &PathState, hit: &Hit) -> Option<(u32, Phong)> {
        let max_depth = p
            .max_depth
            .unwrap_or(super::MAX_DEPTH)
            .min(super::MAX_DEPTH);
        if st.depth >= max_depth {
            return None;
        }
        let geometry: &Geometry = tr.geometry;
        let (material, smooth, light) = geometry.shading_of(hit.prim);
        if smooth || light != NO_LIGHT {
            return None;
        }
        match self.0.get(material as usize).copied().flatten()? {
            Kd::Constant(phong) => Some((material, phong)),
            Kd::Textured => Some((material, textured(tr, material, hit)?)),
        }
    }
}

/// The Phong parameters of textured material `material` at `hit` (on a flat primitive), as
/// `Interaction::new` looks them up, if the lanes shade them: not at a black texel, which
/// reflects nothing and draws no light sample in the one-ray code. (Out of line: the
/// untextured scenes' rounds stay as small as they were.)
#[inline(never)]
fn textured(tr: &Tracer, material: u32, hit: &Hit) -> Option<Phong> {
    // The texture at the hit's coordinates, filtered over the sample's footprint there.
    let (geometry, i): (&Geometry, usize) = (tr.geometry, material as usize);
    let prim = geometry.prim(hit.prim);
    let uv = geometry.uv(&prim, hit.p);
    let width = tr.footprint.width(hit.p, hit.n) * geometry.uv_rate(&prim, hit.p);
    let physical = tr.model == Model::Physical;
    let Material::Phong(phong) = tr.textures[i].apply(&tr.materials[i], uv, width, physical) else {
        return None;
    };
    (!phong.is_black() && diffuse_probability(&phong) == 1.0).then_some(phong)
}

/// One round of a wave: trace each path's ray of `slots` and shade the vertex it meets, the
/// rays in chunks of lanes ([`Geometry::nearest_lanes`] in a scene without a BVH,
/// [`Geometry::nearest_small`] in a small scene of triangles, else each with the one-ray
/// query), the diffuse
/// vertices ([`Diffuse`]) in those lanes, the others with the one-ray [`super::step`] (its
/// random stream swapped into `tr`). Each path adds its vertex's light to its recorder and
/// takes its next ray (counted); `alive[k]` (one per slot) says whether path `k` goes on.
pub fn round<R: Record>(
    tr: &mut Tracer,
    p: &Path,
    diffuse: &Diffuse,
    slots: &mut [PathSlot<R>],
    alive: &mut [bool],
) {
    match tr.geometry.bvh.isa() {
        // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { round_avx512(tr, p, diffuse, slots, alive) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { round_avx2(tr, p, diffuse, slots, alive) },
        // SAFETY: `Vec4` runs on every CPU.
        _ => unsafe { round_in::<glam::Vec4, R>(tr, p, diffuse, slots, alive) },
    }
}

/// [`round`] in sixteen AVX-512 lanes.
///
/// # Safety
/// The CPU must have AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn round_avx512<R: Record>(
    tr: &mut Tracer,
    p: &Path,
    diffuse: &Diffuse,
    slots: &mut [PathSlot<R>],
    alive: &mut [bool],
) {
    // SAFETY: this function runs only where AVX-512F was found.
    unsafe { round_in::<crate::accel::F16, R>(tr, p, diffuse, slots, alive) }
}

/// [`round`] in eight AVX2 lanes.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn round_avx2<R: Record>(
    tr: &mut Tracer,
    p: &Path,
    diffuse: &Diffuse,
    slots: &mut [PathSlot<R>],
    alive: &mut [bool],
) {
    // SAFETY: this function runs only where AVX2 was found.
    unsafe { round_in::<crate::accel::F8, R>(tr, p, diffuse, slots, alive) }
}

/// [`round`] in lanes `L`. No closures that compute in lanes, so that this inlines whole into
/// the AVX2 and AVX-512 copies.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn round_in<L: Floats, R: Record>(
    tr: &mut Tracer,
    p: &Path,
    diffuse: &Diffuse,
    slots: &mut [PathSlot<R>],
    alive: &mut [bool],
) {
    let geometry: &Geometry = tr.geometry;
    for c in (0..slots.len()).step_by(L::LANES) {
        let count = (slots.len() - c).min(L::LANES);
        // The chunk's rays and throughputs in lanes (lanes past `count` repeat the last).
        let st = |i: usize| &slots[c + i.min(count - 1)].st;
        let (mut o_err, mut t_max) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
        for i in 0..L::LANES {
            (o_err[i], t_max[i]) = (st(i).ray.o_err, st(i).ray.t_max);
        }
        // SAFETY: the caller vouches for the instruction set; so for every `unsafe` block
        // below, each makes values of `L`. The vectors transposed into lanes by shuffles.
        let (o, d, beta) = unsafe {
            (
                L::transpose3::<MAX_LANES>(&std::array::from_fn(|i| &st(i).ray.o)),
                L::transpose3::<MAX_LANES>(&std::array::from_fn(|i| &st(i).ray.d)),
                L::transpose3::<MAX_LANES>(&std::array::from_fn(|i| &st(i).beta)),
            )
        };
        let (o_err, t_max) = unsafe { (L::from_array(o_err), L::from_array(t_max)) };
        // The nearest hits, with their records, in the lanes: the packed primitives tested
        // in lanes, or each ray through the BVH with the one-ray query.
        let mut hits = [None; MAX_LANES];
        let h = if geometry.bvh.is_empty() {
            let lanes = RayLanes::from_parts(o, d, o_err);
            let near = unsafe { geometry.nearest_lanes(&lanes, t_max) };
            let rows = near.rows();
            for (i, hit) in hits.iter_mut().enumerate().take(count) {
                *hit = geometry.lane_hit(&rows, i);
            }
            near.hit
        } else {
            // A small scene's triangles met in the lanes, and their records computed there.
            let small = match geometry.is_small() {
                true => {
                    tr.traversal.prims(count as u64 * geometry.lane_prims());
                    let r = ShearLanes::new(o, d, o_err);
                    Some(geometry.nearest_small(&r, t_max))
                }
                false => None,
            };
            // The records of the triangles met in lanes, in rows (zeros elsewhere); the rays
            // the lanes leave to the one-ray query, and every ray through the BVH, each alone.
            let mut rows = match &small {
                Some(near) => geometry.small_records(near, o, d),
                None => [[0.0f32; MAX_LANES]; 8],
            };
            for (i, hit) in hits.iter_mut().enumerate().take(count) {
                let ray = &slots[c + i].st.ray;
                // (`Geometry::small_hit`'s reading, with the one-ray query apart.)
                if let Some(met) = small.as_ref().and_then(|near| geometry.small_met(near, i)) {
                    *hit = met.map(|met| record_hit(&rows, i, met));
                    continue;
                }
                *hit = match tr.traversal {
                    None => geometry.intersect(ray),
                    Some(t) => geometry.intersect_tallied(ray, t),
                };
                if let Some(h) = hit {
                    for x in 0..3 {
                        rows[x][i] = h.p[x];
                        rows[3 + x][i] = h.n[x];
                    }
                    (rows[6][i], rows[7][i]) = (h.err, h.err_along);
                }
            }
            let load = |row: usize| unsafe { L::from_slice(&rows[row]) };
            SurfaceLanes {
                p: [load(0), load(1), load(2)],
                n: [load(3), load(4), load(5)],
                err: load(6),
                err_along: load(7),
            }
        };
        // Diffuse vertices stay in the lanes; the others go one at a time. Each lane's
        // material is kept only for the area-light and environment samples: the point lights'
        // terms read only `kd` (a scene without those skips the copies: 4-5% of its time).
        let (mut shaded, mut kd) = (0u32, [[0.0f32; MAX_LANES]; 3]);
        let mut materials = [None; MAX_LANES];
        let keep_materials = !tr.emitters.is_empty();
        for (i, hit) in hits.iter().enumerate().take(count) {
            let k = c + i;
            let slot = &mut slots[k];
            if let Some(h) = hit
                && let Some((m, phong)) = diffuse.at(tr, p, &slot.st, h)
            {
                shaded |= 1 << i;
                if keep_materials {
                    materials[i] = Some((m, phong));
                }
                for (row, x) in kd.iter_mut().zip(phong.kd.to_array()) {
                    row[i] = x;
                }
                continue;
            }
            std::mem::swap(&mut tr.sampler, &mut slot.sampler);
            alive[k] = super::step(tr, p, &mut slot.st, *hit, &mut slot.rec);
            std::mem::swap(&mut tr.sampler, &mut slot.sampler);
            if alive[k] {
                tr.count(&slot.st.ray, slot.st.kind);
            }
        }
        if shaded != 0 {
            let kd = unsafe {
                [
                    L::from_array(kd[0]),
                    L::from_array(kd[1]),
                    L::from_array(kd[2]),
                ]
            };
            let at = Vertices {
                p: h.p,
                nh: h.n,
                err: h.err,
                err_along: h.err_along,
                d,
                beta,
                kd,
                hits: &hits,
                materials: &materials,
            };
            // The chunk's streams in lanes of their sampler's kind: the shading compiled for
            // each, with no `match` per draw.
            let chunk = &mut slots[c..c + count];
            let kind = chunk[0].sampler.clone();
            kind.with_streams(Shade {
                tr: &mut *tr,
                p,
                slots: chunk,
                shaded,
                at: &at,
                alive: &mut alive[c..],
            });
        }
    }
}

/// A chunk's vertices in lanes: the hit's point, geometric normal and error bounds, the ray's
/// direction, the path's throughput, and the surface's `kd`.
struct Vertices<'h, L> {
    p: [L; 3],
    nh: [L; 3],
    err: L,
    err_along: L,
    d: [L; 3],
    beta: [L; 3],
    kd: [L; 3],
    /// The same hits lane by lane, for the area and environment samples.
    hits: &'h [Option<Hit>; MAX_LANES],
    /// Each shaded lane's material, index and parameters, where the scene has area lights or
    /// an environment (else `None`: only their samples read it).
    materials: &'h [Option<(u32, Phong)>; MAX_LANES],
}

/// [`shade_in`]'s arguments, run with the streams of the chunk's sampler
/// ([`Sampler::with_streams`]).
struct Shade<'a, 'h, 't, L, R> {
    tr: &'a mut Tracer<'t>,
    p: &'a Path,
    slots: &'a mut [PathSlot<R>],
    shaded: u32,
    at: &'a Vertices<'h, L>,
    alive: &'a mut [bool],
}

impl<L: Floats, R: Record> WithStreams for Shade<'_, '_, '_, L, R> {
    type Out = ();

    #[inline(always)]
    fn run<S: Streams>(self) {
        // SAFETY: `at` holds values of `L`, which only code running `L`'s instruction set can
        // make (every `Floats` constructor is `unsafe`); and `Shade`, private to this module,
        // is made only in `round_in`, whose caller vouches for that instruction set.
        unsafe {
            shade_in::<L, R, S>(
                self.tr,
                self.p,
                self.slots,
                self.shaded,
                self.at,
                self.alive,
            )
        }
    }
}

/// Shade the vertices of `at` in the lanes of `shaded` (lane `i` is path `slots[i]`, which
/// adds its light to its recorder and takes its next ray; `alive[i]` says whether it goes on).
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn shade_in<L: Floats, R: Record, S: Streams>(
    tr: &mut Tracer,
    p: &Path,
    slots: &mut [PathSlot<R>],
    shaded: u32,
    at: &Vertices<L>,
    alive: &mut [bool],
) {
    let (p_, nh, d, beta, kd_l) = (at.p, at.nh, at.d, at.beta, at.kd);
    let (err, err_along) = (at.err, at.err_along);
    // SAFETY: the caller vouches for the instruction set; so for every `unsafe` block below,
    // each makes values of `L`.
    let (zero, one) = unsafe { (L::splat(0.0), L::splat(1.0)) };
    let live = unsafe { lane_mask::<L>(shaded) };
    // The paths' random streams, drawn in lanes; the shaded lanes' are written back before
    // the scalar code draws again (`scatter_diffuse`'s roulette).
    let mut rng = S::load(slots.iter().map(|s| &s.sampler));
    let keep = |rng: &S, slots: &mut [PathSlot<R>]| {
        for i in Bits(shaded) {
            slots[i].sampler = rng.sampler(i);
        }
    };
    // `Interaction::new`: the normal on the viewer's side (a flat shape's shading normal), and
    // `Origins::new`: the point moved off the surface by its error's projection on the
    // normal, to either side, with the origins' error bound.
    let wo = [-d[0], -d[1], -d[2]];
    let flip = dot(nh, wo).cmplt(zero);
    let n = [
        L::select(flip, -nh[0], nh[0]),
        L::select(flip, -nh[1], nh[1]),
        L::select(flip, -nh[2], nh[2]),
    ];
    let (front, back, o_err) = origins(p_, nh, err, err_along);
    // The reflectance is `f max(cos, 0)` where `wo` is above the surface: `Phong::brdf` of a
    // diffuse surface, `kd / pi`, under the Physical model; the course's `kd`, whatever `wo`,
    // under the Course model (`Phong::course_reflectance`).
    let course = tr.model == Model::Course;
    let inv_pi = unsafe { L::splat(1.0 / PI) };
    let (f, wo_above) = match course {
        true => (kd_l, zero.cmpge(zero)),
        false => (
            [kd_l[0] * inv_pi, kd_l[1] * inv_pi, kd_l[2] * inv_pi],
            dot(wo, n).cmpgt(zero),
        ),
    };
    let surface = Surface {
        nh,
        n,
        front,
        back,
        o_err,
        f,
        wo_above,
        live,
    };
    // Next-event estimation: every point light's term, or one light's, chosen by power or by
    // importance (`one_light`).
    let by_importance = p.lights_per_vertex == LightsPerVertex::Importance;
    // `next_event`'s strategy for the area lights: sampled unless left to BRDF-sampled rays,
    // and weighted against those under MIS.
    let lights = p.lights_under(tr.model);
    let mis = (lights == LightSampling::Mis && tr.effects.indirect).then_some(p.sampling);
    let sample_area = lights != LightSampling::Brdf || !tr.effects.indirect;
    // Each lane's area-light sample and the chance of its light, if it drew one.
    let mut area = AreaRays::default();
    let nee = if p.one_light_under(tr.model) {
        // The choice, lane by lane: `u` picks the light (by importance: `u`'s place within
        // the point lights' share, with the point and normal of the lane's vertex);
        // `one_light` draws two more numbers for an area light's point, which a point light
        // does not read.
        let (mut pos, mut intensity) = ([[0.0f32; MAX_LANES]; 3], [[0.0f32; MAX_LANES]; 3]);
        let (mut pmf, mut room, mut chosen) = ([1.0f32; MAX_LANES], 0u32, 0u32);
        // The lanes that chose a spot or directional light, and which.
        let (mut other, mut others) = ([0usize; MAX_LANES], 0u32);
        let (at_p, at_n) = match by_importance {
            true => (
                [array(p_[0]), array(p_[1]), array(p_[2])],
                [array(n[0]), array(n[1]), array(n[2])],
            ),
            false => ([[0.0f32; MAX_LANES]; 3], [[0.0f32; MAX_LANES]; 3]),
        };
        let (u, u1, u2) = light_numbers(&mut rng, L::LANES);
        let place = choice_places(tr.emitters.cdf(), &u, L::LANES);
        let any_light = !tr.emitters.cdf().is_empty();
        let mut on = TrianglePoints::default();
        for i in Bits(shaded) {
            let (u, u12) = (u[i], (u1[i], u2[i]));
            // The light and the factor of its term: `1 / pmf` by power, `1 / (share p)` by
            // importance (a light chosen with a chance below f32's range adds nothing).
            let pick = match any_light.then(|| tr.emitters.chosen(place[i] as usize)) {
                Some(Chosen::Point(..)) if by_importance => {
                    let (start, share) = tr.emitters.point_share();
                    let v = ((u - start) / share).clamp(0.0, 1.0 - f64::EPSILON / 2.0);
                    let at = |a: &[[f32; MAX_LANES]; 3]| Vec3A::new(a[0][i], a[1][i], a[2][i]);
                    choose_by_importance(tr.lights, at(&at_p), at(&at_n), false, v)
                        .map(|(j, p)| (j, (1.0 / (share * p)) as f32))
                        .filter(|(_, w)| w.is_finite())
                }
                Some(Chosen::Point(j, w)) => Some((j, w)),
                // An area light or the environment: its sample, for the lanes' shadow rays (an
                // untextured triangle's point sampled in lanes below).
                Some(c) if sample_area && tr.effects.emission => {
                    match untextured_triangle(&c) {
                        Some((t, light, pmf)) => on.put(i, t, light, pmf),
                        None => area.sample(tr, at, (i, slots[i].st.ray.d), c, u12, &mut rng),
                    }
                    None
                }
                // A light left to BRDF-sampled rays, or none.
                Some(Chosen::Area(..) | Chosen::Environment(..)) | None => None,
            };
            if let Some((j, w)) = pick {
                pmf[i] = w;
                match &tr.lights[j] {
                    Light::Point(l) => {
                        for c in 0..3 {
                            pos[c][i] = l.position[c];
                            intensity[c][i] = l.intensity[c];
                        }
                        room |= u32::from(l.in_room) << i;
                        chosen |= 1 << i;
                    }
                    Light::Spot(_) | Light::Directional(_) => {
                        other[i] = j;
                        others |= 1 << i;
                    }
                }
            }
        }
        let light = unsafe {
            LightLanes {
                pos: [
                    L::from_array(pos[0]),
                    L::from_array(pos[1]),
                    L::from_array(pos[2]),
                ],
                intensity: [
                    L::from_array(intensity[0]),
                    L::from_array(intensity[1]),
                    L::from_array(intensity[2]),
                ],
                room,
                lanes: chosen,
            }
        };
        let mut term = unsafe { light_term(tr, &light.incident(p_), &surface) };
        if others != 0 {
            // The spot and directional lights' incident light lane by lane, then their terms
            // in lanes as the point lights'.
            let at_p = [array(p_[0]), array(p_[1]), array(p_[2])];
            let inc = unsafe { incidents_by_lane(|i| &tr.lights[other[i]], &at_p, others) };
            let t = unsafe { light_term(tr, &inc, &surface) };
            let lanes = unsafe { lane_mask::<L>(others) };
            term = [
                L::select(lanes, t[0], term[0]),
                L::select(lanes, t[1], term[1]),
                L::select(lanes, t[2], term[2]),
            ];
        }
        let w = unsafe { L::from_array(pmf) };
        let point = match by_importance {
            true => [term[0] * w, term[1] * w, term[2] * w],
            false => [term[0] / w, term[1] / w, term[2] / w],
        };
        unsafe { area.record_triangles(&surface, &on, p_, (&u1, &u2)) };
        // The lanes that chose an area light take its term.
        let term = unsafe { area.terms(tr, &surface, mis, false) };
        let lanes = unsafe { lane_mask::<L>(area.lanes) };
        [
            L::select(lanes, term[0], point[0]),
            L::select(lanes, term[1], point[1]),
            L::select(lanes, term[2], point[2]),
        ]
    } else {
        // `point_lights`: the terms summed from zero in the lights' order, then the area
        // lights' sample added.
        let mut sum = [zero; 3];
        for light in tr.lights {
            let inc = match light {
                Light::Point(l) => unsafe {
                    LightLanes {
                        pos: [
                            L::splat(l.position.x),
                            L::splat(l.position.y),
                            L::splat(l.position.z),
                        ],
                        intensity: [
                            L::splat(l.intensity.x),
                            L::splat(l.intensity.y),
                            L::splat(l.intensity.z),
                        ],
                        room: if l.in_room { u32::MAX } else { 0 },
                        lanes: u32::MAX,
                    }
                    .incident(p_)
                },
                // Lane by lane (no lane form).
                Light::Spot(_) | Light::Directional(_) => unsafe {
                    let at_p = [array(p_[0]), array(p_[1]), array(p_[2])];
                    incidents_by_lane(|_| light, &at_p, shaded)
                },
            };
            let term = unsafe { light_term(tr, &inc, &surface) };
            sum = [sum[0] + term[0], sum[1] + term[1], sum[2] + term[2]];
        }
        // `area_lights` with one sample: the light chosen by power (`u`), a point on it
        // (`u1`, `u2`), its term (zero where none is drawn).
        if sample_area && tr.effects.emission && !tr.emitters.is_empty() {
            let (u, u1, u2) = light_numbers(&mut rng, L::LANES);
            let place = choice_places(tr.emitters.cdf(), &u, L::LANES);
            // An untextured triangle light's point is sampled in lanes, every other light's
            // lane by lane.
            let mut on = TrianglePoints::default();
            for i in Bits(shaded) {
                // (The point lights take no part in this choice.)
                let c = tr.emitters.chosen(place[i] as usize);
                match untextured_triangle(&c) {
                    Some((t, light, pmf)) => on.put(i, t, light, pmf),
                    None => {
                        area.sample(tr, at, (i, slots[i].st.ray.d), c, (u1[i], u2[i]), &mut rng)
                    }
                }
            }
            unsafe { area.record_triangles(&surface, &on, p_, (&u1, &u2)) };
        }
        let area = unsafe { area.terms(tr, &surface, mis, true) };
        [sum[0] + area[0], sum[1] + area[1], sum[2] + area[2]]
    };
    // Each path adds `beta` times its vertex's light.
    let l = [
        array(beta[0] * nee[0]),
        array(beta[1] * nee[1]),
        array(beta[2] * nee[2]),
    ];
    for i in Bits(shaded) {
        let l = Vec3A::new(l[0][i], l[1][i], l[2][i]);
        if l != Vec3A::ZERO {
            let s = &mut slots[i];
            s.rec.add(l, Technique::Light, s.st.depth + 1);
        }
    }
    if !tr.effects.indirect {
        keep(&rng, slots);
        for i in Bits(shaded) {
            alive[i] = false;
        }
        return;
    }
    // The next direction: cosine-weighted about the shading normal (`hemisphere::cosine` in
    // the frame of `Frame::from_normal`); its numbers drawn in lanes.
    let brdf = p.sampling == Sampling::Brdf;
    let (u1, u2) = rng.next_2d(L::LANES);
    if brdf {
        // `sample_phong` compares a number with the diffuse share, 1 here: the cosine lobe.
        rng.next_u32(L::LANES);
    }
    keep(&rng, slots);
    let (u1, u2) = unsafe { (L::from_array(u1), L::from_array(u2)) };
    let r = u1.sqrt();
    let (sin_p, cos_p) = unsafe { sin_cos_turns(u2) };
    let (x, y) = (r * cos_p, r * sin_p);
    let z = ((one - x * x) - y * y).max(zero).sqrt();
    // glam's `any_orthonormal_pair` (Duff et al. 2017).
    let sign = one.copysign(n[2]);
    let a = -one / (sign + n[2]);
    let b = n[0] * n[1] * a;
    let s_axis = [one + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
    let t_axis = [b, sign + n[1] * n[1] * a, -n[1]];
    let wi = [
        x * s_axis[0] + y * t_axis[0] + z * n[0],
        x * s_axis[1] + y * t_axis[1] + z * n[1],
        x * s_axis[2] + y * t_axis[2] + z * n[2],
    ];
    let cos_i = dot(wi, n);
    let above = cos_i.cmpgt(zero);
    // `brdf_pdf`: `cos / pi` for BRDF sampling of a diffuse surface, `max(cos, 0) / pi` (as a
    // product) for cosine sampling.
    let pdf = match brdf {
        true => cos_i / unsafe { L::splat(PI) },
        false => cos_i.max(zero) * unsafe { L::splat(FRAC_1_PI) },
    };
    let ok = above & pdf.cmpgt(zero);
    // `g`: the reflectance, `f max(cos, 0)` (zero where `wo` is not above the surface), over
    // `(2 pi)^2` under the Course model (`sample_phong`).
    let g = [
        L::select(wo_above, f[0], zero) * cos_i.max(zero),
        L::select(wo_above, f[1], zero) * cos_i.max(zero),
        L::select(wo_above, f[2], zero) * cos_i.max(zero),
    ];
    let g = match course {
        true => {
            let tt = unsafe { L::splat(TAU * TAU) };
            [g[0] / tt, g[1] / tt, g[2] / tt]
        }
        false => g,
    };
    let carries = g[0].cmpne(zero) | g[1].cmpne(zero) | g[2].cmpne(zero);
    let go = L::bitmask(ok & carries);
    let beta = [
        beta[0] * (g[0] / pdf),
        beta[1] * (g[1] / pdf),
        beta[2] * (g[2] / pdf),
    ];
    // `Origins::ray`: the origin on the side of the geometric normal the direction leaves by.
    let side = dot(nh, wi).cmpge(zero);
    let o = [
        L::select(side, front[0], back[0]),
        L::select(side, front[1], back[1]),
        L::select(side, front[2], back[2]),
    ];
    let (wi, o, beta, pdf, o_err, hit_p) = (
        [array(wi[0]), array(wi[1]), array(wi[2])],
        [array(o[0]), array(o[1]), array(o[2])],
        [array(beta[0]), array(beta[1]), array(beta[2])],
        array(pdf),
        array(o_err),
        [array(p_[0]), array(p_[1]), array(p_[2])],
    );
    for i in Bits(shaded) {
        let slot = &mut slots[i];
        if go & (1 << i) == 0 {
            alive[i] = false;
            continue;
        }
        let ray = Ray {
            o: Vec3A::new(o[0][i], o[1][i], o[2][i]),
            d: Vec3A::new(wi[0][i], wi[1][i], wi[2][i]),
            t_max: f32::INFINITY,
            o_err: o_err[i],
        };
        let hit_p = Vec3A::new(hit_p[0][i], hit_p[1][i], hit_p[2][i]);
        let beta = Vec3A::new(beta[0][i], beta[1][i], beta[2][i]);
        alive[i] = slot
            .st
            .scatter_diffuse(ray, hit_p, pdf[i], beta, p.rr_depth, &mut slot.sampler);
        if alive[i] {
            tr.count(&slot.st.ray, RayKind::Indirect);
        }
    }
}

/// The lanes' samples of the area lights and the environment: the lanes that drew one, those
/// whose sample has a shadow
/// ray to test (`light_ray`), and their columns, made at the first sample.
#[derive(Default)]
struct AreaRays {
    lanes: u32,
    tested: u32,
    columns: Option<AreaColumns>,
}

/// The samples' shadow rays (whose directions are the samples' `wi`), radiances and
/// densities, a column per coordinate.
#[derive(Default)]
struct AreaColumns {
    ray: [[f32; MAX_LANES]; 8],
    le: [[f32; MAX_LANES]; 3],
    pdf: [f32; MAX_LANES],
}

impl AreaRays {
    /// Lane `i` of `at` (a shaded lane, whose ray has direction `d`) samples the light it
    /// chose: an area light from the random numbers `u` (`area_sample`), the environment from
    /// one more 2D point of the lane's stream in `rng` (`next_2d_f64_at`, as
    /// `environment_sample`); a point light
    /// has its term apart (`light_term`).
    #[inline(always)]
    fn sample<L, S: Streams>(
        &mut self,
        tr: &Tracer,
        at: &Vertices<L>,
        (i, d): (usize, Vec3A),
        chosen: Chosen,
        u: (f32, f32),
        rng: &mut S,
    ) {
        match chosen {
            Chosen::Area(light, pmf) => {
                let ls = at.hits[i].and_then(|hit| sample_area_light(tr.emitters, light, hit.p, u));
                self.record(tr, at, i, d, ls, pmf);
            }
            Chosen::Environment(env, pmf) => {
                let v = rng.next_2d_f64_at(i);
                self.record(tr, at, i, d, env.sample(v.0, v.1), pmf);
            }
            Chosen::Point(..) => {}
        }
    }

    /// Lane `i`'s light sample `ls` (none if the light gave none), chosen with probability
    /// `pmf`: its shadow ray, direction, radiance and density (`light_ray`) in the columns.
    #[inline(always)]
    fn record<L>(
        &mut self,
        tr: &Tracer,
        at: &Vertices<L>,
        i: usize,
        d: Vec3A,
        ls: Option<LightSample>,
        pmf: f32,
    ) {
        self.lanes |= 1 << i;
        let (Some(hit), Some((m, phong)), Some(ls)) = (&at.hits[i], &at.materials[i], ls) else {
            // (A shaded lane has a hit, and a material where the scene has area lights or an
            // environment, the only scenes that sample here: `round_in` sets them with its bit.)
            return;
        };
        let si = Interaction::flat(*hit, d, &tr.materials[*m as usize]);
        let Some((r, pdf)) = light_ray(&si, phong, &ls, pmf) else {
            return;
        };
        let c = self.columns.get_or_insert_with(Default::default);
        for x in 0..3 {
            c.ray[x][i] = r.o[x];
            c.ray[3 + x][i] = r.d[x];
            c.le[x][i] = ls.le[x];
        }
        (c.ray[6][i], c.ray[7][i], c.pdf[i]) = (r.o_err, r.t_max, pdf);
        self.tested |= 1 << i;
    }

    /// The samples of the lanes of `on` (none may have chosen a triangle) from the points
    /// `p` of `at` with the numbers `u` ([`TrianglePoints::sample`]): what [`AreaRays::record`]
    /// records for each, computed in lanes (`light_ray` at `Interaction::flat`: no radiance, a
    /// direction not above the shading normal or a density not positive leave no shadow ray;
    /// the ray leaves from the origin on the side of the geometric normal it goes to and stops
    /// at `SHADOW_END` of the distance).
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn record_triangles<L: Floats>(
        &mut self,
        at: &Surface<L>,
        on: &TrianglePoints,
        p: [L; 3],
        (u1, u2): (&[f32; MAX_LANES], &[f32; MAX_LANES]),
    ) {
        if on.lanes == 0 {
            return;
        }
        self.lanes |= on.lanes;
        // SAFETY: the caller's; so for every `unsafe` block below, each makes values of `L`.
        let s = unsafe { on.sample::<L>(p, u1, u2) };
        let (zero, end) = unsafe { (L::splat(0.0), L::splat(SHADOW_END)) };
        // `light_ray`'s tests: some radiance (`le != 0`), `wi` not below the shading normal
        // (a Phong surface transmits nothing; a flat hit's normal is not bent, so nothing
        // leaks), and `pmf pdf` neither NaN nor at most zero.
        let lit = s.le[0].cmpne(zero) | s.le[1].cmpne(zero) | s.le[2].cmpne(zero);
        let below = dot(s.wi, at.n).cmple(zero);
        let pdf = unsafe { L::from_slice(&on.pmf) } * s.pdf;
        let ray = s.valid & lit & !below & pdf.cmpgt(zero);
        let tested = L::bitmask(ray);
        if tested == 0 {
            return;
        }
        // `Origins::ray`: the origin on the side of the geometric normal `wi` leaves by.
        let side = dot(at.nh, s.wi).cmpge(zero);
        let o = [
            L::select(side, at.front[0], at.back[0]),
            L::select(side, at.front[1], at.back[1]),
            L::select(side, at.front[2], at.back[2]),
        ];
        let c = self.columns.get_or_insert_with(Default::default);
        // SAFETY: as above, for each `blend_into`.
        unsafe {
            for (x, o) in o.into_iter().enumerate() {
                blend_into(&mut c.ray[x], o, ray);
                blend_into(&mut c.ray[3 + x], s.wi[x], ray);
                blend_into(&mut c.le[x], s.le[x], ray);
            }
            blend_into(&mut c.ray[6], at.o_err, ray);
            blend_into(&mut c.ray[7], s.dist * end, ray);
            blend_into(&mut c.pdf, pdf, ray);
        }
        self.tested |= tested;
    }

    /// The samples' terms `L_e r V w / (pmf pdf)` at the vertices of `at` (`light_term`: the
    /// shadow rays tested in lanes, then each visible sample weighted, `light_weighted`, in
    /// lanes too), zero in the lanes without a sample. With `summed`, each term as
    /// `area_lights` returns it for one sample: added to zero and divided by one.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn terms<L: Floats>(
        &self,
        tr: &mut Tracer,
        at: &Surface<L>,
        mis: Option<Sampling>,
        summed: bool,
    ) -> [L; 3] {
        // SAFETY: the caller's; so for every `unsafe` block below, each makes values of `L`.
        let (zero, one) = unsafe { (L::splat(0.0), L::splat(1.0)) };
        // (Without a column, no lane has a shadow ray to test, `tested` is empty: each term
        // is zero, summed or not.)
        let Some(c) = self.columns.as_ref().filter(|_| self.lanes != 0) else {
            return [zero; 3];
        };
        // The shadow rays, in lanes; their directions are the samples' `wi`.
        let [ox, oy, oz, dx, dy, dz, o_err, t_max] = unsafe { rows::<L, 8>(&c.ray) };
        let wi = [dx, dy, dz];
        let mut blocked = 0u32;
        if tr.effects.shadows && self.tested != 0 {
            let segments = ([ox, oy, oz], wi, o_err, t_max);
            let live = unsafe { lane_mask::<L>(self.tested) };
            let hidden = tr
                .geometry
                .occluded_lanes(segments, true, live, &tr.traversal);
            blocked = L::bitmask(hidden);
            tr.count_shadow_lanes(segments, self.tested);
        }
        // The visible samples' terms, `light_weighted`: `L_e r(wi, wo) w / pdf` with
        // `r = f max(cos, 0)` (the diffuse BRDF, or the course's reflectance; zero where `wi`
        // or, under the Physical model, `wo` is below) and `w` the power heuristic against the
        // BRDF-sampled direction's density under MIS (else 1). The pdf holds the light's
        // chance.
        let seen = unsafe { lane_mask::<L>(self.tested & !blocked) };
        let (le, pdf) = unsafe { (rows::<L, 3>(&c.le), L::from_slice(&c.pdf)) };
        let cos = dot(wi, at.n);
        let above = cos.cmpgt(zero) & at.wo_above;
        let r = [
            L::select(above, at.f[0], zero) * cos.max(zero),
            L::select(above, at.f[1], zero) * cos.max(zero),
            L::select(above, at.f[2], zero) * cos.max(zero),
        ];
        let w = match mis {
            Some(sampling) => unsafe { power_heuristic(pdf, brdf_pdf(cos, sampling)) },
            None => one,
        };
        let k = w / pdf;
        let mut term = [
            L::select(seen, le[0] * r[0] * k, zero),
            L::select(seen, le[1] * r[1] * k, zero),
            L::select(seen, le[2] * r[2] * k, zero),
        ];
        if summed {
            term = [
                (zero + term[0]) / one,
                (zero + term[1]) / one,
                (zero + term[2]) / one,
            ];
        }
        term
    }
}

/// Write `x` into the lanes of `row` that `mask` holds, keeping the others.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn blend_into<L: Floats>(row: &mut [f32; MAX_LANES], x: L, mask: L::Mask) {
    // SAFETY: the caller's.
    L::select(mask, x, unsafe { L::from_slice(row) }).write_to(row);
}

/// `brdf_pdf` of a diffuse surface (every lane's material reflects diffusely only) in lanes,
/// from the cosines `cos` of the directions with the shading normal: zero below the surface.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn brdf_pdf<L: Floats>(cos: L, sampling: Sampling) -> L {
    // SAFETY: the caller's.
    let zero = unsafe { L::splat(0.0) };
    let pdf = match sampling {
        Sampling::Uniform => unsafe { L::splat(crate::sampling::hemisphere::UNIFORM_PDF) },
        // `cosine_pdf`.
        Sampling::Cosine => cos.max(zero) * unsafe { L::splat(FRAC_1_PI) },
        // The diffuse lobe's share is one.
        Sampling::Brdf => cos / unsafe { L::splat(PI) },
    };
    L::select(cos.cmple(zero), zero, pdf)
}

/// `sampling::power_heuristic` in lanes: `pdf^2 / (pdf^2 + other^2)`, scaled by the larger
/// (`f32::max`: the other where one is NaN), one where `pdf` is infinite, zero where the larger
/// is not positive or is infinite.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn power_heuristic<L: Floats>(pdf: L, other: L) -> L {
    // SAFETY: the caller's.
    let (zero, one, inf) = unsafe { (L::splat(0.0), L::splat(1.0), L::splat(f32::INFINITY)) };
    let (pdf_nan, other_nan) = (pdf.cmpne(pdf), other.cmpne(other));
    let m = L::select(pdf_nan, other, L::select(other_nan, pdf, pdf.max(other)));
    let (a, b) = ((pdf / m) * (pdf / m), (other / m) * (other / m));
    let w = L::select(m.cmple(zero) | !m.abs().cmpne(inf), zero, a / (a + b));
    L::select(!pdf.abs().cmpne(inf), one, w)
}

/// The triangle and light of `chosen`, and its chance, if it is an untextured triangle light
/// (sampled in lanes, [`TrianglePoints`]).
#[inline(always)]
fn untextured_triangle<'a>(chosen: &Chosen<'a>) -> Option<(&'a Triangle, &'a AreaLight, f32)> {
    match chosen {
        Chosen::Area(light, pmf) => match &light.shape {
            Emitting::Triangle(t) if light.texture.is_none() => Some((t, *light, *pmf)),
            _ => None,
        },
        Chosen::Environment(..) | Chosen::Point(..) => None,
    }
}

/// The lanes' triangle lights, a column per coordinate, to sample a point on each in lanes
/// (`AreaLight::sample` of an untextured triangle).
#[derive(Default)]
struct TrianglePoints {
    /// Lanes (bits) that chose one.
    lanes: u32,
    /// `v[3 j + axis]`: coordinate `axis` of vertex `j`.
    v: [[f32; MAX_LANES]; 9],
    /// Unit normal.
    n: [[f32; MAX_LANES]; 3],
    /// Radiance.
    radiance: [[f32; MAX_LANES]; 3],
    /// Area.
    area: [f32; MAX_LANES],
    /// Lanes (bits) whose light emits from both sides.
    two_sided: u32,
    /// The chance of each lane's light.
    pmf: [f32; MAX_LANES],
}

/// [`TrianglePoints::sample`]'s samples in lanes: what `AreaLight::sample` returns, in the
/// lanes of `valid`.
struct TriangleSamples<L: Floats> {
    wi: [L; 3],
    dist: L,
    le: [L; 3],
    pdf: L,
    /// Lanes with a sample (a point apart from the vertex, of some density) among those that
    /// chose a triangle.
    valid: L::Mask,
}

impl TrianglePoints {
    /// Lane `i` samples triangle `t` of `light`, chosen with chance `pmf`.
    #[inline(always)]
    fn put(&mut self, i: usize, t: &Triangle, light: &AreaLight, pmf: f32) {
        self.lanes |= 1 << i;
        for j in 0..3 {
            for axis in 0..3 {
                self.v[3 * j + axis][i] = t.v[j][axis];
            }
        }
        for axis in 0..3 {
            self.n[axis][i] = t.n[axis];
            self.radiance[axis][i] = light.emitter.radiance[axis];
        }
        self.area[i] = light.area();
        self.two_sided |= u32::from(light.emitter.two_sided) << i;
        self.pmf[i] = pmf;
    }

    /// Each lane's sample from the point `p` with the numbers `u1`, `u2`, as
    /// `AreaLight::sample` computes it for a triangle: a uniform point (`uniform_triangle`),
    /// the unit direction and distance to it, the density per solid angle
    /// (`area_to_solid_angle`: `d^2 / (A |cos|)`, where positive and finite), and the radiance
    /// towards `p` (zero from a one-sided light's back).
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn sample<L: Floats>(
        &self,
        p: [L; 3],
        u1: &[f32; MAX_LANES],
        u2: &[f32; MAX_LANES],
    ) -> TriangleSamples<L> {
        // SAFETY: the caller's; so for every `unsafe` block below, each makes values of `L`.
        let (zero, one, two) = unsafe { (L::splat(0.0), L::splat(1.0), L::splat(2.0)) };
        let load = |row: &[f32; MAX_LANES]| unsafe { L::from_slice(row) };
        let (u1, u2) = (load(u1), load(u2));
        // `uniform_triangle` (Heitz 2019): the barycentrics.
        let (h1, h2) = (u1 / two, u2 / two);
        let lower = u1.cmplt(u2);
        let b0 = L::select(lower, h1, u1 - h2);
        let b1 = L::select(lower, u2 - h1, h2);
        let b2 = (one - b0 - b1).max(zero);
        // The point, `b0 v0 + b1 v1 + b2 v2`, and the direction towards it.
        let v: [L; 9] = unsafe { rows(&self.v) };
        let q = [
            b0 * v[0] + b1 * v[3] + b2 * v[6],
            b0 * v[1] + b1 * v[4] + b2 * v[7],
            b0 * v[2] + b1 * v[5] + b2 * v[8],
        ];
        let to = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let d2 = dot(to, to);
        let dist = d2.sqrt();
        let wi = [to[0] / dist, to[1] / dist, to[2] / dist];
        // `area_to_solid_angle`.
        let nq: [L; 3] = unsafe { rows(&self.n) };
        let cos_q = dot(nq, wi).abs();
        let pdf = d2 / (load(&self.area) * cos_q);
        let inf = unsafe { L::splat(f32::INFINITY) };
        let finite = d2.abs().cmplt(inf) & pdf.abs().cmplt(inf);
        let valid = d2.cmpne(zero) & cos_q.cmpgt(zero) & finite & pdf.cmpgt(zero);
        // `emitted`: towards `-wi`, from the front or from both sides.
        let front = dot(nq, [-wi[0], -wi[1], -wi[2]]).cmpgt(zero);
        let lit = unsafe { lane_mask::<L>(self.two_sided) } | front;
        let radiance: [L; 3] = unsafe { rows(&self.radiance) };
        let le = [
            L::select(lit, radiance[0], zero),
            L::select(lit, radiance[1], zero),
            L::select(lit, radiance[2], zero),
        ];
        TriangleSamples {
            wi,
            dist,
            le,
            pdf,
            valid: valid & unsafe { lane_mask::<L>(self.lanes) },
        }
    }
}

/// The numbers `one_light` and `area_lights` draw for a light sample, in lanes: `u` (53 bits)
/// chooses the light, `u1` and `u2` a point on an area light.
#[inline(always)]
fn light_numbers<S: Streams>(
    rng: &mut S,
    lanes: usize,
) -> ([f64; MAX_LANES], [f32; MAX_LANES], [f32; MAX_LANES]) {
    let u = rng.next_f64(lanes);
    let (u1, u2) = rng.next_2d(lanes);
    (u, u1, u2)
}

/// The most lights [`choice_places`] counts through; past them, a binary search per lane.
const COUNTED_LIGHTS: usize = 32;

/// Each lane's place in the light choice for its number `u` (`Emitters::choose_any`'s
/// `partition_point`, the same index): for a few lights, the count of the cumulative shares
/// `cdf` at or below it (they do not decrease), without the binary search's branches, in
/// lanes (the loops vectorise); for more, the binary search in each of the first `lanes`.
#[inline(always)]
fn choice_places(cdf: &[f64], u: &[f64; MAX_LANES], lanes: usize) -> [u32; MAX_LANES] {
    let mut place = [0u32; MAX_LANES];
    if cdf.len() > COUNTED_LIGHTS {
        for (p, &u) in place.iter_mut().zip(u).take(lanes) {
            *p = cdf.partition_point(|&c| c <= u) as u32;
        }
        return place;
    }
    for &c in cdf {
        for (p, &u) in place.iter_mut().zip(u) {
            *p += u32::from(c <= u);
        }
    }
    place
}

/// The set bits of a lane mask, lowest first.
struct Bits(u32);

impl Iterator for Bits {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        (self.0 != 0).then(|| {
            let i = self.0.trailing_zeros() as usize;
            self.0 &= self.0 - 1;
            i
        })
    }
}

/// What the light terms read of a chunk's vertices: the geometric and shading
/// normals, the two origins and their error bound, the reflectance's factor `f` (the BRDF
/// `kd / pi` under the Physical model, the course's `kd`), the lanes where `wo` counts as
/// above the surface (all of them under the Course model), and the lanes shaded.
struct Surface<L: Floats> {
    nh: [L; 3],
    n: [L; 3],
    front: [L; 3],
    back: [L; 3],
    o_err: L,
    f: [L; 3],
    wo_above: L::Mask,
    live: L::Mask,
}

/// A point light per lane (the same in every lane for `point_lights`): position, intensity,
/// the lanes where it is in the planes' room, and the lanes that have one.
struct LightLanes<L> {
    pos: [L; 3],
    intensity: [L; 3],
    room: u32,
    lanes: u32,
}

impl<L: Floats> LightLanes<L> {
    /// `PointLight::incident` in lanes at the points `p`: the unit direction, the distance and
    /// `I / d^2`, where the light is not at the point (`d^2` neither zero nor infinite).
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn incident(&self, p: [L; 3]) -> Incidents<L> {
        // SAFETY: the caller's.
        let (zero, inf) = unsafe { (L::splat(0.0), L::splat(f32::INFINITY)) };
        let to = [self.pos[0] - p[0], self.pos[1] - p[1], self.pos[2] - p[2]];
        let d2 = dot(to, to);
        let dist = d2.sqrt();
        Incidents {
            wi: [to[0] / dist, to[1] / dist, to[2] / dist],
            dist,
            li: [
                self.intensity[0] / d2,
                self.intensity[1] / d2,
                self.intensity[2] / d2,
            ],
            valid: unsafe { lane_mask::<L>(self.lanes) } & d2.cmpne(zero) & d2.cmplt(inf),
            room: self.room,
        }
    }
}

/// The light arriving at each lane's vertex from its light (`Light::incident`): the unit
/// direction towards it, the distance, the radiance `L_i`, the lanes that receive some, and
/// the lanes whose light is in the planes' room.
struct Incidents<L: Floats> {
    wi: [L; 3],
    dist: L,
    li: [L; 3],
    valid: L::Mask,
    room: u32,
}

/// `Light::incident` lane by lane, for the lights without a lane form (spot and directional):
/// lane `i` of `lanes` from light `light_of(i)` at the point `p[..][i]`.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn incidents_by_lane<'a, L: Floats>(
    light_of: impl Fn(usize) -> &'a Light,
    p: &[[f32; MAX_LANES]; 3],
    lanes: u32,
) -> Incidents<L> {
    let (mut wi, mut li) = ([[0.0f32; MAX_LANES]; 3], [[0.0f32; MAX_LANES]; 3]);
    let (mut dist, mut valid, mut room) = ([0.0f32; MAX_LANES], 0u32, 0u32);
    for i in Bits(lanes) {
        let light = light_of(i);
        let Some(inc) = light.incident(Vec3A::new(p[0][i], p[1][i], p[2][i])) else {
            continue;
        };
        for c in 0..3 {
            wi[c][i] = inc.wi[c];
            li[c][i] = inc.li[c];
        }
        dist[i] = inc.dist;
        valid |= 1 << i;
        room |= u32::from(light.in_room()) << i;
    }
    // SAFETY: the caller's.
    unsafe {
        Incidents {
            wi: [
                L::from_array(wi[0]),
                L::from_array(wi[1]),
                L::from_array(wi[2]),
            ],
            dist: L::from_array(dist),
            li: [
                L::from_array(li[0]),
                L::from_array(li[1]),
                L::from_array(li[2]),
            ],
            valid: lane_mask::<L>(valid),
            room,
        }
    }
}

/// `point_light` in lanes: each lane's light's term `L_i r(wi, wo) V` at its vertex from its
/// incident light `inc` (zero where the light is behind the surface, gives none, or is
/// hidden), its shadow ray tested in lanes (`Tracer::unoccluded`, or `unoccluded_in_room` in
/// the lanes of `inc.room`) and counted.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn light_term<L: Floats>(tr: &mut Tracer, inc: &Incidents<L>, at: &Surface<L>) -> [L; 3] {
    // SAFETY: the caller's.
    let (zero, end) = unsafe { (L::splat(0.0), L::splat(SHADOW_END)) };
    let (nh, n, front, back, o_err, f) = (at.nh, at.n, at.front, at.back, at.o_err, at.f);
    let (wi, dist, li) = (inc.wi, inc.dist, inc.li);
    // `point_light_ray`: a light below the surface adds nothing.
    let cos = dot(wi, n);
    let lit = at.live & inc.valid & cos.cmpgt(zero);
    let mut seen = lit;
    if tr.effects.shadows && L::any(lit) {
        let side = dot(nh, wi).cmpge(zero);
        let o = [
            L::select(side, front[0], back[0]),
            L::select(side, front[1], back[1]),
            L::select(side, front[2], back[2]),
        ];
        let t_max = dist * end;
        let room = unsafe { lane_mask::<L>(inc.room) };
        let geometry: &Geometry = tr.geometry;
        let mut blocked = zero.cmpne(zero);
        for (planes, part) in [(false, lit & room), (true, lit & !room)] {
            if L::any(part) {
                blocked = blocked
                    | geometry.occluded_lanes((o, wi, o_err, t_max), planes, part, &tr.traversal);
            }
        }
        seen = lit & !blocked;
        tr.count_shadow_lanes((o, wi, o_err, t_max), L::bitmask(lit));
    }
    // `L_i r(wi, wo)` with `r = f max(cos, 0)` (the BRDF, or the course's reflectance; zero
    // where `wo` is below under the Physical model), where the light is seen.
    let r = [
        L::select(at.wo_above, f[0], zero) * cos.max(zero),
        L::select(at.wo_above, f[1], zero) * cos.max(zero),
        L::select(at.wo_above, f[2], zero) * cos.max(zero),
    ];
    [
        L::select(seen, li[0] * r[0], zero),
        L::select(seen, li[1] * r[1], zero),
        L::select(seen, li[2] * r[2], zero),
    ]
}

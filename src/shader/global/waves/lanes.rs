//! One batch of a wave traced and shaded in SIMD lanes, for scenes whose primitives are all
//! packed (no BVH): a ray per lane from the nearest hit to its children. The nearest hits come
//! with their records in lanes ([`crate::accel::Geometry::nearest_lanes`], which
//! `intersect_batch` runs too); the interaction (orientation, the origins and their error
//! bound) and the light pass ([`super::point_sums`]) run in lanes with no gathering, and the
//! two rays of task 2 are spawned in lanes. Scalar, lane by lane: the
//! tree's bookkeeping, the mirror and glass bounces, the light emitted by a surface a chain
//! meets, and every reflectance but the course's diffuse one (a specular lobe, the Physical
//! model), in the light terms and the children's weights. Every lane computes what the scalar
//! code computes for its ray, operation for operation (`Geometry::intersect`'s order and tie
//! rule, `Sphere::surface`, `Plane::surface`, `Interaction::new`, `Origins`, `reflect`,
//! `course_reflectance`), so the result is the depth-first walk's to the bit.

use super::{LightLanes, Node, Scratch, point_sums};
use crate::accel::lanes::{RayLanes, abs_max, dot};
use crate::accel::{Floats, Isa};
use crate::geometry::{Hit, Origins, Ray, UNIT_ROUNDOFF};
use crate::light::NO_LIGHT;
use crate::material::{Material, Model, Phong};
use crate::shader::Tracer;
use crate::shader::global::Global;
use crate::shader::surface::{Interaction, emitted, reflectance};
use crate::stats::RayKind;
use glam::Vec3A;
use std::f32::consts::PI;

/// Rows of a chunk's lane arrays: hit point, geometric normal, shading normal (the geometric
/// one on the viewer's side), front and back origins (three each), then the origins' error,
/// the distance, the hit's two error bounds, and the slot of the primitive hit.
const P: usize = 0;
const NH: usize = 3;
const NS: usize = 6;
const FRONT: usize = 9;
const BACK: usize = 12;
const O_ERR: usize = 15;
const T: usize = 16;
const ERR: usize = 17;
const ERR_ALONG: usize = 18;
const SLOT: usize = 19;
const ROWS: usize = 20;

/// Trace and shade `s.now` in lanes into `s.bounced`, `s.children` and the nodes: what
/// `trace_tree`'s batch and `shade` do for a scene without a BVH, then its Phong hits' light
/// pass and what `finish_direct_light` adds (each node's `rest`), so that it queues nothing
/// for [`super::light_sums`] (`s.ends`) or `finish_direct_light` (`s.lit`).
pub fn wave(tr: &mut Tracer, g: &Global, s: &mut Scratch, depth: u32) {
    match tr.geometry.bvh.isa() {
        // SAFETY: the BVH's instruction set is one the CPU runs (`WideBvh::set_isa`).
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { wave_avx2(tr, g, s, depth) },
        // SAFETY: `Vec4` runs on every CPU.
        _ => unsafe { wave_in::<glam::Vec4>(tr, g, s, depth) },
    }
}

/// [`wave`] in eight AVX2 lanes.
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn wave_avx2(tr: &mut Tracer, g: &Global, s: &mut Scratch, depth: u32) {
    // SAFETY: this function runs only where AVX2 was found.
    unsafe { wave_in::<crate::accel::F8>(tr, g, s, depth) }
}

/// The lanes of a vector as an array.
#[inline(always)]
fn array<L: Floats>(x: L) -> [f32; 8] {
    let mut a = [0.0f32; 8];
    x.write_to(&mut a);
    a
}

/// [`wave`], `L::LANES` rays at a time. No closures that compute in lanes, so that this
/// inlines whole into the AVX2 copy.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
unsafe fn wave_in<L: Floats>(tr: &mut Tracer, g: &Global, s: &mut Scratch, depth: u32) {
    let geometry = tr.geometry;
    // SAFETY: the caller vouches for the instruction set.
    let (zero, two) = unsafe { (L::splat(0.0), L::splat(2.0)) };
    // SAFETY: as above; so for every `unsafe` block below, each makes values of `L`.
    let (unit, two_unit) = unsafe { (L::splat(UNIT_ROUNDOFF), L::splat(2.0 * UNIT_ROUNDOFF)) };
    let end = depth >= g.max_depth || !tr.effects.indirect;
    s.bounced.clear();
    let n_rays = s.now.rays.len();
    for k in (0..n_rays).step_by(L::LANES) {
        let count = (n_rays - k).min(L::LANES);
        let last = n_rays - 1;
        let mut eight = [&s.now.rays[last]; 8];
        for (i, r) in eight.iter_mut().enumerate().take(L::LANES) {
            *r = &s.now.rays[(k + i).min(last)];
        }
        let lanes = unsafe { RayLanes::<L>::gather(&eight) };
        let t_max = unsafe { L::from_array8(eight.map(|r| r.t_max)) };
        // The nearest hits and their records, in the lanes.
        let near = unsafe { geometry.nearest_lanes(&lanes, t_max) };
        let (hit, t_max, slot) = (near.hit, near.t, near.slot);
        // `Interaction::new`: the normal on the viewer's side (a flat shape's shading normal),
        // and `Origins::new`: the point moved off the surface by its error's projection on
        // the normal, to either side, with the origins' error bound.
        let d = lanes.d();
        let wo = [-d[0], -d[1], -d[2]];
        let (p, nh) = (hit.p, hit.n);
        let flip = dot(nh, wo).cmplt(zero);
        let ns = [
            L::select(flip, -nh[0], nh[0]),
            L::select(flip, -nh[1], nh[1]),
            L::select(flip, -nh[2], nh[2]),
        ];
        let n_sum = (nh[0].abs() + nh[1].abs()) + nh[2].abs();
        let off = n_sum * hit.err + two_unit * abs_max(p);
        let front = [p[0] + off * nh[0], p[1] + off * nh[1], p[2] + off * nh[2]];
        let back = [p[0] - off * nh[0], p[1] - off * nh[1], p[2] - off * nh[2]];
        let widest = [
            front[0].abs().max(back[0].abs()),
            front[1].abs().max(back[1].abs()),
            front[2].abs().max(back[2].abs()),
        ];
        let o_err = hit.err + off + two * hit.err_along + unit * abs_max(widest);
        let mut v = [[0.0f32; 8]; ROWS];
        for (row, x) in [
            p[0],
            p[1],
            p[2],
            nh[0],
            nh[1],
            nh[2],
            ns[0],
            ns[1],
            ns[2],
            front[0],
            front[1],
            front[2],
            back[0],
            back[1],
            back[2],
            o_err,
            t_max,
            hit.err,
            hit.err_along,
            slot,
        ]
        .into_iter()
        .enumerate()
        {
            x.write_to(&mut v[row]);
        }
        let vec3 = |row: usize, i: usize| Vec3A::new(v[row][i], v[row + 1][i], v[row + 2][i]);
        // The tree's bookkeeping, lane by lane (`shade`).
        let (mut phong_lanes, mut lit_lanes) = (0u32, 0u32);
        let (mut lambert, mut parents) = (0u32, 0u32);
        let mut kd = [[0.0f32; 8]; 3];
        let mut beta_lanes = [[0.0f32; 8]; 3];
        let mut phong_of: [Option<Phong>; 8] = [None; 8];
        for i in 0..count {
            let node_i = s.now.nodes[k + i];
            let Some(prim) = geometry.slot_prim(v[SLOT][i].to_bits()) else {
                let node = &mut s.nodes[node_i as usize];
                node.rest = Some(node.beta * node.tint * tr.background);
                continue;
            };
            let (material, light) = {
                let p = geometry.prim(prim);
                (tr.materials[p.material as usize], p.light)
            };
            // The whole interaction, for the rare lanes that need it.
            let si = || Interaction {
                hit: Hit {
                    t: v[T][i],
                    p: vec3(P, i),
                    n: vec3(NH, i),
                    err: v[ERR][i],
                    err_along: v[ERR_ALONG][i],
                    prim,
                },
                wo: -s.now.rays[k + i].d,
                n: vec3(NS, i),
                material,
                origins: Origins {
                    front: vec3(FRONT, i),
                    back: vec3(BACK, i),
                    n: vec3(NH, i),
                    o_err: v[O_ERR][i],
                },
                light,
            };
            let node = &mut s.nodes[node_i as usize];
            // The emitter a node's own ray hits is the direct light of the hit it left.
            if node.bounces > 0 {
                let le = if light == NO_LIGHT || !tr.effects.emission {
                    Vec3A::ZERO
                } else {
                    emitted(tr, &si())
                };
                node.le += node.tint * le;
            }
            let Material::Phong(phong) = material else {
                if node.bounces < g.max_specular {
                    node.bounce(node_i, &si(), tr, &mut s.bounced);
                }
                continue;
            };
            let beta = node.beta * node.tint;
            let diffuse = tr.model == Model::Course && phong.ks == Vec3A::ZERO;
            // Eq. 3 in the chunk's light pass below. A surface that reflects nothing has no
            // light terms (`point_lights`).
            (kd[0][i], kd[1][i], kd[2][i]) = (phong.kd.x, phong.kd.y, phong.kd.z);
            phong_lanes |= 1 << i;
            lit_lanes |= u32::from(!phong.is_black()) << i;
            lambert |= u32::from(diffuse) << i;
            if !diffuse {
                phong_of[i] = Some(phong);
            }
            (beta_lanes[0][i], beta_lanes[1][i], beta_lanes[2][i]) = (beta.x, beta.y, beta.z);
            parents |= u32::from(!end) << i;
        }
        // Eq. 3: the point lights' sums of the chunk's Phong hits (zero where a surface
        // reflects nothing).
        let mut point = [[0.0f32; 8]; 3];
        if lit_lanes != 0 {
            let mut filled = [0.0f32; 8];
            for (i, f) in filled.iter_mut().enumerate() {
                *f = if lit_lanes & (1 << i) != 0 { 1.0 } else { 0.0 };
            }
            let h = unsafe {
                LightLanes {
                    p,
                    n: ns,
                    ng: nh,
                    front,
                    back,
                    kd: [
                        L::from_array8(kd[0]),
                        L::from_array8(kd[1]),
                        L::from_array8(kd[2]),
                    ],
                    o_err,
                    filled: L::from_array8(filled).cmpne(zero),
                    scalar: lit_lanes & !lambert,
                }
            };
            let model = tr.model;
            let rays = &s.now.rays[k..];
            point = unsafe {
                point_sums(tr, &h, |i, w, l| {
                    let phong = phong_of[i].expect("a scalar lane's material");
                    l * reflectance(model, &phong, w, -rays[i].d, vec3(NS, i))
                })
            };
        }
        let (kd, beta) = unsafe {
            (
                [
                    L::from_array8(kd[0]),
                    L::from_array8(kd[1]),
                    L::from_array8(kd[2]),
                ],
                [
                    L::from_array8(beta_lanes[0]),
                    L::from_array8(beta_lanes[1]),
                    L::from_array8(beta_lanes[2]),
                ],
            )
        };
        // What each Phong node adds after `beta le` (`finish_direct_light`): `beta` times
        // Eq. 3 as `direct_light` sums it (the point lights' sum, then the area lights' zero),
        // plus the ambient term at depth D (Eq. 2).
        let mut rest = [[0.0f32; 8]; 3];
        for c in 0..3 {
            let l_dir = unsafe { L::from_array8(point[c]) } + zero;
            rest[c] = array(match end {
                true => beta[c] * (l_dir + unsafe { L::splat(g.ambient[c]) } * kd[c]),
                false => beta[c] * l_dir,
            });
        }
        let mut bits = phong_lanes;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let node = &mut s.nodes[s.now.nodes[k + i] as usize];
            node.rest = Some(Vec3A::new(rest[0][i], rest[1][i], rest[2][i]));
        }
        if parents == 0 {
            continue;
        }
        // Task 2: Eq. 4 with the directions fixed to the normal w_n and the reflection w_r of
        // `wo` (`reflect`: `2 (n.wo) n - wo`), weighted by 1 / (4 pi); each ray leaves from
        // the origin on its side.
        let two_cos = two * dot(ns, wo);
        let wr = [
            two_cos * ns[0] - wo[0],
            two_cos * ns[1] - wo[1],
            two_cos * ns[2] - wo[2],
        ];
        let four_pi = unsafe { L::splat(4.0 * PI) };
        let mut rows = [[[0.0f32; 8]; 3]; 6];
        for (c, w) in [ns, wr].into_iter().enumerate() {
            // `course_reflectance` of a diffuse material: `kd max(w.n, 0)`, `max` as a select.
            let cos = dot(w, ns);
            let cos = L::select(cos.cmpgt(zero), cos, zero);
            let side = dot(nh, w).cmpge(zero);
            for x in 0..3 {
                rows[3 * c][x] = array((beta[x] * (kd[x] * cos)) / four_pi);
                rows[3 * c + 1][x] = array(L::select(side, front[x], back[x]));
                rows[3 * c + 2][x] = array(w[x]);
            }
        }
        let mut bits = parents;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let node_i = s.now.nodes[k + i];
            let first = s.nodes.len() as u32;
            s.nodes[node_i as usize].children = Some(first);
            for c in 0..2 {
                let get = |r: usize| Vec3A::new(rows[r][0][i], rows[r][1][i], rows[r][2][i]);
                let w = get(3 * c + 2);
                let b = if lambert & (1 << i) != 0 {
                    get(3 * c)
                } else {
                    let beta = Vec3A::new(beta_lanes[0][i], beta_lanes[1][i], beta_lanes[2][i]);
                    let wo = -s.now.rays[k + i].d;
                    let phong = phong_of[i].expect("a scalar lane's material");
                    beta * reflectance(tr.model, &phong, w, wo, vec3(NS, i)) / (4.0 * PI)
                };
                s.nodes.push(Node::new(b));
                let ray = Ray {
                    o: get(3 * c + 1),
                    d: w,
                    t_max: f32::INFINITY,
                    o_err: v[O_ERR][i],
                };
                s.children.push(first + c as u32, ray);
                tr.stats.count(RayKind::Indirect);
            }
        }
    }
}

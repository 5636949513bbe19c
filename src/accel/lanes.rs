//! Primitives four to a packet in structure-of-arrays lanes, tested together with SSE
//! (`glam::Vec4`). Planes always live here; spheres too when a scene has few of them, where a
//! BVH costs more than it saves. The arithmetic is the scalar tests' (`shape::Sphere`,
//! `shape::Plane`), including their rule for a ray that starts on the surface, so a packet
//! finds the hits the scalar code would (`tests/integration/shapes.rs` checks that they agree).
//!
//! The same tests run the other way round: a ray per lane ([`RayLanes::gather`]) against one
//! primitive in all of them ([`SphereLanes::splat`]), as a batch of rays needs, four lanes in
//! SSE, eight in AVX2 or sixteen in AVX-512 (the tests are written once over the `Floats`
//! lane type). Each lane computes what the scalar test computes for its pair, so every layout
//! gives the same bits.

use super::simd::{Floats, MAX_LANES};
use crate::geometry::{Ray, UNIT_ROUNDOFF, gamma};
use crate::shape::{Plane, Sphere};
use glam::{BVec4A, Vec4};

/// A ray splatted across four lanes ([`RayLanes::new`]), or one ray per lane
/// ([`RayLanes::gather`]), in lanes of type `L`.
#[derive(Clone, Copy)]
pub struct RayLanes<L = Vec4> {
    o: [L; 3],
    d: [L; 3],
    /// The origin's share of a plane's band per unit of `sum |n_i|`:
    /// `gamma(4) max |o_i| + o_err`.
    plane_k: L,
    /// The error of `o` before the sphere's centre is subtracted: `o_err + gamma(1) max |o_i|`.
    sphere_k: L,
    /// `max |o_i|`, for the hit records' error along the surface.
    o_max: L,
}

impl RayLanes {
    /// Splat a ray's origin, direction and origin error.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let (o, d, a) = (ray.o, ray.d, ray.o.abs().max_element());
        RayLanes {
            o: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            d: [Vec4::splat(d.x), Vec4::splat(d.y), Vec4::splat(d.z)],
            plane_k: Vec4::splat(gamma(4) * a + ray.o_err),
            sphere_k: Vec4::splat(ray.o_err + gamma(1) * a),
            o_max: Vec4::splat(a),
        }
    }
}

impl<L: Floats> RayLanes<L> {
    /// `L::LANES` rays, one per lane (the first of `rays`), with each lane's constants as
    /// [`RayLanes::new`] computes them. (No closures that compute in lanes: this inlines into
    /// code compiled for `L`'s instruction set.)
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    pub unsafe fn gather(rays: &[&Ray; MAX_LANES]) -> Self {
        // SAFETY: the caller vouches for the instruction set.
        unsafe {
            let o = L::transpose3(&rays.map(|r| &r.o));
            let d = L::transpose3(&rays.map(|r| &r.d));
            RayLanes::from_parts(o, d, L::from_array(rays.map(|r| r.o_err)))
        }
    }

    /// Rays from origins `o` along `d` with origin errors `o_err`, one per lane, with each
    /// lane's constants as [`RayLanes::new`] computes them.
    #[inline(always)]
    pub fn from_parts(o: [L; 3], d: [L; 3], o_err: L) -> Self {
        let a = abs_max(o);
        // SAFETY: `o_err` is a value of `L`, so the CPU runs `L`'s instruction set.
        let (g4, g1) = unsafe { (L::splat(gamma(4)), L::splat(gamma(1))) };
        RayLanes {
            o,
            d,
            plane_k: g4 * a + o_err,
            sphere_k: o_err + g1 * a,
            o_max: a,
        }
    }
}

/// `max |v_i|` in glam's order (`Vec3A::max_element` of `abs`): max(max(x, z), max(y, z)).
#[inline(always)]
pub fn abs_max<L: Floats>(v: [L; 3]) -> L {
    let [x, y, z] = [v[0].abs(), v[1].abs(), v[2].abs()];
    x.max(z).max(y.max(z))
}

/// The lanes of a vector as an array.
#[inline(always)]
pub fn array<L: Floats>(x: L) -> [f32; MAX_LANES] {
    let mut a = [0.0f32; MAX_LANES];
    x.write_to(&mut a);
    a
}

/// Rows of lanes as vectors: `rows[k]`'s lanes in vector `k`.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
pub unsafe fn rows<L: Floats, const N: usize>(rows: &[[f32; MAX_LANES]; N]) -> [L; N] {
    // SAFETY: the caller's.
    std::array::from_fn(|k| unsafe { L::from_slice(&rows[k]) })
}

/// The lanes of the bits of `bits` as a mask.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
pub unsafe fn lane_mask<L: Floats>(bits: u32) -> L::Mask {
    let mut f = [0.0f32; MAX_LANES];
    for (i, x) in f.iter_mut().enumerate() {
        *x = if bits & (1 << i) != 0 { 1.0 } else { 0.0 };
    }
    // SAFETY: the caller's.
    unsafe { L::from_array(f) }.cmpne(unsafe { L::splat(0.0) })
}

/// Where rays leave the hits of the lanes, `crate::geometry::Origins::new` lane by lane: the
/// hit points `p` moved off their surfaces (unit geometric normals `n`) by the error bound
/// `err` projected on the normal, to the front and to the back, and the origins' error bound
/// (with the hits' error along the surface, `err_along`), each the scalar code's operations in
/// its order.
#[inline(always)]
pub fn origins<L: Floats>(p: [L; 3], n: [L; 3], err: L, err_along: L) -> ([L; 3], [L; 3], L) {
    // SAFETY: a value of `L` (`err`) exists, so the CPU runs its instruction set.
    let (two, unit, two_unit) = unsafe {
        (
            L::splat(2.0),
            L::splat(UNIT_ROUNDOFF),
            L::splat(2.0 * UNIT_ROUNDOFF),
        )
    };
    let n_sum = (n[0].abs() + n[1].abs()) + n[2].abs();
    let off = n_sum * err + two_unit * abs_max(p);
    let front = [p[0] + off * n[0], p[1] + off * n[1], p[2] + off * n[2]];
    let back = [p[0] - off * n[0], p[1] - off * n[1], p[2] - off * n[2]];
    let widest = [
        front[0].abs().max(back[0].abs()),
        front[1].abs().max(back[1].abs()),
        front[2].abs().max(back[2].abs()),
    ];
    (
        front,
        back,
        err + off + two * err_along + unit * abs_max(widest),
    )
}

/// Hit records of a ray per lane, each as its shape's `surface` computes it
/// ([`Sphere::surface`], [`Plane::surface`]): a [`crate::geometry::Hit`]'s point, normal and
/// error bounds.
#[derive(Clone, Copy)]
pub struct SurfaceLanes<L> {
    /// Hit points.
    pub p: [L; 3],
    /// Unit geometric normals, as the shapes define them.
    pub n: [L; 3],
    /// Bounds on the points' error across the surface.
    pub err: L,
    /// Bounds on the points' error along the surface.
    pub err_along: L,
}

/// `o + t d` lane by lane ([`crate::geometry::Ray::at`]).
#[inline(always)]
fn at<L: Floats>(r: &RayLanes<L>, t: L) -> [L; 3] {
    [
        r.o[0] + t * r.d[0],
        r.o[1] + t * r.d[1],
        r.o[2] + t * r.d[2],
    ]
}

/// The hit records of the rays of `r` at distances `t` on spheres of centres `c` and radii
/// `radius`, one per lane: [`Sphere::surface`]'s operations in its order.
#[inline(always)]
pub fn sphere_surface<L: Floats>(c: [L; 3], radius: L, r: &RayLanes<L>, t: L) -> SurfaceLanes<L> {
    // SAFETY: `t` is a value of `L`, so the CPU runs `L`'s instruction set.
    let (two, g3, g5, g6) = unsafe {
        (
            L::splat(2.0),
            L::splat(gamma(3)),
            L::splat(gamma(5)),
            L::splat(gamma(6)),
        )
    };
    // The normal through the computed point (`normalize`: a division by the length), and the
    // point put back on the sphere along it.
    let x = at(r, t);
    let v = [x[0] - c[0], x[1] - c[1], x[2] - c[2]];
    let len = dot(v, v).sqrt();
    let n = [v[0] / len, v[1] / len, v[2] / len];
    let p = [
        c[0] + radius * n[0],
        c[1] + radius * n[1],
        c[2] + radius * n[2],
    ];
    // The error along the ray: the root's error over the rate the ray crosses the sphere, at
    // most a diameter.
    let f = [r.o[0] - c[0], r.o[1] - c[1], r.o[2] - c[2]];
    let ec = g5 * (dot(f, f) + radius * radius);
    let rate = two * radius * dot(n, r.d).abs();
    let dt = L::select(ec.cmplt(rate * two * radius), ec / rate, two * radius);
    SurfaceLanes {
        p,
        n,
        err: g6 * (abs_max(c) + radius),
        err_along: dt + g3 * (r.o_max + t.abs()),
    }
}

/// The hit records of the rays of `r` at distances `t` on planes of unit normals `n` and
/// offsets `dist`, one per lane: [`Plane::surface`]'s operations in its order.
#[inline(always)]
pub fn plane_surface<L: Floats>(n: [L; 3], dist: L, r: &RayLanes<L>, t: L) -> SurfaceLanes<L> {
    // SAFETY: `t` is a value of `L`, so the CPU runs `L`'s instruction set.
    let (g3, g4, g6) = unsafe { (L::splat(gamma(3)), L::splat(gamma(4)), L::splat(gamma(6))) };
    // The computed point projected onto the plane.
    let x = at(r, t);
    let s = dot(n, x) - dist;
    let p = [x[0] - s * n[0], x[1] - s * n[1], x[2] - s * n[2]];
    // The error along the ray: the plane equation's error over the rate the ray crosses it.
    let an = [n[0].abs(), n[1].abs(), n[2].abs()];
    let o_abs = [r.o[0].abs(), r.o[1].abs(), r.o[2].abs()];
    let dist_abs = dist.abs();
    let dt = g4 * (dot(an, o_abs) + dist_abs) / dot(n, r.d).abs();
    SurfaceLanes {
        p,
        n,
        err: g6 * (abs_max(p) + dist_abs),
        err_along: dt + g3 * (r.o_max + t.abs()),
    }
}

/// The dot product of two vectors held a coordinate per lane vector: `(x x' + y y') + z z'`
/// lane by lane, glam's `Vec3A::dot` order.
#[inline(always)]
pub fn dot<L: Floats>(a: [L; 3], b: [L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Up to four spheres in lanes of type `L`; unused lanes have `r2 = -1` and never hit. With
/// `L = f32`, one sphere, to be splatted ([`SphereLanes::splat`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct SphereLanes<L = Vec4> {
    c: [L; 3],
    r: L,
    r2: L,
    /// `1 / r` (0 in unused lanes).
    inv_r: L,
    /// `gamma(1) max |c_i|`: the rounding of `o - c` due to the centre.
    c_err: L,
}

/// Up to four planes in lanes of type `L`; unused lanes have a zero normal and never hit.
/// With `L = f32`, one plane, to be splatted ([`PlaneLanes::splat`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct PlaneLanes<L = Vec4> {
    n: [L; 3],
    dist: L,
    /// `sum |n_i|`.
    n_abs_sum: L,
    /// `gamma(4) |dist|`.
    dist_err: L,
    /// [`Plane::side`] (0 in unused lanes).
    side: L,
}

impl SphereLanes {
    /// Pack up to four spheres.
    pub fn pack(s: &[Sphere]) -> Self {
        let lane = |i: usize, f: fn(&Sphere) -> f32, pad: f32| s.get(i).map_or(pad, f);
        let v = |f: fn(&Sphere) -> f32, pad| {
            Vec4::new(
                lane(0, f, pad),
                lane(1, f, pad),
                lane(2, f, pad),
                lane(3, f, pad),
            )
        };
        SphereLanes {
            c: [v(|s| s.c.x, 0.0), v(|s| s.c.y, 0.0), v(|s| s.c.z, 0.0)],
            r: v(|s| s.r, 0.0),
            r2: v(|s| s.r * s.r, -1.0),
            inv_r: v(|s| 1.0 / s.r, 0.0),
            c_err: v(|s| gamma(1) * s.c.abs().max_element(), 0.0),
        }
    }

    /// Lane `i`'s sphere (an unused lane's padding, which never hits).
    pub fn lane(&self, i: usize) -> SphereLanes<f32> {
        SphereLanes {
            c: self.c.map(|v| v[i]),
            r: self.r[i],
            r2: self.r2[i],
            inv_r: self.inv_r[i],
            c_err: self.c_err[i],
        }
    }
}

impl SphereLanes<f32> {
    /// This sphere in every lane of `L`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    pub unsafe fn splat<L: Floats>(&self) -> SphereLanes<L> {
        // SAFETY: the caller vouches for the instruction set.
        unsafe {
            SphereLanes {
                c: [
                    L::splat(self.c[0]),
                    L::splat(self.c[1]),
                    L::splat(self.c[2]),
                ],
                r: L::splat(self.r),
                r2: L::splat(self.r2),
                inv_r: L::splat(self.inv_r),
                c_err: L::splat(self.c_err),
            }
        }
    }
}

impl<L: Floats> SphereLanes<L> {
    /// The centres and radii.
    #[inline(always)]
    pub fn center_radius(&self) -> ([L; 3], L) {
        (self.c, self.r)
    }

    /// Distances of each lane's hit in `(0, tm]`, and which lanes hit (the scalar
    /// [`Sphere::intersect`], a lane at a time).
    #[inline(always)]
    pub fn hit(&self, r: &RayLanes<L>, tm: L) -> (L, L::Mask) {
        // SAFETY: `tm` is a value of `L`, so the CPU runs `L`'s instruction set.
        let (zero, two, g5) = unsafe { (L::splat(0.0), L::splat(2.0), L::splat(gamma(5))) };
        let f = [r.o[0] - self.c[0], r.o[1] - self.c[1], r.o[2] - self.c[2]];
        let b = -dot(f, r.d);
        let l = [f[0] + b * r.d[0], f[1] + b * r.d[1], f[2] + b * r.d[2]];
        let disc = self.r2 - dot(l, l);
        // Most rays miss every sphere of a packet (a shadow ray in a room of a few spheres):
        // they skip the square root and division below, whose latency dominates the test.
        let real = disc.cmpge(zero);
        if !L::any(real) {
            return (zero, real);
        }
        let f2 = dot(f, f);
        let c = f2 - self.r2;
        let q = b + disc.sqrt().copysign(b);
        let a = c / q;
        let first = a.cmple(q);
        let t0 = L::select(first, a, q);
        let t1 = L::select(first, q, a);
        let ok0 = t0.cmpgt(zero) & t0.cmple(tm);
        let ok1 = t1.cmpgt(zero) & t1.cmple(tm);
        let mut t = L::select(ok0, t0, t1);
        let mut ok = ok0 | ok1;
        // The scalar test's band: an origin on the sphere only meets the root away from zero.
        let e_f = r.sphere_k + self.c_err;
        let band = g5 * (f2 + self.r2) + two * e_f * (f2 * self.inv_r + self.r);
        let on = c.abs().cmple(band);
        if L::any(on) {
            let t_min = band / (f2.sqrt() + self.r);
            let other = L::select(t0.abs().cmple(t1.abs()), t1, t0);
            let ok_on = other.cmpgt(t_min) & other.cmple(tm);
            t = L::select(on, other, t);
            ok = (on & ok_on) | (!on & ok);
        }
        (t, real & q.cmpne(zero) & ok)
    }
}

impl PlaneLanes {
    /// Pack up to four planes.
    pub fn pack(p: &[Plane]) -> Self {
        let lane = |i: usize, f: fn(&Plane) -> f32| p.get(i).map_or(0.0, f);
        let v = |f: fn(&Plane) -> f32| Vec4::new(lane(0, f), lane(1, f), lane(2, f), lane(3, f));
        PlaneLanes {
            n: [v(|p| p.n.x), v(|p| p.n.y), v(|p| p.n.z)],
            dist: v(|p| p.dist),
            n_abs_sum: v(|p| p.n.abs().element_sum()),
            dist_err: v(|p| gamma(4) * p.dist.abs()),
            side: v(|p| p.side),
        }
    }

    /// Lane `i`'s plane (an unused lane's padding, which never hits).
    pub fn lane(&self, i: usize) -> PlaneLanes<f32> {
        PlaneLanes {
            n: self.n.map(|v| v[i]),
            dist: self.dist[i],
            n_abs_sum: self.n_abs_sum[i],
            dist_err: self.dist_err[i],
            side: self.side[i],
        }
    }
}

impl PlaneLanes<f32> {
    /// This plane in every lane of `L`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    pub unsafe fn splat<L: Floats>(&self) -> PlaneLanes<L> {
        // SAFETY: the caller vouches for the instruction set.
        unsafe {
            PlaneLanes {
                n: [
                    L::splat(self.n[0]),
                    L::splat(self.n[1]),
                    L::splat(self.n[2]),
                ],
                dist: L::splat(self.dist),
                n_abs_sum: L::splat(self.n_abs_sum),
                dist_err: L::splat(self.dist_err),
                side: L::splat(self.side),
            }
        }
    }
}

impl<L: Floats> PlaneLanes<L> {
    /// The unit normals and offsets (`n.p = dist` on the plane).
    #[inline(always)]
    pub fn normal_dist(&self) -> ([L; 3], L) {
        (self.n, self.dist)
    }

    /// Distances of each lane's hit in `(0, t_max]`, and which lanes hit (the scalar
    /// [`Plane::intersect`], a lane at a time).
    #[inline(always)]
    pub fn hit(&self, r: &RayLanes<L>, t_max: L) -> (L, L::Mask) {
        // SAFETY: `t_max` is a value of `L`, so the CPU runs `L`'s instruction set.
        let (zero, tiny) = unsafe { (L::splat(0.0), L::splat(f32::MIN_POSITIVE)) };
        let denom = dot(self.n, r.d);
        let s = self.dist - dot(self.n, r.o);
        let band = self.n_abs_sum * r.plane_k + self.dist_err;
        let mut t = s / denom;
        // The scalar test's predicates, NaN included (a NaN `s` is neither within the band nor
        // on the side `d` goes to).
        let within = s.abs().cmple(band);
        // Beyond the band: `s` on the side `d` goes to.
        let mut ok = (s * denom).cmpgt(zero) & !within;
        // Within it: only a ray leaving an oriented plane's side, met where it crosses or at
        // the smallest positive distance (rare: a ray from a crease heading out of the room).
        let leaving = (self.side * denom).cmplt(zero) & within;
        if L::any(leaving) {
            t = L::select(leaving, t.max(tiny), t);
            ok = ok | leaving;
        }
        (t, ok & t.cmple(t_max))
    }
}

/// Packed primitives with the prim index of each lane.
#[derive(Clone, Debug, Default)]
pub struct Lanes<P> {
    /// The packets.
    pub packs: Vec<P>,
    /// `packs.len() * 4` prim indices; padding lanes repeat the last one (they never hit).
    pub prim: Vec<u32>,
    /// The primitives packed (the lanes that are not padding).
    pub count: usize,
}

impl<P> Lanes<P> {
    /// Each primitive alone (`lane` reads it from its packet), with its prim index, in the
    /// order [`Lanes::closest`] tests them: for batches of rays in the lanes.
    pub fn each<Q>(&self, lane: impl Fn(&P, usize) -> Q) -> Vec<(u32, Q)> {
        (0..self.count)
            .map(|k| (self.prim[k], lane(&self.packs[k / 4], k % 4)))
            .collect()
    }

    /// Closest hit over every packet, with the scalar loop's tie rule (a later lane at equal
    /// distance wins), updating `t_max` and `best`.
    #[inline(always)]
    pub fn closest(
        &self,
        r: &RayLanes,
        t_max: &mut f32,
        best: &mut Option<u32>,
        hit: impl Fn(&P, &RayLanes, Vec4) -> (Vec4, BVec4A),
    ) {
        for (k, p) in self.packs.iter().enumerate() {
            let (t, ok) = hit(p, r, Vec4::splat(*t_max));
            let mut mask = ok.bitmask();
            if mask == 0 {
                continue;
            }
            let t = t.to_array();
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if t[i] <= *t_max {
                    *t_max = t[i];
                    *best = Some(self.prim[k * 4 + i]);
                }
            }
        }
    }

    /// True if any lane of any packet hits within `t_max`; `tally` is told the shapes of the
    /// packets tested.
    #[inline(always)]
    pub fn any(
        &self,
        r: &RayLanes,
        t_max: f32,
        hit: impl Fn(&P, &RayLanes, Vec4) -> (Vec4, BVec4A),
        tally: &impl super::Tally,
    ) -> bool {
        let t_max = Vec4::splat(t_max);
        self.packs.iter().enumerate().any(|(k, p)| {
            tally.prims((self.count - 4 * k).min(4) as u64);
            hit(p, r, t_max).1.any()
        })
    }
}

/// Pack `items` (with their prim indices) four at a time.
pub fn pack<T, P>(items: &[(u32, T)], f: impl Fn(&[T]) -> P) -> Lanes<P>
where
    T: Copy,
{
    let mut out = Lanes {
        packs: Vec::new(),
        prim: Vec::new(),
        count: items.len(),
    };
    for chunk in items.chunks(4) {
        let shapes: Vec<T> = chunk.iter().map(|(_, s)| *s).collect();
        out.packs.push(f(&shapes));
        for i in 0..4 {
            out.prim.push(chunk[i.min(chunk.len() - 1)].0);
        }
    }
    out
}

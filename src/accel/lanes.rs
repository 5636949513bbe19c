//! Primitives four to a packet in structure-of-arrays lanes, tested together with SSE
//! (`glam::Vec4`). Planes always live here; spheres too when a scene has few of them, where a
//! BVH costs more than it saves. The arithmetic is the scalar tests' (`shape::Sphere`,
//! `shape::Plane`), including their rule for a ray that starts on the surface, so a packet
//! finds the hits the scalar code would (`tests/shapes.rs` checks that they agree).
//!
//! The same tests run the other way round: four rays in the lanes ([`RayLanes::gather`])
//! against one primitive in all of them ([`SphereLanes::splat_lane`]), as a batch of rays
//! needs. Each lane computes what the scalar test computes for its pair, so both layouts give
//! the same bits.

use crate::geometry::{Ray, gamma};
use crate::shape::{Plane, Sphere};
use glam::{BVec4A, Vec4};

/// A ray splatted across four lanes ([`RayLanes::new`]), or four rays, one per lane
/// ([`RayLanes::gather`]).
#[derive(Clone, Copy)]
pub struct RayLanes {
    o: [Vec4; 3],
    d: [Vec4; 3],
    /// The origin's share of a plane's band per unit of `sum |n_i|`:
    /// `gamma(4) max |o_i| + o_err`.
    plane_k: Vec4,
    /// The error of `o` before the sphere's centre is subtracted: `o_err + gamma(1) max |o_i|`.
    sphere_k: Vec4,
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
        }
    }

    /// Four rays, one per lane, with each lane's constants as [`RayLanes::new`] computes them.
    #[inline(always)]
    pub fn gather(rays: [&Ray; 4]) -> Self {
        // Transpose: four `Vec3A`s (x, y, z, pad) into x, y, z lanes.
        let t = |v: [glam::Vec3A; 4]| {
            let [a, b, c, d] = v.map(|v| v.extend(0.0));
            let m = glam::Mat4::from_cols(a, b, c, d).transpose();
            [m.x_axis, m.y_axis, m.z_axis]
        };
        let a = Vec4::from_array(rays.map(|r| r.o.abs().max_element()));
        let o_err = Vec4::from_array(rays.map(|r| r.o_err));
        RayLanes {
            o: t(rays.map(|r| r.o)),
            d: t(rays.map(|r| r.d)),
            plane_k: Vec4::splat(gamma(4)) * a + o_err,
            sphere_k: o_err + Vec4::splat(gamma(1)) * a,
        }
    }
}

#[inline(always)]
fn dot(a: [Vec4; 3], b: [Vec4; 3]) -> Vec4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Up to four spheres; unused lanes have `r2 = -1` and never hit.
#[derive(Clone, Copy, Debug, Default)]
pub struct SphereLanes {
    c: [Vec4; 3],
    r: Vec4,
    r2: Vec4,
    /// `1 / r` (0 in unused lanes).
    inv_r: Vec4,
    /// `gamma(1) max |c_i|`: the rounding of `o - c` due to the centre.
    c_err: Vec4,
}

/// Up to four planes; unused lanes have a zero normal and never hit.
#[derive(Clone, Copy, Debug, Default)]
pub struct PlaneLanes {
    n: [Vec4; 3],
    dist: Vec4,
    /// `sum |n_i|`.
    n_abs_sum: Vec4,
    /// `gamma(4) |dist|`.
    dist_err: Vec4,
    /// [`Plane::side`] (0 in unused lanes).
    side: Vec4,
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

    /// Lane `i`'s sphere in all four lanes (an unused lane's padding, which never hits).
    pub fn splat_lane(&self, i: usize) -> Self {
        let s = |v: Vec4| Vec4::splat(v[i]);
        SphereLanes {
            c: self.c.map(s),
            r: s(self.r),
            r2: s(self.r2),
            inv_r: s(self.inv_r),
            c_err: s(self.c_err),
        }
    }

    /// Distances of each lane's hit in `(0, tm]`, and which lanes hit (the scalar
    /// [`Sphere::intersect`], four at a time).
    #[inline(always)]
    pub fn hit(&self, r: &RayLanes, tm: Vec4) -> (Vec4, BVec4A) {
        let f = [r.o[0] - self.c[0], r.o[1] - self.c[1], r.o[2] - self.c[2]];
        let b = -dot(f, r.d);
        let l = [f[0] + b * r.d[0], f[1] + b * r.d[1], f[2] + b * r.d[2]];
        let disc = self.r2 - dot(l, l);
        // Most rays miss every sphere of a packet (a shadow ray in a room of a few spheres):
        // they skip the square root and division below, whose latency dominates the test.
        let real = disc.cmpge(Vec4::ZERO);
        if !real.any() {
            return (Vec4::ZERO, real);
        }
        let f2 = dot(f, f);
        let c = f2 - self.r2;
        let q = b + disc.sqrt().copysign(b);
        let a = c / q;
        let first = a.cmple(q);
        let t0 = Vec4::select(first, a, q);
        let t1 = Vec4::select(first, q, a);
        let zero = Vec4::ZERO;
        let ok0 = t0.cmpgt(zero) & t0.cmple(tm);
        let ok1 = t1.cmpgt(zero) & t1.cmple(tm);
        let mut t = Vec4::select(ok0, t0, t1);
        let mut ok = ok0 | ok1;
        // The scalar test's band: an origin on the sphere only meets the root away from zero.
        let e_f = r.sphere_k + self.c_err;
        let band = Vec4::splat(gamma(5)) * (f2 + self.r2)
            + Vec4::splat(2.0) * e_f * (f2 * self.inv_r + self.r);
        let on = c.abs().cmple(band);
        if on.any() {
            let t_min = band / (f2.sqrt() + self.r);
            let other = Vec4::select(t0.abs().cmple(t1.abs()), t1, t0);
            let ok_on = other.cmpgt(t_min) & other.cmple(tm);
            t = Vec4::select(on, other, t);
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

    /// Lane `i`'s plane in all four lanes (an unused lane's padding, which never hits).
    pub fn splat_lane(&self, i: usize) -> Self {
        let s = |v: Vec4| Vec4::splat(v[i]);
        PlaneLanes {
            n: self.n.map(s),
            dist: s(self.dist),
            n_abs_sum: s(self.n_abs_sum),
            dist_err: s(self.dist_err),
            side: s(self.side),
        }
    }

    /// Distances of each lane's hit in `(0, t_max]`, and which lanes hit (the scalar
    /// [`Plane::intersect`], four at a time).
    #[inline(always)]
    pub fn hit(&self, r: &RayLanes, t_max: Vec4) -> (Vec4, BVec4A) {
        let denom = dot(self.n, r.d);
        let s = self.dist - dot(self.n, r.o);
        let band = self.n_abs_sum * r.plane_k + self.dist_err;
        let mut t = s / denom;
        // The scalar test's predicates, NaN included (a NaN `s` is neither within the band nor
        // on the side `d` goes to).
        let within = s.abs().cmple(band);
        // Beyond the band: `s` on the side `d` goes to.
        let mut ok = (s * denom).cmpgt(Vec4::ZERO) & !within;
        // Within it: only a ray leaving an oriented plane's side, met where it crosses or at
        // the smallest positive distance (rare: a ray from a crease heading out of the room).
        let leaving = (self.side * denom).cmplt(Vec4::ZERO) & within;
        if leaving.any() {
            t = Vec4::select(leaving, t.max(Vec4::splat(f32::MIN_POSITIVE)), t);
            ok |= leaving;
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
    /// Each primitive alone in all four lanes (`splat` gives a packet's lane), with its prim
    /// index, in the order [`Lanes::closest`] tests them: for batches of rays in the lanes.
    pub fn each(&self, splat: impl Fn(&P, usize) -> P) -> Vec<(u32, P)> {
        (0..self.count)
            .map(|k| (self.prim[k], splat(&self.packs[k / 4], k % 4)))
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

    /// True if any lane of any packet hits within `t_max`.
    #[inline(always)]
    pub fn any(
        &self,
        r: &RayLanes,
        t_max: f32,
        hit: impl Fn(&P, &RayLanes, Vec4) -> (Vec4, BVec4A),
    ) -> bool {
        let t_max = Vec4::splat(t_max);
        self.packs.iter().any(|p| hit(p, r, t_max).1.any())
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

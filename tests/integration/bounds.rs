//! The rounding-error bounds of the shapes (src/shape/*.rs, src/accel/lanes.rs) are safe and
//! consistent: rays that start on a surface (within rounding) never meet it at their start
//! (planes here are not oriented; `tests/integration/room.rs` and `tests/integration/shapes.rs` test oriented ones),
//! in every code path (scalar, SIMD lanes, BVH); every hit point lies within its bounds; and
//! the bounds scale exactly with the scene. Scaling every coordinate by a power of two changes
//! no rounding, so a bound that is a sum of terms of the right dimension (lengths, or squared
//! lengths for the sphere's band) scales exactly too; a term of the wrong dimension, a factor
//! divided instead of multiplied, is caught even when it leaves the bound safe.

use glam::{DVec3, Vec3A};
use rtis::accel::{Geometry, Prim};
use rtis::geometry::Ray;
use rtis::sampling::Sampler;
use rtis::shape::{Plane, Shape, Sphere, Surface, Triangle};

/// Deterministic random numbers for case `i` of a test.
fn rng(test: u64, i: u64) -> Sampler {
    Sampler::new(0xB0_0D5 ^ test, i, 0)
}

fn unit(s: &mut Sampler) -> Vec3A {
    loop {
        let v = Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.0 - Vec3A::ONE;
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn within(s: &mut Sampler, half: f32) -> Vec3A {
    (Vec3A::new(s.next_f32(), s.next_f32(), s.next_f32()) * 2.0 - Vec3A::ONE) * half
}

/// Log-uniform in [lo, hi].
fn log_uniform(s: &mut Sampler, lo: f32, hi: f32) -> f32 {
    (lo.ln() + s.next_f32() * (hi.ln() - lo.ln())).exp()
}

/// The far root of the ray against the sphere in double precision.
fn far_root(o: Vec3A, d: Vec3A, c: Vec3A, r: f32) -> f64 {
    let f = o.as_dvec3() - c.as_dvec3();
    let d = d.as_dvec3();
    let b = f.dot(d);
    let cc = f.length_squared() - (r as f64) * (r as f64);
    -b + (b * b - cc).max(0.0).sqrt()
}

/// The three ways rtis intersects spheres: the scalar test, a packet of four (scenes with at
/// most 16 spheres), and the BVH (more): each returns the distance to `s` along `ray`.
fn sphere_paths(s: Sphere, ray: &Ray) -> [Option<f32>; 3] {
    let scalar = Shape::Sphere(s).intersect(ray);
    let packed = Geometry::build(vec![Prim::flat(Shape::Sphere(s))], Vec::new());
    // 17 spheres go to the BVH; the 16 others are tiny and far behind the ray's origin.
    let mut many = vec![Prim::flat(Shape::Sphere(s))];
    for k in 0..16 {
        let far = s.c - ray.d * (1e3 * s.r + 10.0 * s.r * k as f32);
        many.push(Prim::flat(Shape::Sphere(Sphere {
            c: far,
            r: s.r * 1e-3,
        })));
    }
    let bvh = Geometry::build(many, Vec::new());
    assert!(bvh.in_bvh == 17 && packed.in_bvh == 0);
    let from = |g: &Geometry| {
        g.intersect(ray)
            .filter(|h| matches!(g.prim(h.prim).shape, Shape::Sphere(x) if x.r == s.r))
            .map(|h| h.t)
    };
    [scalar, from(&packed), from(&bvh)]
}

/// A ray that starts on a sphere (its origin `c + r n` rounded to f32, so a little inside or
/// outside) leaves through the far side when it points inwards, at the chord's length, and
/// meets nothing when it points outwards; in every code path, at radii from 0.05 to 20 and
/// scales 2^-10 to 2^10.
#[test]
fn rays_starting_on_a_sphere_meet_only_its_far_side() {
    let mut checked = 0;
    for i in 0..4000 {
        let s = &mut rng(1, i);
        let k = [-10, 0, 10][i as usize % 3];
        let scale = 2f32.powi(k);
        let r = log_uniform(s, 0.05, 20.0) * scale;
        // A third of the spheres sit at the origin, where the origin's own rounding is as
        // small as the sphere's: the band's terms in r^2 then decide.
        let c = if i % 9 < 3 {
            Vec3A::ZERO
        } else {
            within(s, 50.0) * scale
        };
        let n = unit(s);
        let o = c + r * n;
        let d = unit(s);
        let cos = d.dot(n);
        if cos.abs() < 0.1 {
            continue;
        }
        let ray = Ray::new(o, d);
        let paths = sphere_paths(Sphere { c, r }, &ray);
        if cos < 0.0 {
            let want = far_root(o, d, c, r);
            for (path, t) in ["scalar", "packet", "BVH"].iter().zip(paths) {
                let t = t.unwrap_or_else(|| {
                    panic!("{path}: inward ray from the sphere (r {r}, c {c}) missed its far side")
                });
                assert!(
                    (t as f64 - want).abs() <= 1e-3 * want,
                    "{path}: t {t} where the far side is at {want} (r {r}, c {c}, cos {cos})"
                );
            }
        } else {
            assert_eq!(
                paths, [None; 3],
                "outward ray from the sphere (r {r}, c {c}) met it"
            );
        }
        checked += 1;
    }
    assert!(checked > 3000);
}

/// A ray that starts on an unoriented plane (a point projected onto it in f32) never meets it, wherever
/// the plane is (up to 1e4 from the origin) and whichever way the ray goes; in the scalar test
/// and the packet of planes.
#[test]
fn rays_starting_on_a_plane_do_not_meet_it() {
    for i in 0..4000 {
        let s = &mut rng(2, i);
        // Half the planes are nearly axis-aligned and far along their axis, where the origin's
        // coordinates and the plane's distance are of one size and the band's two terms meet.
        let (n, point) = if i % 2 == 0 {
            (unit(s), within(s, 1e4))
        } else {
            let axis = [Vec3A::X, Vec3A::Y, Vec3A::Z][i as usize % 3];
            let n = (axis + within(s, 0.01)).normalize();
            (n, axis * log_uniform(s, 10.0, 1e4) + within(s, 5.0))
        };
        let plane = Plane::through(point, n);
        // The point of the plane nearest q, exact in double precision, rounded once.
        let (q, nd) = (within(s, 1e4).as_dvec3(), n.as_dvec3());
        let o = (q - (nd.dot(q) - plane.dist as f64) / nd.length_squared() * nd).as_vec3a();
        let d = unit(s);
        if d.dot(n).abs() < 0.05 {
            continue;
        }
        let ray = Ray::new(o, d);
        assert_eq!(
            Shape::Plane(plane).intersect(&ray),
            None,
            "{plane:?} from {o}"
        );
        let g = Geometry::build(vec![Prim::flat(Shape::Plane(plane))], Vec::new());
        assert!(g.intersect(&ray).is_none(), "packet: {plane:?} from {o}");
    }
}

/// A random shape and a ray from afar that hits it, at scale 1.
fn random_hit(s: &mut Sampler, kind: usize) -> Option<(Shape, Ray)> {
    if kind == 3 {
        // A far plane seen from the origin: the rounding of `o + t d` then outweighs the error
        // of `t` from the plane's distance, which is exact.
        let n = unit(s);
        let plane = Plane::through(n * log_uniform(s, 10.0, 1e4), n);
        let d = (n + within(s, 0.5)).normalize();
        let ray = Ray::new(Vec3A::ZERO, d);
        let shape = Shape::Plane(plane);
        return shape.intersect(&ray).map(|_| (shape, ray));
    }
    let target = within(s, 3.0);
    let shape = match kind {
        0 => Shape::Sphere(Sphere {
            c: target + unit(s) * 0.5,
            r: log_uniform(s, 0.6, 4.0),
        }),
        1 => Shape::Plane(Plane::through(target, unit(s))),
        _ => Shape::Triangle(Triangle::new(
            target + within(s, 4.0),
            target + within(s, 4.0),
            target + within(s, 4.0),
        )?),
    };
    let o = target + unit(s) * log_uniform(s, 1.0, 1e3);
    let ray = Ray::new(o, (target - o).normalize());
    shape.intersect(&ray).map(|_| (shape, ray))
}

fn scaled(shape: Shape, k: f32) -> Shape {
    match shape {
        Shape::Sphere(s) => Shape::Sphere(Sphere {
            c: s.c * k,
            r: s.r * k,
        }),
        Shape::Plane(p) => Shape::Plane(Plane {
            dist: p.dist * k,
            ..p
        }),
        Shape::Triangle(t) => Shape::Triangle(Triangle {
            v: t.v.map(|v| v * k),
            n: t.n,
        }),
    }
}

/// Hits, their points and every error bound scale exactly with the scene (powers of two from
/// 2^-20 to 2^20), for spheres (whose band is a squared length), planes and triangles.
#[test]
fn error_bounds_scale_exactly_with_the_scene() {
    let mut checked = 0;
    for i in 0..3000 {
        let s = &mut rng(3, i);
        let Some((shape, ray)) = random_hit(s, i as usize % 3) else {
            continue;
        };
        let t = shape.intersect(&ray).unwrap();
        let at = shape.surface(&ray, t);
        for e in [-20, -7, 9, 20] {
            let k = 2f32.powi(e);
            let shape_k = scaled(shape, k);
            let ray_k = Ray::new(ray.o * k, ray.d);
            let t_k = shape_k.intersect(&ray_k);
            assert_eq!(t_k, Some(t * k), "{shape:?}: t at scale 2^{e}");
            let at_k: Surface = shape_k.surface(&ray_k, t * k);
            assert_eq!(at_k.p, at.p * k, "{shape:?}: point at 2^{e}");
            assert_eq!(at_k.err, at.err * k, "{shape:?}: err at 2^{e}");
            assert_eq!(
                at_k.err_along,
                at.err_along * k,
                "{shape:?}: err_along at 2^{e}"
            );
            match (shape, shape_k) {
                (Shape::Sphere(a), Shape::Sphere(b)) => {
                    let f2 = (ray.o - a.c).length_squared();
                    assert_eq!(
                        b.band(&ray_k, f2 * k * k),
                        a.band(&ray, f2) * k * k,
                        "sphere band"
                    );
                }
                (Shape::Plane(a), Shape::Plane(b)) => {
                    assert_eq!(b.band(&ray_k), a.band(&ray) * k, "plane band");
                }
                _ => {}
            }
        }
        checked += 1;
    }
    assert!(checked > 2000);
}

/// Every hit point lies within its bounds (exact values in double precision from the same f32
/// inputs): off the surface by at most `err` in each coordinate, and from the exact
/// intersection by at most `err_along` more; both bounds are non-negative.
#[test]
fn hit_points_lie_within_their_bounds() {
    for i in 0..6000 {
        let s = &mut rng(4, i);
        let Some((shape, ray)) = random_hit(s, i as usize % 4) else {
            continue;
        };
        let t = shape.intersect(&ray).unwrap();
        let hit = shape.surface(&ray, t);
        assert!(
            hit.err >= 0.0 && hit.err_along >= 0.0,
            "{shape:?}: negative bound"
        );
        let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
        // The exact hit: the root nearest t of the exact equation.
        let t_exact = match shape {
            Shape::Sphere(sp) => {
                let f = o - sp.c.as_dvec3();
                let b = f.dot(d);
                let cc = f.length_squared() - (sp.r as f64).powi(2);
                let q = (b * b - cc).max(0.0).sqrt();
                let (t0, t1) = (-b - q, -b + q);
                if (t0 - t as f64).abs() < (t1 - t as f64).abs() {
                    t0
                } else {
                    t1
                }
            }
            Shape::Plane(p) => {
                let n = p.n.as_dvec3();
                (p.dist as f64 - n.dot(o)) / n.dot(d)
            }
            Shape::Triangle(tr) => {
                let [a, b, c] = tr.v.map(|v| v.as_dvec3());
                let n = (b - a).cross(c - a);
                n.dot(a - o) / n.dot(d)
            }
        };
        let exact: DVec3 = o + t_exact * d;
        let p = hit.p.as_dvec3();
        // Distance from the surface: along the normal for planes and triangles, radial for
        // spheres.
        let across = match shape {
            Shape::Sphere(sp) => ((p - sp.c.as_dvec3()).length() - sp.r as f64).abs(),
            _ => (p - exact).dot(hit.n.as_dvec3().normalize()).abs(),
        };
        let err = hit.err as f64 * 3f64.sqrt();
        assert!(
            across <= err * 1.0001,
            "{shape:?}: {across:e} off the surface, bound {err:e}"
        );
        let from_exact = (p - exact).length();
        assert!(
            from_exact <= (hit.err_along as f64 + err) * 1.0001,
            "{shape:?}: {from_exact:e} from the exact hit, bound {:e} + {err:e}",
            hit.err_along
        );
    }
}

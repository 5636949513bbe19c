//! `rtis warptest`: every direction sampler against its pdf, as Nori's warptest and Mitsuba's
//! `ChiSquareTest` do it.
//!
//! For each sampler: draw `n` directions and bin them on the sphere (`z` and `phi` in equal
//! steps, so every bin has the same solid angle); integrate the pdf over the same bins (a
//! midpoint rule on a finer grid); pool bins whose expected count is below 5; and run Pearson's
//! chi-squared test. The null hypothesis, that the samples follow the pdf, is rejected when the
//! p-value is below the significance level (0.01, Sidak-corrected for the number of tests).
//! The discrete Fresnel choice of Physical glass (reflect with probability `F`) is tested the
//! same way over its two outcomes. Area-light sampling (choose a light by power, then a
//! direction towards it) is tested against `Emitters::pdf_direction` from a point; the
//! environment light's sampler (a constant sky; maps with a tiny bright sun, and of one texel)
//! against `EnvironmentLight::pdf`, with the map's poles on the bins' axis. The
//! microfacet samplers (GGX and Beckmann, visible and full) are tested through the directions
//! they reflect, against `Microfacet::pdf_reflection`; every BSDF through `Bsdf::sample`
//! against `Bsdf::pdf`, over the whole sphere.

use crate::geometry::Frame;
use crate::light::{
    AreaLight, Emitter, Emitters, Emitting, EnvironmentLight, Sky, SkyMap, WorldEnvironment,
};
use crate::material::conductor::Conductor;
use crate::material::microfacet::{Distribution, Microfacet, NormalSampling};
use crate::material::plastic::Plastic;
use crate::material::rough_conductor::RoughConductor;
use crate::material::rough_dielectric::RoughDielectric;
use crate::material::rough_plastic::RoughPlastic;
use crate::material::{Bsdf, Coating, Phong, fresnel_dielectric, reflect};
use crate::raster::Raster;
use crate::sampling::{Sampler, Sampling, hemisphere, warp};
use crate::shader::path;
use crate::shape::{Sphere, Triangle};
use glam::{DVec3, Vec3A};
use std::f64::consts::PI;
use std::fmt::Write;
use std::sync::Arc;

/// Bins in `z` (cosine of the polar angle, from -1 to 1).
pub const BINS_Z: usize = 20;
/// Bins in `phi`.
pub const BINS_PHI: usize = 40;
/// Significance level of the whole set of tests.
pub const ALPHA: f64 = 0.01;

/// Draws one outcome from the random numbers: a bin index, or `None` for a sample the
/// integrator rejects (below the surface).
pub type Draw = Box<dyn Fn(&mut Sampler) -> Option<usize>>;

/// A sampler under test: how it draws, and the pdf it claims.
pub struct Case {
    /// Its name.
    pub name: String,
    /// How it draws.
    pub draw: Draw,
    /// The probability the pdf gives to each bin (summing to at most 1).
    pub expected: Vec<f64>,
    /// Bins per row for the histogram pages (`BINS_PHI` for directions, 2 for Fresnel).
    pub columns: usize,
}

/// The result of one chi-squared test.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The sampler's name.
    pub name: String,
    /// Observed counts per bin.
    pub observed: Vec<f64>,
    /// Expected counts per bin.
    pub expected: Vec<f64>,
    /// Bins per row.
    pub columns: usize,
    /// Pearson's statistic.
    pub chi2: f64,
    /// Degrees of freedom (pooled bins, less one).
    pub dof: usize,
    /// P-value: the probability of a statistic this large if the sampler follows its pdf.
    pub p_value: f64,
}

/// The bin of a unit direction on the `BINS_Z x BINS_PHI` grid.
pub fn direction_bin(w: Vec3A) -> usize {
    let t = (((w.z + 1.0) * 0.5 * BINS_Z as f32) as usize).min(BINS_Z - 1);
    let phi = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU);
    let p = ((phi / std::f32::consts::TAU * BINS_PHI as f32) as usize).min(BINS_PHI - 1);
    t * BINS_PHI + p
}

/// The probability of each bin under a pdf over directions (per steradian), by the midpoint
/// rule on 64 x 8 points per bin (`z` finer: lobes around the pole vary fastest in `z`).
pub fn integrate_pdf(pdf: impl Fn(Vec3A) -> f64) -> Vec<f64> {
    (0..BINS_Z * BINS_PHI)
        .map(|bin| integrate_bin(&pdf, bin, 64, 8))
        .collect()
}

/// As [`integrate_pdf`], for a pdf with edges (a light's outline): bins where a coarse 8 x 4
/// grid sees density, and their neighbours, are integrated on 256 x 64 points, so that a bin
/// the outline only clips still gets its share; the others have none.
pub fn integrate_pdf_with_edges(pdf: impl Fn(Vec3A) -> f64) -> Vec<f64> {
    let coarse: Vec<bool> = (0..BINS_Z * BINS_PHI)
        .map(|bin| integrate_bin(&pdf, bin, 8, 4) > 0.0)
        .collect();
    let lit = |t: isize, p: isize| {
        (0..BINS_Z as isize).contains(&t)
            && coarse[t as usize * BINS_PHI + p.rem_euclid(BINS_PHI as isize) as usize]
    };
    (0..BINS_Z * BINS_PHI)
        .map(|bin| {
            let (t, p) = ((bin / BINS_PHI) as isize, (bin % BINS_PHI) as isize);
            let near = (-1..=1).any(|dt| (-1..=1).any(|dp| lit(t + dt, p + dp)));
            if near {
                integrate_bin(&pdf, bin, 256, 64)
            } else {
                0.0
            }
        })
        .collect()
}

/// As [`integrate_pdf`], for a pdf with narrow peaks (a microfacet lobe of roughness down to
/// 0.01, a few hundredths of a radian wide): each bin is integrated in `(theta, phi)` with the
/// `sin(theta)` Jacobian, so that a lobe at the pole, within a sliver of `z`, is resolved; on
/// 16 x 8 and 32 x 16 points, and where the two differ by more than 1e-4 of the bin's share (or
/// 1e-8 absolutely), again on 512 x 128 points (a peak or its flank in the bin). The bins are
/// integrated in parallel.
pub fn integrate_pdf_peaked(pdf: impl Fn(Vec3A) -> f64 + Sync) -> Vec<f64> {
    use rayon::prelude::*;
    (0..BINS_Z * BINS_PHI)
        .into_par_iter()
        .map(|bin| {
            let rough = integrate_bin_polar(&pdf, bin, 16, 8);
            let finer = integrate_bin_polar(&pdf, bin, 32, 16);
            if (rough - finer).abs() <= 1e-4 * finer + 1e-8 {
                finer
            } else {
                integrate_bin_polar(&pdf, bin, 512, 128)
            }
        })
        .collect()
}

/// The midpoint rule over one bin in `(theta, phi)` on `sub_theta x sub_phi` points, with the
/// solid angle's `sin(theta)`.
fn integrate_bin_polar(
    pdf: &impl Fn(Vec3A) -> f64,
    bin: usize,
    sub_theta: usize,
    sub_phi: usize,
) -> f64 {
    let (t, p) = (bin / BINS_PHI, bin % BINS_PHI);
    // The bin's z range [z0, z1] is theta in [acos z1, acos z0].
    let z0 = -1.0 + 2.0 * t as f64 / BINS_Z as f64;
    let z1 = -1.0 + 2.0 * (t + 1) as f64 / BINS_Z as f64;
    let (th0, th1) = (z1.clamp(-1.0, 1.0).acos(), z0.clamp(-1.0, 1.0).acos());
    let (dth, dphi) = (
        (th1 - th0) / sub_theta as f64,
        2.0 * PI / BINS_PHI as f64 / sub_phi as f64,
    );
    let mut acc = 0.0;
    for a in 0..sub_theta {
        let th = th0 + (a as f64 + 0.5) * dth;
        let (sin_t, cos_t) = th.sin_cos();
        let mut ring = 0.0;
        for b in 0..sub_phi {
            let phi = 2.0 * PI * p as f64 / BINS_PHI as f64 + (b as f64 + 0.5) * dphi;
            ring += pdf(Vec3A::new(
                (sin_t * phi.cos()) as f32,
                (sin_t * phi.sin()) as f32,
                cos_t as f32,
            ));
        }
        acc += ring * sin_t;
    }
    acc * dth * dphi
}

/// The reflection sampler of a microfacet distribution (`Microfacet::sample_reflection`) for
/// the viewer at `theta_o` degrees from the normal (azimuth 30 degrees, off the tangent axes),
/// against the pdf it claims.
pub fn microfacet_case(m: Microfacet, theta_o: f32) -> Case {
    let t = theta_o.to_radians();
    let p = 30f32.to_radians();
    let wo = Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let expected = integrate_pdf_peaked(|wi| m.pdf_reflection(wo, wi) as f64);
    Case {
        name: format!(
            "{:?} {:?}, alpha {} x {}, theta_o {theta_o}",
            m.distribution, m.sampling, m.alpha_x, m.alpha_y
        ),
        draw: Box::new(move |s: &mut Sampler| {
            let (u1, u2) = s.next_2d();
            let (wi, _) = m.sample_reflection(wo, u1, u2)?;
            Some(direction_bin(wi))
        }),
        expected,
        columns: BINS_PHI,
    }
}

/// Every microfacet sampler: each distribution, visible normals at roughness 0.01 to 1 and one
/// anisotropic pair, from normal incidence to 85 degrees (and 89.5 at the roughest); full
/// sampling at two roughnesses.
pub fn microfacet_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    for distribution in [Distribution::Ggx, Distribution::Beckmann] {
        for (ax, ay) in [(0.01, 0.01), (0.1, 0.1), (0.4, 0.4), (1.0, 1.0), (0.1, 0.5)] {
            let m = Microfacet {
                distribution,
                alpha_x: ax,
                alpha_y: ay,
                sampling: NormalSampling::Visible,
            };
            for theta in [0.0, 45.0, 85.0] {
                cases.push(microfacet_case(m, theta));
            }
            if ax == 1.0 {
                cases.push(microfacet_case(m, 89.5));
            }
        }
        for alpha in [0.1, 0.6] {
            let m = Microfacet {
                sampling: NormalSampling::Full,
                ..Microfacet::isotropic(distribution, alpha)
            };
            cases.push(microfacet_case(m, 60.0));
        }
    }
    cases
}

/// The sampler of a BSDF ([`Bsdf::sample`]) for the viewer `wo` (local frame), against
/// [`Bsdf::pdf`], over the whole sphere (a dielectric transmits). A delta lobe (a smooth
/// coating's mirror) is expected in its bin with the probability of choosing it.
pub fn bsdf_case(name: &str, bsdf: Bsdf, wo: Vec3A) -> Case {
    let mut expected = integrate_pdf_peaked(|wi| bsdf.pdf(wo, wi) as f64);
    // The delta lobe's share: the chance of choosing it (the only sample with `uc` below it).
    if let Some(s) = bsdf.sample(wo, 0.0, 0.5, 0.5).filter(|s| s.delta) {
        expected[direction_bin(s.wi)] += s.pdf as f64;
    }
    Case {
        name: name.to_string(),
        draw: Box::new(move |s: &mut Sampler| {
            let uc = s.next_f32();
            let (u1, u2) = s.next_2d();
            let b = bsdf.sample(wo, uc, u1, u2)?;
            Some(direction_bin(b.wi))
        }),
        expected,
        columns: BINS_PHI,
    }
}

/// The BSDF samplers: rough dielectrics from outside and inside, at roughness 0.01 to 1 and
/// one anisotropic pair, from normal incidence to 85 degrees (past the critical angle inside);
/// rough plastics; a smooth plastic, its mirror included; a rough conductor seen from below.
pub fn bsdf_cases() -> Vec<Case> {
    let dir = |theta: f32, side: f32| {
        let (t, p) = (theta.to_radians(), 30f32.to_radians());
        Vec3A::new(t.sin() * p.cos(), t.sin() * p.sin(), side * t.cos())
    };
    let mut cases = Vec::new();
    for distribution in [Distribution::Ggx, Distribution::Beckmann] {
        for (ax, ay) in [(0.01, 0.01), (0.2, 0.2), (1.0, 1.0), (0.1, 0.5)] {
            let microfacet = Microfacet {
                distribution,
                alpha_x: ax,
                alpha_y: ay,
                sampling: NormalSampling::Visible,
            };
            let b = Bsdf::RoughDielectric(RoughDielectric {
                microfacet,
                eta: 1.5,
                specular_reflectance: Vec3A::ONE,
                specular_transmittance: Vec3A::ONE,
            });
            for (theta, side) in [
                (0.0, 1.0),
                (45.0, 1.0),
                (85.0, 1.0),
                (30.0, -1.0),
                (60.0, -1.0),
            ] {
                let name = format!(
                    "RoughDielectric {distribution:?}, alpha {ax} x {ay}, eta 1.5, theta_o {} {theta}",
                    if side > 0.0 { "outside" } else { "inside" }
                );
                cases.push(bsdf_case(&name, b, dir(theta, side)));
            }
        }
        let full = Microfacet {
            sampling: NormalSampling::Full,
            ..Microfacet::isotropic(distribution, 0.3)
        };
        let b = Bsdf::RoughDielectric(RoughDielectric {
            microfacet: full,
            eta: 1.33,
            specular_reflectance: Vec3A::ONE,
            specular_transmittance: Vec3A::ONE,
        });
        cases.push(bsdf_case(
            &format!("RoughDielectric {distribution:?} Full, alpha 0.3, eta 1.33, theta_o 50"),
            b,
            dir(50.0, 1.0),
        ));
        for alpha in [0.05, 0.5] {
            let b = Bsdf::RoughPlastic(RoughPlastic::new(
                Microfacet::isotropic(distribution, alpha),
                1.49,
                Vec3A::new(0.2, 0.5, 0.8),
                Vec3A::ONE,
                false,
            ));
            for theta in [20.0, 80.0] {
                let name = format!("RoughPlastic {distribution:?}, alpha {alpha}, theta_o {theta}");
                cases.push(bsdf_case(&name, b, dir(theta, 1.0)));
            }
        }
    }
    let plastic = Bsdf::Plastic(Plastic {
        coating: Coating::smooth(1.49, Vec3A::splat(0.3), Vec3A::ONE, false),
    });
    for theta in [10.0, 75.0] {
        cases.push(bsdf_case(
            &format!("Plastic, theta_o {theta}"),
            plastic,
            dir(theta, 1.0),
        ));
    }
    let metal = Bsdf::RoughConductor(RoughConductor {
        microfacet: Microfacet::isotropic(Distribution::Ggx, 0.3),
        metal: Conductor {
            eta: Vec3A::splat(0.2),
            k: Vec3A::splat(3.0),
            specular_reflectance: Vec3A::ONE,
        },
    });
    cases.push(bsdf_case(
        "RoughConductor GGX, alpha 0.3, from below",
        metal,
        dir(40.0, -1.0),
    ));
    cases
}

/// The midpoint rule over one bin on `sub_z x sub_phi` points.
fn integrate_bin(pdf: &impl Fn(Vec3A) -> f64, bin: usize, sub_z: usize, sub_phi: usize) -> f64 {
    let (t, p) = (bin / BINS_PHI, bin % BINS_PHI);
    let area = (2.0 / BINS_Z as f64) * (2.0 * PI / BINS_PHI as f64);
    let mut acc = 0.0;
    for a in 0..sub_z {
        for b in 0..sub_phi {
            let z = -1.0 + 2.0 * (t as f64 + (a as f64 + 0.5) / sub_z as f64) / BINS_Z as f64;
            let phi = 2.0 * PI * (p as f64 + (b as f64 + 0.5) / sub_phi as f64) / BINS_PHI as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            acc += pdf(Vec3A::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ));
        }
    }
    acc / (sub_z * sub_phi) as f64 * area
}

/// A direction sampler with the pdf of `path::pdf` for `sampling` (normal +z).
pub fn direction_case(name: &str, phong: Phong, wo: Vec3A, sampling: Sampling) -> Case {
    let n = Vec3A::Z;
    let expected = integrate_pdf(|wi| path::pdf(&phong, wo, n, wi, sampling) as f64);
    Case {
        name: name.into(),
        draw: Box::new(move |s: &mut Sampler| {
            let (u1, u2) = s.next_2d();
            let wi = match sampling {
                Sampling::Uniform => hemisphere::uniform(u1, u2),
                Sampling::Cosine => hemisphere::cosine(u1, u2),
                Sampling::Brdf => {
                    if s.next_f32() < path::diffuse_probability(&phong) {
                        hemisphere::cosine(u1, u2)
                    } else {
                        Frame::from_normal(reflect(wo, n)).to_world(hemisphere::phong_lobe(
                            u1,
                            u2,
                            phong.shininess,
                        ))
                    }
                }
            };
            (wi.dot(n) > 0.0).then(|| direction_bin(wi))
        }),
        expected,
        columns: BINS_PHI,
    }
}

/// The Phong lobe alone around +z, exponent `s`, against `hemisphere::phong_lobe_pdf`.
fn lobe_case(s: f32) -> Case {
    Case {
        name: format!("Phong lobe, s = {s}"),
        draw: Box::new(move |r: &mut Sampler| {
            let (u1, u2) = r.next_2d();
            Some(direction_bin(hemisphere::phong_lobe(u1, u2, s)))
        }),
        expected: integrate_pdf(|w| hemisphere::phong_lobe_pdf(w.z, s) as f64),
        columns: BINS_PHI,
    }
}

/// The Fresnel choice: reflect with probability `F(cos_i, eta)`, refract otherwise.
fn fresnel_case(cos_i: f32, eta: f32) -> Case {
    let f = fresnel_dielectric(cos_i, eta) as f64;
    Case {
        name: format!("Fresnel choice, cos {cos_i}, eta {eta} (F = {f:.4})"),
        draw: Box::new(move |s: &mut Sampler| {
            Some(usize::from(s.next_f32() >= fresnel_dielectric(cos_i, eta)))
        }),
        expected: vec![f, 1.0 - f],
        columns: 2,
    }
}

/// Light sampling from the origin towards `lights`, against the density it claims.
fn light_case(name: &str, lights: Vec<AreaLight>) -> Case {
    let emitters = Emitters::new(lights);
    let expected = integrate_pdf_with_edges(|w| emitters.pdf_direction(Vec3A::ZERO, w) as f64);
    Case {
        name: name.into(),
        draw: Box::new(move |s: &mut Sampler| {
            let u = s.next_f64();
            let (u1, u2) = s.next_2d();
            let (light, _) = emitters.choose(u)?;
            let ls = light.sample(Vec3A::ZERO, u1, u2)?;
            Some(direction_bin(ls.wi))
        }),
        expected,
        columns: BINS_PHI,
    }
}

/// An environment light of `sky`, turned so that the map's zenith is the bins' `+z` (its poles,
/// where the density per solid angle has its `1 / sin(theta)`, on the bins' axis).
pub fn environment(sky: Sky) -> EnvironmentLight {
    WorldEnvironment {
        sky,
        scale: 1.0,
        rotate: DVec3::new(90.0, 0.0, 0.0),
    }
    .extract(1.0)
}

/// A `w x h` map whose texel `(x, y)` is grey `f(x, y)`.
pub fn grey_map(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Sky {
    let texels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| [f(x, y); 3])
        .collect();
    let raster = Raster::new(w, h, texels).expect("a map of w x h texels");
    Sky::Map {
        map: Arc::new(SkyMap::new(raster)),
        source: "(made by rtis warptest)".into(),
    }
}

/// The environment light's sampler (a 2D point of 53-bit coordinates), against the density it
/// claims.
pub fn environment_case(name: &str, light: EnvironmentLight) -> Case {
    let expected = integrate_pdf_peaked(|w| light.pdf(w) as f64);
    Case {
        name: name.into(),
        draw: Box::new(move |s: &mut Sampler| {
            let (u1, u2) = s.next_2d_f64();
            Some(direction_bin(light.sample(u1, u2)?.wi))
        }),
        expected,
        columns: BINS_PHI,
    }
}

/// The environment samplers: a constant sky; a map of a dim sky with a sun of one texel 10^4
/// times brighter (a peak a few degrees wide); and a map of one texel.
fn environment_cases() -> Vec<Case> {
    let sun = grey_map(64, 32, |x, y| {
        if (x, y) == (20, 9) {
            100.0
        } else {
            0.01 * (1.0 + x as f32 / 64.0)
        }
    });
    vec![
        environment_case(
            "environment: constant sky",
            environment(Sky::Uniform(Vec3A::ONE)),
        ),
        environment_case("environment: map with a tiny bright sun", environment(sun)),
        environment_case(
            "environment: map of 1x1",
            environment(grey_map(1, 1, |_, _| 2.0)),
        ),
    ]
}

/// An emitting sphere, one-sided, of radiance `l`.
fn sphere_light(c: Vec3A, r: f32, l: f32) -> AreaLight {
    AreaLight::new(
        Emitting::Sphere(Sphere { c, r }),
        Emitter {
            radiance: Vec3A::splat(l),
            two_sided: false,
        },
    )
}

/// An emitting triangle, two-sided, of radiance `l`.
fn triangle_light(v: [Vec3A; 3], l: f32) -> AreaLight {
    AreaLight::new(
        Emitting::Triangle(Triangle::new(v[0], v[1], v[2]).expect("a triangle")),
        Emitter {
            radiance: Vec3A::splat(l),
            two_sided: true,
        },
    )
}

/// The light samplers: a sphere's cone from near and far, a sphere from inside (by area), a
/// triangle by area, and a rectangle (two triangles) with a sphere chosen by power.
fn light_cases() -> Vec<Case> {
    let quad = |c: Vec3A, u: Vec3A, v: Vec3A, l| {
        [
            triangle_light([c, c + u, c + u + v], l),
            triangle_light([c, c + u + v, c + v], l),
        ]
    };
    let mut mixed = quad(
        Vec3A::new(-1.0, 1.0, -0.5),
        Vec3A::new(2.0, 0.0, 0.0),
        Vec3A::new(0.0, 0.0, 1.5),
        1.0,
    )
    .to_vec();
    mixed.push(sphere_light(Vec3A::new(0.3, -0.2, -1.5), 0.7, 2.0));
    vec![
        light_case(
            "sphere light, near (cone of 64 deg)",
            vec![sphere_light(Vec3A::new(0.2, 0.4, 1.0), 1.0, 1.0)],
        ),
        light_case(
            "sphere light, far (cone of 17 deg)",
            vec![sphere_light(Vec3A::new(-2.0, 2.0, 1.5), 1.0, 1.0)],
        ),
        light_case(
            "sphere light, from inside (by area)",
            vec![sphere_light(Vec3A::new(0.3, -0.2, 0.1), 1.0, 1.0)],
        ),
        light_case(
            "triangle light (by area)",
            vec![triangle_light(
                [
                    Vec3A::new(-1.0, -0.5, 0.8),
                    Vec3A::new(1.5, -0.2, 0.5),
                    Vec3A::new(0.2, 1.2, 0.3),
                ],
                1.0,
            )],
        ),
        light_case("rectangle and sphere, chosen by power", mixed),
    ]
}

/// Rings (of equal area) of the unit disk's bins.
const DISK_RINGS: usize = 8;
/// Sectors of the unit disk's bins.
const DISK_SECTORS: usize = 16;

/// The bin of a point of the unit disk: its ring of equal area (`r^2` in eighths) and its
/// sector of `phi`; `None` outside the disk.
pub fn disk_bin(x: f32, y: f32) -> Option<usize> {
    let r2 = (x as f64).powi(2) + (y as f64).powi(2);
    if r2 > 1.0 {
        return None;
    }
    let ring = ((r2 * DISK_RINGS as f64) as usize).min(DISK_RINGS - 1);
    let phi = (y as f64).atan2(x as f64).rem_euclid(2.0 * PI);
    let sector = ((phi / (2.0 * PI) * DISK_SECTORS as f64) as usize).min(DISK_SECTORS - 1);
    Some(ring * DISK_SECTORS + sector)
}

/// A sampler of points on the unit disk (`warp` of two uniform numbers) against the uniform
/// density `1 / pi`: each equal-area bin expects the same share.
pub fn disk_case(name: &str, warp: fn(f32, f32) -> (f32, f32)) -> Case {
    let bins = DISK_RINGS * DISK_SECTORS;
    Case {
        name: name.to_string(),
        draw: Box::new(move |s: &mut Sampler| {
            let (u1, u2) = s.next_2d();
            let (x, y) = warp(u1, u2);
            disk_bin(x, y)
        }),
        expected: vec![1.0 / bins as f64; bins],
        columns: DISK_SECTORS,
    }
}

/// Cells a side of [`sobol_case`]'s grid on the unit square.
const SQUARE_CELLS: usize = 16;

/// The Sobol' sampler's 2D points (`sampling::Sobol`) against the uniform density on the unit
/// square: each draw a point of a random seed, pixel, sample (up to `MAX_SPP`) and dimension
/// (up to 63), so that the draws are independent and each is one point of some sample, which
/// Owen scrambling makes uniform. (A pixel's points together are stratified, far more even
/// than chance: `sampling::sobol`'s own tests check that.)
pub fn sobol_case() -> Case {
    let bins = SQUARE_CELLS * SQUARE_CELLS;
    Case {
        name: "Sobol' sampler (a point of any sample and dimension)".to_string(),
        draw: Box::new(move |s: &mut Sampler| {
            let seed = s.next_u32() as u64;
            let (pixel, sample) = (s.next_u32() as u64, s.next_below(crate::render::MAX_SPP));
            let mut p = crate::sampling::Sobol::new(seed, pixel, sample as u64);
            p.skip(s.next_below(64));
            let (x, y) = p.next_2d();
            let cell = |u: f32| ((u * SQUARE_CELLS as f32) as usize).min(SQUARE_CELLS - 1);
            Some(cell(y) * SQUARE_CELLS + cell(x))
        }),
        expected: vec![1.0 / bins as f64; bins],
        columns: SQUARE_CELLS,
    }
}

/// Every sampler rtis uses: the Sobol' sampler's points, the thin lens's points, uniform and
/// cosine hemisphere, the Phong lobe at three exponents, the BRDF mixture of Path at two
/// materials and views, the Fresnel choice of glass, the area-light samplers, the microfacet
/// reflection samplers ([`microfacet_cases`]) and the BSDFs' ([`bsdf_cases`]).
pub fn cases() -> Vec<Case> {
    let white = Phong {
        kd: Vec3A::ONE,
        ks: Vec3A::ZERO,
        shininess: 1.0,
    };
    vec![
        sobol_case(),
        disk_case("thin lens (concentric disk)", warp::concentric_disk),
        direction_case("uniform hemisphere", white, Vec3A::Z, Sampling::Uniform),
        direction_case("cosine hemisphere", white, Vec3A::Z, Sampling::Cosine),
        lobe_case(1.0),
        lobe_case(10.0),
        lobe_case(100.0),
        direction_case(
            "BRDF mixture, kd 0.5, ks 0.5, s = 10",
            Phong {
                kd: Vec3A::splat(0.5),
                ks: Vec3A::splat(0.5),
                shininess: 10.0,
            },
            Vec3A::new(0.6, 0.0, 0.8).normalize(),
            Sampling::Brdf,
        ),
        direction_case(
            "BRDF mixture, kd 0.1, ks 0.8, s = 60, grazing",
            Phong {
                kd: Vec3A::splat(0.1),
                ks: Vec3A::splat(0.8),
                shininess: 60.0,
            },
            Vec3A::new(0.0, -0.9, 0.436).normalize(),
            Sampling::Brdf,
        ),
        fresnel_case(1.0, 1.0 / 1.5),
        fresnel_case(0.2, 1.0 / 1.5),
        fresnel_case(0.95, 1.5),
    ]
    .into_iter()
    .chain(light_cases())
    .chain(environment_cases())
    .chain(microfacet_cases())
    .chain(bsdf_cases())
    .collect()
}

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let a = C[1..]
        .iter()
        .enumerate()
        .fold(C[0], |a, (i, c)| a + c / (x + i as f64 + 1.0));
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function `Q(a, x)` (series below `a + 1`, continued
/// fraction above, as in Numerical Recipes' `gammq`).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let lg = ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..1000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - lg).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - lg).exp() * h
    }
}

/// Draw `n` samples of `case` and test them against its pdf.
pub fn run(case: &Case, n: u64, seed: u64) -> Outcome {
    let mut observed = vec![0.0; case.expected.len()];
    let mut s = Sampler::new(seed, 0, 0);
    for _ in 0..n {
        if let Some(b) = (case.draw)(&mut s) {
            observed[b] += 1.0;
        }
    }
    let expected: Vec<f64> = case.expected.iter().map(|p| p * n as f64).collect();
    // Pool bins expected below 5 into one; a sample where the pdf says none can fall makes
    // the statistic infinite.
    let (mut chi2, mut cells, mut pool_o, mut pool_e) = (0.0, 0usize, 0.0, 0.0);
    for (o, e) in observed.iter().zip(&expected) {
        if *e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pool_e >= 5.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        cells += 1;
    } else if pool_o > 0.0 && pool_o > 10.0 * pool_e.max(0.5) {
        chi2 = f64::INFINITY;
    }
    let dof = cells.saturating_sub(1).max(1);
    Outcome {
        name: case.name.clone(),
        observed,
        expected,
        columns: case.columns,
        chi2,
        dof,
        p_value: gamma_q(dof as f64 / 2.0, chi2 / 2.0),
    }
}

/// The per-test significance for `tests` tests at overall level [`ALPHA`] (Sidak).
pub fn per_test_alpha(tests: usize) -> f64 {
    1.0 - (1.0 - ALPHA).powf(1.0 / tests.max(1) as f64)
}

/// A self-contained HTML page: each test's verdict, and its observed and expected histograms
/// side by side (rows: `z` from -1 at the top to 1; columns: `phi`).
pub fn html(outcomes: &[Outcome], samples: u64) -> String {
    let alpha = per_test_alpha(outcomes.len());
    let mut s = String::from(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>rtis warptest</title>\
         <style>body{font-family:sans-serif;margin:2em}td,th{padding:2px 8px}\
         .pass{color:#060}.fail{color:#b00}svg{margin-right:1em;border:1px solid #ccc}</style>\
         </head><body><h1>rtis warptest</h1>",
    );
    let _ = write!(
        s,
        "<p>{samples} samples per sampler, Pearson's chi-squared test, significance {ALPHA} \
         overall ({alpha:.2e} per test, Sidak). Histograms: observed (left) and expected \
         (right) counts; rows are cos&theta; from -1 (top) to 1, columns &phi; from 0 to \
         2&pi;.</p>"
    );
    for o in outcomes {
        let pass = o.p_value >= alpha;
        let _ = write!(
            s,
            "<h2>{}</h2><p class=\"{}\">chi<sup>2</sup> = {:.1}, {} degrees of freedom, \
             p = {:.4}: {}</p><div>{}{}</div>",
            o.name,
            if pass { "pass" } else { "fail" },
            o.chi2,
            o.dof,
            o.p_value,
            if pass { "accepted" } else { "rejected" },
            histogram(&o.observed, o.columns, &o.expected),
            histogram(&o.expected, o.columns, &o.expected)
        );
    }
    s.push_str("</body></html>\n");
    s
}

/// One histogram as inline SVG, grey levels scaled to the largest expected count.
fn histogram(v: &[f64], columns: usize, scale: &[f64]) -> String {
    let max = scale.iter().cloned().fold(0.0, f64::max).max(1e-12);
    let rows = v.len() / columns;
    let cell = if columns == 2 { 60 } else { 8 };
    let mut s = format!(
        "<svg width=\"{}\" height=\"{}\" xmlns=\"http://www.w3.org/2000/svg\">",
        columns * cell,
        rows * cell
    );
    for (i, &c) in v.iter().enumerate() {
        let g = (255.0 * (1.0 - (c / max).min(1.0))) as u8;
        let _ = write!(
            s,
            "<rect x=\"{}\" y=\"{}\" width=\"{cell}\" height=\"{cell}\" fill=\"rgb({g},{g},{g})\">\
             <title>{c:.1}</title></rect>",
            (i % columns) * cell,
            (i / columns) * cell
        );
    }
    s.push_str("</svg>");
    s
}

//! Property tests of the materials: the course reflectance, mirrors and Snell refraction.

use glam::Vec3A;
use proptest::prelude::*;
use rtis::material::{Mirror, Phong, Transmissive};

fn unit() -> impl Strategy<Value = Vec3A> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_filter("non-degenerate", |(x, y, z)| x * x + y * y + z * z > 1e-3)
        .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize())
}

fn phong() -> impl Strategy<Value = Phong> {
    (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1000.0).prop_map(|(kd, ks, s)| Phong {
        kd: Vec3A::splat(kd),
        ks: Vec3A::splat(ks),
        shininess: s,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(5000))]

    /// r(wi, wo) >= 0 and finite for all directions, including below the surface and even
    /// exponents (the original's unclamped lobe went negative or lit back faces).
    #[test]
    fn course_reflectance_is_nonnegative_and_finite(p in phong(), wi in unit(), wo in unit(), n in unit()) {
        let r = p.course_reflectance(wi, wo, n);
        prop_assert!(r.is_finite() && r.min_element() >= 0.0, "{r}");
        let f = p.brdf(wi, wo, n);
        prop_assert!(f.is_finite() && f.min_element() >= 0.0, "{f}");
    }

    /// Mirror reflection preserves the angle to the normal and stays in the plane of wo and n.
    #[test]
    fn mirror_preserves_angles(wo in unit(), n in unit()) {
        let m = Mirror { color: Vec3A::ONE };
        let wr = m.reflect(wo, n);
        prop_assert!((wr.length() - 1.0).abs() < 1e-5);
        prop_assert!((wr.dot(n) - wo.dot(n)).abs() < 1e-5);
        prop_assert!((wr + wo).cross(n).length() < 1e-4);
    }

    /// Snell's law, reversibility, and total internal reflection exactly when sin(theta_t) > 1.
    #[test]
    fn refraction_obeys_snell(ior in 0.2f32..3.0, wo in unit(), n in unit()) {
        let g = Transmissive { ior, color: Vec3A::ONE };
        let r = g.refract(wo, n);
        let entering = wo.dot(n) > 0.0;
        let eta = if entering { 1.0 / ior } else { ior };
        prop_assert!((r.eta - eta).abs() < 1e-6);
        let cos_i = wo.dot(n).abs();
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        let sin_t = eta * sin_i;
        prop_assert!(r.wt.is_finite() && (r.wt.length() - 1.0).abs() < 1e-4);
        if sin_t > 1.0 + 1e-5 {
            prop_assert!(r.total_internal_reflection);
            prop_assert!((r.wt.dot(n) - wo.dot(n)).abs() < 1e-4, "TIR reflects");
        } else if sin_t < 1.0 - 1e-5 {
            prop_assert!(!r.total_internal_reflection);
            // The transmitted ray is on the other side, with sin(theta_t) = eta sin(theta_i).
            prop_assert!(r.wt.dot(n) * wo.dot(n) <= 0.0);
            let cos_t = r.wt.dot(n).abs();
            let got = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            prop_assert!((got - sin_t).abs() < 2e-3, "sin_t {got} vs {sin_t}");
            // Reversible: light arriving along -wt from the other side leaves along wo.
            // (`refract` takes the direction pointing away from the surface on the incident
            // side, which for the reverse path is wt.)
            if sin_t < 0.99 && sin_i < 0.99 {
                let back = g.refract(r.wt, n);
                prop_assert!(!back.total_internal_reflection);
                prop_assert!((back.wt - wo).length() < 2e-3, "{} vs {}", back.wt, wo);
            }
        }
    }
}

/// The Fresnel reflectance against the textbook form in angles (Hecht): with Snell's
/// `sin t = eta sin i`, `R_s = (sin(i - t) / sin(i + t))^2`, `R_p = (tan(i - t) / tan(i + t))^2`
/// and `F = (R_s + R_p) / 2`, at oblique angles into and out of glass (normal incidence alone
/// cannot tell the two polarisations' formulas apart).
#[test]
fn fresnel_matches_the_angle_form_at_oblique_incidence() {
    use rtis::material::fresnel_dielectric;
    for eta in [1.0 / 1.5f64, 1.0 / 2.4, 1.5] {
        for deg in [10.0f64, 30.0, 45.0, 60.0, 80.0] {
            let i = deg.to_radians();
            let sin_t = eta * i.sin();
            if sin_t >= 1.0 {
                assert_eq!(fresnel_dielectric(i.cos() as f32, eta as f32), 1.0);
                continue;
            }
            let t = sin_t.asin();
            let rs = ((i - t).sin() / (i + t).sin()).powi(2);
            let rp = ((i - t).tan() / (i + t).tan()).powi(2);
            let want = 0.5 * (rs + rp);
            let got = fresnel_dielectric(i.cos() as f32, eta as f32) as f64;
            assert!(
                (got - want).abs() < 1e-5,
                "eta {eta}, {deg} deg: {got} vs {want}"
            );
        }
    }
}

//! Choosing one point light at a shading point in proportion to the light it could send there.
//!
//! The path tracer's `lights_per_vertex: Importance` picks its point light this way: light `j`
//! is chosen with probability `w_j / sum_k w_k`, where `w_j = I_j cos(theta_j) / d_j^2` is its
//! unshadowed irradiance at the point (`I_j` the largest channel of its intensity, `theta_j`
//! the angle between the normal and the direction to the light, zero below the surface). This
//! is the importance pbrt-v4's light BVH gives a point light. On a diffuse surface lit by grey
//! lights, the estimate `L_j f cos / P(j)` is then the same for every choice: only visibility
//! is left to vary.

use super::Light;
use glam::Vec3A;

/// The unshadowed irradiance `I cos(theta) / d^2` that `light` sends to `p` across the unit
/// normal `n`, with `I` its largest channel (a spot's times its falloff towards `p`; a sun's
/// `E cos(theta)`, with no distance), in double precision (finite for every finite
/// input: `I <= f32::MAX` and `d^2 >= 2^-149`). Zero when the light is below the surface or
/// coincides with `p`, exactly when [`Light::incident`] gives no light facing `n`; with
/// `transmits` (a surface that passes light, as rough glass), `|cos(theta)|` on either side.
#[inline]
pub fn importance(light: &Light, p: Vec3A, n: Vec3A, transmits: bool) -> f64 {
    let ((wi, _, d2), i_max) = match light {
        Light::Point(l) => (l.toward(p), l.intensity.max_element()),
        // The intensity towards `p`, with the falloff computed as `incident` computes it.
        Light::Spot(l) => {
            let toward = l.toward(p);
            let falloff = l.falloff(-toward.0.dot(l.axis));
            (toward, l.intensity.max_element() * falloff)
        }
        // A directional light's irradiance `E cos(theta)`: no distance (`d^2 = 1` stands in).
        Light::Directional(l) => (
            (l.incident().wi, f32::INFINITY, 1.0),
            l.irradiance.max_element(),
        ),
    };
    // The direction and cosine exactly as `Light::incident` and the light's term compute them,
    // so that a light with a term has a weight. Computed whatever the case and then selected:
    // whether a light is above the surface varies from vertex to vertex, and a branch on it
    // would be mispredicted.
    let cos = if transmits {
        wi.dot(n).abs()
    } else {
        wi.dot(n)
    };
    let lit = d2 != 0.0 && d2.is_finite() && cos > 0.0 && i_max > 0.0;
    let w = f64::from(i_max.max(0.0)) * f64::from(cos) / f64::from(d2);
    if lit { w } else { 0.0 }
}

/// How many lights' weights [`choose_by_importance`] keeps between its two passes; the weights
/// of any further lights are computed twice.
const CACHED: usize = 16;

/// The point light that `u`, uniform in [0, 1), picks among `lights` at `p` with normal `n`,
/// each in proportion to its [`importance`] (from both sides when the surface `transmits`), with
/// the probability of picking it; `None` when no light has any importance there (none lights
/// the point).
#[inline]
pub fn choose_by_importance(
    lights: &[Light],
    p: Vec3A,
    n: Vec3A,
    transmits: bool,
    u: f64,
) -> Option<(usize, f64)> {
    // Total importance, keeping the first lights' weights for the second pass.
    let mut cached = [0.0f64; CACHED];
    let mut total = 0.0;
    for (k, light) in lights.iter().enumerate() {
        let w = importance(light, p, n, transmits);
        if let Some(c) = cached.get_mut(k) {
            *c = w;
        }
        total += w;
    }
    if total <= 0.0 {
        return None;
    }
    let weight = |k: usize| match cached.get(k) {
        Some(&w) => w,
        None => importance(&lights[k], p, n, transmits),
    };
    // The first light whose cumulative weight exceeds u * total: the number of lights whose
    // cumulative weight does not (a prefix, as the sums never decrease), counted without a
    // branch on the data. A light of weight 0 adds nothing to the sum, so it is never first.
    let target = u * total;
    let mut acc = 0.0;
    let mut j = 0;
    for k in 0..lights.len() {
        acc += weight(k);
        j += usize::from(acc <= target);
    }
    // Defensive: `u < 1` and the same sums in the same order keep u * total below the last
    // cumulative weight, but should that ever fail, the last light of weight takes it.
    if j == lights.len() {
        j = (0..lights.len()).rev().find(|&k| weight(k) > 0.0)?;
    }
    Some((j, weight(j) / total))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::PointLight;

    fn point(x: f32, y: f32, z: f32, i: f32) -> Light {
        Light::Point(PointLight {
            position: Vec3A::new(x, y, z),
            intensity: Vec3A::new(i, 0.5 * i, 0.25 * i),
            in_room: false,
        })
    }

    /// On a grid of `u`, each light is chosen as often as its probability says, to within one
    /// grid step, and the probability returned is its importance over the total.
    #[test]
    fn choice_follows_importance() {
        let lights = [
            point(0.0, 1.0, 0.0, 2.0),
            point(3.0, 1.0, 0.0, 5.0),
            point(0.0, -1.0, 0.0, 9.0), // below the surface: never chosen
            point(-1.0, 0.5, 2.0, 0.5),
        ];
        let (p, n) = (Vec3A::ZERO, Vec3A::Y);
        let w: Vec<f64> = lights.iter().map(|l| importance(l, p, n, false)).collect();
        let total: f64 = w.iter().sum();
        assert_eq!(w[2], 0.0);
        // Light 0: I = 2, d = 1, cos = 1.
        assert!((w[0] - 2.0).abs() < 1e-6, "{}", w[0]);
        let steps = 100_000;
        let mut counts = [0usize; 4];
        for k in 0..steps {
            let u = (k as f64 + 0.5) / steps as f64;
            let (j, pmf) = choose_by_importance(&lights, p, n, false, u).unwrap();
            assert_eq!(pmf, w[j] / total);
            counts[j] += 1;
        }
        for j in 0..4 {
            let want = w[j] / total * steps as f64;
            assert!(
                (counts[j] as f64 - want).abs() <= 1.0,
                "light {j}: {} of {steps}, want {want:.1}",
                counts[j]
            );
        }
    }

    /// The defensive end: should `u * total` reach the last cumulative weight (`u = 1`, outside
    /// the contract), the last light with a weight is chosen, never one of weight 0 after it.
    #[test]
    fn a_u_past_the_end_takes_the_last_light_of_weight() {
        let lights = [
            point(0.0, 1.0, 0.0, 2.0),
            point(3.0, 1.0, 0.0, 5.0),
            point(0.0, -1.0, 0.0, 9.0), // below the surface: weight 0
        ];
        let (p, n) = (Vec3A::ZERO, Vec3A::Y);
        let (j, pmf) = choose_by_importance(&lights, p, n, false, 1.0).unwrap();
        assert_eq!(j, 1);
        assert!(pmf > 0.0);
    }

    /// Past the weights kept between the passes (more than 16 lights), the choice and its
    /// probability are still those of the cumulative weights, checked against a direct search.
    #[test]
    fn many_lights_choose_as_few_do() {
        let lights: Vec<Light> = (0..40)
            .map(|k| {
                let a = k as f32 * 0.37;
                // Every fifth light below the surface: weight 0.
                let y = if k % 5 == 0 {
                    -1.0
                } else {
                    0.5 + 0.1 * k as f32
                };
                point(a.cos() * 2.0, y, a.sin() * 2.0, 1.0 + (k % 7) as f32)
            })
            .collect();
        let (p, n) = (Vec3A::new(0.1, 0.0, -0.2), Vec3A::Y);
        let w: Vec<f64> = lights.iter().map(|l| importance(l, p, n, false)).collect();
        let total: f64 = w.iter().sum();
        for k in 0..1000 {
            let u = (k as f64 + 0.5) / 1000.0;
            let (j, pmf) = choose_by_importance(&lights, p, n, false, u).unwrap();
            let mut acc = 0.0;
            let first = w
                .iter()
                .position(|&x| {
                    acc += x;
                    acc > u * total
                })
                .unwrap();
            assert_eq!((j, pmf), (first, w[first] / total), "u = {u}");
            assert!(w[j] > 0.0);
        }
    }

    /// No light above the surface, or none at all: nothing to choose. A light at the point
    /// itself has no direction and no weight.
    #[test]
    fn nothing_to_choose() {
        let below = [point(0.0, -1.0, 0.0, 1.0), point(0.0, 0.0, 0.0, 1.0)];
        assert_eq!(
            choose_by_importance(&below, Vec3A::ZERO, Vec3A::Y, false, 0.3),
            None
        );
        assert_eq!(
            choose_by_importance(&[], Vec3A::ZERO, Vec3A::Y, false, 0.3),
            None
        );
        // Through a surface that transmits, the light below counts, by |cos|: it is the only
        // one with a weight (the other sits at the point).
        assert_eq!(
            choose_by_importance(&below, Vec3A::ZERO, Vec3A::Y, true, 0.3),
            Some((0, 1.0))
        );
        assert_eq!(importance(&below[0], Vec3A::ZERO, Vec3A::Y, true), 1.0);
        // The largest u below 1 still picks a light.
        let one = [point(0.0, 1.0, 0.0, 1.0), point(0.0, 2.0, 0.0, 1.0)];
        let u = 1.0 - f64::EPSILON / 2.0;
        assert_eq!(
            choose_by_importance(&one, Vec3A::ZERO, Vec3A::Y, false, u).map(|c| c.0),
            Some(1)
        );
    }

    /// Extreme but valid inputs keep finite weights: the brightest light a scene may hold at
    /// the smallest distance, and the faintest at the largest.
    #[test]
    fn extreme_weights_stay_finite() {
        let near = Light::Point(PointLight {
            position: Vec3A::new(0.0, 1e-20, 0.0),
            intensity: Vec3A::splat(f32::MAX),
            in_room: false,
        });
        let far = Light::Point(PointLight {
            position: Vec3A::new(0.0, 1e18, 0.0),
            intensity: Vec3A::splat(f32::MIN_POSITIVE),
            in_room: false,
        });
        for l in [near, far] {
            let w = importance(&l, Vec3A::ZERO, Vec3A::Y, false);
            assert!(w.is_finite() && w > 0.0, "{w}");
        }
        let (j, pmf) =
            choose_by_importance(&[near, far], Vec3A::ZERO, Vec3A::Y, false, 0.5).unwrap();
        assert_eq!((j, pmf), (0, 1.0));
    }
}

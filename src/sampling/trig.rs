//! The sine and cosine of an angle given in turns, `phi = 2 pi u`, as every warp draws it.
//!
//! The warps draw `phi = 2 pi u` from a uniform `u` in `[0, 1)`. [`sin_cos_turns`] reduces `u`
//! to the nearest quarter turn exactly (no libm range reduction; the one rounding is of the
//! remainder times `2 pi`) and evaluates Taylor polynomials on the remaining eighth of a turn.
//! Its operations are plain additions, multiplications and comparisons, so the path tracer's
//! lanes (`shader::path::lanes`) repeat them lane by lane to the bit, and its results do not
//! depend on the C library's `sincosf`. (The concentric disk's angle, `powf` and the
//! environment's polar angle still use libm.)

use std::f32::consts::TAU;

/// `(sin 2 pi u, cos 2 pi u)` for `u` in `[0, 1]`, each within `1.2e-7` of the exact value
/// (checked at every multiple of `2^-24`, the sampler's numbers: at most `9.8e-8`).
///
/// Range reduction: `u = q / 4 + x` with `q` the nearest quarter (0 to 4) and `|x| <= 1/8`;
/// the subtraction is exact (Sterbenz: `u` lies within a factor of two of `q / 4`). Then
/// `a = 2 pi x` lies in `[-pi/4, pi/4]` (a hair beyond with `f32`'s `2 pi`), where the Taylor series of `sin a` to `a^9` and of
/// `cos a` to `a^10` are off by less than `(pi/4)^11 / 11!` (`1.7e-9`) and `(pi/4)^12 / 12!`
/// (`1.2e-10`); the rest of the error is `f32` rounding. A quarter turn rotates `(sin, cos)`
/// by swapping them and flipping signs, which is exact.
#[inline(always)]
pub fn sin_cos_turns(u: f32) -> (f32, f32) {
    debug_assert!((0.0..=1.0).contains(&u), "u = {u} outside [0, 1]");
    // The nearest quarter turn: each threshold passed adds a quarter.
    let (m1, m2, m3, m4) = (u >= 0.125, u >= 0.375, u >= 0.625, u >= 0.875);
    let quarter = match (m1, m2, m3, m4) {
        (_, _, _, true) => 1.0,
        (_, _, true, _) => 0.75,
        (_, true, _, _) => 0.5,
        (true, _, _, _) => 0.25,
        _ => 0.0,
    };
    let a = (u - quarter) * TAU;
    let (s, c) = sin_cos_eighth(a);
    // Rotate by the quarters: q = 1 gives (c, -s), q = 2 (-s, -c), q = 3 (-c, s).
    let odd = (m1 && !m2) || (m3 && !m4);
    let (neg_sin, neg_cos) = (m2 && !m4, m1 && !m3);
    let (sin, cos) = if odd { (c, s) } else { (s, c) };
    (
        if neg_sin { -sin } else { sin },
        if neg_cos { -cos } else { cos },
    )
}

/// Taylor coefficients of `(sin a - a) / a^3` in powers of `a^2`: `(-1)^k / (2k + 1)!` for
/// `k` from 1 (the series' first term, `a`, is added as it is).
pub const SIN_TAYLOR: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];

/// Taylor coefficients of `cos a` in powers of `a^2`: `(-1)^k / (2k)!`.
pub const COS_TAYLOR: [f32; 6] = [
    1.0,
    -0.5,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
];

/// `(sin a, cos a)` for `|a| <= pi/4` by [`SIN_TAYLOR`] and [`COS_TAYLOR`] in Horner's form.
#[inline(always)]
fn sin_cos_eighth(a: f32) -> (f32, f32) {
    let a2 = a * a;
    let s = SIN_TAYLOR[2] + a2 * SIN_TAYLOR[3];
    let s = SIN_TAYLOR[1] + a2 * s;
    let s = SIN_TAYLOR[0] + a2 * s;
    let sin = a + a * (a2 * s);
    let c = COS_TAYLOR[4] + a2 * COS_TAYLOR[5];
    let c = COS_TAYLOR[3] + a2 * c;
    let c = COS_TAYLOR[2] + a2 * c;
    let c = COS_TAYLOR[1] + a2 * c;
    let cos = COS_TAYLOR[0] + a2 * c;
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every `u` the sampler draws (multiples of `2^-24`) and the ends: within `1.2e-7` of
    /// double precision's `sin` and `cos`.
    #[test]
    fn every_sampler_value_is_within_its_bound() {
        let mut worst = 0.0f64;
        for k in 0..=(1u32 << 24) {
            let u = k as f32 / (1u32 << 24) as f32;
            let (s, c) = sin_cos_turns(u);
            let (es, ec) = (std::f64::consts::TAU * u as f64).sin_cos();
            worst = worst.max((s as f64 - es).abs()).max((c as f64 - ec).abs());
        }
        assert!(worst < 1.2e-7, "worst error {worst:e}");
    }

    /// The quarter turns are exact, with the signs of the rotation.
    #[test]
    fn quarter_turns_are_exact() {
        let bits = |(s, c): (f32, f32)| (s.to_bits(), c.to_bits());
        for (u, expected) in [
            (0.0, (0.0, 1.0)),
            (0.25, (1.0, -0.0)),
            (0.5, (-0.0, -1.0)),
            (0.75, (-1.0, 0.0)),
            (1.0, (0.0, 1.0)),
        ] {
            assert_eq!(bits(sin_cos_turns(u)), bits(expected), "u = {u}");
        }
    }

    /// Each octant's signs and order: the point `(cos, sin)` lies in the octant of `u`.
    #[test]
    fn each_octant_has_its_signs() {
        for k in 0..8 {
            let u = (k as f32 + 0.5) / 8.0;
            let (s, c) = sin_cos_turns(u);
            let angle = (s as f64).atan2(c as f64).rem_euclid(std::f64::consts::TAU);
            let octant = (angle / (std::f64::consts::TAU / 8.0)).floor() as i32;
            assert_eq!(octant, k, "u = {u}: ({s}, {c})");
        }
    }
}

//! The sampling warps in SIMD lanes, each lane's result the scalar warp's to the bit: the same
//! operations in the same order (no fused multiply-add), for the shaders' lanes kernels
//! (`path/lanes.rs`, `global/waves/lanes.rs`).

use crate::accel::Floats;
use crate::geometry::Frame;
use std::f32::consts::TAU;

/// [`crate::sampling::sin_cos_turns`] in lanes, operation for operation (the quarter chosen
/// by the same thresholds, the same Taylor polynomials in the same order, the same exact
/// swaps and sign flips), so each lane's pair is the scalar function's to the bit.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
pub unsafe fn sin_cos_turns<L: Floats>(u: L) -> (L, L) {
    // (`L::splat` written out below: no closure in a kernel of another instruction set.)
    // SAFETY: the caller vouches for the instruction set; so for every `unsafe` block below,
    // each makes values of `L`.
    use crate::sampling::trig::{COS_TAYLOR as C, SIN_TAYLOR as S};
    // The nearest quarter turn.
    let (m1, m2, m3, m4) = unsafe {
        (
            u.cmpge(L::splat(0.125)),
            u.cmpge(L::splat(0.375)),
            u.cmpge(L::splat(0.625)),
            u.cmpge(L::splat(0.875)),
        )
    };
    let quarter = unsafe {
        let q = L::select(m1, L::splat(0.25), L::splat(0.0));
        let q = L::select(m2, L::splat(0.5), q);
        let q = L::select(m3, L::splat(0.75), q);
        L::select(m4, L::splat(1.0), q)
    };
    let a = (u - quarter) * unsafe { L::splat(TAU) };
    // `sin_cos_eighth`: Horner's form.
    let a2 = a * a;
    let (sin, cos) = unsafe {
        let s = L::splat(S[2]) + a2 * L::splat(S[3]);
        let s = L::splat(S[1]) + a2 * s;
        let s = L::splat(S[0]) + a2 * s;
        let c = L::splat(C[4]) + a2 * L::splat(C[5]);
        let c = L::splat(C[3]) + a2 * c;
        let c = L::splat(C[2]) + a2 * c;
        let c = L::splat(C[1]) + a2 * c;
        (a + a * (a2 * s), L::splat(C[0]) + a2 * c)
    };
    // Rotate by the quarters.
    let odd = (m1 & !m2) | (m3 & !m4);
    let (sin, cos) = (L::select(odd, cos, sin), L::select(odd, sin, cos));
    (
        L::select(m2 & !m4, -sin, sin),
        L::select(m1 & !m3, -cos, cos),
    )
}

/// `frame.to_world(hemisphere::uniform(u1, u2))` in lanes: `cos(theta) = u1`, `phi = 2 pi
/// u2`, then `x s + y t + z n` summed left to right, as `Frame::to_world` sums it.
///
/// # Safety
/// The CPU must run `L`'s instruction set.
#[inline(always)]
pub unsafe fn uniform_hemisphere<L: Floats>(frame: &Frame, u1: L, u2: L) -> [L; 3] {
    // SAFETY: the caller vouches for the instruction set; so for every `unsafe` block below.
    let (zero, one) = unsafe { (L::splat(0.0), L::splat(1.0)) };
    // (No closure: one would not inline into a kernel of another instruction set.)
    let (s, t, n) = unsafe {
        (
            [
                L::splat(frame.s.x),
                L::splat(frame.s.y),
                L::splat(frame.s.z),
            ],
            [
                L::splat(frame.t.x),
                L::splat(frame.t.y),
                L::splat(frame.t.z),
            ],
            [
                L::splat(frame.n.x),
                L::splat(frame.n.y),
                L::splat(frame.n.z),
            ],
        )
    };
    // `hemisphere::uniform`.
    let sin_t = (one - u1 * u1).max(zero).sqrt();
    let (sin_p, cos_p) = unsafe { sin_cos_turns(u2) };
    let (x, y, z) = (sin_t * cos_p, sin_t * sin_p, u1);
    [
        x * s[0] + y * t[0] + z * n[0],
        x * s[1] + y * t[1] + z * n[1],
        x * s[2] + y * t[2] + z * n[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Isa, MAX_LANES};

    /// [`sin_cos_turns`] in lanes gives [`crate::sampling::sin_cos_turns`]'s bits for every
    /// number the sampler draws (multiples of `2^-24`) and for 1, in each instruction set.
    #[test]
    fn sin_cos_turns_in_lanes_is_the_scalar_function() {
        crate::accel::require_all_isas();
        // SAFETY: `Vec4` runs everywhere; the others only where the CPU has them.
        unsafe { agrees::<glam::Vec4>() };
        #[cfg(target_arch = "x86_64")]
        if Isa::Avx2.available() {
            unsafe { agrees::<crate::accel::F8>() };
        }
        #[cfg(target_arch = "x86_64")]
        if Isa::Avx512.available() {
            unsafe { agrees::<crate::accel::F16>() };
        }
    }

    /// [`uniform_hemisphere`] gives `frame.to_world(hemisphere::uniform(u1, u2))`'s bits, on
    /// frames about normals of every octant and the axes, for numbers on a grid that reaches
    /// 0 and 1, in each instruction set.
    #[test]
    fn uniform_hemisphere_in_lanes_is_the_scalar_warp() {
        crate::accel::require_all_isas();
        // SAFETY: `Vec4` runs everywhere; the others only where the CPU has them.
        unsafe { hemisphere_agrees::<glam::Vec4>() };
        #[cfg(target_arch = "x86_64")]
        if Isa::Avx2.available() {
            unsafe { hemisphere_agrees::<crate::accel::F8>() };
        }
        #[cfg(target_arch = "x86_64")]
        if Isa::Avx512.available() {
            unsafe { hemisphere_agrees::<crate::accel::F16>() };
        }
    }

    /// # Safety
    /// The CPU must run `L`'s instruction set.
    unsafe fn hemisphere_agrees<L: Floats>() {
        use crate::sampling::hemisphere;
        use glam::Vec3A;
        let mut normals = vec![Vec3A::X, -Vec3A::Y, Vec3A::Z, -Vec3A::Z];
        for k in 0..8 {
            let sign = |bit: u32| if k & bit == 0 { 1.0 } else { -1.0 };
            normals.push(Vec3A::new(sign(1) * 0.3, sign(2) * 0.8, sign(4) * 0.52).normalize());
        }
        let steps = 97u32;
        let grid: Vec<(f32, f32)> = (0..=steps)
            .flat_map(|i| {
                (0..=steps).map(move |j| (i as f32 / steps as f32, j as f32 / steps as f32))
            })
            .collect();
        let mut rows = [[0.0f32; MAX_LANES]; 3];
        for n in normals {
            let frame = Frame::from_normal(n);
            for chunk in grid.chunks(L::LANES) {
                let (mut u1, mut u2) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
                for (i, &(a, b)) in chunk.iter().enumerate() {
                    (u1[i], u2[i]) = (a, b);
                }
                // SAFETY: the caller's.
                let w = unsafe { uniform_hemisphere(&frame, L::from_array(u1), L::from_array(u2)) };
                for (row, x) in rows.iter_mut().zip(w) {
                    x.write_to(row);
                }
                for (i, &(a, b)) in chunk.iter().enumerate() {
                    let want = frame.to_world(hemisphere::uniform(a, b));
                    let got = Vec3A::new(rows[0][i], rows[1][i], rows[2][i]);
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.to_array().map(f32::to_bits),
                        "n = {n}, u = ({a}, {b}) in {} lanes",
                        L::LANES
                    );
                }
            }
        }
    }

    /// # Safety
    /// The CPU must run `L`'s instruction set.
    unsafe fn agrees<L: Floats>() {
        let n = 1u32 << 24;
        let mut u = [0.0f32; MAX_LANES];
        let (mut s, mut c) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
        for first in (0..=n).step_by(L::LANES) {
            for (i, u) in u.iter_mut().enumerate().take(L::LANES) {
                *u = (first + i as u32).min(n) as f32 / n as f32;
            }
            // SAFETY: the caller's.
            let (sl, cl) = unsafe { sin_cos_turns(L::from_slice(&u)) };
            sl.write_to(&mut s);
            cl.write_to(&mut c);
            for i in 0..L::LANES {
                let (es, ec) = crate::sampling::sin_cos_turns(u[i]);
                assert_eq!(
                    (s[i].to_bits(), c[i].to_bits()),
                    (es.to_bits(), ec.to_bits()),
                    "u = {} in {} lanes",
                    u[i],
                    L::LANES
                );
            }
        }
    }
}

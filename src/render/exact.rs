//! Exact sums of samples, so that a pixel's value does not depend on the order its samples are
//! added in: one machine or many passes merged give the same bits.
//!
//! Floating-point addition is not associative: summing a pixel's samples as one sequence, or as
//! the sums of three passes added afterwards, can differ in the last bit. rtis therefore sums
//! samples exactly. Every finite non-negative `f32` is an integer multiple of `2^-149` below
//! `2^128`, so a fixed-point number of 320 bits with that unit holds any sum of up to `2^40`
//! of them without rounding (a 320-bit "superaccumulator"). Adding is integer addition, which
//! is associative; the pixel's value is read once from the exact total.

use glam::Vec3A;
use std::ops::AddAssign;

/// Words of the accumulator: 320 bits, unit `2^-149`.
pub const WORDS: usize = 5;

/// The exact sum of finite non-negative `f32` values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ExactSum {
    /// Little-endian 64-bit words of the fixed-point total.
    pub words: [u64; WORDS],
}

impl ExactSum {
    /// Add `v`, a finite `f32 >= 0` (NaN, infinities and negatives are the caller's to drop).
    #[inline(always)]
    pub fn add(&mut self, v: f32) {
        debug_assert!(v.is_finite() && v >= 0.0);
        let bits = v.to_bits() & 0x7fff_ffff;
        let exp = bits >> 23;
        let frac = bits & 0x7f_ffff;
        // v = mantissa * 2^(shift - 149), with shift in [0, 253].
        let (mantissa, shift) = if exp == 0 {
            (frac, 0)
        } else {
            (frac | 0x80_0000, exp - 1)
        };
        if mantissa == 0 {
            return;
        }
        self.add_scaled(mantissa as u64, shift);
    }

    /// Add `v`, a finite `f64 >= 0` that is a whole multiple of `2^-149` below `2^171` (an
    /// exact sum of `f32` values; others are the caller's bug).
    #[inline]
    pub fn add_f64(&mut self, v: f64) {
        debug_assert!(v.is_finite() && v >= 0.0);
        let bits = v.to_bits() & 0x7fff_ffff_ffff_ffff;
        let exp = (bits >> 52) as i64;
        // A subnormal f64 is far below 2^-149: only zero is a multiple of it.
        if exp == 0 {
            debug_assert_eq!(bits, 0, "{v} is not a multiple of 2^-149");
            return;
        }
        // v = mantissa * 2^(exp - 1075) = mantissa * 2^(shift - 149).
        let mantissa = (bits & 0xf_ffff_ffff_ffff) | 1 << 52;
        let shift = exp - 1075 + 149;
        let (mantissa, shift) = if shift < 0 {
            // Its low bits are zero (a multiple of 2^-149): the shift drops nothing.
            debug_assert_eq!(mantissa & ((1 << -shift) - 1), 0, "{v}");
            (mantissa >> -shift, 0)
        } else {
            (mantissa, shift as u32)
        };
        self.add_scaled(mantissa, shift);
    }

    /// Add `mantissa * 2^(shift - 149)` (a mantissa of at most 64 bits).
    #[inline(always)]
    fn add_scaled(&mut self, mantissa: u64, shift: u32) {
        let (word, offset) = ((shift / 64) as usize, shift % 64);
        let wide = (mantissa as u128) << offset;
        if word + 1 < WORDS {
            // The two words it spans as one 128-bit add, the carry (rare) taken further up:
            // no loop whose length depends on the value.
            let both = self.words[word] as u128 | (self.words[word + 1] as u128) << 64;
            let (sum, carry) = both.overflowing_add(wide);
            (self.words[word], self.words[word + 1]) = (sum as u64, (sum >> 64) as u64);
            if carry {
                self.add_at(word + 2, 1);
            }
        } else {
            // The top word: what would go past it is beyond the accumulator's range.
            self.add_at(word, wide as u64);
        }
    }

    /// Add `x` at word `i`, carrying upwards.
    #[inline]
    fn add_at(&mut self, mut i: usize, mut x: u64) {
        while x != 0 && i < WORDS {
            let (s, carry) = self.words[i].overflowing_add(x);
            self.words[i] = s;
            x = carry as u64;
            i += 1;
        }
    }

    /// The total as `f64`: a function of the exact value only.
    pub fn to_f64(&self) -> f64 {
        let mut f = 0.0f64;
        for &w in self.words.iter().rev() {
            f = f * 18_446_744_073_709_551_616.0 + w as f64;
        }
        f * 2f64.powi(-149)
    }

    /// The total divided by `n`, as `f32` (a pixel's mean of `n` samples).
    pub fn mean(&self, n: u64) -> f32 {
        (self.to_f64() / n.max(1) as f64) as f32
    }
}

impl AddAssign for ExactSum {
    /// Exact: integer addition of the fixed-point totals.
    fn add_assign(&mut self, o: ExactSum) {
        let mut carry = 0u64;
        for (w, &x) in self.words.iter_mut().zip(&o.words) {
            let (s1, c1) = w.overflowing_add(x);
            let (s2, c2) = s1.overflowing_add(carry);
            *w = s2;
            carry = (c1 || c2) as u64;
        }
    }
}

/// The exact sums of a pixel's three channels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RgbSum(pub [ExactSum; 3]);

impl RgbSum {
    /// Add a sample's radiance (finite, non-negative).
    #[inline(always)]
    pub fn add(&mut self, l: Vec3A) {
        self.0[0].add(l.x);
        self.0[1].add(l.y);
        self.0[2].add(l.z);
    }

    /// The mean of `n` samples.
    pub fn mean(&self, n: u64) -> Vec3A {
        Vec3A::new(self.0[0].mean(n), self.0[1].mean(n), self.0[2].mean(n))
    }
}

impl AddAssign for RgbSum {
    fn add_assign(&mut self, o: RgbSum) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_sums_are_exact_and_order_free() {
        let vals = [
            1.0f32,
            1e-30,
            3.5e30,
            0.1,
            f32::MIN_POSITIVE / 8.0,
            7.25,
            f32::MAX,
        ];
        let mut fwd = ExactSum::default();
        vals.iter().for_each(|&v| fwd.add(v));
        let mut rev = ExactSum::default();
        vals.iter().rev().for_each(|&v| rev.add(v));
        let (mut a, mut b) = (ExactSum::default(), ExactSum::default());
        vals[..3].iter().for_each(|&v| a.add(v));
        vals[3..].iter().for_each(|&v| b.add(v));
        a += b;
        assert_eq!(fwd, rev);
        assert_eq!(fwd, a);
        let mut one = ExactSum::default();
        one.add(0.75);
        one.add(0.5);
        assert_eq!(one.to_f64(), 1.25);
        assert_eq!(one.mean(2), 0.625);
        let mut big = ExactSum::default();
        big.add(f32::MAX);
        assert_eq!(big.to_f64(), f32::MAX as f64);
        // An f64 that sums f32 values exactly lands on the bits of adding them one by one,
        // from the subnormal f32 to the largest.
        let f32_sub = f32::from_bits(1);
        for group in [
            &[1.0, 0.1, 7.25][..],
            &[f32_sub, f32::MIN_POSITIVE / 8.0],
            &[3.5e30],
            &[f32::MAX],
        ] {
            let (mut one_by_one, mut at_once) = (ExactSum::default(), ExactSum::default());
            let mut sum = 0.0f64;
            for &v in group {
                one_by_one.add(v);
                sum += v as f64;
            }
            at_once.add_f64(sum);
            assert_eq!(at_once, one_by_one, "{group:?}");
        }
        let mut tiny = ExactSum::default();
        tiny.add(f32::from_bits(1));
        assert_eq!(tiny.to_f64(), 2f64.powi(-149));
    }
}

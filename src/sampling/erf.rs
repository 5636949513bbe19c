//! The inverse error function, for samplers that invert a Gaussian's or Beckmann's cumulative
//! distribution.

use std::f64::consts::PI;

/// The inverse of the error function on (-1, 1) (infinite at the ends): Giles' single-precision
/// approximation ("Approximating the erfinv function", 2010), then Newton steps on `erf` to
/// double precision.
pub fn erf_inv(y: f64) -> f64 {
    if y <= -1.0 {
        return f64::NEG_INFINITY;
    }
    if y >= 1.0 {
        return f64::INFINITY;
    }
    let w = -((1.0 - y) * (1.0 + y)).ln();
    let mut x = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_36e-08;
        for c in [
            3.432_739_39e-07,
            -3.523_387_7e-06,
            -4.391_506_54e-06,
            0.000_218_580_87,
            -0.001_253_725_03,
            -0.004_177_681_64,
            0.246_640_727,
            1.501_409_41,
        ] {
            p = c + p * w;
        }
        p * y
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -0.000_200_214_257;
        for c in [
            0.000_100_950_558,
            0.001_349_343_22,
            -0.003_673_428_44,
            0.005_739_507_73,
            -0.007_622_461_3,
            0.009_438_870_47,
            1.001_674_06,
            2.832_976_82,
        ] {
            p = c + p * w;
        }
        p * y
    };
    // Newton on erf(x) = y: erf'(x) = 2 exp(-x^2) / sqrt(pi).
    for _ in 0..3 {
        let d = 2.0 / PI.sqrt() * (-x * x).exp();
        if d == 0.0 {
            break;
        }
        x -= (libm::erf(x) - y) / d;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `erf(erf_inv(y)) = y` across (-1, 1), to within double-precision rounding of `erf`
    /// (relative for tiny `y`; near the ends, where `erf` is flat, to 1e-14 absolute).
    #[test]
    fn erf_inv_inverts_erf() {
        for i in 1..2000 {
            let y = -1.0 + i as f64 / 1000.0;
            let x = erf_inv(y);
            assert!((libm::erf(x) - y).abs() < 1e-14, "y {y}: x {x}");
        }
        for y in [1e-300, 1e-10] {
            let x = erf_inv(y);
            let r = libm::erf(x) - y;
            assert!(
                x.is_finite() && r.abs() <= 1e-15 * y.abs().min(1e-1) + 1e-300,
                "y {y}: x {x}, residual {r}"
            );
        }
        for y in [1.0 - 1e-12, -(1.0 - 1e-15)] {
            let x = erf_inv(y);
            assert!(
                x.is_finite() && (libm::erf(x) - y).abs() < 1e-14,
                "y {y}: x {x}"
            );
        }
    }
}

//! Float lanes in the instruction set the CPU has: the closed set [`Isa`], one file per
//! variant, chosen at run time. [`Lanes8`] serves the wide BVH's node test (eight lanes in
//! every set: AVX-512 runs AVX2's); [`Floats`] serves the sphere and plane tests of batched
//! rays (four lanes in SSE, eight in AVX2, sixteen in AVX-512).
//!
//! Every variant computes the same IEEE operations lane by lane (no fused multiply-add), so
//! the queries' answers are bit-identical whichever runs; only the speed differs. The
//! build targets baseline x86-64, so a binary runs on any x86-64 CPU and takes AVX2 or
//! AVX-512 where [`Isa::detect`] finds it, as Embree's ISA dispatch does.

#[cfg(target_arch = "x86_64")]
pub mod avx2;
#[cfg(target_arch = "x86_64")]
pub mod avx512;
pub mod baseline;

/// The most lanes a [`Floats`] has (AVX-512's sixteen): the size of the arrays that the
/// batched queries and the lanes kernel fill a lane at a time.
pub const MAX_LANES: usize = 16;

/// The instruction sets the node test and the batched ray tests are written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// Two four-lane halves: SSE2 (part of every x86-64 CPU), or scalar code elsewhere.
    Baseline,
    /// One eight-lane AVX2 register (x86-64 only).
    Avx2,
    /// Sixteen-lane AVX-512F registers for the batched queries and the lanes kernel, AVX2
    /// for the node test (x86-64 only; every AVX-512 CPU has AVX2).
    Avx512,
}

impl Isa {
    /// The widest instruction set this CPU runs.
    pub fn detect() -> Isa {
        if Isa::Avx512.available() {
            Isa::Avx512
        } else if Isa::Avx2.available() {
            Isa::Avx2
        } else {
            Isa::Baseline
        }
    }

    /// True if this CPU runs the instruction set.
    pub fn available(self) -> bool {
        match self {
            Isa::Baseline => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(target_arch = "x86_64")]
            // `avx512f` as rustc enables it implies AVX2, FMA and F16C: all checked, though
            // every AVX-512 CPU has them.
            Isa::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
                    && std::arch::is_x86_feature_detected!("f16c")
            }
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Avx2 | Isa::Avx512 => false,
        }
    }

    /// Every instruction set this CPU runs, baseline first.
    pub fn all_available() -> Vec<Isa> {
        [Isa::Baseline, Isa::Avx2, Isa::Avx512]
            .into_iter()
            .filter(|isa| isa.available())
            .collect()
    }

    /// Its name, as the bench and `--isa` spell it.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Baseline => "baseline",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// How many rays a batched query or the lanes kernel holds at once ([`Floats::LANES`]).
    pub fn lanes(self) -> usize {
        match self {
            Isa::Baseline => 4,
            Isa::Avx2 => 8,
            Isa::Avx512 => 16,
        }
    }

    /// The instruction set of the wide BVH's node test (`Lanes8`): AVX-512 runs AVX2's, as a
    /// node's eight children fill eight lanes.
    pub fn node_test(self) -> Isa {
        match self {
            Isa::Avx512 => Isa::Avx2,
            isa => isa,
        }
    }
}

impl Default for Isa {
    /// [`Isa::detect`].
    fn default() -> Isa {
        Isa::detect()
    }
}

/// Eight `f32` lanes: what the node test needs of a SIMD register.
///
/// Implementations must compute each operation exactly as IEEE single precision does, lane by
/// lane (the comparisons are ordered: false where a lane is NaN), so that the variants agree
/// to the bit.
///
/// # Safety
/// Every method may run instructions of its set, which only the caller can vouch for: callers
/// must have checked that the CPU runs it (for [`Isa::Avx2`], [`Isa::available`]). The
/// baseline's methods are unsafe only because the trait's are.
pub trait Lanes8: Copy {
    /// `x` in every lane.
    unsafe fn splat(x: f32) -> Self;
    /// Eight grid coordinates as floats (exact: a byte fits a float's significand).
    unsafe fn widen(q: &[u8; 8]) -> Self;
    /// Eight floats, lane `k` from `x[k]`.
    unsafe fn load(x: &[f32; 8]) -> Self;
    /// Lane-wise `self + b`.
    unsafe fn add(self, b: Self) -> Self;
    /// Lane-wise `self - b`.
    unsafe fn sub(self, b: Self) -> Self;
    /// Lane-wise `self * b`.
    unsafe fn mul(self, b: Self) -> Self;
    /// Lane-wise minimum (`b` where either is NaN, as SSE's `minps`).
    unsafe fn min(self, b: Self) -> Self;
    /// Lane-wise maximum (`b` where either is NaN, as SSE's `maxps`).
    unsafe fn max(self, b: Self) -> Self;
    /// The lanes (bits 0 to 7) where `self <= b`.
    unsafe fn le(self, b: Self) -> u32;
    /// The lanes as an array.
    unsafe fn to_array(self) -> [f32; 8];
    /// The lanes (bits 0 to 7) of `x` that differ from `v`.
    unsafe fn ne_u32(x: &[u32; 8], v: u32) -> u32;
}

/// A vector of `f32` lanes with the operations of the sphere and plane tests
/// (`accel::lanes`): four lanes in a `glam::Vec4` on every CPU, eight in an AVX2 register,
/// sixteen in an AVX-512 one.
///
/// As for the node test's lanes, every operation is IEEE single precision lane by lane,
/// exactly as glam's `Vec4` computes it (negation and `copysign` as sign-bit operations, `max`
/// as SSE's `maxps`, ordered comparisons except `cmpne`, which is true where either lane is
/// NaN), so that a lane's answer does not depend on the vector it sits in. (Which NaN comes out of an
/// operation on two NaNs is left open, by IEEE and by the compiler, which may swap the
/// operands of a sum; every comparison treats all NaNs alike.)
///
/// # Safety
/// Making a value from nothing (`splat`, `from_slice`, `from_array`, `transpose3`) runs the
/// set's instructions, so only
/// callers that checked the CPU may do it; every other operation takes a value, whose existence
/// shows that the check was made: a vector, or a mask or an axis, which are made only from
/// vectors (comparisons, [`Floats::axis`]).
pub unsafe trait Floats:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    /// How many lanes (at most [`MAX_LANES`]).
    const LANES: usize;
    /// One flag per lane: a lane of all bits set or clear (SSE, AVX2), or one bit of a mask
    /// register (AVX-512).
    type Mask: Copy
        + std::ops::BitAnd<Output = Self::Mask>
        + std::ops::BitOr<Output = Self::Mask>
        + std::ops::Not<Output = Self::Mask>;
    /// `x` in every lane.
    ///
    /// # Safety
    /// The CPU must run the set.
    unsafe fn splat(x: f32) -> Self;
    /// The first [`Floats::LANES`] values of `x`, one per lane.
    ///
    /// # Safety
    /// The CPU must run the set; `x` holds at least `LANES` values.
    unsafe fn from_slice(x: &[f32]) -> Self;
    /// The first `LANES` values of `v`, one per lane, from registers (no trip through memory,
    /// which would stall the load behind the separate stores). `N` is at least `LANES` (a
    /// compile-time check).
    ///
    /// # Safety
    /// The CPU must run the set.
    unsafe fn from_array<const N: usize>(v: [f32; N]) -> Self;
    /// The `x`, `y` and `z` of the first `LANES` vectors of `v`, lane `i` from `v[i]`: a
    /// transposition by shuffles. `N` is at least `LANES` (a compile-time check).
    ///
    /// # Safety
    /// The CPU must run the set.
    unsafe fn transpose3<const N: usize>(v: &[&glam::Vec3A; N]) -> [Self; 3];
    /// The lanes, written to the first `LANES` values of `out`.
    fn write_to(self, out: &mut [f32]);
    /// The lanes of `bits` (bit `i` for lane `i`), packed in lane order into the first values
    /// of `out`, bits unchanged: a left-packing store, for queues in columns. Values of `out`
    /// past those (up to `LANES`) may be overwritten; `out` holds at least `LANES` values.
    fn compress(self, bits: u32, out: &mut [f32]);
    /// Lane-wise square root.
    fn sqrt(self) -> Self;
    /// Lane-wise absolute value (the sign bit cleared).
    fn abs(self) -> Self;
    /// Lane-wise magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// Lane-wise maximum (`b` where either is NaN).
    fn max(self, b: Self) -> Self;
    /// Lanes where `self >= b`.
    fn cmpge(self, b: Self) -> Self::Mask;
    /// Lanes where `self <= b`.
    fn cmple(self, b: Self) -> Self::Mask;
    /// Lanes where `self > b`.
    fn cmpgt(self, b: Self) -> Self::Mask;
    /// Lanes where `self < b`.
    fn cmplt(self, b: Self) -> Self::Mask;
    /// Lanes where `self != b` (NaN in either included).
    fn cmpne(self, b: Self) -> Self::Mask;
    /// `a` where `m` is set, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// True if any lane of `m` is set.
    fn any(m: Self::Mask) -> bool;
    /// True if every lane of `m` is set.
    fn all(m: Self::Mask) -> bool;
    /// The lanes of `m` as bits 0 to `LANES - 1`.
    fn bitmask(m: Self::Mask) -> u32;
    /// Lanes where the sign bits of `a`, `b` and `c` are not all the same (zeros and NaN by
    /// their sign bits too).
    fn signs_differ(a: Self, b: Self, c: Self) -> Self::Mask;
    /// A coordinate named per lane ([`Floats::axis`]), for [`Floats::pick`].
    type Axis: Copy;
    /// Coordinate 0 in the lanes of `x`, 1 in the others of `y`, 2 in the rest.
    fn axis(x: Self::Mask, y: Self::Mask) -> Self::Axis;
    /// In each lane, the coordinate of `v` (its first three values) that `axis` names there,
    /// bits unchanged: a permutation in one instruction with AVX-512, selects elsewhere.
    fn pick(v: &[f32; 4], axis: Self::Axis) -> Self;
}

/// For tests that compare instruction sets: panics if the environment asks for one the CPU
/// lacks (`RTIS_REQUIRE_AVX2=1`, which `.ci/run` sets, and `RTIS_REQUIRE_AVX512=1`, which it
/// sets where the CPU reports AVX-512F), so that a CI machine cannot pass by comparing the
/// baseline with itself.
pub fn require_all_isas() {
    for (var, isa) in [
        ("RTIS_REQUIRE_AVX2", Isa::Avx2),
        ("RTIS_REQUIRE_AVX512", Isa::Avx512),
    ] {
        if std::env::var_os(var).is_some_and(|v| v == "1") {
            assert!(
                isa.available(),
                "{var}=1 but this CPU does not run {}",
                isa.name()
            );
        }
    }
}

#[cfg(test)]
#[cfg(target_arch = "x86_64")]
mod tests {
    use super::avx2::Avx2;
    use super::baseline::Halves;
    use super::*;

    /// The values where implementations differ if they differ at all: NaN of both signs,
    /// zeros of both signs, infinities, a subnormal, the largest float and plain numbers.
    const SPECIALS: [f32; 12] = [
        f32::NAN,
        -f32::NAN,
        0.0,
        -0.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        1.0,
        -1.0,
        1e-45,
        f32::MAX,
        -3.5,
        2.0,
    ];

    /// Every lane operation gives the same bits in both instruction sets, on the values where
    /// implementations differ if they differ at all: NaN in either operand, zeros of both
    /// signs, infinities, equal operands, subnormals and bytes at both ends.
    #[test]
    fn every_lane_operation_agrees_bit_for_bit() {
        if !to_compare(Isa::Avx2) {
            return;
        }
        let (specials, n) = (SPECIALS, SPECIALS.len());
        let lanes = |k: usize| -> [f32; 8] { std::array::from_fn(|i| specials[(k + 3 * i) % n]) };
        let bits = |v: [f32; 8]| v.map(f32::to_bits);
        for a in 0..n {
            for b in 0..n {
                let (x, y) = (lanes(a), lanes(b));
                // SAFETY: AVX2 is present (checked above); the baseline runs everywhere.
                unsafe {
                    let h = |v: [f32; 8]| {
                        Halves([
                            glam::Vec4::from_slice(&v[..4]),
                            glam::Vec4::from_slice(&v[4..]),
                        ])
                    };
                    let (hx, hy) = (h(x), h(y));
                    // An `Avx2` is a `__m256`: eight `f32` lanes in order.
                    let v = |v: [f32; 8]| std::mem::transmute::<[f32; 8], Avx2>(v);
                    let (vx, vy) = (v(x), v(y));
                    assert_eq!(bits(hx.add(hy).to_array()), bits(vx.add(vy).to_array()));
                    assert_eq!(bits(hx.sub(hy).to_array()), bits(vx.sub(vy).to_array()));
                    assert_eq!(bits(hx.mul(hy).to_array()), bits(vx.mul(vy).to_array()));
                    assert_eq!(bits(hx.min(hy).to_array()), bits(vx.min(vy).to_array()));
                    assert_eq!(bits(hx.max(hy).to_array()), bits(vx.max(vy).to_array()));
                    assert_eq!(hx.le(hy), vx.le(vy), "{x:?} <= {y:?}");
                    assert_eq!(
                        bits(Halves::splat(x[0]).to_array()),
                        bits(Avx2::splat(x[0]).to_array())
                    );
                }
            }
        }
        for q in [[0u8, 1, 2, 127, 128, 254, 255, 7], [255; 8], [0; 8]] {
            // SAFETY: as above.
            unsafe {
                assert_eq!(
                    bits(Halves::widen(&q).to_array()),
                    bits(Avx2::widen(&q).to_array())
                );
            }
        }
        for c in [
            [0u32, 1, u32::MAX, 5, u32::MAX, 0, 1 << 31, 2],
            [u32::MAX; 8],
            [3; 8],
        ] {
            // SAFETY: as above.
            unsafe {
                assert_eq!(
                    Halves::ne_u32(&c, u32::MAX),
                    Avx2::ne_u32(&c, u32::MAX),
                    "{c:?}"
                );
            }
        }
    }

    /// True if this CPU runs `isa` to compare with the baseline; false (saying so) if not,
    /// which fails instead where the environment requires it ([`require_all_isas`]).
    fn to_compare(isa: Isa) -> bool {
        super::require_all_isas();
        let present = isa.available();
        if !present {
            eprintln!("no {} here: nothing to compare", isa.name());
        }
        present
    }

    /// The first `L::LANES` lanes' bits, every NaN as one: which NaN an operation on two NaNs
    /// returns depends on the order of its operands, which IEEE leaves open and the compiler
    /// may swap.
    fn lane_bits<L: Floats>(v: L) -> Vec<u32> {
        let mut out = [0.0; MAX_LANES];
        v.write_to(&mut out);
        nan_as_one(&out[..L::LANES])
    }

    /// The bits of `v`, every NaN as one (see [`lane_bits`]).
    fn nan_as_one(v: &[f32]) -> Vec<u32> {
        v.iter()
            .map(|x| if x.is_nan() { u32::MAX } else { x.to_bits() })
            .collect()
    }

    /// Every [`Floats`] operation of `L` gives the same bits as `glam::Vec4` on each quarter of
    /// its lanes, on the special values (NaN of both signs, signed zeros, infinities,
    /// subnormals, equal operands), and the transposition and gathers put each value in its
    /// lane.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    unsafe fn floats_agree_with_vec4<L: Floats>() {
        use glam::Vec4;
        let (specials, n) = (SPECIALS, SPECIALS.len());
        let lanes =
            |k: usize| -> [f32; MAX_LANES] { std::array::from_fn(|i| specials[(k + 5 * i) % n]) };
        let quarters = L::LANES / 4;
        // SAFETY: the caller vouches for `L`; `Vec4` runs everywhere.
        unsafe {
            let v4 = |q: &[Vec4]| -> Vec<u32> { q.iter().flat_map(|&v| lane_bits(v)).collect() };
            let mask4 = |q: &[u32]| -> u32 {
                q.iter()
                    .enumerate()
                    .fold(0, |acc, (k, &m)| acc | m << (4 * k))
            };
            // `all` and `any` on every lane: all set, then each lane clear in turn.
            let (one, zero) = (L::splat(1.0), L::splat(0.0));
            assert!(L::all(one.cmpgt(zero)) && L::any(one.cmpgt(zero)));
            assert!(!L::any(one.cmplt(zero)) && !L::all(one.cmplt(zero)));
            for lane in 0..L::LANES {
                let mut v = [1.0f32; MAX_LANES];
                v[lane] = -1.0;
                let m = L::from_array(v).cmpgt(zero);
                assert!(!L::all(m) && L::any(m), "lane {lane}");
                assert_eq!(L::bitmask(m), ((1u32 << L::LANES) - 1) & !(1 << lane));
            }
            for a in 0..n {
                for b in 0..n {
                    let (x, y) = (lanes(a), lanes(b));
                    let (xv, yv) = (L::from_slice(&x), L::from_slice(&y));
                    let xq: Vec<Vec4> = (0..quarters)
                        .map(|k| Vec4::from_slice(&x[4 * k..]))
                        .collect();
                    let yq: Vec<Vec4> = (0..quarters)
                        .map(|k| Vec4::from_slice(&y[4 * k..]))
                        .collect();
                    // `$e` over `p` and `q`, in `L`'s lanes and in `Vec4` quarters.
                    macro_rules! same {
                        (|$p:ident, $q:ident| $e:expr) => {{
                            #[allow(unused_variables)]
                            let wide = {
                                let ($p, $q) = (xv, yv);
                                $e
                            };
                            #[allow(unused_variables)]
                            let four: Vec<Vec4> = (0..quarters)
                                .map(|k| {
                                    let ($p, $q) = (xq[k], yq[k]);
                                    $e
                                })
                                .collect();
                            assert_eq!(lane_bits(wide), v4(&four), "{x:?} {y:?}");
                        }};
                    }
                    same!(|p, q| p + q);
                    same!(|p, q| p - q);
                    same!(|p, q| p * q);
                    same!(|p, q| p / q);
                    same!(|p, q| -p);
                    same!(|p, q| Floats::sqrt(p));
                    same!(|p, q| Floats::abs(p));
                    same!(|p, q| Floats::copysign(p, q));
                    same!(|p, q| Floats::max(p, q));
                    // `signs_differ` against the sign bits read lane by lane (with `-p`, a
                    // lane always differs).
                    for c in [xv, yv, -xv] {
                        let got = L::bitmask(L::signs_differ(xv, yv, c));
                        let mut cv = [0.0f32; MAX_LANES];
                        c.write_to(&mut cv);
                        let want = (0..L::LANES).fold(0, |m, i| {
                            let s = [x[i], y[i], cv[i]].map(|v| v.to_bits() >> 31);
                            m | (u32::from(s[0] != s[1] || s[0] != s[2]) << i)
                        });
                        assert_eq!(got, want, "{x:?} {y:?}");
                    }
                    let masks = |p: L, q: L| {
                        [p.cmpge(q), p.cmple(q), p.cmpgt(q), p.cmplt(q), p.cmpne(q)].map(L::bitmask)
                    };
                    let masks4 = |p: Vec4, q: Vec4| {
                        [p.cmpge(q), p.cmple(q), p.cmpgt(q), p.cmplt(q), p.cmpne(q)]
                            .map(|m| m.bitmask())
                    };
                    let per: Vec<[u32; 5]> = (0..quarters).map(|k| masks4(xq[k], yq[k])).collect();
                    let joined: [u32; 5] = std::array::from_fn(|i| {
                        mask4(&per.iter().map(|m| m[i]).collect::<Vec<u32>>())
                    });
                    assert_eq!(masks(xv, yv), joined, "{x:?} {y:?}");
                    let m = xv.cmplt(yv);
                    let mq: Vec<_> = (0..quarters).map(|k| xq[k].cmplt(yq[k])).collect();
                    let sel: Vec<Vec4> = (0..quarters)
                        .map(|k| Vec4::select(mq[k], xq[k], yq[k]))
                        .collect();
                    assert_eq!(lane_bits(L::select(m, xv, yv)), v4(&sel));
                    assert_eq!(L::any(m), mq.iter().any(|m| m.any()));
                    assert_eq!(L::all(m), mq.iter().all(|m| m.all()));
                    let quarter_masks = |f: &dyn Fn(usize) -> u32| {
                        mask4(&(0..quarters).map(f).collect::<Vec<u32>>())
                    };
                    assert_eq!(L::bitmask(!m), quarter_masks(&|k| (!mq[k]).bitmask()));
                    assert_eq!(
                        L::bitmask(m & xv.cmpne(yv)),
                        quarter_masks(&|k| (mq[k] & xq[k].cmpne(yq[k])).bitmask())
                    );
                    assert_eq!(
                        L::bitmask(m | xv.cmpne(yv)),
                        quarter_masks(&|k| (mq[k] | xq[k].cmpne(yq[k])).bitmask())
                    );
                    assert_eq!(lane_bits(L::from_array(x)), nan_as_one(&x[..L::LANES]));
                    let splat = [x[3]; MAX_LANES];
                    assert_eq!(lane_bits(L::splat(x[3])), nan_as_one(&splat[..L::LANES]));
                }
            }
            // The transposition: lane i holds vector i's coordinates.
            let v: [glam::Vec3A; MAX_LANES] =
                std::array::from_fn(|i| glam::Vec3A::new(i as f32, 10.0 + i as f32, -(i as f32)));
            let t = L::transpose3(&std::array::from_fn::<_, MAX_LANES, _>(|i| &v[i]));
            for (axis, lane) in t.iter().enumerate() {
                let want: Vec<u32> = (0..L::LANES).map(|i| v[i][axis].to_bits()).collect();
                assert_eq!(lane_bits(*lane), want, "axis {axis}");
            }
            // `pick`: each lane's coordinate as its axis names it, bits unchanged, for every
            // pattern of axes over the lanes (lane i's axis is digit i of k in base 3).
            let table = [-0.0f32, f32::MIN_POSITIVE / 4.0, -f32::INFINITY, 7.0];
            for k in 0..3usize.pow(6) {
                let named: [usize; MAX_LANES] =
                    std::array::from_fn(|i| k / 3usize.pow(i as u32 % 6) % 3);
                let v = L::from_array(named.map(|a| a as f32));
                let axis = L::axis(v.cmplt(L::splat(0.5)), v.cmplt(L::splat(1.5)));
                let want: Vec<u32> = (0..L::LANES).map(|i| table[named[i]].to_bits()).collect();
                assert_eq!(lane_bits(L::pick(&table, axis)), want, "axes {named:?}");
            }
        }
    }

    #[test]
    fn every_float_operation_agrees_bit_for_bit() {
        // SAFETY: `Vec4` runs everywhere.
        unsafe { floats_agree_with_vec4::<glam::Vec4>() };
        if to_compare(Isa::Avx2) {
            // SAFETY: AVX2 is present.
            unsafe { floats_agree_with_vec4::<super::avx2::F8>() };
        }
        if to_compare(Isa::Avx512) {
            // SAFETY: AVX-512F is present.
            unsafe { floats_agree_with_vec4::<super::avx512::F16>() };
        }
    }

    /// `compress` packs exactly the lanes of its bits, in lane order and with their bits
    /// unchanged (NaN payloads and signed zeros included), for every set of lanes in both
    /// instruction sets.
    #[test]
    fn compress_packs_the_lanes_of_its_bits_in_order() {
        use super::avx2::F8;
        use glam::Vec4;
        let values: [f32; 8] = [
            f32::from_bits(0x7fc0_1234),
            -0.0,
            1.0,
            f32::from_bits(0xffa0_0001),
            f32::INFINITY,
            2.5,
            1e-45,
            -7.0,
        ];
        let bits_of = |x: &[f32]| x.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
        for bits in 0..256u32 {
            let want: Vec<u32> = (0..8)
                .filter(|i| bits & (1 << i) != 0)
                .map(|i| values[i].to_bits())
                .collect();
            let (lo, hi) = (bits & 0xf, bits >> 4);
            let mut out = [0.0f32; 8];
            let (v, w) = (
                Vec4::from_slice(&values[..4]),
                Vec4::from_slice(&values[4..]),
            );
            v.compress(lo, &mut out);
            let n = lo.count_ones() as usize;
            w.compress(hi, &mut out[n..]);
            assert_eq!(
                bits_of(&out[..want.len()]),
                want,
                "baseline, lanes {bits:08b}"
            );
            if !to_compare(Isa::Avx2) {
                continue;
            }
            let mut out = [0.0f32; 8];
            // SAFETY: AVX2 is present (checked above).
            unsafe { F8::from_slice(&values) }.compress(bits, &mut out);
            assert_eq!(bits_of(&out[..want.len()]), want, "AVX2, lanes {bits:08b}");
        }
        if !to_compare(Isa::Avx512) {
            return;
        }
        // Sixteen lanes: the eight values and their negations, every set of lanes.
        let sixteen: [f32; 16] = std::array::from_fn(|i| match i < 8 {
            true => values[i],
            false => -values[i - 8],
        });
        // SAFETY: AVX-512F is present (checked above).
        let v = unsafe { super::avx512::F16::from_slice(&sixteen) };
        for bits in 0..1u32 << 16 {
            let want: Vec<u32> = (0..16)
                .filter(|i| bits & (1 << i) != 0)
                .map(|i| sixteen[i].to_bits())
                .collect();
            let mut out = [0.0f32; 16];
            v.compress(bits, &mut out);
            assert_eq!(
                bits_of(&out[..want.len()]),
                want,
                "AVX-512, lanes {bits:016b}"
            );
        }
    }
}

//! The lane arithmetic of the four-lane watertight triangle test, written once for two widths:
//! four lanes (glam's `Vec4`, SSE: one ray against a leaf's four triangles) and eight (two
//! rays against the same four triangles, AVX2 through `pulp`'s safe intrinsics). Each
//! operation is the same IEEE operation in both (the AVX2 compare predicates are those of the
//! SSE compares glam uses, `max` keeps SSE's operand order, `abs` clears the sign bit), so a
//! lane's answer is the same bits at either width.
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Not, Sub};

use glam::{BVec4A, Vec4};

/// A vector of `f32` lanes and the operations the triangle test uses.
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// The result of a compare, lane by lane.
    type Mask: Copy
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;

    /// `x` in every lane (a method of a vector so that the AVX2 type can carry its token).
    fn splat_as(self, x: f32) -> Self;
    fn cmp_eq(self, other: Self) -> Self::Mask;
    /// Not equal, or either NaN (SSE's `cmpneq`).
    fn cmp_ne(self, other: Self) -> Self::Mask;
    fn cmp_lt(self, other: Self) -> Self::Mask;
    fn cmp_le(self, other: Self) -> Self::Mask;
    fn cmp_gt(self, other: Self) -> Self::Mask;
    fn abs_lanes(self) -> Self;
    /// SSE's `max`: `other` when either is NaN.
    fn max_lanes(self, other: Self) -> Self;
    /// Bit `i` set when lane `i` of `m` is.
    fn bits(m: Self::Mask) -> u32;
}

impl Lanes for Vec4 {
    type Mask = BVec4A;

    #[inline(always)]
    fn splat_as(self, x: f32) -> Self {
        Vec4::splat(x)
    }
    #[inline(always)]
    fn cmp_eq(self, other: Self) -> BVec4A {
        self.cmpeq(other)
    }
    #[inline(always)]
    fn cmp_ne(self, other: Self) -> BVec4A {
        self.cmpne(other)
    }
    #[inline(always)]
    fn cmp_lt(self, other: Self) -> BVec4A {
        self.cmplt(other)
    }
    #[inline(always)]
    fn cmp_le(self, other: Self) -> BVec4A {
        self.cmple(other)
    }
    #[inline(always)]
    fn cmp_gt(self, other: Self) -> BVec4A {
        self.cmpgt(other)
    }
    #[inline(always)]
    fn abs_lanes(self) -> Self {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn max_lanes(self, other: Self) -> Self {
        Vec4::max(self, other)
    }
    #[inline(always)]
    fn bits(m: BVec4A) -> u32 {
        m.bitmask()
    }
}

#[cfg(target_arch = "x86_64")]
pub use avx2::F32x8;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::{__m256, _CMP_EQ_OQ, _CMP_GT_OS, _CMP_LE_OS, _CMP_LT_OS, _CMP_NEQ_UQ};
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Not, Sub};

    use glam::Vec4;
    use pulp::x86::V3;

    use super::Lanes;

    /// Eight `f32` lanes (AVX2), with the token that proves the CPU has them.
    #[derive(Clone, Copy)]
    pub struct F32x8 {
        v: __m256,
        simd: V3,
    }

    /// A compare's result in eight lanes.
    #[derive(Clone, Copy)]
    pub struct M32x8 {
        v: __m256,
        simd: V3,
    }

    impl F32x8 {
        /// Lanes 0–3 from `lo`, 4–7 from `hi`.
        #[inline(always)]
        pub fn halves(simd: V3, lo: Vec4, hi: Vec4) -> Self {
            let (lo, hi) = (pulp::cast(lo.to_array()), pulp::cast(hi.to_array()));
            F32x8 {
                v: simd.avx._mm256_set_m128(hi, lo),
                simd,
            }
        }

        /// `a` in lanes 0–3, `b` in 4–7.
        #[inline(always)]
        pub fn pair(simd: V3, a: f32, b: f32) -> Self {
            Self::halves(simd, Vec4::splat(a), Vec4::splat(b))
        }

        /// Lanes 0–3 and 4–7.
        #[inline(always)]
        pub fn split(self) -> ([f32; 4], [f32; 4]) {
            let a: [f32; 8] = pulp::cast(self.v);
            ([a[0], a[1], a[2], a[3]], [a[4], a[5], a[6], a[7]])
        }

        #[inline(always)]
        fn with(self, v: __m256) -> Self {
            F32x8 { v, simd: self.simd }
        }

        #[inline(always)]
        fn mask(self, v: __m256) -> M32x8 {
            M32x8 { v, simd: self.simd }
        }
    }

    /// `impl $trait for $ty` by one two-operand AVX intrinsic on the lanes.
    macro_rules! lane_op {
        ($ty:ident, $trait:ident, $method:ident, $intrinsic:ident) => {
            impl $trait for $ty {
                type Output = Self;
                #[inline(always)]
                fn $method(self, o: Self) -> Self {
                    $ty {
                        v: self.simd.avx.$intrinsic(self.v, o.v),
                        simd: self.simd,
                    }
                }
            }
        };
    }

    lane_op!(F32x8, Add, add, _mm256_add_ps);
    lane_op!(F32x8, Sub, sub, _mm256_sub_ps);
    lane_op!(F32x8, Mul, mul, _mm256_mul_ps);
    lane_op!(F32x8, Div, div, _mm256_div_ps);
    lane_op!(M32x8, BitAnd, bitand, _mm256_and_ps);
    lane_op!(M32x8, BitOr, bitor, _mm256_or_ps);

    impl Not for M32x8 {
        type Output = Self;
        #[inline(always)]
        fn not(self) -> Self {
            let all = self
                .simd
                .avx
                ._mm256_castsi256_ps(self.simd.avx._mm256_set1_epi32(-1));
            M32x8 {
                v: self.simd.avx._mm256_xor_ps(self.v, all),
                simd: self.simd,
            }
        }
    }

    impl Lanes for F32x8 {
        type Mask = M32x8;

        #[inline(always)]
        fn splat_as(self, x: f32) -> Self {
            self.with(self.simd.avx._mm256_set1_ps(x))
        }
        #[inline(always)]
        fn cmp_eq(self, o: Self) -> M32x8 {
            self.mask(self.simd.avx._mm256_cmp_ps::<_CMP_EQ_OQ>(self.v, o.v))
        }
        #[inline(always)]
        fn cmp_ne(self, o: Self) -> M32x8 {
            self.mask(self.simd.avx._mm256_cmp_ps::<_CMP_NEQ_UQ>(self.v, o.v))
        }
        #[inline(always)]
        fn cmp_lt(self, o: Self) -> M32x8 {
            self.mask(self.simd.avx._mm256_cmp_ps::<_CMP_LT_OS>(self.v, o.v))
        }
        #[inline(always)]
        fn cmp_le(self, o: Self) -> M32x8 {
            self.mask(self.simd.avx._mm256_cmp_ps::<_CMP_LE_OS>(self.v, o.v))
        }
        #[inline(always)]
        fn cmp_gt(self, o: Self) -> M32x8 {
            self.mask(self.simd.avx._mm256_cmp_ps::<_CMP_GT_OS>(self.v, o.v))
        }
        #[inline(always)]
        fn abs_lanes(self) -> Self {
            let sign = self.simd.avx._mm256_set1_ps(-0.0);
            self.with(self.simd.avx._mm256_andnot_ps(sign, self.v))
        }
        #[inline(always)]
        fn max_lanes(self, o: Self) -> Self {
            self.with(self.simd.avx._mm256_max_ps(self.v, o.v))
        }
        #[inline(always)]
        fn bits(m: M32x8) -> u32 {
            m.simd.avx._mm256_movemask_ps(m.v) as u32
        }
    }
}

//! The one seeded random number generator of the crate, its tests and benches: PCG32
//! (O'Neill 2014, `pcg32` = XSH-RR output on a 64-bit LCG state).
//!
//! It is for reproducible random *inputs* — test scenes, stress rays, benchmark rays —
//! never for anything a render depends on: image sampling uses hashes of pixel and
//! point coordinates ([`hash`](super::hash)), which do not depend on an order of calls.

use super::Vec3;

/// The LCG multiplier of PCG's 64-bit state.
const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// The stream of [`Rng::new`]: the one whose increment is that of the reference
/// implementation's `PCG32_INITIALIZER`.
const DEFAULT_STREAM: u64 = 0xda3e_39cb_94b9_5bdb >> 1;

/// A small, fast, seeded generator (PCG32: 64 bits of state, 32-bit outputs, period
/// 2⁶⁴ per stream). The same seed gives the same sequence on every platform.
///
/// ```
/// use emray::math::Rng;
/// let mut a = Rng::new(7);
/// let mut b = Rng::new(7);
/// assert_eq!(a.next_u32(), b.next_u32());
/// let x = a.range(-1.0, 1.0);
/// assert!((-1.0..=1.0).contains(&x));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rng {
    state: u64,
    /// The stream's increment (always odd).
    inc: u64,
}

impl Rng {
    /// A generator seeded with `seed` on the default stream.
    pub fn new(seed: u64) -> Rng {
        Rng::with_stream(seed, DEFAULT_STREAM)
    }

    /// A generator seeded with `seed` on stream `stream` (only its low 63 bits count):
    /// generators on different streams give unrelated sequences for the same seed.
    /// Seeded as the reference `pcg32_srandom_r(seed, stream)`.
    pub fn with_stream(seed: u64, stream: u64) -> Rng {
        let mut rng = Rng {
            state: 0,
            inc: (stream << 1) | 1,
        };
        rng.step();
        rng.state = rng.state.wrapping_add(seed);
        rng.step();
        rng
    }

    /// Advance the LCG state.
    #[inline]
    fn step(&mut self) {
        self.state = self.state.wrapping_mul(MULTIPLIER).wrapping_add(self.inc);
    }

    /// The next 32 uniformly distributed bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.step();
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// The next 64 uniformly distributed bits (two outputs, the first in the high half).
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let hi = u64::from(self.next_u32());
        (hi << 32) | u64::from(self.next_u32())
    }

    /// Uniform in `[0, 1)`, a multiple of 2⁻²⁴ (every such value equally likely).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Uniform in `[0, 1)`, a multiple of 2⁻⁵³ (every such value equally likely).
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform between `lo` and `hi`: `lo + (hi − lo) u` for `u` from
    /// [`Rng::next_f32`], so in `[lo, hi)` up to the rounding of that expression.
    #[inline]
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }

    /// [`Rng::range`] in double precision, from [`Rng::next_f64`].
    #[inline]
    pub fn range_f64(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A point uniform in the box `[lo, hi)³`: [`Rng::range`] for x, then y, then z.
    #[inline]
    pub fn vec3_in(&mut self, lo: f32, hi: f32) -> Vec3 {
        let x = self.range(lo, hi);
        let y = self.range(lo, hi);
        let z = self.range(lo, hi);
        Vec3::new(x, y, z)
    }

    /// Uniform in `0..n`, without bias (Lemire's multiply-and-reject).
    ///
    /// # Panics
    /// When `n` is 0.
    pub fn below(&mut self, n: u32) -> u32 {
        assert!(n > 0, "Rng::below(0): an empty range");
        let mut m = u64::from(self.next_u32()) * u64::from(n);
        if (m as u32) < n {
            // Reject the low products that would make some results more likely.
            let threshold = n.wrapping_neg() % n;
            while (m as u32) < threshold {
                m = u64::from(self.next_u32()) * u64::from(n);
            }
        }
        (m >> 32) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference implementation's `pcg32-demo` output for `pcg32_srandom(42, 54)`.
    #[test]
    fn matches_the_reference_pcg32() {
        let mut rng = Rng::with_stream(42, 54);
        let want = [
            0xa15c_02b7u32,
            0x7b47_f409,
            0xba1d_3330,
            0x83d2_f293,
            0xbfa4_784b,
            0xcbed_606e,
        ];
        for w in want {
            assert_eq!(rng.next_u32(), w);
        }
    }

    #[test]
    fn same_seed_same_sequence_other_seed_or_stream_other_sequence() {
        let take = |mut r: Rng| (0..64).map(|_| r.next_u32()).collect::<Vec<_>>();
        assert_eq!(take(Rng::new(1)), take(Rng::new(1)));
        assert_eq!(take(Rng::new(1).clone()), take(Rng::new(1)));
        assert_ne!(take(Rng::new(1)), take(Rng::new(2)));
        assert_ne!(take(Rng::with_stream(1, 0)), take(Rng::with_stream(1, 1)));
    }

    /// 2¹⁶ draws into 16 equal bins: Pearson's χ² (15 degrees of freedom) stays below
    /// 37.7, which a uniform source exceeds with probability 0.001; and the mean is
    /// within 0.005 of 1/2 (about 4 standard errors).
    #[test]
    fn floats_are_uniform_in_the_unit_interval() {
        const N: usize = 1 << 16;
        let mut rng = Rng::new(0x5eed);
        let mut bins32 = [0usize; 16];
        let mut bins64 = [0usize; 16];
        let (mut sum32, mut sum64) = (0.0f64, 0.0f64);
        for _ in 0..N {
            let (a, b) = (rng.next_f32(), rng.next_f64());
            assert!((0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
            bins32[(a * 16.0) as usize] += 1;
            bins64[(b * 16.0) as usize] += 1;
            sum32 += f64::from(a);
            sum64 += b;
        }
        let expected = N as f64 / 16.0;
        let chi2 = |bins: &[usize; 16]| -> f64 {
            bins.iter()
                .map(|&c| (c as f64 - expected).powi(2) / expected)
                .sum()
        };
        assert!(chi2(&bins32) < 37.7, "f32: χ² = {}", chi2(&bins32));
        assert!(chi2(&bins64) < 37.7, "f64: χ² = {}", chi2(&bins64));
        assert!(
            (sum32 / N as f64 - 0.5).abs() < 0.005,
            "{}",
            sum32 / N as f64
        );
        assert!(
            (sum64 / N as f64 - 0.5).abs() < 0.005,
            "{}",
            sum64 / N as f64
        );
    }

    #[test]
    fn ranges_stay_in_their_bounds_and_cover_them() {
        let mut rng = Rng::new(3);
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for _ in 0..10_000 {
            let x = rng.range(-2.0, 3.0);
            assert!((-2.0..3.0).contains(&x), "{x}");
            lo = lo.min(x);
            hi = hi.max(x);
            let y = rng.range_f64(10.0, 11.0);
            assert!((10.0..11.0).contains(&y), "{y}");
            let v = rng.vec3_in(-1.0, 1.0);
            assert!(v.cmpge(Vec3::splat(-1.0)).all() && v.cmplt(Vec3::ONE).all());
        }
        assert!(lo < -1.99 && hi > 2.99, "{lo} {hi}");
    }

    /// `below(n)` hits every value of `0..n` about equally often (χ² with n − 1 = 6
    /// degrees of freedom below 22.5, probability 0.001), also for `n` that does not
    /// divide 2³², and never reaches `n`.
    #[test]
    fn below_is_uniform_over_its_range() {
        let mut rng = Rng::new(11);
        let mut counts = [0usize; 7];
        for _ in 0..70_000 {
            counts[rng.below(7) as usize] += 1;
        }
        let chi2: f64 = counts
            .iter()
            .map(|&c| (c as f64 - 10_000.0).powi(2) / 10_000.0)
            .sum();
        assert!(chi2 < 22.5, "χ² = {chi2}: {counts:?}");
        assert!((0..1000).all(|_| rng.below(1) == 0));
        assert!((0..1000).all(|_| rng.below(u32::MAX) < u32::MAX));
    }

    #[test]
    #[should_panic(expected = "empty range")]
    fn below_zero_is_refused() {
        Rng::new(0).below(0);
    }
}

//! The value a number has once printed with `%g` ([`super::fmt_g`]) and read back by
//! the NFF loader (`str::parse`), computed without the text.
//!
//! `%g` keeps six significant digits: the integer `m = round(|x| · 10^k)` with `k`
//! chosen so that `10^5 ≤ |x| · 10^k < 10^6`, a tie going to the even neighbour. With
//! `|k| ≤ 22`, the scaled value `s` is `|x| · 10^k` correctly rounded, one operation on
//! exact operands. Rounding is monotonic and the ties `n + ½` are themselves doubles,
//! so `s` is on the same side of a tie as the exact product unless it lands on the tie
//! itself; then a fused multiply-add gives the exact remainder of the product (or
//! quotient), whose sign tells the side, and a remainder of zero an exact tie (binary
//! fractions such as `0.01171875` have many). `s = 10^5` may come from a product a
//! hair below, which `%g` rounds to `10^6 · 10^-(k+1)`: the same value. Reading
//! `m · 10^-k` is again one correctly rounded operation on exact operands (`m < 2^24`,
//! the power exact) when `|k| ≤ 22` (double precision) or `|k| ≤ 10` (single
//! precision), which is the correctly rounded value of the decimal: what `str::parse`
//! returns. Elsewhere, the text decides.

use super::fmt_g;
use std::cmp::Ordering;

/// Powers of ten exact in double precision.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];
/// Powers of ten exact in single precision.
const POW10_F32: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];

/// `x` printed with `%g` and read as an `f64`, bit for bit.
pub(crate) fn g_f64(x: f64) -> f64 {
    match six_digits(x) {
        Some((0, _)) => x, // ±0, its sign kept
        Some((m, k)) if (-22..=22).contains(&k) => {
            let v = if k >= 0 {
                m as f64 / POW10[k as usize]
            } else {
                m as f64 * POW10[(-k) as usize]
            };
            v.copysign(x)
        }
        _ => fmt_g(x).parse().unwrap_or(f64::NAN),
    }
}

/// `x` printed with `%g` and read as an `f32`, bit for bit.
pub(crate) fn g_f32(x: f64) -> f32 {
    match six_digits(x) {
        Some((0, _)) => x as f32,
        Some((m, k)) if (-10..=10).contains(&k) => {
            let v = if k >= 0 {
                m as f32 / POW10_F32[k as usize]
            } else {
                m as f32 * POW10_F32[(-k) as usize]
            };
            v.copysign(x as f32)
        }
        _ => fmt_g(x).parse().unwrap_or(f32::NAN),
    }
}

/// `|x|` to six significant digits as `m · 10^-k` (`m` of six digits, or `10^6` when
/// rounding carried), or `(0, 0)` for zero; `None` when it is not certain (see the
/// module documentation) or `x` is not finite.
#[inline]
fn six_digits(x: f64) -> Option<(u64, i32)> {
    let a = x.abs();
    if a == 0.0 {
        return Some((0, 0));
    }
    if !a.is_finite() {
        return None;
    }
    let mut k = 5 - decimal_exponent_floor(a);
    let mut scaled = scale(a, k)?;
    if scaled < 1e5 {
        k += 1;
        scaled = scale(a, k)?;
    } else if scaled >= 1e6 {
        k -= 1;
        scaled = scale(a, k)?;
    }
    if !(1e5..1e6).contains(&scaled) {
        return None;
    }
    // In that range truncation is the floor, and rounding is the floor plus one above
    // the half (no call to the library's `floor` and `round`).
    let floor = scaled as u64;
    let frac = scaled - floor as f64;
    let up = if frac == 0.5 {
        tie_rounds_up(a, k, scaled)?
    } else {
        frac > 0.5
    };
    Some((floor + u64::from(up), k))
}

/// Whether `a · 10^k` rounds up to six digits when `scaled`, [`scale`]`(a, k)`, ends in
/// exactly .5: when the exact value is above `scaled`, or equal to it with an odd
/// digit before the half. The fused multiply-add computes the remainder of the
/// correctly rounded product or quotient exactly (it is a double).
#[cold]
fn tie_rounds_up(a: f64, k: i32, scaled: f64) -> Option<bool> {
    let p = *POW10.get(k.unsigned_abs() as usize)?;
    let exact_against_scaled = if k >= 0 {
        // a · p − scaled.
        a.mul_add(p, -scaled).partial_cmp(&0.0)?
    } else {
        // scaled · p − a has the sign of scaled − a / p.
        0.0.partial_cmp(&scaled.mul_add(p, -a))?
    };
    Some(match exact_against_scaled {
        Ordering::Less => false,
        Ordering::Greater => true,
        Ordering::Equal => (scaled as u64) % 2 == 1,
    })
}

/// `floor(log10(a))` for a positive finite `a`, or one less: from the binary exponent
/// (`floor(e · log10 2)`, exact in integers for every exponent of an `f64`), since
/// `2^e ≤ a < 2^(e+1)`; [`six_digits`] corrects the one. Subnormals ask `log10`.
fn decimal_exponent_floor(a: f64) -> i32 {
    let biased = ((a.to_bits() >> 52) & 0x7ff) as i32;
    if biased == 0 {
        return a.log10().floor() as i32;
    }
    // 78913 / 2^18 is log10 2 to within 3e-7 relative: the floor is exact for |e| < 1650.
    ((biased - 1023) * 78_913) >> 18
}

/// `a · 10^k`, one rounding away from exact (`None` when `10^|k|` is not exact).
fn scale(a: f64, k: i32) -> Option<f64> {
    let p = *POW10.get(k.unsigned_abs() as usize)?;
    Some(if k >= 0 { a * p } else { a / p })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn same_as_text(x: f64) {
        let text = fmt_g(x);
        let (want64, want32) = (text.parse::<f64>().unwrap(), text.parse::<f32>().unwrap());
        assert_eq!(g_f64(x).to_bits(), want64.to_bits(), "f64 {x:e} ({text})");
        assert_eq!(g_f32(x).to_bits(), want32.to_bits(), "f32 {x:e} ({text})");
    }

    #[test]
    fn printed_values_are_read_back_exactly() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            0.1,
            1e5,
            1e6,
            999_999.5,
            999_999.4,
            99_999.95,
            0.0001,
            0.00001,
            1e-30,
            1e30,
            3.0827,
            -0.816497,
            0.1234565,
            1.2345650000000001,
            12.0,
            2.1,
            0.01,
            100000.0,
            1.0 / 3.0,
            2.0 / 3.0,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            1e22,
            1e23,
            123456789.0,
        ] {
            same_as_text(x);
        }
    }

    #[test]
    fn the_decimal_exponent_is_the_floor_of_log10_or_one_less() {
        let mut x = f64::MIN_POSITIVE;
        while x.is_finite() {
            for a in [
                x,
                x * 1.5,
                x * 1.999_999,
                f64::from_bits((x * 2.0).to_bits() - 1),
            ] {
                let exact = a.log10().floor() as i32;
                let e = decimal_exponent_floor(a);
                assert!(e == exact || e + 1 == exact, "{a:e}: {e} against {exact}");
            }
            x *= 2.0;
        }
        for p in 1..=22 {
            let a = 10f64.powi(p);
            assert!((p - 1..=p).contains(&decimal_exponent_floor(a)), "1e{p}");
        }
    }

    /// Whether `x` scales to a value ending in exactly .5 at six digits: the cases
    /// the remainder decides.
    fn lands_on_a_tie(x: f64) -> bool {
        let a = x.abs();
        let k = 5 - a.log10().floor() as i32;
        let scaled = scale(a, k).unwrap();
        scaled.fract() == 0.5
    }

    /// Binary fractions `i / 2ⁿ` with more than six significant digits: many end in
    /// an exact tie at the sixth, which `%g` rounds to even.
    #[test]
    fn exact_ties_round_to_even_as_the_text_does() {
        let mut ties = 0;
        for n in 1..=24 {
            for i in (1..4000).chain(1_000_000..1_000_100) {
                let x = f64::from(i) / f64::from(1u32 << n);
                for x in [x, -x, x * 1e6, x / 1e4] {
                    same_as_text(x);
                    ties += usize::from(lands_on_a_tie(x));
                }
            }
        }
        assert!(ties > 10_000, "{ties} ties");
    }

    /// Numbers a few units in the last place around `n.5 · 10^-k` (small and large,
    /// so that the scaling multiplies and divides): many scale onto the tie without
    /// being one, and round away from it as their text does.
    #[test]
    fn near_ties_round_as_the_text_does() {
        let mut on_tie = 0;
        for k in [-12, -7, -3, 0, 2, 5, 9, 14] {
            for m in (100_000..1_000_000).step_by(997) {
                let tie = (f64::from(m) + 0.5) / 10f64.powi(k);
                for ulps in -3i64..=3 {
                    let x = f64::from_bits((tie.to_bits() as i64 + ulps) as u64);
                    same_as_text(x);
                    on_tie += usize::from(lands_on_a_tie(x) && x != tie);
                }
            }
        }
        // The SPD's own: 0.075 / 64, a cone radius of spd:jacks at size 7.
        assert!(lands_on_a_tie(0.075 / 64.0));
        same_as_text(0.075 / 64.0);
        assert!(on_tie > 100, "{on_tie} near ties");
    }

    proptest! {
        #[test]
        fn any_value_is_read_back_as_its_text_reads(
            x in proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL,
        ) {
            same_as_text(x);
        }

        #[test]
        fn binary_fractions_are_read_back_as_their_text_reads(
            m in 1u64..(1 << 40), e in 1i32..60, sign in proptest::bool::ANY,
        ) {
            let x = m as f64 / 2f64.powi(e);
            same_as_text(if sign { -x } else { x });
        }

        #[test]
        fn values_of_scene_size_are_read_back_as_their_text_reads(
            m in -1_000_000i64..1_000_000, e in -12i32..12, jitter in -4i64..4,
        ) {
            let x = m as f64 * 10f64.powi(e);
            same_as_text(x);
            same_as_text(f64::from_bits((x.to_bits() as i64 + jitter) as u64));
        }
    }
}

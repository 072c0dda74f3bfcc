//! Decimal numbers read bit for bit as `str::parse::<f64>` and `str::parse::<f32>`
//! read them, faster for the common plain form.
//!
//! A token of the form `[+-]digits[.digits]` with at most 19 digits is an exact
//! integer `m` and a count `d` of digits after the point; when `m` and `10^d` are
//! both exactly representable (`m ≤ 2^53`, `d ≤ 22` in double precision; `m ≤ 2^24`,
//! `d ≤ 10` in single precision) the one division `m / 10^d` is correctly rounded
//! (IEEE 754), which is the value of the decimal correctly rounded: what the standard
//! parser returns. Everything else (exponents, long mantissas, `inf`, `nan`, malformed
//! text) goes to the standard parser.

use super::lexer::is_space;

/// Powers of ten exact in double precision.
const POW10_F64: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];
/// Powers of ten exact in single precision.
const POW10_F32: [f32; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];

/// A plain decimal: sign, all its digits as an integer, and how many of them follow
/// the point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Plain {
    negative: bool,
    mantissa: u64,
    fraction_digits: usize,
}

/// The plain decimal that starts `s` and runs to its end or to the first byte that
/// ends a token (a blank, a line end, `#`), with its length; `None` when the token has
/// another form (or more than 19 digits).
#[inline(always)]
pub(super) fn scan_plain(s: &[u8]) -> Option<(Plain, usize)> {
    let (negative, mut i) = match s.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    // Past 19 digits the mantissa wraps, and the token is refused below.
    let mut mantissa = 0u64;
    let digits = |i: &mut usize, mantissa: &mut u64| {
        let start = *i;
        while let Some(&b @ b'0'..=b'9') = s.get(*i) {
            *mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(b - b'0'));
            *i += 1;
        }
        *i - start
    };
    let whole = digits(&mut i, &mut mantissa);
    let fraction_digits = if s.get(i) == Some(&b'.') {
        i += 1;
        digits(&mut i, &mut mantissa)
    } else {
        0
    };
    let ends = s.get(i).is_none_or(|&b| is_space(b) || b == b'#');
    if !ends || whole + fraction_digits == 0 || whole + fraction_digits > 19 {
        return None;
    }
    let plain = Plain {
        negative,
        mantissa,
        fraction_digits,
    };
    Some((plain, i))
}

/// `s` as a [`Plain`] decimal when all of it is one.
#[inline]
fn plain(s: &[u8]) -> Option<Plain> {
    scan_plain(s).filter(|&(_, n)| n == s.len()).map(|(p, _)| p)
}

/// The value of `p` in double precision, when one division gives it exactly rounded.
#[inline]
pub(super) fn plain_f64(p: Plain) -> Option<f64> {
    if p.mantissa <= 1 << 53 && p.fraction_digits < POW10_F64.len() {
        let v = p.mantissa as f64 / POW10_F64[p.fraction_digits];
        return Some(if p.negative { -v } else { v });
    }
    None
}

/// The value of `p` in single precision, when one division gives it exactly rounded.
#[inline]
pub(super) fn plain_f32(p: Plain) -> Option<f32> {
    if p.mantissa <= 1 << 24 && p.fraction_digits < POW10_F32.len() {
        let v = p.mantissa as f32 / POW10_F32[p.fraction_digits];
        return Some(if p.negative { -v } else { v });
    }
    None
}

/// `s` as `s.parse::<f64>().ok()` returns it, bit for bit.
#[inline]
pub(super) fn parse_f64(s: &str) -> Option<f64> {
    plain(s.as_bytes())
        .and_then(plain_f64)
        .or_else(|| s.parse().ok())
}

/// `s` as `s.parse::<f32>().ok()` returns it, bit for bit.
#[inline]
pub(super) fn parse_f32(s: &str) -> Option<f32> {
    plain(s.as_bytes())
        .and_then(plain_f32)
        .or_else(|| s.parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn same_as_std(s: &str) {
        let (ours, std) = (parse_f64(s), s.parse::<f64>().ok());
        assert_eq!(ours.map(f64::to_bits), std.map(f64::to_bits), "f64 {s:?}");
        let (ours, std) = (parse_f32(s), s.parse::<f32>().ok());
        assert_eq!(ours.map(f32::to_bits), std.map(f32::to_bits), "f32 {s:?}");
    }

    #[test]
    fn plain_forms_and_the_rest_read_as_the_standard_parser_reads_them() {
        for s in [
            "0",
            "-0",
            "+0",
            "-0.0",
            "1",
            "-1",
            "+1.5",
            ".5",
            "5.",
            "-.5",
            ".",
            "-",
            "+",
            "",
            "1.2.3",
            "1e3",
            "1E-3",
            "inf",
            "-inf",
            "nan",
            "infinity",
            "0.1",
            "0.2",
            "0.3",
            "-0.816497",
            "0.0555556",
            "123456",
            "1.23457e+08",
            "16777217",
            "16777216",
            "9007199254740993",
            "9007199254740992",
            "0.00000000001",
            "1234567890123456789",
            "12345678901234567890",
            "0x10",
            "1_000",
            " 1",
            "1 ",
            "--1",
            "+-1",
            "١",
        ] {
            same_as_std(s);
        }
    }

    #[test]
    fn the_parsed_fields() {
        assert_eq!(
            plain(b"-12.050"),
            Some(Plain {
                negative: true,
                mantissa: 12050,
                fraction_digits: 3
            })
        );
        assert_eq!(plain(b"1e5"), None);
        assert_eq!(scan_plain(b"1.5 2").map(|(_, n)| n), Some(3));
        assert_eq!(scan_plain(b"1.5#c").map(|(_, n)| n), Some(3));
        assert_eq!(scan_plain(b"1.5x 2"), None);
    }

    proptest! {
        #[test]
        fn printed_numbers_read_back_as_the_standard_parser_reads_them(
            x in proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
            digits in 0usize..25,
        ) {
            same_as_std(&format!("{x:.digits$}"));
            same_as_std(&format!("{x}"));
            same_as_std(&format!("{}", x as f32));
            same_as_std(&crate::spd::fmt_g(x));
        }

        #[test]
        fn digit_strings_read_back_as_the_standard_parser_reads_them(
            s in "[-+]?[0-9]{0,20}(\\.[0-9]{0,20})?",
        ) {
            same_as_std(&s);
        }
    }
}

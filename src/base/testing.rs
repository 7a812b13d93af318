//! Helpers of the unit tests: repeatable pseudo-random inputs, the values a floor must get right.

/// A small deterministic generator (xorshift) for random inputs: the next value in [0, 1),
/// `seed` (non-zero) moved on. Callers may read `seed` after the call for more bits.
pub(crate) fn random(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// A generator of values in [0, 1) from `seed` (non-zero): [`random`] as a closure.
pub(crate) fn rng(mut seed: u64) -> impl FnMut() -> f64 {
    move || random(&mut seed)
}

/// Values to check a floor-to-integer against `f64::floor`: signed zeros, halves, the
/// neighbours of integers, values near 2⁵¹ and 2⁵², beyond `i64`, infinities and NaN, and
/// 300,000 pseudo-random values of every scale from 10⁻²⁰ to 10¹⁹ with their floors and
/// ceilings (a floor valid only in a range filters them).
pub(crate) fn floor_cases() -> Vec<f64> {
    let mut xs = vec![
        0.0,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        1.5,
        -1.5,
        2.5,
        -2.5,
        0.999_999_999,
        -1.0 - f64::EPSILON,
        1.0 - f64::EPSILON / 2.0,
        -(1.0 - f64::EPSILON / 2.0),
        f64::EPSILON,
        123_456.789,
        -123_456.789,
        -1e-300,
        1e-300,
        2_251_799_813_685_247.0,
        -2_251_799_813_685_247.5,
        4_503_599_627_370_495.5,
        -4_503_599_627_370_495.5,
        9.3e18,
        -9.3e18,
        i64::MIN as f64,
        1e300,
        -1e300,
        f64::MIN_POSITIVE,
        -f64::MIN_POSITIVE,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    for _ in 0..100_000 {
        let unit = random(&mut seed);
        let x = (unit - 0.5) * 10f64.powi((seed % 40) as i32 - 20);
        xs.extend([x, x.floor(), x.ceil()]);
    }
    xs
}

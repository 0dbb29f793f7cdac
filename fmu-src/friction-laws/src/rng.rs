//! A small, bit-reproducible random number generator for the bristle model.
//!
//! xoshiro256++ (Blackman & Vigna 2019) seeded through splitmix64, a uniform
//! sampler on the open interval (0, 1) and Marsaglia's polar method for
//! normal deviates. Everything uses only IEEE-754 `+ − × ÷ √` and a
//! hand-written natural logarithm (`ln_det`, the fdlibm/musl algorithm), so a
//! given seed gives the same numbers on every platform and compiler version,
//! and the whole generator state is four `u64` words that serialise
//! losslessly.

/// xoshiro256++ generator. The state never becomes all-zero.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rng {
    s: [u64; 4],
}

/// One splitmix64 step: advances `x` and returns the next output.
fn splitmix64(x: &mut u64) -> u64 {
    *x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *x;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    /// Seeds the four state words with four successive splitmix64 outputs of
    /// `seed` (the seeding recommended by the xoshiro authors).
    pub fn new(seed: u64) -> Self {
        let mut x = seed;
        let s = [
            splitmix64(&mut x),
            splitmix64(&mut x),
            splitmix64(&mut x),
            splitmix64(&mut x),
        ];
        Self::from_state(s)
    }

    /// Restores a generator from [`Rng::state`]. The all-zero state (a fixed
    /// point of xoshiro) is replaced by the state of `Rng::new(0)`.
    pub fn from_state(s: [u64; 4]) -> Self {
        if s == [0; 4] {
            Self::new(0)
        } else {
            Rng { s }
        }
    }

    /// The four state words, enough to continue the sequence exactly.
    pub fn state(&self) -> [u64; 4] {
        self.s
    }

    /// Next 64 random bits: `rotl(s0 + s3, 23) + s0`, then the xoshiro256
    /// linear update.
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform deviate in the open interval (0, 1): `(k + 0.5)·2⁻⁵³` with `k`
    /// the top 53 bits of [`Rng::next_u64`].
    pub fn uniform(&mut self) -> f64 {
        const SCALE: f64 = 1.0 / 9_007_199_254_740_992.0; // 2^-53
        ((self.next_u64() >> 11) as f64 + 0.5) * SCALE
    }

    /// Normal deviate `mean + std·Z`, `Z ~ N(0, 1)`, by Marsaglia's polar
    /// method: draw `(u, w)` uniform in the square (−1, 1)², reject unless
    /// `0 < s = u² + w² < 1`, return `u·√(−2 ln s / s)`. The second deviate of
    /// the pair is discarded so the state stays four words.
    pub fn normal(&mut self, mean: f64, std: f64) -> f64 {
        // Acceptance is π/4 per attempt; 200 rejections in a row has
        // probability 0.2146^200 < 1e-130, the bound only keeps the loop finite.
        for _ in 0..200 {
            let u = 2.0 * self.uniform() - 1.0;
            let w = 2.0 * self.uniform() - 1.0;
            let s = u * u + w * w;
            if s > 0.0 && s < 1.0 {
                let z = u * (-2.0 * ln_det(s) / s).sqrt();
                return mean + std * z;
            }
        }
        mean
    }
}

/// Natural logarithm of a positive finite `x`, written out with basic IEEE
/// operations only so that it gives the same bits everywhere (the fdlibm
/// `__ieee754_log` algorithm as in musl; error < 1 ulp). Returns NaN for
/// `x < 0` or NaN, −∞ for 0, +∞ for +∞.
pub(crate) fn ln_det(x: f64) -> f64 {
    // Shortest literals of the fdlibm constants (bit patterns in comments,
    // checked by `log_constants_have_the_fdlibm_bit_patterns`).
    const LN2_HI: f64 = 0.693_147_180_369_123_8; // 0x3fe62e42_fee00000
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10; // 0x3dea39ef_35793c76
    const LG1: f64 = 0.666_666_666_666_673_5; // 0x3fe55555_55555593
    const LG2: f64 = 0.399_999_999_994_094_2; // 0x3fd99999_9997fa04
    const LG3: f64 = 0.285_714_287_436_623_9; // 0x3fd24924_94229359
    const LG4: f64 = 0.222_221_984_321_497_84; // 0x3fcc71c5_1d8e78af
    const LG5: f64 = 0.181_835_721_616_180_5; // 0x3fc74664_96cb03de
    const LG6: f64 = 0.153_138_376_992_093_73; // 0x3fc39a09_d078c69f
    const LG7: f64 = 0.147_981_986_051_165_86; // 0x3fc2f112_df3e5244

    let mut x = x;
    let mut ui = x.to_bits();
    let mut hx = (ui >> 32) as u32;
    let mut k: i32 = 0;
    if hx < 0x0010_0000 || (hx >> 31) != 0 {
        if ui << 1 == 0 {
            return f64::NEG_INFINITY;
        }
        if (hx >> 31) != 0 {
            return f64::NAN;
        }
        // Subnormal: scale up by 2^54.
        k -= 54;
        x *= 18_014_398_509_481_984.0;
        ui = x.to_bits();
        hx = (ui >> 32) as u32;
    } else if hx >= 0x7ff0_0000 {
        return x;
    } else if hx == 0x3ff0_0000 && ui << 32 == 0 {
        return 0.0;
    }
    // Reduce x into [√2/2, √2].
    hx = hx.wrapping_add(0x3ff0_0000 - 0x3fe6_a09e);
    k += (hx >> 20) as i32 - 0x3ff;
    hx = (hx & 0x000f_ffff) + 0x3fe6_a09e;
    ui = ((hx as u64) << 32) | (ui & 0xffff_ffff);
    x = f64::from_bits(ui);

    let f = x - 1.0;
    let hfsq = 0.5 * f * f;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG2 + w * (LG4 + w * LG6));
    let t2 = z * (LG1 + w * (LG3 + w * (LG5 + w * LG7)));
    let r = t2 + t1;
    let dk = k as f64;
    s * (hfsq + r) + dk * LN2_LO - hfsq + f + dk * LN2_HI
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_xoshiro256plusplus_reference_vector() {
        // Published outputs of the reference C code from state [1, 2, 3, 4].
        let mut rng = Rng::from_state([1, 2, 3, 4]);
        let expected: [u64; 10] = [
            41943041,
            58720359,
            3588806011781223,
            3591011842654386,
            9228616714210784205,
            9973669472204895162,
            14011001112246962877,
            12406186145184390807,
            15849039046786891736,
            10450023813501588000,
        ];
        for e in expected {
            assert_eq!(rng.next_u64(), e);
        }
    }

    #[test]
    fn splitmix_seeding_matches_an_independent_computation() {
        // splitmix64 from 0: first outputs of the reference generator.
        let mut x = 0u64;
        assert_eq!(splitmix64(&mut x), 0xe220_a839_7b1d_cdaf);
        assert_eq!(splitmix64(&mut x), 0x6e78_9e6a_a1b9_65f4);
        assert_eq!(Rng::new(0).state()[0], 0xe220_a839_7b1d_cdaf);
    }

    #[test]
    fn same_seed_same_sequence_and_state_round_trip() {
        let mut a = Rng::new(12345);
        let mut b = Rng::new(12345);
        let mut c = Rng::new(12346);
        let mut differs = false;
        for _ in 0..1000 {
            let x = a.next_u64();
            assert_eq!(x, b.next_u64());
            differs |= x != c.next_u64();
        }
        assert!(differs);
        let mut d = Rng::from_state(a.state());
        for _ in 0..100 {
            assert_eq!(a.normal(0.0, 1.0).to_bits(), d.normal(0.0, 1.0).to_bits());
        }
        assert_eq!(Rng::from_state([0; 4]), Rng::new(0));
    }

    #[test]
    fn uniform_is_in_the_open_unit_interval() {
        let mut r = Rng::new(3);
        let mut sum = 0.0;
        for _ in 0..100_000 {
            let u = r.uniform();
            assert!(u > 0.0 && u < 1.0);
            sum += u;
        }
        assert!((sum / 1e5 - 0.5).abs() < 0.005);
    }

    #[test]
    fn normal_mean_and_std_within_one_percent() {
        let mut r = Rng::new(2024);
        let n = 100_000;
        let (mean, std) = (3.0, 2.0);
        let xs: Vec<f64> = (0..n).map(|_| r.normal(mean, std)).collect();
        let m = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1) as f64;
        assert!((m - mean).abs() < 0.01 * std, "mean {m}");
        assert!((var.sqrt() / std - 1.0).abs() < 0.01, "std {}", var.sqrt());
        // Tail fraction beyond 2σ: 4.55 %.
        let tail = xs
            .iter()
            .filter(|&&x| ((x - mean) / std).abs() > 2.0)
            .count() as f64
            / n as f64;
        assert!((tail - 0.0455).abs() < 0.003, "tail {tail}");
    }

    #[test]
    fn log_constants_have_the_fdlibm_bit_patterns() {
        let src = include_str!("rng.rs");
        let mut n = 0;
        for line in src
            .lines()
            .filter(|l| l.trim_start().starts_with("const L"))
        {
            let lit = line.split('=').nth(1).unwrap().split(';').next().unwrap();
            let value: f64 = lit.trim().replace('_', "").parse().unwrap();
            let hex = line.split("// 0x").nth(1).unwrap().replace('_', "");
            assert_eq!(
                value.to_bits(),
                u64::from_str_radix(hex.trim(), 16).unwrap(),
                "{line}"
            );
            n += 1;
        }
        assert_eq!(n, 9);
    }

    #[test]
    fn deterministic_log_agrees_with_std() {
        let mut r = Rng::new(9);
        for _ in 0..100_000 {
            let x = r.uniform() * 10f64.powi((r.next_u64() % 40) as i32 - 20);
            let a = ln_det(x);
            let b = x.ln();
            assert!(
                (a - b).abs() <= 2.0 * f64::EPSILON * b.abs().max(1e-300),
                "{x}: {a} vs {b}"
            );
        }
        assert_eq!(ln_det(1.0), 0.0);
        assert_eq!(ln_det(0.0), f64::NEG_INFINITY);
        assert!(ln_det(-1.0).is_nan());
        assert!((ln_det(5e-324) - (5e-324f64).ln()).abs() < 1e-12);
    }
}

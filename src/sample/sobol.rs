//! Owen-scrambled 4D Sobol' points: the low-discrepancy sequence behind the `sobol` line sampler
//! ([`super::lines::Sampler::Sobol`]).
//!
//! The sequence: Sobol' (1967) in base 2 with the direction numbers of Joe and Kuo ("Constructing Sobol
//! sequences with better two-dimensional projections", SIAM J. Sci. Comput. 2008; their table
//! `new-joe-kuo-6.21201`, dimensions 1 to 4), carried to 64 bits by the primitive polynomials'
//! recurrence, so that an index has 64 bits and a coordinate 64 digits (no wrap-around for any run a
//! `u64` line count can ask for). Points come in Gray-code order (Antonov and Saleev 1979): point `i` is
//! the XOR of the direction numbers of the set bits of `i ^ (i >> 1)`, so each point is one XOR per
//! dimension from the previous one. Any aligned block of `2^m` points (`k 2^m .. (k + 1) 2^m`) is the same
//! set in either order, and so a digital net: its projection on dimensions (0, 1) is a (0, m, 2)-net
//! (every elementary box of volume `2^-m` holds exactly one point), on (2, 3) a (2, m, 2)-net, and the 4D
//! points a (3, m, 4)-net (the t-values of these direction numbers, for m up to 20; the tests check
//! them).
//!
//! The randomisation: a nested uniform scramble in the manner of Laine and Karras (2011) and Burley
//! ("Practical hash-based Owen scrambling", JCGT 2020), on 64-bit digits. Written with the digits
//! reversed (the most significant first digit becomes bit 0), a nested scramble flips digit `k` by a
//! random function of digits `0..k`; every step of the scramble (adding a random word, multiplying
//! by a random odd word, XOR with the product by an even constant) changes bit `k` only by a function of
//! the bits below it, so their composition is such a scramble. Two consequences hold whatever the hash's
//! quality: the net properties above survive exactly, and every scrambled point is exactly uniform over
//! the scrambles (the added random word alone makes it so), so estimates stay unbiased. The hash's
//! quality (how close to Owen's independent flips) only moves the variance, which independent
//! randomisations measure honestly.

/// The dimensions of a point.
pub const DIMS: usize = 4;

/// Digits of a coordinate, and bits of an index.
const DIGITS: usize = 64;

/// Joe and Kuo's primitive polynomials and initial direction numbers of dimensions 2 to 4 (dimension 1
/// is van der Corput's): `(s, a, m_1..m_s)`, `s` the polynomial's degree and `a` its inner
/// coefficients, most significant first (the table's columns `s`, `a`, `m_i`).
const JOE_KUO: [(usize, u64, [u64; 3]); DIMS - 1] =
    [(1, 0, [1, 0, 0]), (2, 1, [1, 3, 0]), (3, 1, [1, 3, 1])];

/// The direction numbers `v_k = m_k / 2^k` of each dimension as 64-digit fractions, digits reversed
/// (bit 0 holds the `1/2` digit), `k = 1..=64`.
const DIRECTIONS: [[u64; DIGITS]; DIMS] = directions();

/// The direction numbers, from Sobol's recurrence:
/// `m_k = 2 a_1 m_(k-1) ^ 4 a_2 m_(k-2) ^ ... ^ 2^(s-1) a_(s-1) m_(k-s+1) ^ 2^s m_(k-s) ^ m_(k-s)`.
const fn directions() -> [[u64; DIGITS]; DIMS] {
    let mut out = [[0u64; DIGITS]; DIMS];
    let mut k = 0;
    while k < DIGITS {
        // Van der Corput: m_k = 1.
        out[0][k] = (1u64 << (DIGITS - 1 - k)).reverse_bits();
        k += 1;
    }
    let mut d = 1;
    while d < DIMS {
        let (s, a, initial) = JOE_KUO[d - 1];
        // m_k for k = 1..=64 (m_k < 2^k, so m_64 fits 64 bits), 0-based here.
        let mut m = [0u64; DIGITS];
        let mut k = 0;
        while k < DIGITS {
            m[k] = if k < s {
                initial[k]
            } else {
                let mut v = m[k - s] ^ (m[k - s] << s);
                let mut i = 1;
                while i < s {
                    if (a >> (s - 1 - i)) & 1 == 1 {
                        v ^= m[k - i] << i;
                    }
                    i += 1;
                }
                v
            };
            // v_k = m_k 2^-k: m_k's digits end at position k (1/2^k); reversed, at bit k - 1.
            out[d][k] = (m[k] << (DIGITS - 1 - k)).reverse_bits();
            k += 1;
        }
        d += 1;
    }
    out
}

/// The unscrambled Sobol' point of Gray-code index `index`, each coordinate as 64 digits with the most
/// significant digit in bit 63 (`x = coordinate / 2^64`).
pub fn raw_point(index: u64) -> [u64; DIMS] {
    reversed_point(index).map(u64::reverse_bits)
}

/// [`raw_point`] with the digits reversed.
fn reversed_point(index: u64) -> [u64; DIMS] {
    let gray = index ^ (index >> 1);
    let mut out = [0u64; DIMS];
    for (d, x) in out.iter_mut().enumerate() {
        let mut bits = gray;
        while bits != 0 {
            *x ^= DIRECTIONS[d][bits.trailing_zeros() as usize];
            bits &= bits - 1;
        }
    }
    out
}

/// The nested uniform scramble of one dimension: its two random words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scramble {
    /// Added first: makes every scrambled point exactly uniform.
    add: u64,
    /// Multiplied (made odd): a random dependence of each digit on the digits before it.
    mul: u64,
}

impl Scramble {
    /// The scramble of digits `reversed` (bit 0 the most significant digit); the result has its digits
    /// reversed too. Each step changes bit `k` by a function of bits `0..k` only (see the module's
    /// comment).
    #[inline(always)]
    fn apply(self, reversed: u64) -> u64 {
        let mut v = reversed.wrapping_add(self.add);
        v ^= v.wrapping_mul(0x9e37_79b9_7f4a_7c14);
        v = v.wrapping_mul(self.mul | 1);
        v ^= v.wrapping_mul(0xbf58_476d_1ce4_e5b8);
        v ^= v.wrapping_mul(0x94d0_49bb_1331_11ea);
        v
    }
}

/// One randomisation of the 4D Sobol' sequence: an independent nested uniform scramble per dimension,
/// drawn from `(seed, stream)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScrambledSobol {
    scrambles: [Scramble; DIMS],
}

impl ScrambledSobol {
    /// The randomisation of stream `stream` (a standard-error group) of seed `seed`: its words come from
    /// SplitMix64 over `(seed, stream, dimension)`, so distinct streams and seeds scramble independently
    /// (as far as SplitMix64's outputs are).
    pub fn new(seed: u64, stream: u64) -> Self {
        let base = splitmix64(splitmix64(seed ^ 0x5eed_0b01_5eed_0b01) ^ stream);
        let word = |k: u64| splitmix64(base.wrapping_add(k.wrapping_mul(0x9e37_79b9_7f4a_7c15)));
        let scrambles = std::array::from_fn(|d| Scramble {
            add: word(2 * d as u64),
            mul: word(2 * d as u64 + 1),
        });
        ScrambledSobol { scrambles }
    }

    /// The scrambled point of index `index`, each coordinate as 64 digits (most significant in bit 63).
    pub fn point(&self, index: u64) -> [u64; DIMS] {
        let raw = reversed_point(index);
        std::array::from_fn(|d| self.scrambles[d].apply(raw[d]).reverse_bits())
    }

    /// Calls `visit` with the scrambled points of indices `first..first + count` in order, as doubles in
    /// [0, 1) (each coordinate's 53 most significant digits): the points of [`ScrambledSobol::point`],
    /// one XOR per dimension from one point to the next.
    pub fn for_each_unit(&self, first: u64, count: usize, mut visit: impl FnMut([f64; DIMS])) {
        if count == 0 {
            return;
        }
        let mut state = reversed_point(first);
        let mut index = first;
        for n in 0..count {
            visit(std::array::from_fn(|d| {
                unit(self.scrambles[d].apply(state[d]).reverse_bits())
            }));
            if n + 1 < count {
                // Gray code: point i + 1 differs from point i in the direction of i + 1's lowest set bit.
                index += 1;
                let k = index.trailing_zeros() as usize;
                for (x, dirs) in state.iter_mut().zip(&DIRECTIONS) {
                    *x ^= dirs[k];
                }
            }
        }
    }
}

/// A coordinate's 53 most significant digits as a double in [0, 1).
#[inline(always)]
pub fn unit(digits: u64) -> f64 {
    (digits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// SplitMix64's finaliser: spreads a seed over all 64 bits (the scrambles' seeds, and the
/// independent sampler's per-batch streams).
pub(crate) fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first points of the unscrambled sequence, as tables of Sobol' points list them (Joe and Kuo's
    /// direction numbers, Gray-code order, as e.g. SciPy's `Sobol(d=4, scramble=False)` gives them).
    #[test]
    fn first_points_are_the_published_ones() {
        let expected = [
            [0.0, 0.0, 0.0, 0.0],
            [0.5, 0.5, 0.5, 0.5],
            [0.75, 0.25, 0.25, 0.25],
            [0.25, 0.75, 0.75, 0.75],
            [0.375, 0.375, 0.625, 0.875],
            [0.875, 0.875, 0.125, 0.375],
            [0.625, 0.125, 0.875, 0.625],
            [0.125, 0.625, 0.375, 0.125],
        ];
        for (i, want) in expected.iter().enumerate() {
            let got = raw_point(i as u64).map(unit);
            assert_eq!(&got, want, "point {i}");
        }
    }

    /// Sobol's m_k from the recurrence, against values worked by hand from the polynomials: x + 1 gives
    /// m = 1, 3, 5, 15, 17, 51; x^2 + x + 1 with m = 1, 3 gives 1, 3, 3, 9, 29; x^3 + x + 1 with 1, 3, 1
    /// gives 1, 3, 1, 5, 31.
    #[test]
    fn direction_numbers_follow_the_recurrence() {
        let m = |d: usize, k: usize| DIRECTIONS[d][k - 1].reverse_bits() >> (DIGITS - k);
        let first = |d: usize, n: usize| (1..=n).map(|k| m(d, k)).collect::<Vec<_>>();
        assert_eq!(first(0, 4), [1, 1, 1, 1]);
        assert_eq!(first(1, 6), [1, 3, 5, 15, 17, 51]);
        assert_eq!(first(2, 5), [1, 3, 3, 9, 29]);
        assert_eq!(first(3, 5), [1, 3, 1, 5, 31]);
        for (d, dirs) in DIRECTIONS.iter().enumerate() {
            for (k, v) in (1..=DIGITS).zip(dirs) {
                // v_k has its last digit at position k: m_k is odd and below 2^k.
                let v = v.reverse_bits();
                assert_eq!(v.trailing_zeros() as usize, DIGITS - k, "dim {d}, k {k}");
            }
        }
    }

    /// Whether points (coordinates as 64 digits) of dimensions `dims` form a (t, m, s)-net: every
    /// elementary box of volume 2^(t - m) holds exactly 2^t of the 2^m points.
    fn is_net(points: &[[u64; DIMS]], dims: &[usize], t: u32) -> bool {
        let m = points.len().trailing_zeros();
        assert_eq!(points.len(), 1 << m);
        let mut parts = vec![0u32; dims.len()];
        loop {
            if parts.iter().sum::<u32>() == m - t {
                let mut boxes = std::collections::HashMap::new();
                for p in points {
                    let key: Vec<u64> = dims
                        .iter()
                        .zip(&parts)
                        .map(|(&d, &q)| if q == 0 { 0 } else { p[d] >> (64 - q) })
                        .collect();
                    *boxes.entry(key).or_insert(0u32) += 1;
                }
                if boxes.len() as u64 != 1 << (m - t) || boxes.values().any(|&n| n != 1 << t) {
                    return false;
                }
            }
            // The next split of the digits among the dimensions.
            let mut i = 0;
            loop {
                if i == parts.len() {
                    return true;
                }
                parts[i] += 1;
                if parts[i] <= m - t {
                    break;
                }
                parts[i] = 0;
                i += 1;
            }
        }
    }

    /// Scrambled, aligned blocks of 2^m points are nets: (0, m, 2) on dimensions (0, 1), (2, m, 2) on
    /// (2, 3), (3, m, 4) in 4D, and at m = 12 not better (the t-values of the direction numbers, found
    /// by rank computations over GF(2) apart from this code).
    #[test]
    fn scrambled_blocks_are_nets() {
        for (seed, stream) in [(1, 0), (7, 15), (u64::MAX, 3)] {
            let sobol = ScrambledSobol::new(seed, stream);
            for m in [4u32, 8, 12] {
                for block in [0u64, 1, 37] {
                    let first = block << m;
                    let points: Vec<_> =
                        (first..first + (1 << m)).map(|i| sobol.point(i)).collect();
                    assert!(is_net(&points, &[0, 1], 0), "(0, 1), m {m}");
                    assert!(is_net(&points, &[2, 3], 2), "(2, 3), m {m}");
                    assert!(is_net(&points, &[0, 1, 2, 3], 3), "4D, m {m}");
                    if m == 12 {
                        assert!(!is_net(&points, &[2, 3], 1), "(2, 3) t = 2, m {m}");
                        assert!(!is_net(&points, &[0, 1, 2, 3], 2), "4D t = 3, m {m}");
                    }
                }
            }
        }
    }

    /// A block that is not aligned, or a prefix of a block, is no net: the tests above would notice a
    /// shuffled index.
    #[test]
    fn unaligned_blocks_are_not_nets() {
        let sobol = ScrambledSobol::new(3, 1);
        let points: Vec<_> = (3..3 + 256).map(|i| sobol.point(i)).collect();
        assert!(!is_net(&points, &[0, 1], 0));
    }

    /// The consecutive points of `for_each_unit` are those of `point`, bit for bit, from any start.
    #[test]
    fn gray_code_steps_give_the_direct_points() {
        let sobol = ScrambledSobol::new(11, 5);
        for first in [0u64, 1, 4095, 4096, 123_456_789, u64::MAX - 300] {
            let mut got = Vec::new();
            sobol.for_each_unit(first, 257, |u| got.push(u));
            assert_eq!(got.len(), 257);
            for (n, u) in got.iter().enumerate() {
                assert_eq!(*u, sobol.point(first + n as u64).map(unit), "{first} + {n}");
            }
        }
    }

    /// Reproducible bit for bit; different streams and seeds give different points.
    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a = ScrambledSobol::new(5, 2);
        assert_eq!(a, ScrambledSobol::new(5, 2));
        assert_eq!(a.point(1000), ScrambledSobol::new(5, 2).point(1000));
        for other in [ScrambledSobol::new(5, 3), ScrambledSobol::new(6, 2)] {
            for i in [0, 1, 1000] {
                let (p, q) = (a.point(i), other.point(i));
                assert!((0..DIMS).all(|d| p[d] != q[d]), "index {i}");
            }
        }
    }

    /// Each scrambled point is uniform over the scrambles: over 4000 streams, the mean of each coordinate
    /// of a fixed index is 1/2 and its variance 1/12 (to 4.5 standard errors), and a coordinate's
    /// quarter falls in each of four bins a quarter of the time.
    #[test]
    fn scrambled_points_are_uniform_over_streams() {
        let streams = 4000u64;
        for index in [0u64, 1, 2, 1 << 20] {
            let mut sum = [0.0; DIMS];
            let mut sq = [0.0; DIMS];
            let mut bins = [[0u32; 4]; DIMS];
            for s in 0..streams {
                let u = ScrambledSobol::new(42, s).point(index).map(unit);
                for d in 0..DIMS {
                    sum[d] += u[d];
                    sq[d] += u[d] * u[d];
                    bins[d][(u[d] * 4.0) as usize] += 1;
                }
            }
            let n = streams as f64;
            for d in 0..DIMS {
                let mean = sum[d] / n;
                let var = sq[d] / n - mean * mean;
                let se = (1.0f64 / 12.0 / n).sqrt();
                assert!(
                    (mean - 0.5).abs() < 4.5 * se,
                    "index {index} dim {d}: {mean}"
                );
                assert!(
                    (var - 1.0 / 12.0).abs() < 0.006,
                    "index {index} dim {d}: {var}"
                );
                for &b in &bins[d] {
                    let share = f64::from(b) / n;
                    assert!((share - 0.25).abs() < 4.5 * (0.1875f64 / n).sqrt());
                }
            }
        }
    }

    /// Owen's scramble flips each digit by an independent random bit given the digits before it: two
    /// points that share their first k digits (and differ in digit k + 1) share them after scrambling, and
    /// their next digits agree for half the scrambles.
    #[test]
    fn digits_after_a_split_are_scrambled_independently() {
        let streams = 4000u64;
        for k in [0u32, 1, 5, 20] {
            let x = 0x5a5a_5a5a_5a5a_5a5au64.reverse_bits();
            let y = x ^ (1 << k);
            let mut agree = 0u32;
            for s in 0..streams {
                let scr = ScrambledSobol::new(9, s).scrambles[0];
                let (a, b) = (scr.apply(x), scr.apply(y));
                assert_eq!(a & ((1 << k) - 1), b & ((1 << k) - 1), "prefix kept");
                assert_ne!(a & (1 << k), b & (1 << k), "split kept");
                agree += u32::from((a >> (k + 1)) & 1 == (b >> (k + 1)) & 1);
            }
            let share = f64::from(agree) / streams as f64;
            assert!(
                (share - 0.5).abs() < 4.5 * (0.25 / streams as f64).sqrt(),
                "k {k}: {share}"
            );
        }
    }
}

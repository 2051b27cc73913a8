//! Owen-scrambled Sobol' points in `[0, 1)^2`, the `u` that drive the distributions.
//!
//! Why this and not jittered stratification: the first two Sobol' dimensions form a
//! (0,2)-sequence in base 2, so for any `n_samples = 2^m` every elementary interval of area
//! `2^-m`, of every shape from `1 x 2^-m` to `2^-m x 1`, holds exactly one point. That is
//! stratification in both one-dimensional projections and in every grid `2^a x 2^(m-a)` at once,
//! for every power of two rather than only square counts, and prefixes of the sequence stay well
//! spread, so a vector can grow without being redrawn. Nested uniform (Owen) scrambling keeps
//! those properties, makes each point uniform on `[0, 1)^2` (estimates are unbiased), and gives
//! independent scrambles for different seeds, so `V` vectors of `S` samples give `V` independent
//! estimates. The scrambling is a hash (pbrt-v4's `FastOwenScrambler`, after Burley 2020,
//! "Practical Hash-based Owen Scrambling"), not an RNG: the points for a seed are fixed by this
//! file alone, so baked assets do not change with a `rand` upgrade.

/// One Owen-scrambled Sobol' (0,2)-sequence. Points have 32 bits of precision.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OwenSobol2D {
    seeds: [u32; 2],
}

impl OwenSobol2D {
    /// The sequence scrambled by `seed`; any two seeds, consecutive ones included, give
    /// unrelated scrambles.
    pub fn new(seed: u64) -> Self {
        let h = mix64(seed);
        Self { seeds: [h as u32, (h >> 32) as u32] }
    }

    /// The sequence of vector `vector` among those drawn from `seed`.
    pub fn for_vector(seed: u64, vector: u64) -> Self {
        Self::new(seed ^ mix64(vector.wrapping_add(0x9e37_79b9_7f4a_7c15)))
    }

    /// The sequence scrambled by the words `seeds`, one per dimension, as they are: for callers
    /// that derive them with 32-bit arithmetic a GPU repeats (the scrambling itself is 32-bit).
    pub fn from_words(seeds: [u32; 2]) -> Self {
        Self { seeds }
    }

    /// Point `index` of the sequence, in `[0, 1)^2`.
    pub fn point(&self, index: u32) -> [f64; 2] {
        self.point_bits(index).map(to_unit)
    }

    /// Point `index` in 32-bit fixed point: [`OwenSobol2D::point`] is these times `2^-32`.
    pub fn point_bits(&self, index: u32) -> [u32; 2] {
        [owen_scramble(index.reverse_bits(), self.seeds[0]), owen_scramble(sobol_dim1(index), self.seeds[1])]
    }

    /// The first `n_samples` points. For `n_samples = 2^m` they form a (0,m,2)-net.
    ///
    /// # Panics
    /// If `n_samples > 2^32`, the length of the sequence.
    pub fn points(&self, n_samples: usize) -> Vec<[f64; 2]> {
        assert!(n_samples as u64 <= 1 << 32, "n_samples {n_samples} exceeds the 2^32 points of the sequence");
        (0..n_samples).map(|i| self.point(i as u32)).collect()
    }
}

/// `n_vectors` independent vectors of `n_samples` points each, flat and vector-major: vector `v`
/// is `[v * n_samples..(v + 1) * n_samples]`, drawn from [`OwenSobol2D::for_vector`]`(seed, v)`.
///
/// # Panics
/// If `n_samples > 2^32`.
pub fn owen_sobol_vectors(seed: u64, n_vectors: usize, n_samples: usize) -> Vec<[f64; 2]> {
    (0..n_vectors).flat_map(|v| OwenSobol2D::for_vector(seed, v as u64).points(n_samples)).collect()
}

/// Exact: a 32-bit integer times a power of two, at most `1 - 2^-32`.
fn to_unit(bits: u32) -> f64 {
    bits as f64 * (1.0 / 4_294_967_296.0)
}

/// The second Sobol' dimension (primitive polynomial x + 1): its generator matrix is Pascal's
/// triangle mod 2, whose columns follow `v ^= v >> 1`. With the van der Corput first dimension
/// (bit reversal) it makes a (0,2)-sequence.
fn sobol_dim1(mut index: u32) -> u32 {
    let mut result = 0;
    let mut v = 1 << 31;
    while index != 0 {
        if index & 1 != 0 {
            result ^= v;
        }
        index >>= 1;
        v ^= v >> 1;
    }
    result
}

/// Nested uniform scrambling of the bits of `v`, most significant first: every step below is a
/// bijection in which bit k of the result depends only on bits 0..=k of its input, so between the
/// two reversals each output bit depends only on the more significant input bits. That maps each
/// elementary interval onto one of the same size, which is what keeps nets nets.
fn owen_scramble(v: u32, seed: u32) -> u32 {
    let mut v = v.reverse_bits();
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

/// SplitMix64's finalizer: a bijection on u64 that spreads every input bit over the output.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

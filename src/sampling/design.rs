//! Sampling designs: the unit sample in (0, 1) of instance `i`, dimension `d`, as a pure function
//! of `(design, seed, n, i, d, k)` — counter-based, so instances can be generated in any order,
//! on any thread or shard, and always agree.

use sobol_burley::parts::{hash, owen_scramble_rev, sobol_rev};

/// Dimensions of one Owen-scrambled Sobol sequence (the Joe–Kuo direction numbers shipped with
/// `sobol_burley`). A Sobol design needs `k ≤ MAX_SOBOL_DIMS` inputs and a Saltelli design
/// `2k ≤ MAX_SOBOL_DIMS`; callers validate this when a campaign is loaded. Beyond it
/// [`unit_sample`] does not panic but pads (dimension `d` uses Sobol dimension `d mod 256` under a
/// different scramble seed, as the `sobol_burley` documentation recommends), which keeps each
/// dimension uniform but gives up the joint stratification across padded groups.
pub const MAX_SOBOL_DIMS: usize = sobol_burley::NUM_DIMENSIONS as usize;

/// Points per Sobol block: `sobol_burley` supports indices below 2^16. Index `i` uses point
/// `i mod 2^16` of a sequence scrambled with a seed derived from `i / 2^16`.
const SOBOL_BLOCK_BITS: u32 = 16;

/// Largest `f64` below 1 (1 − 2⁻⁵³).
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;

/// Domain-separation salts so that the hashes of the different designs are unrelated.
const SALT_MONTE_CARLO: u64 = 0x6d6f_6e74_655f_6361; // "monte_ca"
const SALT_LHS_KEY: u64 = 0x6c68_735f_7065_726d; // "lhs_perm"
const SALT_LHS_JITTER: u64 = 0x6c68_735f_6a69_7474; // "lhs_jitt"
const SALT_SOBOL: u64 = 0x736f_626f_6c5f_7365; // "sobol_se"

/// Sampling design of a dispersion campaign.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// Independent pseudo-random samples (counter-based hash of seed, instance, dimension).
    MonteCarlo,
    /// Latin hypercube (McKay, Beckman & Conover 1979): each dimension's `n` values fall one in
    /// each of `n` equal strata, independently permuted per dimension.
    LatinHypercube,
    /// Owen-scrambled Sobol quasi-random sequence (Burley 2020, via `sobol_burley`).
    Sobol,
    /// Saltelli's A/B/AB design for first-order and total Sobol sensitivity indices
    /// (Saltelli et al. 2010), built on the scrambled Sobol sequence; see [`saltelli_layout`].
    Saltelli,
}

impl Design {
    /// The name used in campaign files and outputs: `monte_carlo`, `latin_hypercube`, `sobol` or
    /// `saltelli`.
    pub fn name(self) -> &'static str {
        match self {
            Design::MonteCarlo => "monte_carlo",
            Design::LatinHypercube => "latin_hypercube",
            Design::Sobol => "sobol",
            Design::Saltelli => "saltelli",
        }
    }

    /// Inverse of [`Design::name`] (exact, case-sensitive match); `None` for any other string.
    pub fn from_name(s: &str) -> Option<Design> {
        match s {
            "monte_carlo" => Some(Design::MonteCarlo),
            "latin_hypercube" => Some(Design::LatinHypercube),
            "sobol" => Some(Design::Sobol),
            "saltelli" => Some(Design::Saltelli),
            _ => None,
        }
    }
}

/// Row kind of a Saltelli design (Saltelli et al. 2010, "Variance based sensitivity analysis of
/// model output", Comput. Phys. Commun. 181): the base matrices A and B, and for each input `m`
/// the matrix AB(m) — A with column `m` taken from B.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SaltelliRow {
    /// Row of matrix A.
    A,
    /// Row of matrix B.
    B,
    /// Row of matrix AB(m): A's row with input `m` from B (`m < k`).
    AB(usize),
}

/// Saltelli row layout: instance `i` of a design with `k_inputs` inputs → (base index
/// `b = i / (k + 2)`, row kind). Within each group of `k + 2` consecutive instances the order is
/// A, AB(0), …, AB(k − 1), B — the order of SALib's `saltelli.sample` without second-order
/// terms — so a campaign of `N (k + 2)` instances holds `N` complete base rows.
pub fn saltelli_layout(i: u64, k_inputs: usize) -> (u64, SaltelliRow) {
    let k = k_inputs as u64;
    let period = k.saturating_add(2);
    let (b, r) = (i / period, i % period);
    let row = if r == 0 {
        SaltelliRow::A
    } else if r > k {
        SaltelliRow::B
    } else {
        SaltelliRow::AB((r - 1) as usize)
    };
    (b, row)
}

/// Unit sample strictly inside (0, 1) for instance `i` of `n`, dimension `d`, under `design` and
/// `seed`. A pure function of its arguments: no state, no allocation, no panics.
///
/// - **MonteCarlo**: a counter-based hash — the SplitMix64 finaliser (Steele, Lea & Flood 2014,
///   Stafford's "Mix13" constants) chained over (seed, i, d) — mapped to `(2h + 1) / 2⁵³` with
///   `h` its top 52 bits: 53 significant bits, never 0 or 1. `n` and `k_inputs` are unused.
/// - **LatinHypercube**: stratum `π_{seed,d}(i)` where `π` is a keyed pseudo-random permutation
///   of `[0, n)` — a 4-round Feistel network on the next power of two (halves of ⌊m/2⌋ and
///   ⌈m/2⌉ bits, alternating) with cycle-walking (Black & Rogaway 2002) — and
///   `u = (stratum + jitter) / n`, jitter `= (j + ½) / 2³²` from a 32-bit hash of (seed, i, d).
///   Each dimension's `n` values hit each stratum `[s/n, (s+1)/n)` exactly once. An index
///   `i ≥ n` reuses the stratum of `i mod n` (with its own jitter); `n = 0` is treated as `n = 1`.
/// - **Sobol**: Owen-scrambled Sobol point `i`, dimension `d`, computed exactly as
///   `sobol_burley::sample(i, d, s)` (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT
///   9(4)) with `s` a 32-bit seed hashed from `seed`, but keeping all 32 output bits:
///   `u = (x + ½) / 2³²`, so `⌊u · 2²³⌋ / 2²³` equals `sample`'s `f32`. The first `2^m` points
///   (m ≤ 16) stratify every pair of dimensions like a (0, m, 2)-net. `sobol_burley` supports
///   `i < 2^16`: beyond it, `i` uses point `i mod 2^16` of an independently scrambled sequence per
///   block of 2^16 (each block is a full net; the union is a randomised replicate design).
///   `d ≥ MAX_SOBOL_DIMS` is padded (see [`MAX_SOBOL_DIMS`]). `n` and `k_inputs` are unused.
/// - **Saltelli**: with `(b, kind) = saltelli_layout(i, k)` and `sobol(b, c)` the Sobol sample of
///   point `b`, dimension `c`: kind A → `sobol(b, d)`; B → `sobol(b, k + d)`; AB(m) →
///   `sobol(b, k + d)` if `d == m`, else `sobol(b, d)`. A dimension `d ≥ k` (not an analysed
///   input) takes `sobol(b, 2k + (d − k))` in every row of its base. `n` must be a multiple of
///   `k + 2`, which the caller validates; it is otherwise unused.
///
/// Sobol and Saltelli designs are stratified only within `MAX_SOBOL_DIMS` dimensions (`d < 256`,
/// `2k < 256`): callers validate dimensions; outside them values are still valid but padded.
pub fn unit_sample(design: Design, seed: u64, n: u64, i: u64, d: usize, k_inputs: usize) -> f64 {
    let d = d as u64;
    match design {
        Design::MonteCarlo => unit_from_bits(hash3(SALT_MONTE_CARLO, seed, i, d)),
        Design::LatinHypercube => latin_hypercube(seed, n, i, d),
        Design::Sobol => sobol(seed, i, d),
        Design::Saltelli => {
            let k = k_inputs as u64;
            let (b, row) = saltelli_layout(i, k_inputs);
            let from_b = match row {
                SaltelliRow::A => false,
                SaltelliRow::B => true,
                SaltelliRow::AB(m) => m as u64 == d,
            };
            let column = if d >= k {
                k.saturating_mul(2).saturating_add(d - k)
            } else if from_b {
                k.saturating_add(d)
            } else {
                d
            };
            sobol(seed, b, column)
        }
    }
}

// ------------------------------------------------------------------------------------------
// Private helpers.

/// SplitMix64 finaliser (Stafford's Mix13): a bijective 64-bit mixer with full avalanche.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Counter-based hash of (salt, seed, a, b). For fixed (salt, seed, b) it is a bijection of `a`
/// (and vice versa), so distinct instances never collide before truncation.
fn hash3(salt: u64, seed: u64, a: u64, b: u64) -> u64 {
    const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;
    let h = mix64(seed ^ salt);
    let h = mix64(h ^ mix64(a.wrapping_add(GOLDEN)));
    mix64(h ^ mix64(b.wrapping_add(GOLDEN.wrapping_mul(3))))
}

/// `(2 (h >> 12) + 1) / 2⁵³`: odd multiples of 2⁻⁵³, all exactly representable, in
/// `[2⁻⁵³, 1 − 2⁻⁵³]`.
fn unit_from_bits(h: u64) -> f64 {
    ((h >> 12) as f64 + 0.5) * (1.0 / (1u64 << 52) as f64)
}

/// Latin hypercube unit sample (see [`unit_sample`]).
fn latin_hypercube(seed: u64, n: u64, i: u64, d: u64) -> f64 {
    let n = n.max(1);
    let key = hash3(SALT_LHS_KEY, seed, d, 0);
    let stratum = permute(i % n, n, key);
    let jitter =
        ((hash3(SALT_LHS_JITTER, seed, i, d) >> 32) as f64 + 0.5) * (1.0 / 4_294_967_296.0);
    ((stratum as f64 + jitter) / n as f64).clamp(f64::MIN_POSITIVE, ONE_BELOW)
}

/// Keyed pseudo-random permutation of `[0, n)` applied to `x < n`: a Feistel permutation of
/// `[0, 2^m)`, `2^m` the next power of two ≥ n, iterated until it lands below `n`
/// (cycle-walking). Terminates because `x` itself lies on its cycle; since `2^m < 2n` the expected
/// number of iterations is below 2.
fn permute(x: u64, n: u64, key: u64) -> u64 {
    if n <= 1 {
        return 0;
    }
    let bits = u64::BITS - (n - 1).leading_zeros();
    let mut y = feistel(x, bits, key);
    while y >= n {
        y = feistel(y, bits, key);
    }
    y
}

/// 4-round unbalanced Feistel network on `bits`-bit integers (1 ≤ bits ≤ 64): `x = L·2^r + R`
/// with `L` of `l = ⌊bits/2⌋` bits and `R` of `r = bits − l` bits maps to
/// `R·2^l + (L ⊕ F_k(R) mod 2^l)`, the halves swapping widths each round; each round is
/// invertible, so the whole is a bijection of `[0, 2^bits)`.
fn feistel(x: u64, bits: u32, key: u64) -> u64 {
    let mut left_bits = bits / 2;
    let mut right_bits = bits - left_bits;
    let mut x = x;
    for round in 1..=4u64 {
        let left = x >> right_bits;
        let right = x & low_mask(right_bits);
        let f = mix64(right ^ mix64(key ^ round));
        x = (right << left_bits) | ((left ^ f) & low_mask(left_bits));
        std::mem::swap(&mut left_bits, &mut right_bits);
    }
    x
}

/// Mask of the low `bits` bits (`bits ≤ 64`).
fn low_mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// Owen-scrambled Sobol unit sample of point `index`, dimension `dim` (padded beyond 2^16 points
/// and `MAX_SOBOL_DIMS` dimensions by reseeding).
fn sobol(seed: u64, index: u64, dim: u64) -> f64 {
    let dims = u64::from(sobol_burley::NUM_DIMENSIONS);
    let block = index >> SOBOL_BLOCK_BITS;
    let point = (index & ((1 << SOBOL_BLOCK_BITS) - 1)) as u32;
    let seed32 = (hash3(SALT_SOBOL, seed, block, dim / dims) >> 32) as u32;
    let x = sobol_owen_bits(point, (dim % dims) as u32, seed32);
    (f64::from(x) + 0.5) * (1.0 / 4_294_967_296.0)
}

/// `sobol_burley::sample` (v0.5) before its conversion to `f32`: the 32-bit Owen-scrambled Sobol
/// integer. Requires `index < 2^16` and `dimension < NUM_DIMENSIONS` (guaranteed by [`sobol`]).
fn sobol_owen_bits(index: u32, dimension: u32, seed: u32) -> u32 {
    // Shuffle the index (a nested scramble of its reversed bits) for statistically independent
    // sequences per seed; then Owen-scramble the Sobol point per dimension.
    let shuffled_rev_index = owen_scramble_rev(index.reverse_bits(), hash(seed ^ 0x79c6_8e4a));
    let sobol = sobol_rev(shuffled_rev_index, dimension);
    let scramble = {
        let seed = seed.wrapping_mul(0x9c8f_2d3b);
        let ds = dimension >> 2;
        let lane = [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8];
        ds ^ seed ^ lane[dimension as usize & 0b11]
    };
    owen_scramble_rev(sobol, hash(scramble)).reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Our 32-bit Sobol integer truncates to exactly `sobol_burley::sample`'s `f32`.
    #[test]
    fn sobol_bits_match_sobol_burley() {
        for seed in [0u32, 1, 0xdead_beef] {
            for dim in [0u32, 1, 2, 3, 4, 7, 100, 255] {
                for index in (0..65_536u32).step_by(97).chain([0, 1, 65_535]) {
                    let ours = sobol_owen_bits(index, dim, seed);
                    let theirs = sobol_burley::sample(index, dim, seed);
                    let truncated = (ours >> 9) as f32 / (1u32 << 23) as f32;
                    assert_eq!(truncated, theirs, "index {index} dim {dim} seed {seed}");
                }
            }
        }
    }

    #[test]
    fn feistel_is_a_bijection() {
        for bits in 1..=12 {
            let size = 1u64 << bits;
            let mut seen = vec![false; size as usize];
            for x in 0..size {
                let y = feistel(x, bits, 0x1234_5678);
                assert!(y < size);
                assert!(!seen[y as usize], "bits {bits}: collision at {y}");
                seen[y as usize] = true;
            }
        }
        // Full width works without overflow.
        assert_ne!(feistel(0, 64, 7), feistel(1, 64, 7));
    }

    #[test]
    fn permute_small_domains() {
        for n in 1..=70u64 {
            let mut seen = vec![false; n as usize];
            for x in 0..n {
                let y = permute(x, n, 42);
                assert!(y < n);
                assert!(!seen[y as usize]);
                seen[y as usize] = true;
            }
        }
    }

    #[test]
    fn unit_from_bits_extremes() {
        assert!(unit_from_bits(0) > 0.0);
        assert!(unit_from_bits(u64::MAX) < 1.0);
        assert_eq!(unit_from_bits(u64::MAX), ONE_BELOW);
    }
}

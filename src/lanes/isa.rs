//! The instruction-set extensions this binary was compiled to use, checked against the CPU it
//! runs on: a binary built for x86-64-v3 (the default, `.cargo/config.toml`) or x86-64-v4 (the
//! AVX-512 build of docs/ARCHITECTURE.md, "Build target and width") stops with a message on a
//! CPU without them, where it would otherwise die of an illegal instruction in the first lane
//! operation. Results do not depend on the build: each lane does the same `f64` operations.

/// The compiled-in x86-64 extensions the running CPU lacks (their `target_feature` names);
/// empty on a CPU that has them all, and on other architectures.
pub fn missing_features() -> Vec<&'static str> {
    #[allow(unused_mut)]
    let mut missing = Vec::new();
    #[cfg(target_arch = "x86_64")]
    {
        macro_rules! check {
            ($($f:tt),*) => {$(
                if cfg!(target_feature = $f) && !std::arch::is_x86_feature_detected!($f) {
                    missing.push($f);
                }
            )*};
        }
        check!(
            "sse4.2", "popcnt", "avx", "avx2", "fma", "bmi1", "bmi2", "lzcnt", "movbe", "avx512f",
            "avx512dq", "avx512cd", "avx512bw", "avx512vl"
        );
    }
    missing
}

/// The widest vector extension this binary was compiled for, as a word for messages and
/// benches: `"avx512"`, `"avx2"` or `"baseline"`.
pub fn compiled_vector_isa() -> &'static str {
    if cfg!(target_feature = "avx512f") {
        "avx512"
    } else if cfg!(target_feature = "avx2") {
        "avx2"
    } else {
        "baseline"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_test_binary_runs_on_a_cpu_with_every_compiled_feature() {
        // This test runs, so the CPU executes the build's instructions; the check must agree.
        assert_eq!(missing_features(), Vec::<&str>::new());
    }
}

//! The instruction-set extensions this binary was compiled to use, checked against the CPU it
//! runs on: a binary built for x86-64-v3 (the default, `.cargo/config.toml`) or x86-64-v4 (the
//! AVX-512 build of docs/ARCHITECTURE.md, "The AVX-512 build") stops with a message on a CPU
//! without them, where it would otherwise die of an illegal instruction in the first lane
//! operation. Results do not depend on the build: each lane does the same `f64` operations.
//!
//! The CPU is asked with `cpuid` and `xgetbv` directly: `is_x86_feature_detected!` answers
//! `true` at compile time for every feature the binary was compiled with, so it cannot tell.

/// [`CHECKED`] and [`compiled_features`] from one list (`cfg!` needs each name as a literal).
macro_rules! checked_features {
    ($($f:literal),* $(,)?) => {
        /// The x86-64 extensions the levels x86-64-v2 … v4 add, by their `target_feature` names.
        pub const CHECKED: &[&str] = &[$($f),*];

        /// Which of [`CHECKED`] this binary was compiled to use.
        pub fn compiled_features() -> Vec<&'static str> {
            let mut v = Vec::new();
            $(if cfg!(target_feature = $f) { v.push($f); })*
            v
        }
    };
}

checked_features!(
    "sse4.2", "popcnt", "avx", "avx2", "fma", "bmi1", "bmi2", "lzcnt", "movbe", "xsave", "avx512f",
    "avx512dq", "avx512cd", "avx512bw", "avx512vl",
);

/// Which of [`CHECKED`] the running CPU and operating system support: `cpuid` leaves 1, 7 and
/// 0x8000_0001, with the AVX and AVX-512 register state enabled by the OS (`xgetbv`, XCR0
/// bits 1–2 and 5–7), in [`CHECKED`]'s order. `None` on other architectures.
#[inline(never)]
pub fn cpu_features() -> Option<Vec<&'static str>> {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__cpuid, __cpuid_count, _xgetbv};
        #[allow(unused_unsafe)]
        // SAFETY: `cpuid` exists on every x86-64 CPU; `xgetbv` only runs where leaf 1 says the
        // OS enabled it (OSXSAVE).
        let (l1, l7, e1, xcr0) = unsafe {
            let max = __cpuid(0).eax;
            let max_ext = __cpuid(0x8000_0000).eax;
            let l1 = __cpuid(1);
            let l7 = (max >= 7).then(|| __cpuid_count(7, 0));
            let e1 = (max_ext >= 0x8000_0001).then(|| __cpuid(0x8000_0001));
            let osxsave = l1.ecx & (1 << 27) != 0;
            let xcr0 = if osxsave { _xgetbv(0) } else { 0 };
            (l1, l7, e1, xcr0)
        };
        let ymm_state = xcr0 & 0b110 == 0b110;
        let zmm_state = ymm_state && xcr0 & 0b1110_0000 == 0b1110_0000;
        let bit = |r: u32, b: u32| r & (1 << b) != 0;
        let (b7, c1) = (l7.map_or(0, |r| r.ebx), l1.ecx);
        let mut have = Vec::new();
        for (name, present) in [
            ("sse4.2", bit(c1, 20)),
            ("popcnt", bit(c1, 23)),
            ("avx", bit(c1, 28) && ymm_state),
            ("avx2", bit(b7, 5) && ymm_state),
            ("fma", bit(c1, 12) && ymm_state),
            ("bmi1", bit(b7, 3)),
            ("bmi2", bit(b7, 8)),
            ("lzcnt", e1.is_some_and(|r| bit(r.ecx, 5))),
            ("movbe", bit(c1, 22)),
            ("xsave", bit(c1, 26)),
            ("avx512f", bit(b7, 16) && zmm_state),
            ("avx512dq", bit(b7, 17) && zmm_state),
            ("avx512cd", bit(b7, 28) && zmm_state),
            ("avx512bw", bit(b7, 30) && zmm_state),
            ("avx512vl", bit(b7, 31) && zmm_state),
        ] {
            if present {
                have.push(name);
            }
        }
        Some(have)
    }
    #[cfg(not(target_arch = "x86_64"))]
    None
}

/// What this binary's CPU engine was built as, for `--version`, `run.json` and the Parquet
/// provenance: the architecture, the lane-group width ([`super::WIDTH`] `f64` lanes) and the
/// extensions of [`CHECKED`] compiled in, e.g. "x86_64, 16 f64 lanes, avx2 fma …". Results do
/// not depend on it (the same bits from every build); speed does.
pub fn build_description() -> String {
    let features = compiled_features();
    let features = if features.is_empty() {
        "baseline instruction set".to_string()
    } else {
        features.join(" ")
    };
    format!(
        "{}, {} f64 lanes, {features}",
        std::env::consts::ARCH,
        super::WIDTH
    )
}

/// The members of `compiled` absent from `have` (in `compiled`'s order).
pub fn missing<'a>(compiled: &[&'a str], have: &[&str]) -> Vec<&'a str> {
    compiled
        .iter()
        .copied()
        .filter(|f| !have.contains(f))
        .collect()
}

/// The compiled-in extensions the running CPU lacks; empty where it has them all, and on other
/// architectures.
pub fn missing_features() -> Vec<&'static str> {
    match cpu_features() {
        Some(have) => missing(&compiled_features(), &have),
        None => Vec::new(),
    }
}

/// What to rebuild with when `missing` is not empty: the default build where only AVX-512 is
/// missing, the x86-64 baseline otherwise.
pub fn rebuild_hint(missing: &[&str]) -> &'static str {
    if missing.iter().all(|f| f.starts_with("avx512")) {
        "the default build (x86-64-v3, .cargo/config.toml: unset RUSTFLAGS)"
    } else {
        "RUSTFLAGS=\"-C target-cpu=x86-64\" (the baseline; same results, slower)"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_running_cpu_has_every_feature_this_test_binary_was_compiled_with() {
        // The test runs, so the CPU executes the build's instructions: cpuid must agree.
        assert_eq!(missing_features(), Vec::<&str>::new());
    }

    #[cfg(all(target_arch = "x86_64", target_os = "linux"))]
    #[test]
    fn cpuid_agrees_with_the_kernels_cpu_flags() {
        // An independent reading of the same CPU: Linux's /proc/cpuinfo flags (its names).
        let info = std::fs::read_to_string("/proc/cpuinfo").expect("/proc/cpuinfo");
        let flags: Vec<&str> = info
            .lines()
            .find(|l| l.starts_with("flags"))
            .expect("a flags line")
            .split_whitespace()
            .collect();
        let linux_name = |f: &str| {
            match f {
                "sse4.2" => "sse4_2",
                "lzcnt" => "abm",
                other => other,
            }
            .to_string()
        };
        let from_kernel: Vec<&str> = CHECKED
            .iter()
            .copied()
            .filter(|f| flags.contains(&linux_name(f).as_str()))
            .collect();
        assert_eq!(cpu_features().expect("x86-64"), from_kernel);
    }

    #[test]
    fn the_build_description_names_the_width_and_each_compiled_feature() {
        let d = build_description();
        assert!(d.starts_with(std::env::consts::ARCH), "{d}");
        assert!(
            d.contains(&format!(", {} f64 lanes, ", crate::lanes::WIDTH)),
            "{d}"
        );
        for f in compiled_features() {
            assert!(d.split([' ', ',']).any(|w| w == f), "{f} missing from {d}");
        }
        if cfg!(target_feature = "avx512f") {
            assert!(d.contains("32 f64 lanes") && d.contains("avx512f"), "{d}");
        }
    }

    #[test]
    fn an_avx512_binary_on_an_avx2_cpu_is_told_to_use_the_default_build() {
        let compiled = ["avx", "avx2", "fma", "avx512f", "avx512vl"];
        let have = ["sse4.2", "avx", "avx2", "fma"];
        let m = missing(&compiled, &have);
        assert_eq!(m, ["avx512f", "avx512vl"]);
        assert!(rebuild_hint(&m).contains("default build"));
        let m = missing(&compiled, &["sse4.2"]);
        assert_eq!(m, ["avx", "avx2", "fma", "avx512f", "avx512vl"]);
        assert!(rebuild_hint(&m).contains("x86-64\""));
    }
}

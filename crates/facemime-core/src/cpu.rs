//! What the processor offers, for the kernels that choose their instructions at run time.

/// Whether AVX2 and FMA are present (x86-64 only): the kernels compiled for them run.
#[cfg(target_arch = "x86_64")]
pub(crate) fn has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// For a test of a kernel this CPU cannot run: says on stderr that the test checked nothing,
/// or, with the environment variable `FACEMIME_REQUIRE_SIMD` set (to anything but empty or
/// `0`; on a machine known to have the feature), fails, so that the test cannot pass silently.
#[cfg(all(test, target_arch = "x86_64"))]
pub(crate) fn simd_missing(test: &str, feature: &str) {
    let required = std::env::var("FACEMIME_REQUIRE_SIMD").is_ok_and(|v| !v.is_empty() && v != "0");
    assert!(
        !required,
        "{test}: this CPU has no {feature}, and FACEMIME_REQUIRE_SIMD is set"
    );
    eprintln!(
        "{test}: skipped, this CPU has no {feature} (FACEMIME_REQUIRE_SIMD=1 makes this a failure)"
    );
}

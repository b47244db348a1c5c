//! What the processor offers, for the kernels that choose their instructions at run time.

/// Whether AVX2 and FMA are present (x86-64 only): the kernels compiled for them run.
#[cfg(target_arch = "x86_64")]
pub(crate) fn has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

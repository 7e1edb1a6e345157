//! Start-up check that the CPU can run this build. Release builds on x86_64 target
//! x86-64-v3 (`.cargo/config.toml`), so the compiler may use AVX2 and FMA anywhere; on an older
//! CPU they would crash with an illegal instruction. [`require_cpu_features`] runs first in
//! `main` and refuses in one line instead.

/// Exits with status 1 and one line on stderr if this x86_64 build was compiled for AVX2/FMA
/// and the CPU lacks them. Does nothing on other architectures or on portable builds.
#[inline(never)]
pub fn require_cpu_features() {
    #[cfg(all(target_arch = "x86_64", any(target_feature = "avx2", target_feature = "fma")))]
    {
        if !(std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")) {
            eprintln!(
                "igi: this build needs an x86-64-v3 CPU (AVX2 and FMA); this CPU lacks them. \
                 Rebuild without .cargo/config.toml's target-cpu for a portable binary."
            );
            std::process::exit(1);
        }
    }
}

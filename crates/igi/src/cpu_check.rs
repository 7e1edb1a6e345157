//! Start-up check that the CPU can run this build. Release builds on x86_64 target
//! x86-64-v3 (`.cargo/config.toml`), so the compiler may use AVX2 and FMA anywhere; on an older
//! CPU they would crash with an illegal instruction. [`require_cpu_features`] runs first in
//! `main` and refuses in one line instead.
//!
//! `is_x86_feature_detected!` cannot be used here: in a build that enables AVX2 at compile time
//! it answers `true` without asking the CPU. The check reads CPUID (and XGETBV, whether the OS
//! saves the AVX registers) itself, and writes its message without any formatting code, so
//! nothing compiled for AVX runs before it.

/// Exits with status 1 and one line on stderr if this x86_64 build was compiled for AVX2/FMA
/// and the CPU (or the OS) lacks them. Does nothing on other architectures or portable builds.
#[inline(never)]
pub fn require_cpu_features() {
    #[cfg(all(target_arch = "x86_64", any(target_feature = "avx2", target_feature = "fma")))]
    if !avx2_fma_usable() {
        use std::io::Write;
        let _ = std::io::stderr().write_all(
            b"igi: this build needs an x86-64-v3 CPU (AVX2 and FMA), which this machine lacks; \
              rebuild without the target-cpu line of .cargo/config.toml for a portable binary\n",
        );
        std::process::exit(1);
    }
}

/// AVX2 and FMA reported by CPUID, and the AVX register state enabled by the OS.
#[cfg(all(target_arch = "x86_64", any(target_feature = "avx2", target_feature = "fma")))]
fn avx2_fma_usable() -> bool {
    use std::arch::x86_64::{__cpuid, __cpuid_count, _xgetbv};
    // SAFETY: CPUID exists on every x86_64 CPU; leaf 7 is only read when leaf 0 says it exists,
    // and XGETBV only when CPUID.1:ECX.OSXSAVE says the OS enabled it.
    unsafe {
        if __cpuid(0).eax < 7 {
            return false;
        }
        let leaf1 = __cpuid(1).ecx;
        let (fma, osxsave, avx) = (leaf1 >> 12 & 1 != 0, leaf1 >> 27 & 1 != 0, leaf1 >> 28 & 1 != 0);
        let avx2 = __cpuid_count(7, 0).ebx >> 5 & 1 != 0;
        fma && avx && avx2 && osxsave && _xgetbv(0) & 0b110 == 0b110
    }
}

#pragma once
// The BLAS kernels CHOLMOD's factorisations run on. OpenBLAS (Debian's libblas.so.3) picks its
// kernels from the CPU's model number when it loads; a release that does not know the model
// falls back to its SSE3 ("Prescott") kernels, 3-5x slower than the AVX2 or AVX-512 ones the
// CPU has (OpenBLAS 0.3.21 on Intel model 207, Emerald Rapids; docs/performance.md, "BLAS kernels
// and huge pages, a fresh VM"). Results differ from one kernel to another only by round-off.

#include <string>

namespace mneedle::fe {

/// What the CPU's vector units offer, as the BLAS kernels use them (lowest first).
enum class SimdLevel { Unknown, Sse, Avx, Avx2, Avx512 };

/// This CPU's level, with the operating system's support for the registers (x86-64; Unknown
/// elsewhere). Avx512 needs AVX-512 F, CD, BW, DQ and VL (OpenBLAS's SkylakeX kernels); Avx2
/// needs AVX2 and FMA.
SimdLevel cpu_simd_level();

/// The SIMD level of an OpenBLAS core type, as openblas_get_corename() names it ("Prescott",
/// "Haswell", "SkylakeX", ...; any case); Unknown for a name it does not list.
SimdLevel openblas_core_level(const std::string& core);

/// The OpenBLAS core type to use instead of `detected` on a CPU of level `cpu`, or "" to keep
/// it: only when `detected` is a known core without AVX2 kernels while the CPU has AVX2 and FMA
/// (OpenBLAS's fallback for a model it does not know) — "SkylakeX" with AVX-512, else
/// "Haswell". A core OpenBLAS chose on purpose (Haswell on an AVX-512 CPU, say) is kept.
std::string better_openblas_core(const std::string& detected, SimdLevel cpu);

/// `auto` (the default): replace OpenBLAS's kernels by better_openblas_core's choice; `off`:
/// keep OpenBLAS's own. Either way a user's OPENBLAS_CORETYPE (set, even empty) is kept.
enum class BlasKernelChoice { Auto, Off };

/// MNEEDLE_BLAS_KERNELS ("auto" or "off"; unset or empty: auto). Throws InputError
/// "MNEEDLE_BLAS_KERNELS: must be \"auto\" or \"off\", got '<value>'" otherwise.
BlasKernelChoice blas_kernel_choice_from_environment();

/// The kernels the factorisations run on.
struct BlasKernels {
  std::string detected;  ///< OpenBLAS's own choice; "" when the BLAS is not a dynamic OpenBLAS
  std::string used;      ///< the core in use now (= detected unless it was replaced)
};

/// Applies `choice` once per process; later calls (any choice) return the first call's result.
/// It re-initialises OpenBLAS's kernel table, so it must run before any BLAS call is in flight:
/// the CLI calls it first thing, the first factorisation otherwise (SparseSolver::factorize, with
/// Auto), and the drivers that factorise on several threads call it before they start them.
BlasKernels select_blas_kernels(BlasKernelChoice choice = BlasKernelChoice::Auto);

/// The threads OpenBLAS runs now (openblas_get_num_threads), or 0 where the BLAS is not OpenBLAS.
int openblas_threads();

}  // namespace mneedle::fe

#include "mneedle/fe/blas_kernels.h"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <mutex>
#include <utility>

#include "mneedle/base/error.h"
#include "mneedle/base/text.h"

namespace mneedle::fe {

SimdLevel cpu_simd_level() {
#if defined(__x86_64__) && defined(__GNUC__)
  // libgcc's checks include the operating system's (XCR0) support for the AVX and AVX-512
  // registers, not only the CPUID bits.
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl"))
    return SimdLevel::Avx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return SimdLevel::Avx2;
  if (__builtin_cpu_supports("avx")) return SimdLevel::Avx;
  return SimdLevel::Sse;
#else
  return SimdLevel::Unknown;
#endif
}

SimdLevel openblas_core_level(const std::string& core) {
  std::string name = core;
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // OpenBLAS's x86-64 core types (driver/others/dynamic.c), by the widest vectors their double
  // kernels use.
  static const std::array<std::pair<const char*, SimdLevel>, 26> kCores{{
      {"katmai", SimdLevel::Sse},        {"coppermine", SimdLevel::Sse},
      {"northwood", SimdLevel::Sse},     {"prescott", SimdLevel::Sse},
      {"banias", SimdLevel::Sse},        {"atom", SimdLevel::Sse},
      {"core2", SimdLevel::Sse},         {"penryn", SimdLevel::Sse},
      {"dunnington", SimdLevel::Sse},    {"nehalem", SimdLevel::Sse},
      {"athlon", SimdLevel::Sse},        {"opteron", SimdLevel::Sse},
      {"opteron_sse3", SimdLevel::Sse},  {"barcelona", SimdLevel::Sse},
      {"nano", SimdLevel::Sse},          {"bobcat", SimdLevel::Sse},
      {"sandybridge", SimdLevel::Avx},   {"bulldozer", SimdLevel::Avx},
      {"piledriver", SimdLevel::Avx},    {"steamroller", SimdLevel::Avx},
      {"haswell", SimdLevel::Avx2},      {"excavator", SimdLevel::Avx2},
      {"zen", SimdLevel::Avx2},          {"skylakex", SimdLevel::Avx512},
      {"cooperlake", SimdLevel::Avx512}, {"sapphirerapids", SimdLevel::Avx512},
  }};
  for (const auto& [known, level] : kCores)
    if (name == known) return level;
  return SimdLevel::Unknown;
}

std::string better_openblas_core(const std::string& detected, SimdLevel cpu) {
  const SimdLevel have = openblas_core_level(detected);
  if (have == SimdLevel::Unknown || have >= SimdLevel::Avx2 || cpu < SimdLevel::Avx2) return "";
  return cpu == SimdLevel::Avx512 ? "SkylakeX" : "Haswell";
}

BlasKernelChoice blas_kernel_choice_from_environment() {
  const char* raw = std::getenv("MNEEDLE_BLAS_KERNELS");
  if (raw == nullptr || *raw == '\0') return BlasKernelChoice::Auto;
  const std::string value(trim(raw));
  if (value == "auto") return BlasKernelChoice::Auto;
  if (value == "off") return BlasKernelChoice::Off;
  throw InputError("MNEEDLE_BLAS_KERNELS: must be \"auto\" or \"off\", got '" + value + "'");
}

namespace {

// Looked up at run time, as blas_threads.cpp does: CHOLMOD reaches OpenBLAS through Debian's
// libblas.so.3 alternative, so which BLAS serves it depends on the machine. A library loaded
// without RTLD_GLOBAL (the Python module) does not put OpenBLAS in the global scope: then the
// already loaded libopenblas.so.0 is asked by name.
void* blas_symbol(const char* name) {
  if (void* found = ::dlsym(RTLD_DEFAULT, name)) return found;
  static void* const library = ::dlopen("libopenblas.so.0", RTLD_LAZY | RTLD_NOLOAD);
  return library != nullptr ? ::dlsym(library, name) : nullptr;
}

BlasKernels apply(BlasKernelChoice choice) {
  using CoreName = char* (*)();
  using Hook = void (*)();
  const auto core_name = reinterpret_cast<CoreName>(blas_symbol("openblas_get_corename"));
  const auto quit = reinterpret_cast<Hook>(blas_symbol("gotoblas_dynamic_quit"));
  const auto init = reinterpret_cast<Hook>(blas_symbol("gotoblas_dynamic_init"));
  if (core_name == nullptr) return {};
  BlasKernels kernels;
  kernels.detected = kernels.used = core_name();
  // A core the user named is OpenBLAS's choice already; a build without DYNAMIC_ARCH has one.
  const char* named = std::getenv("OPENBLAS_CORETYPE");
  if (choice == BlasKernelChoice::Off || named != nullptr || quit == nullptr || init == nullptr)
    return kernels;
  const std::string better = better_openblas_core(kernels.detected, cpu_simd_level());
  if (better.empty()) return kernels;
  // OpenBLAS reads OPENBLAS_CORETYPE when it initialises its kernel table and takes the named
  // core as given: cpu_simd_level() above (CPUID and the operating system's register support) is
  // what keeps an instruction the CPU lacks from running. The variable is removed again so that
  // the environment stays the user's (it was unset: a user's value, even empty, is kept above).
  ::setenv("OPENBLAS_CORETYPE", better.c_str(), 1);
  quit();
  init();
  ::unsetenv("OPENBLAS_CORETYPE");
  kernels.used = core_name();
  return kernels;
}

}  // namespace

BlasKernels select_blas_kernels(BlasKernelChoice choice) {
  static std::once_flag once;
  static BlasKernels selected;
  std::call_once(once, [&] { selected = apply(choice); });
  return selected;
}

int openblas_threads() {
  using Threads = int (*)();
  const auto threads = reinterpret_cast<Threads>(blas_symbol("openblas_get_num_threads"));
  return threads != nullptr ? std::max(0, threads()) : 0;
}

}  // namespace mneedle::fe

// libFuzzer harness: the checks on what a plugin declares (docs/plugins.md, "What the host
// checks"), fed descriptor structs built from the input; no library is ever loaded. Strings are
// NUL-terminated (a C plugin's are) but hold any bytes; pointers may be null; numbers may be NaN.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "plugin_descriptor.h"

namespace {

mneedle_status generate_nothing(const double*, size_t, mneedle_mesh_sink*, char*, size_t) {
  return MNEEDLE_STATUS_INTERNAL_ERROR;
}

// Owns the strings the descriptor points at.
struct Strings {
  std::vector<std::string> held;
  const char* next(FuzzedDataProvider& in) {
    if (in.ConsumeBool()) return nullptr;
    held.push_back(in.ConsumeRandomLengthString(24));
    return held.back().c_str();
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Strings strings;
  strings.held.reserve(256);  // stable c_str() pointers
  std::vector<std::vector<mneedle_parameter>> parameters(in.ConsumeIntegralInRange(0, 4));
  std::vector<mneedle_shape> shapes(parameters.size());
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    parameters[s].resize(in.ConsumeIntegralInRange(0, 4));
    for (auto& p : parameters[s])
      p = {strings.next(in),
           strings.next(in),
           in.ConsumeFloatingPoint<double>(),
           in.ConsumeFloatingPoint<double>(),
           in.ConsumeFloatingPoint<double>(),
           strings.next(in)};
    shapes[s] = {strings.next(in),
                 strings.next(in),
                 parameters[s].empty() && in.ConsumeBool() ? nullptr : parameters[s].data(),
                 parameters[s].size(),
                 in.ConsumeIntegral<std::int32_t>(),
                 in.ConsumeBool() ? generate_nothing : nullptr,
                 nullptr,
                 nullptr};
  }
  mneedle_plugin plugin{
      in.ConsumeBool() ? MNEEDLE_PLUGIN_ABI_MAJOR : in.ConsumeIntegral<std::uint32_t>(),
      in.ConsumeIntegral<std::uint32_t>(), strings.next(in),
      shapes.empty() && in.ConsumeBool() ? nullptr : shapes.data(), shapes.size()};
  try {
    const mneedle_plugin& checked = mneedle::check_plugin_descriptor(&plugin, "fuzz.so");
    (void)mneedle::read_plugin_shapes(checked, "fuzz.so");
  } catch (const mneedle::InputError&) {
  }
  return 0;
}

// libFuzzer harness: the quantity parser (docs/cli.md, introduction). A clean InputError is the
// only acceptable failure; any other exception, a crash or a sanitizer report is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const mneedle::Quantity q = mneedle::parse_quantity(text);
    // A parsed quantity is finite: a NaN or infinity must have been refused.
    if (!std::isfinite(q.value_si)) std::abort();
    (void)mneedle::format_quantity(q.value_si, q.dimension);
  } catch (const mneedle::InputError&) {
  }
  for (int k = 0; k <= static_cast<int>(mneedle::Dimension::Energy); ++k) {
    const auto d = static_cast<mneedle::Dimension>(k);
    try {
      if (!std::isfinite(mneedle::parse_quantity(text, d))) std::abort();
    } catch (const mneedle::InputError&) {
    }
  }
  return 0;
}

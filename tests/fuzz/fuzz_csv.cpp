// libFuzzer harness: the CSV reader every measured-curve command uses (docs/cli.md, "CSV input").
// A clean InputError is the only acceptable failure.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "mneedle/base/csv.h"
#include "mneedle/base/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const mneedle::CsvTable table = mneedle::parse_csv(text, "fuzz.csv");
    // The reader promises rectangular records (docs/cli.md): check it holds for any input.
    for (const auto& row : table.rows)
      if (row.fields.size() != table.header.size()) std::abort();
    if (!table.header.empty()) (void)table.column(table.header.front());
    (void)table.where(table.header_line);
    try {
      (void)table.column("depth_m");
    } catch (const mneedle::InputError&) {
    }
  } catch (const mneedle::InputError&) {
  }
  return 0;
}

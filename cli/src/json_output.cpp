#include "json_output.h"

#include "run_provenance.h"

namespace mneedle::cli {

void print_checked_json(std::ostream& out, const nlohmann::json& tree, std::string_view context) {
  require_finite_json(tree, context);
  out << with_provenance(tree).dump(2) << "\n";
}

void print_checked_json(std::ostream& out, const nlohmann::ordered_json& tree,
                        std::string_view context) {
  require_finite_json(tree, context);
  out << with_provenance(tree).dump(2) << "\n";
}

}  // namespace mneedle::cli

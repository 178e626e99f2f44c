#include "mneedle/base/material_model.h"

namespace mneedle {

std::string_view to_string(MaterialModel m) {
  switch (m) {
    case MaterialModel::Linear:
      return "linear";
    case MaterialModel::StVenantKirchhoff:
      return "svk";
    case MaterialModel::NeoHookean:
      return "neo_hookean";
    case MaterialModel::MooneyRivlin:
      return "mooney_rivlin";
  }
  return "?";
}

}  // namespace mneedle

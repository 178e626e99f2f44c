#include <CLI/CLI.hpp>

#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include "commands.h"
#include "mneedle/base/error.h"
#include "mneedle/base/memory.h"
#include "mneedle/base/text.h"
#include "mneedle/fe/blas_kernels.h"
#include "mneedle/fe/sparse_solver.h"
#include "run_provenance.h"

namespace {

// CLI11 answers a misspelt command with "A subcommand is required", which does not say which
// word it did not know. Follows the words from the left through the known commands; at the first
// one that is neither a command nor an option where a command is required, names it, the closest
// known command and the list (docs/cli.md, "Exit status": unknown command).
std::string unknown_command(CLI::App& app, int argc, char** argv) {
  CLI::App* level = &app;
  std::string path = "mneedle";
  for (int i = 1; i < argc; ++i) {
    const std::string word(argv[i]);
    if (word.empty() || word[0] == '-') return "";
    CLI::App* next = nullptr;
    for (CLI::App* sub : level->get_subcommands({}))
      if (sub->get_name() == word) next = sub;
    if (next) {
      level = next;
      path += " " + word;
      continue;
    }
    if (level->get_require_subcommand_min() == 0) return "";
    std::string known, best;
    std::size_t best_distance = 3;
    for (CLI::App* sub : level->get_subcommands({})) {
      known += (known.empty() ? "" : ", ") + sub->get_name();
      const std::size_t d = mneedle::edit_distance(word, sub->get_name());
      if (d < best_distance) best_distance = d, best = sub->get_name();
    }
    // An abbreviation is closest to the command it starts ("sim": simulate, not fit).
    for (CLI::App* sub : level->get_subcommands({}))
      if (word.size() >= 2 && sub->get_name().rfind(word, 0) == 0) {
        best = sub->get_name();
        break;
      }
    return "unknown command '" + path + " " + word + "'" +
           (best.empty() ? "" : " (did you mean '" + path + " " + best + "'?)") +
           "; known: " + known;
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mneedle: evaluate microneedle designs before fabrication"};
  app.require_subcommand(1);
  app.set_version_flag(
      "--version", [] { return mneedle::cli::version_text(); },
      "Print mneedle's version, source revision and library versions");
  mneedle::cli::add_scene_command(app);
  mneedle::cli::add_plugins_command(app);
  mneedle::cli::add_generate_command(app);
  mneedle::cli::add_inspect_command(app);
  mneedle::cli::add_force_command(app);
  mneedle::cli::add_strength_command(app);
  mneedle::cli::add_screen_command(app);
  mneedle::cli::add_optimize_command(app);
  mneedle::cli::add_fit_command(app);
  mneedle::cli::add_predict_command(app);
  mneedle::cli::add_stats_command(app);
  mneedle::cli::add_simulate_command(app);
  mneedle::cli::add_toughness_command(app);
  mneedle::cli::add_calibrate_command(app);
  mneedle::cli::add_energy_command(app);
  mneedle::cli::add_plane_strain_command(app);
  mneedle::cli::add_export_command(app);
  mneedle::cli::add_report_command(app);
  mneedle::cli::add_uncertainty_command(app);
  // Exit statuses (docs/cli.md, "Exit status"): 0 success, 1 bad input, 2 bad command line,
  // 3 a solver that could not deliver, 4 an internal error (a bug: please report it).
  try {
    // the command line as the user typed it; a word with spaces is quoted
    std::string command;
    for (int i = 0; i < argc; ++i) {
      const std::string word = i == 0 ? std::string("mneedle") : std::string(argv[i]);
      command += (i ? " " : "") + (word.find(' ') == std::string::npos ? word : "'" + word + "'");
    }
    // A malformed SOURCE_DATE_EPOCH is an error for a run, not for --help or --version.
    bool asks_help = false;
    for (int i = 1; i < argc; ++i) {
      const std::string word(argv[i]);
      asks_help = asks_help || word == "--help" || word == "-h" || word == "--version";
    }
    try {
      mneedle::cli::run_provenance() = mneedle::start_provenance(mneedle::cli::valid_utf8(command));
    } catch (const mneedle::InputError&) {
      if (!asks_help) throw;
    }
    // A memory budget below the machine's (docs/cli.md, "Environment"): a factorisation that
    // cannot fit in it is refused before it is allocated.
    if (const char* limit = std::getenv("MNEEDLE_MEMORY_LIMIT"); limit != nullptr && *limit) {
      try {
        mneedle::set_memory_limit_bytes(mneedle::parse_memory_size(limit));
      } catch (const mneedle::InputError& e) {
        if (!asks_help) throw mneedle::InputError(std::string("MNEEDLE_MEMORY_LIMIT: ") + e.what());
      }
    }
    // Huge pages for the factor, off unless turned on (docs/cli.md, "Environment").
    if (const char* huge = std::getenv("MNEEDLE_HUGE_PAGES"); huge != nullptr && *huge) {
      const std::string value(mneedle::trim(huge));
      if (value == "on" || value == "off")
        mneedle::fe::set_huge_pages(value == "on");
      else if (!asks_help)
        throw mneedle::InputError("MNEEDLE_HUGE_PAGES: must be \"on\" or \"off\", got '" + value +
                                  "'");
    }
    // The factorisations' BLAS kernels, before any thread starts (docs/cli.md, "Environment").
    try {
      mneedle::fe::select_blas_kernels(mneedle::fe::blas_kernel_choice_from_environment());
    } catch (const mneedle::InputError&) {
      if (!asks_help) throw;
    }
    app.parse(argc, argv);
  } catch (const mneedle::cli::QuietExit& e) {
    return e.status;
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    const std::string unknown = unknown_command(app, argc, argv);
    std::cerr << "mneedle: error: " << (unknown.empty() ? std::string(e.what()) : unknown)
              << " (see mneedle --help)\n";
    return 2;
  } catch (const mneedle::InputError& e) {
    std::cerr << "mneedle: error: " << e.what() << "\n";
    return 1;
  } catch (const mneedle::SolverError& e) {
    std::cerr << "mneedle: error: " << e.what() << "\n";
    return 3;
  } catch (const std::bad_alloc&) {
    // Not a bug: the run asked for more memory than the machine gave (docs/cli.md, "Exit status").
    std::cerr << "mneedle: error: out of memory: this run needs more than the machine has; a "
                 "coarser fidelity, a smaller contact zone or fewer refinement levels needs less\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "mneedle: internal error: " << e.what()
              << " (a bug in mneedle: please report it)\n";
    return 4;
  }
  return 0;
}

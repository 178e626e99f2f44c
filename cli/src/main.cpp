#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>

#include "commands.h"

int main(int argc, char** argv) {
  CLI::App app{"mneedle: evaluate microneedle designs before fabrication"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "mneedle 0.1.0");
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "mneedle: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

#pragma once
// Every subcommand registers itself on the root app; main() calls these in order.
// Each command runs through CLI11's callback and reports errors by throwing; main() turns
// an exception into one line on stderr and exit status 1.

namespace CLI {
class App;
}

namespace mneedle::cli {

/// Thrown by a process whose error another one reports (a rank > 0 of an MPI run whose rank 0
/// failed the same way): main() exits with `status` and prints nothing.
struct QuietExit {
  int status;
};

void add_scene_command(CLI::App& app);
void add_plugins_command(CLI::App& app);
void add_generate_command(CLI::App& app);
void add_inspect_command(CLI::App& app);
void add_force_command(CLI::App& app);
void add_strength_command(CLI::App& app);
void add_screen_command(CLI::App& app);
void add_optimize_command(CLI::App& app);
void add_fit_command(CLI::App& app);
void add_predict_command(CLI::App& app);
void add_stats_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_toughness_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
void add_energy_command(CLI::App& app);
void add_plane_strain_command(CLI::App& app);
void add_export_command(CLI::App& app);
void add_report_command(CLI::App& app);
void add_uncertainty_command(CLI::App& app);

}  // namespace mneedle::cli

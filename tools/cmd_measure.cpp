// `smtcal measure plan|program|read`: the paper's robot calibration
// measurement, from an uncalibrated robot to the raw measurements `table
// build` averages (docs/measure.md). The family only; each command is a file
// of its own (cmd_measure_plan.cpp, cmd_measure_program.cpp,
// cmd_measure_read.cpp).
#include <CLI/CLI.hpp>

#include "tools/commands.h"

namespace smtcal::tools {

void AddMeasureCommand(CLI::App& app, GlobalOptions& options) {
  CLI::App* measure = app.add_subcommand(
      "measure",
      "Measure the robot's error tables with the cell's device (docs/measure.md): plan the grid and the visits,\n"
      "make the controller's measuring programs, read their logs back into raw measurements for table build");
  measure->require_subcommand(1);
  AddMeasurePlanCommand(*measure, options);
  AddMeasureProgramCommand(*measure, options);
  AddMeasureReadCommand(*measure, options);
}

}  // namespace smtcal::tools

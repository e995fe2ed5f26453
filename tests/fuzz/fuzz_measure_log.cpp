// A measuring program's log (`smtcal measure read`): the guide's plan for
// examples/calibrating/scratch.cell.toml (`measure plan --sets 1
// --repetitions 2`, made once, as plan.csv), then the log read against it
// (every line screened at the source), its settings checked against the
// cell, and, when it read cleanly, its readings screened against the device
// and against their node's others.
#include <cstdio>

#include "backend/reports/measurement_csv.h"
#include "calibration/measurement_plan.h"
#include "calibration/measurement_reading.h"
#include "frontend/cell_toml.h"
#include "frontend/measurement_input.h"
#include "tests/fuzz/fuzz_target.h"

namespace {

struct Setup {
  smtcal::SourceManager sources;  // the cell's and the plan's locations point into it
  smtcal::cell::Cell cell;
  smtcal::measure::LoadedPlan plan;
};

const Setup& TheSetup() {
  using namespace smtcal;
  static Setup* setup = [] {
    auto* made = new Setup;
    Diagnostics diags(made->sources);
    const std::string path = (fuzz::SourceDir() / "examples/calibrating/scratch.cell.toml").string();
    Result<std::optional<cell::Cell>> loaded =
        cell::LoadCell(path, made->sources, diags, cell::CellLoadOptions{.tables_may_be_missing = true});
    if (!loaded || !loaded.value()) {
      std::fprintf(stderr, "%s", diags.RenderText().c_str());
      fuzz::Fail("the calibrating example's cell did not load");
    }
    made->cell = std::move(*loaded.value());
    measure::PlanOptions options;
    options.sets = 1;
    options.repetitions = 2;
    std::optional<measure::Plan> plan = measure::MakePlan(made->cell, options, diags);
    if (!plan) fuzz::Fail("the guide's plan was not made");
    const std::uint32_t file = made->sources.Add("plan.csv", FormatPlanCsv(*plan, "scratch.cell.toml"));
    std::optional<measure::LoadedPlan> read = measure::LoadPlan(file, made->cell, diags);
    if (!read || diags.has_errors()) {
      std::fprintf(stderr, "%s", diags.RenderText().c_str());
      fuzz::Fail("the guide's plan did not read back");
    }
    made->plan = std::move(*read);
    return made;
  }();
  return *setup;
}

}  // namespace

SMTCAL_FUZZ_TARGET(measure_log) {
  using namespace smtcal;
  const Setup& setup = TheSetup();
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("measure_s1.log", std::string(fuzz::AsText(data, size)));
  if (std::optional<measure::MeasuringLog> log = measure::ReadMeasuringLog(file, setup.plan, diags)) {
    measure::CheckLogSettings(*log, setup.cell, diags);
    if (!diags.has_errors() && setup.cell.measure) {
      measure::CheckReadings(*setup.cell.measure, setup.cell.robot, log->readings, "plan.csv", diags);
    }
  }
  diags.RenderText();
  return 0;
}

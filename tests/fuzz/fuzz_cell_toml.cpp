// A cell file (`smtcal cell check`) with every table, fixture and feeder
// section; it may name the example cell's tables (placing-table.csv, ...),
// which lie beside it.
#include "calibration/fixture_estimation.h"
#include "frontend/cell_toml.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(cell_toml) {
  using namespace smtcal;
  const std::string path = fuzz::WriteScratch("fuzz.cell.toml", fuzz::AsText(data, size));
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(path, sources, diags);
  if (loaded && loaded.value()) {
    const cell::Cell& cell = *loaded.value();
    for (const cell::Fixture& fixture : cell.fixtures) {
      ExpectedTrips(fixture);
      if (!fixture.teach_trips_mm.empty()) TeachScan(cell, fixture);
    }
  }
  diags.RenderText();
  diags.RenderJson();
  return 0;
}

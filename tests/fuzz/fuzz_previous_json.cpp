// The previous scan of `smtcal fixture --previous` (JSON) for the example
// cell's fixture.
#include "frontend/previous_scan_json.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(previous_json) {
  using namespace smtcal;
  const cell::Fixture& fixture = fuzz::ExampleCell().fixtures.front();
  SourceManager sources;
  Diagnostics diags(sources);
  ReadPreviousScan(sources.Add("previous.json", std::string(fuzz::AsText(data, size))), fixture, diags);
  diags.RenderText();
  diags.RenderJson();
  return 0;
}

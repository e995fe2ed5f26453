// A truth file (`smtcal simulate --truth`) for the example cell: the
// reader and its checks against the cell.
#include "frontend/truth_toml.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(truth_toml) {
  using namespace smtcal;
  const cell::Cell& cell = fuzz::ExampleCell();
  const std::string path = fuzz::WriteScratch("fuzz.truth.toml", fuzz::AsText(data, size));
  SourceManager sources;
  Diagnostics diags(sources);
  (void)LoadTruth(path, cell, sources, diags);
  return 0;
}

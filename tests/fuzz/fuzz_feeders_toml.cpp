// A feeders file (`smtcal import --feeders`): the reader, then the feeder
// table with the import test cell's own feeders (duplicate names, rules to
// unknown feeders, lanes beyond a pallet).
#include "frontend/cad/cad_row.h"
#include "frontend/feeders_toml.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(feeders_toml) {
  using namespace smtcal;
  const cell::Cell& cell = fuzz::ImportCell();
  const std::string path = fuzz::WriteScratch("fuzz.feeders.toml", fuzz::AsText(data, size));
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cad::FeedersFile>> file = cad::LoadFeeders(path, sources, diags);
  if (file && file.value()) {
    std::optional<cad::FeederTable> table = cad::FeederTable::Build(cell.feeders, std::move(*file.value()), diags);
    if (table) {
      cad::Row row;
      row.designator = "R1";
      row.package = "0805";
      row.value = "10k";
      table->Find(row);
    }
  }
  diags.RenderText();
  return 0;
}

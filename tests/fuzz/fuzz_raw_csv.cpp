// Raw repeated measurements (`smtcal table build`): the reader, averaging
// into a table, its validation and the table's CSV.
#include "backend/reports/table_report.h"
#include "calibration/error_table_build.h"
#include "calibration/error_table_check.h"
#include "frontend/table_csv.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(raw_csv) {
  using namespace smtcal;
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("raw.csv", std::string(fuzz::AsText(data, size)));
  std::optional<std::vector<RawMeasurement>> raw = ReadRawMeasurements(file, diags);
  if (raw) {
    std::optional<ErrorTable> table = BuildErrorTable("raw.csv", *raw, SourceLoc{file, 0, 0}, diags);
    if (table && ValidateErrorTable(*table, diags, TableWarnings::kReport)) {
      FormatTableCsv(*table, BuiltTableComment("raw.csv"));
    }
  }
  diags.RenderText();
  diags.RenderJson();
  return 0;
}

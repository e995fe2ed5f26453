// A point list (`smtcal table forward|inverse`) solved through the example
// cell's placing table by both solvers and the forward map.
#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "frontend/table_csv.h"
#include "tests/fuzz/fuzz_solve.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(points_csv) {
  using namespace smtcal;
  struct Example {
    SourceManager sources;
    std::optional<ErrorTable> table;
    TableAnalysis analysis;
  };
  static Example* example = [] {
    auto* loaded = new Example;
    Diagnostics diags(loaded->sources);
    Result<std::uint32_t> file =
        loaded->sources.Load((fuzz::SourceDir() / "examples/paper-cell/placing-table.csv").string());
    if (!file) fuzz::Fail("the example table did not load");
    loaded->table = ReadErrorTable(file.value(), diags);
    if (!loaded->table || !ValidateErrorTable(*loaded->table, diags, TableWarnings::kSkip, &loaded->analysis)) {
      fuzz::Fail("the example table is not valid");
    }
    return loaded;
  }();

  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("points.csv", std::string(fuzz::AsText(data, size)));
  std::optional<std::vector<PointRow>> points = ReadPoints(file, diags);
  if (points) {
    static const fuzz::Solvers solvers(*example->table, example->analysis);
    for (const PointRow& row : *points) fuzz::Solve(solvers, row.point);
  }
  diags.RenderText();
  return 0;
}

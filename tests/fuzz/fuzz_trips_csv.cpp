// A trip file (`smtcal fixture --trips`) for the example cell's fixture,
// then the scan: S1..S3, FIX and every check, with each estimator.
#include "calibration/fixture_estimation.h"
#include "frontend/trips_csv.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(trips_csv) {
  using namespace smtcal;
  const cell::Cell& cell = fuzz::ExampleCell();
  const cell::Fixture& fixture = cell.fixtures.front();
  const std::size_t expected = ExpectedTrips(fixture).size();
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("trips.csv", std::string(fuzz::AsText(data, size)));
  std::optional<std::vector<TripRow>> rows = ReadTrips(file, expected, fixture.name, diags);
  if (rows) {
    std::vector<std::optional<Eigen::Vector2d>> trips(expected);
    for (const TripRow& row : *rows) trips[row.index] = row.point;
    for (cell::Estimator estimator :
         {cell::Estimator::kPaper, cell::Estimator::kRigid, cell::Estimator::kRigidScale}) {
      ScanOptions options;
      options.estimator = estimator;
      options.regions = &cell.regions;
      ScanResult result = ScanFixture(fixture, trips, options);
      if (result.ok()) {
        options.previous = *result.fix;
        ScanFixture(fixture, trips, options);
      }
      DescribeFailure(result, fixture);
    }
  }
  diags.RenderText();
  return 0;
}

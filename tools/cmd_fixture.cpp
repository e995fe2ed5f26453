// `smtcal fixture`: one marker scan of a fixture, as the runtime does it at
// the start of a cycle (docs/periphery.md): the trip points -> S1..S3, FIX,
// the pose, the delta to the previous scan and every check with its value and
// limit. The math is in passes/fixture_estimation; the trip file reader in
// frontend/trips_csv; this file wires files, options, output and exit codes.
#include <cctype>
#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <CLI/CLI.hpp>

#include "base/field_text.h"
#include "base/json_text.h"
#include "calibration/fixture_estimation.h"
#include "frontend/cell_toml.h"
#include "frontend/previous_scan_json.h"
#include "frontend/trips_csv.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

using nlohmann::ordered_json;

struct FixtureOptions {
  std::string cell;
  std::string fixture;
  std::string trips;
  std::string estimator;  // empty: the fixture's own
  std::string previous;
  bool json = false;
};

std::optional<cell::Estimator> ParseEstimator(const std::string& name) {
  for (cell::Estimator estimator :
       {cell::Estimator::kPaper, cell::Estimator::kRigid, cell::Estimator::kRigidScale}) {
    if (cell::EstimatorName(estimator) == name) return estimator;
  }
  return std::nullopt;
}

// Fixed decimals for reports; never "-0.000".
std::string Fixed(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text.front() == '-') text.erase(0, 1);
  return text;
}

// ------------------------------------------------------------------ output

std::string EdgeOf(const cell::Fixture& fixture, const ExpectedTrip& trip) {
  return fixture.edges[static_cast<std::size_t>(trip.edge)].name;
}

std::string RegionName(const cell::Cell& cell, int region) {
  return region < 0 ? "-" : cell.regions[static_cast<std::size_t>(region)].name;
}

std::string MatrixText(const Eigen::Affine3d& fix) {
  std::string out;
  for (int r = 0; r < 4; ++r) {
    out += "  [";
    for (int c = 0; c < 4; ++c) out += fmt::format(" {:>14}", Fixed(fix.matrix()(r, c), c == 3 ? 6 : 9));
    out += " ]\n";
  }
  return out;
}

std::string PoseText(const FixEstimate& estimate) {
  return fmt::format("x {} mm, y {} mm, angle {} deg, scale {}", Fixed(estimate.fix.translation().x(), 6),
                     Fixed(estimate.fix.translation().y(), 6), Fixed(FixAngleRad(estimate.fix) * kDegPerRad, 6),
                     Fixed(estimate.scale, 9));
}

std::string CheckValueText(const CheckResult& check) {
  const std::string_view unit = ScanCheckUnit(check.check);
  if (check.check == ScanCheck::kMissingTrip) return fmt::format("{} missing", static_cast<int>(check.value));
  if (check.check == ScanCheck::kDegenerate) return check.passed ? "pose defined" : "no pose";
  return fmt::format("{} {}", Fixed(check.value, 4), unit);
}

std::string CheckLimitText(const CheckResult& check) {
  if (check.check == ScanCheck::kMissingTrip || check.check == ScanCheck::kDegenerate) return "";
  return fmt::format("<= {} {}", FormatMm(check.limit), ScanCheckUnit(check.check));
}

std::string Text(const cell::Cell& cell, const cell::Fixture& fixture, const std::string& trips_name,
                 const std::vector<TripRow>& rows, const ScanResult& result, bool have_previous) {
  std::string out = fmt::format("fixture {}: estimator {}, {} trips from {}\n", fixture.name,
                                cell::EstimatorName(result.estimator), rows.size(), trips_name);
  out += "trip  edge  commanded (mm)              calibrated (mm)             region    from nominal  residual\n";
  for (std::size_t k = 0; k < result.expected.size(); ++k) {
    std::string line = fmt::format("{:<5} {:<5} ", TripName(k), EdgeOf(fixture, result.expected[k]));
    if (!result.trips[k]) {
      out += line + "missing\n";
      continue;
    }
    const Eigen::Vector2d& t = *result.trips[k];
    line += fmt::format("{:>12} {:>12}  ", Fixed(t.x(), 4), Fixed(t.y(), 4));
    const bool calibrated = result.Check(ScanCheck::kDegenerate).evaluated;
    if (calibrated) {
      line += fmt::format("{:>12} {:>12}  {:<9} ", Fixed(result.calibrated[k].x(), 4),
                          Fixed(result.calibrated[k].y(), 4), RegionName(cell, result.region[k]));
    } else {
      line += fmt::format("{:>12} {:>12}  {:<9} ", "-", "-", "-");
    }
    line += fmt::format("{:>9} mm", Fixed(result.window_mm[k], 4));
    if (result.estimate) line += fmt::format("  {:>8} mm", Fixed(result.estimate->residual_mm[k], 4));
    out += line + "\n";
  }
  if (result.estimate) {
    const FixEstimate& e = *result.estimate;
    for (int s = 0; s < 3; ++s) {
      out += fmt::format("S{} = ({}, {})\n", s + 1, Fixed(e.s[static_cast<std::size_t>(s)].x(), 6),
                         Fixed(e.s[static_cast<std::size_t>(s)].y(), 6));
    }
  }
  if (result.fix) {
    out += "FIX =\n" + MatrixText(*result.fix);
    out += "pose: " + PoseText(*result.estimate) + "\n";
  } else if (result.estimate) {
    out += "FIX: none (the scan failed a check); the rejected estimate: " + PoseText(*result.estimate) + "\n";
  } else {
    out += "FIX: none (the scan failed a check before a pose could be estimated)\n";
  }
  if (result.delta) {
    out += fmt::format("delta to previous: origin moved {} mm, turned {} deg; FIX_n . FIX_(n-1)^-1 =\n",
                       Fixed(result.Check(ScanCheck::kCycleShift).value, 6),
                       Fixed(FixAngleRad(*result.delta) * kDegPerRad, 6));
    out += MatrixText(*result.delta);
  } else {
    out += have_previous ? "delta to previous: none (no pose this scan)\n"
                         : "delta to previous: none (no --previous)\n";
  }
  out += "checks:\n";
  for (const CheckResult& check : result.checks) {
    std::string name(ScanCheckName(check.check));
    if (!check.evaluated) {
      const bool cycle = check.check == ScanCheck::kCycleShift || check.check == ScanCheck::kCycleRotation;
      out += fmt::format("  {:<17} not run ({})\n", name,
                         cycle && !have_previous ? "no previous scan" : "an earlier check failed");
      continue;
    }
    const std::string trip = check.trip >= 0 && !check.passed
                                 ? fmt::format(" ({})", TripName(static_cast<std::size_t>(check.trip)))
                                 : std::string();
    out += fmt::format("  {:<17} {:<16} {:<16} {}{}\n", name, CheckValueText(check), CheckLimitText(check),
                       check.passed ? "ok" : "FAILED", trip);
  }
  const CheckResult* failure = result.FirstFailure();
  out += failure == nullptr ? "result: ok, FIX holds for this cycle\n"
                            : fmt::format("result: FAILED ({}): no pose; the cycle must not place\n",
                                          ScanCheckName(failure->check));
  return out;
}

// Decimals of the JSON output (docs/periphery.md), as the text prints them:
// computed lengths and angles to 1e-6 mm and degrees, the scale to 1e-9.
// The 4 x 4 matrices keep every bit: --previous reads "fix" back, and a
// reader recomputing a placement from it must get the same numbers. The
// trips and limits are the user's numbers, as given; a check's value is
// rounded to 1e-6 of its unit.
constexpr int kMmDecimals = 6;
constexpr int kDegDecimals = 6;
constexpr int kScaleDecimals = 9;

double Mm(double mm) { return RoundedToDecimals(mm, kMmDecimals); }

ordered_json Matrix(const Eigen::Affine3d& transform) {
  ordered_json matrix = ordered_json::array();
  for (int r = 0; r < 4; ++r) {
    ordered_json row = ordered_json::array();
    for (int c = 0; c < 4; ++c) row.push_back(transform.matrix()(r, c) + 0.0);
    matrix.push_back(row);
  }
  return matrix;
}

ordered_json FixJson(const FixEstimate& estimate) {
  return {{"matrix", Matrix(estimate.fix)},
          {"x_mm", Mm(estimate.fix.translation().x())},
          {"y_mm", Mm(estimate.fix.translation().y())},
          {"angle_deg", RoundedToDecimals(FixAngleRad(estimate.fix) * kDegPerRad, kDegDecimals)},
          {"scale", RoundedToDecimals(estimate.scale, kScaleDecimals)}};
}

std::string Json(const cell::Cell& cell, const cell::Fixture& fixture, const std::string& trips_name,
                 const std::vector<TripRow>& rows, const ScanResult& result) {
  ordered_json out;
  const CheckResult* failure = result.FirstFailure();
  out["fixture"] = fixture.name;
  out["estimator"] = cell::EstimatorName(result.estimator);
  out["trips_file"] = trips_name;
  out["ok"] = result.ok();
  out["fault"] = failure == nullptr ? ordered_json() : ordered_json(ScanCheckName(failure->check));
  out["message"] = failure == nullptr ? ordered_json() : ordered_json(DescribeCheck(*failure, fixture));
  std::vector<std::optional<double>> z(result.expected.size());
  for (const TripRow& row : rows) z[row.index] = row.z_mm;
  ordered_json trips = ordered_json::array();
  for (std::size_t k = 0; k < result.expected.size(); ++k) {
    ordered_json trip;
    trip["name"] = TripName(k);
    trip["edge"] = EdgeOf(fixture, result.expected[k]);
    trip["path"] = fixture.scan_paths[result.expected[k].path].name;
    trip["nominal_mm"] = {Mm(result.nominal[k].x()), Mm(result.nominal[k].y())};
    trip["missing"] = !result.trips[k].has_value();
    if (result.trips[k]) {
      trip["commanded_mm"] = {result.trips[k]->x(), result.trips[k]->y()};
      trip["z_mm"] = z[k] ? ordered_json(*z[k]) : ordered_json();
      trip["from_nominal_mm"] = Mm(result.window_mm[k]);
      if (result.Check(ScanCheck::kDegenerate).evaluated) {
        trip["calibrated_mm"] = {Mm(result.calibrated[k].x()), Mm(result.calibrated[k].y())};
        trip["region"] = result.region[k] < 0 ? ordered_json() : ordered_json(RegionName(cell, result.region[k]));
      }
      if (result.estimate) trip["residual_mm"] = Mm(result.estimate->residual_mm[k]);
    }
    trips.push_back(trip);
  }
  out["trips"] = trips;
  if (result.estimate) {
    out["s_mm"] = ordered_json::array();
    for (const Eigen::Vector2d& s : result.estimate->s) out["s_mm"].push_back({Mm(s.x()), Mm(s.y())});
  } else {
    out["s_mm"] = nullptr;
  }
  out["fix"] = result.fix ? FixJson(*result.estimate) : ordered_json();
  out["estimate"] = result.estimate ? FixJson(*result.estimate) : ordered_json();
  if (result.delta) {
    out["delta"] = {{"matrix", Matrix(*result.delta)},
                    {"shift_mm", Mm(result.Check(ScanCheck::kCycleShift).value)},
                    {"rotation_deg", RoundedToDecimals(result.Check(ScanCheck::kCycleRotation).value, kDegDecimals)}};
  } else {
    out["delta"] = nullptr;
  }
  ordered_json checks = ordered_json::array();
  for (const CheckResult& check : result.checks) {
    ordered_json entry;
    entry["name"] = ScanCheckName(check.check);
    entry["evaluated"] = check.evaluated;
    entry["passed"] = check.evaluated ? ordered_json(check.passed) : ordered_json();
    entry["value"] = check.evaluated ? ordered_json(RoundedToDecimals(check.value, kMmDecimals)) : ordered_json();
    entry["limit"] = check.limit;
    entry["unit"] = ScanCheckUnit(check.check);
    entry["trip"] = check.trip >= 0 ? ordered_json(TripName(static_cast<std::size_t>(check.trip))) : ordered_json();
    checks.push_back(entry);
  }
  out["checks"] = checks;
  return JsonText(out);
}

// The failed check as a diagnostic: at the trip's row when it concerns one
// that is in the file, else at the trips file.
void ReportFailure(const ScanResult& result, const cell::Fixture& fixture, const std::vector<TripRow>& rows,
                   std::uint32_t file, Diagnostics& diags) {
  const CheckResult* failure = result.FirstFailure();
  if (failure == nullptr) return;
  SourceRange where(SourceLoc{file, 0, 0});
  for (const TripRow& row : rows) {
    if (failure->trip >= 0 && row.index == static_cast<std::size_t>(failure->trip)) where = row.range;
  }
  diags.Report(DiagKind::FixtureScanFailed, where, fixture.name, ScanCheckName(failure->check),
               DescribeCheck(*failure, fixture));
}

void Run(const FixtureOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"--cell", opt.cell}, {"--trips", opt.trips}, {"--previous", opt.previous}}, {})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  const std::optional<cell::Cell> loaded = LoadCellOrReport(opt.cell, sources, diags, options);
  if (!loaded) return;
  const cell::Cell& cell = *loaded;
  const cell::Fixture* fixture = cell.FindFixture(opt.fixture);
  if (fixture == nullptr) {
    std::string names;
    for (const cell::Fixture& f : cell.fixtures) names += (names.empty() ? "" : ", ") + f.name;
    options.exit_code = ReportUsageError(fmt::format("the cell {} has no fixture '{}'; {}", opt.cell, opt.fixture,
                                                     names.empty() ? "it describes none" : "its fixtures: " + names));
    return;
  }
  Result<std::uint32_t> trips_file = sources.Load(opt.trips);
  if (!trips_file) {
    options.exit_code = ReportIoError(trips_file.error());
    return;
  }
  ScanOptions scan_options;
  scan_options.estimator = opt.estimator.empty() ? fixture->estimator : *ParseEstimator(opt.estimator);
  scan_options.regions = &cell.regions;
  const std::size_t expected = ExpectedTrips(*fixture).size();
  std::optional<std::vector<TripRow>> rows = ReadTrips(trips_file.value(), expected, fixture->name, diags);
  if (!opt.previous.empty()) {
    Result<std::uint32_t> previous_file = sources.Load(opt.previous);
    if (!previous_file) {
      options.exit_code = ReportIoError(previous_file.error());
      return;
    }
    scan_options.previous = ReadPreviousScan(previous_file.value(), *fixture, diags);
  }
  if (!rows || diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  std::vector<std::optional<Eigen::Vector2d>> trips(expected);
  for (const TripRow& row : *rows) trips[row.index] = row.point;
  const ScanResult result = ScanFixture(*fixture, trips, scan_options);
  ReportFailure(result, *fixture, *rows, trips_file.value(), diags);
  const std::string name = sources.File(trips_file.value()).name;
  const std::string text = opt.json ? Json(cell, *fixture, name, *rows, result)
                                    : Text(cell, *fixture, name, *rows, result, !opt.previous.empty());
  options.exit_code = PrintDiagnostics(diags, options);
  Status written = WriteFileAtomically("-", text);
  if (!written) options.exit_code = ReportIoError(written.error());
}

}  // namespace

void AddFixtureCommand(CLI::App& app, GlobalOptions& options) {
  static FixtureOptions opt;
  CLI::App* command = app.add_subcommand(
      "fixture",
      "One marker scan of a fixture (docs/periphery.md): trip points -> S1..S3, FIX, the pose, the delta\n"
      "to the previous scan, and every check with its value and limit; exit 1 when a check fails\n"
      "(the scan gives no pose and the cycle must not place)");
  command->add_option("--cell", opt.cell, "the cell file (*.cell.toml) describing the fixture")->required();
  command->add_option("--fixture", opt.fixture, "the fixture's name in the cell (case-insensitive)")->required();
  command->add_option("--trips", opt.trips,
                      "the trip points: CSV name,x_mm,y_mm[,z_mm], one row per trip T1..Tn in the robot\n"
                      "base frame as commanded when the sensor tripped ('-' for stdin); a trip without a row\n"
                      "is missing, and a header without rows is a scan in which no trip was recorded")
      ->required();
  command->add_option("--estimator", opt.estimator,
                      "paper (Eq. 4 on the fitted lines' crossings), rigid (least squares over all trips:\n"
                      "rotation + translation) or rigid-scale (plus one scale); default: the fixture's")
      ->check(CLI::IsMember({"paper", "rigid", "rigid-scale"}));
  command->add_option("--previous", opt.previous,
                      "the previous cycle's scan, as written by --json: enables the per-cycle checks\n"
                      "FIX_n . FIX_(n-1)^-1 against the shift and rotation limits");
  command->add_flag("--json", opt.json, "print JSON (accepted by --previous of the next run) instead of text");
  command->callback([&options] { Run(opt, options); });
}

}  // namespace smtcal::tools

// What a log of cycle records says about the cell (spc/cycle_monitor.h).
#include "spc/cycle_monitor.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "base/check.h"
#include "base/field_text.h"
#include "base/number_range.h"
#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "calibration/placement_budget.h"
#include "calibration/sample_statistics.h"
#include "spc/bernoulli_cusum.h"

namespace smtcal {
namespace {

constexpr double kUmPerMm = 1000;
constexpr double kPpm = 1e6;

struct QuantityInfo {
  std::string_view name, title, unit;
  Direction direction;
  double resolution;  // the chart's smallest sigma: what 6-decimal records resolve
  bool gates;
};

constexpr std::array<QuantityInfo, kQuantities> kInfo = {{
    {"pose_x", "board pose x", "µm", Direction::kBoth, 0.001, true},
    {"pose_y", "board pose y", "µm", Direction::kBoth, 0.001, true},
    {"pose_angle", "board angle", "mdeg", Direction::kBoth, 0.001, true},
    {"marker_scale", "marker distance", "ppm", Direction::kBoth, 0.01, true},
    {"sensor_threshold", "sensor threshold", "µm", Direction::kBoth, 0.001, true},
    {"residual_rms", "trip scatter", "µm", Direction::kUp, 0.001, true},
    {"residual_max", "largest residual", "µm", Direction::kUp, 0.001, false},
}};

const QuantityInfo& Info(Quantity q) { return kInfo[static_cast<std::size_t>(q)]; }

// The scan's diagnostic fit: every trip on its edge line moved by the
// sensor's threshold, the board turned, shifted and scaled. In the unknowns
// u = (cos, sin) / scale, w (the shift) and delta (the threshold), a trip q
// (base frame, centred) on the edge n . f = d of its marker gives the linear
// equation  u1 (n . q) + u2 (n x q) - n . w - iota delta = d, iota = +1
// when the marker lies on the normal's side of the edge (docs/monitor.md).
class ScanDiagnostics {
 public:
  // The smallest singular value of the (column-normalised) design, relative
  // to the largest, of a fit whose unknowns the layout determines.
  static constexpr double kIdentifiable = 1e-6;
  // The threshold's standard error in single trips' noise that still makes
  // a chart: more, and it charts the trips' noise amplified.
  static constexpr double kThresholdNoise = 2;

  explicit ScanDiagnostics(const cell::Fixture& fixture) : expected_(ExpectedTrips(fixture)) {
    std::vector<std::size_t> on_path(fixture.scan_paths.size(), 0);
    for (const ExpectedTrip& e : expected_) {
      const EdgeLine line = EdgeLineOf(fixture.edges[static_cast<std::size_t>(e.edge)]);
      normals_.push_back(line.normal);
      offsets_.push_back(line.offset);
      // Every path starts off the markers: its trips enter and leave in turn.
      const bool entering = on_path[e.path]++ % 2 == 0;
      const double across = line.normal.dot(e.leg_direction) >= 0 ? 1.0 : -1.0;
      iota_.push_back(entering ? across : -across);
    }
    // Which unknowns the layout determines, from the nominal trips: the
    // scale when the design has full rank, the threshold when its standard
    // error is at most kThresholdNoise times a single trip's (with the
    // paper cell's layout each marker moves as a whole when the sensor sees
    // it smaller, which the pose and the scale take: no threshold).
    const std::vector<Eigen::Vector2d> nominal = NominalTrips(fixture, NominalFix(fixture));
    scale_ = Rank(nominal, 4) == 4;
    threshold_ = scale_ && Rank(nominal, 5) == 5 && ThresholdNoise(nominal) <= kThresholdNoise;
  }

  bool scale() const { return scale_; }
  bool threshold() const { return threshold_; }

  struct Fit {
    double scale_ppm = 0;
    std::optional<double> threshold_um;
    double rms_um = 0;  // what the fit leaves
  };

  std::optional<Fit> Of(const std::vector<Eigen::Vector2d>& trips) const {
    if (!scale_) return std::nullopt;
    const int unknowns = threshold_ ? 5 : 4;
    const Eigen::MatrixXd a = Design(trips, unknowns);
    Eigen::VectorXd d(static_cast<Eigen::Index>(trips.size()));
    for (std::size_t k = 0; k < trips.size(); ++k) d(static_cast<Eigen::Index>(k)) = offsets_[k];
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(d);
    const double length = std::hypot(x(0), x(1));
    if (!std::isfinite(length) || length == 0) return std::nullopt;
    Fit fit;
    fit.scale_ppm = (1 / length - 1) * kPpm;
    if (threshold_) fit.threshold_um = x(4) * kUmPerMm;
    const Eigen::VectorXd r = a * x - d;
    // Residuals in fixture millimetres: the equations are in fixture units.
    fit.rms_um = std::sqrt(r.squaredNorm() / static_cast<double>(trips.size())) * kUmPerMm;
    return fit;
  }

 private:
  Eigen::MatrixXd Design(const std::vector<Eigen::Vector2d>& trips, int unknowns) const {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& t : trips) centre += t;
    centre /= static_cast<double>(trips.size());
    Eigen::MatrixXd a(static_cast<Eigen::Index>(trips.size()), unknowns);
    for (std::size_t k = 0; k < trips.size(); ++k) {
      const Eigen::Vector2d q = trips[k] - centre;
      const Eigen::Vector2d& n = normals_[k];
      const auto row = static_cast<Eigen::Index>(k);
      a(row, 0) = n.dot(q);
      a(row, 1) = n.x() * q.y() - n.y() * q.x();
      a(row, 2) = -n.x();
      a(row, 3) = -n.y();
      if (unknowns == 5) a(row, 4) = -iota_[k];
    }
    return a;
  }

  // The threshold's standard error per unit of trip noise: sqrt of the last
  // diagonal element of (A^T A)^-1.
  double ThresholdNoise(const std::vector<Eigen::Vector2d>& trips) const {
    const Eigen::MatrixXd a = Design(trips, 5);
    const Eigen::MatrixXd inverse = (a.transpose() * a).inverse();
    return std::sqrt(std::max(0.0, inverse(4, 4)));
  }

  int Rank(const std::vector<Eigen::Vector2d>& trips, int unknowns) const {
    if (static_cast<int>(trips.size()) < unknowns) return 0;
    Eigen::MatrixXd a = Design(trips, unknowns);
    // Columns in comparable units: the rotation columns scale with the trips' spread.
    for (Eigen::Index c = 0; c < a.cols(); ++c) {
      const double norm = a.col(c).norm();
      if (norm > 0) a.col(c) /= norm;
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
    const Eigen::VectorXd s = svd.singularValues();
    int rank = 0;
    for (Eigen::Index i = 0; i < s.size(); ++i) rank += s(i) > kIdentifiable * s(0) ? 1 : 0;
    return rank;
  }

  std::vector<ExpectedTrip> expected_;
  std::vector<Eigen::Vector2d> normals_;
  std::vector<double> offsets_;
  std::vector<double> iota_;
  bool scale_ = false, threshold_ = false;
};

// The placement error at a board point per ppm of robot scale error that
// the tables do not know, through the fixture's estimator: the trips the
// runtime calibrates are off by -s (t - c), the part lands off by s (r - c).
double UmPerPpm(const cell::Fixture& fixture, const Eigen::Vector2d& in_fixture) {
  constexpr double s = 1e-4;  // 100 ppm: linear, far above rounding
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, nominal);
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& t : trips) centre += t;
  centre /= static_cast<double>(trips.size());
  std::vector<Eigen::Vector2d> seen;
  for (const Eigen::Vector2d& t : trips) seen.push_back(t - s * (t - centre));
  const std::optional<FixEstimate> estimate = EstimateFix(fixture, ExpectedTrips(fixture), seen, fixture.estimator);
  if (!estimate) return 0;
  const Eigen::Vector2d required = ToBase(estimate->fix, in_fixture);
  const Eigen::Vector2d landed = required + s * (required - centre);
  return (landed - ToBase(nominal, in_fixture)).norm() * kUmPerMm / (s * kPpm);
}

Eigen::Vector2d TripCentre(const cell::Fixture& fixture) {
  const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, NominalFix(fixture));
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& t : trips) centre += t;
  return centre / static_cast<double>(trips.size());
}

// The point of a calibrated region on the board (fixture x in 0..L1, y in
// 0..L2) where a scale error eats the margin first.
std::optional<FarCorner> FindFarCorner(const cell::Cell& cell, const cell::Fixture& fixture) {
  const FixtureErrorModel model(cell, fixture);
  if (!model.defined()) return std::nullopt;
  const Eigen::Affine3d nominal = NominalFix(fixture);
  std::optional<FarCorner> worst;
  double worst_room = std::numeric_limits<double>::infinity();
  constexpr int kSamples = 5;  // per side of a region's bounds
  // The regions that calibrate the scan's trips are the markers' own: no
  // part is placed there.
  const std::vector<int> trip_regions = TripRegions(fixture, cell.regions);
  for (std::size_t r = 0; r < cell.regions.size(); ++r) {
    const cell::Region& region = cell.regions[r];
    if (std::find(trip_regions.begin(), trip_regions.end(), static_cast<int>(r)) != trip_regions.end()) continue;
    for (int i = 0; i < kSamples; ++i) {
      for (int j = 0; j < kSamples; ++j) {
        const Eigen::Vector2d base(region.x_mm.lo + (region.x_mm.hi - region.x_mm.lo) * i / (kSamples - 1),
                                   region.y_mm.lo + (region.y_mm.hi - region.y_mm.lo) * j / (kSamples - 1));
        const Eigen::Vector2d f = ToFixtureFrame(nominal, base);
        if (f.x() < 0 || f.x() > fixture.l1_mm || f.y() < 0 || f.y() > fixture.l2_mm) continue;
        FarCorner corner;
        corner.in_fixture = f;
        corner.in_base = base;
        corner.region = region.name;
        corner.tolerance_mm = region.tolerance_mm;
        const ErrorBudget budget = model.At(f, &region, 0);
        if (!budget.bounded) continue;
        corner.budget_mm = budget.BudgetMm();
        corner.um_per_ppm = UmPerPpm(fixture, f);
        // How many ppm it takes to use up the margin: the smallest wins.
        const double room = corner.um_per_ppm > 0 ? corner.MarginMm() * kUmPerMm / corner.um_per_ppm
                                                  : std::numeric_limits<double>::infinity();
        if (!worst || room < worst_room ||
            (room == worst_room && corner.um_per_ppm > worst->um_per_ppm)) {
          worst = corner;
          worst_room = room;
        }
      }
    }
  }
  return worst;
}

// Scans until |now + per_scan t| reaches `limit` (all >= 0 but per_scan):
// 0 when it is there, none when it does not approach.
std::optional<double> ScansTo(double now, double per_scan, double limit) {
  if (now >= limit) return 0.0;
  if (per_scan <= 0) return std::nullopt;
  return (limit - now) / per_scan;
}

// The same for a point moving with velocity v from p towards a circle of radius r.
std::optional<double> ScansToCircle(const Eigen::Vector2d& p, const Eigen::Vector2d& v, double r) {
  if (p.norm() >= r) return 0.0;
  const double a = v.squaredNorm(), b = 2 * p.dot(v), c = p.squaredNorm() - r * r;
  if (a == 0) return std::nullopt;
  return (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
}


// The monitor's checks of records against the cell: positions the robot
// cannot reach are no scan's (docs/monitor.md, "Values").
struct Travel {
  double x_lo, x_hi, y_lo, y_hi;
  bool Holds(const Eigen::Vector2d& p) const { return p.x() >= x_lo && p.x() <= x_hi && p.y() >= y_lo && p.y() <= y_hi; }
  std::string Text() const {
    return fmt::format("x {}..{}, y {}..{} mm", NumberText(x_lo), NumberText(x_hi), NumberText(y_lo), NumberText(y_hi));
  }
};

// The robot's travel widened by the fixture's size: its markers are within
// reach, and S1..S3 are corners of the board's frame near them.
Travel TravelOf(const cell::Cell& cell, const cell::Fixture& fixture) {
  const double widen = std::max(fixture.l1_mm, fixture.l2_mm);
  const cell::Interval& x = cell.robot.limits[0];
  const cell::Interval& y = cell.robot.limits[1];
  return {x.lo - widen, x.hi + widen, y.lo - widen, y.hi + widen};
}

bool RecordInTravel(const MonitoredCycle& cycle, const Travel& travel, std::string_view cell_name, Diagnostics& diags) {
  auto outside = [&](std::string what, const Eigen::Vector2d& p) {
    diags.Report(DiagKind::RecordAbsurdValue, cycle.where, what, cycle.record.cycle, cycle.fixture,
                 fmt::format("({}, {}) mm", NumberText(p.x()), NumberText(p.y())),
                 fmt::format("outside cell '{}''s robot travel widened by the fixture's size ({}): the robot cannot "
                             "have been there, so the record is not a scan's",
                             cell_name, travel.Text()));
    return false;
  };
  for (std::size_t k = 0; k < cycle.record.trips.size(); ++k) {
    if (cycle.record.trips[k] && !travel.Holds(*cycle.record.trips[k])) {
      return outside(fmt::format("trip T{}", k + 1), *cycle.record.trips[k]);
    }
  }
  if (cycle.record.estimate) {
    for (std::size_t k = 0; k < 3; ++k) {
      if (!travel.Holds((*cycle.record.estimate)[k])) return outside(fmt::format("S{}", k + 1), (*cycle.record.estimate)[k]);
    }
  }
  return true;
}

std::string Where(const Diagnostics& diags, const SourceRange& where) {
  if (where.begin.file == 0) return "-";
  return fmt::format("{}:{}", diags.sources().File(where.begin.file).name, where.begin.line);
}

std::string ScanList(const std::vector<long>& scans) {
  std::string text;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (i == 8) {
      text += fmt::format(" and {} more", scans.size() - i);
      break;
    }
    text += (i == 0 ? "" : ", ") + std::to_string(scans[i]);
  }
  return text;
}

class FixtureAnalysis {
 public:
  FixtureAnalysis(const cell::Cell& cell, const cell::Fixture& fixture, const MonitorOptions& options,
                  const std::vector<MonitoredCycle>& cycles, Diagnostics& diags)
      : cell_(cell),
        fixture_(fixture),
        options_(options),
        cycles_(cycles),
        diags_(diags),
        diagnostics_(fixture),
        nominal_(NominalFix(fixture)) {}

  FixtureMonitor Run(const std::vector<std::size_t>& indices, const FixtureBaseline* stored) {
    FixtureMonitor out;
    out.name = fixture_.name;
    out.fixture = &fixture_;
    out.records = indices;
    out.scans = static_cast<long>(indices.size());
    out.threshold_identifiable = diagnostics_.threshold();
    out.origin_mm = fixture_.origin_mm;
    for (std::size_t q = 0; q < kQuantities; ++q) {
      out.series[q].quantity = static_cast<Quantity>(q);
      out.series[q].gates = kInfo[q].gates;
    }
    Teach(out);
    std::vector<double> gaps;
    std::optional<Eigen::Affine3d> previous;
    for (std::size_t i = 0; i < indices.size(); ++i) {
      const MonitoredCycle& cycle = cycles_[indices[i]];
      const CycleRecord& record = cycle.record;
      const double scan = static_cast<double>(i + 1);
      const bool restart = cycle.restart || record.cycle == 1;
      if (restart && i > 0) out.restarts.push_back(static_cast<long>(i + 1));
      if (i > 0 && !restart && cycle.run == cycles_[indices[i - 1]].run && record.time_s &&
          cycles_[indices[i - 1]].record.time_s && *record.time_s > *cycles_[indices[i - 1]].record.time_s) {
        gaps.push_back(*record.time_s - *cycles_[indices[i - 1]].record.time_s);
      }
      if (restart) previous.reset();  // a new run: the runtime has no previous pose
      const std::optional<Eigen::Affine3d> fix = Recompute(record, previous, static_cast<long>(i + 1), out);
      if (!record.accepted() || !record.estimate) continue;
      previous = fix;
      ++out.accepted;
      Measure(record, *fix, scan, out);
    }
    if (!gaps.empty()) out.seconds_per_scan = Median(gaps);
    out.far_corner = FindFarCorner(cell_, fixture_);
    out.trip_centre = TripCentre(fixture_);
    for (std::size_t q = 0; q < kQuantities; ++q) {
      SeriesResult& series = out.series[q];
      if (series.values.empty()) continue;
      const auto [limit_kind, limit] = LimitOf(static_cast<Quantity>(q));
      out.process[q] = FiguresOf(series.values, options_.confidence, limit_kind, limit);
    }
    const bool based = stored ? Stored(*stored, out) : Baseline(out);
    if (!based) return out;
    out.charted = true;
    Refusals(out);
    Chart(out);
    Findings(out);
    return out;
  }

 private:
  // --- the baseline ------------------------------------------------------------

  std::string RecordAt(const FixtureMonitor& out, long scan) const {
    return Where(diags_, cycles_[out.records[static_cast<std::size_t>(scan - 1)]].where);
  }
  SourceRange RangeAt(const FixtureMonitor& out, long scan) const {
    return cycles_[out.records[static_cast<std::size_t>(scan - 1)]].where;
  }

  // Phase I: the window of the first options_.baseline accepted scans from
  // options_.baseline_from, each chart's reference estimated robustly.
  bool Baseline(FixtureMonitor& out) {
    FixtureBaseline& b = out.baseline;
    b.fixture = fixture_.name;
    std::vector<long> window;  // accepted scans in it
    for (std::size_t i = 0; i < out.records.size(); ++i) {
      const CycleRecord& record = cycles_[out.records[i]].record;
      const long scan = static_cast<long>(i + 1);
      if (scan < options_.baseline_from || !record.accepted() || !record.estimate) continue;
      if (window.size() == options_.baseline) break;
      window.push_back(scan);
    }
    const SourceRange first_where =
        out.records.empty() ? SourceRange() : RangeAt(out, std::min<long>(options_.baseline_from, out.scans));
    if (window.size() < options_.baseline) {
      diags_.Report(DiagKind::MonitorTooFewScans, first_where,
                    fmt::format("fixture '{}' has {} accepted scans from scan {} of the logs on: its baseline needs {} "
                                "(--baseline; at least {}: with fewer, a chart guarded against its estimates' "
                                "uncertainty no longer sees a step of 1.7 sigma); give longer logs, a smaller "
                                "--baseline, or a stored baseline (--baseline-in)",
                                fixture_.name, window.size(), options_.baseline_from, options_.baseline, kMinBaseline));
      return false;
    }
    b.first_scan = window.front();
    b.last_scan = window.back();
    b.first_record = RecordAt(out, b.first_scan);
    b.last_record = RecordAt(out, b.last_scan);
    for (long scan = b.first_scan; scan <= b.last_scan; ++scan) {
      const CycleRecord& record = cycles_[out.records[static_cast<std::size_t>(scan - 1)]].record;
      ++b.scans;
      if (const std::optional<ScanCheck> failed = record.failed()) {
        ++b.refused[static_cast<std::size_t>(*failed) - 1];
        ++b.refused_any;
      }
    }
    // Each chart's reference; the scans of the window to exclude when one drifts.
    bool ok = true;
    struct DriftSaid {
      Quantity quantity;
      long first, last;
      bool at_start;
      double slope, t;
    };
    std::vector<DriftSaid> drifts;
    std::vector<std::pair<Quantity, std::vector<long>>> outliers;
    for (std::size_t q = 0; q < kQuantities; ++q) {
      SeriesResult& series = out.series[q];
      std::vector<double> values;
      std::vector<long> scans;
      for (std::size_t i = 0; i < series.values.size(); ++i) {
        const auto scan = static_cast<long>(series.scan[i]);
        if (scan < b.first_scan || scan > b.last_scan) continue;
        values.push_back(series.values[i]);
        scans.push_back(scan);
      }
      if (values.size() < kMinBaseline) continue;  // a chart the layout or the records do not give
      const BaselineEstimate estimate = EstimateBaseline(values, kInfo[q].resolution);
      for (std::size_t i : estimate.outliers) series.outliers.push_back(scans[i]);
      if (!series.outliers.empty()) outliers.push_back({static_cast<Quantity>(q), series.outliers});
      if (estimate.drift && kInfo[q].gates) {
        drifts.push_back({static_cast<Quantity>(q), scans[estimate.drift->first], scans[estimate.drift->last],
                          estimate.drift->at_start, estimate.drift->slope, estimate.drift->t});
        continue;
      }
      if (estimate.reference.n < static_cast<long>(kMinBaseline)) {
        diags_.Report(DiagKind::MonitorTooFewScans, RangeAt(out, b.first_scan),
                      fmt::format("fixture '{}''s chart of the {} keeps {} of its baseline's {} values once its "
                                  "outliers are left out: it needs at least {}; give a longer baseline (--baseline)",
                                  fixture_.name, QuantityTitle(static_cast<Quantity>(q)), estimate.reference.n,
                                  values.size(), kMinBaseline));
        ok = false;
        continue;
      }
      b.charts[q] = estimate.reference;
    }
    if (!outliers.empty()) {
      std::string text;
      for (const auto& [q, scans] : outliers) {
        text += fmt::format("{}{} at scan{} {}", text.empty() ? "" : "; ", QuantityTitle(q), scans.size() == 1 ? "" : "s",
                            ScanList(scans));
      }
      diags_.Report(DiagKind::MonitorBaselineOutliers, RangeAt(out, outliers.front().second.front()),
                    fmt::format("fixture '{}''s baseline (scans {} to {}) holds values far from their neighbours (more "
                                "than {} robust sigmas), left out of its charts' centre lines and sigmas: {}; if the "
                                "cell was not as usual there, take the baseline elsewhere (--baseline-from)",
                                fixture_.name, b.first_scan, b.last_scan, NumberText(kBaselineOutlierSigmas), text));
    }
    if (!drifts.empty()) {
      // The scans to exclude: from the earliest start of a drift inside the
      // window to its end, or from its start to the latest end of a warm-up.
      long from = b.last_scan + 1, until = b.first_scan - 1;
      std::string text;
      for (const DriftSaid& d : drifts) {
        if (d.at_start) {
          until = std::max(until, d.last);
        } else {
          from = std::min(from, d.first);
        }
        text += fmt::format("{}{} {} {} {} per scan ({} standard errors) {}", text.empty() ? "" : "; ",
                            QuantityTitle(d.quantity), d.slope >= 0 ? "rises" : "falls",
                            NumberText(RoundedToDecimals(std::abs(d.slope), 3)), QuantityUnit(d.quantity),
                            NumberText(RoundedToDecimals(std::abs(d.t), 1)),
                            d.at_start ? fmt::format("until scan {}", d.last) : fmt::format("from scan {}", d.first));
      }
      std::string exclude, remedy;
      if (until >= b.first_scan) {
        exclude = fmt::format("scans {} to {}", b.first_scan, until);
        remedy = fmt::format("start the baseline after them (--baseline-from {})", until + 1);
      }
      if (from <= b.last_scan) {
        exclude += fmt::format("{}scans {} to {}", exclude.empty() ? "" : " and ", from, b.last_scan);
        const long steady = from - std::max(b.first_scan, until + 1);
        remedy += fmt::format("{}{}", remedy.empty() ? "" : ", or ",
                              steady >= static_cast<long>(kMinBaseline)
                                  ? fmt::format("end it before them (--baseline {})", steady)
                                  : std::string("take it where the cell was steady (--baseline-from), or use a stored "
                                                "baseline (--baseline-in)"));
      }
      diags_.Report(DiagKind::MonitorBaselineDrifts, RangeAt(out, from <= b.last_scan ? from : b.first_scan),
                    fmt::format("fixture '{}''s baseline (scans {} to {}) drifts, so it is no reference: {}; exclude {}: "
                                "{}",
                                fixture_.name, b.first_scan, b.last_scan, text, exclude, remedy));
      ok = false;
    }
    return ok;
  }

  // Phase II against a stored baseline.
  bool Stored(const FixtureBaseline& stored, FixtureMonitor& out) {
    out.baseline = stored;
    out.baseline_stored = true;
    return true;
  }

  // --- the scans -----------------------------------------------------------------

  // The record's verdict and pose against the cell's, from its own trips.
  std::optional<Eigen::Affine3d> Recompute(const CycleRecord& record, const std::optional<Eigen::Affine3d>& previous,
                                           long scan, FixtureMonitor& out) {
    std::optional<Eigen::Affine3d> fix;
    if (record.estimate) fix = FixOfEstimate(*record.estimate, fixture_.l1_mm, fixture_.l2_mm);
    if (record.trips.size() != ExpectedTrips(fixture_).size()) return fix;
    ScanOptions scan_options;
    scan_options.estimator = fixture_.estimator;
    scan_options.regions = &cell_.regions;
    scan_options.previous = previous;
    const ScanResult result = ScanFixture(fixture_, record.trips, scan_options);
    double difference = 0;
    if (result.estimate.has_value() != record.estimate.has_value()) {
      difference = std::numeric_limits<double>::infinity();
    } else if (record.estimate) {
      for (std::size_t k = 0; k < 3; ++k) {
        difference = std::max(difference, (result.estimate->s[k] - (*record.estimate)[k]).norm());
      }
    }
    const CheckResult* failure = result.FirstFailure();
    const int status = failure != nullptr ? static_cast<int>(failure->check) : 0;
    // A cycle check needs the previous pose: a log that starts in the middle
    // of a run does not have it, so those verdicts are not compared.
    const bool cycle_check = record.status >= static_cast<int>(ScanCheck::kCycleShift) ||
                             status >= static_cast<int>(ScanCheck::kCycleShift);
    const bool comparable = previous.has_value() || record.cycle == 1 || !cycle_check;
    bool verdict_differs = comparable && status != record.status;
    if (verdict_differs && failure != nullptr && record.status != 0) {
      // A value within rounding of its limit may tip either way.
      const auto& value = record.checks[static_cast<std::size_t>(record.status) - 1];
      const CheckResult& check = result.Check(static_cast<ScanCheck>(record.status));
      verdict_differs = !(value && std::abs(*value - check.limit) < 10 * kRecordAgreementMm);
    }
    if (difference > kRecordAgreementMm || verdict_differs) {
      if (out.disagreements == 0) out.first_disagreement_scan = scan;
      ++out.disagreements;
      if (std::isfinite(difference)) out.worst_disagreement_mm = std::max(out.worst_disagreement_mm, difference);
    }
    return fix;
  }

  void Add(FixtureMonitor& out, Quantity q, double scan, double value) {
    SeriesResult& series = out.series[static_cast<std::size_t>(q)];
    series.scan.push_back(scan);
    series.values.push_back(value);
  }

  void Measure(const CycleRecord& record, const Eigen::Affine3d& fix, double scan, FixtureMonitor& out) {
    const Eigen::Vector2d shift = (FixOrigin(fix) - fixture_.origin_mm) * kUmPerMm;
    Add(out, Quantity::kPoseX, scan, shift.x());
    Add(out, Quantity::kPoseY, scan, shift.y());
    Add(out, Quantity::kPoseAngle, scan, RelativeAngleRad(nominal_, fix) * kDegPerRad * 1000);
    if (const auto& worst = record.checks[static_cast<std::size_t>(ScanCheck::kLineResidual) - 1]) {
      Add(out, Quantity::kResidualMax, scan, *worst * kUmPerMm);
    }
    std::vector<Eigen::Vector2d> calibrated;
    for (const auto& trip : record.trips) {
      if (!trip) return;
      calibrated.push_back(DirectCalibrateInCell(cell_.regions, *trip));
    }
    if (const std::optional<ScanDiagnostics::Fit> fit = diagnostics_.Of(calibrated)) {
      Add(out, Quantity::kMarkerScale, scan, fit->scale_ppm);
      if (fit->threshold_um) Add(out, Quantity::kSensorThreshold, scan, *fit->threshold_um);
      Add(out, Quantity::kResidualRms, scan, fit->rms_um);
    }
  }

  void Teach(FixtureMonitor& out) {
    if (fixture_.teach_trips_mm.empty() || fixture_.teach_trips_mm.size() != ExpectedTrips(fixture_).size()) return;
    std::vector<Eigen::Vector2d> calibrated;
    for (const Eigen::Vector2d& trip : fixture_.teach_trips_mm) calibrated.push_back(DirectCalibrateInCell(cell_.regions, trip));
    if (const std::optional<ScanDiagnostics::Fit> fit = diagnostics_.Of(calibrated)) {
      out.teach_scale_ppm = fit->scale_ppm;
      out.teach_threshold_um = fit->threshold_um;
    }
  }

  // --- the charts -----------------------------------------------------------------

  // Every refusal together, then each check that refused a scan: a Bernoulli
  // CUSUM designed from the baseline's rate, at least kRefusalRateFloor.
  void Refusals(FixtureMonitor& out) {
    const FixtureBaseline& b = out.baseline;
    std::vector<std::optional<ScanCheck>> charts = {std::nullopt};
    for (ScanCheck check : kScanChecks) charts.push_back(check);
    for (const std::optional<ScanCheck>& check : charts) {
      RefusalResult refusal;
      refusal.check = check;
      std::vector<bool> events;
      events.reserve(out.records.size());
      for (std::size_t i = 0; i < out.records.size(); ++i) {
        const std::optional<ScanCheck> failed = cycles_[out.records[i]].record.failed();
        const bool refused = check ? failed == check : failed.has_value();
        events.push_back(refused);
        if (refused) {
          ++refusal.count;
          refusal.at_scans.push_back(static_cast<long>(i + 1));
        }
      }
      if (check && refusal.count == 0) continue;
      refusal.baseline_count = check ? b.refused[static_cast<std::size_t>(*check) - 1] : b.refused_any;
      refusal.baseline_scans = b.scans;
      const double rate = b.scans > 0 ? static_cast<double>(refusal.baseline_count) / static_cast<double>(b.scans) : 0;
      refusal.design = Design(std::max(rate, kRefusalRateFloor));
      refusal.run = RunBernoulliCusum(events, refusal.design);
      if (refusal.run.alarm) {
        refusal.alarm_scan = static_cast<long>(*refusal.run.alarm + 1);
        refusal.change_scan = static_cast<long>(refusal.run.change_point + 1);
      }
      out.refusals.push_back(std::move(refusal));
    }
  }

  // The design for a rate, once per rate.
  const BernoulliCusumDesign& Design(double p0) {
    for (const BernoulliCusumDesign& d : designs_) {
      if (d.p0 == p0) return d;
    }
    designs_.push_back(DesignBernoulliCusum(p0));
    return designs_.back();
  }

  ChartOptions OptionsOf(std::size_t q) const {
    ChartOptions chart;
    chart.cusum_k = options_.cusum_k;
    chart.cusum_h = options_.cusum_h;
    chart.cusum_clip = options_.cusum_clip;
    chart.ewma_lambda = options_.ewma_lambda;
    chart.ewma_l = options_.ewma_l;
    chart.direction = kInfo[q].direction;
    chart.resolution = kInfo[q].resolution;
    return chart;
  }

  void Chart(FixtureMonitor& out) {
    for (std::size_t q = 0; q < kQuantities; ++q) {
      SeriesResult& series = out.series[q];
      const auto kind = static_cast<Quantity>(q);
      const std::optional<ChartReference>& reference = out.baseline.charts[q];
      if (!reference || series.values.empty()) continue;
      series.charted = true;
      series.chart = RunChart(series.values, *reference, OptionsOf(q));
      const bool location = kind != Quantity::kResidualRms && kind != Quantity::kResidualMax;
      // An alarm that is no shift of the mean (the values only spread more)
      // does not end the chart: it starts again after it, so a shift later
      // in a long log is still found. The first alarm is kept when no shift
      // follows.
      ChartResult first = series.chart;
      while (series.chart.alarm && location) {
        series.trend = TrendFrom(series, series.scan[series.chart.change_point]);
        series.shift_confirmed = ShiftConfirmed(series);
        if (series.shift_confirmed || *series.chart.alarm + 1 >= series.values.size()) break;
        ChartResult next = RunChart(series.values, *reference, OptionsOf(q), *series.chart.alarm + 1);
        if (!next.alarm) break;
        series.chart = std::move(next);
      }
      if (location && !series.shift_confirmed) {
        series.chart = std::move(first);
        series.trend = TrendFrom(series, series.scan[series.chart.change_point]);
      }
      if (series.chart.alarm && !location) series.trend = TrendFrom(series, series.scan[series.chart.change_point]);
    }
  }

  // The mean since the change point against the centre line, in standard
  // errors of that mean (its values' own spread).
  static bool ShiftConfirmed(const SeriesResult& series) {
    const std::vector<double> after(series.values.begin() + static_cast<std::ptrdiff_t>(series.chart.change_point),
                                    series.values.end());
    if (after.size() < 2) return true;
    const MeanSigma sample = MeanAndSigma(after);
    const double se = sample.sigma / std::sqrt(static_cast<double>(after.size()));
    return se == 0 || std::abs(sample.mean - series.chart.center) > kShiftConfirmed * se;
  }

  std::optional<Trend> TrendFrom(const SeriesResult& series, double from_scan) const {
    std::vector<double> x, y;
    for (std::size_t i = 0; i < series.values.size(); ++i) {
      if (series.scan[i] < from_scan) continue;
      x.push_back(series.scan[i]);
      y.push_back(series.values[i]);
    }
    if (x.size() < 3) return std::nullopt;
    return FitTrend(x, y);
  }

  // The limit each quantity's process figures are judged against.
  std::pair<LimitKind, double> LimitOf(Quantity q) const {
    switch (q) {
      case Quantity::kPoseX:
      case Quantity::kPoseY: return {LimitKind::kTwoSided, fixture_.max_shift_mm * kUmPerMm};
      case Quantity::kPoseAngle: return {LimitKind::kTwoSided, fixture_.max_rotation_deg * 1000};
      case Quantity::kMarkerScale:
        return {LimitKind::kTwoSided, fixture_.length_tolerance_mm / std::max(fixture_.l1_mm, fixture_.l2_mm) * kPpm};
      case Quantity::kResidualMax: return {LimitKind::kUpper, fixture_.max_line_residual_mm * kUmPerMm};
      case Quantity::kSensorThreshold:
      case Quantity::kResidualRms: return {LimitKind::kNone, 0};
    }
    return {LimitKind::kNone, 0};
  }

  const SeriesResult& Series(const FixtureMonitor& out, Quantity q) const {
    return out.series[static_cast<std::size_t>(q)];
  }

  // The first alarm among some charts: the finding's skeleton, or nullopt.
  std::optional<Finding> Alarmed(const FixtureMonitor& out, FindingKind kind, const std::vector<Quantity>& charts) {
    Finding finding;
    finding.kind = kind;
    bool any = false;
    for (Quantity q : charts) {
      const SeriesResult& series = Series(out, q);
      if (!series.gates || !series.chart.alarm || !series.shift_confirmed) continue;
      const auto alarm = static_cast<long>(series.scan[*series.chart.alarm]);
      const auto change = static_cast<long>(series.scan[series.chart.change_point]);
      finding.alarm_scan = any ? std::min(finding.alarm_scan, alarm) : alarm;
      finding.change_scan = any ? std::min(finding.change_scan, change) : change;
      finding.charts.push_back(q);
      any = true;
    }
    if (!any) return std::nullopt;
    return finding;
  }

  // How far the board's measured origin moves (µm, base frame) per ppm the
  // marker distance changes, when the robot's scale changes about its origin
  // and the tables do not know it: the nominal trips where such a robot
  // trips, through the fixture's estimator (for rigid, about the trips'
  // centre; for paper and rigid-scale, about S1 itself).
  std::optional<Eigen::Vector2d> OriginUmPerScalePpm() const {
    constexpr double s = 1e-4;  // 100 ppm: linear, far above rounding
    const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture_, nominal_);
    std::vector<Eigen::Vector2d> seen;
    for (const Eigen::Vector2d& t : trips) seen.push_back(t / (1 + s));
    const std::optional<FixEstimate> before = EstimateFix(fixture_, ExpectedTrips(fixture_), trips, fixture_.estimator);
    const std::optional<FixEstimate> after = EstimateFix(fixture_, ExpectedTrips(fixture_), seen, fixture_.estimator);
    const std::optional<ScanDiagnostics::Fit> m0 = diagnostics_.Of(trips), m1 = diagnostics_.Of(seen);
    if (!before || !after || !m0 || !m1 || std::abs(m1->scale_ppm - m0->scale_ppm) < 1) return std::nullopt;
    return (FixOrigin(after->fix) - FixOrigin(before->fix)) * kUmPerMm / (m1->scale_ppm - m0->scale_ppm);
  }

  // A pose chart's drift that the marker distance's explains: a robot whose
  // scale changes about its origin moves the board's measured origin too
  // (OriginUmPerScalePpm). Each scan's pose is
  // corrected by its own marker distance's change from the centre line and
  // charted again, against the pose's reference with the sigma the
  // correction adds (the marker distance's, times the lever).
  ExplainedDrift Explain(const FixtureMonitor& out, Quantity q, const SeriesResult& scale) const {
    const SeriesResult& pose = Series(out, q);
    ExplainedDrift explained;
    explained.quantity = q;
    const double um_per_ppm = q == Quantity::kPoseX ? out.origin_um_per_ppm->x() : out.origin_um_per_ppm->y();
    std::vector<double> corrected;
    std::size_t k = 0;
    for (std::size_t i = 0; i < pose.values.size(); ++i) {
      while (k < scale.scan.size() && scale.scan[k] < pose.scan[i]) ++k;
      if (k == scale.scan.size() || scale.scan[k] != pose.scan[i]) continue;  // a scan without a marker distance
      corrected.push_back(pose.values[i] - (scale.values[k] - scale.chart.center) * um_per_ppm);
    }
    ChartReference reference = *out.baseline.charts[static_cast<std::size_t>(q)];
    const double added = scale.chart.sigma_estimate * std::abs(um_per_ppm);
    const double sigma = std::hypot(reference.sigma_estimate, added);
    reference.mr_mean *= sigma / reference.sigma_estimate;
    reference.sigma_estimate = sigma;
    const ChartResult again = RunChart(corrected, reference, pose.chart.options);
    explained.alarms_without = again.alarm.has_value();
    explained.observed_per_100 = pose.trend ? pose.trend->slope * 100 : 0;
    explained.explained_per_100 = scale.trend ? scale.trend->slope * um_per_ppm * 100 : 0;
    return explained;
  }

  void Findings(FixtureMonitor& out) {
    // The robot's scale first: it moves the pose too.
    std::vector<Quantity> pose_charts = {Quantity::kPoseX, Quantity::kPoseY, Quantity::kPoseAngle};
    if (std::optional<Finding> f = Alarmed(out, FindingKind::kRobotScale, {Quantity::kMarkerScale})) {
      const SeriesResult& scale = Series(out, Quantity::kMarkerScale);
      if (const std::optional<Trend>& s = scale.trend) {
        const double scale_ppm = s->at_end;
        const double toward = scale_ppm >= 0 ? s->slope : -s->slope;
        if (out.far_corner && out.far_corner->um_per_ppm > 0) {
          const FarCorner& corner = *out.far_corner;
          f->now = std::abs(scale_ppm) * corner.um_per_ppm;
          f->per_scan = toward * corner.um_per_ppm;
          f->limit = corner.MarginMm() * kUmPerMm;
          f->scans_to_limit = ScansTo(f->now, f->per_scan, f->limit);
        }
        f->stale = Stale(scale_ppm);
        out.origin_um_per_ppm = OriginUmPerScalePpm();
        for (Quantity q : {Quantity::kPoseX, Quantity::kPoseY}) {
          const SeriesResult& pose = Series(out, q);
          if (!out.origin_um_per_ppm) break;
          if (!pose.gates || !pose.chart.alarm || !pose.shift_confirmed) continue;
          const ExplainedDrift e = Explain(out, q, scale);
          f->explains.push_back(e);
          if (!e.alarms_without) std::erase(pose_charts, q);
        }
      }
      out.findings.push_back(*f);
    }
    if (std::optional<Finding> f =
            Alarmed(out, FindingKind::kSensor, {Quantity::kSensorThreshold, Quantity::kResidualRms})) {
      f->limit = fixture_.max_line_residual_mm * kUmPerMm;
      if (const std::optional<Trend> r =
              TrendFrom(Series(out, Quantity::kResidualMax), static_cast<double>(f->change_scan))) {
        f->now = r->at_end;
        f->per_scan = r->slope;
        f->scans_to_limit = ScansTo(f->now, f->per_scan, f->limit);
      }
      out.findings.push_back(*f);
    }
    if (std::optional<Finding> f = Alarmed(out, FindingKind::kFixtureMoving, pose_charts)) {
      const std::optional<Trend> x = TrendFrom(Series(out, Quantity::kPoseX), static_cast<double>(f->change_scan));
      const std::optional<Trend> y = TrendFrom(Series(out, Quantity::kPoseY), static_cast<double>(f->change_scan));
      const std::optional<Trend> a =
          TrendFrom(Series(out, Quantity::kPoseAngle), static_cast<double>(f->change_scan));
      f->limit = fixture_.max_shift_mm * kUmPerMm;
      if (x && y) {
        const Eigen::Vector2d p(x->at_end, y->at_end), v(x->slope, y->slope);
        f->now = p.norm();
        f->per_scan = p.norm() > 0 ? p.dot(v) / p.norm() : v.norm();
        f->scans_to_limit = ScansToCircle(p, v, f->limit);
      }
      if (a) {
        const double limit = fixture_.max_rotation_deg * 1000;
        const double toward = a->at_end >= 0 ? a->slope : -a->slope;
        const std::optional<double> turn = ScansTo(std::abs(a->at_end), toward, limit);
        if (turn && (!f->scans_to_limit || *turn < *f->scans_to_limit)) f->scans_to_limit = turn;
      }
      out.findings.push_back(*f);
    }
    // Refusals: each check whose chart alarmed; the chart of every refusal
    // together only when no check's did (the rise is spread over checks).
    bool check_alarmed = false;
    for (const RefusalResult& refusal : out.refusals) check_alarmed = check_alarmed || (refusal.check && refusal.alarm_scan);
    for (const RefusalResult& refusal : out.refusals) {
      if (!refusal.alarm_scan || (!refusal.check && check_alarmed)) continue;
      Finding f;
      f.kind = FindingKind::kRefusals;
      f.check = refusal.check;
      f.alarm_scan = *refusal.alarm_scan;
      f.change_scan = refusal.change_scan;
      out.findings.push_back(f);
    }
    out.in_control = out.findings.empty();
  }

  // The regions a scale error of `scale_ppm` moves beyond their tables'
  // stated noise, relative to the markers the scan registers the board by.
  std::vector<StaleRegion> Stale(double scale_ppm) const {
    std::vector<StaleRegion> stale;
    const Eigen::Vector2d centre = TripCentre(fixture_);
    for (const cell::Region& region : cell_.regions) {
      double far = 0;
      for (double x : {region.x_mm.lo, region.x_mm.hi}) {
        for (double y : {region.y_mm.lo, region.y_mm.hi}) far = std::max(far, (Eigen::Vector2d(x, y) - centre).norm());
      }
      StaleRegion r;
      r.region = region.name;
      r.drift_um = std::abs(scale_ppm) / kPpm * far * kUmPerMm;
      r.noise_um = kBudgetSigmas * TableStandardErrorMm(region.table, cell_.robot.repeatability_mm).maxCoeff() * kUmPerMm;
      if (r.drift_um > r.noise_um) stale.push_back(r);
    }
    return stale;
  }

  const cell::Cell& cell_;
  const cell::Fixture& fixture_;
  const MonitorOptions& options_;
  const std::vector<MonitoredCycle>& cycles_;
  Diagnostics& diags_;
  ScanDiagnostics diagnostics_;
  Eigen::Affine3d nominal_;
  std::vector<BernoulliCusumDesign> designs_;
};

}  // namespace

std::string_view QuantityName(Quantity quantity) { return Info(quantity).name; }
std::string_view QuantityTitle(Quantity quantity) { return Info(quantity).title; }
std::string_view QuantityUnit(Quantity quantity) { return Info(quantity).unit; }
bool QuantityGates(Quantity quantity) { return Info(quantity).gates; }
std::optional<Quantity> QuantityNamed(std::string_view name) {
  for (std::size_t q = 0; q < kQuantities; ++q) {
    if (kInfo[q].name == name) return static_cast<Quantity>(q);
  }
  return std::nullopt;
}

MonitorResult Monitor(const cell::Cell& cell, const std::vector<MonitoredCycle>& cycles, const MonitorOptions& options,
                      const MonitorBaseline* stored, Diagnostics& diags) {
  MonitorResult result;
  const std::size_t errors_before = diags.error_count();
  std::vector<std::vector<std::size_t>> by_fixture(cell.fixtures.size());
  for (std::size_t i = 0; i < cycles.size(); ++i) {
    for (std::size_t f = 0; f < cell.fixtures.size(); ++f) {
      if (AsciiLowercase(cycles[i].fixture) == AsciiLowercase(RecordName(cell.fixtures[f].name))) {
        by_fixture[f].push_back(i);
      }
    }
  }
  // Positions the robot cannot reach: no scan's (a cell that declares its
  // travel; each record said).
  const bool travel_declared = cell.robot.limits[0].hi > cell.robot.limits[0].lo &&
                               cell.robot.limits[1].hi > cell.robot.limits[1].lo;
  for (std::size_t f = 0; f < cell.fixtures.size() && travel_declared; ++f) {
    const Travel travel = TravelOf(cell, cell.fixtures[f]);
    for (std::size_t i : by_fixture[f]) RecordInTravel(cycles[i], travel, cell.name, diags);
  }
  if (diags.error_count() > errors_before) return result;
  for (std::size_t f = 0; f < cell.fixtures.size(); ++f) {
    if (by_fixture[f].empty()) continue;
    const FixtureBaseline* fixture_baseline = nullptr;
    if (stored) {
      for (const FixtureBaseline& b : stored->fixtures) {
        if (AsciiLowercase(b.fixture) == AsciiLowercase(cell.fixtures[f].name)) fixture_baseline = &b;
      }
      if (fixture_baseline == nullptr) {
        diags.Report(DiagKind::MonitorBaselineOtherCell, cycles[by_fixture[f].front()].where,
                     fmt::format("the stored baseline has no fixture '{}': take a baseline of it (--baseline-out)",
                                 cell.fixtures[f].name));
        continue;
      }
    }
    FixtureAnalysis analysis(cell, cell.fixtures[f], options, cycles, diags);
    result.fixtures.push_back(analysis.Run(by_fixture[f], fixture_baseline));
    result.in_control = result.in_control && result.fixtures.back().in_control;
  }
  result.judged = diags.error_count() == errors_before;
  return result;
}

MonitorBaseline BaselineOf(const MonitorResult& result, const cell::Cell& cell, const std::vector<std::string>& logs) {
  MonitorBaseline baseline;
  baseline.cell = cell.name;
  for (const cell::CellFile& file : cell.files) baseline.files.push_back({file.path, file.sha256});
  baseline.logs = logs;
  for (const FixtureMonitor& f : result.fixtures) baseline.fixtures.push_back(f.baseline);
  return baseline;
}

}  // namespace smtcal

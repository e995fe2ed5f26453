// smtcal_data.ngc for the LinuxCNC runtime (linuxcnc_data.h): the cell's
// numbers, taken from the C runtime's structures (CRuntimeRegion,
// CRuntimeFixture) so both runtimes compute with the same data, laid out in
// numbered parameters (runtime/linuxcnc/README.md) and written one
// assignment per line with a comment naming what it is.
#include "backend/linuxcnc/linuxcnc_data.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "backend/c/c_data.h"
#include "backend/linuxcnc/embedded_files.h"
#include "backend/linuxcnc/linuxcnc_record.h"
#include "backend/linuxcnc/linuxcnc_scan_abort.h"
#include "base/check.h"
#include "calibration/fixture_geometry.h"

namespace smtcal {

namespace L = linuxcnc_layout;

void AppendLinuxCncNumber(std::string& out, double value) {
  SMTCAL_CHECK(std::isfinite(value), "a non-finite number in the LinuxCNC runtime data");
  if (value == 0) {
    out += '0';
    return;
  }
  // The fewest decimals that read back as the same double, correctly rounded
  // (printf's %.Nf). The shortest fixed form that reads back (to_chars
  // without a precision) has that many decimals, and it is the correctly
  // rounded one, except where it may pick other digits: beyond 2^53 (it
  // writes zeros for the digits it does not need) and at a power of two
  // with decimals (the doubles below lie closer than those above, so the
  // nearest decimal may not read back, where a farther one above does).
  // There the decimals are rounded as printf does and checked, one more at a
  // time.
  char text[kMaxLinuxCncNumberChars];
  char* const end = text + sizeof text;
  auto shortest = std::to_chars(text, end, value, std::chars_format::fixed);
  SMTCAL_CHECK(shortest.ec == std::errc(), "a double's shortest decimal fits the buffer");
  int exponent = 0;
  const bool power_of_two = std::abs(std::frexp(value, &exponent)) == 0.5;
  if (std::abs(value) < 0x1p53 && (!power_of_two || value == std::trunc(value))) {
    out.append(text, shortest.ptr);
    return;
  }
  const char* point = std::find(text, shortest.ptr, '.');
  int digits = point == shortest.ptr ? 0 : static_cast<int>(shortest.ptr - point - 1);
  for (; digits <= kMaxLinuxCncDecimals; ++digits) {
    auto rounded = std::to_chars(text, end, value, std::chars_format::fixed, digits);
    SMTCAL_CHECK(rounded.ec == std::errc(), "a double's fixed decimal fits the buffer");
    double back = 0;
    std::from_chars(text, rounded.ptr, back, std::chars_format::fixed);
    if (back == value) {
      out.append(text, rounded.ptr);
      return;
    }
  }
  SMTCAL_CHECK(false, "a number without an exact decimal form");
}

std::string LinuxCncNumber(double value) {
  std::string out;
  AppendLinuxCncNumber(out, value);
  return out;
}

namespace {

// Text for a `;` comment: printable ASCII only.
std::string CommentText(std::string_view text) {
  std::string out;
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte >= 0x7f ? '?' : c;
  }
  return out;
}

// The parameters in address order, each with what it holds.
class Layout {
 public:
  int next() const { return next_; }
  int Reserve(int count) {
    const int at = next_;
    next_ += count;
    return at;
  }
  void Set(int address, double value, std::string what) { values_.push_back({address, value, std::move(what)}); }
  int Append(double value, std::string what) {
    const int at = Reserve(1);
    Set(at, value, std::move(what));
    return at;
  }
  std::string Text() const {
    std::string out;
    for (const Entry& e : values_) {
      out += fmt::format("#{} = {}", e.address, LinuxCncNumber(e.value));
      out += e.what.empty() ? "\n" : fmt::format("  ; {}\n", CommentText(e.what));
    }
    return out;
  }

 private:
  struct Entry {
    int address;
    double value;
    std::string what;
  };
  int next_ = L::kDataStart;
  std::vector<Entry> values_;
};

// The sizes everything takes, to refuse a cell before laying it out.
int RegionSize(const cell::Region& region) {
  int size = L::kRgRecordSize;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = region.table[axis];
    size += 2 + static_cast<int>(t.nx() + t.ny() + t.error_mm.size());
  }
  return size;
}

int FixtureSize(const cell::Fixture& fixture) {
  const int trips = static_cast<int>(ExpectedTrips(fixture).size());
  int size = L::kFxRecordSize + 8 * trips + 1;
  for (const cell::ScanPath& path : fixture.scan_paths) size += 1 + 3 * static_cast<int>(path.points.size());
  return size;
}

int TotalSize(const cell::Cell& cell) {
  int size = L::kDataStart + static_cast<int>(cell.regions.size() + cell.fixtures.size());
  for (const cell::Region& region : cell.regions) size += RegionSize(region);
  for (const cell::Fixture& fixture : cell.fixtures) size += FixtureSize(fixture);
  return size;  // the first address after the data
}

int AppendTable(Layout& layout, const std::string& region, TableAxis axis, const smtcal_axis_table& t) {
  const std::string what = fmt::format("region {} Delta-{}", region, AxisName(axis));
  const int at = layout.Append(t.nx, what + ": nx");
  layout.Append(t.ny, what + ": ny");
  for (int i = 0; i < t.nx; ++i) layout.Append(t.xs[i], i == 0 ? what + ": x lines" : "");
  for (int j = 0; j < t.ny; ++j) layout.Append(t.ys[j], j == 0 ? what + ": y lines" : "");
  for (int j = 0; j < t.ny; ++j) {
    for (int i = 0; i < t.nx; ++i) {
      layout.Append(t.values[j * t.nx + i], i == 0 ? fmt::format("{}: values row {}", what, j) : "");
    }
  }
  return at;
}

void AppendRegion(Layout& layout, const cell::Region& region, int directory_entry) {
  const smtcal_region r = CRuntimeRegion(region);
  const int at = layout.Reserve(L::kRgRecordSize);
  layout.Set(directory_entry, at, fmt::format("region {} at", region.name));
  const std::string& n = region.name;
  layout.Set(at + L::kRgXLo, r.x_lo, n + ": bounds x lo");
  layout.Set(at + L::kRgXHi, r.x_hi, n + ": bounds x hi");
  layout.Set(at + L::kRgYLo, r.y_lo, n + ": bounds y lo");
  layout.Set(at + L::kRgYHi, r.y_hi, n + ": bounds y hi");
  layout.Set(at + L::kRgDomain + 0, r.domain_x0, n + ": table domain x0");
  layout.Set(at + L::kRgDomain + 1, r.domain_x1, n + ": table domain x1");
  layout.Set(at + L::kRgDomain + 2, r.domain_y0, n + ": table domain y0");
  layout.Set(at + L::kRgDomain + 3, r.domain_y1, n + ": table domain y1");
  layout.Set(at + L::kRgContraction, r.contraction, n + ": contraction L");
  layout.Set(at + L::kRgIterationBound, r.iteration_bound, n + ": inverse iteration bound");
  layout.Set(at + L::kRgOutside, static_cast<int>(r.outside), n + ": outside policy 0 error 1 clamp 2 none");
  layout.Set(at + L::kRgDxAt, AppendTable(layout, n, TableAxis::X, r.dx), n + ": Delta-x table at");
  layout.Set(at + L::kRgDyAt, AppendTable(layout, n, TableAxis::Y, r.dy), n + ": Delta-y table at");
}

void AppendFixture(Layout& layout, const cell::Fixture& fixture, const cell::Robot& robot, int directory_entry) {
  const smtcal_fixture f = CRuntimeFixture(fixture);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const int trips = f.trip_count;
  const int at = layout.Reserve(L::kFxRecordSize);
  const std::string& n = fixture.name;
  layout.Set(directory_entry, at, fmt::format("fixture {} at", n));
  layout.Set(at + L::kFxEstimator, static_cast<int>(f.estimator), n + ": estimator 0 paper 1 rigid 2 rigid-scale");
  layout.Set(at + L::kFxOriginX, f.origin_x, n + ": nominal origin x");
  layout.Set(at + L::kFxOriginY, f.origin_y, n + ": nominal origin y");
  layout.Set(at + L::kFxCos, f.cos_angle, n + ": nominal cos angle");
  layout.Set(at + L::kFxSin, f.sin_angle, n + ": nominal sin angle");
  layout.Set(at + L::kFxL1, f.l1, n + ": L1");
  layout.Set(at + L::kFxL2, f.l2, n + ": L2");
  for (int e = 0; e < SMTCAL_EDGE_COUNT; ++e) {
    const std::string edge = fixture.edges[static_cast<std::size_t>(e)].name;
    layout.Set(at + L::kFxEdgeNormal + 2 * e, f.edge_normal[e][0], fmt::format("{}: edge {} normal x", n, edge));
    layout.Set(at + L::kFxEdgeNormal + 2 * e + 1, f.edge_normal[e][1], fmt::format("{}: edge {} normal y", n, edge));
  }
  for (int e = 0; e < SMTCAL_EDGE_COUNT; ++e) {
    layout.Set(at + L::kFxEdgeOffset + e, f.edge_offset[e],
               fmt::format("{}: edge {} offset", n, fixture.edges[static_cast<std::size_t>(e)].name));
  }
  layout.Set(at + L::kFxTripCount, trips, n + ": trip count");
  layout.Set(at + L::kFxTripWindow, f.trip_window, n + ": trip_window_mm");
  layout.Set(at + L::kFxMaxShift, f.max_shift, n + ": max_shift_mm");
  layout.Set(at + L::kFxMaxRotation, f.max_rotation_deg, n + ": max_rotation_deg");
  layout.Set(at + L::kFxLengthTolerance, f.length_tolerance, n + ": length_tolerance_mm");
  layout.Set(at + L::kFxSquareness, f.squareness_deg, n + ": squareness_deg");
  layout.Set(at + L::kFxMaxLineResidual, f.max_line_residual, n + ": max_line_residual_mm");
  layout.Set(at + L::kFxScanZ, fixture.scan_z_mm, n + ": scan z");
  layout.Set(at + L::kFxScanFeed, fixture.scan_speed_mm_s * 60, n + ": scan feed mm/min");
  layout.Set(at + L::kFxLatchFeed, fixture.latch_speed_mm_s * 60, n + ": latch feed mm/min; 0: one stage");
  layout.Set(at + L::kFxHasFix, 0, n + ": not scanned yet");
  layout.Set(at + L::kFxStatus, 0, n + ": last scan status");
  layout.Set(at + L::kFxRecordCycles, 0, n + ": scans recorded since the start");
  layout.Set(at + L::kFxPredictedWindow, fixture.predicted_window_mm, n + ": predicted_window_mm; 0: every scan in full");
  layout.Set(at + L::kFxPredictedPaths, 0, n + ": the last scan's paths latched where predicted");
  layout.Set(at + L::kFxFallbackPaths, 0, n + ": the last scan's paths searched in full after a prediction failed");
  layout.Set(at + L::kFxTraverseFeed, robot.xy_speed_mm_s * 60, n + ": traverse feed mm/min between predicted trips");

  const int edges_at = layout.Reserve(trips);
  layout.Set(at + L::kFxTripEdgeAt, edges_at, n + ": trip edges at");
  for (int k = 0; k < trips; ++k) layout.Set(edges_at + k, f.trip_edge[k], fmt::format("{}: T{} edge", n, k + 1));
  const int nominal_at = layout.Reserve(2 * trips);
  layout.Set(at + L::kFxTripNominalAt, nominal_at, n + ": nominal trips at");
  for (int k = 0; k < trips; ++k) {
    layout.Set(nominal_at + 2 * k, f.trip_nominal[k][0], fmt::format("{}: T{} nominal x", n, k + 1));
    layout.Set(nominal_at + 2 * k + 1, f.trip_nominal[k][1], fmt::format("{}: T{} nominal y", n, k + 1));
  }
  // Filled by each scan.
  layout.Set(at + L::kFxTripsAt, layout.Reserve(2 * trips), n + ": measured trips at");
  layout.Set(at + L::kFxTrippedAt, layout.Reserve(trips), n + ": tripped flags at");
  layout.Set(at + L::kFxCalibratedAt, layout.Reserve(2 * trips), n + ": calibrated trips at");

  // The scan paths in the base frame at the nominal pose, each point with
  // the number of trips on the leg that starts there.
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const int paths_at = layout.Append(static_cast<double>(fixture.scan_paths.size()), n + ": scan path count");
  layout.Set(at + L::kFxScanPathsAt, paths_at, n + ": scan paths at");
  for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
    const cell::ScanPath& path = fixture.scan_paths[p];
    layout.Append(static_cast<double>(path.points.size()), fmt::format("{}: path {} point count", n, path.name));
    for (std::size_t i = 0; i < path.points.size(); ++i) {
      const Eigen::Vector2d base = ToBase(nominal, path.points[i]);
      int on_leg = 0;
      for (const ExpectedTrip& e : expected) on_leg += e.path == p && e.leg == i ? 1 : 0;
      layout.Append(base.x(), fmt::format("{}: path {} point {} x", n, path.name, i));
      layout.Append(base.y(), fmt::format("{}: path {} point {} y", n, path.name, i));
      layout.Append(on_leg, fmt::format("{}: path {} trips on the leg from point {}", n, path.name, i));
    }
  }
}

}  // namespace

std::optional<std::string> LinuxCncDataProblem(const cell::Cell& cell) {
  for (const cell::Fixture& fixture : cell.fixtures) {
    if (!FitsCRuntime(fixture)) {
      return fmt::format("fixture {} makes {} trips; the LinuxCNC runtime holds 1 to {} per scan", fixture.name,
                         ExpectedTrips(fixture).size(), kCRuntimeMaxTrips);
    }
  }
  const int end = TotalSize(cell);
  if (end > L::kScratch) {
    return fmt::format(
        "the cell's regions and fixtures need the numbered parameters #{} to #{}, more than the runtime's "
        "#{} to #{} (#{}..#{} are its scratch space; use smaller error tables)",
        L::kFirst, end - 1, L::kFirst, L::kScratch - 1, L::kScratch, L::kLast);
  }
  return std::nullopt;
}

namespace {

// The data file's text, with the runtime id `id` (none: the line left out).
std::string DataText(const cell::Cell& cell, std::optional<long> id);

std::uint32_t Fnv1a(std::uint32_t hash, std::string_view text) {
  for (char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 16777619u;
  }
  return hash;
}

}  // namespace

long LinuxCncRuntimeIdOf(std::string_view version, std::string_view data_without_id, std::string_view scan_abort,
                         std::string_view record, std::string_view record_open) {
  std::uint32_t hash = Fnv1a(2166136261u, version);
  for (const EmbeddedFile& file : LinuxCncRuntimeFiles()) hash = Fnv1a(Fnv1a(hash, file.name), file.text);
  hash = Fnv1a(hash, data_without_id);
  hash = Fnv1a(hash, scan_abort);
  hash = Fnv1a(hash, record);
  hash = Fnv1a(hash, record_open);
  return static_cast<long>(hash & 0x7fffffffu);
}

long LinuxCncRuntimeId(const cell::Cell& cell) {
  return LinuxCncRuntimeIdOf(SMTCAL_VERSION, DataText(cell, std::nullopt), EmitLinuxCncScanAbort(cell),
                             EmitLinuxCncRecord(cell), EmitLinuxCncRecordOpen(cell));
}

std::string EmitLinuxCncData(const cell::Cell& cell) { return DataText(cell, LinuxCncRuntimeId(cell)); }

namespace {

std::string DataText(const cell::Cell& cell, std::optional<long> id) {
  const std::optional<std::string> problem = LinuxCncDataProblem(cell);
  SMTCAL_CHECK(!problem, "EmitLinuxCncData on a cell that does not fit the LinuxCNC runtime");
  Layout layout;
  const int region_directory = layout.Reserve(static_cast<int>(cell.regions.size()));
  const int fixture_directory = layout.Reserve(static_cast<int>(cell.fixtures.size()));
  for (std::size_t r = 0; r < cell.regions.size(); ++r) {
    AppendRegion(layout, cell.regions[r], region_directory + static_cast<int>(r));
  }
  for (std::size_t k = 0; k < cell.fixtures.size(); ++k) {
    AppendFixture(layout, cell.fixtures[k], cell.robot, fixture_directory + static_cast<int>(k));
  }
  SMTCAL_CHECK(layout.next() == TotalSize(cell), "the LinuxCNC data layout and its size disagree");

  std::string out;
  out += fmt::format(
      "; smtcal_data.ngc: the LinuxCNC runtime's data for cell {} ({}),\n"
      "; written by smtcal {} (smtcal compile --target linuxcnc). Do not edit: compile again.\n"
      "; o<smtcal_data> call stores the cell's regions (error tables) and fixtures in the\n"
      "; numbered parameters #{}..#{} (layout: runtime/linuxcnc/README.md) and marks every\n"
      "; fixture not scanned yet. Lengths mm, angles degrees, base frame.\n",
      CommentText(cell.name), CommentText(cell.path), SMTCAL_VERSION, L::kFirst, layout.next() - 1);
  // The files the data came from: `smtcal diff` names them.
  for (const cell::CellFile& file : cell.files) out += fmt::format("; {}\n", CommentText(cell::CellFileLine(file)));
  out += "o<smtcal_data> sub\n";
  out += fmt::format("#{} = 0  ; not loaded while loading\n", L::kVersion);
  out += fmt::format("#{} = {}  ; region count\n", L::kRegionCount, cell.regions.size());
  out += fmt::format("#{} = {}  ; fixture count\n", L::kFixtureCount, cell.fixtures.size());
  out += fmt::format("#{} = {}  ; region directory at\n", L::kRegionDirectory, region_directory);
  out += fmt::format("#{} = {}  ; fixture directory at\n", L::kFixtureDirectory, fixture_directory);
  out += fmt::format("#{} = {}  ; safe z (robot safe_limz_mm)\n", L::kSafeZ, LinuxCncNumber(cell.robot.safe_limz_mm));
  out += fmt::format("#{} = 0  ; a failed check aborts\n", L::kReportOnly);
  if (id) {
    out += fmt::format("{} = {}  ; this runtime: the main program checks it\n", L::kRuntimeIdParameter, *id);
  }
  out += layout.Text();
  out += fmt::format("#{} = {}  ; loaded: layout version\n", L::kVersion, L::kLayoutVersion);
  out += "o<smtcal_record_open> call  ; the cycle record: its begin line (smtcal_record_open.ngc)\n";
  out += "o<smtcal_data> endsub\n";
  return out;
}

}  // namespace

}  // namespace smtcal

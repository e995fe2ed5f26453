// Reading back a LinuxCNC output (backend/linuxcnc/linuxcnc_output.h).
//
// The runtime's folder. smtcal_data.ngc is a list of `#N = number  ; what`
// lines inside `o<smtcal_data> sub`; its numbers are decoded with the layout
// the runtime reads (linuxcnc_layout.h) into regions (bounds, policy, tables,
// validated) and fixtures (nominal pose, limits, estimator, marker edge
// lines, scan paths), the names taken from the `what` comments. A fixture's
// edge segments are rebuilt on their lines over the trips the data says each
// edge has, and the expected trips recomputed from them must be the data's
// own. Then the data is written again from what was decoded
// (EmitLinuxCncData) and compared line by line: every line the runtime
// reads — the derived numbers (domains, contraction, iteration bound, trip
// positions), the runtime's switches (#37: a failed scan aborts) and initial
// state, the comments — must be the emitter's, a number up to the rounding
// of the geometry decoded (kRoundingRel). Last, the runtime id the data
// records must be the one its text gives (LinuxCncRuntimeIdOf): a changed
// byte anywhere in the runtime's folder changes it. The runtime's own files
// must be this smtcal's, and the files written for the cell (scan abort
// messages, cycle record) what the emitter writes for the cell decoded.
//
// The main program: every form the emitter writes (linuxcnc_emit.cpp) is
// recognised line by line and written back as the .place statement it
// lowers — literal targets as XY(...), point parameters as the point (in its
// root frame: Local frames are folded in), temporaries as the point or
// pallet slot and its offsets, For, If, Wait Sw, Cycle, Scan, Call — and
// that text is parsed and checked like any program. The variables' types
// (the G-code has none) are inferred: a variable is Real when anything
// assigned to it is. Line numbers of the text are mapped back to the .ngc
// file's, so a diff names the lines of the program that runs. The
// o<pick_place> subroutine must be the emitter's for the wiring it names;
// each motion's first call argument (how the runtime commands it) is kept
// for CheckLinuxCncCommands. Blocks and brackets nest at most kMaxNesting
// deep (the .place parser's own bound on blocks).
#include "backend/linuxcnc/linuxcnc_output.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/format.h>

#include "backend/linuxcnc/embedded_files.h"
#include "backend/linuxcnc/linuxcnc_data.h"
#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/linuxcnc/linuxcnc_layout.h"
#include "backend/linuxcnc/linuxcnc_record.h"
#include "backend/linuxcnc/linuxcnc_scan_abort.h"
#include "base/check.h"
#include "calibration/error_table_check.h"
#include "calibration/fixture_geometry.h"
#include "ir/constant_fold.h"
#include "ir/ir_walk.h"
#include "ir/symbols.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
namespace L = linuxcnc_layout;

// How deep blocks (Cycle, For, If) and brackets may nest in a main program
// read back: the .place parser's bound on blocks (frontend/parse.cpp), so
// whatever is read can be parsed again; the recursion stays shallow.
constexpr int kMaxNesting = 100;
// Two numbers of a data line agree when they differ by at most this much of
// their size (or of 1): the rounding of what the decoded geometry gives back
// (an edge's line rebuilt from its normal, a path point through the nominal
// pose and back); anything a hand edit changes is far more, and the runtime
// id catches the rest.
constexpr double kRoundingRel = 1e-9;

// ------------------------------------------------------------------ errors

// A reading error, at a line of a file.
struct ReadError {
  std::uint32_t line = 0;
  std::string what;
};

// ------------------------------------------------------------------ text

// A finite number written as the emitter writes them (no exponent).
std::optional<double> ParseNumber(std::string_view text) {
  if (text.empty()) return std::nullopt;
  double value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value, std::chars_format::fixed);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

// Line `i` (0-based) of a file, without its line end.
std::string_view LineOf(const SourceFile& file, std::size_t i) {
  const std::size_t begin = file.line_starts[i];
  const std::size_t end = i + 1 < file.line_starts.size() ? file.line_starts[i + 1] : file.text.size();
  std::string_view line(file.text.data() + begin, end - begin);
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  return line;
}

// The lines of a text (the newline at the end does not open another).
std::vector<std::string_view> LinesOf(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    at = end + 1;
  }
  return lines;
}

// A line quoted in a message: cut, printable.
std::string Shown(std::string_view line) {
  std::string out;
  for (char c : line.substr(0, 100)) out += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  if (line.size() > 100) out += "...";
  return out;
}

// "#N = value  ; what" split into its address text, value and comment.
struct ParamLine {
  std::string_view address, value, what;
};
std::optional<ParamLine> SplitParamLine(std::string_view line) {
  if (!line.starts_with('#')) return std::nullopt;
  const std::size_t eq = line.find(" = ");
  if (eq == std::string_view::npos) return std::nullopt;
  ParamLine param{line.substr(0, eq), line.substr(eq + 3), {}};
  if (const std::size_t semicolon = param.value.find("  ; "); semicolon != std::string_view::npos) {
    param.what = param.value.substr(semicolon);
    param.value = param.value.substr(0, semicolon);
  }
  return param;
}

// The first line of `file` that is not `expected`'s (nullopt when they are
// the same). With `rounding`, two parameter lines of the same address and
// comment whose numbers agree to kRoundingRel are the same. A line starting
// with `skip` is left out on both sides.
std::optional<ReadError> FirstDifference(const SourceFile& file, std::string_view expected, bool rounding,
                                         std::string_view skip = {}) {
  std::vector<std::string_view> want = LinesOf(expected);
  std::vector<std::pair<std::uint32_t, std::string_view>> have;
  for (std::size_t i = 0; i < file.line_starts.size(); ++i) {
    std::string_view line = LineOf(file, i);
    if (line.empty() && i + 1 == file.line_starts.size() && file.text.ends_with('\n')) break;
    if (!skip.empty() && line.starts_with(skip)) continue;
    have.emplace_back(static_cast<std::uint32_t>(i + 1), line);
  }
  if (!skip.empty()) std::erase_if(want, [&](std::string_view line) { return line.starts_with(skip); });
  for (std::size_t i = 0; i < std::max(want.size(), have.size()); ++i) {
    if (i >= have.size()) {
      return ReadError{have.empty() ? 1 : have.back().first,
                       fmt::format("it ends where smtcal writes '{}'", Shown(want[i]))};
    }
    if (i >= want.size()) return ReadError{have[i].first, "a line after the end of what smtcal writes"};
    if (have[i].second == want[i]) continue;
    if (rounding) {
      std::optional<ParamLine> a = SplitParamLine(have[i].second), b = SplitParamLine(want[i]);
      if (a && b && a->address == b->address && a->what == b->what) {
        std::optional<double> x = ParseNumber(a->value), y = ParseNumber(b->value);
        if (x && y && std::fabs(*x - *y) <= kRoundingRel * std::max({1.0, std::fabs(*x), std::fabs(*y)})) continue;
      }
    }
    return ReadError{have[i].first, fmt::format("smtcal writes '{}' here{}", Shown(want[i]),
                                                rounding ? " for the data as read: this line or one it is "
                                                           "computed from was changed"
                                                         : "")};
  }
  return std::nullopt;
}

// ------------------------------------------------------------------ the data

struct DataParam {
  double value = 0;
  std::uint32_t line = 0;
  std::string what;  // the comment after `;`
};

class DataReader {
 public:
  explicit DataReader(const SourceFile& file) : file_(file) {}

  std::optional<ReadError> Read(cell::Cell& cell) {
    if (auto error = ReadLines(cell)) return error;
    const int regions = Integer(L::kRegionCount), fixtures = Integer(L::kFixtureCount);
    if (!error_.what.empty()) return error_;
    if (regions < 0 || fixtures < 0 || regions > L::kScratch || fixtures > L::kScratch) {
      return ReadError{Where(L::kRegionCount), "a region or fixture count out of range"};
    }
    for (int r = 0; r < regions && error_.what.empty(); ++r) ReadRegion(Integer(Integer(L::kRegionDirectory) + r), r, cell);
    for (int k = 0; k < fixtures && error_.what.empty(); ++k) {
      ReadFixture(Integer(Integer(L::kFixtureDirectory) + k), Integer(L::kFixtureDirectory) + k, cell);
    }
    cell.robot.safe_limz_mm = Value(L::kSafeZ);
    if (!error_.what.empty()) return error_;
    return std::nullopt;
  }
  // The runtime id the data sets, and its line (0: none).
  long id() const { return id_; }
  std::uint32_t id_line() const { return id_line_; }

 private:
  std::optional<ReadError> ReadLines(cell::Cell& cell) {
    bool in_sub = false, ended = false;
    for (std::size_t i = 0; i < file_.line_starts.size(); ++i) {
      const auto number = static_cast<std::uint32_t>(i + 1);
      std::string_view line = LineOf(file_, i);
      if (line.empty() && i + 1 == file_.line_starts.size()) break;  // the newline at the end
      if (ended) return ReadError{number, "text after o<smtcal_data> endsub"};
      if (line.starts_with(";")) {
        if (in_sub) continue;
        std::string_view text = line.substr(1);
        if (text.starts_with(' ')) text.remove_prefix(1);
        if (auto files = cell::ParseCellFileLine(text)) cell.files.push_back(std::move(*files));
        constexpr std::string_view kFor = "data for cell ";
        if (auto at = text.find(kFor); at != std::string_view::npos && cell.name.empty()) {
          std::string_view rest = text.substr(at + kFor.size());
          const std::size_t open = rest.rfind(" (");
          cell.name = std::string(rest.substr(0, open));
          if (open != std::string_view::npos && rest.ends_with("),")) {
            cell.path = std::string(rest.substr(open + 2, rest.size() - open - 4));
          }
        }
        continue;
      }
      if (line == "o<smtcal_data> sub" && !in_sub) {
        in_sub = true;
        continue;
      }
      if (line == "o<smtcal_data> endsub" && in_sub) {
        ended = true;
        continue;
      }
      // The cycle record's begin line (smtcal_record_open.ngc, written for the
      // cell): no data of the cell (the comparison with the emitter's text
      // holds it to its place).
      if (in_sub && line.starts_with("o<smtcal_record_open> call")) continue;
      if (!in_sub || !line.starts_with('#')) return ReadError{number, "a line that is not a parameter of o<smtcal_data>"};
      std::optional<ParamLine> param = SplitParamLine(line);
      if (!param) return ReadError{number, "a parameter line without ' = '"};
      if (param->address == L::kRuntimeIdParameter) {  // the runtime's identity, checked on its own
        std::optional<double> id = ParseNumber(param->value);
        if (!id || *id != std::floor(*id) || *id < 0 || *id > 0x7fffffff || id_line_ != 0) {
          return ReadError{number, "a runtime id that is not the one whole number smtcal writes"};
        }
        id_ = static_cast<long>(*id);
        id_line_ = number;
        continue;
      }
      std::optional<double> address = ParseNumber(param->address.substr(1));
      std::optional<double> value = ParseNumber(param->value);
      if (!address || !value || *address != std::floor(*address) || *address < L::kFirst || *address >= L::kScratch) {
        return ReadError{number, "a parameter line whose address or value is not a plain number in the data's range"};
      }
      std::string_view what = param->what;
      if (what.starts_with("  ; ")) what.remove_prefix(4);
      params_[static_cast<int>(*address)] = {*value, number, std::string(what)};
    }
    if (!ended) return ReadError{static_cast<std::uint32_t>(file_.line_starts.size()), "no o<smtcal_data> endsub"};
    if (Value(L::kVersion) != L::kLayoutVersion) {
      return ReadError{Where(L::kVersion), fmt::format("the layout version is not {}", L::kLayoutVersion)};
    }
    return std::nullopt;
  }

  std::uint32_t Where(int address) const {
    auto it = params_.find(address);
    return it != params_.end() ? it->second.line : 1;
  }

  void Fail(int address, std::string what) {
    if (error_.what.empty()) error_ = {Where(address), std::move(what)};
  }

  double Value(int address) {
    auto it = params_.find(address);
    if (it == params_.end()) {
      Fail(address, fmt::format("parameter #{} is missing", address));
      return 0;
    }
    return it->second.value;
  }
  int Integer(int address) {
    const double value = Value(address);
    if (value != std::floor(value) || std::fabs(value) > 1e6) {
      Fail(address, fmt::format("#{} is not a whole number", address));
      return 0;
    }
    return static_cast<int>(value);
  }
  // A length, limit or speed that must be above 0.
  double Positive(int address) {
    const double value = Value(address);
    if (!(value > 0)) Fail(address, fmt::format("#{} is not above 0", address));
    return value;
  }
  // The name in a "what" comment "<prefix>NAME<suffix>".
  std::string Name(int address, std::string_view prefix, std::string_view suffix) {
    auto it = params_.find(address);
    const std::string& what = it != params_.end() ? it->second.what : std::string();
    if (!what.starts_with(prefix) || !what.ends_with(suffix) || what.size() <= prefix.size() + suffix.size()) {
      Fail(address, fmt::format("#{} does not say what it is ('{}NAME{}')", address, prefix, suffix));
      return "";
    }
    return what.substr(prefix.size(), what.size() - prefix.size() - suffix.size());
  }

  AxisTable ReadTable(int at) {
    AxisTable table;
    const int nx = Integer(at), ny = Integer(at + 1);
    if (nx < 2 || ny < 2 || nx > L::kScratch || ny > L::kScratch || nx * ny > L::kScratch) {
      Fail(at, "a table smaller than 2 x 2 nodes or larger than the data");
      return table;
    }
    for (int i = 0; i < nx; ++i) table.xs.push_back(Value(at + 2 + i));
    for (int j = 0; j < ny; ++j) table.ys.push_back(Value(at + 2 + nx + j));
    for (int n = 0; n < nx * ny; ++n) table.error_mm.push_back(Value(at + 2 + nx + ny + n));
    return table;
  }

  void ReadRegion(int at, int index, cell::Cell& cell) {
    if (!error_.what.empty()) return;
    cell::Region region;
    region.name = Name(Integer(L::kRegionDirectory) + index, "region ", " at");
    region.x_mm = {Value(at + L::kRgXLo), Value(at + L::kRgXHi)};
    region.y_mm = {Value(at + L::kRgYLo), Value(at + L::kRgYHi)};
    const int outside = Integer(at + L::kRgOutside);
    if (outside < 0 || outside > 2) Fail(at + L::kRgOutside, "an outside policy that is not 0, 1 or 2");
    region.outside = static_cast<OutsidePolicy>(std::clamp(outside, 0, 2));
    region.table.name = region.name;
    region.table[TableAxis::X] = ReadTable(Integer(at + L::kRgDxAt));
    region.table[TableAxis::Y] = ReadTable(Integer(at + L::kRgDyAt));
    region.difficulty_level = 2;
    region.difficulty_axes = {cell::TaskAxis::X, cell::TaskAxis::Y};
    if (!error_.what.empty()) return;
    // The tables the runtime inverts must be ones smtcal accepts.
    SourceManager scratch_sources;
    Diagnostics scratch(scratch_sources);
    if (!HasUsableShape(region.table) || !ValidateErrorTable(region.table, scratch, TableWarnings::kSkip)) {
      Fail(at, fmt::format("the tables of region {} are not valid error tables", region.name));
      return;
    }
    region.domain = TableDomain(region.table);
    if (!(region.x_mm.lo < region.x_mm.hi) || !(region.y_mm.lo < region.y_mm.hi)) {
      Fail(at, fmt::format("the bounds of region {} are empty", region.name));
      return;
    }
    cell.regions.push_back(std::move(region));
  }

  // A unit vector of the data (a normal, the nominal pose's cos and sin).
  Eigen::Vector2d Unit(int address) {
    const Eigen::Vector2d v(Value(address), Value(address + 1));
    if (std::fabs(v.norm() - 1) > kRoundingRel) Fail(address, fmt::format("#{} and #{} are not a unit vector", address, address + 1));
    return v;
  }

  void ReadFixture(int at, int directory_entry, cell::Cell& cell) {
    if (!error_.what.empty()) return;
    cell::Fixture fixture;
    fixture.name = Name(directory_entry, "fixture ", " at");
    const int estimator = Integer(at + L::kFxEstimator);
    if (estimator < 0 || estimator > 2) Fail(at + L::kFxEstimator, "an estimator that is not 0, 1 or 2");
    fixture.estimator = static_cast<cell::Estimator>(std::clamp(estimator, 0, 2));
    fixture.origin_mm = {Value(at + L::kFxOriginX), Value(at + L::kFxOriginY)};
    const Eigen::Vector2d cos_sin = Unit(at + L::kFxCos);
    fixture.angle_deg = std::atan2(cos_sin.y(), cos_sin.x()) * kDegPerRad;
    fixture.l1_mm = Positive(at + L::kFxL1);
    fixture.l2_mm = Positive(at + L::kFxL2);
    fixture.trip_window_mm = Positive(at + L::kFxTripWindow);
    fixture.max_shift_mm = Positive(at + L::kFxMaxShift);
    fixture.max_rotation_deg = Positive(at + L::kFxMaxRotation);
    fixture.length_tolerance_mm = Positive(at + L::kFxLengthTolerance);
    fixture.squareness_deg = Positive(at + L::kFxSquareness);
    fixture.max_line_residual_mm = Positive(at + L::kFxMaxLineResidual);
    fixture.scan_z_mm = Value(at + L::kFxScanZ);
    fixture.scan_speed_mm_s = Positive(at + L::kFxScanFeed) / 60;
    fixture.latch_speed_mm_s = Value(at + L::kFxLatchFeed) / 60;  // 0: one stage
    if (fixture.latch_speed_mm_s < 0) Fail(at + L::kFxLatchFeed, "a latch feed below 0");
    fixture.predicted_window_mm = Value(at + L::kFxPredictedWindow);  // 0: every scan in full
    if (fixture.predicted_window_mm < 0) Fail(at + L::kFxPredictedWindow, "a predicted window below 0");
    // The robot's move speed, written into every fixture's record for the
    // predicted scan's traverses: the same in each.
    const double traverse_mm_s = Positive(at + L::kFxTraverseFeed) / 60;
    if (!cell.fixtures.empty() && traverse_mm_s != cell.robot.xy_speed_mm_s) {
      Fail(at + L::kFxTraverseFeed, "a traverse feed other than the first fixture's");
    }
    cell.robot.xy_speed_mm_s = traverse_mm_s;
    const int trips = Integer(at + L::kFxTripCount);
    if (trips < 1 || trips > 64) Fail(at + L::kFxTripCount, "a trip count out of range");
    if (!error_.what.empty()) return;
    const Eigen::Affine3d nominal = NominalFix(fixture);
    // The trips: their edges and nominal positions (base frame, nominal pose).
    const int edges_at = Integer(at + L::kFxTripEdgeAt), nominal_at = Integer(at + L::kFxTripNominalAt);
    std::vector<int> trip_edge;
    std::vector<Eigen::Vector2d> trip_at;  // fixture frame
    for (int k = 0; k < trips; ++k) {
      trip_edge.push_back(Integer(edges_at + k));
      trip_at.push_back(ToFixtureFrame(nominal, {Value(nominal_at + 2 * k), Value(nominal_at + 2 * k + 1)}));
    }
    // Each edge as the segment of its line that spans its trips.
    for (int e = 0; e < 4 && error_.what.empty(); ++e) {
      const Eigen::Vector2d normal = Unit(at + L::kFxEdgeNormal + 2 * e);
      const double offset = Value(at + L::kFxEdgeOffset + e);
      const Eigen::Vector2d along(normal.y(), -normal.x());  // EdgeLineOf turns the direction left into the normal
      const Eigen::Vector2d on_line = normal * offset;
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < trips; ++k) {
        if (trip_edge[static_cast<std::size_t>(k)] != e) continue;
        const double t = along.dot(trip_at[static_cast<std::size_t>(k)] - on_line);
        lo = std::min(lo, t);
        hi = std::max(hi, t);
      }
      if (lo > hi) {
        Fail(at + L::kFxTripEdgeAt, fmt::format("fixture {}'s edge p{} has no trip", fixture.name, e + 1));
        return;
      }
      constexpr double kSpanMarginMm = 1e-6;  // the trips lie on the rebuilt segment, not at its ends
      cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(e)];
      edge.name = fmt::format("p{}", e + 1);
      edge.from = on_line + along * (lo - kSpanMarginMm);
      edge.to = on_line + along * (hi + kSpanMarginMm);
    }
    if (!error_.what.empty()) return;
    // The scan paths, from the base frame at the nominal pose.
    const int paths_at = Integer(at + L::kFxScanPathsAt);
    const int paths = Integer(paths_at);
    if (paths < 1 || paths > 64) Fail(paths_at, "a scan path count out of range");
    int next = paths_at + 1;
    for (int p = 0; p < paths && error_.what.empty(); ++p) {
      cell::ScanPath path;
      const std::string prefix = fixture.name + ": path ";
      const std::string what = Name(next, prefix, " point count");
      path.name = what;
      const int points = Integer(next++);
      if (points < 2 || points > 1000) Fail(next - 1, "a scan path with fewer than 2 or more than 1000 points");
      for (int i = 0; i < points && error_.what.empty(); ++i, next += 3) {
        path.points.push_back(ToFixtureFrame(nominal, {Value(next), Value(next + 1)}));
        if (i > 0 && (path.points[i] - path.points[i - 1]).norm() == 0) Fail(next, "a scan path point repeated");
      }
      fixture.scan_paths.push_back(std::move(path));
    }
    if (!error_.what.empty()) return;
    // What the runtime expects must be what the cell's geometry gives.
    const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    bool same = static_cast<int>(expected.size()) == trips;
    for (std::size_t k = 0; same && k < expected.size(); ++k) {
      same = expected[k].edge == trip_edge[k] && (expected[k].in_fixture - trip_at[k]).norm() < 1e-6;
    }
    if (!same) {
      Fail(at + L::kFxTripNominalAt,
           fmt::format("fixture {}'s scan paths and edges do not make the trips its data lists", fixture.name));
      return;
    }
    cell.fixtures.push_back(std::move(fixture));
  }

  const SourceFile& file_;
  std::map<int, DataParam> params_;
  ReadError error_;
  long id_ = -1;
  std::uint32_t id_line_ = 0;
};

// ------------------------------------------------------------------ the cycle record

// The cycle record's settings ([linuxcnc] record_file, record_max_cycles,
// record_clock_pin) as the files written for them name them; the comparison
// with the emitter's text checks every line.
void DecodeRecord(const SourceFile& record_open, const SourceFile& record, cell::LinuxCnc& linuxcnc) {
  const std::string_view open = record_open.text, rec = record.text;
  constexpr std::string_view kAppend = "(LOGAPPEND,";
  if (const std::size_t at = open.find(kAppend); at != std::string_view::npos) {
    const std::size_t end = open.find(')', at);
    if (end != std::string_view::npos) linuxcnc.record_file = std::string(open.substr(at + kAppend.size(), end - at - kAppend.size()));
  }
  constexpr std::string_view kClock = " clock=";
  if (const std::size_t at = open.find(kClock); at != std::string_view::npos) {
    const std::size_t end = open.find(' ', at + kClock.size());
    const std::string_view pin = open.substr(at + kClock.size(), end == std::string_view::npos ? 0 : end - at - kClock.size());
    linuxcnc.record_clock_pin = pin == "none" ? std::string() : std::string(pin);
  }
  const std::string full = fmt::format("if [#{} GE ", L::kRecordCount);
  if (const std::size_t at = rec.find(full); at != std::string_view::npos) {
    const std::size_t end = rec.find(']', at);
    if (end != std::string_view::npos) {
      std::optional<double> cycles = ParseNumber(rec.substr(at + full.size(), end - at - full.size()));
      if (cycles && *cycles >= 1 && *cycles <= 1e9 && *cycles == std::floor(*cycles)) {
        linuxcnc.record_max_cycles = static_cast<int>(*cycles);
      }
    }
  }
}

// ------------------------------------------------------------------ G-code expressions

// An RS274NGC expression as the emitter writes it: a number, a parameter,
// a bracketed chain `[a OP b OP c]`, or a function `ABS[...]`.
struct GNode {
  enum class Kind { kNumber, kParam, kGroup, kCall } kind = Kind::kNumber;
  std::string text;              // the number as written, the parameter's name (<...> or digits), the function
  std::vector<GNode> operands;   // kGroup: the chain's operands; kCall: one, its argument group
  std::vector<std::string> ops;  // kGroup: between the operands
};

class GParser {
 public:
  explicit GParser(std::string_view text) : text_(text) {}

  std::optional<GNode> Expr() {
    Skip();
    if (at_ >= text_.size()) return std::nullopt;
    // Brackets nest at most kMaxNesting deep: the recursion stays shallow.
    if (depth_ >= kMaxNesting) {
      too_deep_ = true;
      return std::nullopt;
    }
    const char c = text_[at_];
    if (c == '[') return Group();
    if (c == '#') {
      ++at_;
      GNode node;
      node.kind = GNode::Kind::kParam;
      if (at_ < text_.size() && text_[at_] == '<') {
        const std::size_t close = text_.find('>', at_);
        if (close == std::string_view::npos) return std::nullopt;
        node.text = std::string(text_.substr(at_ + 1, close - at_ - 1));
        at_ = close + 1;
      } else {
        const std::size_t begin = at_;
        while (at_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[at_]))) ++at_;
        if (begin == at_) return std::nullopt;
        node.text = std::string(text_.substr(begin, at_ - begin));
      }
      return node;
    }
    if (c == '-' || c == '.' || std::isdigit(static_cast<unsigned char>(c))) {
      const std::size_t begin = at_++;
      while (at_ < text_.size() && (std::isdigit(static_cast<unsigned char>(text_[at_])) || text_[at_] == '.')) ++at_;
      GNode node;
      node.text = std::string(text_.substr(begin, at_ - begin));
      if (!ParseNumber(node.text)) return std::nullopt;
      return node;
    }
    if (std::isalpha(static_cast<unsigned char>(c))) {
      const std::size_t begin = at_;
      while (at_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[at_]))) ++at_;
      GNode node;
      node.kind = GNode::Kind::kCall;
      node.text = std::string(text_.substr(begin, at_ - begin));
      if (at_ >= text_.size() || text_[at_] != '[') return std::nullopt;
      std::optional<GNode> argument = Group();
      if (!argument) return std::nullopt;
      node.operands.push_back(std::move(*argument));
      return node;
    }
    return std::nullopt;
  }

  bool AtEnd() {
    Skip();
    return at_ >= text_.size();
  }
  // Whether an expression failed for nesting deeper than kMaxNesting.
  bool too_deep() const { return too_deep_; }
  std::size_t position() const { return at_; }

 private:
  std::optional<GNode> Group() {
    ++at_;  // [
    ++depth_;
    std::optional<GNode> group = GroupBody();
    --depth_;
    return group;
  }
  std::optional<GNode> GroupBody() {
    GNode node;
    node.kind = GNode::Kind::kGroup;
    std::optional<GNode> first = Expr();
    if (!first) return std::nullopt;
    node.operands.push_back(std::move(*first));
    while (true) {
      Skip();
      if (at_ >= text_.size()) return std::nullopt;
      if (text_[at_] == ']') {
        ++at_;
        return node;
      }
      std::size_t begin = at_;
      if (std::string_view("+-*/").find(text_[at_]) != std::string_view::npos) {
        ++at_;
      } else {
        while (at_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[at_]))) ++at_;
      }
      if (begin == at_) return std::nullopt;
      node.ops.emplace_back(text_.substr(begin, at_ - begin));
      std::optional<GNode> operand = Expr();
      if (!operand) return std::nullopt;
      node.operands.push_back(std::move(*operand));
    }
  }
  void Skip() {
    while (at_ < text_.size() && text_[at_] == ' ') ++at_;
  }

  std::string_view text_;
  std::size_t at_ = 0;
  int depth_ = 0;
  bool too_deep_ = false;
};

// `*too_deep` (when given) says whether it failed for brackets nested too deep.
std::optional<GNode> ParseGExpr(std::string_view text, bool* too_deep = nullptr) {
  GParser parser(text);
  std::optional<GNode> node = parser.Expr();
  if (too_deep != nullptr) *too_deep = parser.too_deep();
  if (!node || !parser.AtEnd()) return std::nullopt;
  return node;
}

bool IsNumber(const GNode& n, std::string_view text) { return n.kind == GNode::Kind::kNumber && n.text == text; }
bool IsParam(const GNode& n, std::string_view name) { return n.kind == GNode::Kind::kParam && n.text == name; }
bool Same(const GNode& a, const GNode& b) {
  if (a.kind != b.kind || a.text != b.text || a.ops != b.ops || a.operands.size() != b.operands.size()) return false;
  for (std::size_t i = 0; i < a.operands.size(); ++i) {
    if (!Same(a.operands[i], b.operands[i])) return false;
  }
  return true;
}
// [a OP b]
bool IsBinary(const GNode& n, std::string_view op) {
  return n.kind == GNode::Kind::kGroup && n.ops.size() == 1 && n.ops[0] == op;
}

// ------------------------------------------------------------------ the main program

enum class Type { kInteger, kReal, kBoolean };

struct PExpr {
  std::string text;
  Type type = Type::kInteger;
};

// One line of the main program: its block (indentation and trailing comment
// removed) and its comment.
struct NgcLine {
  std::uint32_t number = 0;
  std::string raw;  // the line as written (without its line end)
  std::string block;
  std::string comment;  // inside the trailing parentheses, or the whole comment line's
  bool comment_only = false;
};

struct Failure {
  ReadError error;
};

class Decompiler {
 public:
  Decompiler(const SourceFile& ngc, const cell::Cell& cell, double safe_z, std::string program_name)
      : cell_(cell), safe_z_(safe_z), program_name_(std::move(program_name)) {
    for (std::size_t i = 0; i < ngc.line_starts.size(); ++i) {
      const std::size_t begin = ngc.line_starts[i];
      const std::size_t end = i + 1 < ngc.line_starts.size() ? ngc.line_starts[i + 1] : ngc.text.size();
      std::string_view text(ngc.text.data() + begin, end - begin);
      while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
      while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
      if (text.empty() && i + 1 == ngc.line_starts.size()) break;
      NgcLine line;
      line.number = static_cast<std::uint32_t>(i + 1);
      line.raw = std::string(LineOf(ngc, i));
      if (text.starts_with('(') && text.ends_with(')')) {
        line.comment_only = true;
        line.comment = std::string(text.substr(1, text.size() - 2));
      } else if (const std::size_t open = text.find(" ("); open != std::string_view::npos && text.ends_with(')')) {
        line.block = std::string(text.substr(0, open));
        line.comment = std::string(text.substr(open + 2, text.size() - open - 3));
      } else {
        line.block = std::string(text);
      }
      lines_.push_back(std::move(line));
    }
  }

  // What the main program gives of the cell besides the data: the robot's
  // final approach and Move feed, the [linuxcnc] wiring (rotation axis,
  // vacuum sensor), as its moves and its o<pick_place> write them.
  struct Wiring {
    std::optional<char> axis;
    std::optional<double> move_feed;              // G1 F, mm/min
    std::optional<Eigen::Vector2d> approach;      // the final approach of a Jump or o<pick_place>
    bool approach_seen = false;                   // a Jump or o<pick_place> said whether there is one
    std::optional<int> vacuum_sensor;
    std::optional<double> vacuum_timeout_s;
  };
  const Wiring& wiring() const { return wiring_; }
  // The runtime id the main program checks for, and the line.
  long runtime_id() const { return runtime_id_; }
  std::uint32_t runtime_id_line() const { return runtime_id_line_; }

  // The .place text and, per line of it, the .ngc line it stands for and
  // how the runtime commands the position of its motion.
  std::optional<ReadError> Run(std::string& text, std::vector<std::uint32_t>& map, std::vector<int>& commands) {
    // Types settle in a few rounds: each one may find another variable Real.
    for (int round = 0; round < 8; ++round) {
      const std::map<std::string, Type> before = types_;
      try {
        Decompile();
      } catch (const Failure& failure) {
        return failure.error;
      }
      if (types_ == before) break;
    }
    text = std::move(out_);
    map = std::move(map_);
    commands = std::move(commands_);
    return std::nullopt;
  }

 private:
  // ---------------------------------------------------------------- output

  void Emit(std::string line, std::uint32_t ngc_line, int command = kNoLinuxCncCommand) {
    out_ += std::string(static_cast<std::size_t>(indent_) * 2, ' ');
    out_ += line;
    out_ += '\n';
    map_.push_back(ngc_line);
    commands_.push_back(command);
  }

  [[noreturn]] void Fail(const NgcLine& line, std::string what) const { throw Failure{{line.number, std::move(what)}}; }
  [[noreturn]] void FailAt(std::uint32_t line, std::string what) const { throw Failure{{line, std::move(what)}}; }

  const NgcLine& Peek() const {
    if (at_ >= lines_.size()) FailAt(lines_.empty() ? 1 : lines_.back().number, "the program ends early");
    return lines_[at_];
  }
  const NgcLine& Next() {
    const NgcLine& line = Peek();
    ++at_;
    return line;
  }
  const NgcLine& Expect(std::string_view block) {
    const NgcLine& line = Next();
    if (line.block != block) Fail(line, fmt::format("expected '{}'", block));
    return line;
  }

  // ---------------------------------------------------------------- the program

  void Decompile() {
    out_.clear();
    map_.clear();
    commands_.clear();
    at_ = 0;
    indent_ = 0;
    depth_ = 0;
    in_cycle_ = false;
    wiring_ = {};
    pick_place_sub_ = false;
    pick_place_used_ = 0;
    switches_.clear();
    pallets_.clear();
    pallet_lines_.clear();
    assigned_real_.clear();
    std::string functions_text;
    std::vector<std::uint32_t> functions_map;
    std::vector<int> functions_commands;

    const NgcLine& header = Next();
    if (!header.comment_only || !header.comment.starts_with("smtcal ") ||
        header.comment.find(" for LinuxCNC and cell ") == std::string::npos) {
      Fail(header, "the first line is not smtcal's header");
    }
    const std::uint32_t header_line = header.number;
    while (Peek().comment_only) Next();
    Expect("G21 G90 G17 G94 G61");
    Expect("o<smtcal_data> call");
    // The check that the runtime on the path is the one compiled with the
    // program: two ifs, each aborting (not part of the program's text).
    const std::string id(L::kRuntimeIdParameter);
    for (const std::string& condition : {" if [EXISTS[" + id + "] EQ 0]", " if [" + id + " NE "}) {
      const NgcLine& check = Next();
      const std::size_t found = check.block.find(condition);
      if (!check.block.starts_with('o') || found == std::string::npos) {
        Fail(check, "the main program without its runtime check");
      }
      if (condition.ends_with(" NE ")) {  // the id it checks for
        std::string_view value = std::string_view(check.block).substr(found + condition.size());
        std::optional<double> number = value.ends_with(']') ? ParseNumber(value.substr(0, value.size() - 1)) : std::nullopt;
        if (!number || *number != std::floor(*number) || *number < 0 || *number > 0x7fffffff) {
          Fail(check, "a runtime check for something other than a runtime id");
        }
        runtime_id_ = static_cast<long>(*number);
        runtime_id_line_ = check.number;
      }
      if (!Next().comment.starts_with("abort,")) Fail(lines_[at_ - 1], "a runtime check without its abort");
      if (!Next().block.ends_with(" endif")) Fail(lines_[at_ - 1], "a runtime check without its endif");
    }
    // Points, then globals.
    std::vector<std::pair<std::string, std::uint32_t>> points;  // .place line, .ngc line
    while (true) {
      const NgcLine& line = Peek();
      if (line.comment_only && line.comment.starts_with("Point ")) {
        ReadSplitPoint(points);
      } else if (!line.comment_only && line.block.starts_with("#<_p_")) {
        ReadPoint(points);
      } else {
        break;
      }
    }
    std::vector<std::pair<std::string, std::uint32_t>> globals;  // name, line
    while (!Peek().comment_only && Peek().block.starts_with("#<_v_")) {
      const NgcLine& line = Next();
      const std::string name = VariableName(line, line.block.substr(0, line.block.find(' ')));
      if (line.block != fmt::format("#<_v_{}> = 0", name)) Fail(line, "a global that does not start at 0");
      globals.emplace_back(name, line.number);
    }
    // The Pick/Place subroutine, the same in every output of a cell.
    if (Peek().comment_only && Peek().comment.starts_with("Pick and Place:")) PickPlaceSubroutine();
    // The functions.
    std::swap(out_, functions_text);
    std::swap(map_, functions_map);
    std::swap(commands_, functions_commands);
    while (Peek().block.starts_with("o<fn_") && Peek().block.ends_with("> sub")) ReadFunction();
    std::swap(out_, functions_text);
    std::swap(map_, functions_map);
    std::swap(commands_, functions_commands);
    Expect("o<fn_main> call");
    Expect("M2");
    if (at_ != lines_.size()) Fail(lines_[at_], "text after M2");
    if (pick_place_used_ != 0 && !pick_place_sub_) FailAt(pick_place_used_, "o<pick_place> called, and the program does not define it");

    // The declarations, then the functions.
    Emit("Program " + program_name_, header_line);
    Emit("Units mm", header_line);
    if (vacuum_) Emit(fmt::format("Vacuum {}", *vacuum_), vacuum_line_);
    for (const cell::Fixture& fixture : cell_.fixtures) Emit("Fixture " + fixture.name, header_line);
    for (const auto& [line, ngc] : points) Emit(line, ngc);
    for (std::size_t p = 0; p < pallets_.size(); ++p) Emit(fmt::format("Pallet {}, {}", p + 1, pallets_[p]), pallet_lines_[p]);
    for (const auto& [name, line] : globals) Emit(fmt::format("{} {}", TypeName(name), name), line);
    out_ += functions_text;
    map_.insert(map_.end(), functions_map.begin(), functions_map.end());
    commands_.resize(map_.size() - functions_map.size(), kNoLinuxCncCommand);
    commands_.insert(commands_.end(), functions_commands.begin(), functions_commands.end());
  }

  // The o<pick_place> subroutine: the wiring it names (the vacuum sensor and
  // its timeout, the rotation axis, the final approach) read from its moves
  // and waits, then the whole of it, comments included, as the emitter
  // writes it for that wiring (LinuxCncPickPlaceSubroutine).
  void PickPlaceSubroutine() {
    const NgcLine& first = Peek();
    constexpr int kMaxSubroutineLines = 40;
    int read = 0;
    std::string text;
    std::string where;
    while (true) {
      const NgcLine& line = Next();
      text += line.raw;
      text += '\n';
      const std::string& b = line.block;
      if (b.starts_with("M66 P") && b.find(" L3 Q") != std::string::npos) {  // M66 P<sensor> L3 Q<timeout>
        const std::size_t l = b.find(" L3 Q");
        std::optional<double> sensor = ParseNumber(std::string_view(b).substr(5, l - 5));
        std::optional<double> timeout = ParseNumber(std::string_view(b).substr(l + 5));
        if (!sensor || !timeout || *sensor != std::floor(*sensor) || *sensor < 0 || *sensor >= cell::kLinuxCncMaxDio ||
            !(*timeout > 0)) {
          Fail(line, "o<pick_place>'s wait for the vacuum sensor is not smtcal's");
        }
        wiring_.vacuum_sensor = static_cast<int>(*sensor);
        wiring_.vacuum_timeout_s = *timeout;
      } else if (b.starts_with("G0 X") && b.ends_with("#5") && b.size() > 3) {  // the move, its axis, its approach
        const char axis = b[b.size() - 3];
        if (axis != 'A' && axis != 'B' && axis != 'C') Fail(line, "o<pick_place>'s move is not smtcal's");
        Axis(line, axis);
        if (b.starts_with("G0 X[#2 - ")) {
          const std::map<char, GNode> words = Words(line);
          const GNode& x = words.at('X');
          const GNode* y = words.count('Y') ? &words.at('Y') : nullptr;
          if (!IsBinary(x, "-") || y == nullptr || !IsBinary(*y, "-") || x.operands[1].kind != GNode::Kind::kNumber ||
              y->operands[1].kind != GNode::Kind::kNumber) {
            Fail(line, "o<pick_place>'s final approach is not smtcal's");
          }
          Approach(line, Eigen::Vector2d(*ParseNumber(x.operands[1].text), *ParseNumber(y->operands[1].text)));
        } else {
          Approach(line, std::nullopt);
        }
      } else if (line.comment_only && line.comment.starts_with("abort,smtcal: Pick at ")) {
        const std::string& c = line.comment;
        const std::size_t end = c.find(":%d#9");
        if (end == std::string::npos) Fail(line, "o<pick_place>'s abort is not smtcal's");
        where = c.substr(22, end - 22);
      }
      // Its end, or as far as the longest the emitter writes: the comparison
      // names the first line that differs.
      if (b.starts_with("o<pick_place> endsub") || ++read > kMaxSubroutineLines) break;
    }
    // What it names is compared whole below: a line it could not be read
    // from is the first that differs from the emitter's.
    cell::Cell wired;
    wired.linuxcnc.emplace();
    wired.linuxcnc->rotation_axis = wiring_.axis.value_or('C');
    wired.linuxcnc->vacuum_sensor_input = wiring_.vacuum_sensor.value_or(0);
    wired.linuxcnc->vacuum_timeout_s = wiring_.vacuum_timeout_s.value_or(1);
    wired.robot.final_approach_mm = wiring_.approach;
    if (std::optional<ReadError> differs = FirstDifferenceIn(first.number, text,
                                                              LinuxCncPickPlaceSubroutine(wired, where))) {
      throw Failure{*differs};
    }
    pick_place_sub_ = true;
  }

  // The first line of `text` (the .ngc's lines from `first` on) that is not `expected`'s.
  static std::optional<ReadError> FirstDifferenceIn(std::uint32_t first, std::string_view text, std::string_view expected) {
    const std::vector<std::string_view> have = LinesOf(text), want = LinesOf(expected);
    for (std::size_t i = 0; i < std::max(have.size(), want.size()); ++i) {
      const std::uint32_t line = first + static_cast<std::uint32_t>(std::min(i, have.size() - 1));
      if (i >= have.size()) return ReadError{line, fmt::format("it ends where smtcal writes '{}'", Shown(want[i]))};
      if (i >= want.size()) return ReadError{line, "a line after the end of what smtcal writes"};
      if (have[i] != want[i]) return ReadError{line, fmt::format("smtcal writes '{}' here", Shown(want[i]))};
    }
    return std::nullopt;
  }

  // Every move names the same rotation axis.
  void Axis(const NgcLine& line, char axis) {
    if (wiring_.axis && *wiring_.axis != axis) {
      Fail(line, fmt::format("a move on the {} axis where the program turns u on {}", axis, *wiring_.axis));
    }
    wiring_.axis = axis;
  }
  // Every Jump (and o<pick_place>) makes the same final approach, or none.
  void Approach(const NgcLine& line, const std::optional<Eigen::Vector2d>& approach) {
    if (wiring_.approach_seen && wiring_.approach != approach) {
      Fail(line, "a final approach other than the program's other moves make");
    }
    wiring_.approach_seen = true;
    wiring_.approach = approach;
  }

  std::string TypeName(const std::string& name) const {
    auto it = types_.find(name);
    return it != types_.end() && it->second == Type::kReal ? "Real" : "Integer";
  }

  // "#<_v_name>" / "#<v_name>" -> "name".
  std::string VariableName(const NgcLine& line, std::string_view param) const {
    if (param.starts_with("#<_v_") && param.ends_with('>')) return std::string(param.substr(5, param.size() - 6));
    if (param.starts_with("#<v_") && param.ends_with('>')) return std::string(param.substr(4, param.size() - 5));
    Fail(line, "expected a variable");
  }

  // ---------------------------------------------------------------- points

  // "Point R1 In Layer1 -> fixture Board frame": the display name and the root ("" = base).
  void PointComment(const NgcLine& line, std::string_view comment, std::string& name, std::string& root) const {
    const std::size_t arrow = comment.find(" -> ");
    const std::size_t word = comment.find("Point ");
    if (arrow == std::string_view::npos || word == std::string_view::npos) Fail(line, "a point without its comment");
    std::string_view decl = comment.substr(word + 6, arrow - word - 6);
    name = std::string(decl.substr(0, decl.find(' ')));
    std::string_view frame = comment.substr(arrow + 4);
    if (frame == "robot base frame") {
      root.clear();
    } else if (frame.starts_with("fixture ") && frame.ends_with(" frame")) {
      root = std::string(frame.substr(8, frame.size() - 14));
    } else {
      Fail(line, "a point's frame that is neither the robot base nor a fixture");
    }
  }

  std::string PointLine(const NgcLine& line, const std::string& param_name, std::string name,
                        const std::string& root, const std::array<std::string, 4>& values) {
    // A name cut in the comment (long names): the parameter's, lowercase.
    if (name.ends_with("...") || sema_lower(name) != param_name) name = param_name;
    point_names_[param_name] = name;
    point_roots_[param_name] = root;
    (void)line;
    std::string text = fmt::format("Point {} = XY({}, {}, {}, {})", name, values[0], values[1], values[2], values[3]);
    if (!root.empty()) text += " In " + root;
    return text;
  }

  static std::string sema_lower(std::string_view text) {
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  }

  // #<_p_NAME_x> = v #<_p_NAME_y> = v #<_p_NAME_z> = v #<_p_NAME_u> = v (src:L Point ...)
  void ReadPoint(std::vector<std::pair<std::string, std::uint32_t>>& points) {
    const NgcLine& line = Next();
    std::string_view rest = line.block;
    std::string param;
    std::array<std::string, 4> values;
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    for (int a = 0; a < 4; ++a) {
      if (!rest.starts_with("#<_p_")) Fail(line, "a point line without its four parameters");
      const std::size_t close = rest.find("> = ");
      if (close == std::string_view::npos || close < 7 || rest[close - 2] != '_' || rest[close - 1] != kAxes[a]) {
        Fail(line, "a point line without its four parameters");
      }
      const std::string name(rest.substr(5, close - 7));
      if (a == 0) param = name;
      if (name != param) Fail(line, "a point line with parameters of two points");
      rest.remove_prefix(close + 4);
      const std::size_t space = rest.find(' ');
      values[a] = std::string(rest.substr(0, space));
      if (!ParseNumber(values[a])) Fail(line, "a point coordinate that is not a number");
      rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
    }
    if (!rest.empty()) Fail(line, "text after a point's parameters");
    std::string name, root;
    PointComment(line, line.comment, name, root);
    points.emplace_back(PointLine(line, param, name, root, values), line.number);
  }

  // (Point ... -> ... src:L) then one line per axis.
  void ReadSplitPoint(std::vector<std::pair<std::string, std::uint32_t>>& points) {
    const NgcLine& comment = Next();
    std::string name, root;
    // The comment ends with the source location: cut it before the frame is read.
    std::string text = comment.comment.substr(0, comment.comment.rfind(' '));
    PointComment(comment, text, name, root);
    std::string param;
    std::array<std::string, 4> values;
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    for (int a = 0; a < 4; ++a) {
      const NgcLine& line = Next();
      const std::size_t close = line.block.find("> = ");
      if (!line.block.starts_with("#<_p_") || close == std::string::npos || line.block[close - 1] != kAxes[a]) {
        Fail(line, "a point's parameter line");
      }
      const std::string p = line.block.substr(5, close - 7);
      if (a == 0) param = p;
      if (p != param) Fail(line, "a point line with parameters of two points");
      values[a] = line.block.substr(close + 4);
      if (!ParseNumber(values[a])) Fail(line, "a point coordinate that is not a number");
    }
    points.emplace_back(PointLine(comment, param, name, root, values), comment.number);
  }

  // ---------------------------------------------------------------- functions

  void ReadFunction() {
    const NgcLine& sub = Next();
    const std::string name = sub.block.substr(5, sub.block.size() - 10);
    std::vector<std::string> locals;
    while (!Peek().comment_only && Peek().block.starts_with("#<v_") && Peek().comment == sub.comment) {
      const NgcLine& line = Next();
      const std::string local = VariableName(line, line.block.substr(0, line.block.find(' ')));
      if (line.block != fmt::format("#<v_{}> = 0", local)) Fail(line, "a local that does not start at 0");
      locals.push_back(local);
    }
    Emit("Function " + name, sub.number);
    ++indent_;
    for (const std::string& local : locals) Emit(fmt::format("{} {}", TypeName(local), local), sub.number);
    const std::string end = fmt::format("o<fn_{}> endsub", name);
    Body([&](const NgcLine& line) { return line.block == end; });
    --indent_;
    Emit("Fend", Next().number);
  }

  // Statements until a line `stop` accepts (not consumed). A block inside
  // kMaxNesting others is refused at its first line: the .place parser
  // would refuse it, and the recursion stays shallow.
  template <typename Stop>
  void Body(const Stop& stop) {
    if (++depth_ > kMaxNesting) {
      Fail(lines_[at_ - 1], fmt::format("blocks nested more than {} deep", kMaxNesting));
    }
    while (!stop(Peek())) Statement();
    --depth_;
  }

  // The temporaries and switch reads that prepare one statement.
  struct Prepared {
    std::map<std::string, std::vector<GNode>> temps;  // each assignment of a #<t_...> in order
    std::vector<std::pair<std::string, GNode>> order;  // (temp, value) in order
    std::uint32_t first_line = 0;
  };

  void Statement() {
    Prepared prepared;
    // Switch reads and temporaries come before the block that uses them.
    while (true) {
      const NgcLine& line = Peek();
      if (line.comment_only) break;
      if (line.block.starts_with("M66 P") && line.block.ends_with(" L0")) {
        Next();
        if (prepared.first_line == 0) prepared.first_line = line.number;
        std::optional<GNode> bit = ParseGExpr(line.block.substr(5, line.block.size() - 8));
        const NgcLine& store = Next();
        if (!bit || !store.block.starts_with("#<t_sw") || !store.block.ends_with("> = #5399")) {
          Fail(store, "a switch read without its temporary");
        }
        switches_[store.block.substr(2, store.block.find('>') - 2)] = *bit;
        continue;
      }
      if (line.block.starts_with("#<t_") && !line.block.starts_with("#<t_for")) {
        Next();
        if (prepared.first_line == 0) prepared.first_line = line.number;
        const std::size_t eq = line.block.find("> = ");
        if (eq == std::string::npos) Fail(line, "a temporary without a value");
        const std::string temp = line.block.substr(2, eq - 2);
        std::optional<GNode> value = ParseGExpr(line.block.substr(eq + 4));
        if (!value) Fail(line, "an expression smtcal does not write");
        prepared.temps[temp].push_back(*value);
        prepared.order.emplace_back(temp, std::move(*value));
        continue;
      }
      break;
    }
    const NgcLine& line = Next();
    const std::uint32_t at = prepared.first_line != 0 ? prepared.first_line : line.number;
    const std::string& b = line.block;
    if (line.comment_only) {
      if (line.comment.starts_with("Cycle ")) return Cycle(line);
      Fail(line, "a comment where a statement belongs");
    }
    if (b.starts_with("o<pick_place> call ")) return PickPlace(line, prepared, at);
    if (b.starts_with("o<smtcal_correct> call ") || b.starts_with("G0 ") || b.starts_with("G1 ")) {
      return Motion(line, prepared, at);
    }
    if (!prepared.order.empty()) Fail(line, "temporaries before a statement that uses none");
    if (b.starts_with("#<t_for")) return For(line);
    if (b.starts_with("#<v_") || b.starts_with("#<_v_")) {
      const std::size_t eq = b.find(" = ");
      if (eq == std::string::npos) Fail(line, "an assignment without ' = '");
      const std::string name = VariableName(line, b.substr(0, eq));
      PExpr value = Expression(line, b.substr(eq + 3));
      if (value.type == Type::kReal) assigned_real_.insert(name);
      Assigned(name, value.type);
      return Emit(fmt::format("{} = {}", name, value.text), at);
    }
    if (b.starts_with("M64 P") || b.starts_with("M65 P")) {
      return Emit(fmt::format("{} {}", b[2] == '4' ? "On" : "Off", Expression(line, b.substr(5)).text), at);
    }
    if (b.starts_with("G4 P")) return Emit("Wait " + Expression(line, b.substr(4)).text, at);
    if (b.starts_with("o<fn_") && b.ends_with("> call")) return Emit("Call " + b.substr(5, b.size() - 11), at);
    if (b.starts_with("o<fn_") && b.ends_with("> return")) return Emit("Exit Function", at);
    if (b.starts_with("o<smtcal_scan> call [") && b.ends_with("]")) {
      return Emit("Scan " + FixtureName(line, b.substr(21, b.size() - 22)), at);
    }
    if (b.starts_with('o') && b.ends_with(" do")) return WaitSwitch(line);
    if (b.starts_with('o') && b.find(" if ") != std::string::npos) return If(line, at);
    Fail(line, "a block smtcal does not write");
  }

  void Assigned(const std::string& name, Type type) {
    if (type == Type::kReal) types_[name] = Type::kReal;
    types_.emplace(name, Type::kInteger);
  }

  std::string FixtureName(const NgcLine& line, std::string_view index) const {
    std::optional<double> k = ParseNumber(index);
    if (!k || *k < 0 || *k != std::floor(*k) || *k >= static_cast<double>(cell_.fixtures.size())) {
      Fail(line, "a fixture index that is not one of the data's fixtures");
    }
    return cell_.fixtures[static_cast<std::size_t>(*k)].name;
  }

  // (Cycle F src:L) ... (EndCycle F src:L)
  void Cycle(const NgcLine& line) {
    // The emitter writes a Cycle's blocks between these two comments; a
    // Cycle inside a Cycle is no program smtcal compiles.
    if (in_cycle_) Fail(line, "a Cycle inside a Cycle");
    const std::string name = line.comment.substr(6, line.comment.find(' ', 6) - 6);
    Emit("Cycle " + name, line.number);
    ++indent_;
    in_cycle_ = true;
    const std::string end = "EndCycle " + name + " ";
    Body([&](const NgcLine& l) { return l.comment_only && l.comment.starts_with(end); });
    in_cycle_ = false;
    --indent_;
    Emit("EndCycle", Next().number);
  }

  // oN do / M66 P<bit> L3|L4 Q3600 / oN while [#5399 LT 0]
  void WaitSwitch(const NgcLine& line) {
    const std::string o = line.block.substr(0, line.block.size() - 3);
    const NgcLine& wait = Next();
    const std::size_t l = wait.block.find(" L");
    if (!wait.block.starts_with("M66 P") || l == std::string::npos || wait.block.size() < l + 4) {
      Fail(wait, "a Wait Sw without its M66");
    }
    const std::string bit = Expression(wait, wait.block.substr(5, l - 5)).text;
    const char state = wait.block[l + 2];
    Expect(o + " while [#5399 LT 0]");
    Emit(fmt::format("Wait Sw({}) = {}", bit, state == '3' ? "On" : "Off"), line.number);
  }

  // oN if C / oN elseif C / oN else / oN endif
  void If(const NgcLine& line, std::uint32_t at) {
    const std::size_t space = line.block.find(' ');
    const std::string o = line.block.substr(0, space);
    Emit(fmt::format("If {} Then", Condition(line, line.block.substr(space + 4))), at);
    auto ends_branch = [&](const NgcLine& l) {
      return l.block.starts_with(o + " elseif ") || l.block == o + " else" || l.block == o + " endif";
    };
    ++indent_;
    Body(ends_branch);
    --indent_;
    while (true) {
      const NgcLine& next = Next();
      if (next.block == o + " endif") {
        Emit("EndIf", next.number);
        return;
      }
      if (next.block == o + " else") {
        Emit("Else", next.number);
      } else {
        Emit(fmt::format("ElseIf {} Then", Condition(next, next.block.substr(o.size() + 8))), next.number);
      }
      ++indent_;
      Body(ends_branch);
      --indent_;
    }
  }

  std::string Condition(const NgcLine& line, std::string_view text) {
    PExpr condition = Expression(line, text);
    if (condition.type != Type::kBoolean) Fail(line, "a condition that is not a comparison");
    return condition.text;
  }

  // #<t_forN_v> = from / #<t_forN_to> = to / [step and its check] / oN while C / VAR = #<t_forN_v>
  // ... / #<t_forN_v> = [#<t_forN_v> + S] / oN endwhile
  void For(const NgcLine& line) {
    const std::size_t eq = line.block.find("> = ");
    const std::string v = line.block.substr(0, eq + 1);  // #<t_forN_v>
    if (!v.ends_with("_v>")) Fail(line, "a For without its counter");
    const std::string base = v.substr(0, v.size() - 3);  // #<t_forN
    const std::string o = "o" + base.substr(7);
    PExpr from = Expression(line, line.block.substr(eq + 4));
    const NgcLine& to_line = Next();
    if (!to_line.block.starts_with(base + "_to> = ")) Fail(to_line, "a For without its bound");
    PExpr to = Expression(to_line, to_line.block.substr(base.size() + 7));
    std::optional<PExpr> step;
    if (Peek().block.starts_with(base + "_step> = ")) {
      const NgcLine& step_line = Next();
      step = Expression(step_line, step_line.block.substr(base.size() + 9));
      const NgcLine& check = Next();  // oM if [#<t_forN_step> EQ 0] / (abort) / oM endif
      const std::string m = check.block.substr(0, check.block.find(' '));
      if (check.block != fmt::format("{} if [{}_step> EQ 0]", m, base)) Fail(check, "a For step without its check");
      if (!Next().comment.starts_with("abort,")) Fail(lines_[at_ - 1], "a For step check without its abort");
      Expect(m + " endif");
    }
    const NgcLine& loop = Next();
    if (!loop.block.starts_with(o + " while ")) Fail(loop, "a For without its while");
    const NgcLine& var_line = Next();
    if (!var_line.block.ends_with(" = " + v)) Fail(var_line, "a For without its loop variable");
    const std::string var = VariableName(var_line, var_line.block.substr(0, var_line.block.find(' ')));
    Assigned(var, from.type == Type::kReal || to.type == Type::kReal || (step && step->type == Type::kReal)
                      ? Type::kReal
                      : Type::kInteger);
    std::string header = fmt::format("For {} = {} To {}", var, from.text, to.text);
    std::size_t header_at = out_.size();
    Emit(header, line.number);
    ++indent_;
    const std::string increment = fmt::format("{} = [{} + ", v, v);
    Body([&](const NgcLine& l) { return l.block.starts_with(increment); });
    --indent_;
    const NgcLine& next = Next();
    const std::string s = next.block.substr(increment.size(), next.block.size() - increment.size() - 1);
    if (!step && s != "1") step = Expression(next, s);
    if (step) {
      const std::string with_step = header + " Step " + step->text;
      out_.replace(header_at + static_cast<std::size_t>(indent_) * 2, header.size(), with_step);
    }
    Expect(o + " endwhile");
    Emit(fmt::format("Next {}", var), next.number);
  }

  // ---------------------------------------------------------------- motion

  // The target written as a .place point expression, from the position's
  // four expressions and the temporaries that computed them.
  std::string Target(const NgcLine& line, const std::array<GNode, 4>& xyzu, const Prepared& prepared,
                     std::uint32_t at) {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    // XY(...) as given.
    if (std::all_of(xyzu.begin(), xyzu.end(), [](const GNode& n) { return n.kind == GNode::Kind::kNumber; })) {
      if (!prepared.order.empty()) Fail(line, "temporaries before a literal position");
      return fmt::format("XY({}, {}, {}, {})", xyzu[0].text, xyzu[1].text, xyzu[2].text, xyzu[3].text);
    }
    // A point's parameters.
    if (std::string point = PointOf(xyzu); !point.empty()) {
      if (!prepared.order.empty()) Fail(line, "temporaries before a point's parameters");
      return point;
    }
    // Temporaries: a point or a pallet slot, then offsets.
    for (int a = 0; a < 4; ++a) {
      if (!IsParam(xyzu[a], fmt::format("t_{}", kAxes[a]))) Fail(line, "a position smtcal does not write");
    }
    std::array<GNode, 4> base;
    std::size_t k = 0;
    const std::vector<std::pair<std::string, GNode>>& order = prepared.order;
    std::string slot;
    if (!order.empty() && (order[0].first == "t_s" || order[0].first == "t_k")) {
      slot = PalletSlot(line, order, k, base, at);
    } else {
      for (int a = 0; a < 4; ++a, ++k) {
        if (k >= order.size() || order[k].first != fmt::format("t_{}", kAxes[a])) Fail(line, "a position smtcal does not write");
        base[static_cast<std::size_t>(a)] = order[k].second;
      }
      slot = PointOf(base);
      if (slot.empty()) Fail(line, "a position that is not a point");
    }
    std::string offsets;
    for (; k < order.size(); ++k) {
      // #<t_A> = [#<t_A> +|- term]
      const auto& [temp, value] = order[k];
      const int axis = temp.size() == 3 ? static_cast<int>(std::string_view("xyzu").find(temp[2])) : -1;
      if (axis < 0 || !(IsBinary(value, "+") || IsBinary(value, "-")) || !IsParam(value.operands[0], temp)) {
        Fail(line, "an offset smtcal does not write");
      }
      const PExpr amount = Decompile(line, value.operands[1]);
      offsets += fmt::format(" {} {}({})", value.ops[0], static_cast<char>(std::toupper(kAxes[axis])), amount.text);
    }
    return slot + offsets;
  }

  // "R1" when the four are #<_p_r1_x> ... #<_p_r1_u>, else "".
  std::string PointOf(const std::array<GNode, 4>& xyzu) const {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    std::string name;
    for (int a = 0; a < 4; ++a) {
      const GNode& n = xyzu[static_cast<std::size_t>(a)];
      if (n.kind != GNode::Kind::kParam || !n.text.starts_with("_p_") || n.text.size() < 6 ||
          n.text[n.text.size() - 2] != '_' || n.text.back() != kAxes[static_cast<std::size_t>(a)]) {
        return "";
      }
      const std::string p = n.text.substr(3, n.text.size() - 5);
      if (a > 0 && p != name) return "";
      name = p;
    }
    auto it = point_names_.find(name);
    return it != point_names_.end() ? it->second : "";
  }

  // Pallet(n, i, j) or Pallet(n, k) from the emitter's formula
  // (linuxcnc_emit.cpp, PalletSlot): [#<t_k> = [K - 1]], #<t_s> = ..., #<t_t> = ...,
  // #<t_A> = [P1 + [#<t_s> * [P2 - P1]] + [#<t_t> * [P3 - P1]]] for each axis.
  std::string PalletSlot(const NgcLine& line, const std::vector<std::pair<std::string, GNode>>& order,
                         std::size_t& k, std::array<GNode, 4>& base, std::uint32_t at) {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    std::optional<GNode> count;
    if (order[k].first == "t_k") {
      const GNode& value = order[k++].second;
      if (!IsBinary(value, "-") || !IsNumber(value.operands[1], "1")) Fail(line, "a pallet count smtcal does not write");
      count = value.operands[0];
    }
    if (k + 6 > order.size() || order[k].first != "t_s" || order[k + 1].first != "t_t") {
      Fail(line, "a pallet slot smtcal does not write");
    }
    // [[INDEX - 1] / (n - 1)] or 0.
    auto index = [&](const GNode& value, int& n, std::optional<GNode>& of) {
      if (IsNumber(value, "0")) {
        n = 1;
        return;
      }
      if (!IsBinary(value, "/") || value.operands[1].kind != GNode::Kind::kNumber || !IsBinary(value.operands[0], "-") ||
          !IsNumber(value.operands[0].operands[1], "1")) {
        Fail(line, "a pallet slot smtcal does not write");
      }
      n = static_cast<int>(*ParseNumber(value.operands[1].text)) + 1;
      of = value.operands[0].operands[0];
    };
    int columns = 1, rows = 1;
    std::optional<GNode> column, row;
    index(order[k].second, columns, column);
    index(order[k + 1].second, rows, row);
    k += 2;
    std::array<std::string, 3> corners;
    for (int a = 0; a < 4; ++a, ++k) {
      const auto& [temp, value] = order[k];
      if (temp != fmt::format("t_{}", kAxes[a]) || value.kind != GNode::Kind::kGroup || value.ops.size() != 2) {
        Fail(line, "a pallet slot smtcal does not write");
      }
      // [P1 + [#<t_s> * [P2 - P1]] + [#<t_t> * [P3 - P1]]]
      std::array<std::string, 3> names;
      auto corner = [&](const GNode& n) -> std::string {
        const std::string suffix = fmt::format("_{}", kAxes[a]);
        if (n.kind != GNode::Kind::kParam || !n.text.starts_with("_p_") || !n.text.ends_with(suffix)) {
          Fail(line, "a pallet corner that is not a point");
        }
        return n.text.substr(3, n.text.size() - 5);
      };
      names[0] = corner(value.operands[0]);
      for (int c = 1; c <= 2; ++c) {
        const GNode& term = value.operands[static_cast<std::size_t>(c)];
        if (!IsBinary(term, "*") || !IsParam(term.operands[0], c == 1 ? "t_s" : "t_t") ||
            !IsBinary(term.operands[1], "-")) {
          Fail(line, "a pallet slot smtcal does not write");
        }
        names[static_cast<std::size_t>(c)] = corner(term.operands[1].operands[0]);
      }
      if (a == 0) corners = names;
      if (names != corners) Fail(line, "a pallet slot with two sets of corners");
      base[static_cast<std::size_t>(a)] = GNode{GNode::Kind::kParam, fmt::format("_p_{}_{}", names[0], kAxes[a]), {}, {}};
    }
    for (std::string& corner : corners) {
      auto it = point_names_.find(corner);
      if (it == point_names_.end()) Fail(line, "a pallet corner that is not a point");
      corner = it->second;
    }
    const std::string decl = fmt::format("{}, {}, {}, {}, {}", corners[0], corners[1], corners[2], columns, rows);
    auto found = std::find(pallets_.begin(), pallets_.end(), decl);
    if (found == pallets_.end()) {
      pallets_.push_back(decl);
      pallet_lines_.push_back(at);
      found = pallets_.end() - 1;
    }
    const std::size_t number = static_cast<std::size_t>(found - pallets_.begin()) + 1;
    if (count) return fmt::format("Pallet({}, {})", number, Decompile(line, *count).text);
    return fmt::format("Pallet({}, {}, {})", number, column ? Decompile(line, *column).text : "1",
                       row ? Decompile(line, *row).text : "1");
  }

  // The arguments of `o<name> call [a] [b] ...`.
  std::vector<GNode> CallArguments(const NgcLine& line, std::string_view text) const {
    std::vector<GNode> arguments;
    GParser parser(text);
    while (!parser.AtEnd()) {
      std::optional<GNode> argument = parser.Expr();
      if (!argument || argument->kind != GNode::Kind::kGroup || argument->operands.size() != 1 ||
          !argument->ops.empty()) {
        Fail(line, "a call argument smtcal does not write");
      }
      arguments.push_back(std::move(argument->operands[0]));
    }
    return arguments;
  }

  // o<pick_place> call [k] [x] [y] [z] [u] [LimZ] [vacuum] [1|0] [line]
  void PickPlace(const NgcLine& line, const Prepared& prepared, std::uint32_t at) {
    std::vector<GNode> arguments = CallArguments(line, std::string_view(line.block).substr(19));
    if (arguments.size() != 9) Fail(line, "o<pick_place> with other than nine arguments");
    const int command = CommandArgument(line, arguments[0]);
    const std::string target = Target(line, {arguments[1], arguments[2], arguments[3], arguments[4]}, prepared, at);
    if (!IsNumber(arguments[7], "1") && !IsNumber(arguments[7], "0")) Fail(line, "o<pick_place> neither a Pick nor a Place");
    std::string text = fmt::format("{} {}", IsNumber(arguments[7], "1") ? "Pick" : "Place", target);
    const std::string vacuum = Decompile(line, arguments[6]).text;
    if (!vacuum_) {
      vacuum_ = vacuum;
      vacuum_line_ = line.number;
    }
    if (vacuum != *vacuum_) text += " Vacuum " + vacuum;
    text += LimZ(line, arguments[5]);
    // The source line the abort names: the line the emitter wrote the call from.
    if (arguments[8].kind != GNode::Kind::kNumber) Fail(line, "o<pick_place> without its source line");
    if (pick_place_used_ == 0) pick_place_used_ = line.number;
    Emit(text, at, command);
  }

  // " LimZ z", or "" for the cell's safe z (what a Pick, Place or Jump without one rises to).
  std::string LimZ(const NgcLine& line, const GNode& z) {
    if (z.kind == GNode::Kind::kNumber && ParseNumber(z.text) == safe_z_) return "";
    return " LimZ " + Decompile(line, z).text;
  }

  // The first argument of o<pick_place> and o<smtcal_correct>: how the
  // runtime commands the position (linuxcnc_layout.h): a fixture of the
  // data, kCommandBase or kCommandAsWritten. Held against the traced
  // program by CheckLinuxCncCommands.
  int CommandArgument(const NgcLine& line, const GNode& k) const {
    std::optional<double> index = k.kind == GNode::Kind::kNumber ? ParseNumber(k.text) : std::nullopt;
    if (!index || *index < L::kCommandAsWritten || *index != std::floor(*index) ||
        *index >= static_cast<double>(cell_.fixtures.size())) {
      Fail(line, "a correction argument that is neither a fixture of the data nor -1 or -2");
    }
    return static_cast<int>(*index);
  }

  // The letters of a move: exactly `letters` (G and the axes), the rotation
  // on the program's axis.
  void Letters(const NgcLine& line, const std::map<char, GNode>& words, std::string_view letters) {
    std::string have;
    for (const auto& [letter, value] : words) {
      if (letter == 'A' || letter == 'B' || letter == 'C') {
        Axis(line, letter);
        have += 'R';
      } else {
        have += letter;
      }
    }
    std::string want(letters);
    std::sort(want.begin(), want.end());
    std::sort(have.begin(), have.end());
    if (have != want) Fail(line, "a move with other words than smtcal writes");
  }

  // [o<smtcal_correct> call [k] [x] [y]] then G0 Z / G0 X Y A / G0 Z (Jump;
  // with a final approach G0 Z / G0 X[x - a] Y[y - b] A / G0 X Y / G0 Z),
  // G0 X Y Z A (Go), G1 X Y Z A F (Move).
  void Motion(const NgcLine& first, const Prepared& prepared, std::uint32_t at) {
    const NgcLine* line = &first;
    std::optional<std::array<GNode, 2>> corrected;
    int command = L::kCommandAsWritten;
    if (first.block.starts_with("o<smtcal_correct> call ")) {
      std::vector<GNode> arguments = CallArguments(first, std::string_view(first.block).substr(23));
      if (arguments.size() != 3) Fail(first, "o<smtcal_correct> with other than three arguments");
      command = CommandArgument(first, arguments[0]);
      if (command == L::kCommandAsWritten) Fail(first, "o<smtcal_correct> told to command a position as given");
      corrected = std::array<GNode, 2>{arguments[1], arguments[2]};
      line = &Next();
    }
    std::map<char, GNode> words = Words(*line);
    std::string keyword;
    std::string limz;
    if (line->block.starts_with("G0 Z") && words.size() == 2) {  // Jump: up, across, down
      keyword = "Jump";
      limz = LimZ(*line, words.at('Z'));
      const NgcLine& across = Next();
      words = Words(across);
      if (!across.block.starts_with("G0 ")) Fail(across, "a Jump whose move across is not G0");
      Letters(across, words, "GXYR");
      if (IsBinary(words.at('X'), "-") || IsBinary(words.at('Y'), "-")) {  // the final approach, then onto the target
        const GNode& x = words.at('X');
        const GNode& y = words.at('Y');
        const NgcLine& onto = Next();
        std::map<char, GNode> last = Words(onto);
        if (!onto.block.starts_with("G0 ")) Fail(onto, "a Jump whose final approach is not G0");
        Letters(onto, last, "GXY");
        if (!IsBinary(x, "-") || !IsBinary(y, "-") || x.operands[1].kind != GNode::Kind::kNumber ||
            y.operands[1].kind != GNode::Kind::kNumber || !Same(x.operands[0], last.at('X')) ||
            !Same(y.operands[0], last.at('Y'))) {
          Fail(across, "a Jump's final approach that is not smtcal's");
        }
        Approach(across, Eigen::Vector2d(*ParseNumber(x.operands[1].text), *ParseNumber(y.operands[1].text)));
        words['X'] = last.at('X');
        words['Y'] = last.at('Y');
      } else {
        Approach(across, std::nullopt);
      }
      const NgcLine& down = Next();
      std::map<char, GNode> z = Words(down);
      if (!down.block.starts_with("G0 Z") || z.size() != 2) Fail(down, "a Jump without its descent");
      words['Z'] = z.at('Z');
    } else if (line->block.starts_with("G1 ")) {
      keyword = "Move";
      Letters(*line, words, "GXYZRF");
      std::optional<double> feed = words.at('F').kind == GNode::Kind::kNumber ? ParseNumber(words.at('F').text) : std::nullopt;
      if (!feed || !(*feed > 0) || (wiring_.move_feed && *wiring_.move_feed != *feed)) {
        Fail(*line, "a Move at another feed than the program's others (the robot's xy_speed_mm_s)");
      }
      wiring_.move_feed = *feed;
    } else {
      keyword = "Go";
      Letters(*line, words, "GXYZR");
    }
    const char rotation = words.count('A') ? 'A' : words.count('B') ? 'B' : 'C';
    std::array<GNode, 4> xyzu = {words.at('X'), words.at('Y'), words.at('Z'), words.at(rotation)};
    if (corrected) {
      if (!IsParam(xyzu[0], "_smtcal_x") || !IsParam(xyzu[1], "_smtcal_y")) Fail(*line, "a corrected move without the correction");
      xyzu[0] = (*corrected)[0];
      xyzu[1] = (*corrected)[1];
    }
    // A fixture's rotation is added to u, [u + #<_smtcal_angle>], exactly
    // when the runtime corrects the position through a fixture.
    const bool turned = IsBinary(xyzu[3], "+") && IsParam(xyzu[3].operands[1], "_smtcal_angle");
    if (turned != (command >= 0)) {
      Fail(*line, command >= 0 ? "a move through a fixture whose u does not turn with the board"
                               : "a move whose u turns with a board it is not corrected through");
    }
    if (turned) {
      GNode u = xyzu[3].operands[0];
      xyzu[3] = std::move(u);
    }
    Emit(fmt::format("{} {}{}", keyword, Target(*line, xyzu, prepared, at), limz), at, command);
  }

  // The words of a G0/G1 block: letter -> value.
  std::map<char, GNode> Words(const NgcLine& line) const {
    std::map<char, GNode> words;
    std::string_view text = line.block;
    if (!(text.starts_with("G0 ") || text.starts_with("G1 "))) Fail(line, "expected a G0 or G1 move");
    std::size_t at = 3;
    words['G'] = GNode{GNode::Kind::kNumber, std::string(1, text[1]), {}, {}};
    while (at < text.size()) {
      while (at < text.size() && text[at] == ' ') ++at;
      if (at >= text.size()) break;
      const char letter = text[at++];
      GParser parser(text.substr(at));
      std::optional<GNode> value = parser.Expr();
      if (!value || !std::isupper(static_cast<unsigned char>(letter)) || words.count(letter)) {
        Fail(line, "a move word smtcal does not write");
      }
      words[letter] = std::move(*value);
      at += parser.position();
    }
    return words;
  }

  // ---------------------------------------------------------------- expressions

  PExpr Expression(const NgcLine& line, std::string_view text) {
    bool too_deep = false;
    std::optional<GNode> node = ParseGExpr(text, &too_deep);
    if (too_deep) Fail(line, fmt::format("brackets nested more than {} deep", kMaxNesting));
    if (!node) Fail(line, "an expression smtcal does not write");
    return Decompile(line, *node);
  }

  // The .place expression the emitter lowered to `node`.
  PExpr Decompile(const NgcLine& line, const GNode& node) {
    switch (node.kind) {
      case GNode::Kind::kNumber:
        return {node.text.starts_with('-') ? "(" + node.text + ")" : node.text,
                node.text.find('.') != std::string::npos ? Type::kReal : Type::kInteger};
      case GNode::Kind::kParam: {
        if (node.text.starts_with("v_") || node.text.starts_with("_v_")) {
          const std::string name = node.text.substr(node.text.find("v_") + 2);
          auto it = types_.find(name);
          return {name, it != types_.end() ? it->second : Type::kInteger};
        }
        if (auto it = switches_.find(node.text); it != switches_.end()) {
          return {fmt::format("Sw({})", Decompile(line, it->second).text), Type::kBoolean};
        }
        Fail(line, fmt::format("parameter #<{}> where an expression belongs", node.text));
      }
      case GNode::Kind::kCall: Fail(line, fmt::format("{}[...] where smtcal writes none", node.text));
      case GNode::Kind::kGroup: break;
    }
    if (node.ops.empty()) return Decompile(line, node.operands[0]);
    if (node.ops.size() != 1) Fail(line, "an expression smtcal does not write");
    const GNode& a = node.operands[0];
    const GNode& b = node.operands[1];
    const std::string& op = node.ops[0];
    // a Mod b: [[ABS[a] MOD ABS[b]] * [[[a GE 0] * 2] - 1]]
    if (op == "*" && IsBinary(a, "MOD") && a.operands[0].kind == GNode::Kind::kCall &&
        a.operands[0].text == "ABS" && a.operands[1].kind == GNode::Kind::kCall && a.operands[1].text == "ABS") {
      const PExpr x = Decompile(line, a.operands[0].operands[0]), y = Decompile(line, a.operands[1].operands[0]);
      return {fmt::format("({} Mod {})", x.text, y.text), Type::kInteger};
    }
    // a = b: [[a LE b] AND [a GE b]]; a <> b: [[a LT b] OR [a GT b]]
    if ((op == "AND" && IsBinary(a, "LE") && IsBinary(b, "GE")) || (op == "OR" && IsBinary(a, "LT") && IsBinary(b, "GT"))) {
      if (Same(a.operands[0], b.operands[0]) && Same(a.operands[1], b.operands[1])) {
        PExpr x = Decompile(line, a.operands[0]), y = Decompile(line, a.operands[1]);
        BooleanLiteral(x, y);
        return {fmt::format("({} {} {})", x.text, op == "AND" ? "=" : "<>", y.text), Type::kBoolean};
      }
    }
    PExpr x = Decompile(line, a), y = Decompile(line, b);
    if (op == "EQ" && IsNumber(b, "0") && x.type == Type::kBoolean) return {fmt::format("(Not {})", x.text), Type::kBoolean};
    static const std::map<std::string, std::string> kCompare = {{"LT", "<"}, {"GT", ">"}, {"LE", "<="}, {"GE", ">="}};
    if (auto it = kCompare.find(op); it != kCompare.end()) {
      return {fmt::format("({} {} {})", x.text, it->second, y.text), Type::kBoolean};
    }
    if (op == "AND" || op == "OR" || op == "XOR") {
      BooleanLiteral(x, y);
      const std::string word = op == "AND" ? "And" : op == "OR" ? "Or" : "Xor";
      return {fmt::format("({} {} {})", x.text, word, y.text), x.type};
    }
    if (op == "+" || op == "-" || op == "*" || op == "/") {
      const Type type = op == "/" || x.type == Type::kReal || y.type == Type::kReal ? Type::kReal : Type::kInteger;
      return {fmt::format("({} {} {})", x.text, op, y.text), type};
    }
    Fail(line, fmt::format("the operator {} where smtcal writes none", op));
  }

  // On and Off are 1 and 0 in G-code: beside a Boolean they are written back as such.
  static void BooleanLiteral(PExpr& x, PExpr& y) {
    auto to_boolean = [](PExpr& e) {
      if (e.type != Type::kBoolean && (e.text == "1" || e.text == "0")) e = {e.text == "1" ? "On" : "Off", Type::kBoolean};
    };
    if (x.type == Type::kBoolean) to_boolean(y);
    if (y.type == Type::kBoolean) to_boolean(x);
  }

  const cell::Cell& cell_;
  double safe_z_;
  std::string program_name_;
  std::vector<NgcLine> lines_;
  std::size_t at_ = 0;
  int indent_ = 0;
  std::string out_;
  std::vector<std::uint32_t> map_;
  std::map<std::string, std::string> point_names_;  // parameter name -> point name
  std::map<std::string, std::string> point_roots_;
  std::map<std::string, GNode> switches_;           // t_swK -> its bit
  std::map<std::string, Type> types_;               // variables, as inferred so far
  std::set<std::string> assigned_real_;
  std::vector<std::string> pallets_;                // "C1, C2, C3, columns, rows", numbered from 1
  std::vector<std::uint32_t> pallet_lines_;
  std::optional<std::string> vacuum_;
  std::uint32_t vacuum_line_ = 0;
  std::vector<int> commands_;     // per line of out_: how its motion is commanded
  int depth_ = 0;                 // blocks open
  bool in_cycle_ = false;
  Wiring wiring_;
  bool pick_place_sub_ = false;         // o<pick_place> is defined
  std::uint32_t pick_place_used_ = 0;   // the first line that calls it, or 0
  long runtime_id_ = -1;
  std::uint32_t runtime_id_line_ = 0;
};

std::string ProgramNameOf(const std::string& main_path) {
  std::string stem = fs::path(main_path).stem().string();
  std::string name;
  for (char c : stem) name += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (name.empty() || !std::isalpha(static_cast<unsigned char>(name.front()))) name = "P" + name;
  return name;
}

}  // namespace

bool LooksLikeLinuxCncOutput(const std::string& path) {
  std::error_code error;
  return fs::is_directory(path, error) || fs::path(path).extension() == ".ngc";
}


namespace {

// The files the emitter writes into the runtime folder for a cell (besides
// the runtime's own, LinuxCncRuntimeFiles).
constexpr std::string_view kDataFile = "smtcal_data.ngc";
constexpr std::string_view kScanAbortFile = "smtcal_scan_abort.ngc";
constexpr std::string_view kRecordFile = "smtcal_record.ngc";
constexpr std::string_view kRecordOpenFile = "smtcal_record_open.ngc";

// Every file the runtime folder must hold.
std::vector<std::string> RuntimeFolderFiles() {
  std::vector<std::string> names = {std::string(kDataFile), std::string(kScanAbortFile), std::string(kRecordFile),
                                    std::string(kRecordOpenFile)};
  for (const EmbeddedFile& file : LinuxCncRuntimeFiles()) names.push_back(file.name);
  return names;
}

// A text without the line that starts with `prefix` (the runtime id's).
std::string WithoutLine(std::string_view text, std::string_view prefix) {
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    end = end == std::string_view::npos ? text.size() : end + 1;
    const std::string_view line = text.substr(at, end - at);
    if (!line.starts_with(prefix)) out += line;
    at = end;
  }
  return out;
}

// How a position is commanded, for messages.
std::string CommandText(int command, const cell::Cell& cell) {
  if (command == linuxcnc_layout::kCommandAsWritten) return "as given";
  if (command == linuxcnc_layout::kCommandBase) return "as a base position through the error tables";
  if (command >= 0 && static_cast<std::size_t>(command) < cell.fixtures.size()) {
    return fmt::format("through fixture {}'s pose", cell.fixtures[static_cast<std::size_t>(command)].name);
  }
  return fmt::format("with {}", command);
}

}  // namespace

Result<std::optional<LinuxCncOutputRead>> ReadLinuxCncOutput(const std::string& path, SourceManager& sources,
                                                             Diagnostics& diags) {
  // The directory and its main program: the one .ngc file in it.
  std::error_code error;
  fs::path dir = path, main;
  if (fs::is_directory(path, error)) {
    for (const fs::directory_entry& entry : fs::directory_iterator(path, error)) {
      if (entry.path().extension() != ".ngc" || !entry.is_regular_file()) continue;
      if (!main.empty()) {
        return Error{fmt::format("'{}' holds more than one .ngc file ({} and {}); name the main program",
                                 path, main.filename().string(), entry.path().filename().string())};
      }
      main = entry.path();
    }
    if (main.empty()) return Error{fmt::format("'{}' holds no main program (.ngc)", path)};
  } else {
    main = path;
    dir = main.parent_path();
  }
  LinuxCncFolderFiles folder;
  Result<std::uint32_t> main_file = sources.Load(main.generic_string());
  if (!main_file) return main_file.error();
  folder.main = main_file.value();
  folder.subroutines_dir = (dir / "subroutines").generic_string();
  for (const std::string& name : RuntimeFolderFiles()) {
    Result<std::uint32_t> file = sources.Load((dir / "subroutines" / name).generic_string());
    if (!file) {
      return Error{fmt::format("{} (a LinuxCNC output holds its runtime in subroutines/, every file smtcal writes "
                               "there: compile the program again)",
                               file.error().message)};
    }
    folder.subroutines.emplace_back(name, file.value());
  }
  return ReadLinuxCncFolder(folder, sources, diags);
}

Result<std::optional<LinuxCncOutputRead>> ReadLinuxCncFolder(const LinuxCncFolderFiles& folder, SourceManager& sources,
                                                             Diagnostics& diags) {
  std::map<std::string, std::uint32_t, std::less<>> files(folder.subroutines.begin(), folder.subroutines.end());
  for (const std::string& name : RuntimeFolderFiles()) {
    if (!files.contains(name)) {
      return Error{fmt::format("{}/{}: missing (a LinuxCNC output holds its runtime in subroutines/, every file smtcal "
                               "writes there: compile the program again)",
                               folder.subroutines_dir, name)};
    }
  }
  auto file_of = [&](std::string_view name) -> const SourceFile& { return sources.File(files.find(name)->second); };
  auto report = [&](std::uint32_t file, const ReadError& failure) {
    diags.Report(DiagKind::LinuxCncOutputUnreadable, SourceRange(SourceLoc{file, failure.line, 1}), failure.what);
  };
  auto report_in = [&](std::string_view name, const ReadError& failure) { report(files.find(name)->second, failure); };
  const std::optional<LinuxCncOutputRead> none;
  LinuxCncOutputRead read;
  read.main_file = folder.main;
  read.main_path = sources.File(folder.main).name;
  read.data_path = file_of(kDataFile).name;

  // The data, decoded.
  DataReader data(file_of(kDataFile));
  if (std::optional<ReadError> failure = data.Read(read.cell)) {
    report_in(kDataFile, *failure);
    return none;
  }
  if (read.cell.path.empty()) read.cell.path = read.data_path;
  // The runtime's own files: this smtcal's.
  for (const EmbeddedFile& runtime : LinuxCncRuntimeFiles()) {
    if (std::optional<ReadError> differs = FirstDifference(file_of(runtime.name), runtime.text, false)) {
      differs->what = fmt::format("the runtime is not this smtcal's (runtime/linuxcnc/{}): {}", runtime.name, differs->what);
      report_in(runtime.name, *differs);
      return none;
    }
  }
  // The files written for the cell: what the emitter writes for the cell decoded.
  read.cell.linuxcnc.emplace();
  DecodeRecord(file_of(kRecordOpenFile), file_of(kRecordFile), *read.cell.linuxcnc);
  if (std::optional<std::string> problem = LinuxCncRecordProblem(read.cell)) {
    report_in(kRecordOpenFile, {1, *problem});
    return none;
  }
  for (const auto& [name, text] : {std::pair{kScanAbortFile, EmitLinuxCncScanAbort(read.cell)},
                                   std::pair{kRecordFile, EmitLinuxCncRecord(read.cell)},
                                   std::pair{kRecordOpenFile, EmitLinuxCncRecordOpen(read.cell)}}) {
    if (std::optional<ReadError> differs = FirstDifference(file_of(name), text, false)) {
      report_in(name, *differs);
      return none;
    }
  }
  // The data as the emitter writes it for what was decoded: every line the
  // runtime reads, up to the rounding of the geometry decoded.
  if (std::optional<std::string> problem = LinuxCncDataProblem(read.cell)) {
    report_in(kDataFile, {1, *problem});
    return none;
  }
  const std::string_view id_prefix = L::kRuntimeIdParameter;
  if (std::optional<ReadError> differs =
          FirstDifference(file_of(kDataFile), EmitLinuxCncData(read.cell), /*rounding=*/true, id_prefix)) {
    report_in(kDataFile, *differs);
    return none;
  }
  // The runtime id: the one its files give, so no byte of them changed.
  if (data.id_line() == 0) {
    report_in(kDataFile, {1, fmt::format("no {} line", id_prefix)});
    return none;
  }
  const long id = LinuxCncRuntimeIdOf(SMTCAL_VERSION, WithoutLine(file_of(kDataFile).text, id_prefix),
                                      file_of(kScanAbortFile).text, file_of(kRecordFile).text,
                                      file_of(kRecordOpenFile).text);
  if (id != data.id()) {
    report_in(kDataFile, {data.id_line(), fmt::format("it records runtime id {}, and the text of the runtime's files "
                                                      "gives {}: a line of them was changed after smtcal wrote them",
                                                      data.id(), id)});
    return none;
  }

  // The main program.
  Decompiler decompiler(sources.File(folder.main), read.cell, read.cell.robot.safe_limz_mm,
                        ProgramNameOf(read.main_path));
  std::string text;
  if (std::optional<ReadError> failure = decompiler.Run(text, read.line_map, read.commands)) {
    report(folder.main, *failure);
    return none;
  }
  if (decompiler.runtime_id() != data.id()) {
    report(folder.main, {decompiler.runtime_id_line(),
                         fmt::format("it checks for runtime id {}, and its runtime's is {}", decompiler.runtime_id(), data.id())});
    return none;
  }
  const auto& wiring = decompiler.wiring();
  cell::LinuxCnc& linuxcnc = *read.cell.linuxcnc;
  if (wiring.axis) linuxcnc.rotation_axis = *wiring.axis;
  if (wiring.vacuum_sensor) linuxcnc.vacuum_sensor_input = *wiring.vacuum_sensor;
  if (wiring.vacuum_timeout_s) linuxcnc.vacuum_timeout_s = *wiring.vacuum_timeout_s;
  read.cell.robot.final_approach_mm = wiring.approach;
  if (wiring.move_feed) read.cell.robot.xy_speed_mm_s = *wiring.move_feed / 60;
  // The .place program it lowers; the caller parses and checks it.
  read.place_file = sources.Add(read.main_path, std::move(text));
  return std::optional<LinuxCncOutputRead>(std::move(read));
}

void CheckLinuxCncCommands(const ir::Program& program, const MachineTargets& targets, const LinuxCncOutputRead& read,
                           Diagnostics& diags) {
  const sema::SymbolTable& symbols = sema::SymbolsOf(program);
  // The cell's index of the fixture a target hangs on, or kCommandBase.
  auto fixture_of = [&](const ir::PointExpr& point) {
    const sema::Symbol* fixture = nullptr;
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      if (const sema::Symbol* symbol = symbols.Find(*named)) fixture = symbols.FixtureOfPoint(*symbol);
    } else if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      if (std::optional<int> number = sema::FoldInteger(pallet->number.get())) fixture = symbols.FixtureOfPallet(*number);
    }
    const cell::Fixture* in_cell = fixture != nullptr ? read.cell.FindFixture(fixture->name) : nullptr;
    return in_cell != nullptr ? static_cast<int>(in_cell - read.cell.fixtures.data()) : L::kCommandBase;
  };
  ir::ForEachStmt(program.items, [&](const ir::Stmt& stmt) {
    const ir::PointExpr* target = nullptr;
    if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) target = &motion->target;
    if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) target = &pick->target;
    if (target == nullptr || stmt.loc.file != read.place_file) return;
    const std::uint32_t line = stmt.loc.line;
    SMTCAL_CHECK(line >= 1 && line <= read.commands.size(), "every line of the text read back has its command");
    const int given = read.commands[line - 1];
    SMTCAL_CHECK(given != kNoLinuxCncCommand, "the reader wrote a motion only from a line that commands it");
    // What the program's text makes of it: the traced positions' kind; a
    // statement the compile-time run never reached is corrected on the
    // controller, through its fixture when it has one (as the emitter does).
    int expected = fixture_of(*target);
    const std::span<const MachineTarget> positions = targets.Of(&stmt);
    if (!positions.empty()) {
      const MachineTarget& first = positions.front();
      expected = first.kind == MachineTarget::Kind::kFixture   ? first.fixture
                 : first.kind == MachineTarget::Kind::kRunTime ? L::kCommandBase
                                                               : L::kCommandAsWritten;
    }
    if (given == expected) return;
    diags.Report(DiagKind::LinuxCncOutputUnreadable,
                 SourceRange(SourceLoc{read.main_file, read.line_map[line - 1], 1}),
                 fmt::format("the runtime is told to command this position {}, and the program's text {}",
                             CommandText(given, read.cell), CommandText(expected, read.cell)));
  });
}

}  // namespace smtcal

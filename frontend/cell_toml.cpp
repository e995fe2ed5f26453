// Loading a cell file (`*.cell.toml`, docs/cell.md) into a cell::Cell.
//
// toml++ parses the text; everything after that is ours: each TOML table is
// read through a Keys object that knows which keys were asked for, so a key
// nobody asked for is reported as unknown (with "did you mean"). Every value
// is checked where it is read (type, unit, range) and reported at its own
// line and column; reading goes on after a mistake, so one run reports all
// of them. Checks that combine several values (marker geometry, scan trips,
// region overlap, robot limits) run only on the parts that were read cleanly,
// so one typo does not cascade into a page of follow-up errors.
#include "frontend/cell_toml.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "base/check.h"
#include "base/field_text.h"
#include "base/sha256.h"
#include "calibration/error_table_check.h"
#include "calibration/fixture_geometry.h"
#include "calibration/limits.h"
#include "calibration/placement_budget.h"
#include "calibration/region_fit.h"
#include "calibration/scan_plan.h"
#include "calibration/tolerances.h"
#include "calibration/truth_spec.h"
#include "frontend/input_kind.h"
#include "frontend/table_csv.h"
#include "frontend/toml_source.h"

namespace smtcal::cell {
namespace {

constexpr std::array<std::string_view, 4> kEdgeNames = {"p1", "p2", "p3", "p4"};
// The robot's limits, in the order of Robot::limits.
constexpr std::array<std::string_view, 4> kLimitKeys = {"x_mm", "y_mm", "z_mm", "u_deg"};
constexpr std::array<std::string_view, 4> kLimitUnits = {"mm", "mm", "mm", "deg"};
constexpr std::array<NumberRange, 4> kLimitRanges = {limits::kPositionMm, limits::kPositionMm, limits::kPositionMm,
                                                    limits::kAngleDeg};
// The axis words [linuxcnc] rotation_axis may name.
constexpr std::array<std::string_view, 3> kRotationAxisNames = {"A", "B", "C"};

bool SameName(std::string_view a, std::string_view b) { return AsciiLowercase(a) == AsciiLowercase(b); }

// Numbers in messages: the shortest form that reads back (0.1, 190, -2.5e-07).
std::string Num(double value) { return fmt::format("{}", value); }

std::string Choices(const auto& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += i == 0 ? "" : i + 1 == names.size() ? " or " : ", ";
    text += fmt::format("'{}'", names[i]);
  }
  return text;
}

std::string DidYouMean(std::string_view name, const std::vector<std::string>& candidates) {
  std::string closest = ClosestName(name, candidates);
  return closest.empty() ? "" : fmt::format("; did you mean '{}'?", closest);
}

// What a node is, for "found ...".
std::string Describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return fmt::format("the string \"{}\"", Printable(*node.value<std::string>()));
    case toml::node_type::integer: return fmt::format("the integer {}", *node.value<std::int64_t>());
    case toml::node_type::floating_point: {
      // 2.0 stays 2.0: "found 2" would not say why a whole number was refused.
      double value = *node.value<double>();
      return fmt::format("the float {}", value == std::trunc(value) && std::isfinite(value)
                                             ? fmt::format("{:.1f}", value)
                                             : fmt::format("{}", value));
    }
    case toml::node_type::boolean: return *node.value<bool>() ? "true" : "false";
    case toml::node_type::table: return "a table";
    case toml::node_type::array: {
      std::size_t size = node.as_array()->size();
      return size == 0 ? "an empty array" : fmt::format("an array of {}", size);
    }
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

enum class Need { kRequired, kOptional };

// A value read from the file and where it was written.
template <typename T>
struct Located {
  T value;
  SourceRange range;
};

class Loader;

// One TOML table being read. Every lookup names a key the table may hold;
// Finish() reports the keys no lookup asked for.
class Keys {
 public:
  // `range` is where the table is written (the whole file for the root).
  Keys(Loader& loader, const toml::table& table, std::string what, SourceRange range)
      : loader_(loader), table_(table), what_(std::move(what)), range_(range) {}
  Keys(const Keys&) = delete;
  Keys& operator=(const Keys&) = delete;

  // The node of `key`, or nullptr when the table does not have it.
  const toml::node* Get(std::string_view key) {
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.emplace_back(key);
    return table_.get(key);
  }
  // Where `key` is written; the table itself when it is not there.
  SourceRange KeyRange(std::string_view key) const;
  SourceRange TableRange() const { return range_; }
  // The table as messages name it: "[robot]", "region 'layer1'", ...
  const std::string& what() const { return what_; }
  void set_what(std::string what) { what_ = std::move(what); }
  Loader& loader() { return loader_; }
  void Finish();

 private:
  Loader& loader_;
  const toml::table& table_;
  std::string what_;
  SourceRange range_;
  std::vector<std::string> known_;
};

class Loader {
 public:
  Loader(SourceManager& sources, Diagnostics& diags, std::uint32_t file, std::filesystem::path dir,
         CellLoadOptions options)
      : sources_(sources), diags_(diags), file_(file), dir_(std::move(dir)), options_(options),
        locator_(sources, file) {}

  Diagnostics& diags() { return diags_; }

  SourceLoc At(const toml::source_position& position) const { return locator_.At(position); }
  SourceRange Range(const toml::source_region& region) const { return locator_.Range(region); }
  SourceRange Range(const toml::node& node) const { return locator_.Range(node); }
  SourceRange WholeFile() const { return SourceRange(SourceLoc{file_, 0, 0}); }

  std::optional<Cell> Load(const toml::table& root, const std::string& path);

 private:
  struct LoadedTable {
    std::optional<std::string> io_error;  // the file could not be read
    bool missing = false;                 // ... because it does not exist
    bool ok = false;                      // read and valid
    ErrorTable table;
    std::uint32_t file = 0;               // its SourceManager id, when read
  };
  using Names = std::vector<Located<std::string>>;

  // Each Read* reports what is wrong in its part and returns nullopt (or
  // false) when it reported an error; names are collected even then, so a
  // duplicate is found whatever else is wrong.
  void ReadRobot(const toml::table& table, Robot& robot);
  std::optional<Region> ReadRegion(const toml::table& table, int index, Names& names);
  bool ReadDifficulty(Keys& keys, Region& region);
  const LoadedTable& LoadTable(const std::string& table_path);
  std::optional<Fixture> ReadFixture(const toml::table& table, int index, Names& names);
  bool ReadEdges(Keys& keys, Fixture& fixture);
  bool ReadScanPaths(Keys& keys, Fixture& fixture);
  bool ReadFixtureLimits(Keys& keys, Fixture& fixture);
  std::optional<Feeder> ReadFeeder(const toml::table& table, int index, Names& names);
  std::optional<LinuxCnc> ReadLinuxCnc(const toml::table& table);
  std::optional<Measure> ReadMeasure(const toml::table& table);

  bool CheckMarkerGeometry(const Fixture& fixture, Keys& keys);
  bool CheckScanTrips(const Fixture& fixture);
  void CheckTeachTrips(const Fixture& fixture);
  void CheckRegionOverlaps(const std::vector<Region>& regions);
  void CheckTrueFieldGrid(const Robot& robot, Keys& keys);
  void CheckUniqueNames(const Names& names, std::string_view noun);
  // cell.files: the cell file and its tables with their SHA-256.
  void RecordFiles(Cell& cell) const;

  // Whether a part whose reading began at these counts is dropped: it had
  // errors, and not only points outside the robot's travel with keep_drawable.
  bool Dropped(std::size_t errors_before, std::size_t limit_errors_before) const {
    const std::size_t errors = diags_.error_count() - errors_before;
    return errors > 0 && !(options_.keep_drawable && errors == limit_errors_ - limit_errors_before);
  }
  // Robot-limit checks; `robot_ok_` says whether [robot] was read cleanly.
  void CheckInLimit(int axis, double value, SourceRange where, const std::string& subject);
  void CheckPointInLimits(const std::array<double, 4>& point, SourceRange where, const std::string& subject);
  void ReadPocket(Keys& keys, Fixture& fixture);

  SourceManager& sources_;
  Diagnostics& diags_;
  std::uint32_t file_;
  std::filesystem::path dir_;
  CellLoadOptions options_;
  TomlLocator locator_;
  Robot robot_;
  bool robot_ok_ = false;
  // Errors CheckInLimit reported: with keep_drawable, a part whose only
  // errors are these is kept (it can be drawn where it is).
  std::size_t limit_errors_ = 0;
  std::map<std::string, LoadedTable> tables_;  // by resolved path: a table shared by regions is read once
};

SourceRange Keys::KeyRange(std::string_view key) const {
  for (auto&& [k, node] : table_) {
    if (k.str() == key) return loader_.Range(k.source());
  }
  return TableRange();
}

void Keys::Finish() {
  for (auto&& [key, node] : table_) {
    if (std::find(known_.begin(), known_.end(), key.str()) != known_.end()) continue;
    std::string hint = DidYouMean(key.str(), known_);
    if (hint.empty()) hint = " (docs/cell.md lists the keys)";
    loader_.diags().Report(DiagKind::CellUnknownKey, loader_.Range(key.source()), Printable(key.str()), what_, hint);
  }
}

// ------------------------------------------------------------------ values

std::string Quoted(std::string_view key) { return fmt::format("'{}'", key); }

void ReportMissing(Keys& keys, std::string_view key, std::string_view expected) {
  keys.loader().diags().Report(DiagKind::CellMissingKey, keys.TableRange(), keys.what(), key, expected);
}

void ReportWrongType(Keys& keys, const toml::node& node, const std::string& label, std::string_view expected) {
  keys.loader().diags().Report(DiagKind::CellWrongType, keys.loader().Range(node), label, expected, Describe(node));
}

// The node of `key`, after reporting it missing if it is required.
const toml::node* Lookup(Keys& keys, std::string_view key, Need need, std::string_view expected) {
  const toml::node* node = keys.Get(key);
  if (node == nullptr && need == Need::kRequired) ReportMissing(keys, key, expected);
  return node;
}

// What a number key must hold, for "must be ...": "a number in mm".
std::string NumberExpected(const NumberRange& range) {
  if (range.whole) return "a whole number";
  return range.unit.empty() ? std::string("a number") : fmt::format("a number in {}", range.unit);
}

// A number (a TOML integer or float) from `node`, inside `range`: the one
// check of base/number_range.h, so NaN, the infinities and values no cell
// has are reported with the range docs/cell.md states.
// `expected` names the value in a wrong-type message when it is part of a
// point or an interval.
std::optional<double> NumberOf(Keys& keys, const toml::node& node, const std::string& label, const NumberRange& range,
                               std::string_view expected = {}, std::string_view what = {}) {
  std::optional<double> value;
  if (node.is_integer() || (node.is_floating_point() && !range.whole)) value = TomlNumber(node);
  if (!value) {
    ReportWrongType(keys, node, label, expected.empty() ? NumberExpected(range) : std::string(expected));
    return std::nullopt;
  }
  if (!InRange(*value, range)) {
    keys.loader().diags().Report(DiagKind::CellValueOutOfRange, keys.loader().Range(node), label, TomlNumberText(node),
                                 what.empty() ? RangeText(range) : fmt::format("{} ({})", RangeText(range), what));
    return std::nullopt;
  }
  return *value + 0.0;  // -0 as 0
}

std::optional<Located<double>> Number(Keys& keys, std::string_view key, Need need, const NumberRange& range) {
  const toml::node* node = Lookup(keys, key, need, NumberExpected(range));
  if (node == nullptr) return std::nullopt;
  std::optional<double> value = NumberOf(keys, *node, Quoted(key), range);
  if (!value) return std::nullopt;
  return Located<double>{*value, keys.loader().Range(*node)};
}

// The number of `key` in `range`; nullopt when it is missing (reported when
// required) or wrong (reported). A new numeric key is one line:
//   fixture.scan_speed_mm_s = NumberIn(keys, "scan_speed_mm_s", limits::kSpeedMmS).value_or(0);
std::optional<double> NumberIn(Keys& keys, std::string_view key, const NumberRange& range,
                               Need need = Need::kRequired) {
  std::optional<Located<double>> value = Number(keys, key, need, range);
  if (!value) return std::nullopt;
  return value->value;
}

// A whole number (a TOML integer) of `key` in a whole `range`; `what` says
// what it counts or names, for "must be a whole number (what)".
std::optional<int> WholeIn(Keys& keys, std::string_view key, const NumberRange& range, std::string_view what) {
  const std::string expected = fmt::format("a whole number ({})", what);
  const toml::node* node = Lookup(keys, key, Need::kRequired, expected);
  if (node == nullptr) return std::nullopt;
  std::optional<double> value = NumberOf(keys, *node, Quoted(key), range, expected, what);
  if (!value) return std::nullopt;
  return static_cast<int>(*value);
}

std::optional<Located<std::string>> String(Keys& keys, std::string_view key, Need need, std::string_view expected) {
  const toml::node* node = Lookup(keys, key, need, expected);
  if (node == nullptr) return std::nullopt;
  if (!node->is_string()) {
    ReportWrongType(keys, *node, Quoted(key), expected);
    return std::nullopt;
  }
  return Located<std::string>{*node->value<std::string>(), keys.loader().Range(*node)};
}

// A required, non-empty name.
std::optional<Located<std::string>> Name(Keys& keys, std::string_view expected) {
  std::optional<Located<std::string>> name = String(keys, "name", Need::kRequired, expected);
  if (name && name->value.empty()) {
    keys.loader().diags().Report(DiagKind::CellValueOutOfRange, name->range, "'name'", "\"\"", "a non-empty name");
    return std::nullopt;
  }
  return name;
}

// One of `names` (case-sensitive, as written in docs/cell.md); its index.
template <std::size_t N>
std::optional<int> ChoiceOf(Keys& keys, const toml::node& node, const std::string& label,
                            const std::array<std::string_view, N>& names) {
  std::string expected = fmt::format("one of {}", Choices(names));
  if (!node.is_string()) {
    ReportWrongType(keys, node, label, expected);
    return std::nullopt;
  }
  std::string text = *node.value<std::string>();
  for (std::size_t i = 0; i < N; ++i) {
    if (text == names[i]) return static_cast<int>(i);
  }
  std::vector<std::string> candidates(names.begin(), names.end());
  keys.loader().diags().Report(DiagKind::CellUnknownChoice, keys.loader().Range(node), label, Choices(names),
                               Printable(text), DidYouMean(text, candidates));
  return std::nullopt;
}

template <std::size_t N>
std::optional<int> Choice(Keys& keys, std::string_view key, const std::array<std::string_view, N>& names) {
  const toml::node* node = keys.Get(key);
  if (node == nullptr) return std::nullopt;
  return ChoiceOf(keys, *node, Quoted(key), names);
}

// An array of exactly N numbers, each in its range: a point or an interval.
template <std::size_t N>
std::optional<std::array<double, N>> NumbersOf(Keys& keys, const toml::node& node, const std::string& label,
                                               std::string_view expected, const std::array<NumberRange, N>& ranges) {
  const toml::array* array = node.as_array();
  if (array == nullptr || array->size() != N) {
    ReportWrongType(keys, node, label, expected);
    return std::nullopt;
  }
  std::array<double, N> values{};
  bool ok = true;
  for (std::size_t i = 0; i < N; ++i) {
    std::optional<double> value = NumberOf(keys, *array->get(i), label, ranges[i], expected);
    if (value) {
      values[i] = *value;
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return values;
}

std::string PointExpected(std::size_t n) {
  return n == 2 ? "a point [x, y] of numbers in mm" : "a point [x, y, z, u] of numbers (x, y, z in mm, u in degrees)";
}

// Points: x, y (and z) positions, u an angle (calibration/limits.h).
constexpr std::array<NumberRange, 2> kPoint2Ranges = {limits::kPositionMm, limits::kPositionMm};
constexpr std::array<NumberRange, 4> kPoint4Ranges = {limits::kPositionMm, limits::kPositionMm, limits::kPositionMm,
                                                      limits::kAngleDeg};

std::optional<Located<Point2>> Point2At(Keys& keys, std::string_view key, Need need) {
  const toml::node* node = Lookup(keys, key, need, PointExpected(2));
  if (node == nullptr) return std::nullopt;
  std::optional<std::array<double, 2>> xy = NumbersOf<2>(keys, *node, Quoted(key), PointExpected(2), kPoint2Ranges);
  if (!xy) return std::nullopt;
  return Located<Point2>{Point2((*xy)[0], (*xy)[1]), keys.loader().Range(*node)};
}

std::optional<Located<std::array<double, 4>>> Point4At(Keys& keys, std::string_view key, Need need) {
  const toml::node* node = Lookup(keys, key, need, PointExpected(4));
  if (node == nullptr) return std::nullopt;
  std::optional<std::array<double, 4>> xyzu = NumbersOf<4>(keys, *node, Quoted(key), PointExpected(4), kPoint4Ranges);
  if (!xyzu) return std::nullopt;
  return Located<std::array<double, 4>>{*xyzu, keys.loader().Range(*node)};
}

// An array of points [[x, y], ...]; each element checked on its own.
std::optional<std::vector<Located<Point2>>> Point2List(Keys& keys, std::string_view key, Need need) {
  std::string_view expected = "an array of points [x, y] in mm";
  const toml::node* node = Lookup(keys, key, need, expected);
  if (node == nullptr) return std::nullopt;
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    ReportWrongType(keys, *node, Quoted(key), expected);
    return std::nullopt;
  }
  std::vector<Located<Point2>> points;
  bool ok = true;
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& element = *array->get(i);
    std::string label = fmt::format("point {} of '{}'", i + 1, key);
    std::optional<std::array<double, 2>> xy = NumbersOf<2>(keys, element, label, PointExpected(2), kPoint2Ranges);
    if (xy) {
      points.push_back({Point2((*xy)[0], (*xy)[1]), keys.loader().Range(element)});
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return points;
}

// [lo, hi] with lo < hi, each bound in `range`.
std::optional<Located<Interval>> IntervalAt(Keys& keys, std::string_view key, Need need, const NumberRange& range) {
  std::string expected = fmt::format("an interval [lo, hi] of numbers in {}", range.unit);
  const toml::node* node = Lookup(keys, key, need, expected);
  if (node == nullptr) return std::nullopt;
  std::optional<std::array<double, 2>> bounds =
      NumbersOf<2>(keys, *node, Quoted(key), expected, std::array<NumberRange, 2>{range, range});
  if (!bounds) return std::nullopt;
  SourceRange where = keys.loader().Range(*node);
  if ((*bounds)[0] >= (*bounds)[1]) {
    keys.loader().diags().Report(DiagKind::CellEmptyInterval, where, Quoted(key), Num((*bounds)[0]),
                                 Num((*bounds)[1]), range.unit);
    return std::nullopt;
  }
  return Located<Interval>{Interval{(*bounds)[0], (*bounds)[1]}, where};
}

const toml::table* TableAt(Keys& keys, std::string_view key, Need need, std::string_view expected) {
  const toml::node* node = Lookup(keys, key, need, expected);
  if (node == nullptr) return nullptr;
  if (!node->is_table()) {
    ReportWrongType(keys, *node, Quoted(key), expected);
    return nullptr;
  }
  return node->as_table();
}

// The tables of an array of tables ([[key]]); elements that are not tables
// are reported.
std::vector<const toml::table*> TablesAt(Keys& keys, std::string_view key, Need need) {
  std::string expected = fmt::format("an array of tables, written [[{}]]", key);
  const toml::node* node = Lookup(keys, key, need, expected);
  std::vector<const toml::table*> tables;
  if (node == nullptr) return tables;
  const toml::array* array = node->as_array();
  if (array == nullptr) {
    ReportWrongType(keys, *node, Quoted(key), expected);
    return tables;
  }
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& element = *array->get(i);
    if (element.is_table()) {
      tables.push_back(element.as_table());
    } else {
      ReportWrongType(keys, element, fmt::format("element {} of '{}'", i + 1, key), "a table");
    }
  }
  if (tables.empty() && need == Need::kRequired && array->empty()) {
    keys.loader().diags().Report(DiagKind::CellValueOutOfRange, keys.loader().Range(*node), Quoted(key), "[]",
                                 fmt::format("at least one [[{}]] table", key));
  }
  return tables;
}

// "region 'layer1'", or "[[region]] 2" when its name could not be read.
std::string Title(std::string_view noun, const std::optional<Located<std::string>>& name, std::string_view array_key,
                  int index) {
  if (name) return fmt::format("{} '{}'", noun, Printable(name->value));
  return fmt::format("[[{}]] {}", array_key, index + 1);
}

double Cross(const Point2& a, const Point2& b) { return a.x() * b.y() - a.y() * b.x(); }

// ------------------------------------------------------------------ robot

void Loader::ReadRobot(const toml::table& table, Robot& robot) {
  const std::size_t errors_before = diags_.error_count();
  Keys keys(*this, table, "[robot]", Range(table));
  robot.range = Range(table);
  if (auto model = String(keys, "model", Need::kOptional, "a string naming the robot")) robot.model = model->value;
  for (std::size_t axis = 0; axis < kLimitKeys.size(); ++axis) {
    robot.limit_keys[axis] = keys.KeyRange(kLimitKeys[axis]);
    if (auto limit = IntervalAt(keys, kLimitKeys[axis], Need::kRequired, kLimitRanges[axis])) {
      robot.limits[axis] = limit->value;
    }
  }
  robot.repeatability_mm = NumberIn(keys, "repeatability_mm", limits::kAccuracyMm).value_or(0);
  if (auto limz = NumberIn(keys, "safe_limz_mm", limits::kPositionMm)) robot.safe_limz_mm = *limz;
  robot.xy_speed_mm_s = NumberIn(keys, "xy_speed_mm_s", limits::kSpeedMmS).value_or(0);
  robot.xy_accel_mm_s2 = NumberIn(keys, "xy_accel_mm_s2", limits::kAccelerationMmS2).value_or(0);
  robot.z_speed_mm_s = NumberIn(keys, "z_speed_mm_s", limits::kSpeedMmS).value_or(0);
  robot.z_accel_mm_s2 = NumberIn(keys, "z_accel_mm_s2", limits::kAccelerationMmS2).value_or(0);
  robot.u_speed_deg_s = NumberIn(keys, "u_speed_deg_s", limits::kSpeedDegS).value_or(0);
  robot.u_accel_deg_s2 = NumberIn(keys, "u_accel_deg_s2", limits::kAccelerationDegS2).value_or(0);
  robot.pick_time_s = NumberIn(keys, "pick_time_s", limits::kDwellS).value_or(0);
  robot.place_time_s = NumberIn(keys, "place_time_s", limits::kDwellS).value_or(0);
  robot.uncalibrated_accuracy_range = keys.KeyRange("uncalibrated_accuracy_mm");
  robot.uncalibrated_accuracy_mm = NumberIn(keys, "uncalibrated_accuracy_mm", limits::kAccuracyMm, Need::kOptional);
  if (auto length = NumberIn(keys, "uncalibrated_correlation_mm", limits::kCorrelationMm, Need::kOptional)) {
    robot.uncalibrated_correlation_mm = *length;
  }
  robot.servo_period_range = keys.KeyRange("servo_period_s");
  if (auto period = NumberIn(keys, "servo_period_s", limits::kServoPeriodS, Need::kOptional)) robot.servo_period_s = *period;
  robot.final_approach_range = keys.KeyRange("final_approach_mm");
  if (auto approach = Point2At(keys, "final_approach_mm", Need::kOptional)) {
    const Point2& a = approach->value;
    // Written so that a NaN fails too (every comparison with NaN is false).
    if (!(a.x() != 0 && a.y() != 0 && a.cwiseAbs().maxCoeff() <= kMaxFinalApproachMm)) {
      diags_.Report(DiagKind::CellValueOutOfRange, approach->range, "'final_approach_mm'",
                    fmt::format("[{}, {}]", Num(a.x()), Num(a.y())),
                    fmt::format("a move along both axes, each component non-zero and within ±{} mm",
                                Num(kMaxFinalApproachMm)));
    } else {
      robot.final_approach_mm = a;
    }
  }
  if (auto turnaround = NumberIn(keys, "probe_turnaround_s", limits::kProbeTurnaroundS, Need::kOptional)) {
    robot.probe_turnaround_s = *turnaround;
  }
  keys.Finish();
  robot_ = robot;
  robot_ok_ = diags_.error_count() == errors_before;
  if (robot_ok_) CheckInLimit(2, robot.safe_limz_mm, keys.KeyRange("safe_limz_mm"), "'safe_limz_mm'");
  if (robot_ok_) CheckTrueFieldGrid(robot, keys);
}

// `smtcal simulate` samples its true field over the robot's reach every
// uncalibrated_correlation_mm / 8 (calibration/truth_spec.h): a reach and a
// correlation length that make that grid larger than it may be are refused
// here, so no cell that passes `cell check` makes simulate run for hours.
void Loader::CheckTrueFieldGrid(const Robot& robot, Keys& keys) {
  const double samples = TrueFieldSamples(robot, robot.uncalibrated_correlation_mm);
  if (samples <= limits::kMaxTrueFieldSamples) return;
  const bool given = keys.Get("uncalibrated_correlation_mm") != nullptr;
  diags_.Report(DiagKind::CellTrueFieldTooFine,
                given ? keys.KeyRange("uncalibrated_correlation_mm") : keys.KeyRange("x_mm"),
                Num(robot.uncalibrated_correlation_mm), given ? "" : " (the default)", Num(robot.limits[0].lo),
                Num(robot.limits[0].hi), Num(robot.limits[1].lo), Num(robot.limits[1].hi),
                fmt::format("{:.4g}", TrueFieldStepMm(robot.uncalibrated_correlation_mm)), fmt::format("{:.3g}", samples),
                fmt::format("{:.0f}", limits::kMaxTrueFieldSamples),
                fmt::format("{:.3g}", MinTrueFieldCorrelationMm(robot)));
}

void Loader::CheckInLimit(int axis, double value, SourceRange where, const std::string& subject) {
  if (!robot_ok_) return;
  const Interval& limit = robot_.limits[static_cast<std::size_t>(axis)];
  if (limit.Contains(value)) return;
  ++limit_errors_;
  // Computed points (a scan path at the nominal pose, a pallet's far corner)
  // are shown to 1 nm, without the noise of their arithmetic.
  Diagnostic* diag = diags_.Report(DiagKind::CellOutsideRobotLimits, where,
                                   fmt::format("{} = {}", subject, Num(std::round(value * 1e6) / 1e6)),
                                   kTaskAxisNames[static_cast<std::size_t>(axis)], Num(limit.lo), Num(limit.hi),
                                   kLimitUnits[static_cast<std::size_t>(axis)]);
  Diagnostics::AddNote(diag, robot_.limit_keys[static_cast<std::size_t>(axis)],
                       fmt::format("the robot's {} range is set here", kTaskAxisNames[static_cast<std::size_t>(axis)]));
}

void Loader::CheckPointInLimits(const std::array<double, 4>& point, SourceRange where, const std::string& subject) {
  for (int axis = 0; axis < 4; ++axis) {
    CheckInLimit(axis, point[static_cast<std::size_t>(axis)], where,
                 fmt::format("{} of {}", kTaskAxisNames[static_cast<std::size_t>(axis)], subject));
  }
}

// ------------------------------------------------------------------ regions

const Loader::LoadedTable& Loader::LoadTable(const std::string& table_path) {
  std::string resolved = (dir_ / table_path).generic_string();
  auto found = tables_.find(resolved);
  if (found != tables_.end()) return found->second;
  LoadedTable& loaded = tables_[resolved];
  Result<std::uint32_t> file = sources_.Load(resolved);
  if (!file) {
    loaded.io_error = file.error().message;
    std::error_code error;
    loaded.missing = !std::filesystem::exists(resolved, error) && !error;
    return loaded;
  }
  loaded.file = file.value();
  std::optional<ErrorTable> table = ReadErrorTable(file.value(), diags_);
  // Warnings (sign changes, large errors): `smtcal table check` shows each, and
  // ReportTableWarnings sums them up for the commands that decide.
  if (table && ValidateErrorTable(*table, diags_, TableWarnings::kSkip)) {
    loaded.ok = true;
    loaded.table = std::move(*table);
  }
  return loaded;
}

bool Loader::ReadDifficulty(Keys& keys, Region& region) {
  const char* expected = "a table { level = 2, axes = [\"x\", \"y\"] }";
  const toml::table* table = TableAt(keys, "difficulty", Need::kRequired, expected);
  if (table == nullptr) return false;
  region.difficulty_range = keys.KeyRange("difficulty");
  const std::size_t errors_before = diags_.error_count();
  Keys difficulty(*this, *table, fmt::format("the difficulty table of {}", keys.what()), Range(*table));
  std::optional<int> level =
      WholeIn(difficulty, "level", limits::kDifficultyLevel, "L_D, the number of axes");
  const char* axes_expected = "an array of axis names (\"x\", \"y\", \"z\", \"u\")";
  const toml::node* axes_node = Lookup(difficulty, "axes", Need::kRequired, axes_expected);
  if (axes_node != nullptr && !axes_node->is_array()) {
    ReportWrongType(difficulty, *axes_node, "'axes'", axes_expected);
  } else if (axes_node != nullptr) {
    const toml::array& axes = *axes_node->as_array();
    if (axes.empty()) {
      diags_.Report(DiagKind::CellValueOutOfRange, Range(axes), "'axes'", "[]", "at least one axis");
    }
    for (std::size_t i = 0; i < axes.size(); ++i) {
      std::optional<int> axis = ChoiceOf(difficulty, *axes.get(i), fmt::format("axis {} of 'axes'", i + 1), kTaskAxisNames);
      if (!axis) continue;
      auto task_axis = static_cast<TaskAxis>(*axis);
      if (std::find(region.difficulty_axes.begin(), region.difficulty_axes.end(), task_axis) !=
          region.difficulty_axes.end()) {
        diags_.Report(DiagKind::CellDuplicateAxis, Range(*axes.get(i)), kTaskAxisNames[static_cast<std::size_t>(*axis)]);
        continue;
      }
      region.difficulty_axes.push_back(task_axis);
    }
  }
  difficulty.Finish();
  if (diags_.error_count() != errors_before || !level) return false;
  region.difficulty_level = *level;
  if (static_cast<std::size_t>(*level) != region.difficulty_axes.size()) {
    std::string names;
    for (TaskAxis axis : region.difficulty_axes) names += fmt::format("{}{}", names.empty() ? "" : ", ", TaskAxisName(axis));
    diags_.Report(DiagKind::CellDifficultyLevel, difficulty.KeyRange("level"), *level, region.difficulty_axes.size(),
                  names, region.difficulty_axes.size());
    return false;
  }
  return true;
}


std::optional<Region> Loader::ReadRegion(const toml::table& table, int index,
                                         std::vector<Located<std::string>>& names) {
  const std::size_t errors_before = diags_.error_count(), limit_errors_before = limit_errors_;
  Region region;
  region.range = Range(table);
  Keys keys(*this, table, fmt::format("[[region]] {}", index + 1), region.range);
  if (auto name = Name(keys, "a string naming the region")) {
    region.name = name->value;
    region.name_range = name->range;
    keys.set_what(Title("region", name, "region", index));
    names.push_back(*name);
  }

  const LoadedTable* loaded = nullptr;
  if (auto path = String(keys, "table", Need::kRequired,
                         "the path of the region's error table (CSV), relative to the cell file")) {
    region.table_path = path->value;
    region.table_range = path->range;
    if (path->value.empty()) {
      diags_.Report(DiagKind::CellValueOutOfRange, path->range, "'table'", "\"\"", "the path of an error table file");
    } else {
      loaded = &LoadTable(path->value);
      if (loaded->missing && options_.tables_may_be_missing) {
        region.has_table = false;
      } else if (loaded->io_error) {
        diags_.Report(DiagKind::CellTableUnreadable, path->range, Printable(region.name), *loaded->io_error);
      } else if (!loaded->ok) {
        diags_.Report(DiagKind::CellTableInvalid, path->range, Printable(path->value), Printable(region.name));
      }
      region.table_file = loaded->file;
    }
  }

  const std::size_t errors_before_bounds = diags_.error_count();
  std::optional<Located<Interval>> x = IntervalAt(keys, "x_mm", Need::kOptional, limits::kPositionMm);
  std::optional<Located<Interval>> y = IntervalAt(keys, "y_mm", Need::kOptional, limits::kPositionMm);
  const bool bounds_read = diags_.error_count() == errors_before_bounds;
  region.bounds_range = x ? keys.KeyRange("x_mm") : y ? keys.KeyRange("y_mm") : region.table_range;

  ReadDifficulty(keys, region);
  region.tolerance_range = keys.KeyRange("tolerance_mm");
  region.tolerance_mm = NumberIn(keys, "tolerance_mm", limits::kAccuracyMm).value_or(0);
  region.outside_range = keys.KeyRange("outside");
  if (std::optional<int> outside = Choice(keys, "outside", kOutsideNames)) {
    region.outside = static_cast<OutsidePolicy>(*outside);  // kOutsideNames is in OutsidePolicy's order
  }
  keys.Finish();

  if (!region.has_table && bounds_read) {
    // Planning the first measurement: the bounds say what to measure.
    if (!x || !y) {
      diags_.Report(DiagKind::CellRegionNeedsBounds, region.table_range, Printable(region.name),
                    Printable(region.table_path), !x && !y ? "x_mm and y_mm" : !x ? "x_mm" : "y_mm");
    } else {
      region.x_mm = x->value;
      region.y_mm = y->value;
      std::string subject = fmt::format("region '{}'", Printable(region.name));
      CheckInLimit(0, region.x_mm.lo, keys.KeyRange("x_mm"), subject + " x_mm.lo");
      CheckInLimit(0, region.x_mm.hi, keys.KeyRange("x_mm"), subject + " x_mm.hi");
      CheckInLimit(1, region.y_mm.lo, keys.KeyRange("y_mm"), subject + " y_mm.lo");
      CheckInLimit(1, region.y_mm.hi, keys.KeyRange("y_mm"), subject + " y_mm.hi");
    }
  }
  if (loaded != nullptr && loaded->ok && bounds_read) {
    region.table = loaded->table;
    region.domain = TableDomain(region.table);
    const Rect& domain = region.domain;
    region.x_mm = x ? x->value : Interval{domain.x0, domain.x1};
    region.y_mm = y ? y->value : Interval{domain.y0, domain.y1};
    auto inside = [](const Interval& bounds, double lo, double hi) {
      return bounds.lo >= lo - kTableEdgeTolMm && bounds.hi <= hi + kTableEdgeTolMm;
    };
    bool x_inside = inside(region.x_mm, domain.x0, domain.x1);
    bool y_inside = inside(region.y_mm, domain.y0, domain.y1);
    if (!x_inside || !y_inside) {
      SourceRange where = !x_inside ? keys.KeyRange("x_mm") : keys.KeyRange("y_mm");
      diags_.Report(DiagKind::CellBoundsOutsideTable, where, Printable(region.name), Num(region.x_mm.lo),
                    Num(region.x_mm.hi), Num(region.y_mm.lo), Num(region.y_mm.hi), FormatMm(domain.x0),
                    FormatMm(domain.x1), FormatMm(domain.y0), FormatMm(domain.y1));
    }
    std::string subject = fmt::format("region '{}'", Printable(region.name));
    CheckInLimit(0, region.x_mm.lo, region.bounds_range, subject + " x_mm.lo");
    CheckInLimit(0, region.x_mm.hi, region.bounds_range, subject + " x_mm.hi");
    CheckInLimit(1, region.y_mm.lo, y ? keys.KeyRange("y_mm") : region.bounds_range, subject + " y_mm.lo");
    CheckInLimit(1, region.y_mm.hi, y ? keys.KeyRange("y_mm") : region.bounds_range, subject + " y_mm.hi");
  }
  if (Dropped(errors_before, limit_errors_before)) return std::nullopt;
  return region;
}

void Loader::CheckRegionOverlaps(const std::vector<Region>& regions) {
  for (std::size_t j = 0; j < regions.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const Region& a = regions[i];
      const Region& b = regions[j];
      Interval x{std::max(a.x_mm.lo, b.x_mm.lo), std::min(a.x_mm.hi, b.x_mm.hi)};
      Interval y{std::max(a.y_mm.lo, b.y_mm.lo), std::min(a.y_mm.hi, b.y_mm.hi)};
      // Sharing an edge is fine (RegionAt gives the edge to the first region).
      if (x.lo >= x.hi || y.lo >= y.hi) continue;
      Diagnostic* diag = diags_.Report(
          DiagKind::CellRegionsOverlap, b.bounds_range, Printable(b.name), Num(b.x_mm.lo), Num(b.x_mm.hi),
          Num(b.y_mm.lo), Num(b.y_mm.hi), Printable(a.name), Num(a.x_mm.lo), Num(a.x_mm.hi), Num(a.y_mm.lo),
          Num(a.y_mm.hi), Num(x.lo), Num(x.hi), Num(y.lo), Num(y.hi));
      Diagnostics::AddNote(diag, a.bounds_range, fmt::format("the bounds of region '{}'", Printable(a.name)));
    }
  }
}

void Loader::CheckUniqueNames(const std::vector<Located<std::string>>& names, std::string_view noun) {
  for (std::size_t j = 0; j < names.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      if (!SameName(names[i].value, names[j].value)) continue;
      Diagnostic* diag =
          diags_.Report(DiagKind::CellDuplicateName, names[j].range, noun, Printable(names[j].value), noun);
      Diagnostics::AddNote(diag, names[i].range, fmt::format("'{}' is defined here", Printable(names[i].value)));
      break;
    }
  }
}

// ------------------------------------------------------------------ fixtures

bool Loader::ReadEdges(Keys& keys, Fixture& fixture) {
  const toml::table* table =
      TableAt(keys, "edges", Need::kRequired, "a table [fixture.edges] with the marker edges p1, p2, p3, p4");
  if (table == nullptr) return false;
  const std::size_t errors_before = diags_.error_count();
  Keys edges(*this, *table, fmt::format("[fixture.edges] of {}", keys.what()), Range(*table));
  for (std::size_t i = 0; i < kEdgeNames.size(); ++i) {
    MarkerEdge& edge = fixture.edges[i];
    edge.name = kEdgeNames[i];
    edge.range = edges.KeyRange(edge.name);
    const toml::table* entry =
        TableAt(edges, edge.name, Need::kRequired, "a table { from_mm = [x, y], to_mm = [x, y] } (fixture mm)");
    if (entry == nullptr) continue;
    Keys ends(*this, *entry, fmt::format("edge '{}' of {}", edge.name, keys.what()), Range(*entry));
    std::optional<Located<Point2>> from = Point2At(ends, "from_mm", Need::kRequired);
    std::optional<Located<Point2>> to = Point2At(ends, "to_mm", Need::kRequired);
    ends.Finish();
    if (!from || !to) continue;
    edge.from = from->value;
    edge.to = to->value;
    if ((edge.to - edge.from).norm() <= kMarkerGeometryTolMm) {
      diags_.Report(DiagKind::CellEdgeDegenerate, edge.range, edge.name);
    }
  }
  edges.Finish();
  return diags_.error_count() == errors_before;
}

bool Loader::ReadScanPaths(Keys& keys, Fixture& fixture) {
  const std::size_t errors_before = diags_.error_count();
  std::vector<const toml::table*> tables = TablesAt(keys, "scan_path", Need::kRequired);
  std::vector<Located<std::string>> names;
  for (std::size_t i = 0; i < tables.size(); ++i) {
    ScanPath path;
    path.range = Range(*tables[i]);
    Keys path_keys(*this, *tables[i], fmt::format("[[fixture.scan_path]] {} of {}", i + 1, keys.what()), path.range);
    std::optional<Located<std::string>> name = Name(path_keys, "a string naming the scan path");
    if (name) {
      path.name = name->value;
      path_keys.set_what(fmt::format("scan path '{}' of {}", Printable(path.name), keys.what()));
      names.push_back(*name);
    }
    std::optional<std::vector<Located<Point2>>> points = Point2List(path_keys, "points_mm", Need::kRequired);
    path_keys.Finish();
    if (!points) continue;
    const std::string title = name ? Printable(path.name) : fmt::format("{}", i + 1);
    if (points->size() < 2) {
      diags_.Report(DiagKind::CellScanPathTooShort, path_keys.KeyRange("points_mm"), title, points->size());
      continue;
    }
    for (std::size_t k = 0; k < points->size(); ++k) {
      if (k > 0 && ((*points)[k].value - (*points)[k - 1].value).norm() <= kMarkerGeometryTolMm) {
        diags_.Report(DiagKind::CellScanPathRepeatedPoint, (*points)[k].range, k + 1, title);
      }
      path.points.push_back((*points)[k].value);
      path.point_ranges.push_back((*points)[k].range);
    }
    fixture.scan_paths.push_back(std::move(path));
  }
  CheckUniqueNames(names, "scan path");
  return !tables.empty() && diags_.error_count() == errors_before;
}

bool Loader::ReadFixtureLimits(Keys& keys, Fixture& fixture) {
  const toml::table* table = TableAt(keys, "limits", Need::kRequired,
                                     "a table [fixture.limits] with the scan check limits");
  if (table == nullptr) return false;
  const std::size_t errors_before = diags_.error_count();
  Keys limits(*this, *table, fmt::format("[fixture.limits] of {}", keys.what()), Range(*table));
  fixture.max_shift_mm = NumberIn(limits, "max_shift_mm", limits::kFixtureLimitMm).value_or(0);
  fixture.max_rotation_deg = NumberIn(limits, "max_rotation_deg", limits::kFixtureRotationDeg).value_or(0);
  fixture.length_tolerance_mm = NumberIn(limits, "length_tolerance_mm", limits::kFixtureLimitMm).value_or(0);
  fixture.squareness_deg = NumberIn(limits, "squareness_deg", limits::kSquarenessDeg).value_or(0);
  fixture.max_line_residual_mm = NumberIn(limits, "max_line_residual_mm", limits::kFixtureLimitMm).value_or(0);
  limits.Finish();
  return diags_.error_count() == errors_before;
}

// S1 = p1 x p2 = (0, 0), S2 = p1 x p3 = (L1, 0), S3 = p2 x p4 = (0, L2): the
// edges must describe the board that L1 and L2 measure.
bool Loader::CheckMarkerGeometry(const Fixture& fixture, Keys& keys) {
  struct Crossing {
    std::size_t a, b;
    int s;
    Point2 expected;
    std::string_view length_key;  // the length that places it
  };
  const Crossing crossings[] = {{0, 1, 1, Point2(0, 0), ""},
                                {0, 2, 2, Point2(fixture.l1_mm, 0), "l1_mm"},
                                {1, 3, 3, Point2(0, fixture.l2_mm), "l2_mm"}};
  bool ok = true;
  for (const Crossing& c : crossings) {
    const MarkerEdge& a = fixture.edges[c.a];
    const MarkerEdge& b = fixture.edges[c.b];
    Point2 da = a.to - a.from, db = b.to - b.from;
    double denominator = Cross(da, db);
    Point2 at = a.from + (Cross(b.from - a.from, db) / denominator) * da;
    if (denominator == 0 || !at.allFinite()) {
      diags_.Report(DiagKind::CellEdgesParallel, b.range, a.name, b.name, c.s, Num(c.expected.x()),
                    Num(c.expected.y()));
      ok = false;
      continue;
    }
    double miss = (at - c.expected).norm();
    if (miss <= kMarkerGeometryTolMm) continue;
    ok = false;
    Diagnostic* diag = diags_.Report(DiagKind::CellMarkerGeometry, b.range, a.name, b.name,
                                     fmt::format("{:.6f}", at.x()), fmt::format("{:.6f}", at.y()),
                                     fmt::format("{:.3g}", miss), c.s, Num(c.expected.x()), Num(c.expected.y()),
                                     Num(fixture.l1_mm), Num(fixture.l2_mm));
    if (!c.length_key.empty()) {
      Diagnostics::AddNote(diag, keys.KeyRange(c.length_key),
                           fmt::format("S{} is placed by '{}' here", c.s, c.length_key));
    }
  }
  return ok;
}

// Every edge's line is fitted through its trips: it needs two different ones.
// The trips are those the estimator expects (calibration/fixture_geometry.h), so
// the loader and the runtime agree on T1..Tn.
bool Loader::CheckScanTrips(const Fixture& fixture) {
  std::vector<ExpectedTrip> trips = ExpectedTrips(fixture);
  bool ok = true;
  for (std::size_t e = 0; e < fixture.edges.size(); ++e) {
    std::vector<Point2> distinct;
    for (const ExpectedTrip& trip : trips) {
      if (trip.edge != static_cast<int>(e)) continue;
      bool seen = std::any_of(distinct.begin(), distinct.end(), [&](const Point2& p) {
        return (p - trip.in_fixture).norm() <= kMarkerGeometryTolMm;
      });
      if (!seen) distinct.push_back(trip.in_fixture);
    }
    if (distinct.size() < 2) {
      diags_.Report(DiagKind::CellEdgeNotScanned, fixture.edges[e].range, fixture.edges[e].name, distinct.size());
      ok = false;
    }
  }
  return ok;
}

// The teach scan was taken with the board near its nominal pose: trip k lies
// within the trip window of where the nominal pose puts expected trip k, as
// every cycle's scan must (a trip outside it is a scan the runtime refuses).
void Loader::CheckTeachTrips(const Fixture& fixture) {
  std::vector<ExpectedTrip> trips = ExpectedTrips(fixture);
  if (fixture.teach_trips_mm.size() != trips.size()) {
    diags_.Report(DiagKind::CellTeachTripCount, fixture.teach_range, fixture.teach_trips_mm.size(), trips.size(),
                  trips.size());
    return;
  }
  std::vector<Point2> expected = NominalTrips(fixture, NominalFix(fixture));
  for (std::size_t k = 0; k < trips.size(); ++k) {
    const Point2& taught = fixture.teach_trips_mm[k];
    double distance = (taught - expected[k]).norm();
    if (distance <= fixture.trip_window_mm) continue;
    diags_.Report(DiagKind::CellTeachTripFar, fixture.teach_trip_ranges[k], k + 1, Num(taught.x()), Num(taught.y()),
                  fmt::format("{:.3f}", distance), fmt::format("{:.4f}", expected[k].x()),
                  fmt::format("{:.4f}", expected[k].y()), fixture.edges[static_cast<std::size_t>(trips[k].edge)].name,
                  Printable(fixture.scan_paths[trips[k].path].name), Num(fixture.trip_window_mm));
  }
}

// pocket_x_mm, pocket_y_mm: where `smtcal import` puts boards on this
// fixture (docs/cell.md). Both or neither; each [lo, hi] within
// limits::kPocketMm of the fixture origin.
void Loader::ReadPocket(Keys& keys, Fixture& fixture) {
  std::optional<Located<Interval>> x = IntervalAt(keys, "pocket_x_mm", Need::kOptional, limits::kPocketMm);
  std::optional<Located<Interval>> y = IntervalAt(keys, "pocket_y_mm", Need::kOptional, limits::kPocketMm);
  const bool has_x = keys.Get("pocket_x_mm") != nullptr, has_y = keys.Get("pocket_y_mm") != nullptr;
  if (has_x != has_y) {
    diags_.Report(DiagKind::CellMissingKey, keys.KeyRange(has_x ? "pocket_x_mm" : "pocket_y_mm"), keys.what(),
                  has_x ? "pocket_y_mm" : "pocket_x_mm",
                  "a pocket is a rectangle, pocket_x_mm = [lo, hi] and pocket_y_mm = [lo, hi] in the fixture frame");
    return;
  }
  if (!x || !y) return;
  fixture.pocket_mm = std::array<Interval, 2>{x->value, y->value};
  fixture.pocket_range = x->range;
}

std::optional<Fixture> Loader::ReadFixture(const toml::table& table, int index,
                                           std::vector<Located<std::string>>& names) {
  const std::size_t errors_before = diags_.error_count(), limit_errors_before = limit_errors_;
  Fixture fixture;
  fixture.range = Range(table);
  Keys keys(*this, table, fmt::format("[[fixture]] {}", index + 1), fixture.range);
  if (auto name = Name(keys, "a string naming the fixture (the program's 'Fixture NAME')")) {
    fixture.name = name->value;
    fixture.name_range = name->range;
    keys.set_what(Title("fixture", name, "fixture", index));
    names.push_back(*name);
  }

  const std::size_t errors_before_pose = diags_.error_count();
  fixture.pose_range = keys.KeyRange("origin_mm");
  if (auto origin = Point2At(keys, "origin_mm", Need::kRequired)) fixture.origin_mm = origin->value;
  if (auto angle = NumberIn(keys, "angle_deg", limits::kAngleDeg, Need::kOptional)) fixture.angle_deg = *angle;
  const bool pose_ok = diags_.error_count() == errors_before_pose;
  std::optional<double> l1 = NumberIn(keys, "l1_mm", limits::kLengthMm);
  std::optional<double> l2 = NumberIn(keys, "l2_mm", limits::kLengthMm);
  fixture.l1_mm = l1.value_or(0);
  fixture.l2_mm = l2.value_or(0);
  const bool edges_ok = ReadEdges(keys, fixture);
  const bool paths_ok = ReadScanPaths(keys, fixture);
  std::optional<Located<double>> scan_z = Number(keys, "scan_z_mm", Need::kRequired, limits::kPositionMm);
  if (scan_z) fixture.scan_z_mm = scan_z->value;
  fixture.scan_speed_range = keys.KeyRange("scan_speed_mm_s");
  std::optional<Located<double>> place_z = Number(keys, "place_z_mm", Need::kOptional, limits::kPositionMm);
  if (place_z) {
    fixture.place_z_mm = place_z->value;
    fixture.place_z_range = keys.KeyRange("place_z_mm");
  }
  ReadPocket(keys, fixture);
  fixture.scan_speed_mm_s = NumberIn(keys, "scan_speed_mm_s", limits::kSpeedMmS).value_or(0);
  fixture.latch_speed_range = keys.KeyRange("latch_speed_mm_s");
  if (std::optional<Located<double>> latch = Number(keys, "latch_speed_mm_s", Need::kOptional, limits::kSpeedMmS)) {
    if (fixture.scan_speed_mm_s > 0 && latch->value > fixture.scan_speed_mm_s) {
      diags_.Report(DiagKind::CellValueOutOfRange, latch->range, "'latch_speed_mm_s'", Num(latch->value),
                    fmt::format("at most scan_speed_mm_s = {} mm/s: the search finds each edge at the scan "
                                "speed, the latch measures it again slower",
                                Num(fixture.scan_speed_mm_s)));
    } else {
      fixture.latch_speed_mm_s = latch->value;
    }
  }
  std::optional<double> window = NumberIn(keys, "trip_window_mm", limits::kTripWindowMm);
  fixture.trip_window_mm = window.value_or(0);
  fixture.sensor_input =
      WholeIn(keys, "sensor_input", limits::kIoBit, "the input bit the sensor is wired to").value_or(0);
  fixture.sensor_accuracy_mm = NumberIn(keys, "sensor_accuracy_mm", limits::kAccuracyMm).value_or(0);
  // Without the key: 2 x the accuracy for the two scans' trips, 4 x for the
  // board's change between cycles (docs/cell.md).
  fixture.predicted_window_mm = NumberIn(keys, "predicted_window_mm", limits::kPredictedWindowMm, Need::kOptional)
                                    .value_or(std::round(kDefaultPredictedWindowAccuracies * fixture.sensor_accuracy_mm *
                                                         1e6) / 1e6);  // to the micrometre: 0.3, not 0.30000000000000004
  if (std::optional<int> estimator = Choice(keys, "estimator", kEstimatorNames)) {
    fixture.estimator = static_cast<Estimator>(*estimator);  // kEstimatorNames is in Estimator's order
  }
  ReadFixtureLimits(keys, fixture);
  fixture.teach_range = keys.KeyRange("teach_trips_mm");
  std::optional<std::vector<Located<Point2>>> teach = Point2List(keys, "teach_trips_mm", Need::kOptional);
  if (teach) {
    for (const Located<Point2>& trip : *teach) {
      fixture.teach_trips_mm.push_back(trip.value);
      fixture.teach_trip_ranges.push_back(trip.range);
    }
  }
  keys.Finish();

  // A wrong edge usually also breaks its trips: report the geometry first.
  const bool geometry_ok = edges_ok && l1 && l2 && CheckMarkerGeometry(fixture, keys);
  const bool trips_ok = geometry_ok && paths_ok && CheckScanTrips(fixture);
  if (trips_ok && teach && pose_ok && window) CheckTeachTrips(fixture);
  // Where the robot must reach: the origin and the scan paths at the nominal pose.
  if (pose_ok) {
    const std::string subject = fmt::format("the origin of fixture '{}'", Printable(fixture.name));
    CheckInLimit(0, fixture.origin_mm.x(), fixture.pose_range, "x of " + subject);
    CheckInLimit(1, fixture.origin_mm.y(), fixture.pose_range, "y of " + subject);
    for (const ScanPath& path : fixture.scan_paths) {
      for (std::size_t k = 0; k < path.points.size(); ++k) {
        Point2 base = ToBase(NominalFix(fixture), path.points[k]);
        std::string point = fmt::format("point {} of scan path '{}' (at the nominal pose)", k + 1,
                                        Printable(path.name));
        CheckInLimit(0, base.x(), path.point_ranges[k], "the base x of " + point);
        CheckInLimit(1, base.y(), path.point_ranges[k], "the base y of " + point);
      }
    }
  }
  if (scan_z) CheckInLimit(2, scan_z->value, keys.KeyRange("scan_z_mm"), "'scan_z_mm'");
  if (place_z) CheckInLimit(2, place_z->value, keys.KeyRange("place_z_mm"), "'place_z_mm'");
  if (Dropped(errors_before, limit_errors_before)) return std::nullopt;
  return fixture;
}

// ------------------------------------------------------------------ feeders

std::optional<Feeder> Loader::ReadFeeder(const toml::table& table, int index,
                                         std::vector<Located<std::string>>& names) {
  const std::size_t errors_before = diags_.error_count(), limit_errors_before = limit_errors_;
  Feeder feeder;
  feeder.range = Range(table);
  Keys keys(*this, table, fmt::format("[[feeder]] {}", index + 1), feeder.range);
  if (auto name = Name(keys, "a string naming the feeder")) {
    feeder.name = name->value;
    feeder.name_range = name->range;
    keys.set_what(Title("feeder", name, "feeder", index));
    names.push_back(*name);
  }
  const std::string title = fmt::format("feeder '{}'", Printable(feeder.name));
  std::optional<Located<std::array<double, 4>>> pick = Point4At(keys, "pick", Need::kRequired);
  if (pick) feeder.pick = pick->value;

  const char* package_expected = "a package name, or an array of package names";
  if (const toml::node* package = keys.Get("package")) {
    if (package->is_string()) {
      feeder.packages.push_back(*package->value<std::string>());
    } else if (const toml::array* list = package->as_array(); list != nullptr && !list->empty()) {
      for (std::size_t i = 0; i < list->size(); ++i) {
        if (list->get(i)->is_string()) {
          feeder.packages.push_back(*list->get(i)->value<std::string>());
        } else {
          ReportWrongType(keys, *list->get(i), fmt::format("item {} of 'package'", i + 1), "a package name");
        }
      }
    } else {
      ReportWrongType(keys, *package, "'package'", package_expected);
    }
    if (!feeder.packages.empty()) feeder.package = feeder.packages.front();
  }
  if (auto value = String(keys, "value", Need::kOptional, "a string: the part value it holds")) {
    feeder.value = value->value;
  }
  std::optional<int> kind = Choice(keys, "kind", kFeederKindNames);
  feeder.kind_range = kind ? keys.KeyRange("kind") : feeder.range;

  const toml::table* pallet = TableAt(keys, "pallet", Need::kOptional,
                                      "a table { last = [x, y, z, u], back = [x, y, z, u], columns = N, rows = N }");
  std::optional<Located<std::array<double, 4>>> last, back;
  if (pallet != nullptr) {
    Keys pallet_keys(*this, *pallet, fmt::format("the pallet of {}", title), Range(*pallet));
    last = Point4At(pallet_keys, "last", Need::kRequired);
    back = Point4At(pallet_keys, "back", Need::kRequired);
    std::optional<int> columns =
        WholeIn(pallet_keys, "columns", limits::kPalletCount, "pick points from pick to last");
    std::optional<int> rows = WholeIn(pallet_keys, "rows", limits::kPalletCount, "pick points from pick to back");
    pallet_keys.Finish();
    if (last) feeder.pallet_last = last->value;
    if (back) feeder.pallet_back = back->value;
    feeder.columns = columns.value_or(1);
    feeder.rows = rows.value_or(1);
  }
  keys.Finish();
  const int pick_points = feeder.columns * feeder.rows;
  feeder.kind = kind ? static_cast<FeederKind>(*kind)
                     : pallet != nullptr && !(pick_points > 1 && static_cast<int>(feeder.packages.size()) == pick_points)
                         ? FeederKind::kTray
                         : FeederKind::kTape;
  if (feeder.kind == FeederKind::kTray && pallet == nullptr) {
    diags_.Report(DiagKind::CellMissingKey, feeder.kind_range, title, "pallet",
                  "a tray is a pallet of pockets, pallet = { last = [x, y, z, u], back = [x, y, z, u], columns = N, "
                  "rows = N }; a single pick point is a tape (kind = \"tape\")");
  }

  const std::size_t errors_before_limits = diags_.error_count();
  if (pick) CheckPointInLimits(pick->value, pick->range, fmt::format("'pick' of {}", title));
  if (last) CheckPointInLimits(last->value, last->range, fmt::format("'last' of the pallet of {}", title));
  if (back) CheckPointInLimits(back->value, back->range, fmt::format("'back' of the pallet of {}", title));
  if (pick && last && back && diags_.error_count() == errors_before_limits) {
    // The pallet is a parallelogram: its fourth corner is reached too.
    std::array<double, 4> far{};
    for (std::size_t i = 0; i < 4; ++i) far[i] = last->value[i] + back->value[i] - pick->value[i];
    CheckPointInLimits(far, keys.KeyRange("pallet"),
                       fmt::format("the far corner (last + back - pick) of the pallet of {}", title));
  }
  if (Dropped(errors_before, limit_errors_before)) return std::nullopt;
  return feeder;
}

// ------------------------------------------------------------------ the file

// ------------------------------------------------------------------ linuxcnc

std::optional<LinuxCnc> Loader::ReadLinuxCnc(const toml::table& table) {
  const std::size_t errors_before = diags_.error_count();
  Keys keys(*this, table, "[linuxcnc]", Range(table));
  LinuxCnc linuxcnc;
  linuxcnc.range = Range(table);
  if (std::optional<int> axis = Choice(keys, "rotation_axis", kRotationAxisNames)) {
    linuxcnc.rotation_axis = kRotationAxisNames[static_cast<std::size_t>(*axis)][0];
  }
  linuxcnc.vacuum_sensor_input =
      WholeIn(keys, "vacuum_sensor_input", limits::kLinuxCncInput, "motion.digital-in-NN").value_or(0);
  linuxcnc.vacuum_timeout_s = NumberIn(keys, "vacuum_timeout_s", limits::kTimeoutS).value_or(0);
  // The cycle record: names LinuxCNC takes as they are written in a comment
  // (LOGOPEN, #<_hal[...]>), so no parentheses, no spaces at their ends.
  if (auto file = String(keys, "record_file", Need::kOptional, "a string: the log file's path")) {
    linuxcnc.record_file_range = file->range;
    const bool plain = !file->value.empty() && file->value.size() <= 200 &&
                       file->value.find_first_of("()#%\n\r\t;") == std::string::npos && file->value.front() != ' ' &&
                       file->value.back() != ' ';
    if (!plain) {
      diags_.Report(DiagKind::CellWrongType, file->range, "'record_file'",
                    "a path of 1 to 200 characters without ( ) # % ; tabs or line ends, and no space at either end "
                    "(LinuxCNC's LOGOPEN takes it as written)",
                    fmt::format("'{}'", Printable(file->value)));
    } else {
      linuxcnc.record_file = file->value;
    }
  }
  if (keys.Get("record_max_cycles") != nullptr) {
    linuxcnc.record_max_cycles =
        WholeIn(keys, "record_max_cycles", limits::kRecordMaxCycles, "scans per file").value_or(kDefaultRecordMaxCycles);
  }
  if (auto pin = String(keys, "record_clock_pin", Need::kOptional, "a string: a HAL pin's name")) {
    const bool plain = !pin->value.empty() && pin->value.size() <= 47 &&
                       std::all_of(pin->value.begin(), pin->value.end(), [](char c) {
                         return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
                       });
    if (!plain) {
      diags_.Report(DiagKind::CellWrongType, pin->range, "'record_clock_pin'",
                    "a HAL pin's name: 1 to 47 lowercase letters, digits, '.', '_' or '-' (LinuxCNC's interpreter "
                    "reads #<_hal[...]> in lowercase)",
                    fmt::format("'{}'", Printable(pin->value)));
    } else {
      linuxcnc.record_clock_pin = pin->value;
    }
  }
  keys.Finish();
  if (diags_.error_count() != errors_before) return std::nullopt;
  return linuxcnc;
}

// ------------------------------------------------------------------ measure

std::optional<Measure> Loader::ReadMeasure(const toml::table& table) {
  const std::size_t errors_before = diags_.error_count();
  Keys keys(*this, table, "[measure]", Range(table));
  Measure m;
  m.range = Range(table);
  m.device_range = keys.KeyRange("device");
  if (Lookup(keys, "device", Need::kRequired, "one of 'transducer', 'probe' or 'external'") != nullptr) {
    if (std::optional<int> device = Choice(keys, "device", kMeasureDeviceNames)) {
      m.device = static_cast<MeasureDevice>(*device);
    }
  }
  if (auto z = Number(keys, "z_mm", Need::kRequired, limits::kPositionMm)) {
    m.z_mm = z->value;
    CheckInLimit(2, m.z_mm, z->range, "'z_mm' of [measure]");
  }
  m.clear_z_mm = robot_.safe_limz_mm;
  if (auto clear = Number(keys, "clear_z_mm", Need::kOptional, limits::kPositionMm)) {
    m.clear_z_mm = clear->value;
    CheckInLimit(2, m.clear_z_mm, clear->range, "'clear_z_mm' of [measure]");
    if (m.clear_z_mm <= m.z_mm) {
      diags_.Report(DiagKind::CellValueOutOfRange, clear->range, "'clear_z_mm'", Num(clear->value),
                    fmt::format("above z_mm = {}", Num(m.z_mm)));
    }
  }
  if (auto dwell = NumberIn(keys, "dwell_s", limits::kMeasureDwellS, Need::kOptional)) m.dwell_s = *dwell;
  if (auto reading = NumberIn(keys, "reading_time_s", limits::kDwellS, Need::kOptional)) m.reading_time_s = *reading;
  m.noise_mm = NumberIn(keys, "noise_mm", limits::kAccuracyMm).value_or(0);
  if (auto timeout = NumberIn(keys, "timeout_s", limits::kTimeoutS, Need::kOptional)) m.timeout_s = *timeout;
  if (keys.Get("ready_input") != nullptr) {
    m.ready_input = WholeIn(keys, "ready_input", limits::kLinuxCncInput, "motion.digital-in-NN");
  }
  m.placement_mm = NumberIn(keys, "placement_mm", limits::kPlacementMm, Need::kOptional);
  m.placement_deg = NumberIn(keys, "placement_deg", limits::kPlacementDeg, Need::kOptional).value_or(0.1);
  if (auto u = Number(keys, "u_deg", Need::kOptional, limits::kAngleDeg)) {
    m.u_deg = u->value;
    CheckInLimit(3, m.u_deg, u->range, "'u_deg' of [measure]");
  }
  m.artefact_pitch_error_ppm =
      NumberIn(keys, "artefact_pitch_error_ppm", limits::kArtefactPitchPpm, Need::kOptional).value_or(0);
  m.artefact_pitch_u_ppm = NumberIn(keys, "artefact_pitch_u_ppm", limits::kArtefactPitchUPpm, Need::kOptional).value_or(0);
  // The device's own table: required for the device named, refused for the others.
  for (std::size_t d = 0; d < kMeasureDeviceNames.size(); ++d) {
    const std::string_view name = kMeasureDeviceNames[d];
    const bool wanted = static_cast<std::size_t>(m.device) == d;
    const toml::table* device =
        TableAt(keys, name, wanted ? Need::kRequired : Need::kOptional, fmt::format("a [measure.{}] table", name));
    if (device == nullptr) continue;
    if (!wanted) {
      diags_.Report(DiagKind::CellUnknownKey, keys.KeyRange(name), Printable(std::string(name)), "[measure]",
                    fmt::format(" (the device is '{}': its table is [measure.{}])",
                                kMeasureDeviceNames[static_cast<std::size_t>(m.device)],
                                kMeasureDeviceNames[static_cast<std::size_t>(m.device)]));
      continue;
    }
    Keys sub(*this, *device, fmt::format("[measure.{}]", name), Range(*device));
    if (m.device == MeasureDevice::kTransducer) {
      MeasureTransducer& t = m.transducer;
      t.input = WholeIn(sub, "input", limits::kLinuxCncInput, "motion.analog-in-NN").value_or(0);
      t.reference_input = WholeIn(sub, "reference_input", limits::kLinuxCncInput, "motion.analog-in-NN").value_or(0);
      if (auto slope = Number(sub, "slope", Need::kRequired, limits::kTransducerSlope)) {
        if (std::abs(slope->value) < 0.1) {
          diags_.Report(DiagKind::CellValueOutOfRange, slope->range, "'slope'", Num(slope->value),
                        "within 0.1 to 10 in size (a 45 degree flank: 1 or -1)");
        } else {
          t.slope = slope->value;
        }
      }
      if (auto zero = Number(sub, "zero_mm", Need::kOptional, limits::kPositionMm)) t.zero_mm = zero->value;
      if (auto range = IntervalAt(sub, "range_mm", Need::kRequired, limits::kPositionMm)) t.range_mm = range->value;
      t.groove_pitch_mm = NumberIn(sub, "groove_pitch_mm", limits::kLengthMm).value_or(1);
      t.grooves = WholeIn(sub, "grooves", limits::kTransducerGrooves, "grooves per direction").value_or(2);
    } else if (m.device == MeasureDevice::kProbe) {
      MeasureProbe& p = m.probe;
      p.hole_diameter_mm = NumberIn(sub, "hole_diameter_mm", limits::kLengthMm).value_or(0);
      p.hole_pitch_mm = NumberIn(sub, "hole_pitch_mm", limits::kLengthMm).value_or(1);
      p.stylus_diameter_mm = NumberIn(sub, "stylus_diameter_mm", limits::kLengthMm).value_or(0);
      p.speed_mm_s = NumberIn(sub, "speed_mm_s", limits::kSpeedMmS).value_or(1);
      p.overtravel_mm = NumberIn(sub, "overtravel_mm", limits::kLengthMm).value_or(0.5);
      if (sub.Get("holes") != nullptr) {
        p.holes = WholeIn(sub, "holes", limits::kProbeHoles, "holes per direction").value_or(0);
      }
      p.hole_diameter_u_mm = NumberIn(sub, "hole_diameter_u_mm", limits::kDiameterUMm, Need::kOptional).value_or(0);
      p.stylus_diameter_u_mm =
          NumberIn(sub, "stylus_diameter_u_mm", limits::kDiameterUMm, Need::kOptional).value_or(0);
    } else {
      MeasureExternal& e = m.external;
      e.trigger_output = WholeIn(sub, "trigger_output", limits::kLinuxCncInput, "motion.digital-out-NN").value_or(0);
      e.done_input = WholeIn(sub, "done_input", limits::kLinuxCncInput, "motion.digital-in-NN").value_or(0);
      e.node_output = WholeIn(sub, "node_output", limits::kExternalNodeOutput,
                              "motion.analog-out-NN; the set and repetition go on the next two").value_or(0);
    }
    sub.Finish();
  }
  keys.Finish();
  if (diags_.error_count() != errors_before) return std::nullopt;
  return m;
}

std::string DefaultCellName(const std::string& path) {
  if (path == "-") return "cell";
  std::string name = std::filesystem::path(path).filename().string();
  for (std::string_view suffix : {".cell.toml", ".toml"}) {
    if (name.size() > suffix.size() && name.ends_with(suffix)) return name.substr(0, name.size() - suffix.size());
  }
  return name;
}

std::optional<Cell> Loader::Load(const toml::table& root, const std::string& path) {
  const std::size_t errors_before = diags_.error_count();
  Cell cell;
  cell.path = path;
  cell.file = file_;
  Keys keys(*this, root, "the cell file", WholeFile());
  auto name = String(keys, "name", Need::kOptional, "a string naming the cell");
  cell.name = name ? name->value : DefaultCellName(path);

  // [robot] first: the other sections are checked against its limits.
  if (const toml::table* robot = TableAt(keys, "robot", Need::kRequired, "a [robot] table")) {
    ReadRobot(*robot, cell.robot);
  }
  std::vector<Located<std::string>> region_names, fixture_names, feeder_names;
  std::vector<const toml::table*> regions = TablesAt(keys, "region", Need::kOptional);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (auto region = ReadRegion(*regions[i], static_cast<int>(i), region_names)) {
      cell.regions.push_back(std::move(*region));
    }
  }
  std::vector<const toml::table*> fixtures = TablesAt(keys, "fixture", Need::kOptional);
  for (std::size_t i = 0; i < fixtures.size(); ++i) {
    if (auto fixture = ReadFixture(*fixtures[i], static_cast<int>(i), fixture_names)) {
      cell.fixtures.push_back(std::move(*fixture));
    }
  }
  std::vector<const toml::table*> feeders = TablesAt(keys, "feeder", Need::kOptional);
  for (std::size_t i = 0; i < feeders.size(); ++i) {
    if (auto feeder = ReadFeeder(*feeders[i], static_cast<int>(i), feeder_names)) {
      cell.feeders.push_back(std::move(*feeder));
    }
  }
  if (const toml::table* linuxcnc = TableAt(keys, "linuxcnc", Need::kOptional, "a [linuxcnc] table")) {
    cell.linuxcnc = ReadLinuxCnc(*linuxcnc);
  }
  if (const toml::table* measure = TableAt(keys, "measure", Need::kOptional, "a [measure] table")) {
    cell.measure = ReadMeasure(*measure);
  }
  keys.Finish();

  CheckUniqueNames(region_names, "region");
  CheckUniqueNames(fixture_names, "fixture");
  CheckUniqueNames(feeder_names, "feeder");
  CheckRegionOverlaps(cell.regions);
  // keep_drawable: the cell as far as it was read, whatever else is wrong.
  if (diags_.error_count() != errors_before && !options_.keep_drawable) return std::nullopt;
  for (Region& region : cell.regions) {
    // A region planned for measuring has no table yet: nothing to estimate.
    if (region.has_table) region.interpolation = RegionInterpolation(cell.robot, region.table);
  }
  RecordFiles(cell);
  return cell;
}

void Loader::RecordFiles(Cell& cell) const {
  cell.files.push_back({false, cell.path, Sha256Hex(sources_.File(file_).text), {}});
  for (const Region& region : cell.regions) {
    if (!region.has_table) continue;  // planned for measuring: no table file yet
    auto same = std::find_if(cell.files.begin() + 1, cell.files.end(),
                             [&](const CellFile& file) { return file.path == region.table_path; });
    if (same == cell.files.end()) {
      cell.files.push_back({true, region.table_path, Sha256Hex(sources_.File(region.table_file).text), {}});
      same = cell.files.end() - 1;
    }
    same->regions.push_back(region.name);
  }
}

// "Error while parsing key-value pair: expected ..." -> "expected ... (while parsing key-value pair)".
std::string ParseErrorText(std::string_view description) {
  constexpr std::string_view kPrefix = "Error while parsing ";
  std::size_t colon = description.find(": ");
  if (!description.starts_with(kPrefix) || colon == std::string_view::npos) return Printable(description);
  std::string_view what = description.substr(kPrefix.size(), colon - kPrefix.size());
  return fmt::format("{} (while parsing {})", Printable(description.substr(colon + 2)), Printable(what));
}

}  // namespace

// ------------------------------------------------------------------ public

Result<std::optional<Cell>> LoadCell(const std::string& path, SourceManager& sources, Diagnostics& diags) {
  return LoadCell(path, sources, diags, CellLoadOptions{});
}

Result<std::optional<Cell>> LoadCell(const std::string& path, SourceManager& sources, Diagnostics& diags,
                                     const CellLoadOptions& options) {
  Result<std::uint32_t> file = sources.Load(path);
  if (!file) return file.error();
  const SourceFile& source = sources.File(file.value());
  std::filesystem::path dir = path == "-" ? std::filesystem::path() : std::filesystem::path(path).parent_path();
  Loader loader(sources, diags, file.value(), dir, options);
  toml::table root;
  try {
    root = toml::parse(std::string_view(source.text), std::string_view(source.name));
  } catch (const toml::parse_error& error) {
    // Not TOML: another of smtcal's files given as the cell says so in one message.
    if (ReportOtherInputKind(file.value(), {InputKind::kCell, InputKind::kToml}, "a cell file", diags)) {
      return std::optional<Cell>();
    }
    diags.Report(DiagKind::CellTomlSyntax, SourceRange(loader.At(error.source().begin)),
                 ParseErrorText(error.description()));
    return std::optional<Cell>();
  }
  return loader.Load(root, path);
}

// What a clean cell can still get wrong about its scan: trips no table
// calibrates, and a probe latch late by more than the line-residual check
// can take (docs/cell.md, "Trips and their errors").
static void CheckScanErrors(const Fixture& fixture, const Cell& cell, Diagnostics& diags) {
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const std::vector<int> regions = TripRegions(fixture, cell.regions);
  const std::vector<TripWindow> windows = TripWindows(fixture);
  const std::string accuracy =
      cell.robot.uncalibrated_accuracy_mm
          ? fmt::format("up to robot.uncalibrated_accuracy_mm = {} mm", Num(*cell.robot.uncalibrated_accuracy_mm))
          : std::string("not declared: robot.uncalibrated_accuracy_mm");
  for (std::size_t k = 0; k < expected.size(); ++k) {
    if (regions[k] >= 0) continue;
    const ScanPath& path = fixture.scan_paths[expected[k].path];
    diags.Report(DiagKind::CellTripUncalibrated, path.range, TripName(k), Printable(fixture.name),
                  fixture.edges[static_cast<std::size_t>(expected[k].edge)].name, Printable(path.name),
                  fmt::format("{:.3f}", windows[k].nominal.x()), fmt::format("{:.3f}", windows[k].nominal.y()),
                  Num(fixture.trip_window_mm), accuracy);
  }
  const double late_mm = fixture.TripLatchSpeedMmS() * cell.robot.servo_period_s;
  if (late_mm > 0.25 * fixture.max_line_residual_mm) {
    const bool two_stage = fixture.latch_speed_mm_s > 0;
    diags.Report(DiagKind::CellTripLatency, two_stage ? fixture.latch_speed_range : fixture.scan_speed_range,
                  Printable(fixture.name), two_stage ? "latches its trips" : "scans",
                  Num(fixture.TripLatchSpeedMmS()), Num(cell.robot.servo_period_s), fmt::format("{:.4g}", late_mm),
                  Num(fixture.max_line_residual_mm), two_stage ? "latch_speed_mm_s" : "scan_speed_mm_s");
  }
  const CaptureRange capture = ScanCaptureRange(fixture);
  if (capture.factor < 1) {
    const ScanPath& first = fixture.scan_paths.front();
    diags.Report(DiagKind::CellScanCaptureRange, first.range, Printable(fixture.name),
                  fmt::format("{:.2f}", capture.shift_mm), fmt::format("{:.2f}", capture.rotation_deg),
                  fmt::format("{:.2f}", capture.factor), capture.limited_by, Num(fixture.max_shift_mm),
                  Num(fixture.max_rotation_deg));
  }
}

void CheckScanCalibration(const Cell& cell, Diagnostics& diags) {
  for (const Fixture& fixture : cell.fixtures) CheckScanErrors(fixture, cell, diags);
}

std::array<Point2, 4> PocketCornersInBase(const Fixture& fixture) {
  SMTCAL_CHECK(fixture.pocket_mm.has_value(), "PocketCornersInBase needs a pocket");
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const auto& [x, y] = *fixture.pocket_mm;
  return {ToBase(nominal, {x.lo, y.lo}), ToBase(nominal, {x.hi, y.lo}), ToBase(nominal, {x.hi, y.hi}),
          ToBase(nominal, {x.lo, y.hi})};
}

// A length computed from the cell's numbers, to the micrometre.
static std::string Micro(double mm) { return Num(std::round(mm * 1e3) / 1e3 + 0.0); }

void CheckPockets(const Cell& cell, Diagnostics& diags) {
  // A cell with no calibrated region yet has nothing to hold a pocket to
  // (`smtcal import` does not check its boards either).
  if (cell.regions.empty()) return;
  for (const Fixture& fixture : cell.fixtures) {
    if (!fixture.pocket_mm) continue;
    const std::array<Point2, 4> corners = PocketCornersInBase(fixture);
    const RegionFit fit = FitInRegion(cell, {corners.begin(), corners.end()});
    if (fit.fits()) continue;
    std::string how, advice;
    if (fit.region == nullptr) {
      how = "lies outside every calibrated region";
      advice = "move the pocket onto a region, or calibrate one under it";
    } else {
      const Region& region = *fit.region;
      const std::string extent =
          fmt::format("region '{}' (x {}..{}, y {}..{} mm, {} x {} mm)", Printable(region.name), Num(region.x_mm.lo),
                      Num(region.x_mm.hi), Num(region.y_mm.lo), Num(region.y_mm.hi),
                      Micro(region.x_mm.hi - region.x_mm.lo), Micro(region.y_mm.hi - region.y_mm.lo));
      if (fit.larger()) {
        how = fmt::format("is larger than {}", extent);
        advice = "make the pocket no larger than the region, or calibrate a larger region";
      } else {
        std::vector<std::string> past;
        if (fit.past_x_lo > kRegionFitSlackMm) past.push_back(fmt::format("{} mm past x = {}", Micro(fit.past_x_lo), Num(region.x_mm.lo)));
        if (fit.past_x_hi > kRegionFitSlackMm) past.push_back(fmt::format("{} mm past x = {}", Micro(fit.past_x_hi), Num(region.x_mm.hi)));
        if (fit.past_y_lo > kRegionFitSlackMm) past.push_back(fmt::format("{} mm past y = {}", Micro(fit.past_y_lo), Num(region.y_mm.lo)));
        if (fit.past_y_hi > kRegionFitSlackMm) past.push_back(fmt::format("{} mm past y = {}", Micro(fit.past_y_hi), Num(region.y_mm.hi)));
        how = fmt::format("sticks out of {}: {}", extent, fmt::join(past, " and "));
        // The pocket moved so its centre is the region's: in the fixture frame.
        const Eigen::Affine3d nominal = NominalFix(fixture);
        const Point2 move = nominal.linear().topLeftCorner<2, 2>().transpose() * fit.CentringMove();
        const auto& [x, y] = *fixture.pocket_mm;
        advice = fmt::format("pocket_x_mm = [{}, {}], pocket_y_mm = [{}, {}] centres it on the region; or "
                             "calibrate a larger region",
                             Micro(x.lo + move.x()), Micro(x.hi + move.x()), Micro(y.lo + move.y()),
                             Micro(y.hi + move.y()));
      }
    }
    diags.Report(DiagKind::CellPocketOverRegion, fixture.pocket_range, Printable(fixture.name), Micro(fit.x_lo),
                 Micro(fit.x_hi), Micro(fit.y_lo), Micro(fit.y_hi), Micro(fit.width()), Micro(fit.height()), how,
                 advice);
  }
}

void ReportTableWarnings(const Cell& cell, Diagnostics& diags) {
  std::vector<std::string> reported;  // table files, as loaded
  for (const Region& region : cell.regions) {
    if (std::find(reported.begin(), reported.end(), region.table.name) != reported.end()) continue;
    reported.push_back(region.table.name);
    std::string summary;
    for (const std::string& line : SummarizeTableWarnings(region.table)) summary += (summary.empty() ? "" : "; ") + line;
    if (summary.empty()) continue;
    diags.Report(DiagKind::CellTableWarnings, region.table_range, Printable(region.table_path), Printable(region.name),
                 summary, Printable(region.table.name));
  }
}

void ReportGridAdvice(const Cell& cell, Diagnostics& diags) {
  for (const Region& region : cell.regions) {
    ReportCoarseGrid(region.interpolation, region.tolerance_mm,
                     fmt::format("region '{}''s table", Printable(region.name)), region.table_range, diags);
  }
}

}  // namespace smtcal::cell

// Reading the truth file of `smtcal simulate` (frontend/truth_toml.h).
#include "frontend/truth_toml.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "base/field_text.h"
#include "base/number_range.h"
#include "calibration/limits.h"
#include "calibration/truth_spec.h"
#include "calibration/error_table_check.h"
#include "frontend/table_csv.h"
#include "frontend/input_kind.h"
#include "frontend/toml_source.h"

namespace smtcal {
namespace {

// 'a', 'b' and 'c' (or: 'a', 'b' or 'c').
std::string Listed(const std::vector<std::string>& names, std::string_view last = " and ") {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? std::string() : i + 1 == names.size() ? std::string(last) : std::string(", ")) +
            fmt::format("'{}'", names[i]);
  }
  return text.empty() ? "none" : text;
}

class Reader {
 public:
  Reader(SourceManager& sources, std::uint32_t file, const cell::Cell& cell, Diagnostics& diags,
         std::filesystem::path dir)
      : sources_(sources), file_(file), cell_(cell), diags_(diags), dir_(std::move(dir)), locator_(sources, file) {}

  SourceLoc At(const toml::source_position& position) const { return locator_.At(position); }
  SourceRange Range(const toml::node& node) const { return locator_.Range(node); }

  std::optional<TruthSpec> Read(const toml::table& root, const std::string& path) {
    const std::size_t errors_before = diags_.error_count();
    TruthSpec spec;
    spec.path = path;
    CheckKeys(root, "the truth file", {"noise", "field", "region", "board", "sensor", "robot", "drift"});
    if (std::optional<bool> noise = Bool(root, "noise")) spec.noise = *noise;
    if (const toml::table* field = Table(root, "field")) ReadField(*field, spec);
    if (const toml::table* board = Table(root, "board")) ReadBoard(*board, spec.board);
    if (const toml::table* sensor = Table(root, "sensor")) {
      CheckKeys(*sensor, "[sensor]", {"accuracy_mm"});
      spec.sensor_accuracy_mm = Number(*sensor, "accuracy_mm", Closed(0, 5, "mm"));
    }
    if (const toml::table* robot = Table(root, "robot")) {
      CheckKeys(*robot, "[robot]",
                {"repeatability_mm", "uncalibrated_accuracy_mm", "uncalibrated_correlation_mm", "servo_period_s"});
      spec.repeatability_mm = Number(*robot, "repeatability_mm", Closed(0, 5, "mm"));
      spec.uncalibrated_accuracy_mm = Number(*robot, "uncalibrated_accuracy_mm", Closed(0, 10, "mm"));
      spec.uncalibrated_correlation_mm = Number(*robot, "uncalibrated_correlation_mm", limits::kCorrelationMm);
      if (spec.uncalibrated_correlation_mm) CheckTrueFieldGrid(*robot, *spec.uncalibrated_correlation_mm);
      spec.servo_period_s = Number(*robot, "servo_period_s", Closed(0, 1, "s"));
    }
    if (const toml::table* drift = Table(root, "drift")) ReadDrift(*drift, spec.drift);
    for (const toml::table* region : Tables(root, "region")) ReadRegion(*region, spec);
    if (diags_.error_count() != errors_before) return std::nullopt;
    return spec;
  }

 private:
  void ReadField(const toml::table& table, TruthSpec& spec) {
    CheckKeys(table, "[field]",
              {"tables", "perturbation_scale", "interpolation_scale", "outside", "fade_mm", "offset_mm",
               "rotation_deg", "about_mm", "scale_ppm"});
    if (std::optional<int> tables = Choice(table, "tables", {"derived", "cell", "none"})) {
      spec.tables = static_cast<TruthTables>(*tables);
    }
    spec.perturbation_scale = Number(table, "perturbation_scale", Closed(0, 100, "")).value_or(spec.perturbation_scale);
    spec.interpolation_scale = Number(table, "interpolation_scale", Closed(0, 100, "")).value_or(spec.interpolation_scale);
    if (std::optional<int> outside = Choice(table, "outside", {"field", "fade", "clamp"})) {
      spec.outside = static_cast<TruthOutside>(*outside);
    }
    spec.fade_mm = Number(table, "fade_mm", Closed(0, 1000, "mm")).value_or(spec.fade_mm);
    spec.offset_mm = Point(table, "offset_mm", 10).value_or(spec.offset_mm);
    spec.rotation_deg = Number(table, "rotation_deg", Closed(-5, 5, "deg")).value_or(spec.rotation_deg);
    spec.about_mm = Point(table, "about_mm", 1e5).value_or(spec.about_mm);
    spec.scale_ppm = Number(table, "scale_ppm", Closed(-1e4, 1e4, "ppm")).value_or(spec.scale_ppm);
  }

  void ReadBoard(const toml::table& table, BoardPoseModel& board) {
    CheckKeys(table, "[board]",
              {"shift", "shift_scale_mm", "shift_max_mm", "fixed_shift_mm", "rotation_sd_deg", "rotation_max_deg",
               "fixed_rotation_deg"});
    if (std::optional<int> shift = Choice(table, "shift", {"exponential", "normal", "uniform", "fixed"})) {
      board.shift = static_cast<ShiftDistribution>(*shift);
    }
    board.shift_scale_mm = Number(table, "shift_scale_mm", Closed(0, 10, "mm")).value_or(board.shift_scale_mm);
    board.shift_max_mm = Number(table, "shift_max_mm", Closed(0, 50, "mm")).value_or(board.shift_max_mm);
    board.fixed_shift_mm = Point(table, "fixed_shift_mm", 50).value_or(board.fixed_shift_mm);
    board.rotation_sd_deg = Number(table, "rotation_sd_deg", Closed(0, 5, "deg")).value_or(board.rotation_sd_deg);
    board.rotation_max_deg = Number(table, "rotation_max_deg", Closed(0, 10, "deg")).value_or(board.rotation_max_deg);
    board.fixed_rotation_deg = Number(table, "fixed_rotation_deg", Closed(-10, 10, "deg")).value_or(board.fixed_rotation_deg);
  }

  void ReadDrift(const toml::table& table, DriftModel& drift) {
    CheckKeys(table, "[drift]",
              {"start_cycle", "board_mm_per_cycle", "board_deg_per_cycle", "robot_scale_ppm_per_cycle",
               "robot_scale_about_mm", "sensor_threshold_mm_per_cycle", "sensor_accuracy_mm_per_cycle"});
    if (std::optional<double> start = Number(table, "start_cycle", Whole(0, 1e6))) {
      drift.start_cycle = static_cast<long>(*start);
    }
    drift.board_mm_per_cycle = Point(table, "board_mm_per_cycle", 0.1).value_or(drift.board_mm_per_cycle);
    drift.board_deg_per_cycle = Number(table, "board_deg_per_cycle", Closed(-0.01, 0.01, "deg")).value_or(0);
    drift.robot_scale_ppm_per_cycle = Number(table, "robot_scale_ppm_per_cycle", Closed(-100, 100, "ppm")).value_or(0);
    drift.robot_scale_about_mm = Point(table, "robot_scale_about_mm", 1e5).value_or(drift.robot_scale_about_mm);
    drift.sensor_threshold_mm_per_cycle = Number(table, "sensor_threshold_mm_per_cycle", Closed(-0.01, 0.01, "mm")).value_or(0);
    drift.sensor_accuracy_mm_per_cycle = Number(table, "sensor_accuracy_mm_per_cycle", Closed(0, 0.01, "mm")).value_or(0);
  }

  void ReadRegion(const toml::table& table, TruthSpec& spec) {
    CheckKeys(table, "[[region]]", {"name", "table"});
    SourceRange name_range = Range(table);
    std::optional<std::string> name = String(table, "name", &name_range);
    SourceRange table_range = Range(table);
    std::optional<std::string> file = String(table, "table", &table_range);
    for (std::string_view key : {"name", "table"}) {
      if (!table.contains(key)) {
        diags_.Report(DiagKind::TruthWrongType, Range(table), key, "given in every [[region]]", "nothing");
      }
    }
    if (!name || !file) return;
    const cell::Region* region = cell_.FindRegion(*name);
    if (region == nullptr) {
      std::vector<std::string> names;
      for (const cell::Region& r : cell_.regions) names.push_back(r.name);
      diags_.Report(DiagKind::TruthUnknownRegion, name_range, Printable(*name), Listed(names));
      return;
    }
    for (const TruthRegionTable& given : spec.region_tables) {
      if (AsciiLowercase(given.region) != AsciiLowercase(region->name)) continue;
      diags_.Report(DiagKind::TruthDuplicateRegion, name_range, region->name, given.range.begin.line);
      return;
    }
    std::filesystem::path table_path = std::filesystem::path(*file);
    if (table_path.is_relative()) table_path = dir_ / table_path;
    Result<std::uint32_t> loaded = sources_.Load(table_path.string());
    if (!loaded) {
      diags_.Report(DiagKind::TruthTableUnreadable, table_range, loaded.error().message);
      return;
    }
    std::optional<ErrorTable> read = ReadErrorTable(loaded.value(), diags_);
    if (!read || !ValidateErrorTable(*read, diags_, TableWarnings::kSkip)) return;
    spec.region_tables.push_back({region->name, std::move(*read), name_range});
  }

  void CheckKeys(const toml::table& table, std::string_view where, std::vector<std::string> known) {
    for (const auto& [key, node] : table) {
      (void)node;
      if (std::find(known.begin(), known.end(), key.str()) != known.end()) continue;
      std::string closest = ClosestName(key.str(), known);
      diags_.Report(DiagKind::TruthUnknownKey, locator_.Range(key.source()), Printable(key.str()), where,
                    closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest), Listed(known));
    }
  }

  const toml::table* Table(const toml::table& root, std::string_view key) {
    const toml::node* node = root.get(key);
    if (node == nullptr) return nullptr;
    if (!node->is_table()) {
      diags_.Report(DiagKind::TruthWrongType, Range(*node), key, fmt::format("a table written [{}]", key),
                    TomlTypeName(*node));
      return nullptr;
    }
    return node->as_table();
  }

  std::vector<const toml::table*> Tables(const toml::table& root, std::string_view key) {
    std::vector<const toml::table*> tables;
    const toml::node* node = root.get(key);
    if (node == nullptr) return tables;
    const toml::array* array = node->as_array();
    if (array == nullptr || !array->is_array_of_tables()) {
      diags_.Report(DiagKind::TruthWrongType, Range(*node), key, fmt::format("tables written [[{}]]", key),
                    TomlTypeName(*node));
      return tables;
    }
    for (const toml::node& item : *array) tables.push_back(item.as_table());
    return tables;
  }

  std::optional<bool> Bool(const toml::table& table, std::string_view key) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    if (!node->is_boolean()) {
      diags_.Report(DiagKind::TruthWrongType, Range(*node), key, "true or false", TomlTypeName(*node));
      return std::nullopt;
    }
    return *node->value<bool>();
  }

  std::optional<std::string> String(const toml::table& table, std::string_view key, SourceRange* range = nullptr) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    if (range != nullptr) *range = Range(*node);
    if (!node->is_string()) {
      diags_.Report(DiagKind::TruthWrongType, Range(*node), key, "a string", TomlTypeName(*node));
      return std::nullopt;
    }
    return *node->value<std::string>();
  }

  // One of `choices`, as its index.
  std::optional<int> Choice(const toml::table& table, std::string_view key, std::vector<std::string> choices) {
    SourceRange range;
    std::optional<std::string> value = String(table, key, &range);
    if (!value) return std::nullopt;
    for (std::size_t i = 0; i < choices.size(); ++i) {
      if (choices[i] == *value) return static_cast<int>(i);
    }
    diags_.Report(DiagKind::TruthBadValue, range, key, fmt::format("one of {}", Listed(choices, " or ")),
                  fmt::format("'{}'", Printable(*value)));
    return std::nullopt;
  }

  // A number in `range`: the one check of base/number_range.h.
  std::optional<double> NumberOf(const toml::node& node, std::string_view key, const NumberRange& range) {
    if (!node.is_number()) {
      diags_.Report(DiagKind::TruthWrongType, Range(node), key, "a number", TomlTypeName(node));
      return std::nullopt;
    }
    const double value = TomlNumber(node);
    if (!InRange(value, range)) {
      diags_.Report(DiagKind::TruthBadValue, Range(node), key, RangeText(range), TomlNumberText(node));
      return std::nullopt;
    }
    return value + 0.0;  // -0 as 0
  }

  std::optional<double> Number(const toml::table& table, std::string_view key, const NumberRange& range) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    return NumberOf(*node, key, range);
  }

  // [x, y] in mm, each within +-limit.
  std::optional<Eigen::Vector2d> Point(const toml::table& table, std::string_view key, double limit) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    const toml::array* array = node->as_array();
    if (array == nullptr || array->size() != 2) {
      diags_.Report(DiagKind::TruthWrongType, Range(*node), key, "[x, y]: two numbers in mm",
                    array == nullptr ? std::string(TomlTypeName(*node)) : fmt::format("an array of {} items", array->size()));
      return std::nullopt;
    }
    const NumberRange range = Closed(-limit, limit, "mm");
    std::optional<double> x = NumberOf(*array->get(0), key, range);
    std::optional<double> y = NumberOf(*array->get(1), key, range);
    if (!x || !y) return std::nullopt;
    return Eigen::Vector2d(*x, *y);
  }

  // The true field's grid over the cell's robot reach at the truth's
  // correlation length (calibration/truth_spec.h), refused before simulate
  // starts when it is larger than it may be.
  void CheckTrueFieldGrid(const toml::table& robot, double correlation_mm) {
    const double samples = TrueFieldSamples(cell_.robot, correlation_mm);
    if (samples <= limits::kMaxTrueFieldSamples) return;
    const cell::Robot& r = cell_.robot;
    diags_.Report(DiagKind::TruthFieldTooFine, Range(*robot.get("uncalibrated_correlation_mm")),
                  NumberText(correlation_mm), NumberText(r.limits[0].lo), NumberText(r.limits[0].hi),
                  NumberText(r.limits[1].lo), NumberText(r.limits[1].hi),
                  fmt::format("{:.4g}", TrueFieldStepMm(correlation_mm)), fmt::format("{:.3g}", samples),
                  fmt::format("{:.0f}", limits::kMaxTrueFieldSamples), fmt::format("{:.3g}", MinTrueFieldCorrelationMm(r)));
  }

  SourceManager& sources_;
  std::uint32_t file_;
  const cell::Cell& cell_;
  Diagnostics& diags_;
  std::filesystem::path dir_;
  TomlLocator locator_;
};

}  // namespace

Result<std::optional<TruthSpec>> LoadTruth(const std::string& path, const cell::Cell& cell, SourceManager& sources,
                                           Diagnostics& diags) {
  Result<std::uint32_t> file = sources.Load(path);
  if (!file) return file.error();
  const SourceFile& source = sources.File(file.value());
  Reader reader(sources, file.value(), cell, diags, std::filesystem::path(path).parent_path());
  toml::table root;
  try {
    root = toml::parse(std::string_view(source.text), std::string_view(source.name));
  } catch (const toml::parse_error& error) {
    if (ReportOtherInputKind(file.value(), {InputKind::kTruth, InputKind::kToml}, "a truth file", diags)) {
      return std::optional<TruthSpec>();
    }
    diags.Report(DiagKind::TruthSyntax, SourceRange(reader.At(error.source().begin)), std::string(error.description()));
    return std::optional<TruthSpec>();
  }
  return reader.Read(root, path);
}

}  // namespace smtcal

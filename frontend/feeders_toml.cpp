// Reading the feeders file of `smtcal import` and matching parts to feeders
// (see feeders_toml.h). toml++ parses; every key is checked here and each
// mistake is reported at its own line and column, reading on so one run
// shows all of them.
#include "frontend/feeders_toml.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "base/field_text.h"
#include "base/number_range.h"
#include "calibration/limits.h"
#include "calibration/tolerances.h"
#include "frontend/cad/cad_text.h"
#include "frontend/input_kind.h"
#include "frontend/toml_source.h"

namespace smtcal::cad {
namespace {

class Reader {
 public:
  Reader(const SourceManager& sources, std::uint32_t file, Diagnostics& diags)
      : sources_(sources), file_(file), diags_(diags), locator_(sources, file) {}

  SourceLoc At(const toml::source_position& position) const { return locator_.At(position); }
  SourceRange Range(const toml::source_region& region) const { return locator_.Range(region); }
  SourceRange Range(const toml::node& node) const { return locator_.Range(node); }

  std::optional<FeedersFile> Read(const toml::table& root) {
    const std::size_t errors_before = diags_.error_count();
    FeedersFile file;
    file.file = file_;
    CheckKeys(root, "the feeders file", {"feeder", "map", "lane"});
    for (const toml::table* table : Tables(root, "feeder")) {
      if (std::optional<FeederSpec> feeder = Feeder(*table)) file.feeders.push_back(std::move(*feeder));
    }
    for (const toml::table* table : Tables(root, "map")) {
      if (std::optional<FeederRule> rule = Rule(*table)) file.rules.push_back(std::move(*rule));
    }
    for (const toml::table* table : Tables(root, "lane")) {
      if (std::optional<LaneNote> lane = Lane(*table)) file.lanes.push_back(std::move(*lane));
    }
    if (diags_.error_count() != errors_before) return std::nullopt;
    return file;
  }

 private:
  void CheckKeys(const toml::table& table, std::string_view where, std::vector<std::string> known) {
    for (const auto& [key, node] : table) {
      (void)node;
      if (std::find(known.begin(), known.end(), key.str()) != known.end()) continue;
      std::string closest = ClosestName(key.str(), known);
      std::string keys;
      for (std::size_t i = 0; i < known.size(); ++i) {
        keys += (i == 0 ? "" : i + 1 == known.size() ? " and " : ", ") + fmt::format("'{}'", known[i]);
      }
      diags_.Report(DiagKind::FeedersUnknownKey, Range(key.source()), Printable(key.str()), where,
                    closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest), keys);
    }
  }

  std::vector<const toml::table*> Tables(const toml::table& root, std::string_view key) {
    std::vector<const toml::table*> tables;
    const toml::node* node = root.get(key);
    if (node == nullptr) return tables;
    const toml::array* array = node->as_array();
    if (array == nullptr || !array->is_array_of_tables()) {
      diags_.Report(DiagKind::FeedersWrongType, Range(*node), key, fmt::format("tables written [[{}]]", key),
                    TomlTypeName(*node));
      return tables;
    }
    for (const toml::node& item : *array) tables.push_back(item.as_table());
    return tables;
  }

  std::optional<std::string> String(const toml::table& table, std::string_view key, SourceRange* range = nullptr) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    if (range != nullptr) *range = Range(*node);
    if (!node->is_string()) {
      diags_.Report(DiagKind::FeedersWrongType, Range(*node), key, "a string", TomlTypeName(*node));
      return std::nullopt;
    }
    return *node->value<std::string>();
  }

  // A number in `range`: the one check of base/number_range.h.
  std::optional<double> NumberOf(const toml::node& node, const std::string& label, const NumberRange& range) {
    const double value = TomlNumber(node);
    if (!InRange(value, range)) {
      diags_.Report(DiagKind::FeedersBadValue, Range(node), label, RangeText(range), TomlNumberText(node));
      return std::nullopt;
    }
    return value + 0.0;  // -0 as 0
  }

  // A string or a non-empty array of strings; empty when the key is absent
  // (or wrong, which is reported).
  std::vector<std::string> Patterns(const toml::table& table, std::string_view key, std::string_view expected) {
    std::vector<std::string> patterns;
    const toml::node* node = table.get(key);
    if (node == nullptr) return patterns;
    if (node->is_string()) {
      patterns.push_back(*node->value<std::string>());
    } else if (const toml::array* list = node->as_array();
               list != nullptr && !list->empty() &&
               std::all_of(list->begin(), list->end(), [](const toml::node& n) { return n.is_string(); })) {
      for (const toml::node& item : *list) patterns.push_back(*item.value<std::string>());
    } else {
      diags_.Report(DiagKind::FeedersWrongType, Range(*node), key, expected, TomlTypeName(*node));
    }
    return patterns;
  }

  std::optional<double> Number(const toml::table& table, std::string_view key, const NumberRange& range) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    if (!node->is_number()) {
      diags_.Report(DiagKind::FeedersWrongType, Range(*node), key, "a number", TomlTypeName(*node));
      return std::nullopt;
    }
    return NumberOf(*node, std::string(key), range);
  }

  // A whole number in `whole`: pallet columns or rows, a lane.
  std::optional<int> Count(const toml::table& table, std::string_view key, const NumberRange& whole,
                           SourceRange* range = nullptr) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    if (range != nullptr) *range = Range(*node);
    if (!node->is_integer()) {
      diags_.Report(DiagKind::FeedersWrongType, Range(*node), key, "a whole number", TomlTypeName(*node));
      return std::nullopt;
    }
    std::optional<double> value = NumberOf(*node, std::string(key), whole);
    if (!value) return std::nullopt;
    return static_cast<int>(*value);
  }

  // [x, y, z, u]: mm and degrees in the robot base frame.
  std::optional<std::array<double, 4>> Point(const toml::table& table, std::string_view key) {
    const toml::node* node = table.get(key);
    if (node == nullptr) return std::nullopt;
    const toml::array* array = node->as_array();
    if (array == nullptr || array->size() != 4 ||
        !std::all_of(array->begin(), array->end(), [](const toml::node& n) { return n.is_number(); })) {
      diags_.Report(DiagKind::FeedersWrongType, Range(*node), key, "[x, y, z, u]: four numbers (mm, mm, mm, deg)",
                    array == nullptr ? std::string(TomlTypeName(*node)) : fmt::format("an array of {} items", array->size()));
      return std::nullopt;
    }
    std::array<double, 4> point{};
    for (std::size_t i = 0; i < 4; ++i) {
      std::optional<double> value = NumberOf(*array->get(i), fmt::format("{}[{}]", key, i + 1),
                                             i == 3 ? limits::kAngleDeg : limits::kPositionMm);
      if (!value) return std::nullopt;
      point[i] = *value;
    }
    return point;
  }

  std::optional<FeederSpec> Feeder(const toml::table& table) {
    const std::size_t errors_before = diags_.error_count();
    FeederSpec feeder;
    feeder.range = Range(table);
    CheckKeys(table, "[[feeder]]", {"name", "pick", "package", "value", "rotation_offset_deg", "kind", "pallet",
                                    "part_number", "location", "tape_width_mm", "tape_pitch_mm"});
    if (std::optional<std::string> name = String(table, "name", &feeder.name_range)) feeder.name = *name;
    if (!table.contains("name")) diags_.Report(DiagKind::FeedersMissingKey, feeder.range, "[[feeder]]", "'name'");
    if (std::optional<std::array<double, 4>> pick = Point(table, "pick")) feeder.pick = *pick;
    if (!table.contains("pick")) diags_.Report(DiagKind::FeedersMissingKey, feeder.range, "[[feeder]]", "'pick'");
    feeder.packages = Patterns(table, "package", "a package name or an array of package names");
    if (std::optional<std::string> value = String(table, "value")) feeder.value = *value;
    feeder.rotation_offset_deg = Number(table, "rotation_offset_deg", limits::kAngleDeg).value_or(0.0);
    feeder.part_number = String(table, "part_number").value_or("");
    feeder.location = String(table, "location").value_or("");
    feeder.tape_width_mm = Number(table, "tape_width_mm", limits::kLengthMm);
    feeder.tape_pitch_mm = Number(table, "tape_pitch_mm", limits::kLengthMm);
    if (const toml::node* node = table.get("pallet")) {
      if (const toml::table* pallet = node->as_table()) {
        CheckKeys(*pallet, "the pallet", {"last", "back", "columns", "rows"});
        feeder.pallet_last = Point(*pallet, "last");
        feeder.pallet_back = Point(*pallet, "back");
        feeder.columns = Count(*pallet, "columns", limits::kPalletCount).value_or(1);
        feeder.rows = Count(*pallet, "rows", limits::kPalletCount).value_or(1);
        for (std::string_view key : {"last", "back", "columns", "rows"}) {
          if (!pallet->contains(key)) {
            diags_.Report(DiagKind::FeedersMissingKey, Range(*node), "the pallet", fmt::format("'{}'", key));
          }
        }
      } else {
        diags_.Report(DiagKind::FeedersWrongType, Range(*node), "pallet",
                      "a table { last = [x, y, z, u], back = [x, y, z, u], columns = N, rows = N }", TomlTypeName(*node));
      }
    }
    SourceRange kind_range = feeder.range;
    std::optional<std::string> kind = String(table, "kind", &kind_range);
    if (kind && *kind != "tape" && *kind != "tray") {
      diags_.Report(DiagKind::FeedersBadValue, kind_range, "kind", "\"tape\" or \"tray\"", fmt::format("'{}'", Printable(*kind)));
    }
    const bool bank = feeder.is_pallet() && feeder.pick_points() > 1 &&
                      static_cast<int>(feeder.packages.size()) == feeder.pick_points();
    feeder.kind = kind ? (*kind == "tray" ? cell::FeederKind::kTray : cell::FeederKind::kTape)
                       : feeder.is_pallet() && !bank ? cell::FeederKind::kTray
                                                     : cell::FeederKind::kTape;
    if (feeder.kind == cell::FeederKind::kTray && !feeder.is_pallet()) {
      diags_.Report(DiagKind::FeedersMissingKey, kind_range, "a tray",
                    "a pallet of pockets (pallet = { last = [..], back = [..], columns = N, rows = N })");
    }
    if (diags_.error_count() != errors_before) return std::nullopt;
    return feeder;
  }

  std::optional<FeederRule> Rule(const toml::table& table) {
    const std::size_t errors_before = diags_.error_count();
    FeederRule rule;
    rule.range = Range(table);
    CheckKeys(table, "[[map]]", {"feeder", "lane", "package", "value", "designator", "rotation_offset_deg", "part_number"});
    if (std::optional<std::string> feeder = String(table, "feeder", &rule.feeder_range)) rule.feeder = *feeder;
    if (!table.contains("feeder")) diags_.Report(DiagKind::FeedersMissingKey, rule.range, "[[map]]", "'feeder'");
    rule.packages = Patterns(table, "package", "a package (a chip size or a glob) or an array of them");
    rule.values = Patterns(table, "value", "a value (a glob) or an array of them");
    rule.designators = Patterns(table, "designator", "a designator (a glob) or an array of them");
    if (!table.contains("package") && !table.contains("value") && !table.contains("designator")) {
      diags_.Report(DiagKind::FeedersMissingKey, rule.range, "[[map]]",
                    "'package', 'value' or 'designator' to say which parts it maps");
    }
    rule.lane = Count(table, "lane", limits::kPalletPickPoint, &rule.lane_range);
    rule.rotation_offset_deg = Number(table, "rotation_offset_deg", limits::kAngleDeg).value_or(0.0);
    rule.part_number = String(table, "part_number").value_or("");
    if (diags_.error_count() != errors_before) return std::nullopt;
    return rule;
  }

  std::optional<LaneNote> Lane(const toml::table& table) {
    const std::size_t errors_before = diags_.error_count();
    LaneNote lane;
    const SourceRange range = Range(table);
    CheckKeys(table, "[[lane]]", {"feeder", "lane", "value", "package", "part_number", "location", "tape_width_mm",
                                  "tape_pitch_mm"});
    if (std::optional<std::string> feeder = String(table, "feeder", &lane.feeder_range)) lane.feeder = *feeder;
    if (!table.contains("feeder")) diags_.Report(DiagKind::FeedersMissingKey, range, "[[lane]]", "'feeder'");
    lane.lane = Count(table, "lane", limits::kPalletPickPoint, &lane.lane_range);
    lane.value = String(table, "value").value_or("");
    lane.package = String(table, "package").value_or("");
    lane.part_number = String(table, "part_number").value_or("");
    lane.location = String(table, "location").value_or("");
    lane.tape_width_mm = Number(table, "tape_width_mm", limits::kLengthMm);
    lane.tape_pitch_mm = Number(table, "tape_pitch_mm", limits::kLengthMm);
    if (diags_.error_count() != errors_before) return std::nullopt;
    return lane;
  }

  const SourceManager& sources_;
  std::uint32_t file_;
  Diagnostics& diags_;
  TomlLocator locator_;
};

FeederSpec FromCell(const cell::Feeder& feeder) {
  FeederSpec spec;
  spec.name = feeder.name;
  spec.name_range = feeder.name_range;
  spec.range = feeder.range;
  spec.pick = feeder.pick;
  spec.pallet_last = feeder.pallet_last;
  spec.pallet_back = feeder.pallet_back;
  spec.columns = feeder.columns;
  spec.rows = feeder.rows;
  spec.packages = feeder.packages;
  if (spec.packages.empty() && !feeder.package.empty()) spec.packages.push_back(feeder.package);
  spec.value = feeder.value;
  spec.kind = feeder.kind;
  spec.from_cell = true;
  return spec;
}

std::string WhereDefined(const FeederSpec& feeder, const SourceManager& sources) {
  const SourceLoc& loc = feeder.name_range.begin;
  if (!loc.known()) return feeder.from_cell ? "in the cell" : "in this file";
  return fmt::format("at {}:{}", sources.File(loc.file).name, loc.line);
}

// How specifically a feeder's package and value describe a part: 2 both
// given and matching, 1 one given and matching, 0 no match (or nothing
// given: such a feeder is only reached through a [[map]]).
int Specificity(const FeederSpec& feeder, const Row& row, std::optional<int>& lane) {
  if (feeder.packages.empty() && feeder.value.empty()) return 0;
  int score = 0;
  if (!feeder.packages.empty()) {
    auto it = std::find_if(feeder.packages.begin(), feeder.packages.end(),
                           [&](const std::string& pattern) { return PackageMatch(pattern, row.package); });
    if (it == feeder.packages.end()) return 0;
    // A bank of tapes with one package per lane: the lane of the package.
    if (feeder.lanes_by_package()) lane = static_cast<int>(it - feeder.packages.begin()) + 1;
    ++score;
  }
  if (!feeder.value.empty()) {
    if (!GlobMatch(feeder.value, row.value)) return 0;
    ++score;
  }
  return score;
}

}  // namespace

Result<std::optional<FeedersFile>> LoadFeeders(const std::string& path, SourceManager& sources, Diagnostics& diags) {
  Result<std::uint32_t> file = sources.Load(path);
  if (!file) return file.error();
  const SourceFile& source = sources.File(file.value());
  Reader reader(sources, file.value(), diags);
  toml::table root;
  try {
    root = toml::parse(std::string_view(source.text), std::string_view(source.name));
  } catch (const toml::parse_error& error) {
    if (ReportOtherInputKind(file.value(), {InputKind::kFeeders, InputKind::kToml}, "a feeders file", diags)) {
      return std::optional<FeedersFile>();
    }
    diags.Report(DiagKind::FeedersSyntax, SourceRange(reader.At(error.source().begin)),
                 std::string(error.description()));
    return std::optional<FeedersFile>();
  }
  return reader.Read(root);
}

std::optional<FeederTable> FeederTable::Build(const std::vector<cell::Feeder>& cell_feeders, FeedersFile file,
                                              Diagnostics& diags) {
  const std::size_t errors_before = diags.error_count();
  FeederTable table;
  for (const cell::Feeder& feeder : cell_feeders) table.feeders_.push_back(FromCell(feeder));
  auto find = [&](std::string_view name) -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < table.feeders_.size(); ++i) {
      if (AsciiLowercase(table.feeders_[i].name) == AsciiLowercase(name)) return i;
    }
    return std::nullopt;
  };
  for (FeederSpec& feeder : file.feeders) {
    if (std::optional<std::size_t> first = find(feeder.name)) {
      diags.Report(DiagKind::FeedersDuplicateFeeder, feeder.name_range, Printable(feeder.name),
                   WhereDefined(table.feeders_[*first], diags.sources()));
      continue;
    }
    table.feeders_.push_back(std::move(feeder));
  }
  std::vector<std::string> names;
  for (const FeederSpec& feeder : table.feeders_) names.push_back(feeder.name);
  // The feeder a [[map]] or a [[lane]] names, and its lane within the
  // feeder's pick points; nullopt after reporting either.
  auto resolve = [&](const std::string& name, SourceRange name_range, std::optional<int> lane,
                     SourceRange lane_range) -> std::optional<std::size_t> {
    std::optional<std::size_t> feeder = find(name);
    if (!feeder) {
      std::string closest = ClosestName(name, names);
      diags.Report(DiagKind::FeedersUnknownFeeder, name_range, Printable(name),
                   closest.empty() ? "" : fmt::format("; did you mean '{}'?", closest));
      return std::nullopt;
    }
    const FeederSpec& spec = table.feeders_[*feeder];
    if (lane && *lane > spec.pick_points()) {
      diags.Report(DiagKind::FeedersBadValue, lane_range, "lane",
                   fmt::format("a pick point of feeder '{}' (1 to {})", Printable(spec.name), spec.pick_points()),
                   *lane);
      return std::nullopt;
    }
    return feeder;
  };
  for (FeederRule& rule : file.rules) {
    if (std::optional<std::size_t> feeder = resolve(rule.feeder, rule.feeder_range, rule.lane, rule.lane_range)) {
      table.rule_feeder_.push_back(*feeder);
      table.rules_.push_back(std::move(rule));
    }
  }
  for (LaneNote& lane : file.lanes) {
    if (std::optional<std::size_t> feeder = resolve(lane.feeder, lane.feeder_range, lane.lane, lane.lane_range)) {
      table.lane_feeder_.push_back(*feeder);
      table.lanes_.push_back(std::move(lane));
    }
  }
  if (diags.error_count() != errors_before) return std::nullopt;
  return table;
}

LaneDescription FeederTable::Describe(std::size_t feeder, int k) const {
  const FeederSpec& spec = feeders_[feeder];
  LaneDescription description{{}, {}, spec.part_number, spec.location, spec.tape_width_mm, spec.tape_pitch_mm};
  // The feeder-wide [[lane]]s first, then the lane's own: later ones override.
  for (bool own : {false, true}) {
    for (std::size_t i = 0; i < lanes_.size(); ++i) {
      const LaneNote& lane = lanes_[i];
      if (lane_feeder_[i] != feeder || lane.lane.has_value() != own || (own && *lane.lane != k)) continue;
      if (!lane.value.empty()) description.value = lane.value;
      if (!lane.package.empty()) description.package = lane.package;
      if (!lane.part_number.empty()) description.part_number = lane.part_number;
      if (!lane.location.empty()) {
        description.location = lane.location;
        description.lane_location = own;
      }
      if (lane.tape_width_mm) description.tape_width_mm = lane.tape_width_mm;
      if (lane.tape_pitch_mm) description.tape_pitch_mm = lane.tape_pitch_mm;
    }
  }
  return description;
}

std::optional<FeederMatch> FeederTable::Find(const Row& row) const {
  for (std::size_t r = 0; r < rules_.size(); ++r) {
    const FeederRule& rule = rules_[r];
    auto any = [](const std::vector<std::string>& patterns, auto&& match) {
      return patterns.empty() || std::any_of(patterns.begin(), patterns.end(), match);
    };
    if (!any(rule.packages, [&](const std::string& p) { return PackageMatch(p, row.package); })) continue;
    if (!any(rule.values, [&](const std::string& p) { return GlobMatch(p, row.value); })) continue;
    if (!any(rule.designators, [&](const std::string& p) { return GlobMatch(p, row.designator); })) continue;
    return FeederMatch{rule_feeder_[r], rule.lane, rule.rotation_offset_deg, rule.part_number};
  }
  std::optional<FeederMatch> best;
  int best_score = 0;
  for (std::size_t f = 0; f < feeders_.size(); ++f) {
    std::optional<int> lane;
    int score = Specificity(feeders_[f], row, lane);
    if (score > best_score) {
      best_score = score;
      best = FeederMatch{f, lane, feeders_[f].rotation_offset_deg, {}};
    }
  }
  return best;
}

}  // namespace smtcal::cad

// The inputs of `smtcal measure program|read` (frontend/measurement_input.h).
#include "frontend/measurement_input.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "base/field_text.h"
#include "frontend/cad/cad_text.h"

namespace smtcal::measure {
namespace {

constexpr std::string_view kLogMark = "# smtcal measuring log:";

// "key VALUE" in a header of "; "-separated items.
std::string Item(std::string_view header, std::string_view key) {
  std::size_t at = 0;
  while (at < header.size()) {
    std::size_t end = header.find("; ", at);
    if (end == std::string_view::npos) end = header.size();
    std::string_view item = header.substr(at, end - at);
    if (item.starts_with(key) && item.size() > key.size() && item[key.size()] == ' ') {
      return std::string(item.substr(key.size() + 1));
    }
    at = end + 2;
  }
  return "";
}

// The visit a cut reading line would have been (its first field), 0 when
// that is not one of the plan's visits.
int VisitOfCutLine(std::string_view line, std::size_t visits) {
  const std::optional<double> v = ParseNumber(line.substr(0, line.find(',')));
  if (!v || *v != std::floor(*v) || *v < 1 || *v > static_cast<double>(visits)) return 0;
  return static_cast<int>(*v);
}

}  // namespace

std::optional<LoadedPlan> LoadPlan(std::uint32_t file, const cell::Cell& cell, Diagnostics& diags) {
  std::optional<std::vector<PlanRow>> rows = ReadMeasurementPlan(file, diags);
  if (!rows) return std::nullopt;
  const std::size_t errors_before = diags.error_count();
  LoadedPlan loaded;
  loaded.name = diags.sources().File(file).name;
  loaded.file = file;
  loaded.digest = PlanDigest(diags.sources().File(file).text);
  Plan& plan = loaded.plan;
  plan.cell_name = cell.name;
  if (cell.measure) plan.device = cell.measure->device;
  plan.approach_mm = cell.robot.final_approach_mm.value_or(Eigen::Vector2d::Zero());
  std::map<int, const PlanRow*> node_at;
  std::map<std::string, std::size_t> region_of;
  for (std::size_t k = 0; k < rows->size(); ++k) {
    const PlanRow& row = (*rows)[k];
    if (row.visit != static_cast<int>(k) + 1) {
      diags.Report(DiagKind::MeasurePlanVisitOrder, row.visit_field, row.visit, k);
      return std::nullopt;
    }
    const bool transducer_rows = row.axes != MeasuredAxes::kXY;
    if (cell.measure && transducer_rows != (cell.measure->device == cell::MeasureDevice::kTransducer)) {
      diags.Report(DiagKind::MeasurePlanDevice, row.visit_field,
                   transducer_rows ? "transducer" : "probe or external",
                   cell::kMeasureDeviceNames[static_cast<std::size_t>(cell.measure->device)]);
      return std::nullopt;
    }
    auto [first, fresh] = node_at.try_emplace(row.node, &row);
    if (!fresh && first->second->at != row.at) {
      Diagnostic* diag = diags.Report(DiagKind::MeasurePlanNodeMoved, row.node_field, row.node, FormatMm(row.at.x()),
                                      FormatMm(row.at.y()), FormatMm(first->second->at.x()),
                                      FormatMm(first->second->at.y()), first->second->line);
      Diagnostics::AddNote(diag, first->second->node_field, "first given here");
      continue;
    }
    auto [region_it, new_region] = region_of.try_emplace(AsciiLowercase(row.region), plan.regions.size());
    if (new_region) {
      PlanRegion region;
      region.name = row.region;
      if (const cell::Region* known = cell.FindRegion(row.region)) {
        region.x_mm = known->x_mm;
        region.y_mm = known->y_mm;
        region.tolerance_mm = known->tolerance_mm;
      } else {
        // Not in the cell: one the plan proposed under a fixture's markers
        // (FIXTURE_PATH), or a plan of another cell.
        region.proposed = true;
        std::vector<std::string> names;
        bool marker = false;
        for (const cell::Region& r : cell.regions) names.push_back(r.name);
        for (const cell::Fixture& fixture : cell.fixtures) {
          for (const cell::ScanPath& path : fixture.scan_paths) {
            marker = marker || AsciiLowercase(fixture.name + "_" + path.name) == AsciiLowercase(row.region);
          }
        }
        if (!marker) {
          std::string closest = ClosestName(row.region, names);
          diags.Report(DiagKind::MeasurePlanRegion, row.region_field, Printable(row.region), cell.name,
                       closest.empty() ? "" : fmt::format("; did you mean '{}'?", closest));
          return std::nullopt;
        }
      }
      plan.regions.push_back(region);
    }
    PlanRegion& region = plan.regions[region_it->second];
    if (row.kind == VisitKind::kNode) {
      if (std::find(region.xs.begin(), region.xs.end(), row.at.x()) == region.xs.end()) region.xs.push_back(row.at.x());
      if (std::find(region.ys.begin(), region.ys.end(), row.at.y()) == region.ys.end()) region.ys.push_back(row.at.y());
    }
    region.sets = std::max(region.sets, row.set);
    region.repetitions = std::max(region.repetitions, row.repetitions);
    Visit visit;
    visit.number = row.visit;
    visit.region = region_it->second;
    visit.axes = row.axes;
    visit.station = row.station;
    visit.kind = row.kind;
    visit.node = row.node;
    visit.at = row.at;
    visit.set = row.set;
    visit.repetitions = row.repetitions;
    visit.direction = row.direction;
    plan.visits.push_back(visit);
    loaded.lines.push_back(row.line);
  }
  for (PlanRegion& region : plan.regions) {
    std::sort(region.xs.begin(), region.xs.end());
    std::sort(region.ys.begin(), region.ys.end());
  }
  if (diags.error_count() != errors_before) return std::nullopt;
  // The stations: where each placement of the artefact went (the box of
  // its points), the regions it measured as nodes, and the stations it
  // shares nodes with (ties).
  std::map<int, std::size_t> station_of;
  std::map<std::pair<int, MeasuredAxes>, std::set<int>> stations_of_node;
  for (const Visit& v : plan.visits) {
    auto [it, fresh] = station_of.try_emplace(v.station, plan.stations.size());
    if (fresh) {
      PlanStation station;
      station.number = v.station;
      station.axes = v.axes;
      station.origin = station.far = v.at;
      plan.stations.push_back(station);
    }
    PlanStation& station = plan.stations[it->second];
    station.origin = station.origin.cwiseMin(v.at);
    station.far = station.far.cwiseMax(v.at);
    if ((v.kind == VisitKind::kNode || v.kind == VisitKind::kCheck) &&
        std::find(station.regions.begin(), station.regions.end(), v.region) == station.regions.end()) {
      station.regions.push_back(v.region);
    }
    if (v.kind == VisitKind::kTie && v.set == 1 && v.direction > 0) ++station.ties;
    if (v.kind != VisitKind::kCheck) stations_of_node[{v.node, v.axes}].insert(v.station);
  }
  for (const auto& [node, stations] : stations_of_node) {
    for (int a : stations) {
      for (int b : stations) {
        std::vector<int>& tied = plan.stations[station_of[a]].tied_to;
        if (a != b && std::find(tied.begin(), tied.end(), b) == tied.end()) tied.push_back(b);
      }
    }
  }
  for (PlanStation& station : plan.stations) std::sort(station.tied_to.begin(), station.tied_to.end());
  return loaded;
}

std::optional<MeasuringLog> ReadMeasuringLog(std::uint32_t file, const LoadedPlan& plan, Diagnostics& diags) {
  const std::size_t errors_before = diags.error_count();
  const cad::Lines lines(diags.sources(), file);
  const std::string& text = diags.sources().File(file).text;
  MeasuringLog log;
  log.name = diags.sources().File(file).name;
  const std::vector<Visit>& visits = plan.plan.visits;
  // The plan's bounds on the whole-number columns.
  int largest_node = 0, largest_set = 0, largest_repetitions = 0;
  for (const Visit& v : visits) {
    largest_node = std::max(largest_node, v.node);
    largest_set = std::max(largest_set, v.set);
    largest_repetitions = std::max(largest_repetitions, v.repetitions);
  }
  // Per block: the line of each (visit, repetition) read in it.
  std::map<std::pair<int, int>, std::pair<std::uint32_t, std::size_t>> in_block;  // -> line, reading index
  for (std::uint32_t number = 1; number <= lines.count(); ++number) {
    std::string_view line = lines.Text(number);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
    const SourceRange where(lines.At(number, 0), static_cast<std::uint32_t>(line.size()));
    if (log.blocks.empty() && !line.starts_with(kLogMark)) {
      diags.Report(DiagKind::MeasureLogNotARun, SourceRange(lines.At(number, 0)), Printable(log.name));
      return std::nullopt;
    }
    if (line.empty()) continue;
    // A cut line with a resumed run's header glued to it: the cut reading
    // ends where the header begins.
    const std::size_t glued = line.find(kLogMark);
    if (glued != std::string_view::npos && glued > 0) {
      log.blocks.back().cut = CutLine{VisitOfCutLine(line.substr(0, glued), visits.size()),
                                      SourceRange(lines.At(number, 0), static_cast<std::uint32_t>(glued))};
      line = line.substr(glued);
    }
    if (line.starts_with(kLogMark)) {
      const SourceRange header_where(lines.At(number, glued == std::string_view::npos ? 0 : glued),
                                     static_cast<std::uint32_t>(line.size()));
      LogBlock block;
      block.header = std::string(line.substr(2));
      block.header_range = header_where;
      // "...: plan NAME digest HEX; ...; visits F..L"
      const std::size_t digest_at = line.find(" digest ");
      if (digest_at != std::string_view::npos) {
        std::string_view rest = line.substr(digest_at + 8);
        block.digest = std::string(rest.substr(0, rest.find(';')));
      }
      if (block.digest != plan.digest) {
        diags.Report(DiagKind::MeasureLogOtherPlan, header_where, block.digest.empty() ? "(none)" : Printable(block.digest),
                     plan.digest, Printable(plan.name));
        return std::nullopt;
      }
      const std::string range = Item(line, "visits");
      const std::size_t dots = range.find("..");
      std::optional<double> first, last;
      if (dots != std::string::npos) {
        first = ParseNumber(range.substr(0, dots));
        last = ParseNumber(range.substr(dots + 2));
      }
      const auto whole_visit = [&](std::optional<double> v) {
        return v && *v == std::floor(*v) && *v >= 1 && *v <= static_cast<double>(visits.size());
      };
      if (!whole_visit(first) || !whole_visit(last) || *first > *last) {
        diags.Report(DiagKind::MeasureLogBadHeader, header_where, Printable(range), visits.size());
        return std::nullopt;
      }
      block.first_visit = static_cast<int>(*first);
      block.last_visit = static_cast<int>(*last);
      log.blocks.push_back(block);
      in_block.clear();
      continue;
    }
    LogBlock& block = log.blocks.back();
    if (line == "# end") {
      block.ended = true;
      continue;
    }
    if (line.starts_with("# aborted")) {
      block.stopped = std::string(line.substr(2));
      continue;
    }
    if (line.starts_with("#") || line.starts_with("visit,")) continue;
    // The last line of the file without its line end: the controller
    // stopped while writing it.
    if (number == lines.count() && !text.empty() && text.back() != '\n') {
      block.cut = CutLine{VisitOfCutLine(line, visits.size()), where};
      continue;
    }
    // visit,node,set,repetition,x_mm,y_mm,a_mm,b_mm
    std::vector<std::string_view> fields;
    std::size_t at = 0;
    while (true) {
      std::size_t comma = line.find(',', at);
      fields.push_back(line.substr(at, comma == std::string_view::npos ? std::string_view::npos : comma - at));
      if (comma == std::string_view::npos) break;
      at = comma + 1;
    }
    if (fields.size() != 8) {
      diags.Report(DiagKind::CsvFieldCount, where, fmt::format("{} fields", fields.size()), 8,
                   "visit,node,set,repetition,x_mm,y_mm,a_mm,b_mm");
      continue;
    }
    std::array<double, 8> values{};
    std::array<SourceRange, 8> field_at;
    bool ok = true;
    static constexpr std::array<std::string_view, 8> kColumns = {"visit", "node", "set", "repetition",
                                                                 "x_mm",  "y_mm", "a_mm", "b_mm"};
    const std::array<int, 4> bounds = {static_cast<int>(visits.size()), largest_node, largest_set,
                                       largest_repetitions};
    std::uint32_t column = 0;
    for (std::size_t f = 0; f < 8; ++f) {
      field_at[f] = SourceRange(lines.At(number, column), static_cast<std::uint32_t>(fields[f].size()));
      std::optional<double> value = ParseNumber(fields[f]);
      if (!value || !std::isfinite(*value)) {
        diags.Report(DiagKind::CsvBadNumber, field_at[f], Printable(fields[f]), kColumns[f], "");
        ok = false;
      } else if (f < 4 && (*value != std::floor(*value) || *value < 1 || *value > bounds[f])) {
        // Whole numbers within the plan's: never wrapped into an int.
        diags.Report(DiagKind::MeasureLogBadInteger, field_at[f], Printable(fields[f]), kColumns[f], bounds[f]);
        ok = false;
      }
      values[f] = value.value_or(0);
      column += static_cast<std::uint32_t>(fields[f].size()) + 1;
    }
    if (!ok) continue;
    Reading reading;
    reading.visit = static_cast<int>(values[0]);
    reading.node = static_cast<int>(values[1]);
    reading.set = static_cast<int>(values[2]);
    reading.repetition = static_cast<int>(values[3]);
    reading.a = values[6];
    reading.b = values[7];
    reading.where = where;
    const Visit& visit = visits[static_cast<std::size_t>(reading.visit - 1)];
    if (visit.node != reading.node) {
      diags.Report(DiagKind::MeasureLogUnknownVisit, where, reading.visit, reading.node,
                   fmt::format("node {} there", visit.node));
      continue;
    }
    // The rest of the line must be the plan's visit as the program logs it
    // (the commanded position with 6 decimals).
    const auto planned = [&](std::size_t f, std::string_view what, std::string theirs) {
      diags.Report(DiagKind::MeasureLogNotPlanned, field_at[f], reading.visit, what, Printable(fields[f]),
                   std::move(theirs));
    };
    if (reading.set != visit.set) {
      planned(2, "set", std::to_string(visit.set));
      continue;
    }
    if (reading.repetition > visit.repetitions) {
      planned(3, "repetition", fmt::format("1 to {}", visit.repetitions));
      continue;
    }
    constexpr double kLoggedPositionMm = 2e-6;  // "%.6f" of the plan's micrometres
    if (std::abs(values[4] - visit.at.x()) > kLoggedPositionMm) {
      planned(4, "x_mm", FormatMm(visit.at.x()));
      continue;
    }
    if (std::abs(values[5] - visit.at.y()) > kLoggedPositionMm) {
      planned(5, "y_mm", FormatMm(visit.at.y()));
      continue;
    }
    if (reading.visit < block.first_visit || reading.visit > block.last_visit) {
      Diagnostic* diag = diags.Report(DiagKind::MeasureLogOutsideRun, where, reading.visit, block.first_visit,
                                      block.last_visit);
      Diagnostics::AddNote(diag, block.header_range, "the run's header");
      continue;
    }
    auto [seen, fresh] = in_block.try_emplace({reading.visit, reading.repetition}, number, log.readings.size());
    if (!fresh) {
      const Reading& first = log.readings[seen->second.second];
      const bool same = first.a == reading.a && first.b == reading.b;
      Diagnostic* diag = diags.Report(DiagKind::MeasureLogDuplicate, where, reading.visit, reading.repetition,
                                      same ? "" : " with other readings", seen->second.first);
      Diagnostics::AddNote(diag, first.where, "first logged here");
      continue;
    }
    reading.axes = visit.axes;
    reading.kind = visit.kind;
    reading.region = visit.region;
    reading.station = visit.station;
    reading.direction = visit.direction;
    reading.at = visit.at;  // the plan's exact node (the log has 6 decimals)
    log.readings.push_back(reading);
    log.block_of.push_back(static_cast<int>(log.blocks.size()) - 1);
    block.last_visit_logged = reading.visit;
    block.last_repetition_logged = reading.repetition;
  }
  if (diags.error_count() != errors_before) return std::nullopt;
  return log;
}

namespace {

// One setting: its key in the log's header and the raw file's comment, its
// value in the cell, and what it is.
struct Setting {
  std::string key;
  std::string cell_value;
  std::string_view what;
};

std::string Number(double v) { return fmt::format("{}", v); }

std::vector<Setting> SettingsOf(const cell::Cell& cell) {
  std::vector<Setting> out;
  const Eigen::Vector2d a = cell.robot.final_approach_mm.value_or(Eigen::Vector2d::Zero());
  out.push_back({"approach", Number(a.x()) + " " + Number(a.y()), "robot.final_approach_mm"});
  if (!cell.measure) return out;
  const cell::Measure& m = *cell.measure;
  if (m.device == cell::MeasureDevice::kProbe) {
    out.push_back({"hole_diameter_mm", Number(m.probe.hole_diameter_mm), "measure.probe.hole_diameter_mm"});
    out.push_back({"stylus_diameter_mm", Number(m.probe.stylus_diameter_mm), "measure.probe.stylus_diameter_mm"});
  } else if (m.device == cell::MeasureDevice::kTransducer) {
    out.push_back({"slope", Number(m.transducer.slope), "measure.transducer.slope"});
    out.push_back({"zero_mm", Number(m.transducer.zero_mm), "measure.transducer.zero_mm"});
  }
  return out;
}

// The same numbers, however written ("0.5 0.5" and "0.50 0.5").
bool SameNumbers(std::string_view a, std::string_view b) {
  auto split = [](std::string_view text) {
    std::vector<std::optional<double>> values;
    std::size_t at = 0;
    while (at < text.size()) {
      std::size_t end = text.find(' ', at);
      if (end == std::string_view::npos) end = text.size();
      if (end > at) values.push_back(ParseNumber(text.substr(at, end - at)));
      at = end + 1;
    }
    return values;
  };
  const auto x = split(a), y = split(b);
  if (x.size() != y.size()) return false;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!x[k] || !y[k] || std::abs(*x[k] - *y[k]) > 1e-9 * std::max(1.0, std::abs(*y[k]))) return false;
  }
  return true;
}

}  // namespace

void CheckLogSettings(const MeasuringLog& log, const cell::Cell& cell, Diagnostics& diags) {
  for (const LogBlock& block : log.blocks) {
    for (const Setting& setting : SettingsOf(cell)) {
      const std::string logged = Item(block.header, setting.key);
      if (logged.empty()) {
        diags.Report(DiagKind::MeasureLogSettings, block.header_range,
                     fmt::format("the log's header does not say the {} ({}) it was measured with: an older measuring "
                                 "program wrote it; make the programs again (smtcal measure program)",
                                 setting.key, setting.what));
        break;
      }
      if (SameNumbers(logged, setting.cell_value)) continue;
      diags.Report(DiagKind::MeasureLogSettings, block.header_range,
                   fmt::format("the log was measured with {} {}, but the cell's {} is {} now: every error read with "
                               "it would be off",
                               setting.key, Printable(logged), setting.what, setting.cell_value));
    }
  }
}

std::string MeasuredWith(const cell::Cell& cell) {
  std::string out = fmt::format(
      "device {}", cell.measure ? cell::kMeasureDeviceNames[static_cast<std::size_t>(cell.measure->device)] : "none");
  for (const Setting& setting : SettingsOf(cell)) out += fmt::format("; {} {}", setting.key, setting.cell_value);
  return out;
}

void CheckRawSettings(std::uint32_t raw_file, const cell::Cell& cell, Diagnostics& diags) {
  const cad::Lines lines(diags.sources(), raw_file);
  for (std::uint32_t number = 1; number <= lines.count(); ++number) {
    std::string_view line = lines.Text(number);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.remove_suffix(1);
    if (!line.starts_with(kMeasuredWithMark)) continue;
    const SourceRange where(lines.At(number, 0), static_cast<std::uint32_t>(line.size()));
    const std::string device = Item(line.substr(kMeasuredWithMark.size()), "device");
    const std::string want =
        cell.measure ? std::string(cell::kMeasureDeviceNames[static_cast<std::size_t>(cell.measure->device)]) : "none";
    if (device != want) {
      diags.Report(DiagKind::TableRawSettings, where,
                   fmt::format("the raw measurements were taken with the device '{}', but cell '{}' measures with "
                               "'{}'",
                               Printable(device), Printable(cell.name), want));
      return;
    }
    for (const Setting& setting : SettingsOf(cell)) {
      const std::string raw = Item(line.substr(kMeasuredWithMark.size()), setting.key);
      if (SameNumbers(raw, setting.cell_value)) continue;
      diags.Report(DiagKind::TableRawSettings, where,
                   fmt::format("the raw measurements were taken with {} {}, but cell '{}' says {} ({}): the table "
                               "would be off by the difference",
                               setting.key, raw.empty() ? "(not said)" : Printable(raw), Printable(cell.name),
                               setting.cell_value, setting.what));
    }
    return;
  }
  diags.Report(DiagKind::TableRawSettings, SourceRange(SourceLoc{raw_file, 1, 1}),
               fmt::format("the raw file does not say what it was measured with (a '# measured with:' line, which "
                           "smtcal measure read writes), so it cannot be checked against cell '{}'",
                           Printable(cell.name)));
}

}  // namespace smtcal::measure

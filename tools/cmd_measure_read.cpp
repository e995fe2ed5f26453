// `smtcal measure read PLAN.csv --cell CELL.toml LOG... -o RAW.csv`: the
// measuring programs' logs (and an external system's readings) back into
// the raw measurements `smtcal table build` averages, with where they came
// from in the comments (frontend/measurement_input.h for the files,
// calibration/measurement_reading.h for what a reading means). A visit the
// logs lack is an error that names the visit to resume at. This file wires
// the inputs, the checks across them and the exit codes.
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "backend/reports/measurement_csv.h"
#include "base/field_text.h"
#include "calibration/measurement_registration.h"
#include "frontend/measurement_input.h"
#include "frontend/table_csv.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct ReadOptions {
  std::string plan;
  std::string cell;
  std::vector<std::string> logs;
  std::string external;
  std::string region;
  std::string output;
};

std::string BaseName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

// The readings of the logs, given in order: a block's readings replace those
// of earlier blocks for the visits it covers (a resumed run appends a block
// that starts at the visit the abort named). A block's cut last line is an
// error unless a later block measures its visit again.
std::vector<measure::Reading> MergeReadings(const std::vector<measure::MeasuringLog>& logs, const std::string& plan,
                                            int& replaced, Diagnostics& diags) {
  std::map<std::pair<int, int>, measure::Reading> by_key;  // (visit, repetition)
  replaced = 0;
  for (std::size_t l = 0; l < logs.size(); ++l) {
    const measure::MeasuringLog& log = logs[l];
    for (std::size_t b = 0; b < log.blocks.size(); ++b) {
      const measure::LogBlock& block = log.blocks[b];
      for (auto it = by_key.begin(); it != by_key.end();) {
        if (it->first.first >= block.first_visit && it->first.first <= block.last_visit) {
          it = by_key.erase(it);
          ++replaced;
        } else {
          ++it;
        }
      }
      for (std::size_t k = 0; k < log.readings.size(); ++k) {
        if (log.block_of[k] != static_cast<int>(b)) continue;
        by_key[{log.readings[k].visit, log.readings[k].repetition}] = log.readings[k];
      }
      if (!block.cut) continue;
      // Measured again later?
      const int visit = block.cut->visit;
      bool again = false;
      for (std::size_t l2 = l; l2 < logs.size() && !again; ++l2) {
        for (std::size_t b2 = (l2 == l ? b + 1 : 0); b2 < logs[l2].blocks.size(); ++b2) {
          const measure::LogBlock& later = logs[l2].blocks[b2];
          again = again || (visit >= later.first_visit && visit <= later.last_visit);
        }
      }
      if (again) continue;
      const int resume = visit > 0 ? visit : std::max(block.first_visit, block.last_visit_logged);
      diags.Report(DiagKind::MeasureLogCut, block.cut->where, Printable(BaseName(log.name)),
                   visit > 0 ? fmt::format(" (visit {})", visit) : "", plan, resume);
    }
  }
  std::vector<measure::Reading> readings;
  for (auto& [key, reading] : by_key) readings.push_back(reading);
  return readings;
}

// The stations whose readings the region's table needs: those that measured
// its nodes and check points, and every station tied to them.
std::set<int> StationsToRead(const measure::Plan& plan, std::size_t region) {
  std::set<int> stations, frontier;
  for (const measure::Visit& v : plan.visits) {
    if (v.region == region && (v.kind == measure::VisitKind::kNode || v.kind == measure::VisitKind::kCheck)) {
      frontier.insert(v.station);
    }
  }
  while (!frontier.empty()) {
    const int s = *frontier.begin();
    frontier.erase(frontier.begin());
    if (!stations.insert(s).second) continue;
    for (const measure::PlanStation& station : plan.stations) {
      if (station.number != s) continue;
      for (int t : station.tied_to) {
        if (!stations.contains(t)) frontier.insert(t);
      }
    }
  }
  return stations;
}

// What the logs say about a visit they lack: the run that should have
// measured it and how it ended, or that no log given holds its station.
std::string WhyMissing(const std::vector<measure::MeasuringLog>& logs, const measure::Visit& missing,
                       const measure::Plan& plan, std::size_t region) {
  const int visit = missing.number;
  bool covered = false;
  for (const measure::MeasuringLog& log : logs) {
    for (const measure::LogBlock& block : log.blocks) covered = covered || (visit >= block.first_visit && visit <= block.last_visit);
  }
  if (!covered) {
    return fmt::format(" (no log given holds station {}{}: give every log of the stations tied to region {}'s, "
                       "in the order they ran)",
                       missing.station, missing.region == region ? "" : ", whose ties register region's readings",
                       plan.regions[region].name);
  }
  std::string why;
  for (const measure::MeasuringLog& log : logs) {
    for (const measure::LogBlock& block : log.blocks) {
      if (visit < block.first_visit || visit > block.last_visit) continue;
      if (!block.stopped.empty()) {
        why = fmt::format(" ({} says: {})", BaseName(log.name), block.stopped);
      } else if (!block.ended) {
        why = fmt::format(" ({} stopped {} without a word: LinuxCNC stopped the program - its own error, an "
                          "e-stop or a power cut; its error message says why)",
                          BaseName(log.name),
                          block.last_visit_logged > 0 ? fmt::format("after visit {} repetition {}",
                                                                     block.last_visit_logged,
                                                                     block.last_repetition_logged)
                                                      : "before its first reading");
      }
    }
  }
  return why;
}

void RunRead(const ReadOptions& opt, GlobalOptions& options) {
  std::vector<NamedFile> inputs;
  for (const std::string& log : opt.logs) inputs.push_back({"LOG", log});
  inputs.push_back({"PLAN", opt.plan});
  inputs.push_back({"--cell", opt.cell});
  inputs.push_back({"--external", opt.external});
  if (FilesClash(inputs, {{"-o", opt.output}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<cell::Cell> cell;
  std::optional<measure::LoadedPlan> plan;
  if (!LoadMeasurePlan(opt.plan, opt.cell, sources, diags, options, cell, plan)) return;
  const std::uint32_t plan_file = plan->file;
  // The region.
  std::optional<std::size_t> region;
  if (opt.region.empty() && plan->plan.regions.size() == 1) region = 0;
  for (std::size_t r = 0; r < plan->plan.regions.size(); ++r) {
    if (!opt.region.empty() && AsciiLowercase(plan->plan.regions[r].name) == AsciiLowercase(opt.region)) region = r;
  }
  if (!region) {
    std::string names;
    for (const measure::PlanRegion& r : plan->plan.regions) names += (names.empty() ? "" : ", ") + r.name;
    options.exit_code = ReportUsageError(fmt::format(
        "{}: name the region to read with --region (the plan has {})",
        opt.region.empty() ? "the plan measures several regions" : "--region " + opt.region + " is not in the plan",
        names));
    return;
  }
  const measure::PlanRegion& grid = plan->plan.regions[*region];
  // The logs.
  std::vector<measure::MeasuringLog> logs;
  for (const std::string& path : opt.logs) {
    Result<std::uint32_t> file = sources.Load(path);
    if (!file) {
      options.exit_code = ReportIoError(file.error());
      return;
    }
    if (std::optional<measure::MeasuringLog> log = measure::ReadMeasuringLog(file.value(), *plan, diags)) {
      logs.push_back(std::move(*log));
    }
  }
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  for (const measure::MeasuringLog& log : logs) measure::CheckLogSettings(log, *cell, diags);
  int replaced = 0;
  std::vector<measure::Reading> all = MergeReadings(logs, BaseName(opt.plan), replaced, diags);
  std::map<std::pair<int, int>, measure::Reading*> by_key;
  for (measure::Reading& reading : all) by_key[{reading.visit, reading.repetition}] = &reading;
  const measure::Plan& the_plan = plan->plan;
  // The stations the region's table needs: those that measured its nodes,
  // and every station tied to them (the registration needs them all).
  const std::set<int> needed = StationsToRead(the_plan, *region);
  // Every reading of those stations, in plan order.
  std::vector<measure::Reading> readings;
  for (std::size_t k = 0; k < the_plan.visits.size(); ++k) {
    const measure::Visit& visit = the_plan.visits[k];
    if (!needed.contains(visit.station)) continue;
    for (int rep = 1; rep <= visit.repetitions; ++rep) {
      auto it = by_key.find({visit.number, rep});
      if (it != by_key.end()) {
        readings.push_back(*it->second);
        continue;
      }
      if (!diags.has_errors()) {
        diags.Report(DiagKind::MeasureLogIncomplete,
                     SourceRange(SourceLoc{plan_file, plan->lines[k], 1}), visit.number, visit.node,
                     the_plan.regions[visit.region].name, FormatMm(visit.at.x()), FormatMm(visit.at.y()), visit.set,
                     rep, WhyMissing(logs, visit, the_plan, *region), BaseName(opt.plan), visit.number);
      }
    }
  }
  const cell::Measure& device = *cell->measure;
  // Every reading against what the device can give and against its node's
  // others, before any correction spreads it.
  if (!diags.has_errors()) measure::CheckReadings(device, cell->robot, readings, BaseName(opt.plan), diags);
  if (device.device == cell::MeasureDevice::kExternal) {
    if (opt.external.empty()) {
      options.exit_code =
          ReportUsageError("the device is external: give its readings with --external READINGS.csv");
      return;
    }
    Result<std::uint32_t> file = sources.Load(opt.external);
    if (!file) {
      options.exit_code = ReportIoError(file.error());
      return;
    }
    std::optional<std::vector<ExternalReading>> external = ReadExternalReadings(file.value(), diags);
    if (external) {
      std::map<std::tuple<long long, long long, long long>, const ExternalReading*> found;
      for (const ExternalReading& e : *external) {
        auto [it, fresh] = found.try_emplace({e.node, e.set, e.repetition}, &e);
        if (!fresh) diags.Report(DiagKind::MeasureExternalDuplicate, e.range, e.node, e.set, e.repetition, it->second->line);
      }
      std::set<std::tuple<long long, long long, long long>> used;
      for (const measure::Reading& r : all) used.insert({r.node, r.set, r.repetition});
      std::vector<SourceRange> external_where;
      for (measure::Reading& r : readings) {
        auto it = found.find({r.node, r.set, r.repetition});
        if (it == found.end()) {
          diags.Report(DiagKind::MeasureExternalMissing, r.where, r.node, r.set, r.repetition, r.visit,
                       r.where.begin.line);
          continue;
        }
        r.external = it->second->at;
        external_where.push_back(it->second->range);
      }
      for (const ExternalReading& e : *external) {
        if (!used.contains({e.node, e.set, e.repetition})) {
          diags.Report(DiagKind::MeasureExternalUnknown, e.range, e.node, e.set, e.repetition);
        }
      }
      if (!diags.has_errors()) {
        measure::CheckExternalReadings(device, cell->robot, readings, external_where, BaseName(opt.plan), diags);
      }
    }
  }
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  // The errors as read in each placement, the closures, the registration.
  measure::ReadOutcome outcome =
      measure::RegisterReadings(*cell, the_plan, readings, BaseName(opt.plan), diags);
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  std::vector<RawMeasurement> rows;
  std::vector<bool> checks;
  for (const measure::RegisteredError& e : outcome.errors) {
    const measure::Reading& r = readings[e.reading];
    if (r.region != *region || (r.kind != measure::VisitKind::kNode && r.kind != measure::VisitKind::kCheck)) continue;
    RawMeasurement m;
    m.axis = e.axis;
    m.x_mm = r.at.x();
    m.y_mm = r.at.y();
    m.set = r.set;
    m.repetition = r.repetition;
    m.error_mm = e.error_mm;
    m.u_mm = e.u_mm;
    m.reverse = r.direction < 0;
    rows.push_back(m);
    checks.push_back(r.kind == measure::VisitKind::kCheck);
  }
  // Axis x first, then y, each in plan order (a stable sort keeps it).
  std::vector<std::size_t> order(rows.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return rows[a].axis < rows[b].axis; });
  std::vector<RawMeasurement> sorted;
  std::vector<bool> sorted_checks;
  for (std::size_t k : order) {
    sorted.push_back(rows[k]);
    sorted_checks.push_back(checks[k]);
  }
  std::vector<std::string> comment;
  comment.push_back(fmt::format("Raw position-error measurements of region {} of cell '{}', read by smtcal measure read",
                                grid.name, cell->name));
  comment.push_back(fmt::format("plan {} (digest {}); cell {}; device {}", BaseName(opt.plan), plan->digest,
                                BaseName(opt.cell), cell::kMeasureDeviceNames[static_cast<std::size_t>(device.device)]));
  comment.push_back(std::string(measure::kMeasuredWithMark.substr(2)) + measure::MeasuredWith(*cell));
  for (const measure::MeasuringLog& log : logs) {
    for (const measure::LogBlock& block : log.blocks) {
      comment.push_back(fmt::format("log {}: visits {}..{}{}", BaseName(log.name), block.first_visit, block.last_visit,
                                    block.ended ? ", ran to its end" : block.stopped.empty() ? ", stopped" : ", " + block.stopped));
    }
  }
  if (!opt.external.empty()) comment.push_back(fmt::format("external readings {}", BaseName(opt.external)));
  if (replaced > 0) {
    comment.push_back(fmt::format("{} reading{} of a stopped run replaced by the resumed run's", replaced,
                                  replaced == 1 ? "" : "s"));
  }
  for (const std::string& note : outcome.notes) comment.push_back(note);
  for (const std::string& line : measure::DescribeBudget(*cell, the_plan, outcome, *region, readings)) comment.push_back(line);
  comment.push_back(fmt::format("Build the table: smtcal table build {} -o TABLE.csv", BaseName(opt.output)));
  Status written = WriteFileAtomically(opt.output, FormatRawCsv(sorted, sorted_checks, comment));
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  options.exit_code = PrintDiagnostics(diags, options);
  SayDone(options, opt.output,
          fmt::format("wrote {} ({} readings of region {}{})", opt.output, rows.size() / (device.device ==
                                                                    cell::MeasureDevice::kTransducer ? 1 : 2),
                      grid.name, replaced > 0 ? fmt::format("; {} of a stopped run replaced", replaced) : ""));
}

}  // namespace

void AddMeasureReadCommand(CLI::App& measure, GlobalOptions& options) {
  static ReadOptions opt;
  CLI::App* read = measure.add_subcommand(
      "read",
      "Read the measuring programs' logs (and an external system's readings) back into the raw measurements of\n"
      "one region (axis,x_mm,y_mm,set,repetition,error_mm[,kind]) for smtcal table build, with where they came\n"
      "from in the comments. A visit no log has is an error naming the visit to resume at");
  read->add_option("PLAN", opt.plan, "the plan the programs were made from")->required();
  read->add_option("LOG", opt.logs, "the logs the programs wrote, in the order they ran")->required();
  read->add_option("--cell", opt.cell, "the cell file ([measure] says what a reading means)")->required();
  read->add_option("--region", opt.region, "the region to read (needed when the plan has several)");
  read->add_option("--external", opt.external,
                   "the external system's readings: node,set,repetition,x_mm,y_mm (device external)");
  read->add_option("-o,--output", opt.output, "the raw measurement CSV to write ('-' for stdout)")->required();
  read->callback([&options] { RunRead(opt, options); });
}

}  // namespace smtcal::tools

// The baseline file (spc/baseline_file.h).
#include "spc/baseline_file.h"

#include <cmath>

#include <fmt/format.h>

#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal {

using nlohmann::ordered_json;

std::string BaselineJsonText(const MonitorBaseline& baseline) {
  ordered_json json;
  json["smtcal_monitor_baseline"] = kBaselineFormat;
  json["cell"] = baseline.cell;
  ordered_json files = ordered_json::array();
  for (const BaselineFile& file : baseline.files) files.push_back({{"path", file.path}, {"sha256", file.sha256}});
  json["files"] = files;
  json["logs"] = baseline.logs;
  ordered_json fixtures = ordered_json::array();
  for (const FixtureBaseline& b : baseline.fixtures) {
    ordered_json f;
    f["fixture"] = b.fixture;
    f["first_scan"] = b.first_scan;
    f["last_scan"] = b.last_scan;
    f["first_record"] = b.first_record;
    f["last_record"] = b.last_record;
    f["scans"] = b.scans;
    ordered_json refused = ordered_json::object();
    for (ScanCheck check : kScanChecks) refused[std::string(ScanCheckName(check))] = b.refused[static_cast<std::size_t>(check) - 1];
    f["refused"] = refused;
    f["refused_any"] = b.refused_any;
    ordered_json charts = ordered_json::object();
    for (std::size_t q = 0; q < kQuantities; ++q) {
      if (!b.charts[q]) continue;
      const ChartReference& r = *b.charts[q];
      charts[std::string(QuantityName(static_cast<Quantity>(q)))] = {
          {"n", r.n}, {"center", r.center}, {"sigma", r.sigma_estimate}, {"mr_mean", r.mr_mean}};
    }
    f["charts"] = charts;
    fixtures.push_back(f);
  }
  json["fixtures"] = fixtures;
  return JsonText(json);
}

namespace {

class BaselineReader {
 public:
  BaselineReader(std::uint32_t file, Diagnostics& diags) : file_(file), diags_(diags) {}

  std::nullopt_t Fail(std::string what) {
    diags_.Report(DiagKind::MonitorBaselineFile, SourceRange(SourceLoc{file_, 0, 0}),
                  fmt::format("the baseline '{}' {}; write it again with smtcal monitor --baseline-out",
                              Printable(diags_.sources().File(file_).name), what));
    return std::nullopt;
  }

  // A whole number at `key` of `json` within [lo, hi].
  std::optional<long> Whole(const ordered_json& json, const char* key, std::string_view where, long lo, long hi) {
    if (!json.contains(key) || !json[key].is_number_integer() || json[key].get<long long>() < lo ||
        json[key].get<long long>() > hi) {
      return Fail(fmt::format("has no whole number from {} to {} at \"{}\"{}", lo, hi, key, where));
    }
    return static_cast<long>(json[key].get<long long>());
  }
  std::optional<double> Finite(const ordered_json& json, const char* key, std::string_view where, double lo) {
    if (!json.contains(key) || !json[key].is_number() || !std::isfinite(json[key].get<double>()) ||
        json[key].get<double>() < lo) {
      Fail(fmt::format("has no finite number{} at \"{}\"{}", lo > -1e300 ? fmt::format(" of at least {}", lo) : "",
                       key, where));
      return std::nullopt;
    }
    return json[key].get<double>();
  }
  std::optional<std::string> Text(const ordered_json& json, const char* key, std::string_view where) {
    if (!json.contains(key) || !json[key].is_string()) {
      Fail(fmt::format("has no text at \"{}\"{}", key, where));
      return std::nullopt;
    }
    return json[key].get<std::string>();
  }

  std::optional<MonitorBaseline> Read(const cell::Cell& cell) {
    const SourceFile& source = diags_.sources().File(file_);
    JsonParse parsed = ParseJson(source.text);
    if (!parsed.value) {
      diags_.Report(DiagKind::MonitorBaselineFile, SourceRange(source.LocationOf(file_, parsed.error_offset)),
                    fmt::format("the baseline '{}' is not valid JSON: {}", Printable(source.name), parsed.error));
      return std::nullopt;
    }
    const ordered_json& json = *parsed.value;
    if (!json.is_object() || !json.contains("smtcal_monitor_baseline")) {
      Fail("is not a baseline of smtcal monitor (it has no \"smtcal_monitor_baseline\")");
      return std::nullopt;
    }
    if (!json["smtcal_monitor_baseline"].is_number_integer() ||
        json["smtcal_monitor_baseline"].get<long long>() != kBaselineFormat) {
      Fail(fmt::format("is of a format this smtcal does not read (it reads {})", kBaselineFormat));
      return std::nullopt;
    }
    MonitorBaseline baseline;
    const std::optional<std::string> name = Text(json, "cell", "");
    if (!name) return std::nullopt;
    baseline.cell = *name;
    if (!json.contains("files") || !json["files"].is_array() || json["files"].empty()) {
      Fail("has no \"files\" (the cell file and its tables with their SHA-256)");
      return std::nullopt;
    }
    for (const ordered_json& f : json["files"]) {
      if (!f.is_object()) return Fail("has an entry of \"files\" that is not an object");
      const std::optional<std::string> path = Text(f, "path", " of \"files\""), sha = Text(f, "sha256", " of \"files\"");
      if (!path || !sha) return std::nullopt;
      baseline.files.push_back({*path, *sha});
    }
    if (json.contains("logs") && json["logs"].is_array()) {
      for (const ordered_json& l : json["logs"]) {
        if (l.is_string()) baseline.logs.push_back(l.get<std::string>());
      }
    }
    if (!json.contains("fixtures") || !json["fixtures"].is_array()) {
      Fail("has no \"fixtures\"");
      return std::nullopt;
    }
    for (const ordered_json& f : json["fixtures"]) {
      if (!f.is_object()) return Fail("has an entry of \"fixtures\" that is not an object");
      FixtureBaseline b;
      const std::optional<std::string> fixture = Text(f, "fixture", " of \"fixtures\"");
      if (!fixture) return std::nullopt;
      b.fixture = *fixture;
      const std::string where = fmt::format(" of fixture '{}'", Printable(b.fixture));
      const std::optional<long> first = Whole(f, "first_scan", where, 1, 2'000'000'000);
      const std::optional<long> last = Whole(f, "last_scan", where, first.value_or(1), 2'000'000'000);
      const std::optional<long> scans = Whole(f, "scans", where, 1, 2'000'000'000);
      if (!first || !last || !scans) return std::nullopt;
      b.first_scan = *first;
      b.last_scan = *last;
      b.scans = *scans;
      b.first_record = f.contains("first_record") && f["first_record"].is_string() ? f["first_record"].get<std::string>() : "";
      b.last_record = f.contains("last_record") && f["last_record"].is_string() ? f["last_record"].get<std::string>() : "";
      const std::optional<long> any = Whole(f, "refused_any", where, 0, b.scans);
      if (!any) return std::nullopt;
      b.refused_any = *any;
      if (!f.contains("refused") || !f["refused"].is_object()) return Fail(fmt::format("has no \"refused\"{}", where));
      for (ScanCheck check : kScanChecks) {
        const std::string key(ScanCheckName(check));
        const std::optional<long> count = Whole(f["refused"], key.c_str(), where, 0, b.refused_any);
        if (!count) return std::nullopt;
        b.refused[static_cast<std::size_t>(check) - 1] = *count;
      }
      if (!f.contains("charts") || !f["charts"].is_object()) return Fail(fmt::format("has no \"charts\"{}", where));
      for (const auto& [key, chart] : f["charts"].items()) {
        const std::optional<Quantity> q = QuantityNamed(key);
        if (!q || !chart.is_object()) {
          return Fail(fmt::format("has a chart '{}'{} that smtcal monitor does not draw", Printable(key), where));
        }
        const std::string at = fmt::format(" of chart {}{}", key, where);
        ChartReference r;
        const std::optional<long> n = Whole(chart, "n", at, static_cast<long>(kMinBaseline), 2'000'000'000);
        const std::optional<double> center = Finite(chart, "center", at, -1e300);
        const std::optional<double> sigma = Finite(chart, "sigma", at, 0);
        const std::optional<double> mr = Finite(chart, "mr_mean", at, 0);
        if (!n || !center || !sigma || !mr) return std::nullopt;
        if (!(*sigma > 0)) return Fail(fmt::format("has a sigma of 0{}", at));
        r.n = *n;
        r.center = *center;
        r.sigma_estimate = *sigma;
        r.mr_mean = *mr;
        b.charts[static_cast<std::size_t>(*q)] = r;
      }
      baseline.fixtures.push_back(std::move(b));
    }
    if (!SameCell(baseline, cell)) return std::nullopt;
    return baseline;
  }

  // The cell file and every table the same bytes as when the baseline was
  // taken: another table changes what the charts measure.
  bool SameCell(const MonitorBaseline& baseline, const cell::Cell& cell) {
    std::vector<std::string> differ;
    if (cell.files.empty() || baseline.files.front().sha256 != cell.files.front().sha256) {
      differ.push_back(fmt::format("the cell file (sha256 {} then, {} now)", baseline.files.front().sha256.substr(0, 12),
                                   cell.files.empty() ? "?" : cell.files.front().sha256.substr(0, 12)));
    }
    for (std::size_t i = 1; i < cell.files.size(); ++i) {
      const cell::CellFile& now = cell.files[i];
      const BaselineFile* then = nullptr;
      for (std::size_t j = 1; j < baseline.files.size(); ++j) {
        if (baseline.files[j].path == now.path) then = &baseline.files[j];
      }
      if (then == nullptr) {
        differ.push_back(fmt::format("table {} (not in the baseline)", now.path));
      } else if (then->sha256 != now.sha256) {
        differ.push_back(fmt::format("table {} (sha256 {} then, {} now)", now.path, then->sha256.substr(0, 12),
                                     now.sha256.substr(0, 12)));
      }
    }
    if (differ.empty()) return true;
    std::string list;
    for (std::size_t i = 0; i < differ.size(); ++i) list += (i == 0 ? "" : "; ") + differ[i];
    diags_.Report(DiagKind::MonitorBaselineOtherCell, SourceRange(SourceLoc{file_, 0, 0}),
                  fmt::format("the baseline '{}' was taken with cell '{}' as it was then, and the files differ: {}; "
                              "the charts would judge against a cell that is gone: take a new baseline with this cell "
                              "(--baseline-out), or monitor with the cell it was taken with",
                              Printable(diags_.sources().File(file_).name), Printable(baseline.cell), list));
    return false;
  }

 private:
  std::uint32_t file_;
  Diagnostics& diags_;
};

}  // namespace

std::optional<MonitorBaseline> ReadBaseline(std::uint32_t file, const cell::Cell& cell, Diagnostics& diags) {
  return BaselineReader(file, diags).Read(cell);
}

}  // namespace smtcal

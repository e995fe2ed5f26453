// Reading logs of cycle records (frontend/record_log.h; the format is
// docs/monitor.md). Line by line: a begin line sets the fixtures the records
// that follow name; a cycle line opens a record, which its checks line and
// its trip lines complete. Every mistake is reported at its line and field,
// and reading goes on, so one run reports all of them.
#include "frontend/record_log.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include <fmt/format.h>

#include "base/field_text.h"
#include "calibration/tolerances.h"
#include "frontend/input_kind.h"

namespace smtcal {
namespace {

constexpr std::string_view kBeginTag = "smtcal-record";
constexpr std::size_t kCycleFields = 12;   // cycle F N STATUS TRIP TIME S1x S1y S2x S2y S3x S3y
constexpr std::size_t kChecksFields = 3 + kScanChecks.size();  // checks F N V1..V11
constexpr std::size_t kTripFields = 6;     // trip F N K X Y
constexpr int kMaxRecordTrips = 32;        // the runtimes' SMTCAL_MAX_TRIPS

struct Token {
  std::string_view text;
  std::uint32_t column = 1;  // 1-based
};

std::vector<Token> Split(std::string_view line) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) tokens.push_back({line.substr(start, i - start), static_cast<std::uint32_t>(start + 1)});
  }
  return tokens;
}

std::string Plural(std::size_t n, std::string_view word) {
  return fmt::format("{} {}{}", n, word, n == 1 ? "" : "s");
}

class Reader {
 public:
  Reader(std::uint32_t file, RecordLog& log, Diagnostics& diags) : file_(file), log_(log), diags_(diags) {}

  bool Run() {
    if (ReportOtherInputKind(file_, {InputKind::kRecordLog}, "a log of cycle records", diags_)) return false;
    const std::size_t errors_before = diags_.error_count();
    const SourceFile& source = diags_.sources().File(file_);
    const std::string_view text = source.text;
    const bool cut_off = !text.empty() && text.back() != '\n';
    const auto lines = static_cast<std::uint32_t>(source.line_starts.size());
    bool begun = false;
    for (std::uint32_t n = 1; n <= lines; ++n) {
      std::string_view line = source.Line(n);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      line_ = n;
      const std::vector<Token> tokens = Split(line);
      if (tokens.empty() || tokens.front().text.starts_with('#')) continue;
      if (n == lines && cut_off) {
        CutOff(tokens.front().text);
        break;
      }
      const std::string_view kind = tokens.front().text;
      if (!begun && kind != kBeginTag) {
        diags_.Report(DiagKind::RecordNoBegin, At(tokens.front()),
                      fmt::format("the first line of '{}' is '{}'", Printable(source.name),
                                  Printable(line.substr(0, 40))));
        return false;
      }
      if (kind == kBeginTag) {
        Close();
        if (!Begin(tokens)) return false;  // a version this reader cannot read
        begun = true;
      } else if (kind == "cycle") {
        Close();
        Cycle(tokens);
      } else if (kind == "checks") {
        Checks(tokens);
      } else if (kind == "trip") {
        Trip(tokens);
      } else {
        diags_.Report(DiagKind::RecordUnknownLine, At(tokens.front()), Printable(kind));
        pending_.reset();
      }
    }
    Close();
    if (!begun && diags_.error_count() == errors_before) {
      diags_.Report(DiagKind::RecordNoBegin, SourceRange(SourceLoc{file_, 1, 1}),
                    fmt::format("'{}' holds no line", Printable(source.name)));
    }
    return diags_.error_count() == errors_before;
  }

 private:
  // A cycle's record being read: its cycle line came, its checks line and
  // trip lines are expected next.
  struct Pending {
    LoggedCycle cycle;
    std::size_t trips = 0;  // the fixture's trip count
    bool have_checks = false;
    std::size_t next_trip = 0;  // trip lines read
    bool broken = false;        // a line of it had an error: dropped when closed
  };

  SourceRange At(const Token& token) const {
    return SourceRange(SourceLoc{file_, line_, token.column}, static_cast<std::uint32_t>(token.text.size()));
  }
  SourceRange LineStart() const { return SourceRange(SourceLoc{file_, line_, 1}); }

  const RecordBegin& CurrentBegin() const { return log_.begins[current_begin_].begin; }
  std::string FixtureName(int fixture) const {
    return CurrentBegin().fixtures[static_cast<std::size_t>(fixture)].name;
  }

  // --- fields ------------------------------------------------------------------

  std::optional<double> Number(const Token& token, std::string_view what) {
    const std::optional<double> value = ParseNumber(token.text);
    if (!value) {
      diags_.Report(DiagKind::RecordBadField, At(token), what, Printable(token.text), "not a number");
      return std::nullopt;
    }
    if (!std::isfinite(*value)) {
      diags_.Report(DiagKind::RecordBadField, At(token), what, Printable(token.text), "not a finite number");
      return std::nullopt;
    }
    return value;
  }

  // A number or '-' (not measured): nullopt in `value` for '-'; false on an error.
  bool MaybeNumber(const Token& token, std::string_view what, std::optional<double>& value) {
    value.reset();
    if (token.text == "-") return true;
    value = Number(token, what);
    return value.has_value();
  }

  std::optional<long> Whole(const Token& token, std::string_view what, long lo, long hi) {
    const std::optional<double> value = Number(token, what);
    if (!value) return std::nullopt;
    if (*value != std::floor(*value)) {
      diags_.Report(DiagKind::RecordBadField, At(token), what, Printable(token.text), "not a whole number");
      return std::nullopt;
    }
    if (*value < static_cast<double>(lo) || *value > static_cast<double>(hi)) {
      diags_.Report(DiagKind::RecordBadField, At(token), what, Printable(token.text),
                    fmt::format("outside {}..{}", lo, hi));
      return std::nullopt;
    }
    return static_cast<long>(*value);
  }

  bool FieldCount(const std::vector<Token>& tokens, std::size_t want) {
    if (tokens.size() == want) return true;
    const SourceRange where = tokens.size() > want ? At(tokens[want]) : At(tokens.back());
    diags_.Report(DiagKind::RecordFieldCount, where, tokens.front().text, Plural(tokens.size(), "field"),
                  Plural(want, "field"));
    return false;
  }

  // The fixture number of a cycle, checks or trip line.
  std::optional<int> Fixture(const Token& token) {
    const long count = static_cast<long>(CurrentBegin().fixtures.size());
    if (count == 0) {
      diags_.Report(DiagKind::RecordBadField, At(token), "the fixture", Printable(token.text),
                    "the begin line names no fixture");
      return std::nullopt;
    }
    const std::optional<long> k = Whole(token, "the fixture", 0, count - 1);
    if (!k) return std::nullopt;
    return static_cast<int>(*k);
  }

  // --- lines ---------------------------------------------------------------------

  // smtcal-record VERSION cell=NAME fixtures=NAME:TRIPS,... clock=NAME segment=N
  bool Begin(const std::vector<Token>& tokens) {
    LoggedBegin logged;
    logged.where = At(tokens.front());
    if (tokens.size() < 2) {
      diags_.Report(DiagKind::RecordFieldCount, At(tokens.front()), kBeginTag, "no version",
                    "its format version and the keys cell, fixtures, clock and segment");
      return false;
    }
    const std::optional<long> version = Whole(tokens[1], "the format version", 1, 1'000'000);
    if (!version) return false;
    if (*version != kRecordFormat) {
      // Format 1's LinuxCNC runtime wrote every value below 1e-4 mm or deg
      // as 0 (a kinder number than was measured), and its logs cannot say
      // which runtime wrote them.
      diags_.Report(DiagKind::RecordVersion, At(tokens[1]), *version, kRecordFormat,
                    *version == 1 ? "in format 1 the LinuxCNC runtime wrote every value below 1e-4 mm or deg as 0, "
                                    "so small residuals and deltas read as zero; recompile the program with this "
                                    "smtcal and record again"
                                  : "read it with the smtcal that matches the controller's runtime");
      return false;
    }
    RecordBegin& begin = logged.begin;
    begin.version = static_cast<int>(*version);
    const std::vector<std::string> keys = {"cell", "fixtures", "clock", "segment"};
    std::map<std::string, Token> given;
    bool ok = true;
    for (std::size_t i = 2; i < tokens.size(); ++i) {
      const std::string_view text = tokens[i].text;
      const std::size_t equals = text.find('=');
      const std::string key(text.substr(0, equals));
      const bool known = std::find(keys.begin(), keys.end(), key) != keys.end();
      if (equals == std::string_view::npos || !known) {
        const std::string closest = ClosestName(key, keys);
        diags_.Report(DiagKind::RecordBadBeginKey, At(tokens[i]),
                      fmt::format("'{}' is not a key of the begin line{}: its keys are cell=, fixtures=, clock= "
                                  "and segment=",
                                  Printable(text), closest.empty() ? "" : fmt::format(" (did you mean '{}='?)", closest)));
        ok = false;
        continue;
      }
      if (given.count(key)) {
        diags_.Report(DiagKind::RecordBadBeginKey, At(tokens[i]), fmt::format("the key '{}' is given twice", key));
        ok = false;
        continue;
      }
      Token value = tokens[i];
      value.text = text.substr(equals + 1);
      value.column += static_cast<std::uint32_t>(equals + 1);
      given[key] = value;
    }
    for (const std::string& key : keys) {
      if (!given.count(key)) {
        diags_.Report(DiagKind::RecordBadBeginKey, At(tokens.back()),
                      fmt::format("the begin line has no '{}=' key", key));
        ok = false;
      }
    }
    if (!ok) return false;
    auto name = [&](const char* key) -> std::optional<std::string> {
      const Token& value = given.at(key);
      if (value.text.empty()) {
        diags_.Report(DiagKind::RecordBadField, At(value), fmt::format("the {}", key), "", "an empty name");
        return std::nullopt;
      }
      return std::string(value.text);
    };
    const std::optional<std::string> cell = name("cell"), clock = name("clock");
    const std::optional<long> segment = Whole(given.at("segment"), "the segment", 0, 1'000'000'000);
    bool fixtures_ok = true;
    const Token& fixtures = given.at("fixtures");
    if (fixtures.text != "-") {
      std::size_t start = 0;
      for (;;) {
        const std::size_t comma = fixtures.text.find(',', start);
        const std::string_view item = fixtures.text.substr(start, comma == std::string_view::npos ? comma : comma - start);
        Token part{item, fixtures.column + static_cast<std::uint32_t>(start)};
        const std::size_t colon = item.rfind(':');
        if (item.empty() || colon == std::string_view::npos || colon == 0) {
          diags_.Report(DiagKind::RecordBadField, At(part), "a fixture", Printable(item),
                        "write each as NAME:TRIPS, the fixture's name and its number of trips");
          fixtures_ok = false;
        } else {
          Token count{item.substr(colon + 1), part.column + static_cast<std::uint32_t>(colon + 1)};
          const std::optional<long> trips = Whole(count, "a fixture's trip count", 1, kMaxRecordTrips);
          if (!trips) {
            fixtures_ok = false;
          } else {
            begin.fixtures.push_back({std::string(item.substr(0, colon)), static_cast<std::size_t>(*trips)});
          }
        }
        if (comma == std::string_view::npos) break;
        start = comma + 1;
      }
    }
    if (!cell || !clock || !segment || !fixtures_ok) return false;
    begin.cell = *cell;
    begin.clock = *clock;
    begin.segment = *segment;
    if (!log_.begins.empty() && begin.segment < log_.begins.back().begin.segment) {
      diags_.Report(DiagKind::RecordInconsistent, At(given.at("segment")),
                    fmt::format("segment {} follows segment {}: the log goes back in time; give its files oldest "
                                "first",
                                begin.segment, log_.begins.back().begin.segment));
      return false;
    }
    current_begin_ = log_.begins.size();
    log_.begins.push_back(std::move(logged));
    return true;
  }

  // cycle F N STATUS TRIP TIME S1x S1y S2x S2y S3x S3y
  void Cycle(const std::vector<Token>& tokens) {
    if (!FieldCount(tokens, kCycleFields)) return;
    const std::optional<int> fixture = Fixture(tokens[1]);
    const std::optional<long> cycle = Whole(tokens[2], "the cycle", 1, 2'000'000'000);
    const std::optional<long> status = Whole(tokens[3], "the status", 0, static_cast<long>(kScanChecks.size()));
    const std::size_t trips = fixture ? CurrentBegin().fixtures[static_cast<std::size_t>(*fixture)].trips : 0;
    const std::optional<long> trip = Whole(tokens[4], "the failed check's trip", 0, fixture ? static_cast<long>(trips) : 32);
    std::optional<double> time;
    bool ok = MaybeNumber(tokens[5], "the time", time);
    std::array<std::optional<double>, 6> s;
    int given = 0;
    for (std::size_t i = 0; i < 6; ++i) {
      ok = MaybeNumber(tokens[6 + i], "an estimated crossing's coordinate", s[i]) && ok;
      given += s[i] ? 1 : 0;
    }
    if (ok && given != 0 && given != 6) {
      diags_.Report(DiagKind::RecordInconsistent, At(tokens[6]),
                    "the crossings S1, S2, S3 are given in part: write all six numbers, or '-' for each when the "
                    "scan gave no pose");
      ok = false;
    }
    if (!ok || !fixture || !cycle || !status || !trip) {
      pending_.reset();
      return;
    }
    Pending pending;
    pending.trips = trips;
    LoggedCycle& logged = pending.cycle;
    logged.begin = current_begin_;
    logged.where = At(tokens.front());
    CycleRecord& record = logged.record;
    record.fixture = *fixture;
    record.cycle = *cycle;
    record.status = static_cast<int>(*status);
    record.trip = static_cast<int>(*trip) - 1;
    record.time_s = time;
    if (given == 6) {
      record.estimate = std::array<Eigen::Vector2d, 3>{Eigen::Vector2d(*s[0], *s[1]), Eigen::Vector2d(*s[2], *s[3]),
                                                       Eigen::Vector2d(*s[4], *s[5])};
    }
    record.trips.assign(trips, std::nullopt);
    pending_ = std::move(pending);
  }

  // Whether a checks or trip line belongs to the record being read; reports
  // what was expected when not.
  bool Continues(const std::vector<Token>& tokens, std::string_view kind) {
    if (!pending_) {
      diags_.Report(DiagKind::RecordOutOfOrder, At(tokens.front()),
                    fmt::format("a {} line without the cycle line before it", kind));
      return false;
    }
    const std::optional<int> fixture = tokens.size() > 1 ? Fixture(tokens[1]) : std::nullopt;
    const std::optional<long> cycle = tokens.size() > 2 ? Whole(tokens[2], "the cycle", 1, 2'000'000'000) : std::nullopt;
    if (!fixture || !cycle) {
      pending_->broken = true;
      return false;
    }
    const CycleRecord& record = pending_->cycle.record;
    if (*fixture != record.fixture || *cycle != record.cycle) {
      diags_.Report(DiagKind::RecordOutOfOrder, At(tokens[1]),
                    fmt::format("this {} line is of cycle {} of fixture {}, but the record being read is of cycle {} "
                                "of fixture {}",
                                kind, *cycle, *fixture, record.cycle, record.fixture));
      pending_->broken = true;
      return false;
    }
    return true;
  }

  // checks F N V1 .. V11
  void Checks(const std::vector<Token>& tokens) {
    if (!Continues(tokens, "checks")) return;
    Pending& pending = *pending_;
    if (pending.have_checks) {
      diags_.Report(DiagKind::RecordOutOfOrder, At(tokens.front()), "a second checks line of the same cycle");
      pending.broken = true;
      return;
    }
    pending.have_checks = true;
    if (!FieldCount(tokens, kChecksFields)) {
      pending.broken = true;
      return;
    }
    for (std::size_t c = 0; c < kScanChecks.size(); ++c) {
      const std::string what = fmt::format("the value of check {} ({})", c + 1, ScanCheckName(kScanChecks[c]));
      if (!MaybeNumber(tokens[3 + c], what, pending.cycle.record.checks[c])) pending.broken = true;
    }
  }

  // trip F N K X Y
  void Trip(const std::vector<Token>& tokens) {
    if (!Continues(tokens, "trip")) return;
    Pending& pending = *pending_;
    if (!pending.have_checks) {
      diags_.Report(DiagKind::RecordOutOfOrder, At(tokens.front()), "a trip line before the cycle's checks line");
      pending.broken = true;
      return;
    }
    if (!FieldCount(tokens, kTripFields)) {
      pending.broken = true;
      return;
    }
    const long want = static_cast<long>(pending.next_trip) + 1;
    const std::optional<long> k = Whole(tokens[3], "the trip", 1, kMaxRecordTrips);
    if (!k) {
      pending.broken = true;
      return;
    }
    if (*k != want) {
      diags_.Report(DiagKind::RecordOutOfOrder, At(tokens[3]),
                    want > static_cast<long>(pending.trips)
                        ? fmt::format("trip T{}, but fixture '{}' makes {}", *k,
                                      FixtureName(pending.cycle.record.fixture), Plural(pending.trips, "trip"))
                        : fmt::format("trip T{} where T{} comes", *k, want));
      pending.broken = true;
      return;
    }
    std::optional<double> x, y;
    const bool ok = MaybeNumber(tokens[4], "the trip's x", x) && MaybeNumber(tokens[5], "the trip's y", y);
    if (!ok) {
      pending.broken = true;
    } else if (x.has_value() != y.has_value()) {
      diags_.Report(DiagKind::RecordInconsistent, At(tokens[x ? 5 : 4]),
                    "a trip is given in part: write both coordinates, or '-' for both when the sensor did not trip");
      pending.broken = true;
    } else if (x && (std::abs(*x) > kMaxLengthMm || std::abs(*y) > kMaxLengthMm)) {
      diags_.Report(DiagKind::RecordBadField, At(tokens[std::abs(*x) > kMaxLengthMm ? 4 : 5]), "a trip's coordinate",
                    Printable(tokens[std::abs(*x) > kMaxLengthMm ? 4 : 5].text),
                    fmt::format("beyond +-{} mm", kMaxLengthMm));
      pending.broken = true;
    } else if (x) {
      pending.cycle.record.trips[pending.next_trip] = Eigen::Vector2d(*x, *y);
    }
    ++pending.next_trip;
    if (pending.next_trip == pending.trips) Finish();
  }

  // --- records -----------------------------------------------------------------

  // The record being read ends (another record or a begin line follows, or
  // the file ends): incomplete, it is left out with a warning.
  void Close() {
    if (!pending_) return;
    Pending& pending = *pending_;
    if (!pending.broken) {
      const std::string missing = !pending.have_checks ? std::string("its checks line is missing")
                                                       : fmt::format("trip T{} and after are missing", pending.next_trip + 1);
      diags_.Report(DiagKind::RecordIncomplete, pending.cycle.where, pending.cycle.record.cycle,
                    FixtureName(pending.cycle.record.fixture), missing);
    }
    pending_.reset();
  }

  void CutOff(std::string_view kind) {
    const bool continues = pending_ && (kind == "checks" || kind == "trip");
    if (!continues) Close();
    pending_.reset();
    diags_.Report(DiagKind::RecordCutOff, LineStart());
  }

  // The record is complete: its parts agree, its cycle number follows the
  // last of its fixture.
  void Finish() {
    Pending pending = std::move(*pending_);
    pending_.reset();
    if (pending.broken) return;
    CycleRecord& record = pending.cycle.record;
    std::vector<std::string> problems;
    const auto& checks = record.checks;
    auto has = [&](ScanCheck c) { return checks[static_cast<std::size_t>(c) - 1].has_value(); };
    if (const std::optional<ScanCheck> failed = record.failed()) {
      if (!has(*failed)) problems.push_back(fmt::format("the scan failed {} but that check has no value",
                                                        ScanCheckName(*failed)));
      const int last_run = *failed == ScanCheck::kMissingTrip || *failed == ScanCheck::kTripWindow ||
                                   *failed == ScanCheck::kDegenerate
                               ? static_cast<int>(*failed)
                               : static_cast<int>(kScanChecks.size());
      for (int c = last_run + 1; c <= static_cast<int>(kScanChecks.size()); ++c) {
        if (checks[static_cast<std::size_t>(c) - 1]) {
          problems.push_back(fmt::format("check {} has a value, but no check runs after {} fails", c,
                                         ScanCheckName(*failed)));
          break;
        }
      }
    } else {
      if (record.trip >= 0) problems.push_back("an accepted scan names a failed check's trip");
      for (int c = 1; c <= static_cast<int>(ScanCheck::kNominalRotation); ++c) {
        if (!checks[static_cast<std::size_t>(c) - 1]) {
          problems.push_back(fmt::format("an accepted scan has no value for check {} ({})", c,
                                         ScanCheckName(static_cast<ScanCheck>(c))));
          break;
        }
      }
    }
    std::size_t missing = 0;
    for (const auto& trip : record.trips) missing += trip ? 0 : 1;
    if (has(ScanCheck::kMissingTrip) && *checks[0] != static_cast<double>(missing)) {
      problems.push_back(fmt::format("check 1 (missing_trip) says {} trips are missing, the trip lines {}", *checks[0],
                                     missing));
    }
    const bool posed = has(ScanCheck::kDegenerate) && *checks[static_cast<std::size_t>(ScanCheck::kDegenerate) - 1] == 0;
    if (posed != record.estimate.has_value()) {
      problems.push_back(posed ? "the scan gave a pose (check 3 passed) but S1, S2, S3 are not given"
                               : "S1, S2, S3 are given but the scan gave no pose (check 3 did not pass)");
    }
    if (!problems.empty()) {
      std::string text = problems.front();
      for (std::size_t i = 1; i < problems.size(); ++i) text += "; " + problems[i];
      diags_.Report(DiagKind::RecordInconsistent, pending.cycle.where,
                    fmt::format("the record of cycle {} contradicts itself: {}", record.cycle, text));
      return;
    }
    const std::string name = FixtureName(record.fixture);
    auto [last, fresh] = log_.last_cycle.try_emplace(name, 0L);
    if (record.cycle != 1 && !fresh && record.cycle <= last->second) {
      diags_.Report(DiagKind::RecordInconsistent, pending.cycle.where,
                    fmt::format("cycle {} of fixture '{}' follows its cycle {}: the log goes back in time; give its "
                                "files oldest first",
                                record.cycle, name, last->second));
      return;
    }
    if (record.cycle != 1 && record.cycle > last->second + 1 && !fresh) {
      diags_.Report(DiagKind::RecordCycleGap, pending.cycle.where, record.cycle, name, last->second,
                    record.cycle - last->second - 1);
    }
    last->second = record.cycle;
    log_.cycles.push_back(std::move(pending.cycle));
  }

  std::uint32_t file_;
  RecordLog& log_;
  Diagnostics& diags_;
  std::uint32_t line_ = 0;
  std::size_t current_begin_ = 0;
  std::optional<Pending> pending_;
};

}  // namespace

bool ReadRecordLog(std::uint32_t file, RecordLog& log, Diagnostics& diags) { return Reader(file, log, diags).Run(); }

}  // namespace smtcal

// Reading logs of cycle records (frontend/record_log.h; the format is
// docs/monitor.md). Line by line: a begin line starts a run and sets the
// fixtures the records that follow name; a cycle line opens a record, which
// its checks line and its trip lines complete. Bytes that are not records
// (damage: what a power cut, a full disk or an edit leaves) are gathered
// into one stretch until the next line that starts a record or a run, and
// reported once with their byte range; complete records that say
// impossible things are errors at their line, and reading goes on, so one
// run reports all of them.
#include "frontend/record_log.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include <fmt/format.h>

#include "base/field_text.h"
#include "base/number_range.h"
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

std::vector<Token> Split(std::string_view line, std::uint32_t first_column = 1) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) {
      tokens.push_back({line.substr(start, i - start), static_cast<std::uint32_t>(start) + first_column});
    }
  }
  return tokens;
}

std::string Plural(std::size_t n, std::string_view word) {
  return fmt::format("{} {}{}", n, word, n == 1 ? "" : "s");
}

// FNV-1a, 64 bits: a record's text, to recognise it read twice.
std::uint64_t Digest(std::string_view text, std::uint64_t hash = 14695981039346656037ull) {
  for (char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

// A byte no writer of the record writes (they write printable ASCII, spaces
// and tabs).
bool Foreign(char c) {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && c != '\t') || u >= 0x7f;
}

// The range a check's value must lie in (docs/monitor.md, "Values"); its unit.
struct ValueRange {
  double lo = 0, hi = 0;
  std::string_view unit;
};
ValueRange CheckRange(ScanCheck check, std::size_t trips) {
  switch (check) {
    case ScanCheck::kMissingTrip: return {0, static_cast<double>(trips), "trips"};
    case ScanCheck::kDegenerate: return {0, 1, ""};
    case ScanCheck::kSquareness: return {0, kRecordMaxSquarenessDeg, "deg"};
    case ScanCheck::kNominalRotation:
    case ScanCheck::kCycleRotation: return {0, kRecordMaxAngleDeg, "deg"};
    case ScanCheck::kTripWindow:
    case ScanCheck::kLengthL1:
    case ScanCheck::kLengthL2:
    case ScanCheck::kLineResidual:
    case ScanCheck::kNominalShift:
    case ScanCheck::kCycleShift: return {0, kMaxLengthMm, "mm"};
  }
  return {0, 0, ""};
}

class Reader {
 public:
  Reader(std::uint32_t file, RecordLog& log, Diagnostics& diags)
      : file_(file), log_(log), diags_(diags), source_(diags.sources().File(file)) {}

  bool Run() {
    if (ReportOtherInputKind(file_, {InputKind::kRecordLog}, "a log of cycle records", diags_)) return false;
    const std::size_t errors_before = diags_.error_count();
    const std::string_view text = source_.text;
    const bool cut_off = !text.empty() && text.back() != '\n';
    const auto lines = static_cast<std::uint32_t>(source_.line_starts.size());
    // A file without a begin line continues the previous file's last run.
    if (!log_.begins.empty()) current_begin_ = log_.begins.size() - 1;
    begun_ = !log_.begins.empty();
    for (std::uint32_t n = 1; n <= lines; ++n) {
      line_ = n;
      line_start_ = source_.line_starts[n - 1];
      std::string_view line = source_.Line(n);
      if (n == lines && line.empty()) break;  // the end of the file after its last line end
      line_end_ = line_start_ + line.size() + (n == lines && cut_off ? 0 : 1);
      if (n == lines && cut_off) {
        // The file stops in the middle of its last line: what it holds is
        // not known whole.
        Damage(line_start_, line_end_, "the last line, without its end of line (the file was cut while it was written)");
        break;
      }
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      // A begin line glued to what a cut left (the runtime restarted after
      // a power cut): the bytes before it are damage, the begin line is read.
      const std::size_t tag = line.find(kBeginTag);
      if (tag != std::string_view::npos && tag > 0) {
        const std::string_view cut = line.substr(0, tag);
        Damage(line_start_, line_start_ + tag,
               std::any_of(cut.begin(), cut.end(), Foreign)
                   ? ForeignText(cut, n)
                   : fmt::format("line {}: '{}' cut where a begin line starts", n, Printable(Shortened(cut))));
        if (!ReadLine(line.substr(tag), static_cast<std::uint32_t>(tag) + 1)) return false;
        continue;
      }
      if (std::any_of(line.begin(), line.end(), Foreign)) {
        Damage(line_start_, line_end_, ForeignText(line, n));
        continue;
      }
      if (!ReadLine(line, 1)) return false;
    }
    CloseDamage();
    Close();
    if (!begun_ && diags_.error_count() == errors_before) {
      diags_.Report(DiagKind::RecordNoBegin, SourceRange(SourceLoc{file_, 1, 1}),
                    fmt::format("'{}' holds no begin line", Printable(source_.name)));
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
    std::uint64_t digest = 0;
    std::size_t start = 0;      // its first byte
    bool absurd = false;        // a value outside its range (reported): dropped
  };

  // A stretch of bytes that are not records, being gathered.
  struct Damaged {
    std::size_t first = 0, end = 0;  // bytes [first, end)
    std::uint32_t first_line = 0, last_line = 0;
    std::string what;                // the first problem
    std::size_t nul = 0;             // NUL bytes in it
    std::string record;              // the record it cut short, if any
  };

  // One line without damaged bytes (from `column` of the file's line): false
  // when reading cannot go on (no begin line, a format it cannot read).
  bool ReadLine(std::string_view line, std::uint32_t column) {
    const std::vector<Token> tokens = Split(line, column);
    if (tokens.empty() || tokens.front().text.starts_with('#')) return true;
    const std::string_view kind = tokens.front().text;
    if (kind == kBeginTag) {
      CloseDamage();
      Close();
      if (!Begin(tokens)) return false;
      begun_ = true;
      return true;
    }
    if (kind == "cycle" || kind == "checks" || kind == "trip") {
      if (!begun_) {
        diags_.Report(DiagKind::RecordNoBegin, At(tokens.front()),
                      fmt::format("the first record of '{}' comes before any begin line", Printable(source_.name)));
        return false;
      }
      if (kind == "cycle") {
        Cycle(tokens);
      } else if (kind == "checks") {
        Checks(tokens);
      } else {
        Trip(tokens);
      }
      return true;
    }
    Damage(line_start_ + column - 1, line_end_,
           fmt::format("line {}: '{}' is not a line of a record (smtcal-record, cycle, checks, trip)", line_,
                       Printable(Shortened(kind))));
    return true;
  }

  static std::string_view Shortened(std::string_view text) { return text.substr(0, 60); }

  // What a line with bytes no writer writes is: "4096 NUL bytes", "line 66:
  // 'trip 0 7 3 324' cut, then 4096 NUL bytes".
  std::string ForeignText(std::string_view line, std::uint32_t n) const {
    const std::size_t nul = static_cast<std::size_t>(std::count(line.begin(), line.end(), '\0'));
    const std::size_t first = static_cast<std::size_t>(std::find_if(line.begin(), line.end(), Foreign) - line.begin());
    std::string what = nul == line.size() - first ? Plural(nul, "NUL byte")
                                                  : fmt::format("{} no writer of a record writes{}",
                                                                Plural(line.size() - first, "byte"),
                                                                nul > 0 ? fmt::format(" ({} NUL)", nul) : "");
    if (first == 0) return nul == line.size() ? what : fmt::format("line {}: {}", n, what);
    return fmt::format("line {}: '{}' cut, then {}", n, Printable(Shortened(line.substr(0, first))), what);
  }

  SourceRange At(const Token& token) const {
    return SourceRange(SourceLoc{file_, line_, token.column}, static_cast<std::uint32_t>(token.text.size()));
  }

  const RecordBegin& CurrentBegin() const { return log_.begins[current_begin_].begin; }
  std::string FixtureName(int fixture) const {
    return CurrentBegin().fixtures[static_cast<std::size_t>(fixture)].name;
  }

  // --- damage ------------------------------------------------------------------

  // Bytes [first, end) of the current line are not records: the record
  // being read is cut short, and the stretch grows.
  void Damage(std::size_t first, std::size_t end, std::string what) {
    if (!damage_) {
      damage_ = Damaged{};
      damage_->first = first;
      damage_->first_line = line_;
      damage_->what = std::move(what);
      if (pending_) {
        damage_->record = fmt::format("the record of cycle {} of fixture '{}' (line {}) it cut short",
                                      pending_->cycle.record.cycle, FixtureName(pending_->cycle.record.fixture),
                                      pending_->cycle.where.begin.line);
        Numbered(*pending_);  // said: its cycle is not missing
        pending_.reset();
      }
    }
    damage_->end = std::max(damage_->end, end);
    damage_->last_line = line_;
    damage_->nul += static_cast<std::size_t>(std::count(source_.text.begin() + static_cast<std::ptrdiff_t>(first),
                                                        source_.text.begin() + static_cast<std::ptrdiff_t>(end), '\0'));
  }

  // The line being read does not fit the record (structure, a field that is
  // not a number): the record and the line are damage.
  void Broken(std::string what) { Damage(line_start_, line_end_, fmt::format("line {}: {}", line_, what)); }

  void CloseDamage() {
    if (!damage_) return;
    const Damaged& d = *damage_;
    std::string bytes = d.end - d.first == 1 ? fmt::format("byte {}", d.first)
                                             : fmt::format("bytes {}-{}", d.first, d.end - 1);
    bytes += d.first_line == d.last_line ? fmt::format(" (line {})", d.first_line)
                                         : fmt::format(" (lines {}-{})", d.first_line, d.last_line);
    std::string what = d.what;
    if (d.nul > 0 && what.find("NUL") == std::string::npos) what += fmt::format("; {} in all", Plural(d.nul, "NUL byte"));
    if (!d.record.empty()) what += "; " + d.record;
    diags_.Report(DiagKind::RecordDamaged, SourceRange(source_.LocationOf(file_, d.first)), bytes, what);
    damage_.reset();
  }

  // --- fields ------------------------------------------------------------------

  // A number: nullopt (the line is damage, said) when the text is not one.
  std::optional<double> Number(const Token& token, std::string_view what) {
    const std::optional<double> value = ParseNumber(token.text);
    if (!value) Broken(fmt::format("{} is '{}', not a number", what, Printable(Shortened(token.text))));
    return value;
  }

  // A number or '-' (not measured): nullopt in `value` for '-'; false when
  // the line is damage.
  bool MaybeNumber(const Token& token, std::string_view what, std::optional<double>& value) {
    value.reset();
    if (token.text == "-") return true;
    value = Number(token, what);
    return value.has_value();
  }

  std::optional<long> Whole(const Token& token, std::string_view what, long lo, long hi) {
    const std::optional<double> value = Number(token, what);
    if (!value) return std::nullopt;
    if (!std::isfinite(*value) || *value != std::floor(*value) || *value < static_cast<double>(lo) ||
        *value > static_cast<double>(hi)) {
      Broken(fmt::format("{} is '{}', not a whole number from {} to {}", what, Printable(Shortened(token.text)), lo, hi));
      return std::nullopt;
    }
    return static_cast<long>(*value);
  }

  bool FieldCount(const std::vector<Token>& tokens, std::size_t want) {
    if (tokens.size() == want) return true;
    Broken(fmt::format("a '{}' line with {} (it has {})", tokens.front().text, Plural(tokens.size(), "field"), want));
    return false;
  }

  // The fixture number of a cycle, checks or trip line.
  std::optional<int> Fixture(const Token& token) {
    const long count = static_cast<long>(CurrentBegin().fixtures.size());
    if (count == 0) {
      Broken("a record, but the begin line names no fixture");
      return std::nullopt;
    }
    const std::optional<long> k = Whole(token, "the fixture", 0, count - 1);
    if (!k) return std::nullopt;
    return static_cast<int>(*k);
  }

  // A value read from a record: within its documented range, or an error
  // naming the record (the record is left out).
  void Absurd(const Token& token, std::string_view what, const std::string& why) {
    if (!pending_) return;
    pending_->absurd = true;
    diags_.Report(DiagKind::RecordAbsurdValue, At(token), what, pending_->cycle.record.cycle,
                  FixtureName(pending_->cycle.record.fixture), Printable(Shortened(token.text)), why);
  }
  void InRange(const Token& token, std::string_view what, double value, double lo, double hi, std::string_view unit) {
    if (!std::isfinite(value)) {
      Absurd(token, what, "not a finite number");
    } else if (value < lo || value > hi) {
      Absurd(token, what,
             fmt::format("outside {}..{}{}{}, the range docs/monitor.md gives (\"Values\"): no scan measures that", lo, hi,
                         unit.empty() ? "" : " ", unit));
    }
  }

  // --- lines ---------------------------------------------------------------------

  // smtcal-record VERSION cell=NAME fixtures=NAME:TRIPS,... clock=NAME segment=N
  bool Begin(const std::vector<Token>& tokens) {
    LoggedBegin logged;
    logged.where = At(tokens.front());
    for (const Token& t : tokens) logged.digest = Digest(t.text, Digest(" ", logged.digest));
    if (tokens.size() < 2) {
      diags_.Report(DiagKind::RecordBadBeginKey, At(tokens.front()),
                    "a begin line without its format version and the keys cell=, fixtures=, clock= and segment=");
      return false;
    }
    const std::optional<double> version_number = ParseNumber(tokens[1].text);
    if (!version_number || *version_number != std::floor(*version_number) || *version_number < 1 ||
        *version_number > 1e6) {
      diags_.Report(DiagKind::RecordBadField, At(tokens[1]), "the format version", Printable(Shortened(tokens[1].text)),
                    "not a whole number from 1 to 1000000");
      return false;
    }
    const auto version = static_cast<long>(*version_number);
    if (version != kRecordFormat) {
      // Format 1's LinuxCNC runtime wrote every value below 1e-4 mm or deg
      // as 0 (a kinder number than was measured), and its logs cannot say
      // which runtime wrote them.
      diags_.Report(DiagKind::RecordVersion, At(tokens[1]), version, kRecordFormat,
                    version == 1 ? "in format 1 the LinuxCNC runtime wrote every value below 1e-4 mm or deg as 0, "
                                   "so small residuals and deltas read as zero; recompile the program with this "
                                   "smtcal and record again"
                                 : "read it with the smtcal that matches the controller's runtime");
      return false;
    }
    RecordBegin& begin = logged.begin;
    begin.version = static_cast<int>(version);
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
                                  Printable(Shortened(text)),
                                  closest.empty() ? "" : fmt::format(" (did you mean '{}='?)", closest)));
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
    auto whole = [&](const Token& token, std::string_view what, long lo, long hi) -> std::optional<long> {
      const std::optional<double> v = ParseNumber(token.text);
      if (!v || *v != std::floor(*v) || *v < static_cast<double>(lo) || *v > static_cast<double>(hi)) {
        diags_.Report(DiagKind::RecordBadField, At(token), what, Printable(Shortened(token.text)),
                      fmt::format("not a whole number from {} to {}", lo, hi));
        return std::nullopt;
      }
      return static_cast<long>(*v);
    };
    const std::optional<std::string> cell = name("cell"), clock = name("clock");
    const std::optional<long> segment = whole(given.at("segment"), "the segment", 0, 1'000'000'000);
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
          diags_.Report(DiagKind::RecordBadField, At(part), "a fixture", Printable(Shortened(item)),
                        "write each as NAME:TRIPS, the fixture's name and its number of trips");
          fixtures_ok = false;
        } else {
          Token count{item.substr(colon + 1), part.column + static_cast<std::uint32_t>(colon + 1)};
          const std::optional<long> trips = whole(count, "a fixture's trip count", 1, kMaxRecordTrips);
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
    if (!fixture) return;
    const std::optional<long> cycle = Whole(tokens[2], "the cycle", 1, 2'000'000'000);
    if (!cycle) return;
    const std::optional<long> status = Whole(tokens[3], "the status", 0, static_cast<long>(kScanChecks.size()));
    if (!status) return;
    const std::size_t trips = CurrentBegin().fixtures[static_cast<std::size_t>(*fixture)].trips;
    const std::optional<long> trip = Whole(tokens[4], "the failed check's trip", 0, static_cast<long>(trips));
    if (!trip) return;
    std::optional<double> time;
    if (!MaybeNumber(tokens[5], "the time", time)) return;
    std::array<std::optional<double>, 6> s;
    int given = 0;
    for (std::size_t i = 0; i < 6; ++i) {
      if (!MaybeNumber(tokens[6 + i], "an estimated crossing's coordinate", s[i])) return;
      given += s[i] ? 1 : 0;
    }
    if (given != 0 && given != 6) {
      Broken("the crossings S1, S2, S3 are given in part (all six numbers, or '-' for each)");
      return;
    }
    // A cycle line that reads: what came before it ends here.
    CloseDamage();
    Close();
    Pending pending;
    pending.trips = trips;
    pending.start = line_start_;
    pending.digest = Digest(source_.Line(line_));
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
    if (time) InRange(tokens[5], "the time", *time, 0, kRecordMaxTimeS, "s");
    for (std::size_t i = 0; i < 6; ++i) {
      if (s[i]) InRange(tokens[6 + i], "an estimated crossing's coordinate", *s[i], -kMaxLengthMm, kMaxLengthMm, "mm");
    }
  }

  // Whether a checks or trip line belongs to the record being read; the
  // line is damage when not.
  bool Continues(const std::vector<Token>& tokens, std::string_view kind) {
    if (!pending_) {
      Broken(fmt::format("a {} line without the cycle line of its record before it", kind));
      return false;
    }
    if (tokens.size() < 3) {
      Broken(fmt::format("a '{}' line with {}", kind, Plural(tokens.size(), "field")));
      return false;
    }
    const std::optional<int> fixture = Fixture(tokens[1]);
    if (!fixture) return false;
    const std::optional<long> cycle = Whole(tokens[2], "the cycle", 1, 2'000'000'000);
    if (!cycle) return false;
    const CycleRecord& record = pending_->cycle.record;
    if (*fixture != record.fixture || *cycle != record.cycle) {
      Broken(fmt::format("a {} line of cycle {} of fixture {} where the record of cycle {} of fixture {} goes on",
                         kind, *cycle, *fixture, record.cycle, record.fixture));
      return false;
    }
    return true;
  }

  // checks F N V1 .. V11
  void Checks(const std::vector<Token>& tokens) {
    if (damage_ && !pending_) {  // a line of the record the damage cut short
      Damage(line_start_, line_end_, "");
      return;
    }
    if (!Continues(tokens, "checks")) return;
    if (pending_->have_checks) {
      Broken("a second checks line of the same cycle");
      return;
    }
    if (!FieldCount(tokens, kChecksFields)) return;
    std::array<std::optional<double>, kScanChecks.size()> values;
    for (std::size_t c = 0; c < kScanChecks.size(); ++c) {
      const std::string what = fmt::format("the value of check {} ({})", c + 1, ScanCheckName(kScanChecks[c]));
      if (!MaybeNumber(tokens[3 + c], what, values[c])) return;
    }
    Pending& pending = *pending_;
    pending.have_checks = true;
    pending.digest = Digest(source_.Line(line_), Digest("\n", pending.digest));
    pending.cycle.record.checks = values;
    for (std::size_t c = 0; c < kScanChecks.size(); ++c) {
      if (!values[c]) continue;
      const ValueRange range = CheckRange(kScanChecks[c], pending.trips);
      const std::string what = fmt::format("the value of check {} ({})", c + 1, ScanCheckName(kScanChecks[c]));
      InRange(tokens[3 + c], what, *values[c], range.lo, range.hi, range.unit);
    }
  }

  // trip F N K X Y
  void Trip(const std::vector<Token>& tokens) {
    if (damage_ && !pending_) {
      Damage(line_start_, line_end_, "");
      return;
    }
    if (!Continues(tokens, "trip")) return;
    if (!pending_->have_checks) {
      Broken("a trip line before the cycle's checks line");
      return;
    }
    if (!FieldCount(tokens, kTripFields)) return;
    const long want = static_cast<long>(pending_->next_trip) + 1;
    const std::optional<long> k = Whole(tokens[3], "the trip", 1, kMaxRecordTrips);
    if (!k) return;
    if (*k != want) {
      Broken(want > static_cast<long>(pending_->trips)
                 ? fmt::format("trip T{}, but the fixture makes {}", *k, Plural(pending_->trips, "trip"))
                 : fmt::format("trip T{} where T{} comes", *k, want));
      return;
    }
    std::optional<double> x, y;
    if (!MaybeNumber(tokens[4], "the trip's x", x) || !MaybeNumber(tokens[5], "the trip's y", y)) return;
    if (x.has_value() != y.has_value()) {
      Broken("a trip given in part (both coordinates, or '-' for both when the sensor did not trip)");
      return;
    }
    Pending& pending = *pending_;
    pending.digest = Digest(source_.Line(line_), Digest("\n", pending.digest));
    if (x) {
      pending.cycle.record.trips[pending.next_trip] = Eigen::Vector2d(*x, *y);
      InRange(tokens[4], "a trip's x", *x, -kMaxLengthMm, kMaxLengthMm, "mm");
      InRange(tokens[5], "a trip's y", *y, -kMaxLengthMm, kMaxLengthMm, "mm");
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
    const std::string missing = !pending.have_checks ? std::string("its checks line is missing")
                                                     : fmt::format("trip T{} and after are missing", pending.next_trip + 1);
    diags_.Report(DiagKind::RecordIncomplete, pending.cycle.where, pending.cycle.record.cycle,
                  FixtureName(pending.cycle.record.fixture), missing);
    pending_.reset();
  }

  // The record is complete: its parts agree, its cycle number and its time
  // follow the last of its fixture in its run.
  // A record left out with its own diagnostic (cut short by damage, a value
  // out of range): the cycle numbers and the clock go on from it, so the
  // next record is no gap.
  void Numbered(const Pending& pending) {
    const std::string name = FixtureName(pending.cycle.record.fixture);
    RecordLog::Last& last = log_.last[name];
    if (last.begin == current_begin_ && pending.cycle.record.cycle <= last.cycle) return;
    last.cycle = pending.cycle.record.cycle;
    last.time_s = pending.cycle.record.time_s;
    last.begin = current_begin_;
  }

  void Finish() {
    Pending pending = std::move(*pending_);
    pending_.reset();
    if (pending.absurd) {
      Numbered(pending);
      return;
    }
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
    const auto [it, fresh] = log_.last.try_emplace(name);
    RecordLog::Last& last = it->second;
    const bool same_run = !fresh && last.begin == current_begin_;
    if (same_run) {
      // Within a run the cycle numbers rise and the clock does not go back.
      if (record.cycle <= last.cycle) {
        diags_.Report(DiagKind::RecordInconsistent, pending.cycle.where,
                      fmt::format("cycle {} of fixture '{}' follows its cycle {} in the same run: the log goes back in "
                                  "time; give its files oldest first",
                                  record.cycle, name, last.cycle));
        return;
      }
      if (record.time_s && last.time_s && *record.time_s < *last.time_s) {
        diags_.Report(DiagKind::RecordInconsistent, pending.cycle.where,
                      fmt::format("the time of cycle {} of fixture '{}', {} s, is before its cycle {}'s, {} s, in the "
                                  "same run: the controller's clock does not go back while the program runs (a restart "
                                  "writes a begin line first)",
                                  record.cycle, name, NumberText(*record.time_s), last.cycle,
                                  NumberText(*last.time_s)));
        return;
      }
      if (record.cycle > last.cycle + 1) {
        diags_.Report(DiagKind::RecordCycleGap, pending.cycle.where, record.cycle, name, last.cycle,
                      record.cycle - last.cycle - 1);
      }
    } else if (!fresh) {
      // The first record of the fixture in a new run: its cycle numbers go on
      // (a new file of the same program run) or start again (a restart).
      const bool rotated = CurrentBegin().segment > log_.begins[last.begin].begin.segment;
      if (record.cycle == last.cycle + 1) {
        // goes on
      } else if (record.cycle == 1) {
        pending.cycle.restart = true;
      } else if (rotated && record.cycle > last.cycle + 1) {
        diags_.Report(DiagKind::RecordCycleGap, pending.cycle.where, record.cycle, name, last.cycle,
                      record.cycle - last.cycle - 1);
      } else {
        // A restart whose first records are missing.
        pending.cycle.restart = true;
        diags_.Report(DiagKind::RecordCycleGap, pending.cycle.where, record.cycle, name, 0L, record.cycle - 1);
      }
    } else {
      pending.cycle.restart = true;
    }
    last.cycle = record.cycle;
    last.time_s = record.time_s;
    last.begin = current_begin_;
    pending.cycle.digest = pending.digest;
    log_.cycles.push_back(std::move(pending.cycle));
  }

  std::uint32_t file_;
  RecordLog& log_;
  Diagnostics& diags_;
  const SourceFile& source_;
  std::uint32_t line_ = 0;
  std::size_t line_start_ = 0, line_end_ = 0;  // the current line's bytes, its end of line included
  std::size_t current_begin_ = 0;
  bool begun_ = false;
  std::optional<Pending> pending_;
  std::optional<Damaged> damage_;
};

}  // namespace

bool ReadRecordLog(std::uint32_t file, RecordLog& log, Diagnostics& diags) { return Reader(file, log, diags).Run(); }

void DropRepeatedRecords(RecordLog& log, Diagnostics& diags) {
  // The records of each run, in order.
  std::vector<std::vector<std::size_t>> runs(log.begins.size());
  for (std::size_t i = 0; i < log.cycles.size(); ++i) runs[log.cycles[i].begin].push_back(i);
  std::vector<bool> repeated(log.cycles.size(), false);
  struct FileRepeats {
    std::size_t count = 0, first = 0, of = 0;  // repeated records, the first one, the record it repeats
  };
  std::map<std::uint32_t, FileRepeats> by_file;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    if (runs[r].empty()) continue;
    for (std::size_t e = 0; e < r; ++e) {
      if (runs[e].empty() || log.begins[e].digest != log.begins[r].digest) continue;
      if (log.cycles[runs[e].front()].digest != log.cycles[runs[r].front()].digest) continue;
      std::size_t k = 0;
      while (k < runs[r].size() && k < runs[e].size() &&
             log.cycles[runs[r][k]].digest == log.cycles[runs[e][k]].digest) {
        repeated[runs[r][k]] = true;
        FileRepeats& f = by_file[log.cycles[runs[r][k]].where.begin.file];
        if (f.count++ == 0) {
          f.first = runs[r][k];
          f.of = runs[e][k];
        }
        ++k;
      }
      break;
    }
  }
  for (const auto& [file, f] : by_file) {
    const SourceLoc& of = log.cycles[f.of].where.begin;
    diags.Report(DiagKind::RecordRepeated, log.cycles[f.first].where, Plural(f.count, "record"),
                 fmt::format("{}:{}", Printable(diags.sources().File(of.file).name), of.line));
  }
  std::vector<LoggedCycle> kept;
  kept.reserve(log.cycles.size());
  for (std::size_t i = 0; i < log.cycles.size(); ++i) {
    if (!repeated[i]) kept.push_back(std::move(log.cycles[i]));
  }
  log.cycles = std::move(kept);
}

}  // namespace smtcal

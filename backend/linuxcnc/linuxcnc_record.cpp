// Writes smtcal_record.ngc and smtcal_record_open.ngc (see linuxcnc_record.h).
// The parameters read are the fixture record's (backend/linuxcnc/linuxcnc_data.h,
// runtime/linuxcnc/README.md); the lines are docs/monitor.md's, as the C
// runtime's smtcal_record_format writes them.
#include "backend/linuxcnc/linuxcnc_record.h"

#include <fmt/format.h>

#include "backend/linuxcnc/linuxcnc_data.h"
#include "calibration/cycle_record.h"
#include "calibration/fixture_geometry.h"

namespace smtcal {
namespace {

namespace L = linuxcnc_layout;

// rs274 reads a line of at most LINELEN - 2 = 253 characters.
constexpr std::size_t kMaxLineChars = 253;

// The begin line as a LOG comment: the format, the names, the segment.
std::string BeginComment(const cell::Cell& cell) {
  std::string fixtures;
  for (const cell::Fixture& fixture : cell.fixtures) {
    fixtures += fmt::format("{}{}:{}", fixtures.empty() ? "" : ",", RecordName(fixture.name),
                            ExpectedTrips(fixture).size());
  }
  const cell::LinuxCnc& linuxcnc = *cell.linuxcnc;
  return fmt::format("(LOG,smtcal-record {} cell={} fixtures={} clock={} segment=%d#{})", kRecordFormat,
                     RecordName(cell.name), fixtures.empty() ? "-" : fixtures,
                     linuxcnc.record_clock_pin.empty() ? "none" : linuxcnc.record_clock_pin, L::kRecordSegment);
}

bool Records(const cell::Cell& cell) { return cell.linuxcnc && !cell.linuxcnc->record_file.empty(); }

std::string Header(std::string_view file, const cell::Cell& cell, std::string_view what) {
  return fmt::format(
      "; {} - written by smtcal for the cell {} (runtime/linuxcnc/README.md, docs/monitor.md).\n{}", file,
      RecordName(cell.name), what);
}

// A parameter of the buffer the LOG comments print.
int Buffer(int offset) { return L::kRecordBuffer + offset; }

// LinuxCNC 2.9 prints every number below 1e-4 in magnitude as 0, whatever
// the format (found with rs274: 0.00009 prints 0.000000, 0.0001 0.000100),
// and at most 9 decimals. So the record's lengths (mm) and angles (deg) are
// printed in millionths with 9 decimals, and the text e-6 after each makes
// it the value in mm or deg again: 0.000023 deg is written
// 23.000000000e-6. A value below 1e-10 reads as 0, every other one to
// 1e-15 (docs/monitor.md). A LOG comment's format holds for the numbers
// after it, so each line names it once, before its first scaled number.
constexpr int kLogScale = 1000000;
constexpr std::string_view kLogFormat = "%.9f";
std::string Scaled(int parameter) { return fmt::format("#{}e-6", parameter); }

}  // namespace

std::string LinuxCncRecordSecondFile(std::string_view record_file) { return std::string(record_file) + ".1"; }

std::optional<std::string> LinuxCncRecordProblem(const cell::Cell& cell) {
  if (!Records(cell)) return std::nullopt;
  const std::string begin = BeginComment(cell);
  if (begin.size() > kMaxLineChars) {
    return fmt::format(
        "the cycle record's begin line, {}, is {} characters long, and LinuxCNC reads lines of at most {}: shorten "
        "the names of the cell or of its fixtures",
        begin, begin.size(), kMaxLineChars);
  }
  const std::string open = fmt::format("  (LOGOPEN,{})", LinuxCncRecordSecondFile(cell.linuxcnc->record_file));
  if (open.size() > kMaxLineChars) {
    return fmt::format("the cycle record's file name is too long for a line of LinuxCNC ({} characters at most)",
                       kMaxLineChars);
  }
  return std::nullopt;
}

std::string EmitLinuxCncRecordOpen(const cell::Cell& cell) {
  std::string out = Header(
      "smtcal_record_open.ngc", cell,
      "; o<smtcal_record_open> call: at the start of the program (smtcal_data calls it) opens the log of\n"
      "; cycle records and writes its begin line.\n");
  out += "o<smtcal_record_open> sub\n";
  if (!Records(cell)) {
    out += "; The cell names no [linuxcnc] record_file: no record is kept.\n";
    out += "o<smtcal_record_open> endsub\n";
    return out;
  }
  const cell::LinuxCnc& linuxcnc = *cell.linuxcnc;
  out += fmt::format(
      "; The log is {0} and {1}: the runtime writes one until it holds {2} scans, then empties the\n"
      "; other and goes on there. #{3} counts the changes (the log's segment), #{4} says which file,\n"
      "; #{5} how many scans it holds; the machine's parameter file keeps them (#{6} = 1 says it does).\n",
      linuxcnc.record_file, LinuxCncRecordSecondFile(linuxcnc.record_file), linuxcnc.record_max_cycles,
      L::kRecordSegment, L::kRecordFile, L::kRecordCount, L::kRecordKept);
  out += "; On the machine (#<_task> = 1) only: rs274 alone has no parameter file to keep them.\n";
  out += fmt::format("o<smtcal_ro_kept> if [#<_task> EQ 1 AND #{} NE 1]\n", L::kRecordKept);
  out += fmt::format(
      "  (abort,smtcal: the cycle record needs the lines {0} 0, {1} 0, {2} 0 and {3} 1 in the machine's parameter "
      "file, PARAMETER_FILE of the INI: see runtime/linuxcnc/README.md)\n",
      L::kRecordSegment, L::kRecordFile, L::kRecordCount, L::kRecordKept);
  out += "o<smtcal_ro_kept> endif\n";
  if (!linuxcnc.record_clock_pin.empty()) {
    out += fmt::format("o<smtcal_ro_clock> if [EXISTS[#<_hal[{}]>] EQ 0]\n", linuxcnc.record_clock_pin);
    out += fmt::format(
        "  (abort,smtcal: the cycle record cannot read its clock, the HAL pin {}: set HAL_PIN_VARS = 1 in the "
        "RS274NGC section of the INI and load the pin)\n",
        linuxcnc.record_clock_pin);
    out += "o<smtcal_ro_clock> endif\n";
  }
  out += fmt::format("o<smtcal_ro_file> if [#{} EQ 0]\n", L::kRecordFile);
  out += fmt::format("  (LOGAPPEND,{})\n", linuxcnc.record_file);
  out += "o<smtcal_ro_file> else\n";
  out += fmt::format("  (LOGAPPEND,{})\n", LinuxCncRecordSecondFile(linuxcnc.record_file));
  out += "o<smtcal_ro_file> endif\n";
  out += BeginComment(cell) + "\n";
  out += "o<smtcal_record_open> endsub\n";
  return out;
}

std::string EmitLinuxCncRecord(const cell::Cell& cell) {
  std::string out = Header(
      "smtcal_record.ngc", cell,
      "; o<smtcal_record> call [k]: appends the record of fixture k's last scan to the log (a cycle\n"
      "; line, a checks line, a trip line per trip); smtcal_estimate calls it after an accepted scan,\n"
      "; smtcal_scan_failed before a refusal aborts. What a scan did not measure is written -.\n");
  out += "o<smtcal_record> sub\n";
  if (!Records(cell)) {
    out += "; The cell names no [linuxcnc] record_file: no record is kept.\n";
    out += "o<smtcal_record> endsub\n";
    return out;
  }
  const cell::LinuxCnc& linuxcnc = *cell.linuxcnc;
  out += "#<k> = #1\n";
  out += "#<f> = #[#35 + #<k>]\n";
  out += fmt::format("#[#<f> + {0}] = [#[#<f> + {0}] + 1]  ; the scan's number since the start\n", L::kFxRecordCycles);
  out += fmt::format("; the file is full: go on in the other one, emptied\n");
  out += fmt::format("o<smtcal_rec_full> if [#{} GE {}]\n", L::kRecordCount, linuxcnc.record_max_cycles);
  out += fmt::format("  #{0} = [1 - #{0}]\n", L::kRecordFile);
  out += fmt::format("  #{0} = [#{0} + 1]\n", L::kRecordSegment);
  out += fmt::format("  #{} = 0\n", L::kRecordCount);
  out += fmt::format("  o<smtcal_rec_next> if [#{} EQ 0]\n", L::kRecordFile);
  out += fmt::format("    (LOGOPEN,{})\n", linuxcnc.record_file);
  out += "  o<smtcal_rec_next> else\n";
  out += fmt::format("    (LOGOPEN,{})\n", LinuxCncRecordSecondFile(linuxcnc.record_file));
  out += "  o<smtcal_rec_next> endif\n";
  out += "  " + BeginComment(cell) + "\n";
  out += "o<smtcal_rec_full> endif\n";
  out += fmt::format("#{0} = [#{0} + 1]\n", L::kRecordCount);
  // The buffer: fixture, cycle, status, trip, time, S1..S3, the checks; the
  // lengths and angles in millionths (kLogScale).
  out += fmt::format("#{} = #<k>\n", Buffer(0));
  out += fmt::format("#{} = #[#<f> + {}]\n", Buffer(1), L::kFxRecordCycles);
  out += fmt::format("#{} = #[#<f> + {}]\n", Buffer(2), L::kFxStatus);
  out += fmt::format("#{} = [#[#<f> + {}] + 1]\n", Buffer(3), L::kFxFailedTrip);
  for (int i = 0; i < 6; ++i) out += fmt::format("#{} = [#[#<f> + {}] * {}]\n", Buffer(5 + i), L::kFxS + i, kLogScale);
  out += fmt::format("#{} = #[#<f> + {}]  ; missing_trip counts trips\n", Buffer(11), L::kFxCheckValue + 1);
  for (int c = 2; c <= 11; ++c) {
    out += fmt::format("#{} = [#[#<f> + {}] * {}]\n", Buffer(10 + c), L::kFxCheckValue + c, kLogScale);
  }
  const std::string head = fmt::format("%d#{} #{}", Buffer(0), Buffer(1));
  const std::string time = linuxcnc.record_clock_pin.empty()
                               ? std::string(" -")
                               : fmt::format(" %.6f#<_hal[{}]>", linuxcnc.record_clock_pin);
  // The pose when the estimator gave one (check 3 ran and passed).
  out += fmt::format("o<smtcal_rec_pose> if [#[#<f> + {}] EQ 1 AND #[#<f> + {}] EQ 0]\n", L::kFxCheckEvaluated + 3,
                     L::kFxCheckValue + 3);
  std::string s;
  for (int i = 0; i < 6; ++i) s += fmt::format(" {}{}", i == 0 ? kLogFormat : "", Scaled(Buffer(5 + i)));
  out += fmt::format("  (LOG,cycle {} #{} #{}{}{})\n", head, Buffer(2), Buffer(3), time, s);
  out += "o<smtcal_rec_pose> else\n";
  out += fmt::format("  (LOG,cycle {} #{} #{}{} - - - - - -)\n", head, Buffer(2), Buffer(3), time);
  out += "o<smtcal_rec_pose> endif\n";
  // The checks that ran: 1; 1, 2; 1..3; 1..9; 1..11 (docs/periphery.md).
  // Check 1 is a count of trips (%d, as the head); the others are scaled.
  auto checks = [&](int ran) {
    std::string line = fmt::format("(LOG,checks {} #{}", head, Buffer(11));
    for (int c = 2; c <= 11; ++c) {
      line += c <= ran ? fmt::format(" {}{}", c == 2 ? kLogFormat : "", Scaled(Buffer(10 + c))) : " -";
    }
    return line + ")";
  };
  out += fmt::format("o<smtcal_rec_checks> if [#[#<f> + {}] EQ 1]\n", L::kFxCheckEvaluated + 11);
  out += "  " + checks(11) + "\n";
  out += fmt::format("o<smtcal_rec_checks> elseif [#[#<f> + {}] EQ 1]\n", L::kFxCheckEvaluated + 9);
  out += "  " + checks(9) + "\n";
  out += fmt::format("o<smtcal_rec_checks> elseif [#[#<f> + {}] EQ 1]\n", L::kFxCheckEvaluated + 3);
  out += "  " + checks(3) + "\n";
  out += fmt::format("o<smtcal_rec_checks> elseif [#[#<f> + {}] EQ 1]\n", L::kFxCheckEvaluated + 2);
  out += "  " + checks(2) + "\n";
  out += "o<smtcal_rec_checks> else\n";
  out += "  " + checks(1) + "\n";
  out += "o<smtcal_rec_checks> endif\n";
  // One line per trip; a trip the sensor did not make is - -.
  out += fmt::format("#<count> = #[#<f> + {}]\n", L::kFxTripCount);
  out += fmt::format("#<trips> = #[#<f> + {}]\n", L::kFxTripsAt);
  out += fmt::format("#<tripped> = #[#<f> + {}]\n", L::kFxTrippedAt);
  out += "#<i> = 0\n";
  out += "o<smtcal_rec_trips> while [#<i> LT #<count>]\n";
  out += fmt::format("  #{} = [#<i> + 1]\n", Buffer(24));
  out += "  o<smtcal_rec_made> if [#[#<tripped> + #<i>] EQ 1]\n";
  out += fmt::format("    #{} = [#[#<trips> + 2 * #<i>] * {}]\n", Buffer(22), kLogScale);
  out += fmt::format("    #{} = [#[#<trips> + 2 * #<i> + 1] * {}]\n", Buffer(23), kLogScale);
  out += fmt::format("    (LOG,trip {} #{} {}{} {})\n", head, Buffer(24), kLogFormat, Scaled(Buffer(22)),
                     Scaled(Buffer(23)));
  out += "  o<smtcal_rec_made> else\n";
  out += fmt::format("    (LOG,trip {} #{} - -)\n", head, Buffer(24));
  out += "  o<smtcal_rec_made> endif\n";
  out += "  #<i> = [#<i> + 1]\n";
  out += "o<smtcal_rec_trips> endwhile\n";
  out += "o<smtcal_record> endsub\n";
  return out;
}

}  // namespace smtcal

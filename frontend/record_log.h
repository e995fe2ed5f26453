// Logs of cycle records (docs/monitor.md): what the LinuxCNC runtime appends
// every cycle, what the C runtime's smtcal_record_format writes, what
// `smtcal simulate --record` writes. Read back exactly (every number as the
// double nearest its text) and strictly: every mistake is a diagnostic at
// its line and field.
//
//   smtcal-record 2 cell=paper-cell fixtures=Board:8 clock=none segment=0
//   cycle 0 1 0 0 - 138.3 39.8 328.3 39.98 138.29 129.8
//   checks 0 1 0 0.523 0 0 0 0 52.9e-6 0.36 0.1 - -
//   trip 0 1 1 138317400.000000000e-6 42.8
//   ...
//
// A log may hold several begin lines (each program start writes one, and
// every new file starts with one). A cycle's record is its cycle line, its
// checks line and one trip line per trip; a record the controller was
// stopped in the middle of writing (its lines stop before the next record
// or the end of the file), and a last line without an end of line, are
// left out with a warning, never read as data.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "calibration/cycle_record.h"

namespace smtcal {

struct LoggedBegin {
  RecordBegin begin;
  SourceRange where;  // the begin line
};

struct LoggedCycle {
  CycleRecord record;
  std::size_t begin = 0;  // index into RecordLog::begins: the begin line it follows
  SourceRange where;      // its cycle line
};

struct RecordLog {
  std::vector<LoggedBegin> begins;
  std::vector<LoggedCycle> cycles;  // complete records, in the order of the files and their lines
  // The reader's: the last cycle number read of each fixture (by name), so
  // the next file's records are checked against the previous file's.
  std::map<std::string, long> last_cycle;
};

// Reads one file of records and appends what it holds to `log` (a log kept
// in several files: call it for each, oldest first). Returns false when the
// file had an error (reported); warnings do not count.
bool ReadRecordLog(std::uint32_t file, RecordLog& log, Diagnostics& diags);

}  // namespace smtcal

// Logs of cycle records (docs/monitor.md): what the LinuxCNC runtime appends
// every cycle, what the C runtime's smtcal_record_format writes, what
// `smtcal simulate --record` writes. Read back exactly (every number as the
// double nearest its text).
//
//   smtcal-record 2 cell=paper-cell fixtures=Board:8 clock=none segment=0
//   cycle 0 1 0 0 - 138.3 39.8 328.3 39.98 138.29 129.8
//   checks 0 1 0 0.523 0 0 0 0 52.9e-6 0.36 0.1 - -
//   trip 0 1 1 138317400.000000000e-6 42.8
//   ...
//
// A log is the life of a controller: a begin line starts a run (every
// program start writes one, and so does every new file of the log), and
// the records of the run follow it. What a controller that lost its power
// or was stopped leaves behind is read around, never read as data:
// - a record whose lines stop before the next record or the end of the file
//   is left out with a warning (RecordIncomplete);
// - bytes that are not records (a line cut where the next begin line
//   starts, a tail of NUL bytes, lines no writer writes, a record whose
//   lines do not fit together) are one warning naming their byte range and
//   lines (RecordDamaged), and the records around them are read;
// - a record read twice (the same log given twice, rotated files that
//   overlap) is counted once (DropRepeatedRecords, RecordRepeated).
// What no power cut makes is an error at its line: a begin line this reader
// cannot read, a complete record that contradicts itself or whose cycle
// numbers or clock go back within its run, and a value outside the ranges
// docs/monitor.md gives (RecordAbsurdValue, naming the record).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "calibration/cycle_record.h"

namespace smtcal {

// The documented ranges of a record's values (docs/monitor.md, "Values").
inline constexpr double kRecordMaxLengthMm = 1e4;    // positions and lengths: no placement robot reaches 10 m
inline constexpr double kRecordMaxAngleDeg = 180;    // the rotation checks' values (wrapped)
// The squareness check's: |angle(S2 - S1, S3 - S1) - 90 deg| with the angle
// from atan2 in (-180, 180], so up to 270 for a scan that finds S3 on the
// wrong side.
inline constexpr double kRecordMaxSquarenessDeg = 270;
inline constexpr double kRecordMaxTimeS = 1e10;      // the controller's clock (about 317 years)

struct LoggedBegin {
  RecordBegin begin;
  SourceRange where;          // the begin line
  std::uint64_t digest = 0;   // of its text: a run read twice has the same
};

struct LoggedCycle {
  CycleRecord record;
  std::size_t begin = 0;      // index into RecordLog::begins: the run it belongs to
  SourceRange where;          // its cycle line
  std::uint64_t digest = 0;   // of its lines' text
  // The first record of its fixture after a program start (its cycle
  // numbers start again): the runtime had no previous pose.
  bool restart = false;
};

struct RecordLog {
  std::vector<LoggedBegin> begins;
  std::vector<LoggedCycle> cycles;  // complete records, in the order of the files and their lines
  // The reader's, across files: per fixture name, the last record's cycle,
  // time and run.
  struct Last {
    long cycle = 0;
    std::optional<double> time_s;
    std::size_t begin = 0;
  };
  std::map<std::string, Last> last;
};

// Reads one file of records and appends what it holds to `log` (a log kept
// in several files: call it for each, oldest first; a file that starts
// without a begin line continues the previous file's last run, as a file
// rotated by copying and truncating does). Returns false when the file had
// an error (reported); warnings do not count.
bool ReadRecordLog(std::uint32_t file, RecordLog& log, Diagnostics& diags);

// Once every file was read: a run whose begin line and records repeat an
// earlier run's, record by record, is counted once (a warning per file at
// its first repeated record); what it holds beyond the earlier run stays.
void DropRepeatedRecords(RecordLog& log, Diagnostics& diags);

}  // namespace smtcal

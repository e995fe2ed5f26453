// The inputs of `smtcal measure program|read` (docs/measure.md): a plan file
// checked against its cell, and the measuring program's logs.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "calibration/cell.h"
#include "calibration/measurement_plan.h"
#include "calibration/measurement_reading.h"
#include "frontend/table_csv.h"

namespace smtcal::measure {

// A plan file read back: the visits as written, the regions' grids from its
// node rows, its digest. Reports (in the plan file): visits not numbered
// 1, 2, 3, ..., a node number at two points, a plan of another device than
// the cell's ([measure] device), and everything ReadMeasurementPlan does.
struct LoadedPlan {
  Plan plan;
  std::string digest;  // PlanDigest of the file's text
  std::string name;    // the file's name as given
  std::uint32_t file = 0;  // its SourceManager id
  std::vector<std::uint32_t> lines;  // per visit: its line in the file
};
std::optional<LoadedPlan> LoadPlan(std::uint32_t file, const cell::Cell& cell, Diagnostics& diags);

// The log a measuring program writes (LOGOPEN/LOGAPPEND): blocks, each
//   # smtcal measuring log: plan NAME digest HEX; program STEM; region R; axes A; station S; device D; visits F..L
//   visit,node,set,repetition,x_mm,y_mm,a_mm,b_mm
//   1,1,1,1,150.000000,60.000000,0.512000,0.500000
//   ...
//   # end                       (or "# aborted at visit ..." before an abort)
//
// Every line is checked against the plan before anything is computed from
// it: visit, node, set and repetition are whole numbers within the plan's
// (never wrapped), the node, set and commanded position are those the plan
// gives the visit, the visit lies within its block's range, and a visit and
// repetition appear once per block. A last line without its line end (or
// glued to a resumed run's header) is cut: its reading is never used.
struct CutLine {
  int visit = 0;       // the visit it would have been (0: unknown)
  SourceRange where;   // the line
};
struct LogBlock {
  std::string header;  // the first line, without "# "
  std::string digest;
  int first_visit = 0, last_visit = 0;
  SourceRange header_range;
  bool ended = false;  // "# end": the program ran to its end
  std::string stopped;  // the "# aborted ..." line, when it stopped
  int last_visit_logged = 0;      // the last reading's visit (0: none)
  int last_repetition_logged = 0;
  std::optional<CutLine> cut;     // its last line, cut short
};
struct MeasuringLog {
  std::string name;
  std::vector<LogBlock> blocks;
  std::vector<Reading> readings;  // visit, node, set, repetition, at, a, b and where; the rest from the plan
  std::vector<int> block_of;      // per reading: its block
};
// Reports a file that is no such log (MeasureLogNotARun), a block of
// another plan (MeasureLogOtherPlan) or with a visit range that is not the
// plan's (MeasureLogBadHeader), bad lines (CsvBadNumber, CsvFieldCount,
// MeasureLogBadInteger), a reading the plan does not have
// (MeasureLogUnknownVisit, MeasureLogNotPlanned, MeasureLogOutsideRun) and
// one logged twice in a block (MeasureLogDuplicate). Cut lines are left to
// the caller (LogBlock::cut): a later block may measure the visit again.
std::optional<MeasuringLog> ReadMeasuringLog(std::uint32_t file, const LoadedPlan& plan, Diagnostics& diags);

// The settings a reading's meaning depends on (the final approach; the
// probe's hole and stylus diameters; the transducer's slope and zero), as
// the measuring program wrote them into each block's header, against the
// cell's: a difference is an error at the header (MeasureLogSettings).
void CheckLogSettings(const MeasuringLog& log, const cell::Cell& cell, Diagnostics& diags);

// The same settings as "key value; key value" for the raw file's
// "measured with:" comment, which `table build --cell` checks
// (CheckRawSettings).
std::string MeasuredWith(const cell::Cell& cell);
inline constexpr std::string_view kMeasuredWithMark = "# measured with: ";
// Reports (TableRawSettings, at the comment) each setting of the raw
// file's "measured with:" comment that differs from `cell`'s, and a raw
// file without that comment.
void CheckRawSettings(std::uint32_t raw_file, const cell::Cell& cell, Diagnostics& diags);

}  // namespace smtcal::measure

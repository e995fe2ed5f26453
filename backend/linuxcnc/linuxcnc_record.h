// The LinuxCNC runtime's cycle record (docs/monitor.md): smtcal_record.ngc
// appends the record of every marker scan — accepted or refused, before a
// refusal aborts — to the log file the cell names ([linuxcnc] record_file),
// and smtcal_record_open.ngc opens that log at the program's start with its
// begin line. The log's name, the clock's HAL pin and the names in the begin
// line are fixed text of the files, so smtcal writes them for the cell, as
// smtcal_scan_abort.ngc.
//
// How it is written (LinuxCNC 2.9): (LOGAPPEND,file) and (LOGOPEN,file)
// open the log in the task, and every (LOG,...) comment is one fprintf of a
// whole line and an fflush: a line is complete in the file or absent, even
// when the program is aborted. A LOG comment expands its parameters into a
// 512-byte buffer that LinuxCNC does not bound, so a line prints at most 13
// numbers (each at most 29 characters and its e-6): hence a record of
// several lines. LinuxCNC prints a number below 1e-4 as 0, so lengths and
// angles are printed in millionths with the text e-6 after them (format 2,
// docs/monitor.md): every value to 1e-10 mm or deg.
// The log is kept in two files, record_file and record_file.1: when one holds
// record_max_cycles scans the runtime empties the other and goes on there
// (the counters in #4996..#4999, which the machine's parameter file must
// keep across restarts; runtime/linuxcnc/README.md).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "calibration/cell.h"

namespace smtcal {

// The text of smtcal_record.ngc and of smtcal_record_open.ngc for the cell
// (deterministic). They hold nothing of a program: they are part of the
// runtime that every program of the cell shares (LinuxCncRuntimeId hashes
// them). Without [linuxcnc] record_file both are subroutines that do
// nothing.
std::string EmitLinuxCncRecord(const cell::Cell& cell);
std::string EmitLinuxCncRecordOpen(const cell::Cell& cell);

// Why the cell's record cannot be written by LinuxCNC (its begin line would
// be longer than a G-code line may be), or nullopt.
std::optional<std::string> LinuxCncRecordProblem(const cell::Cell& cell);

// The second file of the log.
std::string LinuxCncRecordSecondFile(std::string_view record_file);

}  // namespace smtcal

// Cycle records as text for smtcal's own writers (`smtcal simulate
// --record`): the C runtime's formatter (runtime/c/smtcal_record.h) on C++
// records, so there is one writer of the format besides the LinuxCNC
// runtime's (docs/monitor.md).
#pragma once

#include <string>

#include "calibration/cycle_record.h"

namespace smtcal {

// The begin line (with its newline).
std::string RecordBeginText(const RecordBegin& begin);

// A cycle's record: its cycle, checks and trip lines. decimals as
// smtcal_record_format: 0..17 fixed, -1 the digits that read back exactly.
std::string CycleRecordText(const CycleRecord& record, int decimals);

}  // namespace smtcal

// What kind of smtcal input a file is, guessed from its name and first
// lines, for the one message a reader gives when a command is handed the
// wrong kind of file (`smtcal check paper.cell.toml`: "a cell file, not a
// .place program; check it with smtcal cell check ...") instead of a page of
// syntax errors.
//
// The guess is deliberately shy: it names a kind only when the content says
// so plainly (a TOML table header, a CSV header of one of smtcal's own
// schemas, a CAD tool's header line), so a real input with mistakes is
// always read and its mistakes reported as they are.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

#include "base/diagnostics.h"

namespace smtcal {

enum class InputKind {
  kUnknown,
  kProgram,          // a .place program
  kCell,             // TOML with [robot], [[region]] or [[fixture]]
  kFeeders,          // TOML with [[feeder]] and nothing of a cell
  kTruth,            // TOML of simulate --truth
  kToml,             // other TOML
  kErrorTable,       // CSV: axis, x_mm, y_mm, error_mm
  kRawMeasurements,  // CSV: axis, x_mm, y_mm, set, repetition, error_mm
  kTrips,            // CSV: trip, x_mm, y_mm
  kCadList,          // a CAD tool's placement list
  kJson,
  kSvg,
  kNgc,              // RS274NGC
  kRecordLog,        // cycle records: a line 'smtcal-record N ...'
};

InputKind GuessInputKind(std::string_view name, std::string_view text);

// "a cell file (TOML)".
std::string_view InputKindName(InputKind kind);

// What to do with a file of that kind: "check it with `smtcal cell check
// FILE`" (FILE replaced by `name`); empty when smtcal has no command for it.
std::string InputKindAdvice(InputKind kind, std::string_view name);

// For a reader: when the file plainly is another kind than `accepted` (and
// not kUnknown), reports InputIsOtherKind at its first line ("'x.toml' looks
// like a cell file (TOML), not a .place program; check it with ...") and
// returns true: the reader then reads nothing.
bool ReportOtherInputKind(std::uint32_t file, std::initializer_list<InputKind> accepted, std::string_view wanted,
                          Diagnostics& diags);

}  // namespace smtcal

// Writes smtcal_scan_abort.ngc (see linuxcnc_scan_abort.h). The check codes
// and their order are the C runtime's (runtime/c/smtcal_runtime.h) and
// smtcal_check's; the texts say what docs/periphery.md says of each check.
#include "backend/linuxcnc/linuxcnc_scan_abort.h"

#include <array>
#include <string_view>

#include <fmt/format.h>

#include "calibration/cycle_record.h"

namespace smtcal {
namespace {

// Per check code 1..11: the message after "failed check ", with the value
// (#3), the limit (#4) and the trip (#5, 1-based) substituted by rs274.
constexpr std::array<std::string_view, 11> kMessages = {
    "missing_trip: %d#3 trips missing, the first T%d#5, limit 0",
    "trip_window: trip T%d#5 is %.4f#3 mm from its nominal point, limit trip_window_mm %.4f#4",
    "degenerate: the trips define no pose, value 1, limit 0",
    "length_l1: S2 - S1 is %.4f#3 mm off L1, limit length_tolerance_mm %.4f#4",
    "length_l2: S3 - S1 is %.4f#3 mm off L2, limit length_tolerance_mm %.4f#4",
    "squareness: %.4f#3 deg from square, limit squareness_deg %.4f#4",
    "line_residual: trip T%d#5 is %.4f#3 mm from its edge line, limit max_line_residual_mm %.4f#4",
    "nominal_shift: the origin is %.4f#3 mm from nominal, limit max_shift_mm %.4f#4",
    "nominal_rotation: turned %.4f#3 deg from nominal, limit max_rotation_deg %.4f#4",
    "cycle_shift: the origin moved %.4f#3 mm since the last scan, limit max_shift_mm %.4f#4",
    "cycle_rotation: turned %.4f#3 deg since the last scan, limit max_rotation_deg %.4f#4",
};

}  // namespace

std::string LinuxCncMessageName(std::string_view name) { return name.empty() ? std::string() : RecordName(name); }

std::string EmitLinuxCncScanAbort(const cell::Cell& cell) {
  std::string out = fmt::format(
      "; smtcal_scan_abort.ngc - written by smtcal for the cell {} (runtime/linuxcnc/README.md).\n"
      "; o<smtcal_scan_abort> call [k] [code] [value] [limit] [trip]: aborts the program\n"
      "; with the message of check `code` (1..11) for fixture k, naming the fixture.\n"
      "; Called by smtcal_scan_failed; a message is fixed text, so the names are here.\n"
      "o<smtcal_scan_abort> sub\n",
      LinuxCncMessageName(cell.name));
  for (std::size_t k = 0; k < cell.fixtures.size(); ++k) {
    const std::string name = LinuxCncMessageName(cell.fixtures[k].name);
    out += fmt::format("o<smtcal_sa_fixture_{0}> if [#1 EQ {0}]\n", k);
    for (std::size_t code = 1; code <= kMessages.size(); ++code) {
      out += fmt::format("  o<smtcal_sa_code_{}> {} [#2 EQ {}]\n", k, code == 1 ? "if" : "elseif", code);
      out += fmt::format("    (abort,smtcal: marker scan of fixture {} failed check {})\n", name,
                         kMessages[code - 1]);
    }
    out += fmt::format("  o<smtcal_sa_code_{}> endif\n", k);
    out += fmt::format("o<smtcal_sa_fixture_{}> endif\n", k);
  }
  out += "(abort,smtcal: marker scan of fixture index %d#1 failed check code %d#2)\n";
  out += "o<smtcal_scan_abort> endsub\n";
  return out;
}

}  // namespace smtcal

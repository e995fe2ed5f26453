// Writes the dry-run smtcal_probe_trips.ngc (see linuxcnc_dry_run.h): per
// fixture k, the trips the controller latches at its nominal pose (the commands that reach the nominal trips through the cell's tables) into the trip parameters the runtime's
// estimate reads (runtime/linuxcnc/README.md, "Parameter layout": the
// fixture record at #[#35 + k], the trips' address at +30, the tripped
// flags' address at +31), all marked tripped; no motion.
#include "backend/linuxcnc/linuxcnc_dry_run.h"

#include <fmt/format.h>

#include "backend/linuxcnc/linuxcnc_data.h"
#include "backend/linuxcnc/linuxcnc_scan_abort.h"
#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"

namespace smtcal {

std::string EmitLinuxCncDryRunProbe(const cell::Cell& cell) {
  namespace L = linuxcnc_layout;
  std::string out = fmt::format(
      "; smtcal_probe_trips.ngc - DRY RUN ONLY, written by smtcal for the cell {} (--dry-run-probe).\n"
      "; NOT THE MARKER SCAN: it moves nothing and gives every fixture the trips of its\n"
      "; nominal pose, so LinuxCNC's standalone interpreter rs274 (which has no probe)\n"
      "; runs the whole program. Put its folder first on the subroutine path of rs274 only,\n"
      "; never of a machine: run by LinuxCNC's task (#<_task> = 1) it aborts.\n"
      "o<smtcal_probe_trips> sub\n"
      "o<smtcal_dry_task> if [#<_task> EQ 1]\n"
      "  (abort,smtcal: the dry-run probe file is on this machine's subroutine path: remove its dry-run folder "
      "from [RS274NGC]SUBROUTINE_PATH)\n"
      "o<smtcal_dry_task> endif\n",
      LinuxCncMessageName(cell.name));
  for (std::size_t k = 0; k < cell.fixtures.size(); ++k) {
    const cell::Fixture& fixture = cell.fixtures[k];
    // What the controller would latch on a board at its nominal pose: the
    // commands that reach the nominal trips through the cell's tables, so the
    // runtime's estimate gives the nominal FIX.
    const std::vector<Eigen::Vector2d> trips = CommandedTrips(fixture, cell.regions, NominalFix(fixture));
    out += fmt::format("o<smtcal_dry_{0}> if [#1 EQ {0}]\n", k);
    out += fmt::format("  (DEBUG,smtcal dry run: fixture {} gets the trips of its nominal pose; no scan)\n",
                       LinuxCncMessageName(fixture.name));
    out += fmt::format("  #<f> = #[#{} + {}]\n", L::kFixtureDirectory, k);
    for (std::size_t i = 0; i < trips.size(); ++i) {
      out += fmt::format("  #[#[#<f> + {}] + {}] = {}  ; {} x\n", L::kFxTripsAt, 2 * i, LinuxCncNumber(trips[i].x()),
                         TripName(i));
      out += fmt::format("  #[#[#<f> + {}] + {}] = {}  ; {} y\n", L::kFxTripsAt, 2 * i + 1,
                         LinuxCncNumber(trips[i].y()), TripName(i));
      out += fmt::format("  #[#[#<f> + {}] + {}] = 1\n", L::kFxTrippedAt, i);
    }
    out += fmt::format("o<smtcal_dry_{}> endif\n", k);
  }
  return out + "o<smtcal_probe_trips> endsub\n";
}

std::string EmitLinuxCncDryRunIni(const std::string& dry_run_folder, const std::string& runtime_folder) {
  return fmt::format(
      "# rs274.ini - LinuxCNC's standalone interpreter rs274 on this dry run, written by smtcal {}\n"
      "# (smtcal compile --target linuxcnc --dry-run-probe). For rs274 only, never a machine:\n"
      "#   rs274 -i {}/{} -g PROGRAM.ngc\n"
      "[RS274NGC]\n"
      "PARAMETER_FILE = {}/{}\n"
      "# the dry-run probe file first, then smtcal's runtime for the cell\n"
      "SUBROUTINE_PATH = {}:{}\n",
      SMTCAL_VERSION, dry_run_folder, kLinuxCncDryRunIni, dry_run_folder, kLinuxCncDryRunVar, dry_run_folder,
      runtime_folder);
}

std::string LinuxCncZeroOffsets() {
  // Every coordinate system and G92 offset 0, G54 (#5220 = 1) active: the
  // work coordinates are the robot base frame, as the runtime needs.
  std::string var;
  for (int p = 5211; p <= 5230; ++p) var += fmt::format("{}\t{}\n", p, p == 5220 ? "1.000000" : "0.000000");
  return var;
}

}  // namespace smtcal

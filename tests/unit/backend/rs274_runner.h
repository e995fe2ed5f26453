// Runs LinuxCNC's standalone interpreter `rs274` (Debian package
// linuxcnc-uspace) on a program, for the tests of the LinuxCNC target: its
// exit code, its streams, and the canonical commands it printed, parsed.
// rs274 prints one canonical command per line on stdout
// ("   13 N..... STRAIGHT_TRAVERSE(1.1235, 2.0000, ...)", 4 decimals) and
// interpreter errors and `(abort, ...)` messages on stderr.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace smtcal::test {

// A motion command: STRAIGHT_TRAVERSE, STRAIGHT_FEED or STRAIGHT_PROBE, with
// its target x y z a b c as printed.
struct CanonMove {
  std::string kind;
  std::array<double, 6> xyzabc{};
};

struct Rs274Result {
  int exit_code = -1;                 // -1: rs274 did not exit normally (or is not installed)
  std::string out, err;               // stdout, stderr
  std::vector<std::string> canon;     // every canonical command line, without the "   12 N..... " prefix
  std::vector<std::string> messages;  // the text inside MESSAGE("...")
  std::vector<CanonMove> moves;       // motion commands in order
};

// True when `rs274` is on the PATH.
bool HaveRs274();

// Runs `rs274 -i INI -g NGC` in a temporary working directory. Fails the
// current test (ADD_FAILURE with "install linuxcnc-uspace
// (tools/install-deps.sh)") when rs274 is not installed.
Rs274Result RunRs274(const std::filesystem::path& ini, const std::filesystem::path& ngc);

// Writes DIR/rs274.ini with [RS274NGC]SUBROUTINE_PATH = the given
// directories (in order, ':'-separated) and the axes X Y Z + rotation C, in
// mm and degrees; returns its path.
std::filesystem::path WriteRs274Ini(const std::filesystem::path& dir,
                                    const std::vector<std::filesystem::path>& subroutine_path);

}  // namespace smtcal::test

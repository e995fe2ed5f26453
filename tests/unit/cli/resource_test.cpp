// Running out of memory is not a mistake in the input: smtcal never reports
// it as a syntax error (exit 1), and `simulate` refuses up front a run whose
// kept placement errors cannot fit (exit 3, with the number of cycles that
// would). The memory is limited with the shell's `ulimit -v`, which the
// sanitizers' shadow memory does not survive: the tests skip under them.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "tests/bench/program_generator.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

#if defined(SMTCAL_SANITIZED)  // the top-level CMakeLists.txt, SMTCAL_SANITIZE
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

struct LimitedRun {
  int exit_code = -1;  // -1: ended by a signal (an uncaught exception aborts)
  std::string err;
};

// `smtcal args` with at most `kib` KiB of address space, in `dir`.
LimitedRun RunWithMemoryLimit(const fs::path& dir, long kib, const std::string& args) {
  std::string command = fmt::format("cd '{}' && (ulimit -v {} && exec '{}' {}) >out 2>err </dev/null", dir.string(),
                                    kib, SMTCAL_BINARY, args);
  int status = std::system(command.c_str());
  LimitedRun run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.err = test::ReadFileText(dir / "err");
  return run;
}

fs::path Scratch(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_resource_{}_{}", name, ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

const std::string kCell = SMTCAL_SOURCE_DIR "/examples/paper-cell/paper.cell.toml";

TEST(Resources, RunningOutOfMemoryWhileParsingIsNotASyntaxError) {
  if (kSanitized) GTEST_SKIP() << "ulimit -v and the sanitizers' shadow memory do not mix";
  fs::path dir = Scratch("parse");
  std::ofstream(dir / "big.place") << bench::GeneratePlacements(300000);  // 30 MB, its IR alone 300 MB
  LimitedRun run = RunWithMemoryLimit(dir, 400000, "check big.place");
  // Exit 3, the driver's report of resource failures; never exit 1 with a
  // diagnostic.
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_EQ(run.err.find("parser stopped"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("big.place:"), std::string::npos) << "no diagnostic in the program: " << run.err;
  EXPECT_NE(run.err.find("smtcal: error: out of memory"), std::string::npos) << run.err;
  fs::remove_all(dir);
}

TEST(Resources, SimulateRefusesARunThatCannotFitInMemory) {
  if (kSanitized) GTEST_SKIP() << "ulimit -v and the sanitizers' shadow memory do not mix";
  fs::path dir = Scratch("simulate");
  std::ofstream(dir / "board.place") << bench::GeneratePlacements(2000);
  // 2000 placements x 5000 cycles x 56 bytes = 0.56 GB of kept errors, more
  // than a 400 MB address space; 1e7 placements are within the run's own
  // bound (limits::kMaxSimulatedPlacements, Hostile tests), so this is the
  // memory check speaking.
  LimitedRun refused = RunWithMemoryLimit(dir, 400000, fmt::format("simulate board.place --cell '{}' --cycles 5000", kCell));
  EXPECT_EQ(refused.exit_code, 3) << refused.err;
  EXPECT_NE(refused.err.find("simulating 5000 cycles of 2000 placements keeps 0.6 GB of placement errors (56 "
                             "bytes a placement)"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("; simulate at most"), std::string::npos) << refused.err;
  // What fits runs.
  LimitedRun fits = RunWithMemoryLimit(dir, 400000, fmt::format("simulate board.place --cell '{}' --cycles 20", kCell));
  EXPECT_EQ(fits.exit_code, 0) << fits.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smtcal

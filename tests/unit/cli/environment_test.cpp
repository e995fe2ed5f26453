// Hostile environments (docs/files-and-exit-codes.md): a standard output
// that fails, directories and endless files as inputs, devices, symbolic
// links and long names as outputs, temporaries left by a killed run, a report
// beside a program that cannot be written, file names that are not UTF-8.
// Each runs the real smtcal executable; none may end other than by exit 0-3.
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/field_text.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = SMTCAL_SOURCE_DIR;
const std::string kProgram = (kSource / "examples/paper-cell/layers.place").string();
const std::string kCell = (kSource / "examples/paper-cell/paper.cell.toml").string();
const std::string kTable = (kSource / "examples/paper-cell/placing-table.csv").string();

std::string Quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// A scratch folder per test, removed at the end.
class Environment : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("smtcal_env_{}_{}", ::getpid(), testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `smtcal args` in the scratch folder with stdout sent to `stdout_to`
  // (a path; empty: a file in the scratch folder).
  struct Run {
    int exit_code = -1;  // -1: did not exit normally (a signal)
    std::string out, err;
  };
  Run Smtcal(const std::string& args, const std::string& stdout_to = "") {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    std::string command = fmt::format("cd {} && {} {} </dev/null >{} 2>{}", Quote(dir_.string()), Quote(SMTCAL_BINARY),
                                      args, Quote(stdout_to.empty() ? out.string() : stdout_to), Quote(err.string()));
    int status = std::system(command.c_str());
    Run run;
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.out = test::ReadFileText(out);
    run.err = test::ReadFileText(err);
    fs::remove(out);
    fs::remove(err);
    return run;
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

TEST_F(Environment, AFailedStandardOutputIsExitThreeInEveryMode) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  std::ofstream(Path("ugly.place")) << "program Ugly\nunits mm\nfunction main\nfend\n";
  const std::string commands[] = {
      fmt::format("verify {} --cell {}", Quote(kProgram), Quote(kCell)),
      fmt::format("verify {} --cell {} --json", Quote(kProgram), Quote(kCell)),
      fmt::format("simulate {} --cell {} --cycles 2", Quote(kProgram), Quote(kCell)),
      fmt::format("simulate {} --cell {} --cycles 2 --json", Quote(kProgram), Quote(kCell)),
      fmt::format("compile {} --cell {} -o -", Quote(kProgram), Quote(kCell)),
      fmt::format("fmt {}", Quote(kProgram)),
      "fmt --check ugly.place",
      fmt::format("table stats {}", Quote(kTable)),
      fmt::format("table stats {} --json", Quote(kTable)),
      fmt::format("cell check {}", Quote(kCell)),
      fmt::format("cell check {} --json", Quote(kCell)),
      "--help",
  };
  for (const std::string& command : commands) {
    Run run = Smtcal(command, "/dev/full");
    EXPECT_EQ(run.exit_code, 3) << command << "\n" << run.err;
    EXPECT_NE(run.err.find("cannot write to standard output: No space left on device"), std::string::npos)
        << command << "\n" << run.err;
  }
}

TEST_F(Environment, ADirectoryAsInputIsExitThree) {
  fs::create_directories(Path("folder.place"));
  Run fmt_run = Smtcal("fmt folder.place -o out.place");
  EXPECT_EQ(fmt_run.exit_code, 3);
  EXPECT_EQ(fmt_run.err, "smtcal: error: cannot read 'folder.place': it is a directory\n");
  EXPECT_FALSE(fs::exists(Path("out.place")));
  Run check_run = Smtcal("check .");
  EXPECT_EQ(check_run.exit_code, 3);
  EXPECT_NE(check_run.err.find("it is a directory"), std::string::npos);
}

TEST_F(Environment, AnEndlessInputIsBounded) {
  Run run = Smtcal("check /dev/zero");
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_EQ(run.err,
            "smtcal: error: cannot read '/dev/zero': it is larger than 256 MiB, the most smtcal reads from one input "
            "(is it the right file?)\n");
}

TEST_F(Environment, ADeviceOrDirectoryIsNeverReplaced) {
  // A device node of our own (the null device's numbers), never the
  // system's /dev/null: a smtcal that replaced devices would replace this one.
  if (::mknod(Path("null").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
    Run device = Smtcal(fmt::format("fmt {} -o null", Quote(kProgram)));
    EXPECT_EQ(device.exit_code, 3);
    EXPECT_NE(device.err.find("'null': it is a character device, not a regular file"), std::string::npos)
        << device.err;
    struct stat info {};
    ASSERT_EQ(::stat(Path("null").c_str(), &info), 0);
    EXPECT_TRUE(S_ISCHR(info.st_mode));
  }  // else not root: the FIFO below is a special file all the same

  fs::create_directories(Path("out"));
  Run directory = Smtcal(fmt::format("fmt {} -o out", Quote(kProgram)));
  EXPECT_EQ(directory.exit_code, 3);
  EXPECT_NE(directory.err.find("'out': it is a directory"), std::string::npos) << directory.err;
  EXPECT_TRUE(fs::is_directory(Path("out")));

  ASSERT_EQ(::mkfifo(Path("fifo").c_str(), 0600), 0);
  Run fifo = Smtcal(fmt::format("fmt {} -o fifo", Quote(kProgram)));  // must not block
  EXPECT_EQ(fifo.exit_code, 3);
  EXPECT_NE(fifo.err.find("it is a FIFO"), std::string::npos) << fifo.err;
}

TEST_F(Environment, ASymbolicLinkIsWrittenThroughAtomically) {
  fs::create_directories(Path("real"));
  std::ofstream(Path("real/target.place")) << "old\n";
  fs::create_symlink("real/target.place", Path("link.place"));     // relative to the link's folder
  fs::create_symlink(Path("link.place"), Path("link2.place"));     // a link to a link
  Run run = Smtcal(fmt::format("fmt {} -o link2.place", Quote(kProgram)));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(fs::is_symlink(Path("link.place")));
  EXPECT_TRUE(fs::is_symlink(Path("link2.place")));
  EXPECT_EQ(test::ReadFileText(Path("real/target.place")), test::ReadFileText(kProgram));
  // A dangling link: its target is created.
  fs::create_symlink("real/new.place", Path("dangling.place"));
  ASSERT_EQ(Smtcal(fmt::format("fmt {} -o dangling.place", Quote(kProgram))).exit_code, 0);
  EXPECT_TRUE(fs::is_symlink(Path("dangling.place")));
  EXPECT_EQ(test::ReadFileText(Path("real/new.place")), test::ReadFileText(kProgram));
  // A loop of links.
  fs::create_symlink("loop_b", Path("loop_a"));
  fs::create_symlink("loop_a", Path("loop_b"));
  Run loop = Smtcal(fmt::format("fmt {} -o loop_a", Quote(kProgram)));
  EXPECT_EQ(loop.exit_code, 3);
  EXPECT_NE(loop.err.find("Too many levels of symbolic links"), std::string::npos) << loop.err;
}

TEST_F(Environment, AReplacedFileKeepsItsMode) {
  std::ofstream(Path("out.place")) << "old\n";
  fs::permissions(Path("out.place"), fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  ASSERT_EQ(Smtcal(fmt::format("fmt {} -o out.place", Quote(kProgram))).exit_code, 0);
  EXPECT_EQ(fs::status(Path("out.place")).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST_F(Environment, OutputNamesOfEveryLegalLength) {
  for (std::size_t length : {240u, 247u, 250u, 255u}) {
    const std::string name(length, 'n');
    Run run = Smtcal(fmt::format("fmt {} -o {}", Quote(kProgram), name));
    EXPECT_EQ(run.exit_code, 0) << length << ": " << run.err;
    EXPECT_EQ(test::ReadFileText(Path(name)), test::ReadFileText(kProgram)) << length;
  }
  // Only the outputs: no temporary left.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 4);
}

TEST_F(Environment, StaleTemporariesOfAKilledRunAreRemoved) {
  // The pid of a process that has ended: a stand-in for a smtcal killed by kill -9.
  pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  const std::string stale = Path(fmt::format("out.place.smtcal-tmp-{}", child));
  const std::string alive = Path(fmt::format("out.place.smtcal-tmp-{}", ::getpid()));  // a running writer's
  const std::string other = Path("out.place.smtcal-tmp-notapid");                   // not ours
  for (const std::string& path : {stale, alive, other}) std::ofstream(path) << "partial";
  ASSERT_EQ(Smtcal(fmt::format("fmt {} -o out.place", Quote(kProgram))).exit_code, 0);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_EQ(test::ReadFileText(Path("out.place")), test::ReadFileText(kProgram));
}

TEST_F(Environment, ReportAndProgramAreWrittenTogetherOrNotAtAll) {
  std::ofstream(Path("report.json")) << "old report\n";
  Run run = Smtcal(fmt::format("compile {} --cell {} -o missing/out.place --report report.json", Quote(kProgram),
                               Quote(kCell)));
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find("cannot write 'missing/out.place'"), std::string::npos) << run.err;
  EXPECT_EQ(test::ReadFileText(Path("report.json")), "old report\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1) << "a temporary was left";

  Run both = Smtcal(fmt::format("compile {} --cell {} -o out.place --report report.json", Quote(kProgram),
                                Quote(kCell)));
  ASSERT_EQ(both.exit_code, 0) << both.err;
  EXPECT_TRUE(nlohmann::json::accept(test::ReadFileText(Path("report.json"))));
  EXPECT_FALSE(test::ReadFileText(Path("out.place")).empty());
}

// Out of memory is reported as such (exit 3), never as a mistake in the
// input. (ASan reserves more address space than the limit allows.)
TEST_F(Environment, OutOfMemoryIsExitThreeNotAnInputError) {
#if defined(SMTCAL_SANITIZED)
  GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
#endif
  {
    std::ofstream big(Path("big.place"));
    big << "Program Big\nUnits mm\nVacuum 8\nPoint P = XY(200, 20, -10, 0)\n\nFunction Main\n";
    for (int i = 0; i < 300000; ++i) big << "  Jump P + X(1) + Y(2) + Z(3)\n";  // checked in about 290 MB
    big << "Fend\n";
  }
  // A valid program, in 150 MB of address space.
  std::string command = fmt::format("cd {} && ulimit -v 150000 && {} check big.place >/dev/null 2>err.txt",
                                    Quote(dir_.string()), Quote(SMTCAL_BINARY));
  int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << "ended by a signal";
  EXPECT_EQ(WEXITSTATUS(status), 3);
  EXPECT_EQ(test::ReadFileText(Path("err.txt")), "smtcal: error: out of memory\n");
}

// A file name with bytes that are not UTF-8 (legal on Linux) in every JSON
// output and the SVG pictures: valid JSON and XML text, U+FFFD for the bytes.
TEST_F(Environment, FileNamesThatAreNotUtf8) {
  const std::string bad = "lay\xff\xfe";
  fs::copy_file(kProgram, Path(bad + ".place"));
  fs::copy_file(kTable, Path(bad + ".csv"));
  std::string cell = test::ReadFileText(kCell);
  const std::string absolute = "table = \"" + (kSource / "examples/paper-cell").string() + "/";
  for (std::size_t at = 0; (at = cell.find("table = \"", at)) != std::string::npos; at += absolute.size()) {
    cell.replace(at, 9, absolute);
  }
  std::ofstream(Path(bad + ".cell.toml")) << cell;
  fs::copy_file(kSource / "tests/golden/fixture/scan.csv", Path(bad + ".trips.csv"));
  const std::string program = Quote(bad + ".place");
  const std::string json_commands[] = {
      fmt::format("verify {} --cell {} --json", program, Quote(kCell)),
      fmt::format("simulate {} --cell {} --cycles 2 --json", program, Quote(kCell)),
      fmt::format("table stats {} --json", Quote(bad + ".csv")),
      fmt::format("cell check {} --json", Quote(bad + ".cell.toml")),
      fmt::format("diff {} {} --json", program, program),
      fmt::format("fixture --cell {} --fixture Board --trips {} --json",
                  Quote((kSource / "tests/golden/fixture/data/board.cell.toml").string()), Quote(bad + ".trips.csv")),
  };
  for (const std::string& command : json_commands) {
    Run run = Smtcal(command);
    EXPECT_EQ(run.exit_code, 0) << command << "\n" << run.err;
    EXPECT_TRUE(nlohmann::json::accept(run.out)) << command;
    EXPECT_NE(run.out.find("lay\xef\xbf\xbd\xef\xbf\xbd"), std::string::npos) << command;
  }
  Run report = Smtcal(fmt::format("compile {} --cell {} -o out.place --report report.json", program, Quote(kCell)));
  EXPECT_EQ(report.exit_code, 0) << report.err;
  EXPECT_TRUE(nlohmann::json::accept(test::ReadFileText(Path("report.json"))));

  Run svg = Smtcal(fmt::format("simulate {} --cell {} --cycles 2 --svg out.svg", program, Quote(kCell)));
  EXPECT_EQ(svg.exit_code, 0) << svg.err;
  const std::string picture = test::ReadFileText(Path("out.svg"));
  ASSERT_FALSE(picture.empty());
  for (std::size_t i = 0; i < picture.size(); i += std::max<std::size_t>(Utf8Length(picture, i), 1)) {
    ASSERT_NE(Utf8Length(picture, i), 0u) << "invalid UTF-8 at byte " << i;
  }
  EXPECT_NE(picture.find("lay\xef\xbf\xbd\xef\xbf\xbd"), std::string::npos);
}

}  // namespace
}  // namespace smtcal

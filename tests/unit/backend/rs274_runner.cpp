// The rs274 runner (rs274_runner.h): the interpreter runs as a child process
// through the shell, with its streams in files of a scratch directory that
// is also its working directory (rs274 may write files there).
#include "tests/unit/backend/rs274_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace smtcal::test {

namespace fs = std::filesystem;

namespace {

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::string Quoted(const fs::path& path) {
  std::string out = "'";
  for (char c : path.string()) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// "   12 N..... NAME(args)" -> "NAME(args)"; other lines (none expected) as is.
std::string WithoutPrefix(const std::string& line) {
  const std::size_t dots = line.find("N..... ");
  return dots == std::string::npos ? line : line.substr(dots + 7);
}

void Parse(Rs274Result& result) {
  std::istringstream lines(result.out);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const std::string command = WithoutPrefix(line);
    result.canon.push_back(command);
    if (command.starts_with("MESSAGE(\"") && command.ends_with("\")")) {
      result.messages.push_back(command.substr(9, command.size() - 11));
      continue;
    }
    for (const char* kind : {"STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "STRAIGHT_PROBE"}) {
      const std::string open = std::string(kind) + "(";
      if (!command.starts_with(open)) continue;
      CanonMove move;
      move.kind = kind;
      std::istringstream args(command.substr(open.size()));
      for (double& v : move.xyzabc) {
        char separator = 0;
        args >> v >> separator;
      }
      result.moves.push_back(move);
    }
  }
}

}  // namespace

bool HaveRs274() { return std::system("command -v rs274 >/dev/null 2>&1") == 0; }

Rs274Result RunRs274(const fs::path& ini, const fs::path& ngc) {
  Rs274Result result;
  if (!HaveRs274()) {
    ADD_FAILURE() << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
    return result;
  }
  static int run_count = 0;
  const fs::path scratch = fs::temp_directory_path() / fmt::format("smtcal_rs274_{}_{}", ::getpid(), ++run_count);
  fs::create_directories(scratch);
  // HOME is the scratch folder: rs274 keeps its tool table in $HOME/.tool.mmap,
  // truncating and mapping it at start-up, so two runs sharing a HOME (ctest -j)
  // can kill each other with SIGBUS.
  const std::string command =
      fmt::format("cd {0} && HOME={0} rs274 -i {1} -g {2} </dev/null >{3} 2>{4}", Quoted(scratch),
                  Quoted(fs::absolute(ini)),
                  Quoted(fs::absolute(ngc)), Quoted(scratch / "out"), Quoted(scratch / "err"));
  const int status = std::system(command.c_str());
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = ReadAll(scratch / "out");
  result.err = ReadAll(scratch / "err");
  fs::remove_all(scratch);
  Parse(result);
  return result;
}

fs::path WriteRs274Ini(const fs::path& dir, const std::vector<fs::path>& subroutine_path) {
  std::string path;
  for (const fs::path& p : subroutine_path) path += (path.empty() ? "" : ":") + fs::absolute(p).string();
  fs::create_directories(dir);
  const fs::path ini = dir / "rs274.ini";
  std::ofstream(ini, std::ios::binary) << fmt::format(
      "# Written by the smtcal tests for rs274 (tests/unit/backend/rs274_runner.h).\n"
      "[EMC]\nMACHINE = smtcal-test\n\n"
      "[RS274NGC]\nSUBROUTINE_PATH = {}\n\n"
      "[TRAJ]\nCOORDINATES = X Y Z C\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n\n"
      "[KINS]\nKINEMATICS = trivkins coordinates=XYZC\nJOINTS = 4\n",
      path);
  return ini;
}

}  // namespace smtcal::test

// Helpers shared by the tests: reading a file, and running the real smtcal
// executable the way a user does. (Parsing a text: tests/unit/parse_text.h.)
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/core.h>


namespace smtcal::test {

// The whole file as bytes; empty if it cannot be read.
inline std::string ReadFileText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

struct SmtcalRun {
  int exit_code = -1;  // -1 if smtcal did not exit normally
  std::string out;
  std::string err;
  std::string command;  // for failure messages
};

// Runs `smtcal args` (args are shell words, quoted by the caller) with the
// working directory `working_dir` and `stdin_text` on standard input. The
// captured streams live in a scratch folder of the temp directory, never
// beside the inputs.
inline SmtcalRun RunSmtcal(const std::string& args,
                           const std::filesystem::path& working_dir = std::filesystem::temp_directory_path(),
                           const std::string& stdin_text = "") {
  static int run_count = 0;
  std::filesystem::path scratch = std::filesystem::temp_directory_path() /
                                  fmt::format("smtcal_test_run_{}_{}", ::getpid(), ++run_count);
  std::filesystem::create_directories(scratch);
  std::ofstream(scratch / "in", std::ios::binary) << stdin_text;
  SmtcalRun run;
  run.command = fmt::format("cd '{}' && '{}' {} <'{}' >'{}' 2>'{}'", working_dir.string(), SMTCAL_BINARY, args,
                            (scratch / "in").string(), (scratch / "out").string(), (scratch / "err").string());
  int status = std::system(run.command.c_str());
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = ReadFileText(scratch / "out");
  run.err = ReadFileText(scratch / "err");
  std::filesystem::remove_all(scratch);
  return run;
}

}  // namespace smtcal::test

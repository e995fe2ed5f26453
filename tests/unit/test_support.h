// Helpers shared by the tests: parsing a text, reading a file, and running
// the real smtcal executable the way a user does.
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

#include "frontend/diagnostics.h"
#include "frontend/parse.h"
#include "passes/ir.h"

namespace smtcal::test {

// A .place text parsed on its own, registered as "t.place".
struct ParsedText {
  ir::Program program;
  std::string diagnostics;  // RenderText of every diagnostic
  std::size_t error_count = 0;
  bool ok() const { return error_count == 0; }
};

inline ParsedText ParseText(const std::string& text) {
  SourceManager sources;
  std::uint32_t file = sources.Add("t.place", text);
  Diagnostics diags(sources);
  ParsedText parsed;
  parsed.program = ParseProgram(file, diags);
  parsed.diagnostics = diags.RenderText();
  parsed.error_count = diags.error_count();
  return parsed;
}

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

// A .place text parsed on its own, for the tests of the frontend and above.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "base/diagnostics.h"
#include "frontend/parse.h"
#include "ir/ir.h"

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

}  // namespace smtcal::test

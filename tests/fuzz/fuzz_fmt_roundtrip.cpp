// `smtcal fmt`'s promise: a program that parses prints in canonical form,
// that text parses without errors to the same IR (after the canonical
// changes), and printing it again changes nothing.
#include "backend/place/place_printer.h"
#include "frontend/parse.h"
#include "ir/ir_dump.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(fmt_roundtrip) {
  using namespace smtcal;
  SourceManager sources;
  Diagnostics diags(sources);
  ir::Program program = ParseProgram(sources.Add("fuzz.place", std::string(fuzz::AsText(data, size))), diags);
  if (diags.has_errors()) return 0;
  const std::string canonical = PrintPlace(program);
  Diagnostics reparse_diags(sources);
  ir::Program reparsed = ParseProgram(sources.Add("canonical.place", canonical), reparse_diags);
  if (reparse_diags.has_errors()) {
    std::fprintf(stderr, "%s--- canonical text:\n%s", reparse_diags.RenderText().c_str(), canonical.c_str());
    fuzz::Fail("fmt's output does not parse");
  }
  ApplyCanonicalChanges(program);
  if (DumpIr(reparsed) != DumpIr(program)) fuzz::Fail("fmt's output parses to another program");
  if (PrintPlace(reparsed) != canonical) fuzz::Fail("fmt is not idempotent");
  return 0;
}

// A .place program: the parser, then every semantic check (`smtcal check`),
// and both renderings of the diagnostics.
#include "frontend/parse.h"
#include "passes/pass_manager.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(place_check) {
  using namespace smtcal;
  SourceManager sources;
  Diagnostics diags(sources);
  ir::Program program = ParseProgram(sources.Add("fuzz.place", std::string(fuzz::AsText(data, size))), diags);
  if (!diags.has_errors()) {
    std::vector<const PassInfo*> checks;
    for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
    RunPasses(program, diags, checks, /*verify_each=*/true);
  }
  diags.RenderText();
  diags.RenderJson();
  return 0;
}

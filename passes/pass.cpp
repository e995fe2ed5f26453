// The pass registry and the pass runner.
#include <algorithm>

#include <fmt/format.h>

#include "base/check.h"
#include "ir/symbols.h"
#include "ir/verifier.h"
#include "passes/checks/checks.h"
#include "passes/correction/correction_passes.h"
#include "passes/pass.h"
#include "passes/pass_manager.h"

namespace smtcal {

const std::vector<PassInfo>& PassRegistry() {
  // The default pipeline, in order: names before anything that resolves
  // them, so a user reading the output top-down sees causes first.
  static const std::vector<PassInfo> registry = {
      {"check-header", "Program first and once, Units mm once, a Function Main exists",
       CreateCheckHeaderPass},
      {"check-names", "names defined once and used as the right kind; Local frames do not loop",
       CreateCheckNamesPass},
      {"check-types", "Integer/Real/Boolean expressions, conditions, assignments, For/Next",
       CreateCheckTypesPass},
      {"check-ranges", "I/O bits, vacuum outputs, pallets, steps, waits, angles and LimZ within limits",
       CreateCheckRangesPass},
      {"check-fixture-scope", "fixture points used only inside a Cycle of their fixture, across Calls",
       CreateCheckFixtureScopePass},
      {"check-reachability", "unreachable statements, functions never called, recursion",
       CreateCheckReachabilityPass},
  };
  return registry;
}

const std::vector<PassInfo>& CorrectionPassRegistry() {
  static const std::vector<PassInfo> registry = {
      {"bind", "program fixtures bound to the cell's; FIX_0 of taught points; every motion target found",
       CreateBindPass},
      {"regions", "each target's calibrated region and correction kind; regions must calibrate x and y",
       CreateRegionsPass},
      {"static-inversion", "base-frame targets get nominal coordinates through the inverse calibration",
       CreateStaticInversionPass},
      {"fixture-correction", "taught points to FIXPOS_0 = FIX_0^-1 F(ROBOT_0); what the runtime needs per target",
       CreateFixtureCorrectionPass},
      {"scan-injection", "every Cycle opens with the Scan of its fixture", CreateScanInjectionPass},
      {"verify", "robot limits, regions under every allowed fixture pose, residuals, tolerance budgets, cycle time",
       CreateVerifyTargetsPass},
  };
  return registry;
}

Result<std::vector<const PassInfo*>> FindPasses(const std::vector<std::string>& names) {
  const std::vector<PassInfo>& registry = PassRegistry();
  std::vector<const PassInfo*> found;
  for (const std::string& name : names) {
    auto it = std::find_if(registry.begin(), registry.end(),
                           [&](const PassInfo& info) { return info.name == name; });
    if (it == registry.end()) {
      std::vector<std::string> valid;
      for (const PassInfo& info : registry) valid.push_back(info.name);
      return Error{fmt::format("unknown pass '{}'; valid passes: {}", name, fmt::join(valid, ", "))};
    }
    found.push_back(&*it);
  }
  return found;
}

namespace {

void VerifyOrFail(const ir::Program& program, const Diagnostics& diags, std::string_view culprit) {
  std::vector<VerifierIssue> issues = VerifyProgram(program);
  // The passes share one symbol table (sema::SymbolsOf): one that changed
  // the declarations must have forgotten it.
  if (program.symbols && !sema::SameSymbols(*program.symbols, sema::SymbolTable::Build(program))) {
    InternalError(fmt::format("internal error: the shared symbol table no longer fits the program {}; a pass that "
                              "changes declarations must call sema::ForgetSymbols. This is a bug in smtcal, not in "
                              "the program.",
                              culprit));
  }
  if (issues.empty()) return;
  std::string report = fmt::format(
      "internal error: the IR is broken {} ({} problem{}); this is a bug in smtcal, not in the program:", culprit,
      issues.size(), issues.size() == 1 ? "" : "s");
  for (const VerifierIssue& issue : issues) {
    report += fmt::format("\n  {}", FormatVerifierIssue(issue, diags.sources(), program.file));
  }
  InternalError(report);
}

}  // namespace

Status RunPasses(ir::Program& program, Diagnostics& diags, const std::vector<std::string>& names,
                 bool verify_each) {
  std::vector<const PassInfo*> passes;
  if (names.empty()) {
    for (const PassInfo& info : PassRegistry()) passes.push_back(&info);
  } else {
    Result<std::vector<const PassInfo*>> found = FindPasses(names);
    if (!found) return found.error();
    passes = std::move(found).value();
  }
  RunPasses(program, diags, passes, verify_each);
  return Ok{};
}

void RunPasses(ir::Program& program, Diagnostics& diags, const std::vector<const PassInfo*>& passes,
               bool verify_each) {
  if (verify_each) VerifyOrFail(program, diags, "in the input to the first pass");
  for (const PassInfo* info : passes) {
    std::unique_ptr<Pass> pass = info->create();
    pass->Run(program, diags);
    if (verify_each) VerifyOrFail(program, diags, fmt::format("after pass '{}'", info->name));
  }
}

std::string DescribePasses() { return DescribePasses(PassRegistry()); }

std::string DescribePasses(const std::vector<PassInfo>& registry) {
  std::size_t width = 0;
  for (const PassInfo& info : registry) width = std::max(width, info.name.size());
  std::string text;
  for (const PassInfo& info : registry) {
    text += fmt::format("  {:<{}}  {}\n", info.name, width, info.description);
  }
  return text;
}

}  // namespace smtcal

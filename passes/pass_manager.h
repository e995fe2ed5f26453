// Running passes: by name, in order, optionally verifying the IR after each.
#pragma once

#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/result.h"
#include "ir/ir.h"
#include "passes/pass.h"

namespace smtcal {

// The registry entries for `names`, in the order given. An unknown name is
// an Error whose message lists the valid names.
Result<std::vector<const PassInfo*>> FindPasses(const std::vector<std::string>& names);

// Runs the named passes in the order given; with no names, the whole
// registry in pipeline order. Every pass runs even when an earlier one
// reported errors, so the user sees all of them at once: checks skip what
// they cannot resolve instead of reporting it twice.
//
// With verify_each the verifier checks the IR before the first pass (naming
// the input as the culprit) and after every pass; a broken IR is a bug in
// smtcal, so it prints every violation, names the pass that caused it and
// ends as an internal error (base/check.h). An unknown pass name is returned as an Error before anything runs.
Status RunPasses(ir::Program& program, Diagnostics& diags, const std::vector<std::string>& names,
                 bool verify_each);
// The same for passes already looked up (or made by a test).
void RunPasses(ir::Program& program, Diagnostics& diags, const std::vector<const PassInfo*>& passes,
               bool verify_each);

// One line per registered pass, "  name  description", for --help.
std::string DescribePasses();
// The same for another registry (CorrectionPassRegistry()).
std::string DescribePasses(const std::vector<PassInfo>& registry);

}  // namespace smtcal

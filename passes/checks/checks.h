// Factories of the semantic check passes, one per file in passes/check_*.cpp.
// Only the registry (passes/pass.cpp) calls them; everyone else finds passes
// by name through PassRegistry().
#pragma once

#include <memory>

#include "passes/pass.h"

namespace smtcal {

std::unique_ptr<Pass> CreateCheckHeaderPass();
std::unique_ptr<Pass> CreateCheckNamesPass();
std::unique_ptr<Pass> CreateCheckTypesPass();
std::unique_ptr<Pass> CreateCheckRangesPass();
std::unique_ptr<Pass> CreateCheckFixtureScopePass();
std::unique_ptr<Pass> CreateCheckReachabilityPass();

}  // namespace smtcal

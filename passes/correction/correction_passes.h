// The correction passes of `smtcal compile` and `smtcal verify`, one file
// each in passes/, run after the checks on a program with a cell
// (ir::Program::compile set). Only the registry (passes/pass.cpp) calls the
// factories.
#pragma once

#include <memory>
#include <vector>

#include "passes/pass.h"

namespace smtcal {

// The correction pipeline, in order (bind, regions, static-inversion,
// fixture-correction, scan-injection, verify).
const std::vector<PassInfo>& CorrectionPassRegistry();

std::unique_ptr<Pass> CreateBindPass();
std::unique_ptr<Pass> CreateRegionsPass();
std::unique_ptr<Pass> CreateStaticInversionPass();
std::unique_ptr<Pass> CreateFixtureCorrectionPass();
std::unique_ptr<Pass> CreateScanInjectionPass();
std::unique_ptr<Pass> CreateVerifyTargetsPass();

}  // namespace smtcal

// The .place parser. The only public door into the ANTLR-generated code:
// nothing here or in the IR mentions an ANTLR type.
#pragma once

#include <cstdint>

#include "base/diagnostics.h"
#include "ir/ir.h"

namespace smtcal {

// Parses the source registered as `file` in diags.sources(). Syntax errors
// are reported to `diags` (bounded: a file of garbage gives a handful of
// errors, not one per byte). The returned program holds everything that
// parsed; when diags has errors it must not be compiled, only inspected.
ir::Program ParseProgram(std::uint32_t file, Diagnostics& diags);

}  // namespace smtcal

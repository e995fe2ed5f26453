// The .place parser. The only public door into the ANTLR-generated code:
// nothing here or in the IR mentions an ANTLR type.
#pragma once

#include <cstdint>
#include <vector>

#include "base/diagnostics.h"
#include "frontend/place_lexer.h"
#include "ir/ir.h"

namespace smtcal {

// Parses the source registered as `file` in diags.sources(). Syntax errors
// are reported to `diags` (bounded: a file of garbage gives a handful of
// errors, not one per byte). The returned program holds everything that
// parsed; when diags has errors it must not be compiled, only inspected.
// Memory is the IR, the file's tokens (16 bytes each) and one line's parse
// tree at a time; running out of it throws std::bad_alloc, never a syntax
// error.
ir::Program ParseProgram(std::uint32_t file, Diagnostics& diags);

// The same from tokens already made for the file's text, by LexPlace or by
// the reference lexer (the differential test parses with both).
ir::Program ParseTokens(std::uint32_t file, LexedPlace lexed, Diagnostics& diags);

}  // namespace smtcal

// The canonical printer for .place programs (`smtcal fmt`, and the `place`
// target's output). The canonical form is documented in docs/language.md,
// section "Canonical form". Printing keeps everything the IR holds: comments,
// blank lines between statements, names as written; parsing the output gives
// the same IR as the input, and printing that again gives the same text.
#pragma once

#include <string>

#include "base/result.h"
#include "base/text_output.h"
#include "ir/ir.h"
#include "ir/ir_text.h"  // the expressions and literals inside a program

namespace smtcal {

// The whole program in canonical form: every line ends with '\n', an empty
// program prints as "".
std::string PrintPlace(const ir::Program& program);
// The same appended to `out` as it is produced (a large program is never
// held as one string)...
void PrintPlace(const ir::Program& program, TextOutput& out);
// ... and written to the file `path` ("-": standard output) that way,
// atomically (base/text_output.h).
Status WritePlace(const std::string& path, const ir::Program& program);

// What printing changes on purpose, done to an IR: a `Next` that is bare or
// spells its loop variable differently gets the For's spelling, and the first
// statement of the file and of every block loses its blank line. For every
// program p that parses, parsing PrintPlace(p) gives exactly the IR of
// ApplyCanonicalChanges(p) (equal DumpIr without locations).
void ApplyCanonicalChanges(ir::Program& program);

}  // namespace smtcal

#include "frontend/parse.h"

#include "PlaceLexer.h"
#include "PlaceParser.h"

namespace smtcal {

ir::Program ParseProgram(std::uint32_t file, Diagnostics& diags) {
  (void)diags;
  ir::Program program;
  program.file = file;
  return program;
}

}  // namespace smtcal

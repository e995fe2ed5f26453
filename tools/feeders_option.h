// `--feeders FILE`, which `smtcal import` and `smtcal setup-sheet` both take:
// the feeders file read the same way for both.
#pragma once

#include <string>

#include "base/diagnostics.h"
#include "base/source.h"
#include "frontend/feeders_toml.h"
#include "tools/commands.h"

namespace smtcal::tools {

// Reads the feeders file at `path` into `out` ("" : none, `out` left empty).
// False when the file cannot be read: the diagnostics so far and the I/O
// error are printed and options.exit_code is set. Mistakes inside the file
// are diagnostics in `diags` (the caller prints them with the rest).
bool LoadFeedersOption(const std::string& path, SourceManager& sources, Diagnostics& diags, cad::FeedersFile& out,
                       GlobalOptions& options);

}  // namespace smtcal::tools

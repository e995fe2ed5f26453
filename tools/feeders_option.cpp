// --feeders FILE (see feeders_option.h).
#include "tools/feeders_option.h"

#include <optional>
#include <utility>

namespace smtcal::tools {

bool LoadFeedersOption(const std::string& path, SourceManager& sources, Diagnostics& diags, cad::FeedersFile& out,
                       GlobalOptions& options) {
  if (path.empty()) return true;
  Result<std::optional<cad::FeedersFile>> file = cad::LoadFeeders(path, sources, diags);
  if (!file) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(file.error());
    return false;
  }
  if (file.value()) out = std::move(*file.value());
  return true;
}

}  // namespace smtcal::tools

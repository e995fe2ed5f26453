// The cell a compiled program was compiled with (backend/diff/diff_cells.h).
#include "backend/diff/diff_cells.h"

#include <fmt/format.h>

namespace smtcal::diff {

std::vector<cell::CellFile> RecordedCellFiles(const ir::Program& program) {
  std::vector<cell::CellFile> files;
  for (const ir::StmtPtr& stmt : program.items) {
    const auto* comment = std::get_if<ir::Comment>(&stmt->node);
    if (comment == nullptr) break;  // the header is the leading comments
    std::string_view text = comment->text;
    if (text.starts_with(' ')) text.remove_prefix(1);
    if (std::optional<cell::CellFile> file = cell::ParseCellFileLine(text)) files.push_back(std::move(*file));
  }
  return files;
}

std::string ShortHash(const std::string& sha256) { return sha256.substr(0, 12); }

std::vector<std::string> CellFileDifferences(const std::vector<cell::CellFile>& recorded, const cell::Cell& cell) {
  // The cell file by its bytes; tables by their bytes whatever path names them.
  std::vector<std::string> differences;
  auto has = [](const std::vector<cell::CellFile>& files, const cell::CellFile& file) {
    for (const cell::CellFile& f : files) {
      if (f.table == file.table && f.sha256 == file.sha256) return true;
    }
    return false;
  };
  for (const cell::CellFile& want : recorded) {
    if (has(cell.files, want)) continue;
    differences.push_back(want.table ? fmt::format("the program was compiled with a table {} (sha256 {}...) it does not have",
                                                   want.path, ShortHash(want.sha256))
                                     : fmt::format("its cell file is not the one the program was compiled with "
                                                   "(sha256 {}..., not {}...)",
                                                   ShortHash(cell.files.empty() ? "" : cell.files.front().sha256),
                                                   ShortHash(want.sha256)));
  }
  for (const cell::CellFile& have : cell.files) {
    if (have.table && !has(recorded, have)) {
      differences.push_back(fmt::format("its table {} (sha256 {}...) is not one the program was compiled with",
                                        have.path, ShortHash(have.sha256)));
    }
  }
  return differences;
}

}  // namespace smtcal::diff

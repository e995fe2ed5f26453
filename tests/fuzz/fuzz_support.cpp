// Shared by the harnesses (fuzz_target.h).
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <system_error>

#include "frontend/cell_toml.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

namespace smtcal::fuzz {

const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    namespace fs = std::filesystem;
    fs::path made = fs::temp_directory_path() / ("smtcal_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(made);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(ScratchDir(), ignored);
    });
    for (const fs::directory_entry& entry : fs::directory_iterator(SourceDir() / "examples" / "paper-cell")) {
      if (entry.path().extension() != ".csv") continue;
      std::error_code ignored;
      fs::create_symlink(entry.path(), made / entry.path().filename(), ignored);
    }
    return made;
  }();
  return dir;
}

std::string WriteScratch(const std::string& name, std::string_view text) {
  std::string path = (ScratchDir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (!out.flush()) Fail("cannot write the scratch file");
  return path;
}

namespace {

const cell::Cell& LoadOnce(const std::filesystem::path& path) {
  static SourceManager sources;  // the cells' locations point into it
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(path.string(), sources, diags);
  if (!loaded || !loaded.value()) {
    std::fprintf(stderr, "%s", diags.RenderText().c_str());
    Fail("a cell the harnesses use did not load");
  }
  return *new cell::Cell(std::move(*loaded.value()));
}

}  // namespace

const cell::Cell& ExampleCell() {
  static const cell::Cell& cell = LoadOnce(SourceDir() / "examples/paper-cell/paper.cell.toml");
  return cell;
}

const cell::Cell& ImportCell() {
  static const cell::Cell& cell = LoadOnce(SourceDir() / "tests/golden/import-data/cell.toml");
  return cell;
}

}  // namespace smtcal::fuzz

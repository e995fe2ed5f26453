// Text files compiled into the smtcal executable (cmake/embed_files.cmake),
// so an emitter can write them next to its output without knowing where the
// source tree is.
#pragma once

#include <string>
#include <vector>

namespace smtcal {

struct EmbeddedFile {
  std::string name;  // file name, without a directory
  std::string text;  // its bytes, exactly
};

// The LinuxCNC runtime: every runtime/linuxcnc/*.ngc, sorted by name
// (runtime/linuxcnc/README.md).
const std::vector<EmbeddedFile>& LinuxCncRuntimeFiles();
// The measuring program's runtime: every runtime/linuxcnc/measure/*.ngc,
// sorted by name (`smtcal measure program`, docs/measure.md).
const std::vector<EmbeddedFile>& LinuxCncMeasureFiles();

}  // namespace smtcal

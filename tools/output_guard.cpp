// The files of one command checked against each other before anything is
// read (tools/commands.h, FilesClash): `smtcal compile x.place -o x.place`
// would replace the source with its corrected form, `-o x --report x` would
// leave one output in place of both, and `simulate - --truth -` would read
// standard input twice and silently get nothing the second time.
#include <filesystem>
#include <system_error>

#include <fmt/core.h>

#include "base/source.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

namespace fs = std::filesystem;

// An input is overwritten by an output that is the same file, or (for a
// folder output such as the LinuxCNC target's) by a folder that holds it.
bool Overwrites(const fs::path& output, const fs::path& input) {
  std::error_code error;
  if (!fs::exists(output, error) || !fs::exists(input, error)) return false;
  if (fs::equivalent(output, input, error)) return true;
  if (!fs::is_directory(output, error)) return false;
  const fs::path folder = fs::canonical(output, error);
  if (error) return false;
  for (fs::path p = fs::canonical(input, error).parent_path(); !error && !p.empty(); p = p.parent_path()) {
    if (p == folder) return true;
    if (p == p.parent_path()) break;
  }
  return false;
}

// Where an output lands, spelled one way: the file a write replaces
// (symbolic links followed, as StagedOutput does), or a folder output's own
// entry (replaced by a rename, links and all), with its folders resolved.
fs::path Landing(const NamedFile& output) {
  std::error_code error;
  const fs::path destination = output.folder ? fs::path(output.path) : fs::path(OutputDestination(output.path));
  const fs::path parent = destination.has_parent_path() ? destination.parent_path() : fs::path(".");
  fs::path resolved = fs::weakly_canonical(fs::absolute(parent, error), error);
  if (error) return fs::absolute(destination, error).lexically_normal();
  return resolved / destination.filename();
}

bool Inside(const fs::path& path, const fs::path& folder) {
  for (fs::path p = path.parent_path(); !p.empty(); p = p.parent_path()) {
    if (p == folder) return true;
    if (p == p.parent_path()) break;
  }
  return false;
}

std::string Named(const NamedFile& file) {
  return file.option.starts_with("-") ? fmt::format("{} {}", file.option, file.path) : file.option;
}

}  // namespace

bool FilesClash(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs) {
  // Standard input and standard output, each named once at most.
  for (const std::vector<NamedFile>* files : {&inputs, &outputs}) {
    const NamedFile* first = nullptr;
    for (const NamedFile& file : *files) {
      if (file.path != "-") continue;
      if (first == nullptr) {
        first = &file;
        continue;
      }
      const bool in = files == &inputs;
      const NamedFile& change = file.option.starts_with("-") || !first->option.starts_with("-") ? file : *first;
      ReportUsageError(fmt::format("standard {} ('-') is named by both {} and {}; {}, so give {} a file",
                                   in ? "input" : "output", first->option, file.option,
                                   in ? "it can be read only once" : "two outputs on it would be mixed",
                                   change.option));
      return true;
    }
  }
  // Two outputs on one file, or one inside the other's folder.
  for (std::size_t j = 0; j < outputs.size(); ++j) {
    if (outputs[j].path.empty() || outputs[j].path == "-") continue;
    const fs::path b = Landing(outputs[j]);
    for (std::size_t i = 0; i < j; ++i) {
      if (outputs[i].path.empty() || outputs[i].path == "-") continue;
      const fs::path a = Landing(outputs[i]);
      if (a == b) {
        ReportUsageError(fmt::format("{} and {} name the same file; each output needs a file of its own",
                                     Named(outputs[i]), Named(outputs[j])));
        return true;
      }
      const NamedFile* inside = outputs[i].folder && Inside(b, a)   ? &outputs[j]
                                : outputs[j].folder && Inside(a, b) ? &outputs[i]
                                                                    : nullptr;
      if (inside != nullptr) {
        ReportUsageError(fmt::format("{} is inside the folder {}, which is replaced as a whole; write it elsewhere",
                                     Named(*inside), Named(inside == &outputs[j] ? outputs[i] : outputs[j])));
        return true;
      }
    }
  }
  // An output onto an input.
  for (const NamedFile& output : outputs) {
    if (output.path.empty() || output.path == "-") continue;
    for (const NamedFile& input : inputs) {
      if (input.path.empty() || input.path == "-" || !Overwrites(output.path, input.path)) continue;
      ReportUsageError(fmt::format("{} {} would overwrite the input {}; write the output elsewhere", output.option,
                                   output.path, input.path));
      return true;
    }
  }
  return false;
}

}  // namespace smtcal::tools

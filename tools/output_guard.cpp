// Refusing an output that would overwrite one of the command's own inputs
// (tools/commands.h): `smtcal compile x.place -o x.place` would replace the
// source with its corrected form, which compiled again corrects twice.
#include <filesystem>
#include <system_error>

#include <fmt/core.h>

#include "tools/commands.h"

namespace smtcal::tools {
namespace {

// The same file, or (for a folder output such as the LinuxCNC target's) a
// folder that holds the input.
bool Overwrites(const std::filesystem::path& output, const std::filesystem::path& input) {
  std::error_code error;
  if (!std::filesystem::exists(output, error) || !std::filesystem::exists(input, error)) return false;
  if (std::filesystem::equivalent(output, input, error)) return true;
  if (!std::filesystem::is_directory(output, error)) return false;
  const std::filesystem::path folder = std::filesystem::canonical(output, error);
  if (error) return false;
  for (std::filesystem::path p = std::filesystem::canonical(input, error).parent_path(); !error && !p.empty();
       p = p.parent_path()) {
    if (p == folder) return true;
    if (p == p.parent_path()) break;
  }
  return false;
}

}  // namespace

bool OutputOverwritesInput(std::string_view option, const std::string& output,
                           const std::vector<std::string>& inputs) {
  if (output.empty() || output == "-") return false;
  for (const std::string& input : inputs) {
    if (input.empty() || input == "-" || !Overwrites(output, input)) continue;
    fmt::print(stderr, "smtcal: error: {} {} would overwrite the input {}; write the output elsewhere\n", option,
               output, input);
    return true;
  }
  return false;
}

}  // namespace smtcal::tools

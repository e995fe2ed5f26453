// smtcal_fuzz_replay HARNESS PATH...: runs a harness (fuzz_target.h) once on
// each file, and on every file of each folder, like a libFuzzer binary given
// a corpus. The test suite runs it over tests/fuzz/corpus/<harness>/ and
// tests/fuzz/regressions/<harness>/.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "tests/fuzz/fuzz_target.h"

namespace smtcal::fuzz {

std::map<std::string, FuzzFunction>& Harnesses() {
  static std::map<std::string, FuzzFunction> harnesses;
  return harnesses;
}

bool Register(const char* name, FuzzFunction function) {
  Harnesses()[name] = function;
  return true;
}

}  // namespace smtcal::fuzz

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  using smtcal::fuzz::Harnesses;
  if (argc < 2 || !Harnesses().contains(argv[1])) {
    std::fprintf(stderr, "usage: smtcal_fuzz_replay HARNESS PATH...\nharnesses:");
    for (const auto& [name, function] : Harnesses()) std::fprintf(stderr, " %s", name.c_str());
    std::fprintf(stderr, "\n");
    return 2;
  }
  std::vector<fs::path> files;
  for (int i = 2; i < argc; ++i) {
    if (fs::is_directory(argv[i])) {
      for (const fs::directory_entry& entry : fs::directory_iterator(argv[i])) {
        if (entry.is_regular_file()) files.push_back(entry.path());
      }
    } else {
      files.push_back(argv[i]);
    }
  }
  std::sort(files.begin(), files.end());
  smtcal::fuzz::FuzzFunction harness = Harnesses()[argv[1]];
  for (const fs::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "%s: %s (%zu bytes)\n", argv[1], file.c_str(), bytes.size());
    harness(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::fprintf(stderr, "%s: %zu inputs, no finding\n", argv[1], files.size());
  return 0;
}

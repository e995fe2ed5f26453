// One fuzz harness per reader or stage a user's file reaches (README.md in
// this folder). A harness is written once with SMTCAL_FUZZ_TARGET(name) and
// builds two ways:
// - with SMTCAL_LIBFUZZER (the clang sanitizer build, libFuzzer): it is
//   LLVMFuzzerTestOneInput of its own executable, smtcal_fuzz_<name>;
// - otherwise it registers itself in smtcal_fuzz_replay, which the test
//   suite runs over the seed corpus and every regression input, so each
//   finding stays fixed in the ordinary and the sanitizer builds.
// A harness aborts (a finding) on anything smtcal must never do: an escaping
// exception, an internal check (which aborts here instead of exit 3), a
// sanitizer report, or a broken property it states itself (fmt's round trip).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "base/check.h"

namespace smtcal::fuzz {

// A failed SMTCAL_CHECK ends smtcal with exit 3 (base/check.h); in a harness
// it must be a crash that libFuzzer and the replay report as a finding, so
// every harness asks for the abort before it runs.
inline const bool kAbortOnInternalError = [] {
  ::setenv(kAbortOnInternalErrorVariable, "1", 1);
  return true;
}();

using FuzzFunction = int (*)(const std::uint8_t* data, std::size_t size);

// Registers a harness with the replay driver (replay_main.cpp).
bool Register(const char* name, FuzzFunction function);

inline std::string_view AsText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A property of smtcal failed: a finding.
[[noreturn]] inline void Fail(const char* what) {
  std::fprintf(stderr, "smtcal fuzz: property failed: %s\n", what);
  std::abort();
}

// The source tree (examples/, tests/golden/), for the cells the harnesses use.
inline std::filesystem::path SourceDir() { return SMTCAL_SOURCE_DIR; }

// A private scratch folder for inputs that smtcal reads by path (cell,
// feeders and truth files), holding symbolic links to the example cell's
// tables so a fuzzed cell file can name them.
const std::filesystem::path& ScratchDir();
// Writes `text` to ScratchDir()/name and returns the path.
std::string WriteScratch(const std::string& name, std::string_view text);

}  // namespace smtcal::fuzz

#ifdef SMTCAL_LIBFUZZER
#define SMTCAL_FUZZ_TARGET(name) extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
#else
#define SMTCAL_FUZZ_TARGET(name)                                                               \
  static int name##_fuzz(const std::uint8_t* data, std::size_t size);                           \
  [[maybe_unused]] static const bool name##_registered = smtcal::fuzz::Register(#name, name##_fuzz); \
  static int name##_fuzz(const std::uint8_t* data, std::size_t size)
#endif

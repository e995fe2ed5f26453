// Checks the symbols of a compiled C object of smtcal's runtimes (`nm -P`
// output): the runtimes call only what `allowed` names and keep no writable
// globals (runtime/c/README.md).
#pragma once

#include <set>
#include <sstream>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

namespace smtcal::test {

// Expects every undefined symbol in `allowed` and no writable global
// (data, bss or common) in `nm_output`; `what` names the object in the
// failures ("the runtime"). Returns the number of functions it defines.
inline int ExpectOnlyAllowedCallsAndNoWritableGlobals(const std::string& nm_output,
                                                       const std::set<std::string>& allowed, std::string_view what) {
  std::istringstream lines(nm_output);
  std::string line;
  int defined_functions = 0;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string name, type;
    fields >> name >> type;
    if (type == "U") {
      EXPECT_TRUE(allowed.count(name)) << what << " calls " << name;
    }
    EXPECT_TRUE(type != "D" && type != "d" && type != "B" && type != "b" && type != "C")
        << "writable global " << name << " (" << type << ") in " << what;
    if (type == "T") ++defined_functions;
  }
  return defined_functions;
}

}  // namespace smtcal::test

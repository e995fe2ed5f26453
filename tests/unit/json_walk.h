// Walking a parsed JSON output in tests: every floating-point number with
// the name of the member it is in (arrays pass their member's name down).
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

namespace smtcal::test {

inline void ForEachNumber(const nlohmann::json& json, const std::string& key,
                          const std::function<void(const std::string&, const nlohmann::json&)>& check) {
  if (json.is_object()) {
    for (const auto& [k, v] : json.items()) ForEachNumber(v, k, check);
  } else if (json.is_array()) {
    for (const nlohmann::json& v : json) ForEachNumber(v, key, check);
  } else if (json.is_number_float()) {
    check(key, json);
  }
}

}  // namespace smtcal::test

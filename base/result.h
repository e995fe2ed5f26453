// I/O and configuration failures travel as a [[nodiscard]] Result: either a
// value or an Error with a message for the user. Mistakes *inside* an input
// file are Diagnostics, not Errors.
#pragma once

#include <string>
#include <utility>
#include <variant>

#include "base/check.h"

namespace smtcal {

struct Error {
  std::string message;
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::move(value)) {}
  Result(Error error) : state_(std::move(error)) {}

  bool ok() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return ok(); }

  T& value() & {
    SMTCAL_CHECK(ok(), "value() on a failed Result");
    return std::get<T>(state_);
  }
  const T& value() const& {
    SMTCAL_CHECK(ok(), "value() on a failed Result");
    return std::get<T>(state_);
  }
  T&& value() && {
    SMTCAL_CHECK(ok(), "value() on a failed Result");
    return std::get<T>(std::move(state_));
  }
  const Error& error() const {
    SMTCAL_CHECK(!ok(), "error() on a successful Result");
    return std::get<Error>(state_);
  }

 private:
  std::variant<T, Error> state_;
};

// For operations that produce nothing but can fail.
struct Ok {};
using Status = Result<Ok>;

}  // namespace smtcal

// SHA-256 (FIPS 180-4) of a byte string, as `sha256sum` prints it: what a
// compiled program says of the cell and table files it was compiled with,
// so `smtcal diff` can tell whether a cell is the one (docs/diff.md). A
// page of code instead of a dependency: none of the libraries smtcal uses
// has it.
#pragma once

#include <string>
#include <string_view>

namespace smtcal {

// 64 lowercase hexadecimal digits.
std::string Sha256Hex(std::string_view bytes);

}  // namespace smtcal

// Trip files of a marker scan (`smtcal fixture --trips`): one row per trip
// the sensor made, in the robot base frame as commanded when it tripped.
//
//   name,x_mm,y_mm,z_mm
//   T1,138.1174,42.9500,-2
//
// The CSV dialect is the error tables' (frontend/table_csv.h: comments,
// quoting, spaces, BOM, CRLF); the header is required, its columns in any
// order, z_mm optional. Names are T1..Tn for the n trips the fixture's scan
// paths make (case-insensitive), each at most once, rows in any order. A
// trip that is not in the file is a trip the sensor did not make: the scan's
// missing_trip check reports it, not the reader. A header without rows is a
// scan in which no trip was recorded (every trip missing); a file without
// even the header is refused.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"

namespace smtcal {

struct TripRow {
  std::size_t index = 0;  // 0-based: T1 is 0
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  std::optional<double> z_mm;  // when the file has a z_mm column
  SourceRange name_range;  // the name field
  SourceRange range;       // the row, from its first to its last field
};

// Reads the trips of a fixture whose scan paths make `expected_trips` trips.
// Every mistake is a diagnostic at its row and field (the reader goes on to
// report them all); nullopt when any was an error.
std::optional<std::vector<TripRow>> ReadTrips(std::uint32_t file, std::size_t expected_trips,
                                              std::string_view fixture, Diagnostics& diags);

}  // namespace smtcal

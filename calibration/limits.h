// Limits of the robot controller that a .place program must respect. These are
// hard bounds of the language and the controller (SPEL+ conventions), checked
// by passes/checks/check_ranges.cpp; measurement tolerances live in tolerances.h.
#pragma once

namespace smtcal::limits {

// I/O bits addressed by On/Off/Sw/Wait Sw: the controller's standard and
// expansion I/O, numbered from 0.
inline constexpr int kIoBitMin = 0;
inline constexpr int kIoBitMax = 511;

// Vacuum outputs (Vacuum n, Pick/Place ... Vacuum n) are ordinary output bits.
inline constexpr int kVacuumOutputMin = kIoBitMin;
inline constexpr int kVacuumOutputMax = kIoBitMax;

// SPEL+ pallets are numbered 0..15.
inline constexpr int kPalletNumberMin = 0;
inline constexpr int kPalletNumberMax = 15;

// A pallet has at least one column and one row; pallet indices are 1-based.
inline constexpr int kPalletMinColumns = 1;
inline constexpr int kPalletMinRows = 1;
inline constexpr int kPalletFirstIndex = 1;

// The rotation u of a point, in degrees: within one turn either way.
inline constexpr double kMaxAbsAngleDeg = 360.0;

}  // namespace smtcal::limits

// Tolerances and safety margins: one named constant per quantity, the unit in
// the name (Mm = millimetres; plain numbers are dimensionless). Each area keeps
// its constants in its own section with a comment on why the value is what it
// is. Limits of the language and the controller live in limits.h instead.
#pragma once

#include <cstddef>

namespace smtcal {

// --- error tables and inverse calibration ------------------------------------
// (passes/error_table*.cpp, calibration/inverse_calibration.cpp; docs/error-tables.md)

// The residual |F(n) - a| that the default inverse solver reaches for every
// point inside a valid table (DESIGN.md, "Numbers"). The iteration bound of a
// table is derived for half of it, which leaves room for rounding.
inline constexpr double kInverseResidualTolMm = 1e-9;
// Within that bound the solver keeps going while the residual is above this:
// machine precision for millimetre coordinates of a robot cell (the rounding
// of n + Delta(n) - a is a few ulp of ~1000 mm, about 1e-13 mm). It also stops
// when a step no longer makes progress, so larger coordinates are fine.
inline constexpr double kInversePolishMm = 1e-12;

// The paper's solver stops when the direct-calibrated interval means are this
// close to the required point: the task tolerance of the basic assembly
// operation, here a hundredth of the paper's +-0.1 mm placing tolerance.
inline constexpr double kPaperSolverTolMm = 0.001;
// ... or after this many interval steps, whichever comes first.
inline constexpr int kPaperSolverMaxSteps = 60;

// A table must not fold: det(I + grad(Delta)) stays at or above this in every
// cell. A real robot's error changes by micrometres per millimetre (det near
// 1); anything near 0 is a sign or unit blunder in the measurements.
inline constexpr double kMinJacobianDet = 0.5;
// ... and the error must change slowly: the contraction factor
// L = max |grad(Delta)|_inf stays at or below this. L < 1 is what makes the
// fixed-point step of the inverse solver contract (and the iteration bound
// finite); 0.5 keeps that bound small and is still 100x a real robot's slope.
// The solver's early stop also needs it below 1/sqrt(2) (static_assert there).
inline constexpr double kMaxErrorSlope = 0.5;

// Grid lines of one axis table closer than this are the same line written two
// ways (a rounding difference between measurement sessions), not a grid.
inline constexpr double kMinGridLineSpacingMm = 0.01;

// The largest |length| a table, raw or point file may hold (coordinates,
// errors, stddevs): 100 m, far beyond any robot cell, so a larger value is a
// unit mistake. Within it double arithmetic keeps the inverse residual far
// below kInverseResidualTolMm (an ulp of 2e5 mm is 3e-11 mm) and the fold
// check's slopes finite (at most 2e5 mm over kMinGridLineSpacingMm).
inline constexpr double kMaxLengthMm = 1e5;

// A point this close outside the table's rectangle still counts as inside, so
// a solution that lands on the edge up to rounding is not called "outside".
inline constexpr double kTableEdgeTolMm = 1e-9;

// The paper's condition for linear interpolation is checked as a warning: an
// error larger than this fraction of the grid pitch around its node is more
// likely micrometres written as millimetres than a real robot error.
inline constexpr double kMaxErrorPitchFraction = 0.5;

// `table build` flags a node whose repetition scatter (pooled stddev) is above
// median + kNoisyNodeMadFactor * 1.4826 * MAD of its axis's nodes (a robust
// 5-sigma) and at least kNoisyNodeFloorMm (the transducers' resolution) above
// the median, so a table of perfectly repeatable nodes does not flag noise;
// and above the chi-square bound (at the same 5 sigma) of its own number of
// readings against its axis's pooled scatter, so a node of two readings one
// device step apart is not flagged where most nodes show no scatter at all.
inline constexpr double kNoisyNodeMadFactor = 5.0;
inline constexpr double kNoisyNodeFloorMm = 0.001;
// ... and a node whose set means differ by more than kSetShiftFactor standard
// errors of that difference (from the repetition scatter) and by more than
// kSetShiftFloorMm: the robot or the fixture moved between the sets.
inline constexpr double kSetShiftFactor = 6.0;
inline constexpr double kSetShiftFloorMm = 0.001;
// Screening the readings before they are averaged (calibration/reading_screen.h):
// a reading farther from its set's median than this many robust scatters
// (and kOutlierFloorMm) is an outlier; a set needs this many readings to
// have a centre of its own. With the paper's 2.5 µm repetition scatter the
// limit is 25 µm: ten times the largest deviation 2420 normal readings give.
inline constexpr double kReadingOutlierFactor = 10.0;
inline constexpr std::size_t kScreenMinSetSize = 3;
// Of two sets a decimal point apart, the one farther from what the
// neighbouring nodes predict is the culprit when the other is at least this
// many times nearer; otherwise the node cannot tell.
inline constexpr double kSetSlipDecisiveRatio = 3.0;

// --- the cell file -------------------------------------------------------------
// (frontend/cell_toml.cpp; docs/cell.md)

// The marker edge lines of a fixture must cross at S1 = (0,0), S2 = (L1,0) and
// S3 = (0,L2) within this. Edges and L1/L2 come from one drawing of the board,
// so any larger miss is a typo or a wrong L1/L2, not a measurement error.
inline constexpr double kMarkerGeometryTolMm = 1e-6;

// The robot's final approach (robot.final_approach_mm) takes up backlash,
// which is micrometres to a tenth of a millimetre: a longer approach is a
// typo (or a unit mistake), and costs time at every target.
inline constexpr double kMaxFinalApproachMm = 10;

// --- CAD import ----------------------------------------------------------------
// (frontend/cad_*.cpp, frontend/cad/cad_to_program.cpp; docs/import.md)

// Lengths read from a placement list, and the board origins of a panel, are
// rounded to a nanometre: KiCad's own internal unit, far below any placing
// tolerance, so nothing real is lost, and a converted value prints as the
// short decimal it is (175 mil = 4.445 mm, not 4.4450000000000003).
inline constexpr double kCadResolutionMm = 1e-6;
// Rotations after the side and offset conventions, likewise (a micro-degree).
inline constexpr double kCadResolutionDeg = 1e-6;
// The feeder set-up sheet of a program (backend/reports/setup_sheet.cpp)
// finds a Pick's feeder by its pick point: the program's point (its pallet
// corners interpolated) and the cell's are the same numbers, apart from the
// arithmetic's rounding, when they describe the same lane. A pick farther
// than this from every pick point of the cell is at no feeder the cell knows
// and is reported; lanes are millimetres apart.
inline constexpr double kFeederPickMatchMm = 0.01;

// --- periphery calibration ---------------------------------------------------
// (calibration/fixture_estimation.cpp; the C runtime runtime/c/ repeats these values
// as SMTCAL_* macros and a test keeps them equal; docs/periphery.md)

// Two trips of one edge closer than this define no line: the sensor's own
// accuracy is +-0.05 mm, so trips 0.01 mm apart are one trip seen twice.
inline constexpr double kMinTripSeparationMm = 0.01;
// Two fitted lines that cross at an angle whose sine is below this (about
// 5.7 degrees) have no usable crossing: an error e across either line moves
// the crossing by e / sin, ten times e here. Marker edges cross at 90 degrees.
inline constexpr double kMinLineCrossingSin = 0.1;
// A 2 x 2 least-squares system whose determinant is below this fraction of
// its squared trace is singular (the edges do not fix the pose): relative
// conditioning worse than 1e12, where double arithmetic has no digits left
// for a pose.
inline constexpr double kMinRelativeDeterminant = 1e-12;
// The rigid estimator's Newton steps on the rotation stop below this step
// (radians: it moves a point 1 m away by 1e-12 mm) or after
// kRigidMaxIterations (from the similarity solution, 3 to 5 steps suffice).
inline constexpr double kRigidStepTolRad = 1e-15;
inline constexpr int kRigidMaxIterations = 20;
// The error budget (calibration/placement_budget.h) differentiates the
// estimator by central differences with this trip displacement: small against
// the 0.05 mm accuracy it scales, large against rounding (relative error
// about 1e-8).
inline constexpr double kTripSensitivityStepMm = 1e-4;

// --- smtcal diff (backend/diff/program_diff.cpp, docs/diff.md) --------------------

// Two positions closer than this are the same position: compiled programs
// print coordinates to 1e-10 mm, so re-printing alone never moves a target
// by a nanometre, and a real change in a table is thousands of times larger.
inline constexpr double kDiffSamePositionMm = 1e-6;
inline constexpr double kDiffSameAngleDeg = 1e-6;
// The deployment gate's default: a target that moved by more than this (µm)
// fails `smtcal diff`. A tenth of the paper cell's +-0.1 mm tolerance.
inline constexpr double kDiffDefaultThresholdUm = 10;
// Statement alignment: the exact dynamic programme runs on at most this many
// cells (about 32 MB); larger differing middles use Myers' O(ND) alignment,
// which gives up beyond kDiffMaxEditDistance edits in one function.
inline constexpr double kDiffMaxAlignCells = 4e6;
inline constexpr long kDiffMaxEditDistance = 2000;
// The board poses the diff evaluates a fixture target at (calibration/
// machine_model.h) lie this fraction of the way to the fixture's check
// limits (max_shift_mm, max_rotation_deg): at the limits themselves a
// runtime whose estimate differs from the board's true pose by micrometres
// (a re-measured marker table) would refuse the scan on one side only.
inline constexpr double kDiffPoseLimitFraction = 0.99;

// A table's error "changes sign between neighbouring nodes" (the paper's
// condition for linear interpolation, warned by table check) only where both
// nodes are farther from zero than this (and three standard errors): values
// closer to zero are noise around a zero crossing the grid resolves.
inline constexpr double kSignChangeMinMm = 0.005;

// An error table's outliers (calibration/table_outliers.h): a node whose
// value differs from what its neighbours predict by more than this many times
// the table's robust scatter of such differences, this many times its own
// standard error, and this floor. The robust scatter of the example tables is
// under 1 µm; a slipped digit in a 0.05 mm error moves it by 0.45 mm.
inline constexpr double kOutlierScatterFactor = 10;
inline constexpr double kOutlierNoiseFactor = 6;
inline constexpr double kOutlierFloorMm = 0.005;
// A node's standard error excuses its disagreement only up to this many times
// its axis's median standard error: a node whose own measurements scatter
// farther than that holds a bad measurement, and is the one to blame.
inline constexpr double kOutlierNoiseCapFactor = 10;

}  // namespace smtcal

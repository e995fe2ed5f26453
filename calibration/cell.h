// The cell: what smtcal knows about the robot cell a program runs in, as
// loaded from a `*.cell.toml` file by frontend/cell_toml.h (docs/cell.md documents every key with the paper
// cell's example). Units as in the file: mm, degrees, seconds; the loader
// converts nothing except that every `*_deg` value is kept in degrees here
// too (the math converts where it uses them).
//
// Every part keeps the SourceRange of the TOML key or table it came from, so
// a pass that finds something wrong with the cell points into the cell file.
//
// Loading (frontend/cell_toml.cpp) reports every mistake it finds (unknown
// key, wrong type, missing key, value out of range, a table file that is
// missing or invalid, marker geometry that contradicts L1/L2, overlapping
// regions ...) as a diagnostic located in the TOML file, and returns nullopt
// when any was an error. A loaded Cell therefore satisfies every check listed
// in docs/cell.md ("What the loader checks").
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/source.h"
#include "calibration/error_table.h"
#include "calibration/interpolation_error.h"
#include "calibration/inverse_calibration.h"

namespace smtcal::cell {

// [lo, hi] with lo < hi, in the key's unit.
struct Interval {
  double lo = 0;
  double hi = 0;
  bool Contains(double v) const { return v >= lo && v <= hi; }
};

// A 2-D point given as [x, y] in the file (mm).
using Point2 = Eigen::Vector2d;

// [robot]
struct Robot {
  std::string model;                      // free text, for reports
  std::array<Interval, 4> limits;         // x_mm, y_mm, z_mm, u_deg: reachable commanded positions
  std::array<SourceRange, 4> limit_keys;  // where each limit is written (its key)
  double repeatability_mm = 0;            // +- band of repeated moves to one point
  double safe_limz_mm = 0;                // z a Jump rises to when it has no LimZ
  // Motion model for cycle-time estimates: each axis moves with a trapezoidal
  // profile (accelerate, cruise, decelerate); x and y move together, the
  // slower of the two decides.
  double xy_speed_mm_s = 0;
  double xy_accel_mm_s2 = 0;
  double z_speed_mm_s = 0;
  double z_accel_mm_s2 = 0;
  double u_speed_deg_s = 0;
  double u_accel_deg_s2 = 0;
  double pick_time_s = 0;   // vacuum on and settle at a pick
  double place_time_s = 0;  // vacuum off and release at a place
  // The robot's accuracy where no table corrects it: the largest position
  // error it makes there (the paper: about 0.25 mm once the gripper was
  // mounted). Unset: not declared, and nothing that depends on it can be
  // bounded (verify says so).
  std::optional<double> uncalibrated_accuracy_mm;
  SourceRange uncalibrated_accuracy_range;  // its key (the [robot] table when absent)
  // How far the error changes by about its own size: next to a table the
  // error stays near the table's edge value for about this distance (how far
  // a table may be trusted beyond its edge). Shapes the virtual cell's field.
  double uncalibrated_correlation_mm = 25;
  // The controller latches the marker sensor once per servo period, so a
  // trip lands up to scan_speed_mm_s * servo_period_s past the edge along
  // its leg (LinuxCNC's servo thread: 1 ms).
  double servo_period_s = 0.001;
  SourceRange servo_period_range;  // its key (the [robot] table when absent)
  // What a probe move costs the controller besides the move itself: it
  // plans the next move only once the probe's result is in (LinuxCNC 2.9
  // without a realtime kernel, [TASK]CYCLE_TIME 0.001: 0.025 s measured,
  // each task cycle about a third of it). Feeds the scan's time.
  double probe_turnaround_s = 0.025;

  // The final approach: every calibrated target is reached by a last straight
  // x-y move of this vector, from target - approach to the target, so each
  // axis's backlash is taken up the same way at every target as at every
  // node of the measurement (docs/measure.md, "Backlash"). Unset: targets are
  // reached straight, and `smtcal measure plan` asks for it.
  std::optional<Eigen::Vector2d> final_approach_mm;
  SourceRange final_approach_range;  // its key (the [robot] table when absent)
  SourceRange range;        // the [robot] table
};

// What the robot declares about the roughness of its error
// (uncalibrated_accuracy_mm over uncalibrated_correlation_mm); nullopt when
// it declares no accuracy.
std::optional<DeclaredRoughness> DeclaredRoughnessOf(const Robot& robot);
// The interpolation error of a region's table in this robot's cell: with the
// robot's declared roughness, and a node that states no noise counted as one
// measurement with the robot's repeatability (as the budget does).
InterpolationEstimate RegionInterpolation(const Robot& robot, const ErrorTable& table);

// The axes a region's difficulty measure names.
enum class TaskAxis { X, Y, Z, U };

// [[region]]: a calibrated region of the work space.
struct Region {
  std::string name;
  SourceRange name_range;
  // Bounds in the robot base frame, on required (actual) positions: a target
  // belongs to the region when its required x, y lie within them. Default:
  // the table's domain. Always inside the domain.
  Interval x_mm, y_mm;
  // The x_mm key (else the y_mm key, else the table key when both bounds
  // default to the table's domain).
  SourceRange bounds_range;
  // Difficulty measure D = (L_D, {axes}); the paper's regions: (2, {x, y}).
  // The loader accepts any of x, y, z, u (level = number of distinct axes);
  // the compiler's regions pass refuses a region it cannot serve.
  int difficulty_level = 0;
  std::vector<TaskAxis> difficulty_axes;  // as written, no duplicates
  SourceRange difficulty_range;
  std::string table_path;  // as written, relative to the cell file
  SourceRange table_range;
  // Loaded and validated (ValidateErrorTable passed). Only a cell loaded for
  // planning a measurement (CellLoadOptions) may have a region without a
  // table yet: then has_table is false, the table and domain are empty, and
  // the bounds are as written.
  bool has_table = true;
  std::uint32_t table_file = 0;  // the table file's SourceManager id (0: not read from a file)
  ErrorTable table;
  Rect domain;             // TableDomain(table): where F is defined
  // How far the robot's error may depart from the table's interpolation
  // between its nodes: RegionInterpolation(robot, table), set by the loader.
  InterpolationEstimate interpolation;
  double tolerance_mm = 0;  // the task tolerance: +- this around the required position
  SourceRange tolerance_range;
  OutsidePolicy outside = OutsidePolicy::kError;  // policy for points outside the grid
  SourceRange outside_range;  // the outside key (the [[region]] table when defaulted)
  SourceRange range;  // the [[region]] table

  bool Contains(const Point2& p) const { return x_mm.Contains(p.x()) && y_mm.Contains(p.y()); }
};

// A straight marker edge, as the segment of it the sensor can see, in fixture
// coordinates. The edge's line (p1..p4 in the paper) is its infinite extension.
struct MarkerEdge {
  std::string name;  // p1, p2, p3, p4
  Point2 from = Point2::Zero();
  Point2 to = Point2::Zero();
  SourceRange range;  // the edge's key in [fixture.edges]
};

// A V-shaped scan path in fixture coordinates: a polyline the sensor moves
// along at the scan height; where a leg crosses a marker edge the sensor trips.
// The trips are numbered T1, T2, ... in the order the paths meet them (first
// path first); ExpectedTrips() in calibration/fixture_geometry.h lists them.
struct ScanPath {
  std::string name;
  std::vector<Point2> points;  // at least 2, consecutive points distinct
  std::vector<SourceRange> point_ranges;  // one per point: its [x, y]
  SourceRange range;           // the [[fixture.scan_path]] table
};

enum class Estimator { kPaper, kRigid, kRigidScale };

// predicted_window_mm without the key, in sensor accuracies: the two scans'
// trips are each within the sensor's accuracy of their edges (2), the rest
// is for the board's change between cycles (4).
inline constexpr double kDefaultPredictedWindowAccuracies = 6;

// [[fixture]]
struct Fixture {
  std::string name;  // bound to the program's `Fixture NAME` (case-insensitive)
  SourceRange name_range;
  // Nominal pose of the fixture frame in the robot base frame: origin S1 and
  // the angle of its x axis (n) against the base x axis.
  Point2 origin_mm = Point2::Zero();
  double angle_deg = 0;
  SourceRange pose_range;  // the origin_mm key
  double l1_mm = 0;  // |S2 - S1|, measured when the board was made
  double l2_mm = 0;  // |S3 - S1|
  // The four marker edges: S1 = p1 x p2, S2 = p1 x p3, S3 = p2 x p4 (see
  // docs/cell.md for the paper cell's layout), in that order. The loader has
  // checked that the lines cross at (0,0), (L1,0) and (0,L2) within
  // kMarkerGeometryTolMm.
  std::array<MarkerEdge, 4> edges;
  std::vector<ScanPath> scan_paths;  // at least one; every edge crossed at least twice
  double scan_z_mm = 0;          // sensor height over the markers (robot z)
  double scan_speed_mm_s = 0;    // feed along the scan paths (two stages: the search's)
  SourceRange scan_speed_range;  // its key
  // Two-stage probing: each edge is found at scan_speed_mm_s, crossed back
  // and latched again at this feed. 0 (the key absent): one stage, every trip
  // latched at scan_speed_mm_s. Never above scan_speed_mm_s.
  double latch_speed_mm_s = 0;
  SourceRange latch_speed_range;  // its key (the [[fixture]] table when absent)
  // The feed at which the controller latches a trip: latch_speed_mm_s with
  // two stages, else scan_speed_mm_s. A trip lands up to this times the
  // servo period past its edge.
  double TripLatchSpeedMmS() const { return latch_speed_mm_s > 0 ? latch_speed_mm_s : scan_speed_mm_s; }
  // Predicted search (docs/periphery.md, "Searches predicted from the last
  // scan"): every scan after a fixture's first latches each trip within this
  // distance either side of where the last scan's FIX puts it, and searches
  // the path in full when a trip is not there. 0 (the key absent): every
  // scan searches in full. A time, not a limit: it refuses no board. The
  // loader's default is kDefaultPredictedWindowAccuracies x sensor_accuracy_mm.
  double predicted_window_mm = 0;
  double trip_window_mm = 0;     // a trip is expected within this distance of its nominal point along the leg
  int sensor_input = 0;          // digital input the sensor is wired to
  double sensor_accuracy_mm = 0; // +- where the sensor trips against the true edge
  Estimator estimator = Estimator::kPaper;
  // Check limits (all > 0).
  double max_shift_mm = 0;        // |p_n - p_{n-1}| per cycle, and |p - nominal| at any cycle
  double max_rotation_deg = 0;    // |angle_n - angle_{n-1}| per cycle, and against nominal
  double length_tolerance_mm = 0; // | |S2-S1| - L1 | and | |S3-S1| - L2 |
  double squareness_deg = 0;      // | angle(S2-S1, S3-S1) - 90 deg |
  double max_line_residual_mm = 0;  // largest distance of a trip from its fitted line
  // The teach-time scan that gives FIX_0 for taught points: trips T1..Tn in
  // robot base coordinates as commanded when the sensor tripped. Empty when the
  // cell has none (then a taught point on this fixture is an error). When
  // given, there is one per nominal trip, each within trip_window_mm of where
  // the nominal pose puts its nominal trip.
  std::vector<Point2> teach_trips_mm;
  std::vector<SourceRange> teach_trip_ranges;  // one per trip: its [x, y]
  SourceRange teach_range;  // the teach_trips_mm key (the [[fixture]] table when absent)
  // The robot z at which a part is released on a board on this fixture (the
  // board's top): the z of every placement `smtcal import` writes. Absent:
  // import asks for --place-z instead of guessing.
  std::optional<double> place_z_mm;
  SourceRange place_z_range;  // the place_z_mm key
  // The pocket boards sit in (pocket_x_mm, pocket_y_mm: x and y intervals in
  // the fixture frame): `smtcal import` puts a board's outline, turned over
  // for its bottom side, into the pocket's lower left corner, so the top and
  // the bottom of one board are placed where the board really lies. Absent:
  // import centres the board on a calibrated region instead.
  std::optional<std::array<Interval, 2>> pocket_mm;
  SourceRange pocket_range;  // the pocket_x_mm key
  SourceRange range;  // the [[fixture]] table
};

// What a feeder holds, for CAD import: a tape gives every part of one kind
// from the same pick point (a pallet of tapes is a bank of lanes, one kind
// of part each); a tray holds one part per pocket, taken in order.
enum class FeederKind { kTape, kTray };
inline constexpr std::array<std::string_view, 2> kFeederKindNames = {"tape", "tray"};

// [[feeder]]: a named pick point in the robot base frame, optionally a pallet
// of pick points (columns along from -> last, rows along from -> back).
struct Feeder {
  std::string name;
  SourceRange name_range;
  std::array<double, 4> pick{};  // x, y, z mm, u deg
  std::optional<std::array<double, 4>> pallet_last;  // the last column of the first row
  std::optional<std::array<double, 4>> pallet_back;  // the first column of the last row
  int columns = 1;
  int rows = 1;
  // Which parts it holds, for CAD import: package and/or value; empty = any.
  // `package` may be written as an array of names (a bank of mixed lanes):
  // `packages` holds them all and `package` the first one, so a feeder with
  // one package has package == packages[0]. Match against `packages`.
  std::string package;
  std::vector<std::string> packages;
  std::string value;
  // `kind`; without the key: a tape, except a pallet whose pick points do
  // not each have a package of their own, which is a tray.
  FeederKind kind = FeederKind::kTape;
  SourceRange kind_range;  // the kind key (the [[feeder]] table when absent)
  SourceRange range;  // the [[feeder]] table

  int pick_points() const { return columns * rows; }  // 1 without a pallet
  // Pick point k (1-based, PalletPickPoint's order).
  std::array<double, 4> PickPoint(int k) const;
};

// The cycle record's bound per file ([linuxcnc] record_max_cycles, its
// range limits::kRecordMaxCycles): a week of the paper cell's cycles.
inline constexpr int kDefaultRecordMaxCycles = 10000;
// Pick point k (1 .. columns * rows) of a pallet, in the order of the
// language's Pallet(n, k): along the first row from `first` to `last`, then
// row after row toward `back` (the first column of the last row; `first`
// when absent). Without `last` (one pick point) it is `first`. The cell's
// feeders, the feeders file's and the picture of the cell all use it.
std::array<double, 4> PalletPickPoint(const std::array<double, 4>& first,
                                      const std::optional<std::array<double, 4>>& last,
                                      const std::optional<std::array<double, 4>>& back, int columns, int rows,
                                      int k);

// [linuxcnc]: how the cell's LinuxCNC controller is wired, for
// `smtcal compile --target linuxcnc` (docs/linuxcnc.md). Optional: only that
// target needs it (and reports its absence).
struct LinuxCnc {
  char rotation_axis = 'C';      // the axis word u is commanded on: A, B or C
  int vacuum_sensor_input = 0;   // motion.digital-in-NN the gripper's vacuum sensor is wired to
  double vacuum_timeout_s = 0;   // how long a Pick/Place waits for the sensor before aborting (> 0)
  // The cycle record (docs/monitor.md): the log file the runtime appends a
  // record of every scan to (empty: none), how many scans a file holds
  // before the runtime goes on in the other of its two files, and the HAL
  // pin it reads the time from (empty: no clock).
  std::string record_file;
  int record_max_cycles = kDefaultRecordMaxCycles;
  std::string record_clock_pin;
  SourceRange record_file_range;  // the key, for messages
  SourceRange range;             // the [linuxcnc] table
};

// [measure]: the instrument that measures the robot's error at the nodes of
// a region (docs/measure.md, docs/cell.md). One of three devices:
enum class MeasureDevice {
  // The paper's (Fig. 4): a linear displacement transducer touches the flank
  // of a groove in a precise plate the robot carries; the flank turns the
  // robot's error along the axis into a vertical displacement, read as an
  // analog input, and a second transducer on the plate's surface takes out
  // the robot's z error. One axis per run (the transducer is mounted for it).
  kTransducer,
  // A touch probe in the gripper against a precise hole at every node (a
  // hole plate): the probe moves from the node towards the hole's wall along
  // each axis; the trip against the wall's calibrated position is the error.
  kProbe,
  // An external system (camera, CMM, laser tracker): the program triggers it
  // at every node and waits for it; its readings come as CSV keyed by node.
  kExternal,
};
inline constexpr std::array<std::string_view, 3> kMeasureDeviceNames = {"transducer", "probe", "external"};

struct MeasureTransducer {
  int input = 0;            // motion.analog-in-NN of the measuring transducer (on the groove's flank)
  int reference_input = 1;  // motion.analog-in-NN of the z reference transducer (on the plate's surface)
  // The reading's change per mm of the robot's error along the measured axis
  // (the flank's slope, signed: 1 for a 45 degree flank rising with the axis).
  double slope = 1;
  // The measuring minus the reference reading with the robot exactly at the
  // node (from the set-up: the plate's certificate and the zeroing gauge).
  double zero_mm = 0;
  Interval range_mm{0, 1};  // readings outside it: the transducer lost contact (the program aborts)
  double groove_pitch_mm = 5;  // nodes and check points must lie on grooves: multiples of it from the first node
  int grooves = 11;            // grooves per direction: the plate's reach
};

struct MeasureProbe {
  double hole_diameter_mm = 0;    // the holes' calibrated diameter
  double hole_pitch_mm = 5;       // the holes sit on a square lattice of this pitch; nodes and check points must be holes
  double stylus_diameter_mm = 0;  // the stylus ball's effective diameter (calibrated on a ring gauge)
  double speed_mm_s = 1;          // the probing feed
  double overtravel_mm = 0.5;     // how far past the expected wall a probe move may go before it is a miss
  int holes = 0;                  // holes per direction: the plate reaches (holes - 1) x hole_pitch_mm; 0: not declared
  double hole_diameter_u_mm = 0;    // the standard uncertainty of hole_diameter_mm (the plate's certificate)
  double stylus_diameter_u_mm = 0;  // ... of stylus_diameter_mm (the ring gauge's calibration)
};

struct MeasureExternal {
  int trigger_output = 0;  // motion.digital-out-NN: on asks the system for a reading
  int done_input = 0;      // motion.digital-in-NN: on when the system has taken it
  int node_output = 0;     // motion.analog-out-NN: the node; the set and repetition on the next two
};

struct Measure {
  MeasureDevice device = MeasureDevice::kProbe;
  SourceRange device_range;
  double z_mm = 0;        // the robot z at which the device reads
  double clear_z_mm = 0;  // the z between nodes (default: the robot's safe_limz_mm)
  double dwell_s = 0.2;   // settle time at the node before the reading
  double noise_mm = 0;    // one standard deviation of a single reading (the device's stated noise)
  double timeout_s = 5;   // how long the program waits for the device before it aborts
  double reading_time_s = 0;  // the device's own time per reading (an external system's exposure), for the plan's time
  std::optional<int> ready_input;  // motion.digital-in-NN, on while the device is ready (checked before each reading)
  // How far off and how far turned the artefact may be put down at a set-up
  // (the probing cycle's clearances; the registration of untied set-ups).
  // Default: the robot's uncalibrated_accuracy_mm, and 0.1 degree.
  std::optional<double> placement_mm;
  double placement_deg = 0.1;
  double u_deg = 0;  // the nozzle angle u the programs command before measuring
  // The artefact's certificate: its pitch (scale) error, which measure read
  // corrects, and the standard uncertainty of that, in parts per million.
  double artefact_pitch_error_ppm = 0;
  double artefact_pitch_u_ppm = 0;
  MeasureTransducer transducer;
  MeasureProbe probe;
  MeasureExternal external;
  SourceRange range;  // the [measure] table
};

// LinuxCNC's motion controller has at most 64 digital inputs and outputs
// (motion.digital-in/out-00..63, [EMCMOT]num_dio).
inline constexpr int kLinuxCncMaxDio = 64;
// ... and at most 64 analog inputs and outputs (motion.analog-in/out-NN, [EMCMOT]num_aio).
inline constexpr int kLinuxCncMaxAio = 64;

// A file a cell was read from, with the SHA-256 of its bytes (base/sha256.h):
// what a compiled program records of the cell it was compiled for, so
// `smtcal diff` can tell whether a cell is that one (docs/diff.md).
struct CellFile {
  bool table = false;        // an error table (else the cell file itself)
  std::string path;          // the cell file as given; a table as the cell file writes it
  std::string sha256;        // 64 lowercase hex digits
  std::vector<std::string> regions;  // a table: the regions that use it, in cell order
};

// How a compiled output records one of its cell's files, in a comment line
// (docs/diff.md): "cell file sha256 <64 hex digits> <path>" or "table file
// sha256 <64 hex digits> <path>". The regions are not part of it.
std::string CellFileLine(const CellFile& file);
// The inverse, for the text of such a comment; nullopt for anything else.
std::optional<CellFile> ParseCellFileLine(std::string_view text);

struct Cell {
  std::string name;    // the `name` key; default: the file name without .cell.toml / .toml
  std::string path;    // the cell file as given
  std::uint32_t file = 0;  // its SourceManager id
  Robot robot;
  std::vector<Region> regions;  // pairwise without common interior (they may share an edge)
  std::vector<Fixture> fixtures;
  std::vector<Feeder> feeders;
  std::optional<LinuxCnc> linuxcnc;  // the [linuxcnc] table, when the file has one
  std::optional<Measure> measure;    // the [measure] table, when the file has one
  // The cell file, then each table file once, in the order the regions name
  // them: set by the loader (and by the reader of a LinuxCNC output, from
  // what the compile wrote there).
  std::vector<CellFile> files;

  const Fixture* FindFixture(std::string_view name) const;  // case-insensitive
  const Region* FindRegion(std::string_view name) const;    // case-insensitive
  const Feeder* FindFeeder(std::string_view name) const;    // case-insensitive
  // The region whose bounds contain the required position p: regions do not
  // overlap, so there is at most one, except on an edge two regions share,
  // which belongs to the one listed first in the file. nullptr if none.
  const Region* RegionAt(const Point2& p) const;
};

// The names as the file writes them, in the order of their enums.
inline constexpr std::array<std::string_view, 4> kTaskAxisNames = {"x", "y", "z", "u"};
static_assert(static_cast<int>(TaskAxis::U) == 3);
inline constexpr std::array<std::string_view, 3> kEstimatorNames = {"paper", "rigid", "rigid-scale"};
static_assert(static_cast<int>(Estimator::kRigidScale) == 2);
inline constexpr std::array<std::string_view, 3> kOutsideNames = {"error", "clamp", "none"};
static_assert(static_cast<int>(OutsidePolicy::kClamp) == 1 && static_cast<int>(OutsidePolicy::kNone) == 2);

std::string_view EstimatorName(Estimator estimator);  // paper | rigid | rigid-scale
std::string_view TaskAxisName(TaskAxis axis);         // x | y | z | u
std::string_view OutsidePolicyName(OutsidePolicy policy);  // error | clamp | none

}  // namespace smtcal::cell

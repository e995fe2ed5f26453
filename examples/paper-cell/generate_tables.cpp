// Generates the example error tables of the placing region, modelled on the
// paper (section 3.2.2 and its Figure 5):
//
//   placing-raw.csv    raw measurements: 11 x 11 nodes at 5 mm pitch over
//                      50 x 50 mm per axis, two sets of ten repetitions per
//                      node, 2.5 µm repetition scatter, 1 µm transducer
//                      resolution; the y grid is offset from the x grid by
//                      (+0.004, -0.003) mm (each axis was measured separately)
//   placing-table.csv  the table `smtcal table build` makes of them
//   placing-table.svg  the plot `smtcal table plot` makes of the table
//
// and the tables of the example cell's other regions (paper.cell.toml), for
// which the paper gives no figures:
//
//   layer2-table.csv   the placing area of layer 2 (base x 205..255, y 60..110)
//   layer3-table.csv   the placing area of layer 3 (base x 260..310, y 60..110)
//   feeders-table.csv  the feeder pick area (base x 155..245, y 5..30)
//   marker1-table.csv  under the fixture's marker 1 scan (base x 127.5..152.5, y 31..56)
//   marker2-table.csv  under the fixture's marker 2 scan (base x 313.5..338.5, y 114..139)
//
// Those are a smooth model of the same robot's error (see ModelDx/ModelDy)
// evaluated at the nodes of the same kind of grid, without raw measurements;
// each node states the scatter and count of the paper's measurement (2.5 µm,
// two sets of ten), so the tables' own noise enters the budgets. The marker
// tables make the scan's trips direct-calibrated: without them the robot's
// own error at the markers would move every placement on the board.
//
// The error field is smooth and shaped so that the built table has the
// paper's statistics to the micrometre: Delta-x from -153 to +27 µm with mean
// -79 µm, Delta-y from -71 to +62 µm with mean +7 µm. The noise is fixed by the
// seed, so the shape parameters are tuned against the very values that get
// written. Output is byte-identical across runs: std::mt19937_64 with our own
// Box-Muller (std::normal_distribution differs between standard libraries)
// and fixed-precision printing.
//
// Usage (from the repository root, after building):
//   build/smtcal_gen_paper_tables examples/paper-cell
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "backend/reports/table_plot.h"
#include "backend/reports/table_report.h"
#include "calibration/error_table_build.h"
#include "calibration/error_table_check.h"
#include "frontend/table_csv.h"

namespace smtcal {
namespace {

constexpr std::uint64_t kSeed = 1994;  // the paper's year
constexpr int kNodes = 11;             // per side
constexpr double kPitchMm = 5.0;
constexpr double kOriginXMm = 150.0, kOriginYMm = 60.0;        // the x grid's first node
constexpr double kYGridShiftXMm = 0.004, kYGridShiftYMm = -0.003;  // the y grid against the x grid
constexpr int kSets = 2, kRepetitions = 10;
constexpr double kRepeatScatterMm = 0.0025;
constexpr double kResolutionMm = 0.001;
constexpr int kMeasurements = kSets * kRepetitions;
// The built table's min, max and mean are tuned to the paper's figures within
// this (a nanometre; the mean within a quarter of it, so all three print as
// the paper's numbers to 6 decimals).
constexpr double kTuneTolMm = 1e-6;

struct Target {
  double min_mm, max_mm, mean_mm;
};
constexpr Target kTargetX{-0.153, 0.027, -0.079};
constexpr Target kTargetY{-0.071, 0.062, 0.007};

// Standard normal samples: Box-Muller on mt19937_64, both outputs used.
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : engine_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
    double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;          // [0, 1)
    double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * std::numbers::pi * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// The shapes of the two error fields over the unit square (u along x, v
// along y): a scale error, an out-of-squareness and a gentle bow, like a
// Cartesian robot with a heavy gripper. Each has one minimum and one maximum
// node; Shape() maps them to [0, 1] and the generator stretches that.
double ShapeX(double u, double v) {
  return u + 0.6 * v + 0.3 * std::sin(std::numbers::pi * u) * (1 - v) + 0.15 * u * v * v;
}
double ShapeY(double u, double v) {
  return 0.9 * v - 0.5 * u + 0.25 * std::sin(1.5 * std::numbers::pi * u) * (0.4 + v) + 0.1 * u * v;
}

struct Axis {
  TableAxis axis;
  double x0, y0;                 // first node
  std::vector<double> shape;     // per node, in [0, 1]
  std::vector<double> bump;      // per node: sin(pi u) sin(pi v), 0 on the edges
  std::vector<double> noise;     // per node and measurement, standard normal
  Target target;
  // Tuned: value = lo + (hi - lo) * shape^power + fine * bump.
  double lo = 0, hi = 0, power = 1, fine = 0;

  double True(std::size_t node) const {
    return lo + (hi - lo) * std::pow(shape[node], power) + fine * bump[node];
  }
  // A measurement as the transducer reports it: rounded to its resolution.
  double Measured(std::size_t node, int k) const {
    double value = True(node) + kRepeatScatterMm * noise[node * kMeasurements + static_cast<std::size_t>(k)];
    return std::round(value / kResolutionMm) * kResolutionMm;
  }
  // The node means (as `table build` takes them) and their min, max, mean.
  Target Achieved() const {
    Target t{INFINITY, -INFINITY, 0};
    for (std::size_t node = 0; node < shape.size(); ++node) {
      double sum = 0;
      for (int k = 0; k < kMeasurements; ++k) sum += Measured(node, k);
      double mean = sum / kMeasurements;
      t.min_mm = std::min(t.min_mm, mean);
      t.max_mm = std::max(t.max_mm, mean);
      t.mean_mm += mean / static_cast<double>(shape.size());
    }
    return t;
  }
  // The power whose noiseless field has the given mean (bisection on log p).
  double PowerForMean(double mean) const {
    double a = -4, b = 4;  // log2 of the power; the mean falls as the power grows
    for (int step = 0; step < 100; ++step) {
      double mid = 0.5 * (a + b), power_mid = std::exp2(mid), sum = 0;
      for (double s : shape) sum += lo + (hi - lo) * std::pow(s, power_mid);
      (sum / static_cast<double>(shape.size()) > mean ? a : b) = mid;
    }
    return std::exp2(0.5 * (a + b));
  }
  // Stretches and bends the shape until the built table's min, max and mean
  // are within kTuneTolMm of the target (the node means move in steps of
  // 0.05 µm, so the search keeps the best parameters it has seen).
  bool Tune() {
    lo = target.min_mm, hi = target.max_mm;
    double mean_goal = target.mean_mm;
    double best_error = INFINITY, best_lo = lo, best_hi = hi, best_power = power;
    for (int round = 0; round < 1000 && best_error >= kTuneTolMm; ++round) {
      power = PowerForMean(mean_goal);
      Target got = Achieved();
      double e_min = got.min_mm - target.min_mm, e_max = got.max_mm - target.max_mm,
             e_mean = got.mean_mm - target.mean_mm;
      double error = std::max({std::abs(e_min), std::abs(e_max), std::abs(e_mean)});
      if (error < best_error) best_error = error, best_lo = lo, best_hi = hi, best_power = power;
      // Damped, with a gain that varies from round to round so the search
      // does not lock into a cycle on the 0.05 µm steps.
      double gain = 0.3 + 0.4 * ((round * 7) % 11) / 10.0;
      lo -= gain * e_min;
      hi -= gain * e_max;
      mean_goal -= gain * e_mean;
    }
    lo = best_lo, hi = best_hi, power = best_power;
    // The mean moves in steps of 0.05 µm / 121 only when single nodes round
    // differently; a tiny smooth bump (zero on the edges, where the extremes
    // are) makes it land within kTuneTolMm / 4 without touching min and max.
    for (int k = 0; k <= 4000; ++k) {
      fine = (k % 2 == 0 ? 1 : -1) * (k / 2) * 1e-8;
      Target got = Achieved();
      if (std::abs(got.min_mm - target.min_mm) < kTuneTolMm && std::abs(got.max_mm - target.max_mm) < kTuneTolMm &&
          std::abs(got.mean_mm - target.mean_mm) < kTuneTolMm / 4) {
        return true;
      }
    }
    return false;
  }
};

Axis MakeAxis(TableAxis which, double x0, double y0, Target target, Normal& normal,
              double (*shape)(double, double)) {
  Axis axis{which, x0, y0, {}, {}, {}, target};
  double lowest = INFINITY, highest = -INFINITY;
  std::vector<double> raw;
  for (int j = 0; j < kNodes; ++j) {
    for (int i = 0; i < kNodes; ++i) {
      double value = shape(i / double(kNodes - 1), j / double(kNodes - 1));
      raw.push_back(value);
      lowest = std::min(lowest, value);
      highest = std::max(highest, value);
    }
  }
  for (double value : raw) axis.shape.push_back((value - lowest) / (highest - lowest));
  for (int j = 0; j < kNodes; ++j) {
    for (int i = 0; i < kNodes; ++i) {
      double u = static_cast<double>(i) / (kNodes - 1), v = static_cast<double>(j) / (kNodes - 1);
      axis.bump.push_back(std::sin(std::numbers::pi * u) * std::sin(std::numbers::pi * v));
    }
  }
  for (std::size_t k = 0; k < raw.size() * kMeasurements; ++k) axis.noise.push_back(normal());
  return axis;
}

// --- the other regions' tables ----------------------------------------------

// One region's model table: a 5 mm grid from (x0, y0), the y grid offset as
// in the placing region (each axis measured separately).
struct ModelTable {
  const char* file;
  const char* what;
  double x0, y0;
  int nx, ny;
};
constexpr ModelTable kModelTables[] = {
    {"layer2-table.csv", "the placing area of layer 2", 205.0, 60.0, 11, 11},
    {"layer3-table.csv", "the placing area of layer 3", 260.0, 60.0, 11, 11},
    {"feeders-table.csv", "the feeder pick area", 155.0, 5.0, 19, 6},
    {"marker1-table.csv", "the scan area of the fixture's marker 1", 127.5, 31.0, 6, 6},
    {"marker2-table.csv", "the scan area of the fixture's marker 2", 313.5, 114.0, 6, 6},
};

// The model error field over the base frame (mm in, mm out), of the kind the
// placing region has: a scale error, an out-of-squareness and a gentle bow.
// Over the work area x 150..315, y 0..115 Delta-x stays between about -140
// and -15 µm and Delta-y between about +5 and +95 µm (no sign change, so the
// paper's condition for linear interpolation holds), and the slopes stay
// below 0.001 (mm per mm), 500 times below kMaxErrorSlope.
double ModelDx(double x, double y) {
  return -0.040 - 0.00045 * (x - 150) + 0.00030 * (y - 60) +
         0.012 * std::sin(std::numbers::pi * (x - 150) / 110) * std::cos(std::numbers::pi * y / 230);
}
double ModelDy(double x, double y) {
  return 0.030 + 0.00025 * (x - 150) - 0.00020 * (y - 60) +
         0.010 * std::sin(std::numbers::pi * (y - 5) / 105 + 0.4) * (1 + (x - 150) / 330);
}

// A grid coordinate as the nearest double of its 3-decimal value, so it is
// written with 3 decimals.
double GridMm(double mm) { return std::round(mm * 1000) / 1000; }

// The table of one region, as CSV text; empty (after printing why) when it
// does not assemble and validate without warnings.
std::string ModelTableCsv(const ModelTable& spec) {
  SourceManager sources;
  Diagnostics diags(sources);
  std::vector<TableNode> nodes;
  for (TableAxis axis : kTableAxes) {
    const bool is_y = axis == TableAxis::Y;
    for (int j = 0; j < spec.ny; ++j) {
      for (int i = 0; i < spec.nx; ++i) {
        TableNode node;
        node.axis = axis;
        node.x_mm = GridMm(spec.x0 + i * kPitchMm + (is_y ? kYGridShiftXMm : 0));
        node.y_mm = GridMm(spec.y0 + j * kPitchMm + (is_y ? kYGridShiftYMm : 0));
        node.error_mm = std::round((is_y ? ModelDy : ModelDx)(node.x_mm, node.y_mm) / 1e-6) * 1e-6;
        node.stddev_mm = kRepeatScatterMm;
        node.count = kMeasurements;
        nodes.push_back(node);
      }
    }
  }
  std::uint32_t file = sources.Add(spec.file, "");
  std::optional<ErrorTable> table = AssembleErrorTable(spec.file, nodes, SourceLoc{file, 0, 0}, diags);
  if (!table || !ValidateErrorTable(*table, diags, TableWarnings::kReport) || diags.warning_count() > 0) {
    fmt::print(stderr, "generate_tables: the model table {} is not clean:\n{}", spec.file, diags.RenderText());
    return "";
  }
  const std::vector<std::string> comment = {
      fmt::format("error table of {} (example cell paper.cell.toml)", spec.what),
      "a smooth model of the robot's error at the nodes, not measured: the paper gives figures only for the",
      "placing region; stddev and count are the paper's measurement (2.5 um scatter, two sets of ten);",
      "generated by examples/paper-cell/generate_tables.cpp, do not edit"};
  return FormatTableCsv(*table, comment);
}

std::string RawCsv(const std::array<Axis, 2>& axes) {
  std::string out =
      "# Raw position-error measurements of the placing region, modelled on the paper (3.2.2):\n"
      "# 11 x 11 nodes at 5 mm pitch per axis, two sets of ten repetitions per node, transducer\n"
      "# resolution 0.001 mm; the y grid is offset from the x grid by (+0.004, -0.003) mm.\n"
      "# Generated by examples/paper-cell/generate_tables.cpp (seed 1994); do not edit.\n"
      "# Rebuild the table: smtcal table build placing-raw.csv -o placing-table.csv\n"
      "axis,x_mm,y_mm,set,repetition,error_mm\n";
  for (const Axis& axis : axes) {
    for (int set = 1; set <= kSets; ++set) {
      for (int j = 0; j < kNodes; ++j) {
        for (int i = 0; i < kNodes; ++i) {
          std::size_t node = static_cast<std::size_t>(j * kNodes + i);
          for (int rep = 1; rep <= kRepetitions; ++rep) {
            double value = axis.Measured(node, (set - 1) * kRepetitions + rep - 1);
            out += fmt::format("{},{},{},{},{},{:.3f}\n", AxisName(axis.axis), FormatMm(axis.x0 + i * kPitchMm),
                               FormatMm(axis.y0 + j * kPitchMm), set, rep, value == 0 ? 0.0 : value);
          }
        }
      }
    }
  }
  return out;
}

int Run(const std::filesystem::path& dir) {
  Normal normal(kSeed);
  std::array<Axis, 2> axes = {
      MakeAxis(TableAxis::X, kOriginXMm, kOriginYMm, kTargetX, normal, ShapeX),
      MakeAxis(TableAxis::Y, kOriginXMm + kYGridShiftXMm, kOriginYMm + kYGridShiftYMm, kTargetY, normal, ShapeY)};
  for (Axis& axis : axes) {
    if (!axis.Tune()) {
      fmt::print(stderr, "generate_tables: could not tune the {} field to the paper's statistics\n",
                 AxisName(axis.axis));
      return 1;
    }
  }

  // Write the raw file, then build the table from its text exactly as
  // `smtcal table build` does, so the shipped table is its output.
  const std::string raw_text = RawCsv(axes);
  SourceManager sources;
  std::uint32_t file = sources.Add("placing-raw.csv", raw_text);
  Diagnostics diags(sources);
  std::optional<std::vector<RawMeasurement>> raw = ReadRawMeasurements(file, diags);
  std::optional<ErrorTable> table;
  if (raw) table = BuildErrorTable("placing-table.csv", *raw, SourceLoc{file, 0, 0}, diags);
  if (!table || !ValidateErrorTable(*table, diags, TableWarnings::kSkip) || diags.warning_count() > 0) {
    fmt::print(stderr, "generate_tables: the generated data do not build cleanly:\n{}", diags.RenderText());
    return 1;
  }
  TableStats stats = ComputeTableStats(*table);
  for (const Axis& axis : axes) {
    const AxisStats& s = stats.axes[static_cast<int>(axis.axis)];
    auto um = [](double mm) { return std::lround(mm * 1000); };
    if (um(s.min_mm) != um(axis.target.min_mm) || um(s.max_mm) != um(axis.target.max_mm) ||
        um(s.mean_mm) != um(axis.target.mean_mm)) {
      fmt::print(stderr, "generate_tables: the built {} table misses the paper's statistics\n", AxisName(axis.axis));
      return 1;
    }
    fmt::print("Δ{}: min {:+.1f} µm, max {:+.1f} µm, mean {:+.1f} µm (shape power {:.3f})\n", AxisName(axis.axis),
               s.min_mm * 1000, s.max_mm * 1000, s.mean_mm * 1000, axis.power);
  }

  // The plot is of the table as written (6 decimals), as `smtcal table plot`
  // reads it back.
  const std::string table_text = FormatTableCsv(*table, BuiltTableComment("placing-raw.csv"));
  std::optional<ErrorTable> written_table =
      ReadErrorTable(sources.Add("placing-table.csv", table_text), diags);
  if (!written_table) {
    fmt::print(stderr, "generate_tables: the written table does not read back:\n{}", diags.RenderText());
    return 1;
  }
  struct Output {
    const char* name;
    std::string text;
  };
  for (const Output& output : {Output{"placing-raw.csv", raw_text}, Output{"placing-table.csv", table_text},
                               Output{"placing-table.svg", PlotTableSvg(*written_table, "placing-table.csv")}}) {
    Status written = WriteFileAtomically((dir / output.name).string(), output.text);
    if (!written) {
      fmt::print(stderr, "generate_tables: {}\n", written.error().message);
      return 3;
    }
    fmt::print("wrote {}\n", (dir / output.name).string());
  }
  for (const ModelTable& spec : kModelTables) {
    std::string text = ModelTableCsv(spec);
    if (text.empty()) return 1;
    Status written = WriteFileAtomically((dir / spec.file).string(), text);
    if (!written) {
      fmt::print(stderr, "generate_tables: {}\n", written.error().message);
      return 3;
    }
    fmt::print("wrote {}\n", (dir / spec.file).string());
  }
  return 0;
}

}  // namespace
}  // namespace smtcal

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: smtcal_gen_paper_tables OUTPUT_DIR   (e.g. examples/paper-cell)\n");
    return 2;
  }
  return smtcal::Run(argv[1]);
}

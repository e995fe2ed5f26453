// Reading back a LinuxCNC output (frontend/linuxcnc_output.h).
//
// The data: smtcal_data.ngc is a list of `#N = number  ; what` lines inside
// `o<smtcal_data> sub`; its numbers are decoded with the layout the writer
// uses (frontend/linuxcnc_layout.h) into regions (bounds, policy, tables,
// validated) and fixtures (nominal pose, limits, estimator, marker edge
// lines, scan paths), the names taken from the `what` comments. A fixture's
// edge segments are rebuilt on their lines over the trips the data says
// each edge has, and the expected trips recomputed from them must be the
// data's own, or the file is refused.
//
// The main program: every form the emitter writes (backend/linuxcnc/
// linuxcnc_emit.cpp) is recognised line by line and written back as the
// .place statement it lowers — literal targets as XY(...), point parameters
// as the point (in its root frame: Local frames are folded in), temporaries
// as the point or pallet slot and its offsets, For, If, Wait Sw, Cycle,
// Scan, Call — and that text is parsed and checked like any program. The
// variables' types (the G-code has none) are inferred: a variable is Real
// when anything assigned to it is. Line numbers of the text are mapped back
// to the .ngc file's, so a diff names the lines of the program that runs.
#include "frontend/linuxcnc_output.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/error_table_check.h"
#include "calibration/fixture_geometry.h"
#include "frontend/linuxcnc_layout.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
namespace L = linuxcnc_layout;

// ------------------------------------------------------------------ errors

// A reading error, at a line of a file.
struct ReadError {
  std::uint32_t line = 0;
  std::string what;
};

// ------------------------------------------------------------------ the data

std::optional<double> ParseNumber(std::string_view text) {
  if (text.empty()) return std::nullopt;
  double value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value, std::chars_format::fixed);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

struct DataParam {
  double value = 0;
  std::uint32_t line = 0;
  std::string what;  // the comment after `;`
};

class DataReader {
 public:
  DataReader(const SourceFile& file) : file_(file) {}

  std::optional<ReadError> Read(cell::Cell& cell) {
    if (auto error = ReadLines(cell)) return error;
    const int regions = Integer(L::kRegionCount), fixtures = Integer(L::kFixtureCount);
    if (!error_.what.empty()) return error_;
    for (int r = 0; r < regions && error_.what.empty(); ++r) ReadRegion(Integer(Integer(L::kRegionDirectory) + r), r, cell);
    for (int k = 0; k < fixtures && error_.what.empty(); ++k) {
      ReadFixture(Integer(Integer(L::kFixtureDirectory) + k), Integer(L::kFixtureDirectory) + k, cell);
    }
    if (!error_.what.empty()) return error_;
    safe_z_ = Value(L::kSafeZ);
    return std::nullopt;
  }
  double safe_z() const { return safe_z_; }

 private:
  std::optional<ReadError> ReadLines(cell::Cell& cell) {
    bool in_sub = false, ended = false;
    for (std::size_t i = 0; i < file_.line_starts.size(); ++i) {
      const auto number = static_cast<std::uint32_t>(i + 1);
      std::string_view line = Line(i);
      if (line.empty() && i + 1 == file_.line_starts.size()) break;  // the newline at the end
      if (ended) return ReadError{number, "text after o<smtcal_data> endsub"};
      if (line.starts_with(";")) {
        if (in_sub) continue;
        std::string_view text = line.substr(1);
        if (text.starts_with(' ')) text.remove_prefix(1);
        if (auto files = cell::ParseCellFileLine(text)) cell.files.push_back(std::move(*files));
        constexpr std::string_view kFor = "data for cell ";
        if (auto at = text.find(kFor); at != std::string_view::npos && cell.name.empty()) {
          std::string_view rest = text.substr(at + kFor.size());
          const std::size_t open = rest.rfind(" (");
          cell.name = std::string(rest.substr(0, open));
          if (open != std::string_view::npos && rest.ends_with("),")) {
            cell.path = std::string(rest.substr(open + 2, rest.size() - open - 4));
          }
        }
        continue;
      }
      if (line == "o<smtcal_data> sub" && !in_sub) {
        in_sub = true;
        continue;
      }
      if (line == "o<smtcal_data> endsub" && in_sub) {
        ended = true;
        continue;
      }
      // The cycle record's begin line (smtcal_record_open.ngc, written for the
      // cell): no data of the cell.
      if (in_sub && line.starts_with("o<smtcal_record_open> call")) continue;
      if (!in_sub || !line.starts_with('#')) return ReadError{number, "a line that is not a parameter of o<smtcal_data>"};
      if (line.starts_with(L::kRuntimeIdParameter)) continue;  // the runtime's identity, not the cell's data
      // #N = value[  ; what]
      const std::size_t eq = line.find(" = ");
      if (eq == std::string_view::npos) return ReadError{number, "a parameter line without ' = '"};
      std::string_view rest = line.substr(eq + 3);
      std::string_view what;
      if (const std::size_t semicolon = rest.find("  ; "); semicolon != std::string_view::npos) {
        what = rest.substr(semicolon + 4);
        rest = rest.substr(0, semicolon);
      }
      std::optional<double> address = ParseNumber(line.substr(1, eq - 1));
      std::optional<double> value = ParseNumber(rest);
      if (!address || !value || *address != std::floor(*address) || *address < L::kFirst || *address >= L::kScratch) {
        return ReadError{number, "a parameter line whose address or value is not a plain number in the data's range"};
      }
      params_[static_cast<int>(*address)] = {*value, number, std::string(what)};
    }
    if (!ended) return ReadError{static_cast<std::uint32_t>(file_.line_starts.size()), "no o<smtcal_data> endsub"};
    if (Value(L::kVersion) != L::kLayoutVersion) {
      return ReadError{Where(L::kVersion), fmt::format("the layout version is not {}", L::kLayoutVersion)};
    }
    return std::nullopt;
  }

  std::string_view Line(std::size_t i) const {
    const std::size_t begin = file_.line_starts[i];
    const std::size_t end = i + 1 < file_.line_starts.size() ? file_.line_starts[i + 1] : file_.text.size();
    std::string_view line(file_.text.data() + begin, end - begin);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    return line;
  }

  std::uint32_t Where(int address) const {
    auto it = params_.find(address);
    return it != params_.end() ? it->second.line : 1;
  }

  void Fail(int address, std::string what) {
    if (error_.what.empty()) error_ = {Where(address), std::move(what)};
  }

  double Value(int address) {
    auto it = params_.find(address);
    if (it == params_.end()) {
      Fail(address, fmt::format("parameter #{} is missing", address));
      return 0;
    }
    return it->second.value;
  }
  int Integer(int address) {
    const double value = Value(address);
    if (value != std::floor(value) || std::fabs(value) > 1e6) Fail(address, fmt::format("#{} is not a whole number", address));
    return static_cast<int>(value);
  }
  // The name in a "what" comment "<prefix>NAME<suffix>".
  std::string Name(int address, std::string_view prefix, std::string_view suffix) {
    auto it = params_.find(address);
    const std::string& what = it != params_.end() ? it->second.what : std::string();
    if (!what.starts_with(prefix) || !what.ends_with(suffix) || what.size() <= prefix.size() + suffix.size()) {
      Fail(address, fmt::format("#{} does not say what it is ('{}NAME{}')", address, prefix, suffix));
      return "";
    }
    return what.substr(prefix.size(), what.size() - prefix.size() - suffix.size());
  }

  AxisTable ReadTable(int at) {
    AxisTable table;
    const int nx = Integer(at), ny = Integer(at + 1);
    if (nx < 2 || ny < 2 || nx * ny > L::kScratch) {
      Fail(at, "a table smaller than 2 x 2 nodes");
      return table;
    }
    for (int i = 0; i < nx; ++i) table.xs.push_back(Value(at + 2 + i));
    for (int j = 0; j < ny; ++j) table.ys.push_back(Value(at + 2 + nx + j));
    for (int n = 0; n < nx * ny; ++n) table.error_mm.push_back(Value(at + 2 + nx + ny + n));
    return table;
  }

  void ReadRegion(int at, int index, cell::Cell& cell) {
    if (!error_.what.empty()) return;
    cell::Region region;
    region.name = Name(Integer(L::kRegionDirectory) + index, "region ", " at");
    region.x_mm = {Value(at + L::kRgXLo), Value(at + L::kRgXHi)};
    region.y_mm = {Value(at + L::kRgYLo), Value(at + L::kRgYHi)};
    const int outside = Integer(at + L::kRgOutside);
    if (outside < 0 || outside > 2) Fail(at + L::kRgOutside, "an outside policy that is not 0, 1 or 2");
    region.outside = static_cast<OutsidePolicy>(std::clamp(outside, 0, 2));
    region.table.name = region.name;
    region.table[TableAxis::X] = ReadTable(Integer(at + L::kRgDxAt));
    region.table[TableAxis::Y] = ReadTable(Integer(at + L::kRgDyAt));
    region.difficulty_level = 2;
    region.difficulty_axes = {cell::TaskAxis::X, cell::TaskAxis::Y};
    if (!error_.what.empty()) return;
    // The tables the runtime inverts must be ones smtcal accepts.
    SourceManager scratch_sources;
    Diagnostics scratch(scratch_sources);
    if (!HasUsableShape(region.table) || !ValidateErrorTable(region.table, scratch, TableWarnings::kSkip)) {
      Fail(at, fmt::format("the tables of region {} are not valid error tables", region.name));
      return;
    }
    region.domain = TableDomain(region.table);
    cell.regions.push_back(std::move(region));
  }

  void ReadFixture(int at, int directory_entry, cell::Cell& cell) {
    if (!error_.what.empty()) return;
    cell::Fixture fixture;
    fixture.name = Name(directory_entry, "fixture ", " at");
    const int estimator = Integer(at + L::kFxEstimator);
    if (estimator < 0 || estimator > 2) Fail(at + L::kFxEstimator, "an estimator that is not 0, 1 or 2");
    fixture.estimator = static_cast<cell::Estimator>(std::clamp(estimator, 0, 2));
    fixture.origin_mm = {Value(at + L::kFxOriginX), Value(at + L::kFxOriginY)};
    fixture.angle_deg = std::atan2(Value(at + L::kFxSin), Value(at + L::kFxCos)) * kDegPerRad;
    fixture.l1_mm = Value(at + L::kFxL1);
    fixture.l2_mm = Value(at + L::kFxL2);
    fixture.trip_window_mm = Value(at + L::kFxTripWindow);
    fixture.max_shift_mm = Value(at + L::kFxMaxShift);
    fixture.max_rotation_deg = Value(at + L::kFxMaxRotation);
    fixture.length_tolerance_mm = Value(at + L::kFxLengthTolerance);
    fixture.squareness_deg = Value(at + L::kFxSquareness);
    fixture.max_line_residual_mm = Value(at + L::kFxMaxLineResidual);
    fixture.scan_z_mm = Value(at + L::kFxScanZ);
    fixture.scan_speed_mm_s = Value(at + L::kFxScanFeed) / 60;
    fixture.latch_speed_mm_s = Value(at + L::kFxLatchFeed) / 60;  // 0: one stage
    const int trips = Integer(at + L::kFxTripCount);
    if (trips < 1 || trips > 64) Fail(at + L::kFxTripCount, "a trip count out of range");
    if (!error_.what.empty()) return;
    const Eigen::Affine3d nominal = NominalFix(fixture);
    // The trips: their edges and nominal positions (base frame, nominal pose).
    const int edges_at = Integer(at + L::kFxTripEdgeAt), nominal_at = Integer(at + L::kFxTripNominalAt);
    std::vector<int> trip_edge;
    std::vector<Eigen::Vector2d> trip_at;  // fixture frame
    for (int k = 0; k < trips; ++k) {
      trip_edge.push_back(Integer(edges_at + k));
      trip_at.push_back(ToFixtureFrame(nominal, {Value(nominal_at + 2 * k), Value(nominal_at + 2 * k + 1)}));
    }
    // Each edge as the segment of its line that spans its trips.
    for (int e = 0; e < 4; ++e) {
      const Eigen::Vector2d normal(Value(at + L::kFxEdgeNormal + 2 * e), Value(at + L::kFxEdgeNormal + 2 * e + 1));
      const double offset = Value(at + L::kFxEdgeOffset + e);
      const Eigen::Vector2d along(normal.y(), -normal.x());  // EdgeLineOf turns the direction left into the normal
      const Eigen::Vector2d on_line = normal * offset;
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < trips; ++k) {
        if (trip_edge[static_cast<std::size_t>(k)] != e) continue;
        const double t = along.dot(trip_at[static_cast<std::size_t>(k)] - on_line);
        lo = std::min(lo, t);
        hi = std::max(hi, t);
      }
      if (lo > hi) {
        Fail(at + L::kFxTripEdgeAt, fmt::format("fixture {}'s edge p{} has no trip", fixture.name, e + 1));
        return;
      }
      constexpr double kSpanMarginMm = 1e-6;  // the trips lie on the rebuilt segment, not at its ends
      cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(e)];
      edge.name = fmt::format("p{}", e + 1);
      edge.from = on_line + along * (lo - kSpanMarginMm);
      edge.to = on_line + along * (hi + kSpanMarginMm);
    }
    // The scan paths, from the base frame at the nominal pose.
    const int paths_at = Integer(at + L::kFxScanPathsAt);
    const int paths = Integer(paths_at);
    int next = paths_at + 1;
    for (int p = 0; p < paths && error_.what.empty(); ++p) {
      cell::ScanPath path;
      const std::string prefix = fixture.name + ": path ";
      const std::string what = Name(next, prefix, " point count");
      path.name = what;
      const int points = Integer(next++);
      if (points < 2 || points > 1000) Fail(next - 1, "a scan path with fewer than 2 points");
      for (int i = 0; i < points && error_.what.empty(); ++i, next += 3) {
        path.points.push_back(ToFixtureFrame(nominal, {Value(next), Value(next + 1)}));
      }
      fixture.scan_paths.push_back(std::move(path));
    }
    if (!error_.what.empty()) return;
    // What the runtime expects must be what the cell's geometry gives.
    const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    bool same = static_cast<int>(expected.size()) == trips;
    for (std::size_t k = 0; same && k < expected.size(); ++k) {
      same = expected[k].edge == trip_edge[k] && (expected[k].in_fixture - trip_at[k]).norm() < 1e-6;
    }
    if (!same) {
      Fail(at + L::kFxTripNominalAt,
           fmt::format("fixture {}'s scan paths and edges do not make the trips its data lists", fixture.name));
      return;
    }
    cell.fixtures.push_back(std::move(fixture));
  }

  const SourceFile& file_;
  std::map<int, DataParam> params_;
  ReadError error_;
  double safe_z_ = 0;
};

// ------------------------------------------------------------------ G-code expressions

// An RS274NGC expression as the emitter writes it: a number, a parameter,
// a bracketed chain `[a OP b OP c]`, or a function `ABS[...]`.
struct GNode {
  enum class Kind { kNumber, kParam, kGroup, kCall } kind = Kind::kNumber;
  std::string text;              // the number as written, the parameter's name (<...> or digits), the function
  std::vector<GNode> operands;   // kGroup: the chain's operands; kCall: one, its argument group
  std::vector<std::string> ops;  // kGroup: between the operands
};

class GParser {
 public:
  explicit GParser(std::string_view text) : text_(text) {}

  std::optional<GNode> Expr() {
    Skip();
    if (at_ >= text_.size()) return std::nullopt;
    const char c = text_[at_];
    if (c == '[') return Group();
    if (c == '#') {
      ++at_;
      GNode node;
      node.kind = GNode::Kind::kParam;
      if (at_ < text_.size() && text_[at_] == '<') {
        const std::size_t close = text_.find('>', at_);
        if (close == std::string_view::npos) return std::nullopt;
        node.text = std::string(text_.substr(at_ + 1, close - at_ - 1));
        at_ = close + 1;
      } else {
        const std::size_t begin = at_;
        while (at_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[at_]))) ++at_;
        if (begin == at_) return std::nullopt;
        node.text = std::string(text_.substr(begin, at_ - begin));
      }
      return node;
    }
    if (c == '-' || c == '.' || std::isdigit(static_cast<unsigned char>(c))) {
      const std::size_t begin = at_++;
      while (at_ < text_.size() && (std::isdigit(static_cast<unsigned char>(text_[at_])) || text_[at_] == '.')) ++at_;
      GNode node;
      node.text = std::string(text_.substr(begin, at_ - begin));
      if (!ParseNumber(node.text)) return std::nullopt;
      return node;
    }
    if (std::isalpha(static_cast<unsigned char>(c))) {
      const std::size_t begin = at_;
      while (at_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[at_]))) ++at_;
      GNode node;
      node.kind = GNode::Kind::kCall;
      node.text = std::string(text_.substr(begin, at_ - begin));
      if (at_ >= text_.size() || text_[at_] != '[') return std::nullopt;
      std::optional<GNode> argument = Group();
      if (!argument) return std::nullopt;
      node.operands.push_back(std::move(*argument));
      return node;
    }
    return std::nullopt;
  }

  bool AtEnd() {
    Skip();
    return at_ >= text_.size();
  }
  std::size_t position() const { return at_; }

 private:
  std::optional<GNode> Group() {
    ++at_;  // [
    GNode node;
    node.kind = GNode::Kind::kGroup;
    std::optional<GNode> first = Expr();
    if (!first) return std::nullopt;
    node.operands.push_back(std::move(*first));
    while (true) {
      Skip();
      if (at_ >= text_.size()) return std::nullopt;
      if (text_[at_] == ']') {
        ++at_;
        return node;
      }
      std::size_t begin = at_;
      if (std::string_view("+-*/").find(text_[at_]) != std::string_view::npos) {
        ++at_;
      } else {
        while (at_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[at_]))) ++at_;
      }
      if (begin == at_) return std::nullopt;
      node.ops.emplace_back(text_.substr(begin, at_ - begin));
      std::optional<GNode> operand = Expr();
      if (!operand) return std::nullopt;
      node.operands.push_back(std::move(*operand));
    }
  }
  void Skip() {
    while (at_ < text_.size() && text_[at_] == ' ') ++at_;
  }

  std::string_view text_;
  std::size_t at_ = 0;
};

std::optional<GNode> ParseGExpr(std::string_view text) {
  GParser parser(text);
  std::optional<GNode> node = parser.Expr();
  if (!node || !parser.AtEnd()) return std::nullopt;
  return node;
}

bool IsNumber(const GNode& n, std::string_view text) { return n.kind == GNode::Kind::kNumber && n.text == text; }
bool IsParam(const GNode& n, std::string_view name) { return n.kind == GNode::Kind::kParam && n.text == name; }
bool Same(const GNode& a, const GNode& b) {
  if (a.kind != b.kind || a.text != b.text || a.ops != b.ops || a.operands.size() != b.operands.size()) return false;
  for (std::size_t i = 0; i < a.operands.size(); ++i) {
    if (!Same(a.operands[i], b.operands[i])) return false;
  }
  return true;
}
// [a OP b]
bool IsBinary(const GNode& n, std::string_view op) {
  return n.kind == GNode::Kind::kGroup && n.ops.size() == 1 && n.ops[0] == op;
}

// ------------------------------------------------------------------ the main program

enum class Type { kInteger, kReal, kBoolean };

struct PExpr {
  std::string text;
  Type type = Type::kInteger;
};

// One line of the main program: its block (indentation and trailing comment
// removed) and its comment.
struct NgcLine {
  std::uint32_t number = 0;
  std::string block;
  std::string comment;  // inside the trailing parentheses, or the whole comment line's
  bool comment_only = false;
};

struct Failure {
  ReadError error;
};

class Decompiler {
 public:
  Decompiler(const SourceFile& ngc, const cell::Cell& cell, double safe_z, std::string program_name)
      : cell_(cell), safe_z_(safe_z), program_name_(std::move(program_name)) {
    for (std::size_t i = 0; i < ngc.line_starts.size(); ++i) {
      const std::size_t begin = ngc.line_starts[i];
      const std::size_t end = i + 1 < ngc.line_starts.size() ? ngc.line_starts[i + 1] : ngc.text.size();
      std::string_view text(ngc.text.data() + begin, end - begin);
      while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
      while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
      if (text.empty() && i + 1 == ngc.line_starts.size()) break;
      NgcLine line;
      line.number = static_cast<std::uint32_t>(i + 1);
      if (text.starts_with('(') && text.ends_with(')')) {
        line.comment_only = true;
        line.comment = std::string(text.substr(1, text.size() - 2));
      } else if (const std::size_t open = text.find(" ("); open != std::string_view::npos && text.ends_with(')')) {
        line.block = std::string(text.substr(0, open));
        line.comment = std::string(text.substr(open + 2, text.size() - open - 3));
      } else {
        line.block = std::string(text);
      }
      lines_.push_back(std::move(line));
    }
  }

  // The .place text and, per line of it, the .ngc line it stands for.
  std::optional<ReadError> Run(std::string& text, std::vector<std::uint32_t>& map) {
    // Types settle in a few rounds: each one may find another variable Real.
    for (int round = 0; round < 8; ++round) {
      const std::map<std::string, Type> before = types_;
      try {
        Decompile();
      } catch (const Failure& failure) {
        return failure.error;
      }
      if (types_ == before) break;
    }
    text = std::move(out_);
    map = std::move(map_);
    return std::nullopt;
  }

 private:
  // ---------------------------------------------------------------- output

  void Emit(std::string line, std::uint32_t ngc_line) {
    out_ += std::string(static_cast<std::size_t>(indent_) * 2, ' ');
    out_ += line;
    out_ += '\n';
    map_.push_back(ngc_line);
  }

  [[noreturn]] void Fail(const NgcLine& line, std::string what) const { throw Failure{{line.number, std::move(what)}}; }
  [[noreturn]] void FailAt(std::uint32_t line, std::string what) const { throw Failure{{line, std::move(what)}}; }

  const NgcLine& Peek() const {
    if (at_ >= lines_.size()) FailAt(lines_.empty() ? 1 : lines_.back().number, "the program ends early");
    return lines_[at_];
  }
  const NgcLine& Next() {
    const NgcLine& line = Peek();
    ++at_;
    return line;
  }
  const NgcLine& Expect(std::string_view block) {
    const NgcLine& line = Next();
    if (line.block != block) Fail(line, fmt::format("expected '{}'", block));
    return line;
  }

  // ---------------------------------------------------------------- the program

  void Decompile() {
    out_.clear();
    map_.clear();
    at_ = 0;
    indent_ = 0;
    switches_.clear();
    pallets_.clear();
    pallet_lines_.clear();
    assigned_real_.clear();
    std::string functions_text;
    std::vector<std::uint32_t> functions_map;

    const NgcLine& header = Next();
    if (!header.comment_only || !header.comment.starts_with("smtcal ") ||
        header.comment.find(" for LinuxCNC and cell ") == std::string::npos) {
      Fail(header, "the first line is not smtcal's header");
    }
    const std::uint32_t header_line = header.number;
    while (Peek().comment_only) Next();
    Expect("G21 G90 G17 G94 G61");
    Expect("o<smtcal_data> call");
    // The check that the runtime on the path is the one compiled with the
    // program: two ifs, each aborting (not part of the program's text).
    const std::string id(L::kRuntimeIdParameter);
    for (const std::string& condition : {" if [EXISTS[" + id + "] EQ 0]", " if [" + id + " NE "}) {
      const NgcLine& check = Next();
      if (!check.block.starts_with('o') || check.block.find(condition) == std::string::npos) {
        Fail(check, "the main program without its runtime check");
      }
      if (!Next().comment.starts_with("abort,")) Fail(lines_[at_ - 1], "a runtime check without its abort");
      if (!Next().block.ends_with(" endif")) Fail(lines_[at_ - 1], "a runtime check without its endif");
    }
    // Points, then globals.
    std::vector<std::pair<std::string, std::uint32_t>> points;  // .place line, .ngc line
    while (true) {
      const NgcLine& line = Peek();
      if (line.comment_only && line.comment.starts_with("Point ")) {
        ReadSplitPoint(points);
      } else if (!line.comment_only && line.block.starts_with("#<_p_")) {
        ReadPoint(points);
      } else {
        break;
      }
    }
    std::vector<std::pair<std::string, std::uint32_t>> globals;  // name, line
    while (!Peek().comment_only && Peek().block.starts_with("#<_v_")) {
      const NgcLine& line = Next();
      const std::string name = VariableName(line, line.block.substr(0, line.block.find(' ')));
      if (line.block != fmt::format("#<_v_{}> = 0", name)) Fail(line, "a global that does not start at 0");
      globals.emplace_back(name, line.number);
    }
    // The Pick/Place subroutine, the same in every output of a cell.
    if (Peek().comment_only && Peek().comment.starts_with("Pick and Place:")) {
      while (Peek().block != "o<pick_place> endsub") Next();
      Next();
    }
    // The functions.
    std::swap(out_, functions_text);
    std::swap(map_, functions_map);
    while (Peek().block.starts_with("o<fn_") && Peek().block.ends_with("> sub")) ReadFunction();
    std::swap(out_, functions_text);
    std::swap(map_, functions_map);
    Expect("o<fn_main> call");
    Expect("M2");
    if (at_ != lines_.size()) Fail(lines_[at_], "text after M2");

    // The declarations, then the functions.
    Emit("Program " + program_name_, header_line);
    Emit("Units mm", header_line);
    if (vacuum_) Emit(fmt::format("Vacuum {}", *vacuum_), vacuum_line_);
    for (const cell::Fixture& fixture : cell_.fixtures) Emit("Fixture " + fixture.name, header_line);
    for (const auto& [line, ngc] : points) Emit(line, ngc);
    for (std::size_t p = 0; p < pallets_.size(); ++p) Emit(fmt::format("Pallet {}, {}", p + 1, pallets_[p]), pallet_lines_[p]);
    for (const auto& [name, line] : globals) Emit(fmt::format("{} {}", TypeName(name), name), line);
    out_ += functions_text;
    map_.insert(map_.end(), functions_map.begin(), functions_map.end());
  }

  std::string TypeName(const std::string& name) const {
    auto it = types_.find(name);
    return it != types_.end() && it->second == Type::kReal ? "Real" : "Integer";
  }

  // "#<_v_name>" / "#<v_name>" -> "name".
  std::string VariableName(const NgcLine& line, std::string_view param) const {
    if (param.starts_with("#<_v_") && param.ends_with('>')) return std::string(param.substr(5, param.size() - 6));
    if (param.starts_with("#<v_") && param.ends_with('>')) return std::string(param.substr(4, param.size() - 5));
    Fail(line, "expected a variable");
  }

  // ---------------------------------------------------------------- points

  // "Point R1 In Layer1 -> fixture Board frame": the display name and the root ("" = base).
  void PointComment(const NgcLine& line, std::string_view comment, std::string& name, std::string& root) const {
    const std::size_t arrow = comment.find(" -> ");
    const std::size_t word = comment.find("Point ");
    if (arrow == std::string_view::npos || word == std::string_view::npos) Fail(line, "a point without its comment");
    std::string_view decl = comment.substr(word + 6, arrow - word - 6);
    name = std::string(decl.substr(0, decl.find(' ')));
    std::string_view frame = comment.substr(arrow + 4);
    if (frame == "robot base frame") {
      root.clear();
    } else if (frame.starts_with("fixture ") && frame.ends_with(" frame")) {
      root = std::string(frame.substr(8, frame.size() - 14));
    } else {
      Fail(line, "a point's frame that is neither the robot base nor a fixture");
    }
  }

  std::string PointLine(const NgcLine& line, const std::string& param_name, std::string name,
                        const std::string& root, const std::array<std::string, 4>& values) {
    // A name cut in the comment (long names): the parameter's, lowercase.
    if (name.ends_with("...") || sema_lower(name) != param_name) name = param_name;
    point_names_[param_name] = name;
    point_roots_[param_name] = root;
    (void)line;
    std::string text = fmt::format("Point {} = XY({}, {}, {}, {})", name, values[0], values[1], values[2], values[3]);
    if (!root.empty()) text += " In " + root;
    return text;
  }

  static std::string sema_lower(std::string_view text) {
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
  }

  // #<_p_NAME_x> = v #<_p_NAME_y> = v #<_p_NAME_z> = v #<_p_NAME_u> = v (src:L Point ...)
  void ReadPoint(std::vector<std::pair<std::string, std::uint32_t>>& points) {
    const NgcLine& line = Next();
    std::string_view rest = line.block;
    std::string param;
    std::array<std::string, 4> values;
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    for (int a = 0; a < 4; ++a) {
      if (!rest.starts_with("#<_p_")) Fail(line, "a point line without its four parameters");
      const std::size_t close = rest.find("> = ");
      if (close == std::string_view::npos || close < 7 || rest[close - 2] != '_' || rest[close - 1] != kAxes[a]) {
        Fail(line, "a point line without its four parameters");
      }
      const std::string name(rest.substr(5, close - 7));
      if (a == 0) param = name;
      if (name != param) Fail(line, "a point line with parameters of two points");
      rest.remove_prefix(close + 4);
      const std::size_t space = rest.find(' ');
      values[a] = std::string(rest.substr(0, space));
      if (!ParseNumber(values[a])) Fail(line, "a point coordinate that is not a number");
      rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
    }
    if (!rest.empty()) Fail(line, "text after a point's parameters");
    std::string name, root;
    PointComment(line, line.comment, name, root);
    points.emplace_back(PointLine(line, param, name, root, values), line.number);
  }

  // (Point ... -> ... src:L) then one line per axis.
  void ReadSplitPoint(std::vector<std::pair<std::string, std::uint32_t>>& points) {
    const NgcLine& comment = Next();
    std::string name, root;
    // The comment ends with the source location: cut it before the frame is read.
    std::string text = comment.comment.substr(0, comment.comment.rfind(' '));
    PointComment(comment, text, name, root);
    std::string param;
    std::array<std::string, 4> values;
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    for (int a = 0; a < 4; ++a) {
      const NgcLine& line = Next();
      const std::size_t close = line.block.find("> = ");
      if (!line.block.starts_with("#<_p_") || close == std::string::npos || line.block[close - 1] != kAxes[a]) {
        Fail(line, "a point's parameter line");
      }
      const std::string p = line.block.substr(5, close - 7);
      if (a == 0) param = p;
      if (p != param) Fail(line, "a point line with parameters of two points");
      values[a] = line.block.substr(close + 4);
      if (!ParseNumber(values[a])) Fail(line, "a point coordinate that is not a number");
    }
    points.emplace_back(PointLine(comment, param, name, root, values), comment.number);
  }

  // ---------------------------------------------------------------- functions

  void ReadFunction() {
    const NgcLine& sub = Next();
    const std::string name = sub.block.substr(5, sub.block.size() - 10);
    std::vector<std::string> locals;
    while (!Peek().comment_only && Peek().block.starts_with("#<v_") && Peek().comment == sub.comment) {
      const NgcLine& line = Next();
      const std::string local = VariableName(line, line.block.substr(0, line.block.find(' ')));
      if (line.block != fmt::format("#<v_{}> = 0", local)) Fail(line, "a local that does not start at 0");
      locals.push_back(local);
    }
    Emit("Function " + name, sub.number);
    ++indent_;
    for (const std::string& local : locals) Emit(fmt::format("{} {}", TypeName(local), local), sub.number);
    const std::string end = fmt::format("o<fn_{}> endsub", name);
    Body([&](const NgcLine& line) { return line.block == end; });
    --indent_;
    Emit("Fend", Next().number);
  }

  // Statements until a line `stop` accepts (not consumed).
  template <typename Stop>
  void Body(const Stop& stop) {
    while (!stop(Peek())) Statement();
  }

  // The temporaries and switch reads that prepare one statement.
  struct Prepared {
    std::map<std::string, std::vector<GNode>> temps;  // each assignment of a #<t_...> in order
    std::vector<std::pair<std::string, GNode>> order;  // (temp, value) in order
    std::uint32_t first_line = 0;
  };

  void Statement() {
    Prepared prepared;
    // Switch reads and temporaries come before the block that uses them.
    while (true) {
      const NgcLine& line = Peek();
      if (line.comment_only) break;
      if (line.block.starts_with("M66 P") && line.block.ends_with(" L0")) {
        Next();
        if (prepared.first_line == 0) prepared.first_line = line.number;
        std::optional<GNode> bit = ParseGExpr(line.block.substr(5, line.block.size() - 8));
        const NgcLine& store = Next();
        if (!bit || !store.block.starts_with("#<t_sw") || !store.block.ends_with("> = #5399")) {
          Fail(store, "a switch read without its temporary");
        }
        switches_[store.block.substr(2, store.block.find('>') - 2)] = *bit;
        continue;
      }
      if (line.block.starts_with("#<t_") && !line.block.starts_with("#<t_for")) {
        Next();
        if (prepared.first_line == 0) prepared.first_line = line.number;
        const std::size_t eq = line.block.find("> = ");
        if (eq == std::string::npos) Fail(line, "a temporary without a value");
        const std::string temp = line.block.substr(2, eq - 2);
        std::optional<GNode> value = ParseGExpr(line.block.substr(eq + 4));
        if (!value) Fail(line, "an expression smtcal does not write");
        prepared.temps[temp].push_back(*value);
        prepared.order.emplace_back(temp, std::move(*value));
        continue;
      }
      break;
    }
    const NgcLine& line = Next();
    const std::uint32_t at = prepared.first_line != 0 ? prepared.first_line : line.number;
    const std::string& b = line.block;
    if (line.comment_only) {
      if (line.comment.starts_with("Cycle ")) return Cycle(line);
      Fail(line, "a comment where a statement belongs");
    }
    if (b.starts_with("o<pick_place> call ")) return PickPlace(line, prepared, at);
    if (b.starts_with("o<smtcal_correct> call ") || b.starts_with("G0 ") || b.starts_with("G1 ")) {
      return Motion(line, prepared, at);
    }
    if (!prepared.order.empty()) Fail(line, "temporaries before a statement that uses none");
    if (b.starts_with("#<t_for")) return For(line);
    if (b.starts_with("#<v_") || b.starts_with("#<_v_")) {
      const std::size_t eq = b.find(" = ");
      if (eq == std::string::npos) Fail(line, "an assignment without ' = '");
      const std::string name = VariableName(line, b.substr(0, eq));
      PExpr value = Expression(line, b.substr(eq + 3));
      if (value.type == Type::kReal) assigned_real_.insert(name);
      Assigned(name, value.type);
      return Emit(fmt::format("{} = {}", name, value.text), at);
    }
    if (b.starts_with("M64 P") || b.starts_with("M65 P")) {
      return Emit(fmt::format("{} {}", b[2] == '4' ? "On" : "Off", Expression(line, b.substr(5)).text), at);
    }
    if (b.starts_with("G4 P")) return Emit("Wait " + Expression(line, b.substr(4)).text, at);
    if (b.starts_with("o<fn_") && b.ends_with("> call")) return Emit("Call " + b.substr(5, b.size() - 11), at);
    if (b.starts_with("o<fn_") && b.ends_with("> return")) return Emit("Exit Function", at);
    if (b.starts_with("o<smtcal_scan> call [") && b.ends_with("]")) {
      return Emit("Scan " + FixtureName(line, b.substr(21, b.size() - 22)), at);
    }
    if (b.starts_with('o') && b.ends_with(" do")) return WaitSwitch(line);
    if (b.starts_with('o') && b.find(" if ") != std::string::npos) return If(line, at);
    Fail(line, "a block smtcal does not write");
  }

  void Assigned(const std::string& name, Type type) {
    if (type == Type::kReal) types_[name] = Type::kReal;
    types_.emplace(name, Type::kInteger);
  }

  std::string FixtureName(const NgcLine& line, std::string_view index) const {
    std::optional<double> k = ParseNumber(index);
    if (!k || *k < 0 || *k != std::floor(*k) || *k >= static_cast<double>(cell_.fixtures.size())) {
      Fail(line, "a fixture index that is not one of the data's fixtures");
    }
    return cell_.fixtures[static_cast<std::size_t>(*k)].name;
  }

  // (Cycle F src:L) ... (EndCycle F src:L)
  void Cycle(const NgcLine& line) {
    const std::string name = line.comment.substr(6, line.comment.find(' ', 6) - 6);
    Emit("Cycle " + name, line.number);
    ++indent_;
    const std::string end = "EndCycle " + name + " ";
    Body([&](const NgcLine& l) { return l.comment_only && l.comment.starts_with(end); });
    --indent_;
    Emit("EndCycle", Next().number);
  }

  // oN do / M66 P<bit> L3|L4 Q3600 / oN while [#5399 LT 0]
  void WaitSwitch(const NgcLine& line) {
    const std::string o = line.block.substr(0, line.block.size() - 3);
    const NgcLine& wait = Next();
    const std::size_t l = wait.block.find(" L");
    if (!wait.block.starts_with("M66 P") || l == std::string::npos || wait.block.size() < l + 4) {
      Fail(wait, "a Wait Sw without its M66");
    }
    const std::string bit = Expression(wait, wait.block.substr(5, l - 5)).text;
    const char state = wait.block[l + 2];
    Expect(o + " while [#5399 LT 0]");
    Emit(fmt::format("Wait Sw({}) = {}", bit, state == '3' ? "On" : "Off"), line.number);
  }

  // oN if C / oN elseif C / oN else / oN endif
  void If(const NgcLine& line, std::uint32_t at) {
    const std::size_t space = line.block.find(' ');
    const std::string o = line.block.substr(0, space);
    Emit(fmt::format("If {} Then", Condition(line, line.block.substr(space + 4))), at);
    auto ends_branch = [&](const NgcLine& l) {
      return l.block.starts_with(o + " elseif ") || l.block == o + " else" || l.block == o + " endif";
    };
    ++indent_;
    Body(ends_branch);
    --indent_;
    while (true) {
      const NgcLine& next = Next();
      if (next.block == o + " endif") {
        Emit("EndIf", next.number);
        return;
      }
      if (next.block == o + " else") {
        Emit("Else", next.number);
      } else {
        Emit(fmt::format("ElseIf {} Then", Condition(next, next.block.substr(o.size() + 8))), next.number);
      }
      ++indent_;
      Body(ends_branch);
      --indent_;
    }
  }

  std::string Condition(const NgcLine& line, std::string_view text) {
    PExpr condition = Expression(line, text);
    if (condition.type != Type::kBoolean) Fail(line, "a condition that is not a comparison");
    return condition.text;
  }

  // #<t_forN_v> = from / #<t_forN_to> = to / [step and its check] / oN while C / VAR = #<t_forN_v>
  // ... / #<t_forN_v> = [#<t_forN_v> + S] / oN endwhile
  void For(const NgcLine& line) {
    const std::size_t eq = line.block.find("> = ");
    const std::string v = line.block.substr(0, eq + 1);  // #<t_forN_v>
    if (!v.ends_with("_v>")) Fail(line, "a For without its counter");
    const std::string base = v.substr(0, v.size() - 3);  // #<t_forN
    const std::string o = "o" + base.substr(7);
    PExpr from = Expression(line, line.block.substr(eq + 4));
    const NgcLine& to_line = Next();
    if (!to_line.block.starts_with(base + "_to> = ")) Fail(to_line, "a For without its bound");
    PExpr to = Expression(to_line, to_line.block.substr(base.size() + 7));
    std::optional<PExpr> step;
    if (Peek().block.starts_with(base + "_step> = ")) {
      const NgcLine& step_line = Next();
      step = Expression(step_line, step_line.block.substr(base.size() + 9));
      const NgcLine& check = Next();  // oM if [#<t_forN_step> EQ 0] / (abort) / oM endif
      const std::string m = check.block.substr(0, check.block.find(' '));
      if (check.block != fmt::format("{} if [{}_step> EQ 0]", m, base)) Fail(check, "a For step without its check");
      if (!Next().comment.starts_with("abort,")) Fail(lines_[at_ - 1], "a For step check without its abort");
      Expect(m + " endif");
    }
    const NgcLine& loop = Next();
    if (!loop.block.starts_with(o + " while ")) Fail(loop, "a For without its while");
    const NgcLine& var_line = Next();
    if (!var_line.block.ends_with(" = " + v)) Fail(var_line, "a For without its loop variable");
    const std::string var = VariableName(var_line, var_line.block.substr(0, var_line.block.find(' ')));
    Assigned(var, from.type == Type::kReal || to.type == Type::kReal || (step && step->type == Type::kReal)
                      ? Type::kReal
                      : Type::kInteger);
    std::string header = fmt::format("For {} = {} To {}", var, from.text, to.text);
    std::size_t header_at = out_.size();
    Emit(header, line.number);
    ++indent_;
    const std::string increment = fmt::format("{} = [{} + ", v, v);
    Body([&](const NgcLine& l) { return l.block.starts_with(increment); });
    --indent_;
    const NgcLine& next = Next();
    const std::string s = next.block.substr(increment.size(), next.block.size() - increment.size() - 1);
    if (!step && s != "1") step = Expression(next, s);
    if (step) {
      const std::string with_step = header + " Step " + step->text;
      out_.replace(header_at + static_cast<std::size_t>(indent_) * 2, header.size(), with_step);
    }
    Expect(o + " endwhile");
    Emit(fmt::format("Next {}", var), next.number);
  }

  // ---------------------------------------------------------------- motion

  // The target written as a .place point expression, from the position's
  // four expressions and the temporaries that computed them.
  std::string Target(const NgcLine& line, const std::array<GNode, 4>& xyzu, const Prepared& prepared,
                     std::uint32_t at) {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    // XY(...) as given.
    if (std::all_of(xyzu.begin(), xyzu.end(), [](const GNode& n) { return n.kind == GNode::Kind::kNumber; })) {
      if (!prepared.order.empty()) Fail(line, "temporaries before a literal position");
      return fmt::format("XY({}, {}, {}, {})", xyzu[0].text, xyzu[1].text, xyzu[2].text, xyzu[3].text);
    }
    // A point's parameters.
    if (std::string point = PointOf(xyzu); !point.empty()) {
      if (!prepared.order.empty()) Fail(line, "temporaries before a point's parameters");
      return point;
    }
    // Temporaries: a point or a pallet slot, then offsets.
    for (int a = 0; a < 4; ++a) {
      if (!IsParam(xyzu[a], fmt::format("t_{}", kAxes[a]))) Fail(line, "a position smtcal does not write");
    }
    std::array<GNode, 4> base;
    std::size_t k = 0;
    const std::vector<std::pair<std::string, GNode>>& order = prepared.order;
    std::string slot;
    if (!order.empty() && (order[0].first == "t_s" || order[0].first == "t_k")) {
      slot = PalletSlot(line, order, k, base, at);
    } else {
      for (int a = 0; a < 4; ++a, ++k) {
        if (k >= order.size() || order[k].first != fmt::format("t_{}", kAxes[a])) Fail(line, "a position smtcal does not write");
        base[static_cast<std::size_t>(a)] = order[k].second;
      }
      slot = PointOf(base);
      if (slot.empty()) Fail(line, "a position that is not a point");
    }
    std::string offsets;
    for (; k < order.size(); ++k) {
      // #<t_A> = [#<t_A> +|- term]
      const auto& [temp, value] = order[k];
      const int axis = temp.size() == 3 ? static_cast<int>(std::string_view("xyzu").find(temp[2])) : -1;
      if (axis < 0 || !(IsBinary(value, "+") || IsBinary(value, "-")) || !IsParam(value.operands[0], temp)) {
        Fail(line, "an offset smtcal does not write");
      }
      const PExpr amount = Decompile(line, value.operands[1]);
      offsets += fmt::format(" {} {}({})", value.ops[0], static_cast<char>(std::toupper(kAxes[axis])), amount.text);
    }
    return slot + offsets;
  }

  // "R1" when the four are #<_p_r1_x> ... #<_p_r1_u>, else "".
  std::string PointOf(const std::array<GNode, 4>& xyzu) const {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    std::string name;
    for (int a = 0; a < 4; ++a) {
      const GNode& n = xyzu[static_cast<std::size_t>(a)];
      if (n.kind != GNode::Kind::kParam || !n.text.starts_with("_p_") || n.text.size() < 6 ||
          n.text[n.text.size() - 2] != '_' || n.text.back() != kAxes[static_cast<std::size_t>(a)]) {
        return "";
      }
      const std::string p = n.text.substr(3, n.text.size() - 5);
      if (a > 0 && p != name) return "";
      name = p;
    }
    auto it = point_names_.find(name);
    return it != point_names_.end() ? it->second : "";
  }

  // Pallet(n, i, j) or Pallet(n, k) from the emitter's formula
  // (linuxcnc_emit.cpp, PalletSlot): [#<t_k> = [K - 1]], #<t_s> = ..., #<t_t> = ...,
  // #<t_A> = [P1 + [#<t_s> * [P2 - P1]] + [#<t_t> * [P3 - P1]]] for each axis.
  std::string PalletSlot(const NgcLine& line, const std::vector<std::pair<std::string, GNode>>& order,
                         std::size_t& k, std::array<GNode, 4>& base, std::uint32_t at) {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    std::optional<GNode> count;
    if (order[k].first == "t_k") {
      const GNode& value = order[k++].second;
      if (!IsBinary(value, "-") || !IsNumber(value.operands[1], "1")) Fail(line, "a pallet count smtcal does not write");
      count = value.operands[0];
    }
    if (k + 6 > order.size() || order[k].first != "t_s" || order[k + 1].first != "t_t") {
      Fail(line, "a pallet slot smtcal does not write");
    }
    // [[INDEX - 1] / (n - 1)] or 0.
    auto index = [&](const GNode& value, int& n, std::optional<GNode>& of) {
      if (IsNumber(value, "0")) {
        n = 1;
        return;
      }
      if (!IsBinary(value, "/") || value.operands[1].kind != GNode::Kind::kNumber || !IsBinary(value.operands[0], "-") ||
          !IsNumber(value.operands[0].operands[1], "1")) {
        Fail(line, "a pallet slot smtcal does not write");
      }
      n = static_cast<int>(*ParseNumber(value.operands[1].text)) + 1;
      of = value.operands[0].operands[0];
    };
    int columns = 1, rows = 1;
    std::optional<GNode> column, row;
    index(order[k].second, columns, column);
    index(order[k + 1].second, rows, row);
    k += 2;
    std::array<std::string, 3> corners;
    for (int a = 0; a < 4; ++a, ++k) {
      const auto& [temp, value] = order[k];
      if (temp != fmt::format("t_{}", kAxes[a]) || value.kind != GNode::Kind::kGroup || value.ops.size() != 2) {
        Fail(line, "a pallet slot smtcal does not write");
      }
      // [P1 + [#<t_s> * [P2 - P1]] + [#<t_t> * [P3 - P1]]]
      std::array<std::string, 3> names;
      auto corner = [&](const GNode& n) -> std::string {
        const std::string suffix = fmt::format("_{}", kAxes[a]);
        if (n.kind != GNode::Kind::kParam || !n.text.starts_with("_p_") || !n.text.ends_with(suffix)) {
          Fail(line, "a pallet corner that is not a point");
        }
        return n.text.substr(3, n.text.size() - 5);
      };
      names[0] = corner(value.operands[0]);
      for (int c = 1; c <= 2; ++c) {
        const GNode& term = value.operands[static_cast<std::size_t>(c)];
        if (!IsBinary(term, "*") || !IsParam(term.operands[0], c == 1 ? "t_s" : "t_t") ||
            !IsBinary(term.operands[1], "-")) {
          Fail(line, "a pallet slot smtcal does not write");
        }
        names[static_cast<std::size_t>(c)] = corner(term.operands[1].operands[0]);
      }
      if (a == 0) corners = names;
      if (names != corners) Fail(line, "a pallet slot with two sets of corners");
      base[static_cast<std::size_t>(a)] = GNode{GNode::Kind::kParam, fmt::format("_p_{}_{}", names[0], kAxes[a]), {}, {}};
    }
    for (std::string& corner : corners) {
      auto it = point_names_.find(corner);
      if (it == point_names_.end()) Fail(line, "a pallet corner that is not a point");
      corner = it->second;
    }
    const std::string decl = fmt::format("{}, {}, {}, {}, {}", corners[0], corners[1], corners[2], columns, rows);
    auto found = std::find(pallets_.begin(), pallets_.end(), decl);
    if (found == pallets_.end()) {
      pallets_.push_back(decl);
      pallet_lines_.push_back(at);
      found = pallets_.end() - 1;
    }
    const std::size_t number = static_cast<std::size_t>(found - pallets_.begin()) + 1;
    if (count) return fmt::format("Pallet({}, {})", number, Decompile(line, *count).text);
    return fmt::format("Pallet({}, {}, {})", number, column ? Decompile(line, *column).text : "1",
                       row ? Decompile(line, *row).text : "1");
  }

  // The arguments of `o<name> call [a] [b] ...`.
  std::vector<GNode> CallArguments(const NgcLine& line, std::string_view text) const {
    std::vector<GNode> arguments;
    GParser parser(text);
    while (!parser.AtEnd()) {
      std::optional<GNode> argument = parser.Expr();
      if (!argument || argument->kind != GNode::Kind::kGroup || argument->operands.size() != 1 ||
          !argument->ops.empty()) {
        Fail(line, "a call argument smtcal does not write");
      }
      arguments.push_back(std::move(argument->operands[0]));
    }
    return arguments;
  }

  // o<pick_place> call [k] [x] [y] [z] [u] [LimZ] [vacuum] [1|0] [line]
  void PickPlace(const NgcLine& line, const Prepared& prepared, std::uint32_t at) {
    std::vector<GNode> arguments = CallArguments(line, std::string_view(line.block).substr(19));
    if (arguments.size() != 9) Fail(line, "o<pick_place> with other than nine arguments");
    const std::string target = Target(line, {arguments[1], arguments[2], arguments[3], arguments[4]}, prepared, at);
    CheckKind(line, arguments[0], target);
    std::string text = fmt::format("{} {}", IsNumber(arguments[7], "1") ? "Pick" : "Place", target);
    const std::string vacuum = Decompile(line, arguments[6]).text;
    if (!vacuum_) {
      vacuum_ = vacuum;
      vacuum_line_ = line.number;
    }
    if (vacuum != *vacuum_) text += " Vacuum " + vacuum;
    text += LimZ(line, arguments[5]);
    Emit(text, at);
  }

  // " LimZ z", or "" for the cell's safe z (what a Pick, Place or Jump without one rises to).
  std::string LimZ(const NgcLine& line, const GNode& z) {
    if (z.kind == GNode::Kind::kNumber && ParseNumber(z.text) == safe_z_) return "";
    return " LimZ " + Decompile(line, z).text;
  }

  // The fixture index written beside a position is the frame the position is in.
  void CheckKind(const NgcLine& line, const GNode& k, const std::string& target) {
    std::optional<double> index = k.kind == GNode::Kind::kNumber ? ParseNumber(k.text) : std::nullopt;
    if (!index || *index < -2 || *index != std::floor(*index)) Fail(line, "a correction kind that is not a number");
    (void)target;
  }

  // [o<smtcal_correct> call [k] [x] [y]] then G0 Z / G0 X Y A / G0 Z (Jump), G0 X Y Z A (Go), G1 X Y Z A F (Move).
  void Motion(const NgcLine& first, const Prepared& prepared, std::uint32_t at) {
    const NgcLine* line = &first;
    std::optional<std::array<GNode, 2>> corrected;
    if (first.block.starts_with("o<smtcal_correct> call ")) {
      std::vector<GNode> arguments = CallArguments(first, std::string_view(first.block).substr(23));
      if (arguments.size() != 3) Fail(first, "o<smtcal_correct> with other than three arguments");
      corrected = std::array<GNode, 2>{arguments[1], arguments[2]};
      line = &Next();
    }
    std::map<char, GNode> words = Words(*line);
    std::string keyword;
    std::string limz;
    if (line->block.starts_with("G0 Z") && words.size() == 2) {  // Jump: up, across, down
      keyword = "Jump";
      limz = LimZ(*line, words.at('Z'));
      const NgcLine& across = Next();
      words = Words(across);
      const NgcLine& down = Next();
      std::map<char, GNode> z = Words(down);
      if (!down.block.starts_with("G0 Z") || z.size() != 2) Fail(down, "a Jump without its descent");
      words['Z'] = z.at('Z');
    } else {
      keyword = line->block.starts_with("G1 ") ? "Move" : "Go";
    }
    const char rotation = words.count('A') ? 'A' : words.count('B') ? 'B' : 'C';
    if (!words.count('X') || !words.count('Y') || !words.count('Z') || !words.count(rotation)) {
      Fail(*line, "a move without X, Y, Z and its rotation");
    }
    std::array<GNode, 4> xyzu = {words.at('X'), words.at('Y'), words.at('Z'), words.at(rotation)};
    if (corrected) {
      if (!IsParam(xyzu[0], "_smtcal_x") || !IsParam(xyzu[1], "_smtcal_y")) Fail(*line, "a corrected move without the correction");
      xyzu[0] = (*corrected)[0];
      xyzu[1] = (*corrected)[1];
      // A fixture's rotation is added to u: [u + #<_smtcal_angle>].
      if (IsBinary(xyzu[3], "+") && IsParam(xyzu[3].operands[1], "_smtcal_angle")) {
        GNode u = xyzu[3].operands[0];
        xyzu[3] = std::move(u);
      }
    }
    Emit(fmt::format("{} {}{}", keyword, Target(*line, xyzu, prepared, at), limz), at);
  }

  // The words of a G0/G1 block: letter -> value.
  std::map<char, GNode> Words(const NgcLine& line) const {
    std::map<char, GNode> words;
    std::string_view text = line.block;
    if (!(text.starts_with("G0 ") || text.starts_with("G1 "))) Fail(line, "expected a G0 or G1 move");
    std::size_t at = 3;
    words['G'] = GNode{GNode::Kind::kNumber, std::string(1, text[1]), {}, {}};
    while (at < text.size()) {
      while (at < text.size() && text[at] == ' ') ++at;
      if (at >= text.size()) break;
      const char letter = text[at++];
      GParser parser(text.substr(at));
      std::optional<GNode> value = parser.Expr();
      if (!value || !std::isupper(static_cast<unsigned char>(letter)) || words.count(letter)) {
        Fail(line, "a move word smtcal does not write");
      }
      words[letter] = std::move(*value);
      at += parser.position();
    }
    return words;
  }

  // ---------------------------------------------------------------- expressions

  PExpr Expression(const NgcLine& line, std::string_view text) {
    std::optional<GNode> node = ParseGExpr(text);
    if (!node) Fail(line, "an expression smtcal does not write");
    return Decompile(line, *node);
  }

  // The .place expression the emitter lowered to `node`.
  PExpr Decompile(const NgcLine& line, const GNode& node) {
    switch (node.kind) {
      case GNode::Kind::kNumber:
        return {node.text.starts_with('-') ? "(" + node.text + ")" : node.text,
                node.text.find('.') != std::string::npos ? Type::kReal : Type::kInteger};
      case GNode::Kind::kParam: {
        if (node.text.starts_with("v_") || node.text.starts_with("_v_")) {
          const std::string name = node.text.substr(node.text.find("v_") + 2);
          auto it = types_.find(name);
          return {name, it != types_.end() ? it->second : Type::kInteger};
        }
        if (auto it = switches_.find(node.text); it != switches_.end()) {
          return {fmt::format("Sw({})", Decompile(line, it->second).text), Type::kBoolean};
        }
        Fail(line, fmt::format("parameter #<{}> where an expression belongs", node.text));
      }
      case GNode::Kind::kCall: Fail(line, fmt::format("{}[...] where smtcal writes none", node.text));
      case GNode::Kind::kGroup: break;
    }
    if (node.ops.empty()) return Decompile(line, node.operands[0]);
    if (node.ops.size() != 1) Fail(line, "an expression smtcal does not write");
    const GNode& a = node.operands[0];
    const GNode& b = node.operands[1];
    const std::string& op = node.ops[0];
    // a Mod b: [[ABS[a] MOD ABS[b]] * [[[a GE 0] * 2] - 1]]
    if (op == "*" && IsBinary(a, "MOD") && a.operands[0].kind == GNode::Kind::kCall &&
        a.operands[0].text == "ABS" && a.operands[1].kind == GNode::Kind::kCall && a.operands[1].text == "ABS") {
      const PExpr x = Decompile(line, a.operands[0].operands[0]), y = Decompile(line, a.operands[1].operands[0]);
      return {fmt::format("({} Mod {})", x.text, y.text), Type::kInteger};
    }
    // a = b: [[a LE b] AND [a GE b]]; a <> b: [[a LT b] OR [a GT b]]
    if ((op == "AND" && IsBinary(a, "LE") && IsBinary(b, "GE")) || (op == "OR" && IsBinary(a, "LT") && IsBinary(b, "GT"))) {
      if (Same(a.operands[0], b.operands[0]) && Same(a.operands[1], b.operands[1])) {
        PExpr x = Decompile(line, a.operands[0]), y = Decompile(line, a.operands[1]);
        BooleanLiteral(x, y);
        return {fmt::format("({} {} {})", x.text, op == "AND" ? "=" : "<>", y.text), Type::kBoolean};
      }
    }
    PExpr x = Decompile(line, a), y = Decompile(line, b);
    if (op == "EQ" && IsNumber(b, "0") && x.type == Type::kBoolean) return {fmt::format("(Not {})", x.text), Type::kBoolean};
    static const std::map<std::string, std::string> kCompare = {{"LT", "<"}, {"GT", ">"}, {"LE", "<="}, {"GE", ">="}};
    if (auto it = kCompare.find(op); it != kCompare.end()) {
      return {fmt::format("({} {} {})", x.text, it->second, y.text), Type::kBoolean};
    }
    if (op == "AND" || op == "OR" || op == "XOR") {
      BooleanLiteral(x, y);
      const std::string word = op == "AND" ? "And" : op == "OR" ? "Or" : "Xor";
      return {fmt::format("({} {} {})", x.text, word, y.text), x.type};
    }
    if (op == "+" || op == "-" || op == "*" || op == "/") {
      const Type type = op == "/" || x.type == Type::kReal || y.type == Type::kReal ? Type::kReal : Type::kInteger;
      return {fmt::format("({} {} {})", x.text, op, y.text), type};
    }
    Fail(line, fmt::format("the operator {} where smtcal writes none", op));
  }

  // On and Off are 1 and 0 in G-code: beside a Boolean they are written back as such.
  static void BooleanLiteral(PExpr& x, PExpr& y) {
    auto to_boolean = [](PExpr& e) {
      if (e.type != Type::kBoolean && (e.text == "1" || e.text == "0")) e = {e.text == "1" ? "On" : "Off", Type::kBoolean};
    };
    if (x.type == Type::kBoolean) to_boolean(y);
    if (y.type == Type::kBoolean) to_boolean(x);
  }

  const cell::Cell& cell_;
  double safe_z_;
  std::string program_name_;
  std::vector<NgcLine> lines_;
  std::size_t at_ = 0;
  int indent_ = 0;
  std::string out_;
  std::vector<std::uint32_t> map_;
  std::map<std::string, std::string> point_names_;  // parameter name -> point name
  std::map<std::string, std::string> point_roots_;
  std::map<std::string, GNode> switches_;           // t_swK -> its bit
  std::map<std::string, Type> types_;               // variables, as inferred so far
  std::set<std::string> assigned_real_;
  std::vector<std::string> pallets_;                // "C1, C2, C3, columns, rows", numbered from 1
  std::vector<std::uint32_t> pallet_lines_;
  std::optional<std::string> vacuum_;
  std::uint32_t vacuum_line_ = 0;
};

std::string ProgramNameOf(const std::string& main_path) {
  std::string stem = fs::path(main_path).stem().string();
  std::string name;
  for (char c : stem) name += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (name.empty() || !std::isalpha(static_cast<unsigned char>(name.front()))) name = "P" + name;
  return name;
}

}  // namespace

bool LooksLikeLinuxCncOutput(const std::string& path) {
  std::error_code error;
  return fs::is_directory(path, error) || fs::path(path).extension() == ".ngc";
}

Result<std::optional<LinuxCncOutputRead>> ReadLinuxCncOutput(const std::string& path, SourceManager& sources,
                                                             Diagnostics& diags) {
  // The directory and its main program: the one .ngc file in it.
  std::error_code error;
  fs::path dir = path, main;
  if (fs::is_directory(path, error)) {
    for (const fs::directory_entry& entry : fs::directory_iterator(path, error)) {
      if (entry.path().extension() != ".ngc" || !entry.is_regular_file()) continue;
      if (!main.empty()) {
        return Error{fmt::format("'{}' holds more than one .ngc file ({} and {}); name the main program",
                                 path, main.filename().string(), entry.path().filename().string())};
      }
      main = entry.path();
    }
    if (main.empty()) return Error{fmt::format("'{}' holds no main program (.ngc)", path)};
  } else {
    main = path;
    dir = main.parent_path();
  }
  const fs::path data = dir / "subroutines" / "smtcal_data.ngc";
  LinuxCncOutputRead read;
  read.main_path = main.generic_string();
  read.data_path = data.generic_string();
  Result<std::uint32_t> main_file = sources.Load(read.main_path);
  if (!main_file) return main_file.error();
  Result<std::uint32_t> data_file = sources.Load(read.data_path);
  if (!data_file) {
    return Error{fmt::format("{} (a LinuxCNC output has its data in subroutines/smtcal_data.ngc)", data_file.error().message)};
  }
  auto report = [&](std::uint32_t file, const ReadError& failure) {
    diags.Report(DiagKind::LinuxCncOutputUnreadable, SourceRange(SourceLoc{file, failure.line, 1}), failure.what);
  };
  DataReader data_reader(sources.File(data_file.value()));
  if (std::optional<ReadError> failure = data_reader.Read(read.cell)) {
    report(data_file.value(), *failure);
    return std::optional<LinuxCncOutputRead>();
  }
  if (read.cell.path.empty()) read.cell.path = read.data_path;
  Decompiler decompiler(sources.File(main_file.value()), read.cell, data_reader.safe_z(), ProgramNameOf(read.main_path));
  std::string text;
  if (std::optional<ReadError> failure = decompiler.Run(text, read.line_map)) {
    report(main_file.value(), *failure);
    return std::optional<LinuxCncOutputRead>();
  }
  // The .place program it lowers; the caller parses and checks it.
  read.main_file = main_file.value();
  read.place_file = sources.Add(read.main_path, std::move(text));
  return std::optional<LinuxCncOutputRead>(std::move(read));
}

}  // namespace smtcal

// The reader of a LinuxCNC output (backend/linuxcnc/linuxcnc_output.h):
//   - read(emit(plan)) == plan over 1000 random programs for the example
//     cell (tests/unit/backend/random_place_program.h): the correction data
//     read from the runtime's data (regions and their tables, fixtures and
//     their geometry, estimator, limits, scan paths) are the cell's, and
//     every target of every motion statement is commanded as the compile
//     planned it (how: as written, through the tables at run time, through a
//     fixture's pose; which fixture; where), for the LinuxCNC output read
//     back as for the .place output;
//   - every line of the runtime's folder the controller reads, changed, is
//     an error — at its line, or at the runtime id's line when the change is
//     to a value the data holds (then no byte of it may differ from what
//     smtcal wrote); the o<pick_place> subroutine and each motion's
//     correction argument likewise;
//   - hostile nesting is an error at its line, never a crash.
//
// Property tests print their seed; SMTCAL_TEST_SEED repeats one.
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/linuxcnc/linuxcnc_layout.h"
#include "backend/linuxcnc/linuxcnc_output.h"
#include "backend/place/place_printer.h"
#include "base/check.h"
#include "calibration/fixture_geometry.h"
#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "ir/ir_walk.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/machine_targets.h"
#include "passes/pass_manager.h"
#include "tests/unit/backend/random_place_program.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
namespace L = linuxcnc_layout;

const fs::path kExample = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";

// The example cell, loaded once.
const cell::Cell& ExampleCell() {
  static SourceManager sources;
  static Diagnostics diags(sources);
  static const cell::Cell cell = [] {
    Result<std::optional<cell::Cell>> loaded = cell::LoadCell((kExample / "paper.cell.toml").string(), sources, diags);
    SMTCAL_CHECK(loaded && loaded.value(), "the example cell loads");
    return std::move(*loaded.value());
  }();
  return cell;
}

// Parse and the checks, as `smtcal check` does.
ir::Program ParseAndCheck(std::uint32_t file, Diagnostics& diags) {
  ir::Program program = ParseProgram(file, diags);
  if (!diags.has_errors()) {
    std::vector<const PassInfo*> checks;
    for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
    RunPasses(program, diags, checks, false);
  }
  return program;
}

// A program compiled for the example cell, its LinuxCNC output in `sources`.
struct Emitted {
  ir::Program program;
  MachineTargets plan;  // what the compile planned for every target
  LinuxCncFolderFiles folder;
  std::string main_text;
  std::vector<EmbeddedFile> subroutines;
};

bool Emit(const std::string& text, SourceManager& sources, Diagnostics& diags, Emitted& out) {
  const std::uint32_t file = sources.Add("gen.place", text);
  out.program = ParseAndCheck(file, diags);
  if (diags.has_errors()) return false;
  out.program.compile = std::make_shared<CompileState>();
  out.program.compile->cell = &ExampleCell();
  std::vector<const PassInfo*> corrections;
  for (const PassInfo& info : CorrectionPassRegistry()) corrections.push_back(&info);
  RunPasses(out.program, diags, corrections, false);
  if (diags.has_errors()) return false;
  out.plan = MachineTargets::FromState(*out.program.compile, /*compiled=*/false);
  TextOutput main;
  std::optional<LinuxCncOutput> output = EmitLinuxCnc(out.program, *out.program.compile, "gen.place", main, diags);
  if (!output || diags.has_errors()) return false;
  out.main_text = main.text();
  out.subroutines = output->subroutines;
  out.folder.main = sources.Add("out/gen.ngc", out.main_text);
  out.folder.subroutines_dir = "out/subroutines";
  for (const EmbeddedFile& file : output->subroutines) {
    out.folder.subroutines.emplace_back(file.name, sources.Add("out/subroutines/" + file.name, file.text));
  }
  return true;
}

// A folder of texts (some changed) read back.
struct Read {
  std::unique_ptr<SourceManager> sources = std::make_unique<SourceManager>();
  std::unique_ptr<Diagnostics> diags = std::make_unique<Diagnostics>(*sources);
  std::optional<LinuxCncOutputRead> read;
  bool io_error = false;
};
Read ReadTexts(const std::string& main_text, const std::vector<EmbeddedFile>& subroutines) {
  Read out;
  LinuxCncFolderFiles folder;
  folder.main = out.sources->Add("out/gen.ngc", main_text);
  folder.subroutines_dir = "out/subroutines";
  for (const EmbeddedFile& file : subroutines) {
    folder.subroutines.emplace_back(file.name, out.sources->Add("out/subroutines/" + file.name, file.text));
  }
  Result<std::optional<LinuxCncOutputRead>> read = ReadLinuxCncFolder(folder, *out.sources, *out.diags);
  if (!read) {
    out.io_error = true;
    return out;
  }
  out.read = std::move(read.value());
  return out;
}

// The targets of a compiled program read back (and its commands checked).
MachineTargets TraceRead(const LinuxCncOutputRead& read, ir::Program& program, Diagnostics& diags) {
  program = ParseAndCheck(read.place_file, diags);
  if (diags.has_errors()) return {};
  MachineTargets targets = CompiledProgramTargets(program, read.cell, diags);
  CheckLinuxCncCommands(program, targets, read, diags);
  return targets;
}

// Every statement's targets, in order, the same (kind, fixture, known,
// position to the 10 decimals a program's text holds).
void ExpectSamePlan(const ir::Program& a, const MachineTargets& plan_a, const ir::Program& b,
                    const MachineTargets& plan_b, const std::string& what) {
  const std::vector<const ir::Stmt*> sa = test::Motions(a), sb = test::Motions(b);
  ASSERT_EQ(sa.size(), sb.size()) << what;
  for (std::size_t s = 0; s < sa.size(); ++s) {
    const std::span<const MachineTarget> x = plan_a.Of(sa[s]), y = plan_b.Of(sb[s]);
    ASSERT_EQ(x.size(), y.size()) << what << ": statement " << s << " at line " << sa[s]->loc.line;
    for (std::size_t i = 0; i < x.size(); ++i) {
      SCOPED_TRACE(testing::Message() << what << ": statement " << s << " (line " << sa[s]->loc.line << ") target " << i);
      EXPECT_EQ(x[i].kind, y[i].kind);
      EXPECT_EQ(x[i].fixture, y[i].fixture);
      ASSERT_EQ(x[i].known, y[i].known);
      if (!x[i].known) continue;
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(x[i].position[k], y[i].position[k], 1e-9) << "axis " << k;
    }
  }
}

// The correction data read back are the cell's.
void ExpectSameData(const cell::Cell& cell, const cell::Cell& read) {
  ASSERT_EQ(cell.regions.size(), read.regions.size());
  for (std::size_t r = 0; r < cell.regions.size(); ++r) {
    const cell::Region& a = cell.regions[r];
    const cell::Region& b = read.regions[r];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.x_mm.lo, b.x_mm.lo);
    EXPECT_EQ(a.x_mm.hi, b.x_mm.hi);
    EXPECT_EQ(a.y_mm.lo, b.y_mm.lo);
    EXPECT_EQ(a.y_mm.hi, b.y_mm.hi);
    EXPECT_EQ(a.outside, b.outside);
    for (TableAxis axis : kTableAxes) {
      EXPECT_EQ(a.table[axis].xs, b.table[axis].xs);
      EXPECT_EQ(a.table[axis].ys, b.table[axis].ys);
      EXPECT_EQ(a.table[axis].error_mm, b.table[axis].error_mm);
    }
  }
  ASSERT_EQ(cell.fixtures.size(), read.fixtures.size());
  for (std::size_t k = 0; k < cell.fixtures.size(); ++k) {
    const cell::Fixture& a = cell.fixtures[k];
    const cell::Fixture& b = read.fixtures[k];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.origin_mm, b.origin_mm);
    EXPECT_NEAR(a.angle_deg, b.angle_deg, 1e-12);
    EXPECT_EQ(a.l1_mm, b.l1_mm);
    EXPECT_EQ(a.l2_mm, b.l2_mm);
    EXPECT_EQ(a.estimator, b.estimator);
    EXPECT_EQ(a.trip_window_mm, b.trip_window_mm);
    EXPECT_EQ(a.max_shift_mm, b.max_shift_mm);
    EXPECT_EQ(a.max_rotation_deg, b.max_rotation_deg);
    EXPECT_EQ(a.length_tolerance_mm, b.length_tolerance_mm);
    EXPECT_EQ(a.squareness_deg, b.squareness_deg);
    EXPECT_EQ(a.max_line_residual_mm, b.max_line_residual_mm);
    EXPECT_EQ(a.scan_z_mm, b.scan_z_mm);
    EXPECT_NEAR(a.scan_speed_mm_s, b.scan_speed_mm_s, 1e-12);
    EXPECT_NEAR(a.latch_speed_mm_s, b.latch_speed_mm_s, 1e-12);
    for (std::size_t e = 0; e < 4; ++e) {
      const EdgeLine x = EdgeLineOf(a.edges[e]), y = EdgeLineOf(b.edges[e]);
      EXPECT_LT((x.normal - y.normal).norm(), 1e-12) << "edge " << e;
      EXPECT_NEAR(x.offset, y.offset, 1e-12) << "edge " << e;
    }
    ASSERT_EQ(a.scan_paths.size(), b.scan_paths.size());
    for (std::size_t p = 0; p < a.scan_paths.size(); ++p) {
      ASSERT_EQ(a.scan_paths[p].points.size(), b.scan_paths[p].points.size());
      for (std::size_t i = 0; i < a.scan_paths[p].points.size(); ++i) {
        EXPECT_LT((a.scan_paths[p].points[i] - b.scan_paths[p].points[i]).norm(), 1e-9);
      }
    }
  }
  EXPECT_EQ(cell.robot.safe_limz_mm, read.robot.safe_limz_mm);
}

std::uint64_t FirstSeed() {
  const char* fixed = std::getenv("SMTCAL_TEST_SEED");
  return fixed != nullptr ? std::strtoull(fixed, nullptr, 10) : 1;
}

// read(emit(plan)) == plan, for the LinuxCNC output and the .place output.
TEST(LinuxCncOutput, ReadsBackWhatTheCompilePlannedForEveryTarget) {
  const std::uint64_t first = FirstSeed();
  // 1000 in the ordinary build (the property); 100 under the sanitizers,
  // whose run checks the memory, not the property again (1000 took 169 s).
#if defined(SMTCAL_SANITIZED)
  constexpr int kPrograms = 100;
#else
  constexpr int kPrograms = 1000;
#endif
  const int programs = std::getenv("SMTCAL_TEST_SEED") != nullptr ? 1 : kPrograms;
  int targets = 0;
  for (std::uint64_t seed = first; seed < first + static_cast<std::uint64_t>(programs); ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
    SourceManager sources;
    Diagnostics diags(sources);
    Emitted emitted;
    const std::string text = test::RandomPlaceProgram(seed);
    ASSERT_TRUE(Emit(text, sources, diags, emitted)) << text << "\n" << diags.all().front().message;
    // The LinuxCNC output.
    Result<std::optional<LinuxCncOutputRead>> read = ReadLinuxCncFolder(emitted.folder, sources, diags);
    ASSERT_TRUE(read && read.value()) << (diags.all().empty() ? "" : diags.all().front().message);
    ir::Program read_program;
    const MachineTargets read_plan = TraceRead(*read.value(), read_program, diags);
    ASSERT_FALSE(diags.has_errors()) << diags.all().back().message;
    ExpectSameData(ExampleCell(), read.value()->cell);
    ExpectSamePlan(emitted.program, emitted.plan, read_program, read_plan, "linuxcnc");
    // The .place output.
    const std::uint32_t place = sources.Add("gen.corrected.place", PrintPlace(emitted.program));
    ir::Program place_program = ParseAndCheck(place, diags);
    const MachineTargets place_plan = CompiledProgramTargets(place_program, ExampleCell(), diags);
    ASSERT_FALSE(diags.has_errors());
    ExpectSamePlan(emitted.program, emitted.plan, place_program, place_plan, "place");
    targets += static_cast<int>(emitted.plan.size());
    if (HasFailure()) break;
  }
  RecordProperty("targets", targets);
  std::cout << fmt::format("[round trip] {} programs, {} targets\n", programs, targets);
}

// The example's output, once.
const Emitted& Example() {
  static SourceManager sources;
  static Diagnostics diags(sources);
  static Emitted emitted;
  static const bool ok = Emit(test::ReadFileText(kExample / "layers.place"), sources, diags, emitted);
  SMTCAL_CHECK(ok, "the example compiles");
  return emitted;
}

// The file `name` of the example's output with its line `line` (1-based)
// replaced by `text`.
std::vector<EmbeddedFile> WithLine(const std::string& name, std::size_t line, const std::string& text) {
  std::vector<EmbeddedFile> files = Example().subroutines;
  for (EmbeddedFile& file : files) {
    if (file.name != name) continue;
    std::size_t begin = 0;
    for (std::size_t i = 1; i < line; ++i) begin = file.text.find('\n', begin) + 1;
    const std::size_t end = file.text.find('\n', begin);
    file.text.replace(begin, end - begin, text);
  }
  return files;
}

const EmbeddedFile& FileNamed(const std::string& name) {
  for (const EmbeddedFile& file : Example().subroutines) {
    if (file.name == name) return file;
  }
  SMTCAL_CHECK(false, "a file of the output");
}

std::vector<std::string> LinesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    lines.push_back(text.substr(at, end - at));
    at = end + 1;
  }
  return lines;
}

// The error a changed folder gives: its file and line.
std::optional<std::pair<std::string, std::uint32_t>> ErrorOf(const Read& read) {
  for (const Diagnostic& d : read.diags->all()) {
    if (d.severity != Severity::Error) continue;
    return std::pair{read.sources->File(d.range.begin.file).name, d.range.begin.line};
  }
  return std::nullopt;
}

TEST(LinuxCncOutput, TheExampleReadsBackUnchanged) {
  const Read read = ReadTexts(Example().main_text, Example().subroutines);
  ASSERT_TRUE(read.read.has_value()) << (read.diags->all().empty() ? "" : read.diags->all().front().message);
  EXPECT_FALSE(read.diags->has_errors());
}

// The parameter lines of smtcal_data.ngc (every one that says what it is, a
// tenth of the tables' rows) changed as a hand edit would (a
// whole number by 1, another by 0.001) is refused. Where the line is read on
// its own — a limit, a speed, a derived number (domain, contraction,
// iteration bound), a runtime switch or initial state — at its line, or, a
// value the reader would take as the cell's, at the runtime id's line (then
// no byte may differ from what smtcal wrote). A line the layout or the
// geometry cross-checks (a count, an address, a table's lines and values, an
// edge, a trip, a path point, the nominal pose) may be refused at the line
// the check fails at, in the same file.
TEST(LinuxCncOutput, EveryChangedLineOfTheDataIsAnError) {
  const EmbeddedFile& data = FileNamed("smtcal_data.ngc");
  const std::vector<std::string> lines = LinesOf(data.text);
  std::uint32_t id_line = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].starts_with(L::kRuntimeIdParameter)) id_line = static_cast<std::uint32_t>(i + 1);
  }
  ASSERT_NE(id_line, 0u);
  int at_line = 0, at_id = 0, cross_checked = 0;
  std::string what;  // the last comment: the lines of a table's rows have none
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const std::size_t eq = line.find(" = ");
    if (!line.starts_with('#') || eq == std::string::npos) continue;
    std::size_t end = line.find("  ; ", eq);
    if (end != std::string::npos) what = line.substr(end + 4);
    // Every line that says what it is; of a table's rows, every 10th.
    if (end == std::string::npos && i % 10 != 0) continue;
    if (end == std::string::npos) end = line.size();
    const double value = std::stod(line.substr(eq + 3, end - eq - 3));
    const double changed_value = value == std::floor(value) ? value + 1 : value + 0.001;
    const std::string changed = line.substr(0, eq + 3) + fmt::format("{}", changed_value) + line.substr(end);
    const Read read = ReadTexts(Example().main_text, WithLine("smtcal_data.ngc", i + 1, changed));
    const auto error = ErrorOf(read);
    ASSERT_TRUE(error.has_value()) << "line " << i + 1 << " changed to '" << changed << "' was read";
    EXPECT_EQ(error->first, "out/subroutines/smtcal_data.ngc") << "line " << i + 1;
    if (i + 1 == id_line) continue;
    if (error->second == i + 1 || error->second == id_line) {
      (error->second == i + 1 ? at_line : at_id)++;
      continue;
    }
    ++cross_checked;
    const bool layout_or_geometry =
        what.ends_with(" at") || what.find("count") != std::string::npos || what.find(": n") != std::string::npos ||
        what.find(" lines") != std::string::npos || what.find("values row") != std::string::npos ||
        what.find("edge") != std::string::npos || what.find("nominal") != std::string::npos ||
        what.find("path") != std::string::npos || what.find(": T") != std::string::npos;
    EXPECT_TRUE(layout_or_geometry) << "line " << i + 1 << " ('" << line << "', " << what
                                    << ") changed, the error names line " << error->second;
  }
  EXPECT_GT(at_line, 40);
  std::cout << fmt::format("[data] changed lines refused: {} at their line, {} at the runtime id's, {} where the "
                           "layout or the geometry cross-checks them\n",
                           at_line, at_id, cross_checked);
}

// The switches the issue named, at their lines.
TEST(LinuxCncOutput, TheRuntimesSwitchesAreErrorsAtTheirLines) {
  const std::vector<std::string> lines = LinesOf(FileNamed("smtcal_data.ngc").text);
  for (const auto& [prefix, changed] : std::vector<std::pair<std::string, std::string>>{
           {"#37 = 0", "#37 = 1  ; a failed check aborts"}, {"#56 = ", "#56 = 0"}, {"#55 = ", "#55 = -1"}}) {
    std::size_t line = 0;
    while (line < lines.size() && !lines[line].starts_with(prefix)) ++line;
    ASSERT_LT(line, lines.size()) << prefix;
    const Read read = ReadTexts(Example().main_text, WithLine("smtcal_data.ngc", line + 1, changed));
    const auto error = ErrorOf(read);
    ASSERT_TRUE(error.has_value()) << changed;
    EXPECT_EQ(error->second, line + 1) << changed;
  }
}

// Every line of every other runtime file changed is an error at that line.
TEST(LinuxCncOutput, EveryChangedLineOfTheRuntimeIsAnError) {
  int changed_lines = 0;
  for (const EmbeddedFile& file : Example().subroutines) {
    if (file.name == "smtcal_data.ngc") continue;
    const std::vector<std::string> lines = LinesOf(file.text);
    for (std::size_t i = 0; i < lines.size(); i += 1 + lines.size() / 40) {  // 40 lines of each at most
      const Read read = ReadTexts(Example().main_text, WithLine(file.name, i + 1, lines[i] + " "));
      const auto error = ErrorOf(read);
      ASSERT_TRUE(error.has_value()) << file.name << ":" << i + 1;
      EXPECT_EQ(error->first, "out/subroutines/" + file.name);
      EXPECT_EQ(error->second, i + 1) << file.name;
      ++changed_lines;
    }
  }
  EXPECT_GT(changed_lines, 200);
  // A file missing is an I/O error naming it.
  std::vector<EmbeddedFile> files = Example().subroutines;
  files.erase(files.begin());
  EXPECT_TRUE(ReadTexts(Example().main_text, files).io_error);
}

// The main program: o<pick_place> line by line, and a correction argument.
TEST(LinuxCncOutput, TheMainProgramsRuntimeLinesAreChecked) {
  const std::vector<std::string> lines = LinesOf(Example().main_text);
  std::size_t begin = 0;
  while (begin < lines.size() && lines[begin] != "o<pick_place> sub") ++begin;
  ASSERT_LT(begin, lines.size());
  for (std::size_t i = begin; i < lines.size() && lines[i - 1] != "o<pick_place> endsub"; ++i) {
    std::vector<std::string> changed = lines;
    changed[i] = lines[i].ends_with(')') ? lines[i].substr(0, lines[i].size() - 1) + " x)" : lines[i] + " ";
    std::string text;
    for (const std::string& line : changed) text += line + "\n";
    const Read read = ReadTexts(text, Example().subroutines);
    const auto error = ErrorOf(read);
    ASSERT_TRUE(error.has_value()) << "line " << i + 1 << ": " << changed[i];
    EXPECT_EQ(error->second, i + 1) << changed[i];
  }
  // The runtime check names another runtime.
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].find(" NE ") == std::string::npos || lines[i].find("_smtcal_runtime_id") == std::string::npos) continue;
    std::vector<std::string> changed = lines;
    const std::size_t ne = changed[i].find(" NE ") + 4;
    changed[i].insert(ne, "1");
    std::string text;
    for (const std::string& line : changed) text += line + "\n";
    const auto error = ErrorOf(ReadTexts(text, Example().subroutines));
    ASSERT_TRUE(error.has_value());
    EXPECT_EQ(error->second, i + 1);
  }
  // A placement on the board told to the runtime as a base position: read,
  // and refused once traced, at its line.
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string call = "o<pick_place> call [0] ";
    const std::size_t at = lines[i].find(call);
    if (at == std::string::npos) continue;
    std::vector<std::string> changed = lines;
    changed[i].replace(at, call.size(), "o<pick_place> call [-1] ");
    std::string text;
    for (const std::string& line : changed) text += line + "\n";
    Read read = ReadTexts(text, Example().subroutines);
    ASSERT_TRUE(read.read.has_value());
    ir::Program program;
    TraceRead(*read.read, program, *read.diags);
    const auto error = ErrorOf(read);
    ASSERT_TRUE(error.has_value()) << changed[i];
    EXPECT_EQ(error->second, i + 1);
    break;
  }
}

// Hostile nesting: a Cycle comment repeated 12000 times, blocks and brackets
// nested far deeper than a program: an error at the culprit's line, no crash.
TEST(LinuxCncOutput, NestingIsBoundedAndNamedAtItsLine) {
  const std::vector<std::string> lines = LinesOf(Example().main_text);
  std::size_t cycle = 0;
  for (; cycle < lines.size() && lines[cycle].find("(Cycle Board") == std::string::npos; ++cycle) {
  }
  ASSERT_LT(cycle, lines.size());
  for (const std::size_t copies : {std::size_t{1}, std::size_t{12000}}) {
    std::vector<std::string> changed = lines;
    changed.insert(changed.begin() + static_cast<long>(cycle) + 1, copies, lines[cycle]);
    std::string text;
    for (const std::string& line : changed) text += line + "\n";
    const auto error = ErrorOf(ReadTexts(text, Example().subroutines));
    ASSERT_TRUE(error.has_value());
    EXPECT_EQ(error->second, cycle + 2) << copies << " copies";  // the first copy: a Cycle inside a Cycle
  }
  // 20000 nested ifs, 100000 nested brackets.
  std::vector<std::string> deep = lines;
  std::vector<std::string> ifs;
  for (int d = 0; d < 20000; ++d) ifs.push_back(fmt::format("o{} if [1 LT 2]", 1000 + d));
  for (int d = 19999; d >= 0; --d) ifs.push_back(fmt::format("o{} endif", 1000 + d));
  deep.insert(deep.begin() + static_cast<long>(cycle) + 1, ifs.begin(), ifs.end());
  std::string text;
  for (const std::string& line : deep) text += line + "\n";
  auto error = ErrorOf(ReadTexts(text, Example().subroutines));
  ASSERT_TRUE(error.has_value());
  // The if that opens the 101st block (the function, loop and Cycle are three).
  EXPECT_EQ(error->second, cycle + 2 + 97);
  std::vector<std::string> brackets = lines;
  brackets.insert(brackets.begin() + static_cast<long>(cycle) + 1,
                  "  #<_v_boardstobuild> = " + std::string(100000, '[') + "1" + std::string(100000, ']'));
  text.clear();
  for (const std::string& line : brackets) text += line + "\n";
  error = ErrorOf(ReadTexts(text, Example().subroutines));
  ASSERT_TRUE(error.has_value());
  EXPECT_EQ(error->second, cycle + 2);
}

}  // namespace
}  // namespace smtcal

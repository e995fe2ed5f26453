// smtcal import LIST --cell CELL.toml [--feeders FEEDERS.toml] -o BOARD.place:
// a CAD placement list into a .place program (docs/import.md). The work is in
// frontend/cad_reader (the list), frontend/feeders_toml (which feeder holds
// which part) and passes/cad_to_program (the program); this file wires files,
// options and exit codes.
#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <numbers>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "backend/place/place_printer.h"
#include "backend/reports/import_report.h"
#include "backend/reports/setup_sheet.h"
#include "base/field_text.h"
#include "calibration/limits.h"
#include "calibration/tolerances.h"
#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_text.h"
#include "frontend/cad/cad_to_program.h"
#include "frontend/cell_toml.h"
#include "frontend/feeders_toml.h"
#include "frontend/input_kind.h"
#include "tools/commands.h"
#include "tools/feeders_option.h"

namespace smtcal::tools {
namespace {

struct ImportCliOptions {
  std::string list;
  std::string cell;
  std::string feeders;
  std::string output;
  std::string format;
  std::string units;
  std::string delimiter;
  std::string columns;
  std::string side;
  std::string mirror;
  std::string bottom_positions;
  std::string bottom_rotation = "top-view";
  std::string angles = "signed";
  std::string origin;  // empty: in the fixture's pocket, else centred on its largest calibrated region (BoardSpot)
  std::string board;   // --board W,H or X,Y,W,H: the outline in the list's coordinates
  std::string report;       // --report FILE.json
  std::string setup_sheet;  // --setup-sheet FILE: the feeder set-up sheet as text
  std::string setup_csv;    // --setup-csv FILE: the same as CSV
  std::string setup_svg;    // --setup-svg FILE: the same as a printable page
  std::uint64_t lot_boards = 0;     // --boards N: the lot, for the set-up sheet
  double spares_percent = 2;        // --spares PCT
  double rotation_deg = 0;
  std::string panel = "1x1";
  std::string pitch = "0,0";
  std::optional<double> place_z_mm;  // else the fixture's place_z_mm
  int vacuum = 8;
  bool skip_unmapped = false;
  bool skip_empty_designators = false;
  bool keep_dnp = false;
  bool no_default_excludes = false;
  std::vector<std::string> exclude_designators;
  std::vector<std::string> exclude_packages;
  std::string fixture;
  std::string name;
};

// A path as a shell word: quoted when it holds anything but letters,
// digits and / . _ - + , = : @ (for the command the summary suggests).
std::string ShellWord(const std::string& path) {
  bool plain = !path.empty() && std::all_of(path.begin(), path.end(), [](unsigned char c) {
    return std::isalnum(c) || std::strchr("/._-+,=:@", c) != nullptr;
  });
  if (plain) return path;
  std::string quoted = "'";
  for (char c : path) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string BaseName(const std::string& path) {
  return path == "-" ? "<stdin>" : std::filesystem::path(path).filename().string();
}

// "X,Y" -> two positions in mm (limits::kPositionMm), or why not. Each
// number goes through the one check of base/number_range.h.
Result<std::array<double, 2>> ParsePair(const std::string& text) {
  std::size_t comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos) {
    return Error{"expected X,Y in mm: two numbers with a comma between them and no space, e.g. 10.5,20 or -5,10"};
  }
  Result<double> a = ParseNumberIn(std::string_view(text).substr(0, comma), limits::kPositionMm);
  if (!a) return Error{"X: " + a.error().message};
  Result<double> b = ParseNumberIn(std::string_view(text).substr(comma + 1), limits::kPositionMm);
  if (!b) return Error{"Y: " + b.error().message};
  return std::array<double, 2>{a.value(), b.value()};
}

CLI::Validator PairValidator() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        Result<std::array<double, 2>> pair = ParsePair(text);
        return pair ? std::string() : pair.error().message;
      },
      "");
}

// "W,H" or "X,Y,W,H" -> the outline x0, y0, x1, y1, or why not. X and Y
// are positions (limits::kPositionMm), W and H lengths (limits::kLengthMm),
// each through the one check of base/number_range.h.
Result<std::array<double, 4>> ParseBoard(const std::string& text) {
  std::vector<std::string_view> parts;
  std::string_view rest(text);
  for (;;) {
    const std::size_t comma = rest.find(',');
    parts.push_back(rest.substr(0, comma));
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  if (parts.size() != 2 && parts.size() != 4) {
    return Error{"expected W,H or X,Y,W,H in mm with no spaces, e.g. 16.6,40.1 or -5,0,50,30"};
  }
  const char* names[] = {"X", "Y", "W", "H"};
  std::array<double, 4> numbers{0, 0, 0, 0};
  const std::size_t first = 4 - parts.size();
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::size_t slot = first + k;
    Result<double> number = ParseNumberIn(parts[k], slot < 2 ? limits::kPositionMm : limits::kLengthMm);
    if (!number) return Error{fmt::format("{}: {}", names[slot], number.error().message)};
    numbers[slot] = number.value();
  }
  return std::array<double, 4>{numbers[0], numbers[1], numbers[0] + numbers[2], numbers[1] + numbers[3]};
}

// "CxR" -> columns and rows of a panel, or why not.
Result<std::array<int, 2>> ParsePanel(const std::string& text) {
  std::size_t x = text.find_first_of("xX");
  if (x == std::string::npos) return Error{"expected CxR, e.g. 3x2"};
  Result<WholeNumber> columns = ParseWholeNumberIn(std::string_view(text).substr(0, x), limits::kPalletCount);
  if (!columns) return Error{"C: " + columns.error().message};
  Result<WholeNumber> rows = ParseWholeNumberIn(std::string_view(text).substr(x + 1), limits::kPalletCount);
  if (!rows) return Error{"R: " + rows.error().message};
  const long boards = static_cast<long>(columns.value().magnitude * rows.value().magnitude);
  if (boards > limits::kMaxPanelBoards) {
    return Error{fmt::format("{} boards; a panel has at most {}", boards, limits::kMaxPanelBoards)};
  }
  return std::array<int, 2>{static_cast<int>(columns.value().magnitude), static_cast<int>(rows.value().magnitude)};
}

std::optional<char> ParseDelimiter(const std::string& text) {
  if (text == "comma") return ',';
  if (text == "semicolon") return ';';
  if (text == "tab") return '\t';
  if (text == "space") return ' ';
  return std::nullopt;
}

void UsageError(const std::string& option, const std::string& message) { throw CLI::ValidationError(option, message); }

// Where a board goes without --origin: the centre of the largest calibrated
// region (the first in file order among equals) whose centre lies on the
// fixture, between its markers (0..l1_mm, 0..l2_mm of the fixture frame at
// its nominal pose), in fixture coordinates: a placing area, not a small
// region calibrated under a marker. nullopt when the fixture carries none.
std::optional<std::pair<std::array<double, 2>, std::string>> BoardSpot(const cell::Cell& cell,
                                                                       const cell::Fixture& fixture) {
  const double angle = fixture.angle_deg * std::numbers::pi / 180.0;
  std::optional<std::pair<std::array<double, 2>, std::string>> spot;
  double largest = 0;
  for (const cell::Region& region : cell.regions) {
    const double dx = (region.x_mm.lo + region.x_mm.hi) / 2 - fixture.origin_mm.x();
    const double dy = (region.y_mm.lo + region.y_mm.hi) / 2 - fixture.origin_mm.y();
    const double fx = std::cos(angle) * dx + std::sin(angle) * dy;
    const double fy = -std::sin(angle) * dx + std::cos(angle) * dy;
    const double area = (region.x_mm.hi - region.x_mm.lo) * (region.y_mm.hi - region.y_mm.lo);
    if (fx >= 0 && fx <= fixture.l1_mm && fy >= 0 && fy <= fixture.l2_mm && area > largest) {
      largest = area;
      spot = std::make_pair(std::array<double, 2>{fx, fy}, fmt::format("region '{}'", region.name));
    }
  }
  return spot;
}

// The fixture the board is on: --fixture, or the cell's only one.
const cell::Fixture* ChooseFixture(const cell::Cell& cell, const std::string& wanted, Diagnostics& diags) {
  const SourceRange cell_start(SourceLoc{cell.file, 1, 1});
  std::vector<std::string> names;
  for (const cell::Fixture& fixture : cell.fixtures) names.push_back(fmt::format("'{}'", fixture.name));
  std::string list = fmt::format("{}", fmt::join(names, ", "));
  if (!wanted.empty()) {
    if (const cell::Fixture* fixture = cell.FindFixture(wanted)) return fixture;
    std::vector<std::string> plain;
    for (const cell::Fixture& fixture : cell.fixtures) plain.push_back(fixture.name);
    std::string closest = ClosestName(wanted, plain);
    if (cell.fixtures.empty()) {
      diags.Report(DiagKind::ImportNoFixture, cell_start);
    } else {
      diags.Report(DiagKind::ImportUnknownFixture, cell.fixtures.front().name_range, Printable(wanted),
                   closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest), list);
    }
    return nullptr;
  }
  if (cell.fixtures.size() == 1) return &cell.fixtures.front();
  if (cell.fixtures.empty()) {
    diags.Report(DiagKind::ImportNoFixture, cell_start);
  } else {
    diags.Report(DiagKind::ImportChooseFixture, cell.fixtures.front().name_range, cell.fixtures.size(), list);
  }
  return nullptr;
}

cad::ReadOptions MakeReadOptions(const ImportCliOptions& opt) {
  cad::ReadOptions read;
  read.skip_empty_designators = opt.skip_empty_designators;
  if (!opt.format.empty()) read.format = cad::FormatFromName(opt.format);
  if (!opt.units.empty()) read.units = cad::UnitFromName(opt.units);
  if (!opt.delimiter.empty()) read.delimiter = ParseDelimiter(opt.delimiter);
  if (!opt.columns.empty()) {
    if (read.format != cad::Format::kGenericCsv) UsageError("--columns", "--columns is for --format csv");
    if (std::optional<std::string> error = cad::ParseColumnMapping(opt.columns, read.mapping)) {
      UsageError("--columns", *error);
    }
  } else if (read.format == cad::Format::kGenericCsv) {
    UsageError("--format", "--format csv needs --columns, e.g. --columns designator=Ref,x=X,y=Y,rotation=Rot");
  }
  // A list without a side column holds the side asked for; Eagle's bottom
  // list is the .mnb file.
  std::string lower = opt.list;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (opt.side == "bottom" || (opt.side.empty() && lower.ends_with(".mnb"))) {
    read.side_without_column = cad::Side::kBottom;
  }
  return read;
}

ImportOptions MakeImportOptions(const ImportCliOptions& opt, const cell::Fixture& fixture) {
  ImportOptions import;
  if (!opt.side.empty()) import.side = opt.side == "top" ? cad::Side::kTop : cad::Side::kBottom;
  std::string lower = opt.list;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (opt.side.empty() && lower.ends_with(".mnb")) import.side = cad::Side::kBottom;
  if (opt.mirror == "none") import.mirror = ImportMirror::kNone;
  if (opt.mirror == "x") import.mirror = ImportMirror::kX;
  if (opt.mirror == "y") import.mirror = ImportMirror::kY;
  if (opt.bottom_positions == "top-view") import.bottom_positions = cad::BottomPositions::kTopView;
  if (opt.bottom_positions == "negated-x") import.bottom_positions = cad::BottomPositions::kNegatedX;
  import.bottom_rotation = opt.bottom_rotation == "bottom-view" ? BottomRotation::kBottomView : BottomRotation::kTopView;
  import.angles = opt.angles == "positive" ? AngleRange::kPositive : AngleRange::kSigned;
  std::array<double, 2> origin = opt.origin.empty() ? std::array<double, 2>{0, 0} : ParsePair(opt.origin).value();
  if (!opt.board.empty()) import.board = ParseBoard(opt.board).value();
  if (fixture.pocket_mm) {
    const auto& [x, y] = *fixture.pocket_mm;
    import.pocket = std::array<double, 4>{x.lo, y.lo, x.hi, y.hi};
    import.pocket_range = fixture.pocket_range;
  }
  import.keep_fates = !opt.report.empty();
  std::array<double, 2> pitch = ParsePair(opt.pitch).value();
  import.origin_given = !opt.origin.empty();
  std::array<int, 2> panel = ParsePanel(opt.panel).value();
  import.origin_x_mm = origin[0];
  import.origin_y_mm = origin[1];
  import.rotation_deg = opt.rotation_deg;
  import.columns = panel[0];
  import.rows = panel[1];
  import.pitch_x_mm = pitch[0];
  import.pitch_y_mm = pitch[1];
  import.place_z_mm = opt.place_z_mm.value_or(fixture.place_z_mm.value_or(0.0));
  import.vacuum = opt.vacuum;
  import.skip_unmapped = opt.skip_unmapped;
  import.keep_dnp = opt.keep_dnp;
  import.default_excludes = !opt.no_default_excludes;
  import.exclude_designators = opt.exclude_designators;
  import.exclude_packages = opt.exclude_packages;
  import.fixture = fixture.name;
  std::string stem = opt.name;
  if (stem.empty()) {
    const std::string& from = opt.output != "-" ? opt.output : opt.list;
    stem = from == "-" ? "Imported" : std::filesystem::path(from).stem().string();
  }
  import.program_name = MakeIdentifier(stem);
  return import;
}

void RunImport(const ImportCliOptions& opt, GlobalOptions& options) {
  cad::ReadOptions read = MakeReadOptions(opt);  // usage errors first, before any file is read
  if (FilesClash({{"LIST", opt.list}, {"--cell", opt.cell}, {"--feeders", opt.feeders}},
                 {{"-o", opt.output},
                  {"--report", opt.report},
                  {"--setup-sheet", opt.setup_sheet},
                  {"--setup-csv", opt.setup_csv},
                  {"--setup-svg", opt.setup_svg}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(opt.cell, sources, diags);
  if (!loaded) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(loaded.error());
    return;
  }
  std::optional<cell::Cell> cell = std::move(loaded).value();
  const cell::Fixture* fixture = cell ? ChooseFixture(*cell, opt.fixture, diags) : nullptr;
  cad::FeedersFile feeders_file;
  if (!LoadFeedersOption(opt.feeders, sources, diags, feeders_file, options)) return;
  if (fixture != nullptr && !opt.place_z_mm && !fixture->place_z_mm) {
    diags.Report(DiagKind::ImportNoPlaceZ, fixture->name_range, fixture->name);
  }
  if (!cell || fixture == nullptr || diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  std::optional<cad::FeederTable> feeders = cad::FeederTable::Build(cell->feeders, std::move(feeders_file), diags);
  Result<std::uint32_t> list = sources.Load(opt.list);
  if (!list) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(list.error());
    return;
  }
  if (ReportOtherInputKind(list.value(), {InputKind::kCadList}, "a CAD placement list", diags)) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  cad::TextEncoding encoding = cad::TextEncoding::kUtf8;
  std::optional<std::uint32_t> list_file = cad::DecodeList(list.value(), sources, diags, encoding);
  std::unique_ptr<cad::ListReader> reader = list_file ? cad::OpenList(*list_file, read, diags) : nullptr;
  if (!feeders || !reader) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }

  ImportOptions import = MakeImportOptions(opt, *fixture);
  import.encoding = encoding;
  if (auto spot = BoardSpot(*cell, *fixture)) {
    import.centre_spot = spot->first;
    import.centre_spot_name = spot->second;
  }
  import.cell = &*cell;
  import.cell_fixture = fixture;
  const std::string place_z_source =
      opt.place_z_mm ? std::string("--place-z") : fmt::format("place_z_mm of fixture {}", fixture->name);
  const double place_z = import.place_z_mm;
  import.header_lines = {
      fmt::format("Imported by smtcal import from {} ({}, {}{}).", BaseName(opt.list),
                  cad::FormatTitle(reader->format()), cad::UnitName(reader->unit()),
                  encoding == cad::TextEncoding::kUtf8 ? "" : fmt::format(", {} text", cad::EncodingName(encoding))),
      fmt::format("Cell {}, fixture {}{}.", BaseName(opt.cell), fixture->name,
                  opt.feeders.empty() ? "" : ", feeders " + BaseName(opt.feeders)),
      "To change it, change the list, the cell, the feeders or the options and import again.",
  };
  CadImporter importer(*feeders, std::move(import), *list_file, diags);
  cad::Row row;
  while (reader->Next(row)) importer.Add(row);
  std::optional<ir::Program> program = importer.Finish(*reader);
  options.exit_code = PrintDiagnostics(diags, options);
  std::string summary = FormatImportSummary(importer.summary());
  if (program) {
    const ImportSummary& s = importer.summary();
    summary += fmt::format("  board:   outline {}\n           origin ({}, {}) mm in fixture {}: {}\n"
                           "  place:   at z = {} mm ({})\n",
                           s.outline, s.origin_x_mm, s.origin_y_mm, fixture->name, s.origin_how, place_z,
                           place_z_source);
  }
  if (options.exit_code != kExitOk || !program) {
    SaySummary(summary);
    options.exit_code = kExitInputError;
    return;  // nothing half-written
  }
  // Every output is staged first, complete, beside its file, and then all
  // are renamed into place: a run that cannot write one writes none.
  std::vector<std::pair<std::string, std::string>> outputs = {{opt.output, PrintPlace(*program)}};
  if (!opt.report.empty()) {
    outputs.emplace_back(opt.report, ImportReportJson(importer.summary(), importer.fates(), BaseName(opt.list)));
  }
  SetupSheet sheet = importer.setup_sheet();
  sheet.lot_boards = opt.lot_boards;
  sheet.spares_percent = opt.spares_percent;
  if (!opt.setup_sheet.empty()) outputs.emplace_back(opt.setup_sheet, SetupSheetText(sheet));
  if (!opt.setup_csv.empty()) outputs.emplace_back(opt.setup_csv, SetupSheetCsv(sheet));
  if (!opt.setup_svg.empty()) outputs.emplace_back(opt.setup_svg, SetupSheetSvg(sheet));
  Status written = WriteFilesAtomically(outputs);
  if (!written) {
    SaySummary(summary);
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (opt.output != "-") {
    summary += fmt::format("  next:    smtcal verify {} --cell {}\n", ShellWord(opt.output), ShellWord(opt.cell));
  }
  SaySummary(summary);
}

}  // namespace

void AddImportCommand(CLI::App& app, GlobalOptions& options) {
  static ImportCliOptions opt;
  CLI::App* cmd = app.add_subcommand(
      "import", "Turn a CAD placement list (KiCad, Altium, Eagle, JLCPCB, DipTrace, CSV) into a .place program\n"
                "that picks every part from its feeder and places it on the fixture's board (docs/import.md)");
  cmd->add_option("LIST", opt.list, "the placement list ('-' for stdin); its format is detected from the content")
      ->required();
  cmd->add_option("--cell", opt.cell, "the cell file: the fixture and the feeders")->required();
  cmd->add_option("--feeders", opt.feeders, "a feeders file: more feeders and [[map]] rules (package, value, designator)");
  cmd->add_option("-o,--output", opt.output, "the .place program to write ('-' for stdout)")->required();

  // The list.
  cmd->add_option("--format", opt.format, "the list's format when detection is not wanted")
      ->check(CLI::IsMember(std::vector<std::string>(std::begin(cad::kFormatNames), std::end(cad::kFormatNames))));
  cmd->add_option("--columns", opt.columns,
                  "for --format csv: KEY=COLUMN,... with keys designator, x, y (needed) and rotation, value,\n"
                  "package, side, dnp; columns by header name or 1-based number (then there is no header)");
  cmd->add_option("--units", opt.units, "unit of lengths the list writes without one and does not state: mm, mil, in "
                                        "(default mm)")
      ->check(CLI::IsMember({"mm", "mil", "in"}));
  cmd->add_option("--delimiter", opt.delimiter, "field separator: comma, semicolon, tab or space (default: from the "
                                                "header line)")
      ->check(CLI::IsMember({"comma", "semicolon", "tab", "space"}));

  // Which parts.
  cmd->add_option("--side", opt.side,
                  "the side to place: top or bottom (default: the only side the list has parts on; a list\n"
                  "without a side column is on this side, Eagle's .mnb on the bottom)")
      ->check(CLI::IsMember({"top", "bottom"}));
  cmd->add_flag("--skip-empty-designators", opt.skip_empty_designators,
                "leave out rows without a designator (each is reported) instead of failing");
  cmd->add_flag("--skip-unmapped", opt.skip_unmapped, "leave out parts no feeder holds (each is listed) instead of "
                                                      "failing");
  cmd->add_flag("--keep-dnp", opt.keep_dnp, "place parts a DNP column or a DNP/DNF value marks do-not-place");
  cmd->add_option("--exclude-designator", opt.exclude_designators, "leave out parts whose designator matches (glob, "
                                                                   "any case; repeatable)");
  cmd->add_option("--exclude-package", opt.exclude_packages, "leave out parts whose package matches (glob; repeatable)");
  cmd->add_flag("--no-default-excludes", opt.no_default_excludes,
                "place fiducials and mounting holes too (by default designators FID* and packages\n"
                "*Fiducial*, *MountingHole* are left out)");

  // Where the board is.
  cmd->add_option("--fixture", opt.fixture, "the cell fixture the board is on (default: the cell's only fixture)");
  cmd->add_option("--origin", opt.origin,
                  fmt::format("X,Y: the board origin in the fixture frame, mm, e.g. -5,10 (each {}; default: the "
                              "board's outline\nin the fixture's pocket, else centred on its largest calibrated region, "
                              "else 0,0)",
                              RangeText(limits::kPositionMm)))
      ->check(PairValidator())
      ->type_name("X,Y");
  cmd->add_option("--board", opt.board,
                  fmt::format("W,H or X,Y,W,H: the board's outline in the list's coordinates seen from the top, mm\n"
                              "(its lower left corner X,Y, default 0,0: where KiCad's drill/place file origin is when\n"
                              "it was put on that corner; X, Y each {}; W, H each {}); a part outside it is an error\n"
                              "(default: the parts' bounding box)",
                              RangeText(limits::kPositionMm), RangeText(limits::kLengthMm)))
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            Result<std::array<double, 4>> board = ParseBoard(text);
            return board ? std::string() : board.error().message;
          },
          ""))
      ->type_name("W,H");
  AddNumberOption(*cmd, "--rotation", opt.rotation_deg, "the board's x axis against the fixture's, degrees (default 0)",
                  limits::kAngleDeg);
  cmd->add_option("--mirror", opt.mirror,
                  "the board coordinate that changes sign: none, x or y (default: none for the top side, x for\n"
                  "the bottom side, the board turned over about its y axis)")
      ->check(CLI::IsMember({"none", "x", "y"}));
  cmd->add_option("--bottom-positions", opt.bottom_positions,
                  "how the list gives bottom-side x: top-view (as seen from the top) or negated-x (as seen\n"
                  "from the bottom: KiCad 6 and older, KiCad's 'negative X'); default: detected, and the\n"
                  "summary says what was applied and why")
      ->check(CLI::IsMember({"top-view", "negated-x"}));
  cmd->add_option("--bottom-rotation", opt.bottom_rotation,
                  "how the list gives bottom-side rotations: top-view (as seen through the board from the top,\n"
                  "mirrored with the positions) or bottom-view (as seen from below, kept)")
      ->check(CLI::IsMember({"top-view", "bottom-view"}))
      ->capture_default_str();
  cmd->add_option("--panel", opt.panel,
                  fmt::format("CxR: a panel of C columns and R rows of boards (default 1x1; each {}, at most {} "
                              "boards)",
                              RangeText(limits::kPalletCount), limits::kMaxPanelBoards))
      ->check(CLI::Validator(
          [](const std::string& text) {
            Result<std::array<int, 2>> panel = ParsePanel(text);
            return panel ? std::string() : panel.error().message;
          },
          ""))
      ->type_name("CxR");
  cmd->add_option("--pitch", opt.pitch,
                  fmt::format("DX,DY: the distance between the panel's boards along its x and y, mm (each {})",
                              RangeText(limits::kPositionMm)))
      ->check(PairValidator())
      ->type_name("X,Y");
  AddNumberOption(*cmd, "--place-z", opt.place_z_mm,
                  "z of the placements, mm: the robot z of the board's top (default: the fixture's place_z_mm\n"
                  "in the cell; without either it is an error)",
                  limits::kPositionMm);

  // The program.
  AddNumberOption(*cmd, "--vacuum", opt.vacuum, "the gripper's vacuum output, the program's Vacuum (default 8)",
                  limits::kVacuumOutput)
      ->capture_default_str();
  cmd->add_option("--angles", opt.angles, "rotations in the program: signed (-180..180) or positive (0..360)")
      ->check(CLI::IsMember({"signed", "positive"}))
      ->capture_default_str();
  cmd->add_option("--name", opt.name, "the program's name (default: from the output file's name)");
  cmd->add_option("--report", opt.report, "write the import report: every row of the list and what became of it (JSON)");
  cmd->add_option("--setup-sheet", opt.setup_sheet,
                  "write the feeder set-up sheet, which part goes in which feeder, lane or pocket, as a text table");
  cmd->add_option("--setup-csv", opt.setup_csv, "write the feeder set-up sheet as CSV");
  cmd->add_option("--setup-svg", opt.setup_svg, "write the feeder set-up sheet as a printable SVG page");
  AddNumberOption(*cmd, "--boards", opt.lot_boards,
                  "the lot's boards, for the set-up sheet: each slot's parts for the lot (a panel's boards a cycle) "
                  "and its spares",
                  limits::kLotBoards);
  AddNumberOption(*cmd, "--spares", opt.spares_percent,
                  "the set-up sheet's spares per slot with --boards, percent of the lot's parts, rounded up",
                  limits::kSparesPercent)
      ->capture_default_str();
  cmd->footer(
      "Every row becomes a placement or a diagnostic at its line; the summary on stderr counts rows\n"
      "read, placed and skipped by reason. Exit codes: 0 ok, 1 errors in the list, the cell or the\n"
      "feeders, 2 bad command line, 3 a file could not be read or written.");
  cmd->callback([&options] { RunImport(opt, options); });
}

}  // namespace smtcal::tools

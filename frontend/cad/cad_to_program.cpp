// From CAD rows to a .place program (see cad_to_program.h).
//
// Assumes: rows as the readers give them (lengths in mm, rotations in
// degrees as the list writes them), a feeder table whose rules are resolved,
// options checked by the command line (|rotation| <= 360, columns and rows
// >= 1, a valid program name, a fixture of the cell).
// Guarantees: every row ends as a placement or a diagnostic at its line;
// the program it returns passes the IR verifier and, printed, is canonical
// and clean under the check passes (names unique and valid, every point's
// frame declared, pallets 0..15, rotations within one turn).
#include "frontend/cad/cad_to_program.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <unordered_map>

#include <fmt/format.h>

#include "base/field_text.h"
#include "calibration/fixture_geometry.h"
#include "calibration/limits.h"
#include "calibration/region_fit.h"
#include "calibration/tolerances.h"
#include "frontend/cad/cad_bottom.h"
#include "frontend/cad/cad_text.h"

namespace smtcal {
namespace {

// The .place keywords (docs/language.md, "Lexical rules"); a name may not be one.
constexpr std::string_view kKeywords[] = {
    "and",   "call",  "cycle", "else",   "elseif", "endcycle", "endif",   "exit",  "fend",  "fixture", "for",
    "function", "go", "if",    "in",     "integer", "jump",    "limz",    "local", "mod",   "move",    "next",
    "not",   "off",   "on",    "or",     "pallet", "pick",     "place",   "point", "program", "real",  "scan",
    "step",  "sw",    "taught", "then",  "to",     "units",    "vacuum",  "wait",  "xor",   "xy"};

bool IsKeyword(std::string_view name) {
  std::string lower = AsciiLowercase(name);
  return std::find(std::begin(kKeywords), std::end(kKeywords), lower) != std::end(kKeywords);
}

// Text for a comment: one line, no control characters, valid UTF-8, no
// trailing blanks (the canonical form drops them).
std::string CommentText(std::string_view text) {
  if (std::all_of(text.begin(), text.end(), [](char c) { return c >= 0x20 && c < 0x7f; })) {
    std::string out(text);  // the common case: printable ASCII
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out;
  }
  std::string out = Printable(text);
  // Printable shows control bytes as \xNN; a tab or line end in a value
  // reads better as a space.
  for (std::string_view control : {"\\x09", "\\x0a", "\\x0d"}) {
    for (std::size_t at; (at = out.find(control)) != std::string::npos;) out.replace(at, control.size(), " ");
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

double Round(double value, double resolution) {
  const double scale = std::round(1.0 / resolution);
  double rounded = std::round(value * scale) / scale;
  return rounded == 0 ? 0.0 : rounded;  // no -0.0
}

// A length for messages and the summary: rounded to the list's resolution,
// in its shortest form (372.21, not 372.21000000000004).
std::string FormatLength(double mm) { return fmt::format("{}", Round(mm, kCadResolutionMm)); }

double NormaliseAngle(double degrees, AngleRange range) {
  double u = std::fmod(degrees, 360.0);
  if (range == AngleRange::kPositive) {
    if (u < 0) u += 360.0;
    if (Round(u, kCadResolutionDeg) >= 360.0) u = 0;
  } else {
    if (u <= -180.0) u += 360.0;
    if (u > 180.0) u -= 360.0;
    if (Round(u, kCadResolutionDeg) <= -180.0) u = 180.0;
  }
  return Round(u, kCadResolutionDeg);
}

// Values and packages that mean "do not place" (any case).
bool IsDnpValue(std::string_view value) {
  std::string lower = AsciiLowercase(value);
  for (std::string_view mark : {"dnp", "dnf", "dni", "nf", "np", "nopop", "no pop", "do not place",
                                "do not populate", "do not fit", "not fitted", "not populated"}) {
    if (lower == mark) return true;
  }
  return false;
}

// Pallets are numbered from 1, as a person numbers feeder banks (SPEL+'s
// pallet 0 is left free).
constexpr int kFirstPallet = 1;

// The exclusions smtcal makes unless told otherwise: fiducials and
// mounting holes are not parts a robot picks.
const std::vector<std::string> kDefaultExcludedDesignators = {"FID*"};
const std::vector<std::string> kDefaultExcludedPackages = {"*Fiducial*", "*MountingHole*"};

ir::StmtPtr MakeStmt(SourceLoc loc, auto node, std::string comment = {}) {
  auto stmt = std::make_unique<ir::Stmt>();
  stmt->loc = loc;
  stmt->node = std::move(node);
  stmt->trailing_comment = std::move(comment);
  return stmt;
}

ir::StmtPtr CommentStmt(SourceLoc loc, std::string_view text, bool blank_before = false) {
  ir::StmtPtr stmt = MakeStmt(loc, ir::Comment{text.empty() ? std::string() : " " + CommentText(text)});
  stmt->blank_line_before = blank_before;
  return stmt;
}

ir::Coords MakeCoords(SourceLoc loc, std::array<double, 4> values) {
  ir::Coords coords;
  coords.loc = loc;
  coords.values = values;
  return coords;
}

ir::ExprPtr IntLit(SourceLoc loc, int value) {
  auto expr = std::make_unique<ir::Expr>();
  expr->loc = loc;
  expr->length = static_cast<std::uint32_t>(std::to_string(value).size());
  expr->node = ir::NumberLit{static_cast<double>(value), true};
  return expr;
}

// What a name in the program is, described only when a collision is
// reported (building a sentence per part would dominate a large import).
struct NameOwner {
  std::string_view what;  // "the fixture", "the pick point of feeder", "the point of"
  std::string_view name;  // the feeder or designator (empty for the others)
  std::uint32_t line = 0;  // the part's line
  std::string Describe() const {
    if (name.empty()) return std::string(what);
    std::string text = fmt::format("{} '{}'", what, Printable(name));
    if (line != 0) text += fmt::format(" (line {})", line);
    return text;
  }
};

// Unique names in the program's one namespace (case-insensitive). An open-
// addressing table over the names as written: a large import makes one name
// per part and board, and a node-based map's allocation per name would cost
// more than the rest of building the program.
class NameTable {
 public:
  explicit NameTable(std::size_t expected) {
    std::size_t slots = 64;
    while (slots < 2 * expected) slots *= 2;
    slots_.assign(slots, kEmpty);
    entries_.reserve(expected);
  }

  // `wanted` if free, else wanted_2, wanted_3, ...; `taken_by` tells who
  // had `wanted`. The next suffix to try is kept per wanted name, so n
  // parts with one designator cost n claims, not n^2 / 2.
  std::string Claim(const std::string& wanted, NameOwner owner, std::optional<NameOwner>* taken_by = nullptr) {
    if (const NameOwner* existing = Insert(wanted, owner)) {
      if (taken_by != nullptr) *taken_by = *existing;
      int& next = next_suffix_[AsciiLowercase(wanted)];
      for (int k = std::max(next, 2);; ++k) {
        std::string name = fmt::format("{}_{}", wanted, k);
        if (Insert(name, owner) == nullptr) {
          next = k + 1;
          return name;
        }
      }
    }
    return wanted;
  }

 private:
  static constexpr std::uint32_t kEmpty = 0xffffffff;
  struct Entry {
    std::string name;
    NameOwner owner;
  };

  static std::size_t Hash(std::string_view name) {
    std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
    for (char c : name) hash = (hash ^ static_cast<unsigned char>(AsciiLower(c))) * 1099511628211ull;
    return static_cast<std::size_t>(hash);
  }
  static bool Same(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (AsciiLower(a[i]) != AsciiLower(b[i])) return false;
    }
    return true;
  }

  // Adds `name`, or returns the owner that already has it.
  const NameOwner* Insert(const std::string& name, const NameOwner& owner) {
    if (2 * (entries_.size() + 1) > slots_.size()) Grow();
    std::size_t mask = slots_.size() - 1;
    for (std::size_t slot = Hash(name) & mask;; slot = (slot + 1) & mask) {
      if (slots_[slot] == kEmpty) {
        slots_[slot] = static_cast<std::uint32_t>(entries_.size());
        entries_.push_back({name, owner});
        return nullptr;
      }
      const Entry& entry = entries_[slots_[slot]];
      if (Same(entry.name, name)) return &entry.owner;
    }
  }

  void Grow() {
    slots_.assign(slots_.size() * 2, kEmpty);
    std::size_t mask = slots_.size() - 1;
    for (std::uint32_t e = 0; e < entries_.size(); ++e) {
      std::size_t slot = Hash(entries_[e].name) & mask;
      while (slots_[slot] != kEmpty) slot = (slot + 1) & mask;
      slots_[slot] = e;
    }
  }

  std::vector<std::uint32_t> slots_;
  std::vector<Entry> entries_;
  std::unordered_map<std::string, int> next_suffix_;  // per wanted name (lower case): the suffix to try first
};

// 'text' for a message, or "none" when the list gives none.
std::string Quoted(std::string_view text) {
  return text.empty() ? std::string("none") : fmt::format("'{}'", Printable(text));
}

// "C1 10uF C_0805_2012Metric": what a part is, for its trailing comments.
template <typename Part>
std::string PartComment(const Part& part) {
  std::string text = CommentText(part.designator);
  for (const std::string* field : {&part.value, &part.package}) {
    std::string more = CommentText(*field);
    if (!more.empty()) text += " " + more;
  }
  return text;
}

}  // namespace

std::string MakeIdentifier(std::string_view text) {
  std::string name;
  for (char c : text) {
    bool word = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    // A multi-byte UTF-8 character becomes one '_', not one per byte.
    if (!word && (static_cast<unsigned char>(c) & 0xc0) == 0x80) continue;
    name += word ? c : '_';
  }
  if (name.empty() || (name.front() >= '0' && name.front() <= '9')) name.insert(name.begin(), '_');
  if (IsKeyword(name)) name += '_';
  return name;
}

std::string_view SkipReasonName(SkipReason reason) {
  switch (reason) {
    case SkipReason::kOtherSide: return "on the other side";
    case SkipReason::kDnp: return "do-not-place";
    case SkipReason::kExcluded: return "excluded";
    case SkipReason::kUnmapped: return "no feeder";
    case SkipReason::kNoDesignator: return "no designator";
    case SkipReason::kCount: break;
  }
  return "?";
}

namespace {

// "C3, C4, C5, ..." wrapped to lines of at most kSummaryWidth columns, each
// continuation line indented by `indent` spaces.
constexpr std::size_t kSummaryWidth = 100;
std::string WrappedNames(const std::vector<std::string>& names, std::size_t first_column, std::size_t indent) {
  std::string text;
  std::size_t column = first_column;
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string item = names[i] + (i + 1 < names.size() ? "," : "");
    if (i > 0) {
      if (column + 1 + item.size() > kSummaryWidth) {
        text += "\n" + std::string(indent, ' ');
        column = indent;
      } else {
        text += ' ';
        ++column;
      }
    }
    text += item;
    column += item.size();
  }
  return text;
}

}  // namespace

std::string FormatImportSummary(const ImportSummary& s) {
  std::string text = fmt::format("import: {} row{} read ({})", s.rows_read, s.rows_read == 1 ? "" : "s", s.format);
  if (s.rows_with_errors > 0) text += fmt::format(", {} with errors", s.rows_with_errors);
  text += '\n';
  if (s.encoding == cad::TextEncoding::kWindows1252) {
    text += "  note:    the list is not UTF-8, so it was read as Windows-1252 (as Altium on Windows writes it);\n"
            "           check that its letters beyond ASCII (µ, °, ±) read right in the program's comments\n";
  }
  if (s.failed) {
    text += "  placed:  nothing (see the errors above)\n";
  } else {
    text += fmt::format("  placed:  {} part{}", s.parts_placed, s.parts_placed == 1 ? "" : "s");
    if (s.boards > 1) text += fmt::format(" on each of {} boards ({} placements)", s.boards, s.parts_placed * s.boards);
    text += fmt::format(" from {} feeder{}\n", s.feeders_used, s.feeders_used == 1 ? "" : "s");
  }
  std::size_t skipped = 0;
  std::string reasons;
  for (int r = 0; r < static_cast<int>(SkipReason::kCount); ++r) {
    if (s.skipped[r] == 0) continue;
    skipped += s.skipped[r];
    reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", s.skipped[r], SkipReasonName(static_cast<SkipReason>(r)));
  }
  text += fmt::format("  skipped: {}{}\n", skipped, reasons.empty() ? "" : " (" + reasons + ")");
  // Every row left out, named, by reason and rule; the other side's rows
  // are a job of their own, one line.
  for (const SkipGroup& group : s.skip_groups) {
    const std::size_t n = group.names.size();
    const bool lines = group.reason == SkipReason::kNoDesignator;
    if (group.reason == SkipReason::kOtherSide) {
      text += fmt::format("    {}: {} part{}\n", group.why, n, n == 1 ? "" : "s");
      continue;
    }
    // "    <rule>, 3 parts: C1, C2, C3" when that fits a line; else the
    // names start on the next line, and wrap there.
    const std::string head = fmt::format("    {}, {} {}{}:", group.why, n, lines ? "row" : "part", n == 1 ? "" : "s");
    const std::string names = WrappedNames(group.names, 6, 6);
    const bool one_line = names.find('\n') == std::string::npos && head.size() + 1 + names.size() <= kSummaryWidth;
    text += head + (one_line ? " " : "\n      ") + names + "\n";
  }
  if (!s.bottom.empty()) text += fmt::format("  bottom:  {}\n", s.bottom);
  return text;
}

CadImporter::CadImporter(const cad::FeederTable& feeders, ImportOptions options, std::uint32_t list_file,
                         Diagnostics& diags)
    : feeders_(feeders), options_(std::move(options)), list_file_(list_file), diags_(diags) {
  summary_.boards = static_cast<std::size_t>(options_.columns) * static_cast<std::size_t>(options_.rows);
}

bool CadImporter::Classify(const cad::Row& row, Part& part) {
  if (!options_.keep_dnp && (row.dnp || IsDnpValue(row.value))) {
    part.skip = SkipReason::kDnp;
    part.skip_detail = static_cast<int>(skip_details_.size());
    skip_details_.push_back({row.dnp ? "the DNP column" : fmt::format("its value '{}'", Printable(row.value))});
    part.skip_range = row.dnp ? row.dnp_range : row.value_range;
    return true;
  }
  auto match = [&](const std::vector<std::string>& patterns, std::string_view field, std::string_view text,
                   const SourceRange& range, std::string_view rule) {
    for (const std::string& pattern : patterns) {
      if (!cad::GlobMatch(pattern, text)) continue;
      part.skip = SkipReason::kExcluded;
      part.skip_detail = static_cast<int>(skip_details_.size());
      skip_details_.push_back({std::string(field), Printable(text), std::string(rule), Printable(pattern)});
      part.skip_range = range;
      return true;
    }
    return false;
  };
  if (match(options_.exclude_designators, "designator", row.designator, row.designator_range, "--exclude-designator") ||
      match(options_.exclude_packages, "package", row.package, row.package_range, "--exclude-package")) {
    return true;
  }
  if (!options_.default_excludes) return false;
  return match(kDefaultExcludedDesignators, "designator", row.designator, row.designator_range,
               "the default exclusion") ||
         match(kDefaultExcludedPackages, "package", row.package, row.package_range, "the default exclusion");
}

std::optional<cad::FeederMatch> CadImporter::FindFeeder(const cad::Row& row) {
  if (feeders_.matches_designators()) return feeders_.Find(row);
  cache_key_.assign(row.package);
  cache_key_ += '\0';
  cache_key_ += row.value;
  auto it = feeder_cache_.find(cache_key_);
  if (it != feeder_cache_.end()) return it->second;
  std::optional<cad::FeederMatch> match = feeders_.Find(row);
  feeder_cache_.emplace(cache_key_, match);
  return match;
}

void CadImporter::Add(const cad::Row& row) {
  Part part;
  part.line = row.line;
  part.designator = row.designator;
  part.value = row.value;
  part.package = row.package;
  part.x_mm = row.x_mm;
  part.y_mm = row.y_mm;
  part.rotation_deg = row.rotation_deg;
  part.side = row.side;
  part.designator_range = row.designator_range;
  part.side_range = row.side_range;
  if (!Classify(row, part)) part.feeder = FindFeeder(row);
  if (options_.keep_fates) {
    fates_.emplace_back().row = row;
  }
  parts_.push_back(std::move(part));
}

void CadImporter::Skip(const Part& part, cad::Side placed_side) {
  SkipReason reason;
  std::string why;
  if (part.side != placed_side) {
    reason = SkipReason::kOtherSide;
    why = fmt::format("on the {} side (--side {} imports them)", cad::SideName(part.side), cad::SideName(part.side));
  } else if (part.skip == SkipReason::kDnp) {
    reason = SkipReason::kDnp;
    const std::string& by = skip_details_[part.skip_detail][0];
    why = fmt::format("marked do-not-place by {} (--keep-dnp places them)",
                      by.starts_with("its value ") ? "the value " + by.substr(10) : by);
  } else if (part.skip == SkipReason::kExcluded) {
    reason = SkipReason::kExcluded;
    const std::array<std::string, 4>& detail = skip_details_[part.skip_detail];
    why = fmt::format("excluded: the {} matches {} '{}'", detail[0], detail[2], detail[3]);
  } else {
    reason = SkipReason::kUnmapped;
    why = fmt::format("no feeder holds package {}, value {} (--skip-unmapped)", Quoted(part.package), Quoted(part.value));
  }
  ++summary_.skipped[static_cast<int>(reason)];
  auto [it, fresh] = group_of_.emplace(std::make_pair(static_cast<int>(reason), why), summary_.skip_groups.size());
  if (fresh) {
    summary_.skip_groups.push_back({reason, why, {}});
    group_first_.push_back(&part);
  }
  summary_.skip_groups[it->second].names.push_back(Printable(part.designator));
  if (options_.keep_fates) {
    RowFate& fate = fates_[static_cast<std::size_t>(&part - parts_.data())];
    fate.reason = reason;
    fate.why = std::move(why);
  }
}

void CadImporter::ReportSkipGroups(cad::Side placed_side) {
  // One warning per group, at its first row; the summary names every part.
  for (std::size_t g = 0; g < summary_.skip_groups.size(); ++g) {
    const SkipGroup& group = summary_.skip_groups[g];
    if (group_first_[g] == nullptr) continue;  // rows without a designator: the reader reported each
    const Part& first = *group_first_[g];
    const std::size_t n = group.names.size();
    const std::string subject = n == 1   ? fmt::format("{} is", group.names[0])
                                : n == 2 ? fmt::format("{} and {} are", group.names[0], group.names[1])
                                         : fmt::format("{} and {} other parts are", group.names[0], n - 1);
    const std::string all = n > 2 ? "; the summary names them all" : "";
    const char* them = n == 1 ? "it" : "them";
    switch (group.reason) {
      case SkipReason::kOtherSide:
        diags_.Report(DiagKind::ImportSkippedSide, first.side_range, subject, cad::SideName(first.side),
                      cad::SideName(placed_side), cad::SideName(first.side), them);
        break;
      case SkipReason::kDnp: {
        const std::string& by = skip_details_[first.skip_detail][0];
        diags_.Report(DiagKind::ImportSkippedDnp, first.skip_range, subject,
                      by.starts_with("its value ") && n > 1 ? "their value " + by.substr(10) : by, them, them, all);
        break;
      }
      case SkipReason::kExcluded: {
        const std::array<std::string, 4>& detail = skip_details_[first.skip_detail];
        const std::string what = n == 1 ? fmt::format("its {} '{}' matches", detail[0], detail[1])
                                        : fmt::format("their {}s match", detail[0]);
        diags_.Report(DiagKind::ImportExcluded, first.skip_range, subject, what, detail[2], detail[3], all);
        break;
      }
      case SkipReason::kUnmapped:
        diags_.Report(DiagKind::ImportSkippedUnmapped, first.designator_range, subject, Quoted(first.package),
                      Quoted(first.value), all);
        break;
      case SkipReason::kNoDesignator:
      case SkipReason::kCount: break;  // the reader reported each row
    }
  }
  std::stable_sort(summary_.skip_groups.begin(), summary_.skip_groups.end(),
                   [](const SkipGroup& a, const SkipGroup& b) { return a.reason < b.reason; });
}

void CadImporter::ReportUnmapped(const std::vector<const Part*>& unmapped) {
  // One group per package and value, in the order they first appear.
  std::vector<std::vector<const Part*>> groups;
  std::map<std::pair<std::string, std::string>, std::size_t> group_of;
  for (const Part* part : unmapped) {
    auto [it, fresh] = group_of.emplace(std::make_pair(part->package, part->value), groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(part);
  }
  Diagnostic* error = diags_.Report(DiagKind::ImportUnmappedParts, unmapped.front()->designator_range,
                                    unmapped.size(), unmapped.size() == 1 ? "part has" : "parts have", groups.size(),
                                    groups.size() == 1 ? "kind" : "kinds");
  constexpr std::size_t kNamesShown = 8;  // designators listed per kind; the count says the rest
  for (const std::vector<const Part*>& group : groups) {
    std::string names;
    for (std::size_t i = 0; i < group.size() && i < kNamesShown; ++i) {
      names += (i == 0 ? "" : ", ") + Printable(group[i]->designator);
    }
    if (group.size() > kNamesShown) names += ", ...";
    Diagnostics::AddNote(error, group.front()->designator_range,
                         fmt::format("package {}, value {}: {} part{} ({})", Quoted(group.front()->package),
                                     Quoted(group.front()->value), group.size(), group.size() == 1 ? "" : "s", names));
  }
}

std::size_t CadImporter::FateIndex(const Part& part) const { return static_cast<std::size_t>(&part - parts_.data()); }

double SignedDegrees(double degrees) {
  double u = std::fmod(degrees, 360.0);
  if (u <= -180) u += 360;
  if (u > 180) u -= 360;
  return u == 0 ? 0.0 : u;
}

void AddDistinct(std::vector<double>& values, double value) {
  if (std::none_of(values.begin(), values.end(), [&](double v) { return std::abs(v - value) < 1e-9; })) {
    values.push_back(value);
  }
}

void DescribeSlot(SetupSlot& slot, const cad::FeederTable& feeders, std::size_t feeder, int k) {
  const cad::FeederSpec& spec = feeders.feeders()[feeder];
  const cad::LaneDescription description = feeders.Describe(feeder, std::max(k, 1));
  // The lane's own location, else the feeder's with the lane's row and
  // column on its pallet.
  slot.location = description.location;
  if (!description.lane_location && spec.is_pallet() && spec.pick_points() > 1) {
    const int index = std::max(k, 1) - 1;
    slot.location += fmt::format("{}row {} of {}, column {} of {}", slot.location.empty() ? "" : ", ",
                                 index / spec.columns + 1, spec.rows, index % spec.columns + 1, spec.columns);
  }
  slot.tape_width_mm = description.tape_width_mm;
  slot.tape_pitch_mm = description.tape_pitch_mm;
  // A [[lane]] that says the lane holds another part than the one placed
  // from it (a lane an import gave to the next kind of part) describes
  // another reel: its part number is not this one's.
  auto differs = [](const std::vector<std::string>& parts, const std::string& declared, bool package) {
    return !declared.empty() && !parts.empty() && std::none_of(parts.begin(), parts.end(), [&](const std::string& part) {
      return package ? cad::PackageMatch(declared, part) : cad::GlobMatch(declared, part);
    });
  };
  if (differs(slot.values, description.value, false) || differs(slot.packages, description.package, true)) {
    const std::string note = fmt::format(
        "the feeders file says this lane holds {}{}{}: not the part placed from it, so its part number is not given",
        description.value, description.value.empty() || description.package.empty() ? "" : " ", description.package);
    slot.note = slot.note.empty() ? note : slot.note + "; " + note;
    return;
  }
  if (!description.part_number.empty() &&
      std::find(slot.part_numbers.begin(), slot.part_numbers.end(), description.part_number) == slot.part_numbers.end()) {
    slot.part_numbers.push_back(description.part_number);
  }
  // What [[lane]] says it holds, where the parts said nothing.
  if (slot.values.empty() && !description.value.empty()) slot.values.push_back(description.value);
  if (slot.packages.empty() && !description.package.empty()) slot.packages.push_back(description.package);
}

void CadImporter::AddToSetup(SetupSlot& slot, const cad::FeederSpec& feeder, int k, bool is_lane, const Part& part,
                             std::size_t board, const std::string& board_name) {
  if (slot.count == 0) {
    slot.feeder = feeder.name;
    slot.feeder_kind = cell::kFeederKindNames[static_cast<std::size_t>(feeder.kind)];
    slot.slot_kind = !feeder.is_pallet() ? "" : is_lane ? "lane" : "pocket";
    slot.slot = k;
    slot.pick = cell::PalletPickPoint(feeder.pick, feeder.pallet_last, feeder.pallet_back, feeder.columns,
                                      feeder.rows, std::max(k, 1));
    for (double& coordinate : slot.pick) coordinate = Round(coordinate, kCadResolutionMm);
  }
  ++slot.count;
  if (board == 0) {
    // The part lies in its tape with its 0° at the pick's u less its offset;
    // the nozzle turns it to its place (the board's and the fixture's turn
    // included).
    const double offset = part.feeder->rotation_offset_deg;
    AddDistinct(slot.in_tape_deg, Round(SignedDegrees(slot.pick[3] - offset), kCadResolutionDeg));
    double theta = part.rotation_deg;
    if (placed_mirror_rotation_) theta = placed_mirror_ == ImportMirror::kX ? 180.0 - theta : -theta;
    const double fixture_angle = options_.cell_fixture != nullptr ? options_.cell_fixture->angle_deg : 0.0;
    AddDistinct(slot.turns_deg, Round(SignedDegrees(theta + offset + options_.rotation_deg + fixture_angle - slot.pick[3]),
                                      kCadResolutionDeg));
    if (!part.feeder->part_number.empty() && std::find(slot.part_numbers.begin(), slot.part_numbers.end(),
                                                       part.feeder->part_number) == slot.part_numbers.end()) {
      slot.part_numbers.push_back(part.feeder->part_number);
    }
  }
  // A lane or a single tape gives the same parts to every board: named once.
  // A pocket holds one part of one board.
  if (board == 0 || slot.slot_kind == "pocket") {
    slot.designators.push_back(board == 0 ? Printable(part.designator)
                                          : fmt::format("{} ({})", Printable(part.designator), board_name));
  }
  for (auto [field, seen] : {std::pair{&part.value, &slot.values}, std::pair{&part.package, &slot.packages}}) {
    if (!field->empty() && std::find(seen->begin(), seen->end(), *field) == seen->end()) seen->push_back(*field);
  }
}

std::optional<ir::Program> CadImporter::Finish(const cad::ListReader& reader) {
  summary_.rows_read = reader.rows_read();
  summary_.rows_with_errors = reader.rows_with_errors();
  summary_.format = fmt::format("{}, {}", cad::FormatTitle(reader.format()), cad::UnitName(reader.unit()));
  summary_.encoding = options_.encoding;
  if (options_.encoding != cad::TextEncoding::kUtf8) {
    summary_.format += fmt::format(", {} text", cad::EncodingName(options_.encoding));
  }
  const SourceRange list_start(SourceLoc{list_file_, 1, 1});

  // The side: as asked, or the only one the list places parts on.
  std::array<std::size_t, 2> on_side{};
  std::array<const Part*, 2> first_on_side{};
  for (const Part& part : parts_) {
    if (part.skip) continue;
    int s = static_cast<int>(part.side);
    if (on_side[s]++ == 0) first_on_side[s] = &part;
  }
  cad::Side side = options_.side.value_or(on_side[1] > 0 && on_side[0] == 0 ? cad::Side::kBottom : cad::Side::kTop);
  summary_.placed_side = side;
  if (!options_.side && on_side[0] > 0 && on_side[1] > 0) {
    int minority = on_side[1] <= on_side[0] ? 1 : 0;
    diags_.Report(DiagKind::ImportMixedSides, first_on_side[minority]->side_range, on_side[0], on_side[1]);
    summary_.failed = true;
    return std::nullopt;
  }

  std::vector<const Part*> placed, unmapped;
  for (const Part& part : parts_) {
    if (part.side != side || part.skip) {
      Skip(part, side);
    } else if (!part.feeder) {
      if (options_.skip_unmapped) {
        Skip(part, side);
      } else {
        unmapped.push_back(&part);
      }
    } else {
      placed.push_back(&part);
    }
  }
  if (!reader.lines_without_designator().empty()) {
    SkipGroup group{SkipReason::kNoDesignator, "without a designator (--skip-empty-designators)", {}};
    for (std::uint32_t line : reader.lines_without_designator()) {
      group.names.push_back(fmt::format("line {}", line));
      if (options_.keep_fates) {
        RowFate fate;
        fate.row.line = line;
        fate.reason = SkipReason::kNoDesignator;
        fate.why = group.why;
        fates_.push_back(std::move(fate));
      }
    }
    summary_.skipped[static_cast<int>(SkipReason::kNoDesignator)] = group.names.size();
    summary_.skip_groups.push_back(std::move(group));
    group_first_.push_back(nullptr);
  }
  ReportSkipGroups(side);
  summary_.parts_placed = placed.size();
  if (!unmapped.empty()) {
    ReportUnmapped(unmapped);
    summary_.failed = true;
    return std::nullopt;
  }
  if (placed.empty()) {
    if (summary_.rows_read == 0) {
      diags_.Report(DiagKind::CadNoRows, list_start, cad::FormatTitle(reader.format()));
    } else if (summary_.rows_with_errors == 0) {
      std::size_t rows = summary_.rows_read;
      // About the whole list, so it is printed after the skips it sums up.
      diags_.Report(DiagKind::ImportNothingToPlace, SourceRange(SourceLoc{list_file_, 0, 0}), rows,
                    rows == 1 ? "row" : "rows");
    }
    summary_.failed = true;
    return std::nullopt;
  }
  // The program's size is asked for by the list and the panel together:
  // bounded before it is built (calibration/limits.h).
  const double placements = static_cast<double>(placed.size()) * static_cast<double>(summary_.boards);
  if (placements > static_cast<double>(limits::kMaxImportedPlacements)) {
    diags_.Report(DiagKind::ImportTooManyPlacements, SourceRange(SourceLoc{list_file_, 0, 0}), placed.size(),
                  options_.columns, options_.rows, fmt::format("{:.0f}", placements), limits::kMaxImportedPlacements);
    summary_.failed = true;
    return std::nullopt;
  }
  // How the list writes bottom x matters for the bottom side's placements
  // and, either side, for the outline the parts span.
  cad::BottomPositions bottom_positions = cad::BottomPositions::kTopView;
  if (side == cad::Side::kBottom) {
    bottom_positions = DescribeBottom(reader);
  } else if (on_side[1] > 0 || options_.bottom_positions) {
    bottom_positions = options_.bottom_positions.value_or(DecideBottom(reader).positions);
  }
  std::optional<ir::Program> program = Build(placed, side, bottom_positions);
  std::vector<Part>().swap(parts_);  // the program holds what it needs; free the rows before printing
  if (options_.keep_fates) {
    std::stable_sort(fates_.begin(), fates_.end(), [](const RowFate& a, const RowFate& b) { return a.row.line < b.row.line; });
  }
  if (!program || diags_.has_errors()) {
    summary_.failed = true;
    return std::nullopt;
  }
  return program;
}

cad::BottomDecision CadImporter::DecideBottom(const cad::ListReader& reader) const {
  std::vector<cad::SidedX> sided;
  sided.reserve(parts_.size());
  for (const Part& part : parts_) sided.push_back({part.x_mm, part.side});
  return cad::DecideBottomPositions(reader, sided);
}

cad::BottomPositions CadImporter::DescribeBottom(const cad::ListReader& reader) {
  cad::BottomPositions positions;
  std::string why;
  if (options_.bottom_positions) {
    positions = *options_.bottom_positions;
    why = "as --bottom-positions says";
  } else {
    cad::BottomDecision decision = DecideBottom(reader);
    positions = decision.positions;
    why = decision.why;
  }
  const ImportMirror mirror = options_.mirror.value_or(ImportMirror::kX);
  const bool negated = positions == cad::BottomPositions::kNegatedX;
  const bool top_view_rotation = options_.bottom_rotation == BottomRotation::kTopView;
  // The program's x, y and u from the list's, in the list's own numbers.
  std::string x = (mirror == ImportMirror::kX) != negated ? "x' = -x" : "x' = x";
  std::string y = mirror == ImportMirror::kY ? ", y' = -y" : "";
  std::string u = mirror == ImportMirror::kNone || !top_view_rotation ? "u = rotation"
                  : mirror == ImportMirror::kX                        ? "u = 180° - rotation"
                                                                      : "u = -rotation";
  summary_.bottom = fmt::format(
      "x as seen from the {}: {}\n           rotations as seen from the {}; {}: {}{}, {}",
      negated ? "bottom (negated)" : "top", why, top_view_rotation ? "top" : "bottom",
      mirror == ImportMirror::kX   ? "the board turned over about its y axis"
      : mirror == ImportMirror::kY ? "the board turned over about its x axis"
                                   : "the board not turned over (--mirror none)",
      x, y, u);
  return positions;
}

std::array<double, 4> CadImporter::Outline(cad::BottomPositions bottom_positions) const {
  if (options_.board) return *options_.board;
  // Every part the list gives, of both sides, seen from the top: fiducials
  // and parts left out mark the board as well as the parts placed.
  const double inf = std::numeric_limits<double>::infinity();
  std::array<double, 4> box = {inf, inf, -inf, -inf};
  for (const Part& part : parts_) {
    const double x = part.side == cad::Side::kBottom && bottom_positions == cad::BottomPositions::kNegatedX
                         ? -part.x_mm
                         : part.x_mm;
    box = {std::min(box[0], x), std::min(box[1], part.y_mm), std::max(box[2], x), std::max(box[3], part.y_mm)};
  }
  return box;
}

bool CadImporter::PlaceBoard(const std::array<double, 4>& outline, double angle) {
  // The whole panel in the panel's own axes: board (c, r) is (c * pitch_x,
  // r * pitch_y) from the first.
  const double span_x = (options_.columns - 1) * options_.pitch_x_mm, span_y = (options_.rows - 1) * options_.pitch_y_mm;
  const double lo_x = outline[0] + std::min(0.0, span_x), hi_x = outline[2] + std::max(0.0, span_x);
  const double lo_y = outline[1] + std::min(0.0, span_y), hi_y = outline[3] + std::max(0.0, span_y);
  const double c = std::cos(angle), s = std::sin(angle);
  auto turned = [&](double x, double y) { return std::array<double, 2>{c * x - s * y, s * x + c * y}; };
  const bool panel = options_.columns * options_.rows > 1;
  if (options_.pocket) {
    // The panel's corners turned into the fixture's axes; their lower left
    // goes to the pocket's lower left corner.
    double min_x = std::numeric_limits<double>::infinity(), min_y = min_x, max_x = -min_x, max_y = -min_x;
    for (double x : {lo_x, hi_x}) {
      for (double y : {lo_y, hi_y}) {
        const auto [tx, ty] = turned(x, y);
        min_x = std::min(min_x, tx);
        min_y = std::min(min_y, ty);
        max_x = std::max(max_x, tx);
        max_y = std::max(max_y, ty);
      }
    }
    const auto [px0, py0, px1, py1] = *options_.pocket;
    options_.origin_x_mm = Round(px0 - min_x, kCadResolutionMm);
    options_.origin_y_mm = Round(py0 - min_y, kCadResolutionMm);
    summary_.origin_how = fmt::format("the {}'s lower left corner in the pocket of fixture {} (pocket_x_mm, pocket_y_mm)",
                                      panel ? "panel" : "board", options_.fixture);
    if (max_x - min_x > px1 - px0 + kCadResolutionMm || max_y - min_y > py1 - py0 + kCadResolutionMm) {
      diags_.Report(DiagKind::ImportBoardOverPocket, options_.pocket_range, panel ? "panel" : "board",
                    FormatLength(max_x - min_x), FormatLength(max_y - min_y), options_.fixture,
                    FormatLength(px1 - px0), FormatLength(py1 - py0));
      return false;
    }
    return true;
  }
  if (options_.centre_spot) {
    const auto [cx, cy] = turned((lo_x + hi_x) / 2, (lo_y + hi_y) / 2);
    const auto [spot_x, spot_y] = *options_.centre_spot;
    options_.origin_x_mm = Round(spot_x - cx, kCadResolutionMm);
    options_.origin_y_mm = Round(spot_y - cy, kCadResolutionMm);
    summary_.origin_how = fmt::format("the {}'s centre on {} (--origin X,Y places it elsewhere)",
                                      panel ? "panel" : "board", options_.centre_spot_name);
    return true;
  }
  summary_.origin_how =
      "the fixture has no pocket (pocket_x_mm, pocket_y_mm) and no calibrated region to centre the board on; "
      "give --origin X,Y";
  return true;
}

bool CadImporter::CheckRegions(const std::vector<const Part*>& parts,
                               const std::vector<std::array<double, 2>>& on_board,
                               const std::vector<std::array<double, 3>>& board_frames,
                               const std::array<double, 4>& outline) {
  // A cell with no calibrated region yet (being calibrated, or a test's)
  // has nothing to hold the parts to: verify will say so.
  if (options_.cell == nullptr || options_.cell_fixture == nullptr || parts.empty() || options_.cell->regions.empty()) {
    return true;
  }
  const cell::Cell& cell = *options_.cell;
  const Eigen::Affine3d nominal = NominalFix(*options_.cell_fixture);
  std::vector<Eigen::Vector2d> placed;  // robot base frame, every part of every board
  std::vector<std::string> outside;     // designators (with the board of a panel)
  const Part* first_outside = nullptr;
  const bool panel = board_frames.size() > 1;
  for (std::size_t b = 0; b < board_frames.size(); ++b) {
    const auto [bx, by, rotation] = board_frames[b];
    const double angle = rotation * std::numbers::pi / 180.0, c = std::cos(angle), s = std::sin(angle);
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const auto [x, y] = on_board[i];
      const Eigen::Vector2d base = ToBase(nominal, {bx + c * x - s * y, by + s * x + c * y});
      placed.push_back(base);
      if (cell.RegionAt(base) != nullptr) continue;
      if (first_outside == nullptr) first_outside = parts[i];
      outside.push_back(panel ? fmt::format("{} on board {}", Printable(parts[i]->designator), b + 1)
                              : Printable(parts[i]->designator));
    }
  }
  if (outside.empty()) return true;
  const RegionFit fit = FitInRegion(cell, placed);
  std::string names;
  for (std::size_t k = 0; k < outside.size() && k < 5; ++k) names += (k == 0 ? "" : ", ") + outside[k];
  if (outside.size() > 5) names += fmt::format(" and {} more", outside.size() - 5);
  std::string region_text, advice;
  if (fit.region == nullptr) {
    region_text = "no calibrated region lies under them";
    advice = "give --origin X,Y to put the board on a region (docs/import.md, \"Where the board is\")";
  } else {
    const cell::Region& region = *fit.region;
    const double rw = region.x_mm.hi - region.x_mm.lo, rh = region.y_mm.hi - region.y_mm.lo;
    region_text = fmt::format("region '{}' spans x {}..{}, y {}..{} mm ({} x {} mm)", Printable(region.name),
                              FormatLength(region.x_mm.lo), FormatLength(region.x_mm.hi), FormatLength(region.y_mm.lo),
                              FormatLength(region.y_mm.hi), FormatLength(rw), FormatLength(rh));
    if (fit.larger()) {
      std::vector<std::string> over;
      if (fit.width() > rw + kRegionFitSlackMm) over.push_back(fmt::format("{} mm wider", FormatLength(fit.width() - rw)));
      if (fit.height() > rh + kRegionFitSlackMm) over.push_back(fmt::format("{} mm taller", FormatLength(fit.height() - rh)));
      advice = fmt::format("the parts are {} than the region, so no --origin fits: place fewer of them (--side, "
                           "--exclude-designator), or calibrate a larger region",
                           fmt::join(over, " and "));
    } else {
      // The move that centres the parts on the region, in the fixture frame.
      const Eigen::Vector2d move = nominal.linear().topLeftCorner<2, 2>().transpose() * fit.CentringMove();
      const double room_x = (rw - fit.width()) / 2, room_y = (rh - fit.height()) / 2;
      const double shift = options_.cell_fixture->max_shift_mm;
      advice = fmt::format("--origin {},{} centres them on it, {} mm from its edges in x and {} mm in y{}",
                           FormatLength(options_.origin_x_mm + move.x()), FormatLength(options_.origin_y_mm + move.y()),
                           FormatLength(room_x), FormatLength(room_y),
                           std::min(room_x, room_y) < shift
                               ? fmt::format(" (less than the {} mm fixture {} may shift: verify says which parts "
                                             "then leave the region)",
                                             FormatLength(shift), options_.fixture)
                               : std::string());
    }
  }
  diags_.Report(DiagKind::ImportBoardOverRegion, first_outside->designator_range, outside.size(),
                panel ? "panel" : "board", placed.size(), outside.size() == 1 ? "lands" : "land", names, FormatLength(fit.x_lo), FormatLength(fit.x_hi),
                FormatLength(fit.y_lo), FormatLength(fit.y_hi), FormatLength(fit.width()), FormatLength(fit.height()),
                FormatLength(outline[2] - outline[0]), FormatLength(outline[3] - outline[1]), region_text, advice);
  return false;
}

std::vector<std::unordered_map<std::size_t, int>> CadImporter::AssignTapeLanes(
    const std::vector<const Part*>& parts, const std::vector<std::vector<std::size_t>>& by_feeder) {
  const std::vector<cad::FeederSpec>& feeders = feeders_.feeders();
  std::vector<std::unordered_map<std::size_t, int>> lane_of(feeders.size());
  for (std::size_t f = 0; f < feeders.size(); ++f) {
    const cad::FeederSpec& feeder = feeders[f];
    if (by_feeder[f].empty() || feeder.kind != cell::FeederKind::kTape || feeder.lanes_by_package()) continue;
    // One kind of part (package and value) per tape, lanes in the order the
    // kinds first appear in the list; a lane a [[map]] gives is kept.
    std::map<std::pair<std::string, std::string>, int> lanes;
    // A single tape: every kind it is given, with its parts, for one warning.
    std::vector<std::vector<const Part*>> kinds;
    for (std::size_t i : by_feeder[f]) {
      const Part& part = *parts[i];
      if (part.feeder->lane) continue;
      auto [it, fresh] = lanes.emplace(std::make_pair(part.package, part.value), static_cast<int>(lanes.size()) + 1);
      if (!feeder.is_pallet()) {
        if (fresh) kinds.emplace_back();
        kinds[static_cast<std::size_t>(it->second - 1)].push_back(&part);
        continue;
      }
      if (!fresh) {
        lane_of[f][i] = it->second;
        continue;
      }
      if (it->second == feeder.pick_points() + 1) {
        diags_.Report(DiagKind::ImportTapeLanesFull, part.designator_range, Printable(feeder.name),
                      feeder.pick_points(), Quoted(part.package), Quoted(part.value), it->second);
      }
      lane_of[f][i] = it->second;
    }
    if (kinds.size() < 2) continue;
    // One warning at the first part of the second kind, a note per kind.
    Diagnostic* diag = diags_.Report(DiagKind::ImportTapeMixedKinds, kinds[1].front()->designator_range,
                                     Printable(feeder.name), kinds.size());
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      const std::vector<const Part*>& of_kind = kinds[k];
      std::string names;
      for (std::size_t j = 0; j < of_kind.size() && j < 4; ++j) {
        names += (j == 0 ? "" : ", ") + Printable(of_kind[j]->designator);
      }
      if (of_kind.size() > 4) names += fmt::format(" and {} more", of_kind.size() - 4);
      Diagnostics::AddNote(diag, of_kind.front()->designator_range,
                           fmt::format("kind {} of {}: package {}, value {}: {} ({} part{})", k + 1, kinds.size(),
                                       Quoted(of_kind.front()->package), Quoted(of_kind.front()->value), names,
                                       of_kind.size(), of_kind.size() == 1 ? "" : "s"));
    }
  }
  return lane_of;
}

std::optional<ir::Program> CadImporter::Build(const std::vector<const Part*>& parts, cad::Side side,
                                              cad::BottomPositions bottom_positions) {
  const SourceLoc start{list_file_, 1, 1};
  const std::vector<cad::FeederSpec>& feeders = feeders_.feeders();
  NameTable names(parts.size() * static_cast<std::size_t>(options_.columns) * static_cast<std::size_t>(options_.rows) +
                  2 * feeders.size() + 64);
  names.Claim(options_.fixture, {"the fixture", {}, 0});
  names.Claim("Main", {"the function Main", {}, 0});

  ir::Program program;
  program.file = list_file_;
  ir::Block& items = program.items;
  for (const std::string& line : options_.header_lines) items.push_back(CommentStmt(start, line));
  items.push_back(MakeStmt(start, ir::ProgramDecl{options_.program_name, start}));
  items.push_back(MakeStmt(start, ir::UnitsDecl{"mm", start}));
  items.push_back(MakeStmt(start, ir::FixtureDecl{options_.fixture, start}));
  items.push_back(MakeStmt(start, ir::VacuumDecl{options_.vacuum, start}, " the gripper's vacuum output (--vacuum)"));

  // --- where each part is on its board: x, y as the list gives them,
  // turned over for the bottom side ---------------------------------------
  const ImportMirror mirror = options_.mirror.value_or(side == cad::Side::kBottom ? ImportMirror::kX : ImportMirror::kNone);
  const bool mirror_rotation =
      mirror != ImportMirror::kNone && !(side == cad::Side::kBottom && options_.bottom_rotation == BottomRotation::kBottomView);
  placed_mirror_ = mirror;
  placed_mirror_rotation_ = mirror_rotation;
  const bool list_negated = side == cad::Side::kBottom && bottom_positions == cad::BottomPositions::kNegatedX;
  std::vector<std::array<double, 2>> on_board(parts.size());
  const std::array<double, 4> outline = Outline(bottom_positions);  // seen from the top
  const bool outline_given = options_.board.has_value();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const double x_top = list_negated ? -parts[i]->x_mm : parts[i]->x_mm;  // the list's x as seen from the top
    const double x = mirror == ImportMirror::kX ? -x_top : x_top;
    const double y = mirror == ImportMirror::kY ? -parts[i]->y_mm : parts[i]->y_mm;
    on_board[i] = {x == 0 ? 0.0 : x, y == 0 ? 0.0 : y};
    if (outline_given && (x_top < outline[0] - kCadResolutionMm || x_top > outline[2] + kCadResolutionMm ||
                          parts[i]->y_mm < outline[1] - kCadResolutionMm || parts[i]->y_mm > outline[3] + kCadResolutionMm)) {
      diags_.Report(DiagKind::ImportPartOffBoard, parts[i]->designator_range, Printable(parts[i]->designator),
                    FormatLength(x_top), FormatLength(parts[i]->y_mm), FormatLength(outline[0]),
                    FormatLength(outline[2]), FormatLength(outline[1]), FormatLength(outline[3]));
    }
  }
  summary_.outline = fmt::format("x {}..{}, y {}..{} mm{}", FormatLength(outline[0]), FormatLength(outline[2]),
                                 FormatLength(outline[1]), FormatLength(outline[3]),
                                 outline_given ? " (--board)" : ", the parts' bounding box (no --board)");

  // --- the boards of the panel, row by row from the origin --------------
  // The outline on the board as placed: turned over with the parts, so the
  // bottom side turns about the board's own edge and lands where its top did.
  std::array<double, 4> placed_outline = outline;
  if (mirror == ImportMirror::kX) placed_outline = {-outline[2], outline[1], -outline[0], outline[3]};
  if (mirror == ImportMirror::kY) placed_outline = {outline[0], -outline[3], outline[2], -outline[1]};
  const double angle = options_.rotation_deg * std::numbers::pi / 180.0;
  if (options_.origin_given) {
    summary_.origin_how = "--origin";
  } else {
    if (!PlaceBoard(placed_outline, angle)) return std::nullopt;
    if (!outline_given && (options_.pocket || options_.centre_spot)) {
      diags_.Report(DiagKind::ImportOutlineFromParts, SourceRange(SourceLoc{list_file_, 0, 0}),
                    FormatLength(outline[0]), FormatLength(outline[2]), FormatLength(outline[1]),
                    FormatLength(outline[3]));
    }
  }
  summary_.origin_x_mm = options_.origin_x_mm;
  summary_.origin_y_mm = options_.origin_y_mm;
  std::vector<std::string> boards;
  std::vector<std::array<double, 3>> board_frames;  // x, y, rotation of each board in the fixture
  std::string board_text = fmt::format("origin ({}, {}) mm, rotated {}°", options_.origin_x_mm, options_.origin_y_mm,
                                       options_.rotation_deg);
  if (!options_.origin_given && options_.pocket) {
    board_text += ", its outline in the fixture's pocket";
  } else if (!options_.origin_given && options_.centre_spot) {
    board_text += ", its outline centred on " + options_.centre_spot_name;
  }
  const bool panel = options_.columns * options_.rows > 1;
  items.push_back(CommentStmt(
      start,
      panel ? fmt::format("A panel of {} x {} boards in fixture {}: {}, pitch ({}, {}) mm", options_.columns, options_.rows,
                          options_.fixture, board_text, options_.pitch_x_mm, options_.pitch_y_mm)
            : fmt::format("The board in fixture {}: {}", options_.fixture, board_text),
      true));
  for (int r = 0; r < options_.rows; ++r) {
    for (int c = 0; c < options_.columns; ++c) {
      double dx = c * options_.pitch_x_mm, dy = r * options_.pitch_y_mm;
      double x = Round(options_.origin_x_mm + std::cos(angle) * dx - std::sin(angle) * dy, kCadResolutionMm);
      double y = Round(options_.origin_y_mm + std::sin(angle) * dx + std::cos(angle) * dy, kCadResolutionMm);
      std::string name = names.Claim(panel ? fmt::format("Pcb{}", boards.size() + 1) : "Pcb", {"a board frame", {}, 0});
      board_frames.push_back({x, y, Round(options_.rotation_deg, kCadResolutionDeg)});
      ir::LocalDecl local{name, start, MakeCoords(start, {x, y, 0.0, Round(options_.rotation_deg, kCadResolutionDeg)}),
                          options_.fixture, start};
      items.push_back(MakeStmt(start, std::move(local),
                               panel ? fmt::format(" column {}, row {}", c + 1, r + 1) : std::string()));
      boards.push_back(name);
    }
  }

  if (!CheckRegions(parts, on_board, board_frames, outline)) return std::nullopt;

  // --- the feeders the parts use, in the feeder table's order ------------
  std::vector<std::vector<std::size_t>> by_feeder(feeders.size());  // indices into parts
  for (std::size_t i = 0; i < parts.size(); ++i) by_feeder[parts[i]->feeder->feeder].push_back(i);
  std::vector<std::unordered_map<std::size_t, int>> tape_lane = AssignTapeLanes(parts, by_feeder);
  std::vector<std::string> pick_name(feeders.size());  // a point, or empty for a pallet
  std::vector<int> pallet_number(feeders.size(), 0);
  int next_pallet = kFirstPallet;
  bool first_feeder = true;
  for (std::size_t f = 0; f < feeders.size(); ++f) {
    if (by_feeder[f].empty()) continue;
    ++summary_.feeders_used;
    const cad::FeederSpec& feeder = feeders[f];
    SourceLoc loc = feeder.name_range.begin.known() ? feeder.name_range.begin : start;
    const NameOwner owner{"the pick point of feeder", feeder.name, 0};
    std::string comment = fmt::format(" feeder {}{}", CommentText(feeder.name), feeder.from_cell ? " (cell)" : "");
    if (first_feeder) items.push_back(CommentStmt(start, "The feeders' pick points (robot base frame)", true));
    first_feeder = false;
    std::string base = MakeIdentifier(feeder.name);
    if (!feeder.is_pallet()) {
      pick_name[f] = names.Claim(base, owner);
      items.push_back(MakeStmt(loc, ir::PointDecl{pick_name[f], loc, false, MakeCoords(loc, feeder.pick), "", {}},
                               comment));
      continue;
    }
    if (next_pallet > limits::kPalletNumberMax) {
      diags_.Report(DiagKind::ImportTooManyPallets, feeder.name_range, Printable(feeder.name), next_pallet,
                    kFirstPallet, limits::kPalletNumberMax);
      continue;
    }
    pallet_number[f] = next_pallet++;
    std::array<std::string, 3> corners = {names.Claim(base + "First", owner), names.Claim(base + "Last", owner),
                                          names.Claim(base + "Back", owner)};
    const std::array<std::array<double, 4>, 3> where = {feeder.pick, *feeder.pallet_last,
                                                        feeder.pallet_back.value_or(feeder.pick)};
    for (std::size_t k = 0; k < 3; ++k) {
      items.push_back(MakeStmt(loc, ir::PointDecl{corners[k], loc, false, MakeCoords(loc, where[k]), "", {}}));
    }
    ir::PalletDecl pallet;
    pallet.number = pallet_number[f];
    pallet.number_loc = loc;
    pallet.corners = corners;
    pallet.corner_locs = {loc, loc, loc};
    pallet.columns = feeder.columns;
    pallet.columns_loc = loc;
    pallet.rows = feeder.rows;
    pallet.rows_loc = loc;
    items.push_back(MakeStmt(loc, std::move(pallet), comment));
  }

  // --- the parts, board by board -----------------------------------------
  std::string how = mirror == ImportMirror::kX   ? (list_negated ? ", turned over: x as the list writes it (negated there)"
                                                                 : ", turned over: x negated")
                    : mirror == ImportMirror::kY ? (list_negated ? ", turned over: y negated, the list's negated x undone"
                                                                 : ", turned over: y negated")
                                                 : (list_negated ? ", the list's negated x undone" : "");
  std::vector<std::string> comments;  // per part: " C1 100n C_0603"
  comments.reserve(parts.size());
  for (const Part* part : parts) comments.push_back(" " + PartComment(*part));
  // point_name[b][i]: the point of part i on board b.
  std::vector<std::vector<std::string>> point_name(boards.size(), std::vector<std::string>(parts.size()));
  for (std::size_t b = 0; b < boards.size(); ++b) {
    items.push_back(CommentStmt(start,
                                fmt::format("The parts on the {} side{}, in {} (board coordinates, mm)",
                                            cad::SideName(side), how, boards[b]),
                                true));
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const Part& part = *parts[i];
      const SourceLoc loc = part.designator_range.begin;
      const std::string wanted = panel ? boards[b] + "_" + MakeIdentifier(part.designator) : MakeIdentifier(part.designator);
      std::optional<NameOwner> taken;
      std::string name = names.Claim(wanted, {"the point of", part.designator, part.line}, &taken);
      // Equal designators make equal names, so a duplicate shows as a
      // collision with the point of the same designator.
      if (b == 0 && taken) {
        if (taken->what == "the point of" && AsciiLowercase(taken->name) == AsciiLowercase(part.designator)) {
          diags_.Report(DiagKind::ImportDuplicateDesignator, part.designator_range, Printable(part.designator),
                        taken->line, name);
        } else {
          diags_.Report(DiagKind::ImportNameCollision, part.designator_range, Printable(part.designator), wanted,
                        fmt::format("that is {}", taken->Describe()), name);
        }
      }
      point_name[b][i] = name;
      const auto [x, y] = on_board[i];
      double theta = part.rotation_deg;
      if (mirror_rotation) theta = mirror == ImportMirror::kX ? 180.0 - theta : -theta;
      double u = NormaliseAngle(theta + part.feeder->rotation_offset_deg, options_.angles);
      if (b == 0 && options_.keep_fates) {
        RowFate& fate = fates_[FateIndex(part)];
        fate.placed = true;
        fate.point = name;
        fate.board_xyu = {x, y, u};
      }
      ir::PointDecl point{std::move(name), loc, false,
                          MakeCoords(loc, {x, y, options_.place_z_mm, u}), boards[b], loc};
      items.push_back(MakeStmt(loc, std::move(point), comments[i]));
    }
  }

  // --- Main: one Cycle, Pick/Place pairs grouped by feeder -----------------
  ir::Cycle cycle;
  cycle.fixture = options_.fixture;
  cycle.fixture_loc = start;
  cycle.end.loc = start;
  std::vector<int> pockets_used(feeders.size(), 0);
  setup_ = SetupSheet{options_.program_name, options_.fixture, boards.size(), {}, {}};
  for (std::size_t f = 0; f < feeders.size(); ++f) {
    if (by_feeder[f].empty()) continue;
    const cad::FeederSpec& feeder = feeders[f];
    std::map<int, SetupSlot> slots;  // by lane or pocket (0: the single pick point)
    std::size_t count = by_feeder[f].size() * boards.size();
    cycle.body.push_back(CommentStmt(start,
                                     fmt::format("feeder {}: {} placement{}", feeder.name, count, count == 1 ? "" : "s"),
                                     !cycle.body.empty()));
    for (std::size_t b = 0; b < boards.size(); ++b) {
      for (std::size_t i : by_feeder[f]) {
        const Part* part = parts[i];
        const SourceLoc loc = part->designator_range.begin;
        ir::PickPlace pick;
        std::string pick_comment;
        pick.kind = ir::PickPlaceKind::Pick;
        pick.target.loc = loc;
        int slot = 0;
        bool is_lane = false;
        if (!feeder.is_pallet()) {
          pick.target.base = ir::NamedPoint{pick_name[f], static_cast<std::uint32_t>(pick_name[f].size())};
        } else {
          int k = part->feeder->lane.value_or(0);
          if (auto lane = tape_lane[f].find(i); k == 0 && lane != tape_lane[f].end()) k = lane->second;
          is_lane = k != 0;
          if (k == 0) {
            k = ++pockets_used[f];
            if (k == feeder.pick_points() + 1) {
              diags_.Report(DiagKind::ImportPalletFeederFull, part->designator_range, Printable(feeder.name),
                            feeder.pick_points(), feeder.pick_points() == 1 ? "point" : "points", feeder.columns,
                            feeder.rows, k);
            }
          }
          pick.target.base = ir::PalletPoint{IntLit(loc, std::max(pallet_number[f], 0)), IntLit(loc, k), nullptr};
          pick_comment = is_lane ? fmt::format(" lane {}", k) : fmt::format(" pocket {} of {}", k, feeder.pick_points());
          slot = k;
        }
        AddToSetup(slots[slot], feeder, slot, is_lane, *part, b, boards[b]);
        if (b == 0 && options_.keep_fates) {
          RowFate& fate = fates_[FateIndex(*part)];
          fate.feeder = feeder.name;
          fate.slot_kind = !feeder.is_pallet() ? "" : is_lane ? "lane" : "pocket";
          fate.slot = slot;
        }
        cycle.body.push_back(MakeStmt(loc, std::move(pick), pick_comment));
        ir::PickPlace place;
        place.kind = ir::PickPlaceKind::Place;
        place.target.loc = loc;
        place.target.base = ir::NamedPoint{point_name[b][i], static_cast<std::uint32_t>(point_name[b][i].size())};
        cycle.body.push_back(MakeStmt(loc, std::move(place), comments[i]));
      }
    }
    for (auto& [k, slot] : slots) {
      DescribeSlot(slot, feeders_, f, k);
      setup_.slots.push_back(std::move(slot));
    }
  }
  ir::Function main;
  main.name = "Main";
  main.name_loc = start;
  main.end.loc = start;
  main.body.push_back(MakeStmt(start, std::move(cycle)));
  items.push_back(MakeStmt(start, std::move(main)));
  items.back()->blank_line_before = true;
  if (diags_.has_errors()) return std::nullopt;
  return program;
}

}  // namespace smtcal

// The lexical layer of the CAD list readers (see cad_text.h).
#include "frontend/cad/cad_text.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "base/field_text.h"
#include "calibration/tolerances.h"

namespace smtcal::cad {
namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t'; }

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (AsciiLower(a[i]) != AsciiLower(b[i])) return false;
  }
  return true;
}

bool IsContinuationByte(char c) { return (static_cast<unsigned char>(c) & 0xc0) == 0x80; }

// The byte offset of code point `column` (text.size() when beyond).
std::size_t ByteOfCodePoint(std::string_view text, std::size_t column) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (IsContinuationByte(text[i])) continue;
    if (count == column) return i;
    ++count;
  }
  return text.size();
}

std::string_view Trim(std::string_view text) {
  while (!text.empty() && IsBlank(text.front())) text.remove_prefix(1);
  while (!text.empty() && IsBlank(text.back())) text.remove_suffix(1);
  return text;
}


double Round(double value, double resolution) {
  // Dividing by the exact integer 1/resolution gives the double nearest to
  // the decimal, which prints back as that decimal.
  const double scale = std::round(1.0 / resolution);
  return std::round(value * scale) / scale;
}

// Splits "12.5mm" into the number and what follows it.
struct NumberText {
  std::string_view number;
  std::string_view suffix;
};
NumberText SplitSuffix(std::string_view text) {
  std::size_t end = text.size();
  while (end > 0) {
    char c = text[end - 1];
    bool unit_char = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '"' ||
                     static_cast<unsigned char>(c) >= 0x80;
    // A number ends in a digit or '.', so an exponent ("2.5e3") is never
    // taken for a unit.
    if (!unit_char) break;
    --end;
  }
  return {Trim(text.substr(0, end)), text.substr(end)};
}

}  // namespace

// ------------------------------------------------------------------ lines

Lines::Lines(const SourceManager& sources, std::uint32_t file)
    : source_(&sources.File(file)),
      file_(file),
      count_(static_cast<std::uint32_t>(source_->text.empty() ? 0 : source_->line_starts.size())),
      bom_(source_->text.starts_with("\xEF\xBB\xBF") ? 3 : 0) {}

std::string_view Lines::Text(std::uint32_t number) const {
  std::string_view line = source_->Line(number);
  if (number == 1) line.remove_prefix(std::min(bom_, line.size()));
  return line;
}

SourceLoc Lines::At(std::uint32_t number, std::size_t offset) const {
  std::size_t skipped = number == 1 ? bom_ : 0;
  return SourceLoc{file_, number, static_cast<std::uint32_t>(offset + skipped + 1)};
}

SourceRange Lines::Range(std::uint32_t number, std::size_t offset, std::size_t length) const {
  return SourceRange(At(number, offset), static_cast<std::uint32_t>(length));
}

bool Lines::IsFiller(std::uint32_t number) const {
  std::string_view text = Trim(Text(number));
  // Quoted report lines (Altium's CSV preamble) are judged by their inside.
  if (text.size() >= 2 && text.front() == '"' && text.back() == '"') text = Trim(text.substr(1, text.size() - 2));
  if (text.empty() || text.front() == '#') return true;
  return text.size() >= 3 && std::all_of(text.begin(), text.end(), [&](char c) { return c == text.front(); }) &&
         (text.front() == '=' || text.front() == '-' || text.front() == '*');
}

// ------------------------------------------------------------------ fields

namespace {

// The next field of a row, reusing the vector's strings: a list is read
// row after row into the same fields, so their buffers are allocated once.
Field& NextField(std::vector<Field>& fields, std::size_t& count) {
  if (count == fields.size()) fields.emplace_back();
  Field& field = fields[count++];
  field.text.clear();
  field.quoted = false;
  return field;
}

void TrimInPlace(std::string& text) {
  std::size_t end = text.size();
  while (end > 0 && IsBlank(text[end - 1])) --end;
  text.erase(end);
  std::size_t begin = 0;
  while (begin < text.size() && IsBlank(text[begin])) ++begin;
  text.erase(0, begin);
}

}  // namespace

bool SplitDelimited(const Lines& lines, std::uint32_t& number, char delimiter, std::vector<Field>& fields,
                    Diagnostics& diags, bool multiline) {
  std::size_t count = 0;
  std::string_view line = lines.Text(number);
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && IsBlank(line[i]) && line[i] != delimiter) ++i;
    Field& field = NextField(fields, count);
    field.start = 0;  // only blank-separated fields have columns
    const std::size_t begin = i;
    const std::uint32_t begin_line = number;
    if (i < line.size() && line[i] == '"') {
      field.quoted = true;
      ++i;
      while (true) {
        if (i >= line.size()) {
          // RFC 4180: a line end inside quotes belongs to the field.
          if (!multiline) {
            diags.Report(DiagKind::CsvUnclosedQuote, lines.Range(begin_line, begin, 1));
            fields.resize(count);
            return false;
          }
          if (number >= lines.count()) {
            diags.Report(DiagKind::CadUnclosedQuote, lines.Range(begin_line, begin, 1));
            fields.resize(count);
            return false;
          }
          field.text += '\n';
          line = lines.Text(++number);
          i = 0;
          continue;
        }
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            field.text += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        std::size_t run = i;  // copy up to the next quote at once
        while (run < line.size() && line[run] != '"') ++run;
        field.text.append(line.substr(i, run - i));
        i = run;
      }
      const std::size_t end = i;
      while (i < line.size() && IsBlank(line[i]) && line[i] != delimiter) ++i;
      if (i < line.size() && line[i] != delimiter) {
        diags.Report(DiagKind::CsvStrayQuote, lines.Range(number, i, 1), "text after the closing quote of a field");
        fields.resize(count);
        return false;
      }
      field.range = begin_line == number ? lines.Range(number, begin, end - begin) : lines.Range(begin_line, begin, 1);
      TrimInPlace(field.text);
    } else {
      while (i < line.size() && line[i] != delimiter) {
        if (line[i] == '"') {
          diags.Report(DiagKind::CsvStrayQuote, lines.Range(number, i, 1), "'\"' inside an unquoted field");
          fields.resize(count);
          return false;
        }
        ++i;
      }
      std::size_t end = i;
      while (end > begin && IsBlank(line[end - 1])) --end;
      field.text.assign(line.substr(begin, end - begin));
      field.range = lines.Range(number, begin, end - begin);
    }
    if (i < line.size() && line[i] == delimiter) {
      ++i;
      continue;
    }
    fields.resize(count);
    return true;
  }
}

bool SplitWhitespace(const Lines& lines, std::uint32_t number, std::vector<Field>& fields, Diagnostics& diags) {
  std::size_t count = 0;
  std::string_view line = lines.Text(number);
  std::size_t i = 0;
  std::size_t counted = 0, code_points = 0;  // code points in line[0, counted)
  while (true) {
    while (i < line.size() && IsBlank(line[i])) ++i;
    if (i >= line.size()) {
      fields.resize(count);
      return true;
    }
    Field& field = NextField(fields, count);
    for (; counted < i; ++counted) code_points += IsContinuationByte(line[counted]) ? 0 : 1;
    field.start = code_points;
    const std::size_t begin = i;
    if (line[i] == '"') {
      field.quoted = true;
      ++i;
      while (true) {
        if (i >= line.size()) {
          diags.Report(DiagKind::CsvUnclosedQuote, lines.Range(number, begin, 1));
          fields.resize(count);
          return false;
        }
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            field.text += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        field.text += line[i++];
      }
      if (i < line.size() && !IsBlank(line[i])) {
        diags.Report(DiagKind::CsvStrayQuote, lines.Range(number, i, 1), "text after the closing quote of a field");
        fields.resize(count);
        return false;
      }
      TrimInPlace(field.text);
    } else {
      while (i < line.size() && !IsBlank(line[i])) ++i;
      field.text.assign(line.substr(begin, i - begin));
    }
    field.range = lines.Range(number, begin, i - begin);
  }
}

bool SplitFixed(const Lines& lines, std::uint32_t number, const std::vector<std::size_t>& starts,
                std::vector<Field>& fields) {
  fields.clear();
  std::string_view line = lines.Text(number);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    std::size_t begin = ByteOfCodePoint(line, starts[k]);
    std::size_t end = k + 1 < starts.size() ? ByteOfCodePoint(line, starts[k + 1]) : line.size();
    // A cut must fall between words: the byte before a column is blank.
    if (begin > 0 && begin < line.size() && !IsBlank(line[begin - 1])) return false;
    std::string_view slice = line.substr(begin, end - begin);
    std::size_t lead = 0;
    while (lead < slice.size() && IsBlank(slice[lead])) ++lead;
    std::string_view text = Trim(slice);
    Field field;
    field.start = starts[k];
    field.range = lines.Range(number, begin + lead, text.size());
    if (text.size() >= 2 && text.front() == '"' && text.back() == '"') {
      field.quoted = true;
      text = Trim(text.substr(1, text.size() - 2));
    }
    field.text = std::string(text);
    fields.push_back(std::move(field));
  }
  return true;
}

char GuessDelimiter(std::string_view line) {
  std::size_t comma = 0, semicolon = 0, tab = 0;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    comma += c == ',';
    semicolon += c == ';';
    tab += c == '\t';
  }
  if (semicolon > comma && semicolon >= tab) return ';';
  if (tab > comma && tab > semicolon) return '\t';
  return ',';
}

// ------------------------------------------------------------------ numbers


namespace {

std::optional<double> ParseDecimal(std::string_view text, bool decimal_comma) {
  if (decimal_comma && text.find(',') != std::string_view::npos && text.find('.') == std::string_view::npos &&
      std::count(text.begin(), text.end(), ',') == 1) {
    std::string copy(text);
    std::replace(copy.begin(), copy.end(), ',', '.');
    return ParseNumber(copy);
  }
  return ParseNumber(text);
}

}  // namespace

std::optional<LengthUnit> UnitFromName(std::string_view name) {
  std::string lower = AsciiLowercase(Trim(name));
  if (lower == "mm") return LengthUnit::kMm;
  if (lower == "mil" || lower == "mils") return LengthUnit::kMil;
  if (lower == "in" || lower == "inch" || lower == "inches" || lower == "\"") return LengthUnit::kInch;
  return std::nullopt;
}

Length ParseLength(std::string_view text, LengthUnit unit, bool decimal_comma) {
  Length length;
  NumberText parts = SplitSuffix(Trim(text));
  length.suffix = parts.suffix;
  std::optional<double> value = ParseDecimal(parts.number, decimal_comma);
  if (!value || !std::isfinite(*value)) {
    length.status = Length::Status::kNotNumber;
    return length;
  }
  if (!parts.suffix.empty()) {
    std::optional<LengthUnit> written = UnitFromName(parts.suffix);
    if (!written) {
      length.status = Length::Status::kUnknownUnit;
      return length;
    }
    unit = *written;
  }
  double mm = *value * MmPer(unit);
  if (std::abs(mm) > kMaxLengthMm) {
    length.mm = mm;  // for the message
    length.status = Length::Status::kTooLarge;
    return length;
  }
  length.mm = Round(mm, kCadResolutionMm);
  if (length.mm == 0) length.mm = 0;  // no "-0.0" in the program
  length.status = Length::Status::kOk;
  return length;
}

std::optional<double> ParseAngle(std::string_view text, bool decimal_comma) {
  text = Trim(text);
  if (text.ends_with("\xC2\xB0")) {  // °
    text.remove_suffix(2);
  } else if (text.size() > 3 && EqualsIgnoreCase(text.substr(text.size() - 3), "deg")) {
    text.remove_suffix(3);
  }
  std::optional<double> value = ParseDecimal(Trim(text), decimal_comma);
  if (!value || !std::isfinite(*value)) return std::nullopt;
  return *value;
}

std::optional<Side> ParseSide(std::string_view text) {
  std::string lower = AsciiLowercase(Trim(text));
  lower.erase(std::remove(lower.begin(), lower.end(), ' '), lower.end());
  for (std::string_view top : {"top", "t", "front", "f", "f.cu", "toplayer", "topside"}) {
    if (lower == top) return Side::kTop;
  }
  for (std::string_view bottom : {"bottom", "b", "bot", "back", "b.cu", "bottomlayer", "bottomside"}) {
    if (lower == bottom) return Side::kBottom;
  }
  return std::nullopt;
}

std::optional<bool> ParseDnp(std::string_view text) {
  std::string lower = AsciiLowercase(Trim(text));
  for (std::string_view yes : {"yes", "y", "true", "1", "x", "dnp", "dnf", "dni", "excluded"}) {
    if (lower == yes) return true;
  }
  for (std::string_view no : {"", "no", "n", "false", "0"}) {
    if (lower == no) return false;
  }
  return std::nullopt;
}

// ------------------------------------------------------------------ column names

ColumnName NormaliseColumnName(std::string_view name) {
  ColumnName column;
  name = Trim(name);
  // A unit after the name: "X (mm)", "Center-X(mil)", "PosX[mm]".
  if (!name.empty() && (name.back() == ')' || name.back() == ']')) {
    char open = name.back() == ')' ? '(' : '[';
    std::size_t at = name.rfind(open);
    if (at != std::string_view::npos) {
      std::string_view unit = name.substr(at + 1, name.size() - at - 2);
      column.unit = UnitFromName(unit);
      if (!column.unit) column.unit_text = std::string(Trim(unit));
      name = name.substr(0, at);
    }
  }
  for (char c : name) {
    if (c == ' ' || c == '\t' || c == '-' || c == '_' || c == '.') continue;
    column.base += AsciiLower(c);
  }
  return column;
}


bool GlobMatch(std::string_view pattern, std::string_view text) {
  // The common shapes first: "PREFIX*" and "*PART*" (every row of a large
  // list meets the default exclusions).
  auto same = [](char a, char b) { return AsciiLower(a) == AsciiLower(b); };
  if (pattern.find('?') == std::string_view::npos) {
    std::size_t stars = std::count(pattern.begin(), pattern.end(), '*');
    if (stars == 1 && pattern.back() == '*') {
      std::string_view prefix = pattern.substr(0, pattern.size() - 1);
      return text.size() >= prefix.size() && std::equal(prefix.begin(), prefix.end(), text.begin(), same);
    }
    if (stars == 2 && pattern.size() >= 2 && pattern.front() == '*' && pattern.back() == '*') {
      std::string_view part = pattern.substr(1, pattern.size() - 2);
      return std::search(text.begin(), text.end(), part.begin(), part.end(), same) != text.end();
    }
  }
  // Otherwise an iterative matcher with one backtrack point per '*'.
  std::size_t p = 0, t = 0, star = std::string_view::npos, mark = 0;
  auto step = [&](std::size_t i) {  // the length of the code point at text[i]
    std::size_t n = Utf8Length(text, i);
    return n == 0 ? 1 : n;
  };
  while (t < text.size()) {
    if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      mark = t;
    } else if (p < pattern.size() && pattern[p] == '?') {
      ++p;
      t += step(t);
    } else if (p < pattern.size() && AsciiLower(pattern[p]) == AsciiLower(text[t])) {
      ++p;
      ++t;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      mark += step(mark);
      t = mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

// ------------------------------------------------------------------ packages

namespace {

// Chip sizes, imperial code (inch/100) and metric code (mm/10).
struct ChipSizeCode {
  std::string_view imperial;
  std::string_view metric;
};
constexpr ChipSizeCode kChipSizes[] = {
    {"01005", "0402"}, {"0201", "0603"}, {"0402", "1005"}, {"0603", "1608"}, {"0805", "2012"},
    {"1008", "2520"},  {"1206", "3216"}, {"1210", "3225"}, {"1806", "4516"}, {"1812", "4532"},
    {"1825", "4564"},  {"2010", "5025"}, {"2220", "5750"}, {"2512", "6332"},
};

// IPC-7351 land pattern families whose names go on with the metric size:
// CAPC2012X135N, RESC1005X40N, INDC3225X...
constexpr std::string_view kIpcFamilies[] = {"capc", "capm", "capmp", "resc", "resm", "indc", "indm", "indp",
                                             "dioc", "diom", "ledc", "ledm", "fusc", "fusm"};

// Runs of letters and runs of digits, lower case; everything else splits.
std::vector<std::string> NameTokens(std::string_view name) {
  std::vector<std::string> tokens;
  auto kind = [](char c) {
    if (c >= '0' && c <= '9') return 1;
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')) return 2;
    return 0;
  };
  for (std::size_t i = 0; i < name.size();) {
    int k = kind(name[i]);
    if (k == 0) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < name.size() && kind(name[end]) == k) ++end;
    tokens.push_back(AsciiLowercase(name.substr(i, end - i)));
    i = end;
  }
  return tokens;
}

std::string_view ImperialFromMetric(std::string_view metric) {
  for (const ChipSizeCode& size : kChipSizes) {
    if (size.metric == metric) return size.imperial;
  }
  return {};
}

// The size a feeder's pattern names: "0805", "2012Metric" -> "0805".
std::string_view PatternSize(std::string_view pattern) {
  for (const ChipSizeCode& size : kChipSizes) {
    if (size.imperial == pattern) return size.imperial;
  }
  std::string lower = AsciiLowercase(pattern);
  if (lower.size() > 6 && lower.ends_with("metric")) return ImperialFromMetric(std::string_view(pattern).substr(0, lower.size() - 6));
  return {};
}

std::string WithoutSeparators(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c != '-' && c != '_' && c != ' ') out += c;
  }
  return out;
}

}  // namespace

std::string_view ChipSize(std::string_view package) {
  std::vector<std::string> tokens = NameTokens(package);
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& token = tokens[i];
    if (token.size() < 4 || token.size() > 5 || token.front() < '0' || token.front() > '9') continue;
    const bool before_metric = i + 1 < tokens.size() && tokens[i + 1] == "metric";
    const bool after_family = i > 0 && std::find(std::begin(kIpcFamilies), std::end(kIpcFamilies), tokens[i - 1]) !=
                                           std::end(kIpcFamilies);
    if (before_metric || after_family) {
      if (std::string_view imperial = ImperialFromMetric(token); !imperial.empty()) return imperial;
      continue;
    }
    for (const ChipSizeCode& size : kChipSizes) {
      if (size.imperial == token) return size.imperial;
    }
  }
  return {};
}

bool PackageMatch(std::string_view pattern, std::string_view package) {
  if (std::string_view size = PatternSize(pattern); !size.empty()) return ChipSize(package) == size;
  return GlobMatch(WithoutSeparators(pattern), WithoutSeparators(package));
}

// ------------------------------------------------------------------ names

std::string_view FormatName(Format format) { return kFormatNames[static_cast<int>(format)]; }

std::string_view FormatTitle(Format format) {
  switch (format) {
    case Format::kKicadPos: return "KiCad .pos";
    case Format::kKicadCsv: return "KiCad CSV";
    case Format::kJlcpcb: return "JLCPCB CPL";
    case Format::kEasyEda: return "EasyEDA pick and place";
    case Format::kAltium: return "Altium pick and place";
    case Format::kEagle: return "Eagle mountsmd";
    case Format::kDipTrace: return "DipTrace";
    case Format::kGenericCsv: return "CSV";
  }
  return "?";
}

std::optional<Format> FormatFromName(std::string_view name) {
  for (int i = 0; i < static_cast<int>(std::size(kFormatNames)); ++i) {
    if (EqualsIgnoreCase(name, kFormatNames[i])) return static_cast<Format>(i);
  }
  return std::nullopt;
}

std::string_view UnitName(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kMm: return "mm";
    case LengthUnit::kMil: return "mil";
    case LengthUnit::kInch: return "in";
  }
  return "mm";
}

double MmPer(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kMm: return 1.0;
    case LengthUnit::kMil: return 0.0254;
    case LengthUnit::kInch: return 25.4;
  }
  return 1.0;
}

std::string_view SideName(Side side) { return side == Side::kTop ? "top" : "bottom"; }

}  // namespace smtcal::cad

// OpenList: detection, then the family's reader (see cad_reader.h).
#include "frontend/cad/cad_reader.h"

#include <algorithm>

#include <fmt/format.h>

#include "frontend/cad/cad_table.h"

namespace smtcal::cad {

std::optional<std::uint32_t> DecodeList(std::uint32_t file, SourceManager& sources, Diagnostics& diags,
                                        TextEncoding& encoding) {
  const SourceFile& raw = sources.File(file);
  DecodedText decoded = DecodeListText(raw.text);
  encoding = decoded.encoding;
  if (!decoded.ok) {
    // The line and column of the byte in the file as it is.
    auto line = std::upper_bound(raw.line_starts.begin(), raw.line_starts.end(), decoded.bad_offset);
    auto number = static_cast<std::uint32_t>(line - raw.line_starts.begin());
    auto column = static_cast<std::uint32_t>(decoded.bad_offset - raw.line_starts[number - 1] + 1);
    diags.Report(DiagKind::CadUndecodable, SourceRange(SourceLoc{file, number, column}, 1), decoded.why);
    return std::nullopt;
  }
  if (decoded.encoding == TextEncoding::kUtf8) return file;
  return sources.Add(raw.name, std::move(decoded.text));
}

std::unique_ptr<ListReader> OpenList(std::uint32_t file, const ReadOptions& options, Diagnostics& diags) {
  Lines lines(diags.sources(), file);
  std::optional<Format> format = options.format ? options.format : DetectFormat(lines, diags.sources());
  if (!format) {
    std::string names;
    for (std::string_view name : kFormatNames) names += (names.empty() ? "" : ", ") + std::string(name);
    std::uint32_t first = 1;
    while (first < lines.count() && lines.IsFiller(first)) ++first;
    diags.Report(DiagKind::CadUnknownFormat, RowRange(lines, first), names);
    return nullptr;
  }
  switch (*format) {
    case Format::kKicadPos: return OpenTable(lines, KicadPosDialect(), options, diags);
    case Format::kKicadCsv: return OpenTable(lines, KicadCsvDialect(), options, diags);
    case Format::kJlcpcb: return OpenTable(lines, JlcpcbDialect(), options, diags);
    case Format::kEasyEda: return OpenTable(lines, EasyEdaDialect(), options, diags);
    case Format::kAltium: return OpenTable(lines, AltiumDialect(), options, diags);
    case Format::kDipTrace: return OpenTable(lines, DipTraceDialect(), options, diags);
    case Format::kGenericCsv: return OpenTable(lines, GenericDialect(options.mapping), options, diags);
    case Format::kEagle: return OpenEagle(lines, options, diags);
  }
  return nullptr;
}

}  // namespace smtcal::cad

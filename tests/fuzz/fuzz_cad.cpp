// A CAD placement list (`smtcal import`): the first byte chooses the format
// (detection, or one of the --format names, with each --units and
// --delimiter), the rest is the list. Every row goes through the importer
// with the import test cell's feeders to a printed program.
#include "backend/place/place_printer.h"
#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_to_program.h"
#include "frontend/feeders_toml.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(cad) {
  using namespace smtcal;
  if (size == 0) return 0;
  static const cad::FeederTable* feeders = [] {
    SourceManager sources;
    Diagnostics diags(sources);
    std::optional<cad::FeederTable> table = cad::FeederTable::Build(fuzz::ImportCell().feeders, {}, diags);
    if (!table) fuzz::Fail("the import cell's feeders are not valid");
    return new cad::FeederTable(std::move(*table));
  }();
  const std::uint8_t choice = data[0];
  cad::ReadOptions read;
  if (choice % 8 != 7) read.format = static_cast<cad::Format>(choice % 8);  // 7: detect
  if ((choice >> 3) % 4 != 0) read.units = static_cast<cad::LengthUnit>((choice >> 3) % 4 - 1);
  constexpr char kDelimiters[] = {',', ';', '\t', ' '};
  if ((choice >> 5) % 2 != 0) read.delimiter = kDelimiters[(choice >> 6) % 4];
  if (read.format == cad::Format::kGenericCsv) {
    (void)cad::ParseColumnMapping("designator=Ref,x=X,y=Y,rotation=Rot,value=Val,package=Package,side=Side",
                                  read.mapping);
  }
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("list.txt", std::string(fuzz::AsText(data + 1, size - 1)));
  std::unique_ptr<cad::ListReader> reader = cad::OpenList(file, read, diags);
  if (reader) {
    ImportOptions options;
    options.program_name = "Fuzz";
    options.fixture = fuzz::ImportCell().fixtures.front().name;
    options.skip_unmapped = (choice & 1) != 0;
    CadImporter importer(*feeders, options, file, diags);
    cad::Row row;
    while (reader->Next(row)) importer.Add(row);
    std::optional<ir::Program> program = importer.Finish(*reader);
    if (program) PrintPlace(*program);
    FormatImportSummary(importer.summary());
  }
  diags.RenderText();
  return 0;
}

// A LinuxCNC machine configuration (`smtcal compile --target linuxcnc --ini`):
// the input is an INI file, optionally followed by a line `%%HAL%%` and a
// HAL file, written as machine.ini and machine.hal (an INI's HALFILE may name
// machine.hal, an #INCLUDE may name machine.ini itself). Runs the INI and
// HAL readers, the check of the machine against the example cell with the
// example program's vacuum output and the cell's vacuum switch, and the
// runtime's folder from SUBROUTINE_PATH.
#include "backend/linuxcnc/linuxcnc_machine.h"
#include "frontend/linuxcnc_config.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(linuxcnc_ini) {
  using namespace smtcal;
  const std::string_view input = fuzz::AsText(data, size);
  constexpr std::string_view kHalMark = "\n%%HAL%%\n";
  const std::size_t mark = input.find(kHalMark);
  const std::string ini_path = fuzz::WriteScratch("machine.ini", input.substr(0, mark));
  fuzz::WriteScratch("machine.hal", mark == std::string_view::npos ? "" : input.substr(mark + kHalMark.size()));
  SourceManager sources;
  Diagnostics diags(sources);
  Result<IniFile> ini = ReadLinuxCncIni(ini_path, sources, diags);
  if (ini) {
    const HalConfig hal = ReadLinuxCncHal(ini.value(), sources, diags);
    const std::vector<LinuxCncIoUse> io = {{true, 8, "vacuum output", SourceRange()},
                                           {false, 11, "the vacuum switch", SourceRange()}};
    CheckLinuxCncMachine(fuzz::ExampleCell(), io, ini.value(), hal, sources, diags);
    (void)LinuxCncRuntimeFolder(ini.value());
  }
  diags.RenderText();
  diags.RenderJson();
  return 0;
}

// A LinuxCNC machine configuration as LinuxCNC reads it: the INI file (with
// its #INCLUDE lines expanded, as the `linuxcnc` script does) and the HAL
// files its [HAL] section names. `smtcal compile --target linuxcnc --ini`
// checks them against the cell (backend/linuxcnc/linuxcnc_machine.h;
// docs/linuxcnc.md, "The machine's configuration").
//
// INI: `[SECTION]` lines, `KEY = VALUE` lines (spaces around the value
// dropped), `#` and `;` comment lines; LinuxCNC takes the first value of a
// key in a section, and so does Find(). `#INCLUDE FILE` includes FILE
// (relative to the including INI's folder) at that line, one level deep as
// the script does.
//
// HAL: what smtcal needs of it: which pins the `net` (and `linkps`/`linksp`)
// lines connect, with `[SECTION]KEY` replaced by the INI's value, and the
// `num_dio` of the motion controller (`loadrt motmod ... num_dio=N`, 4 when
// not given). Other commands are read past. HAL files in Tcl (`.tcl`) or
// from LinuxCNC's library (`LIB:`) cannot be read: a warning says so, and
// nothing in them counts as connected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"

namespace smtcal {

struct IniEntry {
  std::string section;  // without the brackets, as written
  std::string key;
  std::string value;
  SourceRange range;  // the value (the key when the value is empty)
};

struct IniFile {
  std::string path;                 // as given
  std::filesystem::path directory;  // where relative paths in it start (LinuxCNC runs there)
  std::vector<IniEntry> entries;    // in reading order, includes expanded
  SourceRange range;                // the file's first line (for a key that is missing)

  // The first entry of the key in the section (as LinuxCNC reads it), or null.
  const IniEntry* Find(std::string_view section, std::string_view key) const;
  // Every entry of the key in the section, in order (HALFILE lists several).
  std::vector<const IniEntry*> FindAll(std::string_view section, std::string_view key) const;
};

// Reads the INI file and its includes. I/O failures (the file itself) are
// the Result's error; a missing include or a line that is neither is a
// diagnostic (the file is still returned).
Result<IniFile> ReadLinuxCncIni(const std::string& path, SourceManager& sources, Diagnostics& diags);

struct HalPin {
  std::string signal;  // the net that connects it
  SourceRange range;   // the pin on its net line
};

struct HalConfig {
  std::map<std::string, HalPin> connected;  // every pin a net connects, by name
  int num_dio = 4;                          // motmod's digital inputs and outputs
  SourceRange motmod;                       // its loadrt line, if read
  bool motmod_found = false;
  std::vector<std::string> unread;          // HAL files that could not be read (Tcl, LIB:)
};

// Reads every HAL file of [HAL]HALFILE and [HAL]POSTGUI_HALFILE, relative to
// the INI's folder. A file that cannot be opened is a diagnostic at its
// HALFILE value.
HalConfig ReadLinuxCncHal(const IniFile& ini, SourceManager& sources, Diagnostics& diags);

}  // namespace smtcal

// Reading a LinuxCNC machine configuration (linuxcnc_config.h). Assumes
// nothing of the files; guarantees every entry and pin a range in the file
// it came from.
#include "frontend/linuxcnc_config.h"

#include <algorithm>
#include <cctype>
#include <charconv>

#include <fmt/format.h>

namespace smtcal {
namespace fs = std::filesystem;

namespace {

std::string_view Trim(std::string_view text) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!text.empty() && space(text.front())) text.remove_prefix(1);
  while (!text.empty() && space(text.back())) text.remove_suffix(1);
  return text;
}

SourceRange RangeAt(std::uint32_t file, std::uint32_t line, std::size_t column, std::size_t length) {
  return SourceRange(SourceLoc{file, line, static_cast<std::uint32_t>(column + 1)},
                     static_cast<std::uint32_t>(length));
}

// The lines of one INI file into `ini`; `depth` 0 is the main file, whose
// #INCLUDE lines are expanded.
void ReadIniLines(std::uint32_t file, const fs::path& directory, int depth, std::string& section, IniFile& ini,
                  SourceManager& sources, Diagnostics& diags) {
  const SourceFile& source = sources.File(file);
  for (std::uint32_t n = 1; n <= source.line_starts.size(); ++n) {
    const std::string_view whole = source.Line(n);
    const std::string_view line = Trim(whole);
    const std::size_t indent = static_cast<std::size_t>(line.data() - whole.data());
    if (line.empty()) continue;
    if (line.starts_with("#INCLUDE")) {
      const std::string name(Trim(line.substr(8)));
      const SourceRange where = RangeAt(file, n, indent, line.size());
      if (depth > 0) {
        diags.Report(DiagKind::LinuxCncIniLine, where, "an #INCLUDE inside an included file",
                     "the linuxcnc script expands the includes of the INI it starts with only");
        continue;
      }
      const fs::path included = fs::path(name).is_absolute() ? fs::path(name) : directory / name;
      Result<std::uint32_t> loaded = name.empty() ? Result<std::uint32_t>(Error{"no file named"})
                                                  : sources.Load(included.string());
      if (!loaded) {
        diags.Report(DiagKind::LinuxCncConfigFileMissing, where, "#INCLUDE", name, loaded.error().message);
        continue;
      }
      ReadIniLines(loaded.value(), directory, depth + 1, section, ini, sources, diags);
      continue;
    }
    if (line.front() == '#' || line.front() == ';') continue;
    if (line.front() == '[') {
      const std::size_t close = line.find(']');
      if (close == std::string_view::npos) {
        diags.Report(DiagKind::LinuxCncIniLine, RangeAt(file, n, indent, line.size()), "a section without ']'",
                     "write [SECTION]");
        continue;
      }
      section = std::string(line.substr(1, close - 1));
      continue;
    }
    const std::size_t equals = line.find('=');
    if (equals == std::string_view::npos) {
      diags.Report(DiagKind::LinuxCncIniLine, RangeAt(file, n, indent, line.size()), "a line that is not KEY = VALUE",
                   "LinuxCNC reads nothing from it");
      continue;
    }
    IniEntry entry;
    entry.section = section;
    entry.key = std::string(Trim(line.substr(0, equals)));
    const std::string_view value = Trim(line.substr(equals + 1));
    entry.value = std::string(value);
    const std::size_t column = value.empty() ? indent : static_cast<std::size_t>(value.data() - whole.data());
    entry.range = RangeAt(file, n, column, value.empty() ? entry.key.size() : value.size());
    ini.entries.push_back(std::move(entry));
  }
}

// "[SECTION]KEY" replaced by the INI's value, as halcmd does (-i INI).
std::string Substitute(std::string_view token, const IniFile& ini) {
  if (token.size() < 4 || token.front() != '[') return std::string(token);
  const std::size_t close = token.find(']');
  if (close == std::string_view::npos || close + 1 >= token.size()) return std::string(token);
  const IniEntry* entry = ini.Find(token.substr(1, close - 1), token.substr(close + 1));
  return entry != nullptr ? entry->value : std::string(token);
}

struct Token {
  std::string text;
  std::size_t column = 0;
};

std::vector<Token> Tokens(std::string_view line) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i >= line.size() || line[i] == '#') break;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    tokens.push_back({std::string(line.substr(start, i - start)), start});
  }
  return tokens;
}

void ReadHalLines(std::uint32_t file, const IniFile& ini, HalConfig& hal, SourceManager& sources) {
  const SourceFile& source = sources.File(file);
  for (std::uint32_t n = 1; n <= source.line_starts.size(); ++n) {
    std::vector<Token> tokens = Tokens(source.Line(n));
    if (tokens.empty()) continue;
    for (Token& token : tokens) token.text = Substitute(token.text, ini);
    const std::string& command = tokens.front().text;
    auto connect = [&](const Token& pin, const std::string& signal) {
      hal.connected.emplace(pin.text, HalPin{signal, RangeAt(file, n, pin.column, pin.text.size())});
    };
    if (command == "net" && tokens.size() >= 2) {
      for (std::size_t k = 2; k < tokens.size(); ++k) {
        const std::string& text = tokens[k].text;
        if (text == "=>" || text == "<=" || text == "<=>") continue;
        connect(tokens[k], tokens[1].text);
      }
    } else if (command == "linkps" && tokens.size() >= 3) {
      connect(tokens[1], tokens[2].text);
    } else if (command == "linksp" && tokens.size() >= 3) {
      connect(tokens[2], tokens[1].text);
    } else if (command == "loadrt" && tokens.size() >= 2 && tokens[1].text == "motmod") {
      hal.motmod_found = true;
      hal.motmod = RangeAt(file, n, tokens.front().column, source.Line(n).size() - tokens.front().column);
      for (std::size_t k = 2; k < tokens.size(); ++k) {
        const std::string& text = tokens[k].text;
        if (!text.starts_with("num_dio=")) continue;
        int value = 0;
        const auto [end, error] = std::from_chars(text.data() + 8, text.data() + text.size(), value);
        if (error == std::errc() && end == text.data() + text.size()) hal.num_dio = value;
      }
    }
  }
}

}  // namespace

const IniEntry* IniFile::Find(std::string_view section, std::string_view key) const {
  for (const IniEntry& entry : entries) {
    if (entry.section == section && entry.key == key) return &entry;
  }
  return nullptr;
}

std::vector<const IniEntry*> IniFile::FindAll(std::string_view section, std::string_view key) const {
  std::vector<const IniEntry*> found;
  for (const IniEntry& entry : entries) {
    if (entry.section == section && entry.key == key) found.push_back(&entry);
  }
  return found;
}

Result<IniFile> ReadLinuxCncIni(const std::string& path, SourceManager& sources, Diagnostics& diags) {
  Result<std::uint32_t> file = sources.Load(path);
  if (!file) return file.error();
  IniFile ini;
  ini.path = path;
  ini.directory = fs::path(path).parent_path();
  if (ini.directory.empty()) ini.directory = ".";
  ini.range = RangeAt(file.value(), 1, 0, 1);
  std::string section;
  ReadIniLines(file.value(), ini.directory, 0, section, ini, sources, diags);
  return ini;
}

HalConfig ReadLinuxCncHal(const IniFile& ini, SourceManager& sources, Diagnostics& diags) {
  HalConfig hal;
  std::vector<const IniEntry*> files = ini.FindAll("HAL", "HALFILE");
  for (const IniEntry* entry : ini.FindAll("HAL", "POSTGUI_HALFILE")) files.push_back(entry);
  for (const IniEntry* entry : files) {
    const std::string& name = entry->value;
    if (name.starts_with("LIB:") || fs::path(name).extension() == ".tcl") {
      hal.unread.push_back(name);
      diags.Report(DiagKind::LinuxCncHalNotRead, entry->range, name);
      continue;
    }
    const fs::path resolved = fs::path(name).is_absolute() ? fs::path(name) : ini.directory / name;
    Result<std::uint32_t> loaded = sources.Load(resolved.string());
    if (!loaded) {
      diags.Report(DiagKind::LinuxCncConfigFileMissing, entry->range, "HALFILE", name, loaded.error().message);
      continue;
    }
    ReadHalLines(loaded.value(), ini, hal, sources);
  }
  return hal;
}

}  // namespace smtcal

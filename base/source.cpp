#include "base/source.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

#include <fmt/core.h>

#include "base/text_output.h"

namespace smtcal {

std::string_view SourceFile::Line(std::uint32_t line) const {
  if (line == 0 || line > line_starts.size()) return {};
  std::size_t begin = line_starts[line - 1];
  std::size_t end = line < line_starts.size() ? line_starts[line] : text.size();
  std::string_view view(text.data() + begin, end - begin);
  while (!view.empty() && (view.back() == '\n' || view.back() == '\r')) view.remove_suffix(1);
  return view;
}

std::uint32_t SourceManager::Add(std::string name, std::string text) {
  auto file = std::make_unique<SourceFile>();
  file->name = std::move(name);
  file->text = std::move(text);
  file->line_starts.push_back(0);
  for (std::size_t i = 0; i < file->text.size(); ++i) {
    if (file->text[i] == '\n' && i + 1 < file->text.size()) file->line_starts.push_back(i + 1);
  }
  files_.push_back(std::move(file));
  return static_cast<std::uint32_t>(files_.size());
}

Result<std::uint32_t> SourceManager::Load(const std::string& path) {
  std::string text;
  if (path == "-") {
    text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    return Add("<stdin>", std::move(text));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{fmt::format("cannot open '{}': {}", path, std::strerror(errno))};
  // Read in chunks into a string sized for the file up front: a large file is
  // held once, not twice (a stream buffer and its copy) while it is read.
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  std::error_code size_error;
  std::uintmax_t size = std::filesystem::file_size(path, size_error);
  if (!size_error) text.reserve(static_cast<std::size_t>(size) + kChunk);
  for (;;) {
    const std::size_t read = text.size();
    text.resize(read + kChunk);
    in.read(text.data() + read, static_cast<std::streamsize>(kChunk));
    text.resize(read + static_cast<std::size_t>(in.gcount()));
    if (!in) break;
  }
  if (in.bad()) return Error{fmt::format("cannot read '{}': {}", path, std::strerror(errno))};
  return Add(path, std::move(text));
}

const SourceFile& SourceManager::File(std::uint32_t id) const {
  SMTCAL_CHECK(id >= 1 && id <= files_.size(), "unknown source file id");
  return *files_[id - 1];
}

Status WriteFileAtomically(const std::string& path, std::string_view contents) {
  Result<std::unique_ptr<TextOutput>> output = TextOutput::Open(path);
  if (!output) return output.error();
  output.value()->Append(contents);
  return output.value()->Commit();
}

}  // namespace smtcal

#include "base/text_output.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/core.h>

namespace smtcal {

Result<std::unique_ptr<TextOutput>> TextOutput::Open(const std::string& path) {
  auto output = std::make_unique<TextOutput>();
  output->path_ = path;
  if (path == "-") return output;
  output->temp_ = fmt::format("{}.tmp.{}", path, ::getpid());
  output->file_ = std::fopen(output->temp_.c_str(), "wb");
  // Name the file the user asked for; the temporary is our business.
  if (output->file_ == nullptr) return Error{fmt::format("cannot write '{}': {}", path, std::strerror(errno))};
  return output;
}

TextOutput::~TextOutput() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::remove(temp_.c_str());
  }
}

void TextOutput::Flush() {
  if (error_ == 0 && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) error_ = errno;
  written_ += buffer_.size();
  buffer_.clear();
}

Status TextOutput::Commit() {
  if (path_.empty()) return Ok{};
  if (path_ == "-") {
    std::fwrite(buffer_.data(), 1, buffer_.size(), stdout);
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) return Error{"cannot write to standard output"};
    return Ok{};
  }
  Flush();
  if (std::fflush(file_) != 0 && error_ == 0) error_ = errno;
  if (std::fclose(file_) != 0 && error_ == 0) error_ = errno;
  file_ = nullptr;
  if (error_ != 0) {
    std::remove(temp_.c_str());
    return Error{fmt::format("cannot write '{}': {}", path_, std::strerror(error_))};
  }
  if (std::rename(temp_.c_str(), path_.c_str()) != 0) {
    int saved = errno;
    std::remove(temp_.c_str());
    return Error{fmt::format("cannot write '{}' (renaming the finished temporary '{}' failed): {}", path_, temp_,
                             std::strerror(saved))};
  }
  return Ok{};
}

}  // namespace smtcal

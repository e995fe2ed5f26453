#include "base/text_output.h"

#include <utility>

namespace smtcal {

Result<std::unique_ptr<TextOutput>> TextOutput::Open(const std::string& path) {
  auto output = std::make_unique<TextOutput>();
  output->path_ = path;
  if (path == "-") return output;  // kept whole: nothing of a failed run is printed
  Result<StagedOutput> staged = StagedOutput::Open(path);
  if (!staged) return staged.error();
  output->file_.emplace(std::move(staged).value());
  return output;
}

// A TextOutput never committed leaves nothing: the StagedOutput removes its
// temporary.
TextOutput::~TextOutput() = default;

void TextOutput::Flush() {
  file_->Append(buffer_);
  written_ += buffer_.size();
  buffer_.clear();
}

Status TextOutput::Commit() {
  if (path_.empty()) return Ok{};
  if (path_ == "-") return WriteToStdout(buffer_);
  Flush();
  Status committed = file_->Commit();
  file_.reset();
  return committed;
}

}  // namespace smtcal

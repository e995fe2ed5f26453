// An output text written as it is produced, still atomically: the pieces go
// to a temporary file beside the target (a StagedOutput, base/source.h, with
// its rules for links, devices and modes), and only Commit() renames it into
// place, so a run that fails (or is killed) never leaves a half-written
// file, and a large output never has to be held in memory at once. Standard
// output ("-") and memory keep the whole text until Commit(), for the same
// reason (nothing of a failed run is printed).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "base/result.h"
#include "base/source.h"

namespace smtcal {

class TextOutput {
 public:
  // Kept in memory: text() after Commit().
  TextOutput() = default;
  // To `path` ("-": standard output); an Error names the file when the
  // temporary cannot be created.
  static Result<std::unique_ptr<TextOutput>> Open(const std::string& path);
  ~TextOutput();  // an output never committed leaves nothing behind
  TextOutput(const TextOutput&) = delete;
  TextOutput& operator=(const TextOutput&) = delete;

  // Producers append to buffer() (fmt::format_to(std::back_inserter(...)))
  // and call Produced() now and then, which writes a large buffer out.
  std::string& buffer() { return buffer_; }
  void Append(std::string_view text) {
    buffer_.append(text);
    Produced();
  }
  void Produced() {
    if (file_ && buffer_.size() >= kFlushBytes) Flush();
  }

  // Writes what is left and renames the temporary to the target (prints it,
  // for standard output). An Error names the target.
  Status Commit();
  // The whole text of an output kept in memory or for standard output.
  const std::string& text() const { return buffer_; }
  // Bytes produced so far.
  std::size_t size() const { return written_ + buffer_.size(); }

 private:
  static constexpr std::size_t kFlushBytes = 1 << 20;
  void Flush();

  std::string path_;                  // the target; empty for memory
  std::optional<StagedOutput> file_;  // a file's temporary, until Commit
  std::string buffer_;
  std::size_t written_ = 0;
};

}  // namespace smtcal

// Source files and locations. Every IR node and every diagnostic carries a
// SourceLoc; the SourceManager owns the text so diagnostics can quote lines.
// Outputs are written atomically (StagedOutput, WriteFileAtomically).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/result.h"

namespace smtcal {

struct SourceLoc {
  std::uint32_t file = 0;    // index into SourceManager; 0 = no file
  std::uint32_t line = 0;    // 1-based; 0 = unknown
  std::uint32_t column = 0;  // 1-based, in bytes

  bool known() const { return file != 0 && line != 0; }
  friend bool operator==(const SourceLoc&, const SourceLoc&) = default;
};

struct SourceFile {
  std::string name;  // as the user gave it (or "<stdin>")
  std::string text;
  std::vector<std::size_t> line_starts;  // byte offset of each line

  std::string_view Line(std::uint32_t line) const;  // without the newline
  // The location of a byte offset (offsets past the end: the last byte).
  SourceLoc LocationOf(std::uint32_t id, std::size_t offset) const;
};

// The most smtcal reads from one input file or from standard input. The
// largest real inputs (a million-placement program or CAD list) are under
// 100 MiB; a bound keeps `smtcal check /dev/zero` from reading forever.
inline constexpr std::size_t kMaxInputBytes = std::size_t{256} << 20;

class SourceManager {
 public:
  // Registers text under a name; returns its id (never 0).
  std::uint32_t Add(std::string name, std::string text);
  // Reads a file ("-" is stdin) and registers it. Fails on a directory and
  // on more than kMaxInputBytes.
  Result<std::uint32_t> Load(const std::string& path);

  const SourceFile& File(std::uint32_t id) const;

 private:
  std::vector<std::unique_ptr<SourceFile>> files_;
};

// An output written completely to a temporary file beside its destination,
// not yet in place. Commit() renames it over the destination; a StagedOutput
// destroyed before that removes the temporary. Staging several outputs
// before committing any is how a command writes all of them or none.
//
// The destination: "-" is standard output (written at Commit). A symbolic
// link is followed to the file it names, which is replaced (the link stays).
// A directory, device, FIFO or socket is refused: replacing it by renaming
// would be wrong, and writing into it is not atomic. An existing file keeps
// its permission bits.
//
// The temporary is "<destination>.smtcal-tmp-<pid>" (the file name shortened
// to fit the system's 255-byte limit). One left behind by a killed smtcal is
// removed the next time smtcal writes that destination.
class StagedOutput {
 public:
  // The whole contents at once.
  static Result<StagedOutput> Stage(const std::string& path, std::string_view contents);
  // An output written piece by piece (base/text_output.h): Append() as it is
  // produced, then Commit(). A failed write is reported by Commit().
  static Result<StagedOutput> Open(const std::string& path);
  void Append(std::string_view contents);

  StagedOutput(StagedOutput&& other) noexcept;
  StagedOutput& operator=(StagedOutput&& other) noexcept;
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;
  ~StagedOutput();

  Status Commit();

 private:
  StagedOutput() = default;
  Status Close();            // the temporary's descriptor; the first write error
  std::string path_;         // as the user gave it, for messages
  std::string destination_;  // the file replaced (symbolic links followed); empty: stdout
  std::string temporary_;    // empty once committed or removed
  std::string stdout_text_;  // the contents, for stdout
  int fd_ = -1;              // the temporary, while it is written
  int write_error_ = 0;      // the errno of the first failed write
};

// The file a write of `path` replaces: symbolic links followed, as
// StagedOutput follows them (`path` itself when it cannot be resolved; the
// write will say why). For commands that check their outputs against each
// other before writing.
std::string OutputDestination(const std::string& path);

// Removes the temporaries "<prefix><pid>" in `directory` of smtcal processes
// that no longer run (killed while writing); a temporary of a running process
// is its own. `remove` removes one (a file, or a folder output's folder).
void RemoveStaleTemporaries(const std::string& directory, const std::string& prefix,
                            void (*remove)(const std::string& path));

// `text` on standard output, flushed: the "-" output of StagedOutput and
// TextOutput.
Status WriteToStdout(std::string_view text);

// Stage and Commit in one: a failure never leaves a half-written output.
Status WriteFileAtomically(const std::string& path, std::string_view contents);
// Several outputs (path, contents), all or none: every one is staged before
// any is committed.
Status WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& outputs);

}  // namespace smtcal

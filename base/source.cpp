#include "base/source.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cstdio>
#include <cstring>
#include <utility>

#include <fmt/core.h>

#include "base/field_text.h"

namespace smtcal {

std::string_view SourceFile::Line(std::uint32_t line) const {
  if (line == 0 || line > line_starts.size()) return {};
  std::size_t begin = line_starts[line - 1];
  std::size_t end = line < line_starts.size() ? line_starts[line] : text.size();
  std::string_view view(text.data() + begin, end - begin);
  while (!view.empty() && (view.back() == '\n' || view.back() == '\r')) view.remove_suffix(1);
  return view;
}

SourceLoc SourceFile::LocationOf(std::uint32_t id, std::size_t offset) const {
  if (!text.empty()) offset = std::min(offset, text.size() - 1);
  auto after = std::upper_bound(line_starts.begin(), line_starts.end(), offset);
  std::size_t line = static_cast<std::size_t>(after - line_starts.begin());  // >= 1: line_starts[0] == 0
  return SourceLoc{id, static_cast<std::uint32_t>(line),
                   static_cast<std::uint32_t>(offset - line_starts[line - 1] + 1)};
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

namespace {

std::string Errno(int error) { return std::strerror(error); }

// What a file that is not a regular file is, for messages.
std::string_view FileTypeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Reads all of `fd` (at most kMaxInputBytes). `name` is for messages.
Result<std::string> ReadAll(int fd, const std::string& name) {
  std::string text;
  struct stat info {};
  if (::fstat(fd, &info) == 0) {
    if (S_ISDIR(info.st_mode)) return Error{fmt::format("cannot read '{}': it is a directory", name)};
    if (S_ISREG(info.st_mode) && static_cast<std::size_t>(info.st_size) <= kMaxInputBytes) {
      text.reserve(static_cast<std::size_t>(info.st_size));
    }
  }
  char buffer[1 << 16];
  for (;;) {
    ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return Error{fmt::format("cannot read '{}': {}", name, Errno(errno))};
    if (got == 0) return text;
    if (text.size() + static_cast<std::size_t>(got) > kMaxInputBytes) {
      return Error{fmt::format("cannot read '{}': it is larger than {} MiB, the most smtcal reads from one input "
                               "(is it the right file?)",
                               name, kMaxInputBytes >> 20)};
    }
    text.append(buffer, static_cast<std::size_t>(got));
  }
}

}  // namespace

Result<std::uint32_t> SourceManager::Load(const std::string& path) {
  if (path == "-") {
    Result<std::string> text = ReadAll(STDIN_FILENO, "<stdin>");
    if (!text) return text.error();
    return Add("<stdin>", std::move(text).value());
  }
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Error{fmt::format("cannot open '{}': {}", path, Errno(errno))};
  Result<std::string> text = ReadAll(fd, path);
  ::close(fd);
  if (!text) return text.error();
  return Add(path, std::move(text).value());
}

const SourceFile& SourceManager::File(std::uint32_t id) const {
  SMTCAL_CHECK(id >= 1 && id <= files_.size(), "unknown source file id");
  return *files_[id - 1];
}

// ------------------------------------------------------------------ outputs

namespace {

constexpr std::string_view kTemporaryMark = ".smtcal-tmp-";
constexpr int kMaxSymlinkHops = 40;  // as the kernel's own limit (ELOOP)

std::string DirectoryOf(const std::string& path) {
  std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string FileNameOf(const std::string& path) {
  std::size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The file a write to `path` replaces: symbolic links followed. An error for
// destinations that are not (or would not be) a regular file.
Result<std::string> Destination(const std::string& path) {
  std::string current = path;
  for (int hops = 0; hops <= kMaxSymlinkHops; ++hops) {
    struct stat info {};
    if (::lstat(current.c_str(), &info) != 0) {
      if (errno == ENOENT) return current;  // a new file
      return Error{fmt::format("cannot write '{}': {}", path, Errno(errno))};
    }
    if (S_ISREG(info.st_mode)) return current;
    if (!S_ISLNK(info.st_mode)) {
      return Error{fmt::format("cannot write '{}': it is {}, not a regular file; smtcal replaces its outputs "
                               "atomically, so it writes only files (to write elsewhere, use '-' for standard "
                               "output and redirect it)",
                               path, FileTypeName(info.st_mode))};
    }
    std::string target(static_cast<std::size_t>(PATH_MAX), '\0');
    ssize_t length = ::readlink(current.c_str(), target.data(), target.size());
    if (length < 0) return Error{fmt::format("cannot write '{}': {}", path, Errno(errno))};
    target.resize(static_cast<std::size_t>(length));
    current = target.starts_with('/') ? target : DirectoryOf(current) + "/" + target;
  }
  return Error{fmt::format("cannot write '{}': {}", path, Errno(ELOOP))};
}

// "<name>.smtcal-tmp-": the start of a temporary's name, followed by the
// writer's pid. The name is shortened (at a character boundary) so that the
// whole fits NAME_MAX with any pid, and every writer of the same destination
// uses the same prefix.
std::string TemporaryPrefix(const std::string& file_name) {
  constexpr std::size_t kPidDigits = 10;
  const std::size_t room = NAME_MAX - kTemporaryMark.size() - kPidDigits;
  std::size_t keep = 0;
  while (keep < file_name.size()) {
    std::size_t length = std::max<std::size_t>(Utf8Length(file_name, keep), 1);
    if (keep + length > room) break;
    keep += length;
  }
  return file_name.substr(0, keep) + std::string(kTemporaryMark);
}


}  // namespace

Result<StagedOutput> StagedOutput::Open(const std::string& path) {
  StagedOutput staged;
  staged.path_ = path;
  if (path == "-") return staged;
  Result<std::string> destination = Destination(path);
  if (!destination) return destination.error();
  staged.destination_ = std::move(destination).value();
  const std::string directory = DirectoryOf(staged.destination_);
  const std::string file_name = FileNameOf(staged.destination_);
  RemoveStaleTemporaries(directory, TemporaryPrefix(file_name), [](const std::string& stale) { ::unlink(stale.c_str()); });

  mode_t mode = 0666;  // less the umask, as any new file
  struct stat existing {};
  bool exists = ::stat(staged.destination_.c_str(), &existing) == 0;
  if (exists) mode = existing.st_mode & 07777;
  std::string temporary = fmt::format("{}/{}{}", directory, TemporaryPrefix(file_name), ::getpid());
  int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  if (fd < 0 && errno == EEXIST) {  // our own, from an earlier write of this run
    ::unlink(temporary.c_str());
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  }
  // Name the file the user asked for; the temporary is our business.
  if (fd < 0) return Error{fmt::format("cannot write '{}': {}", path, Errno(errno))};
  staged.temporary_ = temporary;
  staged.fd_ = fd;
  if (exists) (void)::fchmod(fd, mode);  // keep the replaced file's mode, umask or not
  return staged;
}

void StagedOutput::Append(std::string_view contents) {
  if (path_ == "-") {
    stdout_text_.append(contents);
    return;
  }
  while (write_error_ == 0 && fd_ >= 0 && !contents.empty()) {
    ssize_t wrote = ::write(fd_, contents.data(), contents.size());
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote < 0) write_error_ = errno;
    else contents.remove_prefix(static_cast<std::size_t>(wrote));
  }
}

Result<StagedOutput> StagedOutput::Stage(const std::string& path, std::string_view contents) {
  Result<StagedOutput> staged = Open(path);
  if (!staged) return staged.error();
  staged.value().Append(contents);
  Status closed = staged.value().Close();
  if (!closed) return closed.error();
  return staged;
}

Status StagedOutput::Close() {
  if (fd_ < 0) return Ok{};
  if (::close(fd_) != 0 && write_error_ == 0) write_error_ = errno;
  fd_ = -1;
  if (write_error_ != 0) return Error{fmt::format("cannot write '{}': {}", path_, Errno(write_error_))};
  return Ok{};
}

StagedOutput::StagedOutput(StagedOutput&& other) noexcept { *this = std::move(other); }

StagedOutput& StagedOutput::operator=(StagedOutput&& other) noexcept {
  if (this != &other) {
    if (!temporary_.empty()) ::unlink(temporary_.c_str());
    path_ = std::move(other.path_);
    destination_ = std::move(other.destination_);
    temporary_ = std::exchange(other.temporary_, std::string());
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    write_error_ = other.write_error_;
    stdout_text_ = std::move(other.stdout_text_);
  }
  return *this;
}

StagedOutput::~StagedOutput() {
  if (fd_ >= 0) ::close(fd_);
  if (!temporary_.empty()) ::unlink(temporary_.c_str());
}

std::string OutputDestination(const std::string& path) {
  Result<std::string> destination = Destination(path);
  return destination ? destination.value() : path;
}

void RemoveStaleTemporaries(const std::string& directory, const std::string& prefix,
                            void (*remove)(const std::string& path)) {
  DIR* dir = ::opendir(directory.c_str());
  if (dir == nullptr) return;
  std::vector<std::string> stale;
  while (const dirent* entry = ::readdir(dir)) {
    std::string_view name = entry->d_name;
    if (!name.starts_with(prefix) || name.size() == prefix.size()) continue;
    std::string_view digits = name.substr(prefix.size());
    long pid = 0;
    auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), pid);
    if (ec != std::errc() || end != digits.data() + digits.size() || pid <= 0) continue;
    if (pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    stale.push_back(directory + "/" + std::string(name));
  }
  ::closedir(dir);
  for (const std::string& path : stale) remove(path);
}

Status WriteToStdout(std::string_view text) {
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    return Error{fmt::format("cannot write to standard output: {}", Errno(errno))};
  }
  return Ok{};
}

Status StagedOutput::Commit() {
  if (path_ == "-") return WriteToStdout(stdout_text_);
  SMTCAL_CHECK(!temporary_.empty(), "a staged output is committed once");
  Status closed = Close();
  if (!closed) return closed.error();
  if (std::rename(temporary_.c_str(), destination_.c_str()) != 0) {
    int saved = errno;
    return Error{fmt::format("cannot write '{}' (renaming the finished temporary '{}' failed): {}", path_,
                             temporary_, Errno(saved))};
  }
  temporary_.clear();
  return Ok{};
}

Status WriteFileAtomically(const std::string& path, std::string_view contents) {
  Result<StagedOutput> staged = StagedOutput::Stage(path, contents);
  if (!staged) return staged.error();
  return staged.value().Commit();
}

Status WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::vector<StagedOutput> staged;
  for (const auto& [path, contents] : outputs) {
    Result<StagedOutput> stage = StagedOutput::Stage(path, contents);
    if (!stage) return stage.error();
    staged.push_back(std::move(stage).value());
  }
  for (StagedOutput& output : staged) {
    if (Status committed = output.Commit(); !committed) return committed;
  }
  return Ok{};
}

}  // namespace smtcal

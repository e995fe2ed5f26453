// The LinuxCNC target: a compiled program (the IR after the correction passes
// and their CompileState) lowered to RS274NGC for LinuxCNC's interpreter,
// and the output directory that holds it with the runtime subroutines
// (docs/linuxcnc.md has the lowering table, the directory and the checks).
//
// The main program calls the runtime (runtime/linuxcnc/*.ngc) for
// everything that happens on the controller: loading the cell's data, the
// marker scan and the correction of fixture and run-time targets. Static
// targets are the nominal coordinates the passes computed.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "backend/linuxcnc/embedded_files.h"
#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "base/text_output.h"
#include "ir/ir.h"
#include "passes/correction/compile_state.h"

namespace smtcal {

// What one compile writes besides the main program's text: its file name
// and the subroutine files.
struct LinuxCncOutput {
  std::string main_name;                  // "<program file stem>.ngc"
  std::vector<EmbeddedFile> subroutines;  // the runtime's files and smtcal_data.ngc, sorted by name
  std::vector<EmbeddedFile> dry_run;      // OUTDIR/dry-run/ (--dry-run-probe, linuxcnc_dry_run.h), or none
  std::vector<EmbeddedFile> more_mains;   // further programs beside the main one (the measuring programs), or none
};

// Lowers the program, writing the main program's text to `main` as it is
// produced. What the target cannot express (a cell without a [linuxcnc]
// table, data the runtime cannot hold, an I/O bit LinuxCNC does not have, a
// pallet number known only at run time, a line too long for rs274) is
// reported to `diags`; nullopt, or errors in `diags`, leave `main`
// incomplete: never commit it then. `program_path` names the source in the
// output's comments (its file name only).
std::optional<LinuxCncOutput> EmitLinuxCnc(const ir::Program& program, const CompileState& state,
                                           const std::string& program_path, TextOutput& main, Diagnostics& diags);

// The name of the main program file for a source path: "layers.place" ->
// "layers.ngc" ("-" -> "program.ngc").
std::string LinuxCncMainName(const std::string& program_path);

// Every generated file for review on one stream: the main program, then
// smtcal_data.ngc, each after a "(smtcal file: PATH)" line. The runtime's
// own files are not repeated (they are runtime/linuxcnc/*.ngc verbatim).
std::string LinuxCncReviewText(const LinuxCncOutput& output, std::string_view main_text);

// The output directory OUTDIR: OUTDIR/<main_name> and OUTDIR/subroutines/*,
// written into a temporary sibling (OUTDIR.tmp.PID) and swapped in by a
// rename at Commit(), so OUTDIR is never half-written; a directory never
// committed leaves nothing behind, and one left by a killed smtcal is removed
// the next time smtcal writes OUTDIR (as a file output's temporary is). An existing OUTDIR is replaced only when
// it is an earlier smtcal output (its .ngc files open with smtcal's header
// line, subroutines/ holds only smtcal_*.ngc); anything else is refused by
// Open() with an Error naming what is in the way.
class LinuxCncDirectory {
 public:
  static Result<std::unique_ptr<LinuxCncDirectory>> Open(const std::filesystem::path& outdir,
                                                        const std::string& main_name);
  ~LinuxCncDirectory();
  LinuxCncDirectory(const LinuxCncDirectory&) = delete;
  LinuxCncDirectory& operator=(const LinuxCncDirectory&) = delete;

  // The main program's file, written as EmitLinuxCnc produces it.
  TextOutput& main() { return *main_; }
  // Completes the main program, writes the subroutines and swaps the
  // directory in.
  Status Commit(const LinuxCncOutput& output);

 private:
  LinuxCncDirectory() = default;
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool replaces_ = false;  // OUTDIR exists (an earlier output)
  bool committed_ = false;
  std::unique_ptr<TextOutput> main_;
};

}  // namespace smtcal
